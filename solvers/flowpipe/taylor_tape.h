#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hybrid/automaton/expression.h"
#include "solvers/flowpipe/tight_interval.h"

namespace hybrid::flowpipe_internal {

/// Where each slot of the system's environment goes in the flowpipe engine: a state component
/// (a continuous variable or an uncertain parameter, which is a state with zero flow), an input,
/// or neither (then the expression must not read it: parameters and discrete variables are
/// substituted before compiling).
struct SlotMap {
  std::vector<int> state;  ///< slot -> state component or -1
  std::vector<int> input;  ///< slot -> input index or -1
};

/// The right-hand side x' = f(x, u) of one mode, compiled into a tape for Taylor-mode automatic
/// differentiation: with the state's Taylor coefficients x_0..x_k known, one pass gives the k-th
/// coefficient of f and so x_{k+1} = f_k / (k + 1) (the recurrences of Moore, and of Flow*'s and
/// CAPD's Taylor methods: (a b)_k = sum_i a_i b_{k-i}, (a / b)_k = (a_k - sum_{i>=1} b_i
/// (a/b)_{k-i}) / b_0). The same tape runs on affine forms (the coefficients over the step's start
/// set) and on intervals (the remainder over the a-priori enclosure).
///
/// Supported: + - * /, unary minus, and ^ with a constant integer exponent 0..16, over constants,
/// state components and inputs. Inputs must enter affinely with coefficients that read no
/// variable and no input (x' = A x + B u + c, and polynomial f(x) + B u): Compile says why not
/// otherwise.
class TaylorTape {
 public:
  /// `flows[i]`: the right-hand side of state component i (nullopt: zero). Nullopt, with `why`,
  /// for an unsupported flow.
  static std::optional<TaylorTape> Compile(std::span<const std::optional<Expression>> flows,
                                           const SlotMap& slots, int num_inputs, std::string* why);

  int dimension() const { return static_cast<int>(outputs_.size()); }
  int num_inputs() const { return num_inputs_; }
  /// Whether the flow reads some input.
  bool reads_inputs() const { return reads_inputs_; }

  /// The Taylor coefficients x_0..x_order of the solution from `x0` with the inputs held at
  /// `inputs` (coefficient k of component i at [k][i]). T: AffineForm or TightInterval.
  template <class T>
  std::vector<std::vector<T>> Series(const std::vector<T>& x0, const std::vector<T>& inputs,
                                     int order) const;
  /// f over the box `x` and the input box `inputs`.
  std::vector<TightInterval> Evaluate(const std::vector<TightInterval>& x,
                                      const std::vector<TightInterval>& inputs) const;
  /// Enclosures of df_i/dx_j over the boxes (row i, column j).
  std::vector<std::vector<TightInterval>> Jacobian(const std::vector<TightInterval>& x,
                                                   const std::vector<TightInterval>& inputs) const;
  /// Bounds of |df_i/du_j| (f is affine in u; the coefficients read state components that are
  /// parameters only).
  std::vector<std::vector<double>> InputGainMagnitude(const std::vector<TightInterval>& x) const;

 private:
  enum class Kind { kConstant, kState, kInput, kNeg, kAdd, kSub, kMul, kDiv };
  struct Node {
    Kind kind;
    int a = -1;  // argument node, state index or input index
    int b = -1;
    double value = 0.0;
  };
  TaylorTape() = default;
  int Add(Node node);
  int Build(const Expression& e, const SlotMap& slots, std::string* why);
  template <class T>
  T Coefficient(const Node& node, int k, const std::vector<std::vector<T>>& values,
                const std::vector<std::vector<T>>& x, const std::vector<T>& inputs) const;
  template <class T>
  std::vector<T> NodeValues(const std::vector<T>& x, const std::vector<T>& inputs,
                            std::size_t count) const;

  std::vector<Node> nodes_;
  std::vector<int> outputs_;        // node of f_i, -1 for zero
  std::size_t num_flow_nodes_ = 0;  // nodes_[0, this) compute f; the rest its derivatives
  int num_inputs_ = 0;
  bool reads_inputs_ = false;
  // Derivative tapes: d f_i / d x_j (per i, j: node index or -1) and d f_i / d u_j.
  std::vector<std::vector<int>> jacobian_;
  std::vector<std::vector<int>> input_gain_;
};

}  // namespace hybrid::flowpipe_internal
