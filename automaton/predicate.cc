#include "automaton/predicate.h"

#include <algorithm>

namespace hybrid {

struct Predicate::Node {
  Kind kind = Kind::kTrue;
  Comparison comparison;
  std::string mode;
  std::vector<Predicate> operands;
};

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
  n->operands.push_back(std::move(p));
  return Predicate(std::move(n));
}
Predicate Predicate::And(Predicate a, Predicate b) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kAnd;
  n->operands = {std::move(a), std::move(b)};
  return Predicate(std::move(n));
}
Predicate Predicate::Or(Predicate a, Predicate b) {
  auto n = std::make_shared<Node>();
  n->kind = Kind::kOr;
  n->operands = {std::move(a), std::move(b)};
  return Predicate(std::move(n));
}

Predicate::Kind Predicate::kind() const { return node_->kind; }
const Comparison& Predicate::comparison() const { return node_->comparison; }
const std::string& Predicate::mode() const { return node_->mode; }
std::span<const Predicate> Predicate::operands() const { return node_->operands; }

bool Predicate::Evaluate(std::span<const double> env, std::span<const std::string> modes,
                         double tol) const {
  switch (kind()) {
    case Kind::kTrue:
      return true;
    case Kind::kFalse:
      return false;
    case Kind::kComparison:
      return node_->comparison.Holds(env, tol);
    case Kind::kInMode:
      return std::find(modes.begin(), modes.end(), node_->mode) != modes.end();
    case Kind::kNot:
      return !operands()[0].Evaluate(env, modes, tol);
    case Kind::kAnd:
      return operands()[0].Evaluate(env, modes, tol) && operands()[1].Evaluate(env, modes, tol);
    case Kind::kOr:
      return operands()[0].Evaluate(env, modes, tol) || operands()[1].Evaluate(env, modes, tol);
  }
  return false;
}

void Predicate::ForEachComparison(const std::function<void(const Comparison&)>& f) const {
  if (kind() == Kind::kComparison) f(node_->comparison);
  for (const Predicate& p : operands()) p.ForEachComparison(f);
}

void Predicate::ForEachMode(const std::function<void(const std::string&)>& f) const {
  if (kind() == Kind::kInMode) f(node_->mode);
  for (const Predicate& p : operands()) p.ForEachMode(f);
}

namespace {
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
std::string Wrap(const Predicate& p, bool wrap) {
  return wrap ? "(" + p.ToString() + ")" : p.ToString();
}
}  // namespace

std::string Predicate::ToString() const {
  switch (kind()) {
    case Kind::kTrue:
      return "true";
    case Kind::kFalse:
      return "false";
    case Kind::kComparison:
      return node_->comparison.ToString();
    case Kind::kInMode:
      return "in " + node_->mode;
    case Kind::kNot:
      return "not " + Wrap(operands()[0], Level(operands()[0].kind()) < 3);
    case Kind::kAnd:
    case Kind::kOr: {
      // Left-associative: an equal-level right operand keeps its parentheses.
      const int level = Level(kind());
      return Wrap(operands()[0], Level(operands()[0].kind()) < level) +
             (kind() == Kind::kAnd ? " and " : " or ") +
             Wrap(operands()[1], Level(operands()[1].kind()) <= level);
    }
  }
  return "?";
}

bool operator==(const Predicate& a, const Predicate& b) {
  if (a.node_ == b.node_) return true;
  if (a.kind() != b.kind()) return false;
  switch (a.kind()) {
    case Predicate::Kind::kComparison:
      return a.comparison() == b.comparison();
    case Predicate::Kind::kInMode:
      return a.mode() == b.mode();
    default:
      break;
  }
  return std::equal(a.operands().begin(), a.operands().end(), b.operands().begin(),
                    b.operands().end());
}

}  // namespace hybrid
