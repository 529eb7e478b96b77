#include "hybrid/automaton/predicate.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "automaton/tree_walk.h"

namespace hybrid {

struct Predicate::Node {
  Kind kind = Kind::kTrue;
  int depth = 1;
  Comparison comparison;
  std::string mode;
  std::vector<Predicate> operands;

  Node() = default;
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;
  ~Node();
};

Predicate::Node::~Node() {
  // As Expression's nodes: operands owned by this node alone are taken apart one at a time, not
  // recursively (a predicate may be kMaxTreeDepth deep).
  std::vector<std::shared_ptr<const Node>> orphans;
  auto adopt = [&](std::vector<Predicate>& children) {
    for (Predicate& c : children) {
      if (c.node_ && c.node_.use_count() == 1) orphans.push_back(std::move(c.node_));
    }
  };
  adopt(operands);
  while (!orphans.empty()) {
    std::shared_ptr<const Node> n = std::move(orphans.back());
    orphans.pop_back();
    adopt(const_cast<Node&>(*n).operands);  // nodes are created mutable (make_shared<Node>)
  }
}

namespace {

// `depth` if a predicate may be that deep (kMaxTreeDepth); throws std::invalid_argument otherwise.
int CheckedDepth(int depth) {
  if (depth > kMaxTreeDepth) {
    throw std::invalid_argument("predicate too long or nested too deeply (more than " +
                                std::to_string(kMaxTreeDepth) + " levels)");
  }
  return depth;
}

}  // namespace

Predicate::Predicate() : Predicate(True()) {}
Predicate::Predicate(std::shared_ptr<const Node> node) : node_(std::move(node)) {}

Predicate Predicate::True() {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kTrue;
  return Predicate(std::move(n));
}
Predicate Predicate::False() {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kFalse;
  return Predicate(std::move(n));
}
Predicate Predicate::Compare(Comparison c) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kComparison;
  n->depth = CheckedDepth(std::max(c.lhs.depth(), c.rhs.depth()) + 1);
  n->comparison = std::move(c);
  return Predicate(std::move(n));
}
Predicate Predicate::InMode(std::string mode) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kInMode;
  n->mode = std::move(mode);
  return Predicate(std::move(n));
}
Predicate Predicate::Not(Predicate p) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kNot;
  n->depth = CheckedDepth(p.depth() + 1);
  n->operands.push_back(std::move(p));
  return Predicate(std::move(n));
}
Predicate Predicate::And(Predicate a, Predicate b) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kAnd;
  n->depth = CheckedDepth(std::max(a.depth(), b.depth()) + 1);
  n->operands = {std::move(a), std::move(b)};
  return Predicate(std::move(n));
}
Predicate Predicate::Or(Predicate a, Predicate b) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kOr;
  n->depth = CheckedDepth(std::max(a.depth(), b.depth()) + 1);
  n->operands = {std::move(a), std::move(b)};
  return Predicate(std::move(n));
}

Predicate::Kind Predicate::kind() const { return node_->kind; }
const Comparison& Predicate::comparison() const { return node_->comparison; }
const std::string& Predicate::mode() const { return node_->mode; }
std::span<const Predicate> Predicate::operands() const { return node_->operands; }
int Predicate::depth() const { return node_->depth; }

namespace {

// The operands of a predicate, for the walks of tree_walk.h.
std::span<const Predicate> Operands(const Predicate& p) { return p.operands(); }

int Level(Predicate::Kind k) {
  switch (k) {
    case Predicate::Kind::kOr:
      return 1;
    case Predicate::Kind::kAnd:
      return 2;
    case Predicate::Kind::kNot:
      return 3;
    default:
      return 4;
  }
}

}  // namespace

namespace {

// Predicate::Lenient at polarity `positive` (a recursion no deeper than the predicate's depth).
bool LenientAt(const Predicate& p, std::span<const double> env, std::span<const std::string> modes,
               double tol, bool positive) {
  switch (p.kind()) {
    case Predicate::Kind::kTrue:
      return true;
    case Predicate::Kind::kFalse:
      return false;
    case Predicate::Kind::kComparison: {
      const Comparison& c = p.comparison();
      return LenientBand(c.relation, positive ? tol : -tol)
          .Contains(c.lhs.Evaluate(env) - c.rhs.Evaluate(env));
    }
    case Predicate::Kind::kInMode:
      return std::find(modes.begin(), modes.end(), p.mode()) != modes.end();
    case Predicate::Kind::kNot:
      return !LenientAt(p.operands()[0], env, modes, tol, !positive);
    case Predicate::Kind::kAnd:
      return LenientAt(p.operands()[0], env, modes, tol, positive) &&
             LenientAt(p.operands()[1], env, modes, tol, positive);
    case Predicate::Kind::kOr:
      return LenientAt(p.operands()[0], env, modes, tol, positive) ||
             LenientAt(p.operands()[1], env, modes, tol, positive);
  }
  return false;
}

}  // namespace

