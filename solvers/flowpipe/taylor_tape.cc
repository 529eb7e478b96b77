#include "solvers/flowpipe/taylor_tape.h"

#include <cmath>

#include "solvers/flowpipe/affine_form.h"

namespace hybrid::flowpipe_internal {
namespace {

constexpr int kMaxIntegerExponent = 16;

// The series operations the tape needs, for both coefficient types.
AffineForm DivideByInteger(const AffineForm& a, int k) {
  return a.Scaled(TightInterval(1.0) / TightInterval(static_cast<double>(k)));
}
TightInterval DivideByInteger(const TightInterval& a, int k) {
  return a / TightInterval(static_cast<double>(k));
}
template <class T>
T Zero();
template <>
AffineForm Zero<AffineForm>() {
  return AffineForm(0.0);
}
template <>
TightInterval Zero<TightInterval>() {
  return TightInterval(0.0);
}

AffineForm Square(const AffineForm& a) { return a.Square(); }
TightInterval Square(const TightInterval& a) { return Power(a, 2); }

}  // namespace

int TaylorTape::Add(Node node) {
  nodes_.push_back(node);
  return static_cast<int>(nodes_.size()) - 1;
}

// Appends the nodes of e (arguments first) and returns e's node; -1 with `why` if unsupported.
int TaylorTape::Build(const Expression& e, const SlotMap& slots, std::string* why) {
  switch (e.op()) {
    case Op::kConstant:
      return Add({Kind::kConstant, -1, -1, e.constant()});
    case Op::kSymbol: {
      const auto s = static_cast<std::size_t>(e.slot());
      if (s < slots.state.size() && slots.state[s] >= 0) return Add({Kind::kState, slots.state[s]});
      if (s < slots.input.size() && slots.input[s] >= 0) {
        reads_inputs_ = true;
        return Add({Kind::kInput, slots.input[s]});
      }
      if (why)
        *why = "the flow reads '" + e.symbol_name() + "', which is neither a variable nor an input";
      return -1;
    }
    case Op::kNeg: {
      const int a = Build(e.args()[0], slots, why);
      return a < 0 ? -1 : Add({Kind::kNeg, a});
    }
    case Op::kAdd:
    case Op::kSub:
    case Op::kMul:
    case Op::kDiv: {
      const int a = Build(e.args()[0], slots, why);
      if (a < 0) return -1;
      const int b = Build(e.args()[1], slots, why);
      if (b < 0) return -1;
      const Kind kind = e.op() == Op::kAdd   ? Kind::kAdd
                        : e.op() == Op::kSub ? Kind::kSub
                        : e.op() == Op::kMul ? Kind::kMul
                                             : Kind::kDiv;
      return Add({kind, a, b});
    }
    case Op::kPow: {
      const Expression& exponent = e.args()[1];
      const double n = exponent.is_constant() ? exponent.constant() : -1.0;
      if (n < 0 || n > kMaxIntegerExponent || n != std::floor(n)) {
        if (why)
          *why = "the flow has a power '" + e.ToString() +
                 "' whose exponent is not a constant integer from 0 to 16";
        return -1;
      }
      if (n == 0) return Add({Kind::kConstant, -1, -1, 1.0});
      const int base = Build(e.args()[0], slots, why);
      if (base < 0) return -1;
      int result = base;
      for (int i = 1; i < static_cast<int>(n); ++i) result = Add({Kind::kMul, result, base});
      return result;
    }
    default:
      if (why)
        *why = "the flow '" + e.ToString() +
               "' is not polynomial or rational (the flowpipe engine takes + - * / and integer "
               "powers)";
      return -1;
  }
}

std::optional<TaylorTape> TaylorTape::Compile(std::span<const std::optional<Expression>> flows,
                                              const SlotMap& slots, int num_inputs,
                                              std::string* why) {
  TaylorTape tape;
  tape.num_inputs_ = num_inputs;
  const int n = static_cast<int>(flows.size());
  std::vector<int> slot_of_state(static_cast<std::size_t>(n), -1);
  for (std::size_t s = 0; s < slots.state.size(); ++s) {
    if (slots.state[s] >= 0 && slots.state[s] < n)
      slot_of_state[static_cast<std::size_t>(slots.state[s])] = static_cast<int>(s);
  }
  std::vector<int> slot_of_input(static_cast<std::size_t>(num_inputs), -1);
  for (std::size_t s = 0; s < slots.input.size(); ++s) {
    if (slots.input[s] >= 0)
      slot_of_input[static_cast<std::size_t>(slots.input[s])] = static_cast<int>(s);
  }
  for (const auto& f : flows) {
    if (!f) {
      tape.outputs_.push_back(-1);
      continue;
    }
    const int node = tape.Build(*f, slots, why);
    if (node < 0) return std::nullopt;
    tape.outputs_.push_back(node);
  }
  tape.num_flow_nodes_ = tape.nodes_.size();
  // Inputs must enter affinely: d f / d u reads no variable and no input.
  tape.jacobian_.assign(static_cast<std::size_t>(n),
                        std::vector<int>(static_cast<std::size_t>(n), -1));
  tape.input_gain_.assign(static_cast<std::size_t>(n),
                          std::vector<int>(static_cast<std::size_t>(num_inputs), -1));
  for (int i = 0; i < n; ++i) {
    const auto& f = flows[static_cast<std::size_t>(i)];
    if (!f) continue;
    for (int j = 0; j < num_inputs; ++j) {
      const int slot = slot_of_input[static_cast<std::size_t>(j)];
      if (slot < 0) continue;
      const Expression d = f->Derivative(slot).FoldConstants();
      if (d.is_constant() && d.constant() == 0) continue;
      for (int read : d.Slots()) {
        const auto r = static_cast<std::size_t>(read);
        const bool input = r < slots.input.size() && slots.input[r] >= 0;
        const bool variable_state = r < slots.state.size() && slots.state[r] >= 0 &&
                                    slots.state[r] < n &&
                                    flows[static_cast<std::size_t>(slots.state[r])].has_value();
        if (input || variable_state) {
          if (why)
            *why = "the flow '" + f->ToString() +
                   "' is not affine in its inputs with constant coefficients";
          return std::nullopt;
        }
      }
      const int node = tape.Build(d, slots, why);
      if (node < 0) return std::nullopt;
      tape.input_gain_[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = node;
    }
    for (int j = 0; j < n; ++j) {
      const int slot = slot_of_state[static_cast<std::size_t>(j)];
      if (slot < 0) continue;
      const Expression d = f->Derivative(slot).FoldConstants();
      if (d.is_constant() && d.constant() == 0) continue;
      const int node = tape.Build(d, slots, why);
      if (node < 0) return std::nullopt;
      tape.jacobian_[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = node;
    }
  }
  return tape;
}

template <class T>
T TaylorTape::Coefficient(const Node& node, int k, const std::vector<std::vector<T>>& v,
                          const std::vector<std::vector<T>>& x,
                          const std::vector<T>& inputs) const {
  auto at = [&](int a, int i) -> const T& {
    return v[static_cast<std::size_t>(i)][static_cast<std::size_t>(a)];
  };
  switch (node.kind) {
    case Kind::kConstant:
      return k == 0 ? T(node.value) : Zero<T>();
    case Kind::kState:
      return x[static_cast<std::size_t>(k)][static_cast<std::size_t>(node.a)];
    case Kind::kInput:
      return k == 0 ? inputs[static_cast<std::size_t>(node.a)] : Zero<T>();
    case Kind::kNeg:
      return -at(node.a, k);
    case Kind::kAdd:
      return at(node.a, k) + at(node.b, k);
    case Kind::kSub:
      return at(node.a, k) - at(node.b, k);
    case Kind::kMul: {
      if (node.a == node.b) {  // a square: sum_i a_i a_{k-i}, the middle term squared once
        T sum = k % 2 == 0 ? Square(at(node.a, k / 2)) : Zero<T>();
        for (int i = 0; 2 * i < k; ++i) {
          const T p = at(node.a, i) * at(node.a, k - i);
          sum = sum + p + p;
        }
        return sum;
      }
      T sum = at(node.a, 0) * at(node.b, k);
      for (int i = 1; i <= k; ++i) sum = sum + at(node.a, i) * at(node.b, k - i);
      return sum;
    }
    case Kind::kDiv: {
      // q_k = (a_k - sum_{i=1}^k b_i q_{k-i}) / b_0, the q_{k-i} being this node's earlier values.
      const int self = static_cast<int>(&node - nodes_.data());
      T num = at(node.a, k);
      for (int i = 1; i <= k; ++i) num = num - at(node.b, i) * at(self, k - i);
      return num / at(node.b, 0);
    }
  }
  return Zero<T>();
}

template <class T>
std::vector<std::vector<T>> TaylorTape::Series(const std::vector<T>& x0,
                                               const std::vector<T>& inputs, int order) const {
  std::vector<std::vector<T>> x(static_cast<std::size_t>(order) + 1);
  x[0] = x0;
  std::vector<std::vector<T>> v;  // v[k][node]
  for (int k = 0; k < order; ++k) {
    v.emplace_back();
    v.back().reserve(num_flow_nodes_);
    for (std::size_t i = 0; i < num_flow_nodes_; ++i)
      v.back().push_back(Coefficient(nodes_[i], k, v, x, inputs));
    std::vector<T>& next = x[static_cast<std::size_t>(k) + 1];
    for (int out : outputs_) {
      next.push_back(out < 0 ? Zero<T>()
                             : DivideByInteger(v.back()[static_cast<std::size_t>(out)], k + 1));
    }
  }
  return x;
}

template std::vector<std::vector<AffineForm>> TaylorTape::Series(const std::vector<AffineForm>&,
                                                                 const std::vector<AffineForm>&,
                                                                 int) const;
template std::vector<std::vector<TightInterval>> TaylorTape::Series(
    const std::vector<TightInterval>&, const std::vector<TightInterval>&, int) const;

template <class T>
std::vector<T> TaylorTape::NodeValues(const std::vector<T>& x, const std::vector<T>& inputs,
                                      std::size_t count) const {
  std::vector<std::vector<T>> v(1);
  const std::vector<std::vector<T>> xs = {x};
  v[0].reserve(count);
  for (std::size_t i = 0; i < count; ++i) v[0].push_back(Coefficient(nodes_[i], 0, v, xs, inputs));
  return v[0];
}

std::vector<TightInterval> TaylorTape::Evaluate(const std::vector<TightInterval>& x,
                                                const std::vector<TightInterval>& inputs) const {
  const std::vector<TightInterval> v = NodeValues(x, inputs, num_flow_nodes_);
  std::vector<TightInterval> f;
  for (int out : outputs_)
    f.push_back(out < 0 ? TightInterval(0.0) : v[static_cast<std::size_t>(out)]);
  return f;
}

std::vector<std::vector<TightInterval>> TaylorTape::Jacobian(
    const std::vector<TightInterval>& x, const std::vector<TightInterval>& inputs) const {
  const std::vector<TightInterval> v = NodeValues(x, inputs, nodes_.size());
  std::vector<std::vector<TightInterval>> out;
  for (const auto& row : jacobian_) {
    out.emplace_back();
    for (int node : row) {
      out.back().push_back(node < 0 ? TightInterval(0.0) : v[static_cast<std::size_t>(node)]);
    }
  }
  return out;
}

std::vector<std::vector<double>> TaylorTape::InputGainMagnitude(
    const std::vector<TightInterval>& x) const {
  const std::vector<TightInterval> inputs(static_cast<std::size_t>(num_inputs_),
                                          TightInterval(0.0));
  const std::vector<TightInterval> v = NodeValues(x, inputs, nodes_.size());
  std::vector<std::vector<double>> out;
  for (const auto& row : input_gain_) {
    out.emplace_back();
    for (int node : row)
      out.back().push_back(node < 0 ? 0.0 : v[static_cast<std::size_t>(node)].MagnitudeUp());
  }
  return out;
}

}  // namespace hybrid::flowpipe_internal
