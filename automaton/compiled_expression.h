#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "automaton/expression.h"

namespace hybrid {

/// An Expression compiled once into a flat postfix program for fast repeated evaluation.
///
/// Evaluation walks a contiguous instruction array with a small value stack: no tree pointers, no
/// strings, no map look-ups and no heap allocation (for programs whose stack depth is at most
/// kMaxInlineStack, which covers every expression of practical size; deeper ones use a heap buffer).
/// Binary operations whose right operand is a constant or a symbol read it directly from the
/// instruction, halving the dispatches of typical flows such as `m1 * u`.
/// The result equals Expression::Evaluate bit for bit (same operations in the same order).
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

 private:
  enum class Operand : std::uint8_t { kStack, kConstant, kSlot };
  struct Instruction {
    Op op;
    Operand operand;  // where the right operand (binary) or the pushed value (leaf) comes from
    std::int32_t slot;
    double value;
  };
  void Emit(const Expression& e, int depth);
  double Run(const double* env, double* stack) const;

  std::vector<Instruction> code_;
  int max_depth_ = 0;
};

}  // namespace hybrid