bool Predicate::Witnessed(std::span<const double> env, std::span<const std::string> modes,
                          double tol) const {
  switch (kind()) {
    case Kind::kTrue:
      return true;
    case Kind::kFalse:
      return false;
    case Kind::kComparison: {
      const Comparison& c = comparison();
      const bool strict = c.relation == Relation::kLess || c.relation == Relation::kGreater;
      return LenientBand(c.relation, strict ? -tol : tol)
          .Contains(c.lhs.Evaluate(env) - c.rhs.Evaluate(env));
    }
    case Kind::kInMode:
      return std::find(modes.begin(), modes.end(), mode()) != modes.end();
    case Kind::kNot:
      return !operands()[0].Witnessed(env, modes, tol);
    case Kind::kAnd:
      return operands()[0].Witnessed(env, modes, tol) && operands()[1].Witnessed(env, modes, tol);
    case Kind::kOr:
      return operands()[0].Witnessed(env, modes, tol) || operands()[1].Witnessed(env, modes, tol);
  }
  return false;
}

bool Predicate::Lenient(std::span<const double> env, std::span<const std::string> modes,
                        double tol) const {
  return LenientAt(*this, env, modes, tol, true);
}

bool Predicate::Evaluate(std::span<const double> env, std::span<const std::string> modes,
                         double tol) const {
  // Truth values as int: std::vector<bool> has no contiguous storage for the walk's spans.
  return internal::PostOrder<int>(
             *this, Operands,
             [&](const Predicate& p) -> std::optional<int> {
               switch (p.kind()) {
                 case Kind::kTrue:
                   return true;
                 case Kind::kFalse:
                   return false;
                 case Kind::kComparison:
                   return p.comparison().Holds(env, tol);
                 case Kind::kInMode:
                   return std::find(modes.begin(), modes.end(), p.mode()) != modes.end();
                 default:
                   return std::nullopt;
               }
             },
             [](const Predicate& p, std::span<int> v) -> int {
               switch (p.kind()) {
                 case Kind::kNot:
                   return !v[0];
                 case Kind::kAnd:
                   return v[0] && v[1];
                 default:
                   return v[0] || v[1];
               }
             }) != 0;
}

void Predicate::ForEachComparison(const std::function<void(const Comparison&)>& f) const {
  internal::PreOrder(*this, Operands, [&](const Predicate& p) {
    if (p.kind() == Kind::kComparison) f(p.comparison());
  });
}

void Predicate::ForEachMode(const std::function<void(const std::string&)>& f) const {
  internal::PreOrder(*this, Operands, [&](const Predicate& p) {
    if (p.kind() == Kind::kInMode) f(p.mode());
  });
}

std::string Predicate::ToString() const {
  // Pending pieces on a heap stack: text, or a predicate wrapped in parentheses or not.
  struct Piece {
    const Predicate* p;     // nullptr for text
    std::string_view text;  // static text when p is nullptr
    bool wrap = false;
  };
  std::string out;
  std::vector<Piece> todo = {{this, {}, false}};
  while (!todo.empty()) {
    const Piece piece = todo.back();
    todo.pop_back();
    if (piece.p == nullptr) {
      out.append(piece.text);
      continue;
    }
    const Predicate& p = *piece.p;
    if (piece.wrap) {
      out.push_back('(');
      todo.push_back({nullptr, ")"});
    }
    switch (p.kind()) {
      case Kind::kTrue:
        out.append("true");
        break;
      case Kind::kFalse:
        out.append("false");
        break;
      case Kind::kComparison:
        out.append(p.comparison().ToString());
        break;
      case Kind::kInMode:
        out.append("in " + p.mode());
        break;
      case Kind::kNot:
        out.append("not ");
        todo.push_back({&p.operands()[0], {}, Level(p.operands()[0].kind()) < 3});
        break;
      case Kind::kAnd:
      case Kind::kOr: {
        // Left-associative: an equal-level right operand keeps its parentheses.
        const int level = Level(p.kind());
        todo.push_back({&p.operands()[1], {}, Level(p.operands()[1].kind()) <= level});
        todo.push_back({nullptr, p.kind() == Kind::kAnd ? " and " : " or "});
        todo.push_back({&p.operands()[0], {}, Level(p.operands()[0].kind()) < level});
        break;
      }
    }
  }
  return out;
}

bool operator==(const Predicate& a, const Predicate& b) {
  std::vector<std::pair<const Predicate*, const Predicate*>> todo = {{&a, &b}};
  while (!todo.empty()) {
    const auto [p, q] = todo.back();
    todo.pop_back();
    if (p->node_ == q->node_) continue;
    if (p->kind() != q->kind()) return false;
    if (p->kind() == Predicate::Kind::kComparison && !(p->comparison() == q->comparison())) {
      return false;
    }
    if (p->kind() == Predicate::Kind::kInMode && p->mode() != q->mode()) return false;
    const auto x = p->operands(), y = q->operands();
    if (x.size() != y.size()) return false;
    for (size_t i = 0; i < x.size(); ++i) todo.emplace_back(&x[i], &y[i]);
  }
  return true;
}

}  // namespace hybrid
