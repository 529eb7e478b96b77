#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "hybrid/automaton/expression.h"

namespace hybrid {

/// An Expression compiled once into a flat postfix program for fast repeated evaluation.
///
/// The program is an array of 16-byte instructions run by a direct-threaded interpreter (one
/// indirect jump per instruction) that keeps the top of the value stack in a register. There are
/// no tree pointers, strings, map look-ups or heap allocations per evaluation (programs deeper
/// than kMaxInlineStack use a heap buffer). Binary operations whose right operand is a constant
/// or a symbol read it straight from the instruction, and `x^n` for a small integer constant n
/// becomes repeated multiplication.
///
/// A subexpression shared by several parents (Expression::node_id, e.g. a point of a linkage used
/// in several distances) is computed once into a register and then read from it, so the program
/// is linear in the number of distinct nodes.
///
/// The result equals Expression::Evaluate bit for bit, except that `x^n` with integer n in
/// [-4, 4] is computed by multiplication (like the C++ compilers' own expansion of std::pow with
/// small integer exponents), which can differ from std::pow in the last bit.
class CompiledExpression {
 public:
  static constexpr int kMaxInlineStack = 64;

  /// Evaluates to 0.
  CompiledExpression();
  explicit CompiledExpression(const Expression& expression);

  /// The value with symbol values env[slot]; precondition: env covers every slot read.
  double Evaluate(const double* env) const;
  double operator()(std::span<const double> env) const { return Evaluate(env.data()); }

  /// Number of instructions (for diagnostics and tests).
  int size() const { return static_cast<int>(code_.size()); }

  /// Opcodes; public only so that the implementation's dispatch table can name them.
  enum class Code : std::uint32_t;

 private:
  struct Instruction {
    Code code;
    std::int32_t slot;
    double value;
  };
  void Emit(const Expression& root);
  double Run(const double* env, double* stack, double* registers) const;

  std::vector<Instruction> code_;
  int max_depth_ = 0;
  int num_registers_ = 0;
  // While compiling: register of each shared node (-1 until its value has been computed).
  std::unordered_map<const void*, int> registers_;
  int next_register_ = 0;
};

}  // namespace hybrid
