#include "automaton/spaceex/sx_formula.h"

#include <cctype>
#include <utility>

namespace hybrid::spaceex {
namespace {

constexpr int kMaxDepth = 200;

bool IsNameStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.';
}
bool IsDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

// Recursive descent over the text; every method leaves pos_ after what it read.
class Reader {
 public:
  explicit Reader(std::string_view text) : text_(text) {}

  SxFormula Whole(bool expression) {
    SxFormula f = expression ? Expr() : Formula();
    SkipSpace();
    if (pos_ < text_.size()) Fail("unexpected '" + std::string(1, text_[pos_]) + "'");
    return f;
  }

 private:
  [[noreturn]] void Fail(const std::string& message) const { throw FormulaError(pos_, message); }

  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  // True (and consumes it) if `token` comes next; `&` does not match the first half of `&&`
  // unless asked for, and `<` not the start of `<=`.
  bool Accept(std::string_view token) {
    SkipSpace();
    if (text_.substr(pos_, token.size()) != token) return false;
    const char next = pos_ + token.size() < text_.size() ? text_[pos_ + token.size()] : '\0';
    if ((token == "<" || token == ">" || token == ":") && next == '=') return false;
    if (token == "=" && next == '=') return false;
    pos_ += token.size();
    return true;
  }
  void Expect(std::string_view token) {
    if (!Accept(token)) Fail("expected '" + std::string(token) + "'");
  }
  bool PeekName(std::string_view name) {
    SkipSpace();
    if (text_.substr(pos_, name.size()) != name) return false;
    const std::size_t end = pos_ + name.size();
    return end >= text_.size() || !IsNameChar(text_[end]);
  }

  struct Depth {
    explicit Depth(Reader& r) : reader(r) {
      if (++reader.depth_ > kMaxDepth) reader.Fail("formula nested too deeply");
    }
    ~Depth() { --reader.depth_; }
    Reader& reader;
  };

  SxFormula Node(SxFormula::Kind kind, std::string text, std::size_t offset) {
    SxFormula n;
    n.kind = kind;
    n.text = std::move(text);
    n.offset = offset;
    return n;
  }

  SxFormula Junction(SxFormula::Kind kind, SxFormula first, std::string_view op,
                     SxFormula (Reader::*operand)()) {
    SxFormula result = Node(kind, "", first.offset);
    result.children.push_back(std::move(first));
    while (true) {
      const bool doubled = Accept(std::string(2, op[0]));
      if (!doubled && !Accept(op)) break;
      result.children.push_back((this->*operand)());
    }
    if (result.children.size() == 1) return std::move(result.children[0]);
    return result;
  }
  SxFormula Formula() {
    Depth depth(*this);
    return Junction(SxFormula::Kind::kOr, Conjunction(), "|", &Reader::Conjunction);
  }
  SxFormula Conjunction() { return Junction(SxFormula::Kind::kAnd, Atom(), "&", &Reader::Atom); }

  SxFormula Atom() {
    Depth depth(*this);
    SkipSpace();
    const std::size_t start = pos_;
    if (PeekName("true") || PeekName("false")) {
      const bool value = PeekName("true");
      pos_ += value ? 4 : 5;
      return Node(value ? SxFormula::Kind::kTrue : SxFormula::Kind::kFalse, "", start);
    }
    if (PeekName("loc")) return Location();
    if (pos_ < text_.size() && text_[pos_] == '(') {
      try {
        return Relation();
      } catch (const FormulaError&) {
        pos_ = start;
      }
      Expect("(");
      SxFormula inner = Formula();
      Expect(")");
      return inner;
    }
    return Relation();
  }

  SxFormula Location() {
    const std::size_t start = pos_;
    pos_ += 3;
    Expect("(");
    SkipSpace();
    std::string instance;
    if (pos_ < text_.size() && IsNameStart(text_[pos_])) instance = NameText();
    Expect(")");
    Expect("==");
    SkipSpace();
    if (pos_ >= text_.size() || !IsNameStart(text_[pos_])) Fail("expected a location name");
    SxFormula loc = Node(SxFormula::Kind::kLocation, std::move(instance), start);
    const std::size_t at = pos_;
    loc.children.push_back(Node(SxFormula::Kind::kName, NameText(), at));
    return loc;
  }

  SxFormula Relation() {
    SxFormula left = Expr();
    const std::size_t at = (SkipSpace(), pos_);
    if (Accept(":=")) {
      if (left.kind != SxFormula::Kind::kName) Fail("only a variable can be assigned");
      SxFormula assign = Node(SxFormula::Kind::kAssign, ":=", left.offset);
      assign.children.push_back(std::move(left));
      assign.children.push_back(Expr());
      return assign;
    }
    for (const char* op : {"==", "<=", ">=", "<", ">"}) {
      if (!Accept(op)) continue;
      SxFormula compare = Node(SxFormula::Kind::kCompare, op, left.offset);
      compare.children.push_back(std::move(left));
      compare.children.push_back(Expr());
      return compare;
    }
    pos_ = at;
    if (text_.substr(at, 2) == "!=") Fail("'!=' is not supported: write two transitions (< and >)");
    if (text_.substr(at, 1) == "=") Fail("'=' is not a comparison: write '=='");
    Fail("expected a comparison (==, <=, >=, <, >) or ':='");
  }

  SxFormula Binary(SxFormula left, std::string op, SxFormula right) {
    SxFormula b = Node(SxFormula::Kind::kBinary, std::move(op), left.offset);
    b.children.push_back(std::move(left));
    b.children.push_back(std::move(right));
    return b;
  }
  SxFormula Expr() {
    SxFormula e = Term();
    while (true) {
      if (Accept("+")) {
        e = Binary(std::move(e), "+", Term());
      } else if (Accept("-")) {
        e = Binary(std::move(e), "-", Term());
      } else {
        return e;
      }
    }
  }
  SxFormula Term() {
    SxFormula e = Unary();
    while (true) {
      if (Accept("*")) {
        e = Binary(std::move(e), "*", Unary());
      } else if (Accept("/")) {
        e = Binary(std::move(e), "/", Unary());
      } else {
        return e;
      }
    }
  }
  SxFormula Unary() {
    Depth depth(*this);
    SkipSpace();
    const std::size_t start = pos_;
    if (Accept("-")) {
      SxFormula n = Node(SxFormula::Kind::kNegate, "-", start);
      n.children.push_back(Unary());
      return n;
    }
    if (Accept("+")) return Unary();
    SxFormula base = Primary();
    if (Accept("^")) return Binary(std::move(base), "^", Unary());
    return base;
  }

  std::string NameText() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && IsNameChar(text_[pos_])) ++pos_;
    return std::string(text_.substr(start, pos_ - start));
  }
  std::string NumberText() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && IsDigit(text_[pos_])) ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '.') ++pos_;
    while (pos_ < text_.size() && IsDigit(text_[pos_])) ++pos_;
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      std::size_t e = pos_ + 1;
      if (e < text_.size() && (text_[e] == '+' || text_[e] == '-')) ++e;
      if (e < text_.size() && IsDigit(text_[e])) {
        pos_ = e;
        while (pos_ < text_.size() && IsDigit(text_[pos_])) ++pos_;
      }
    }
    if (pos_ - start == 1 && text_[start] == '.') Fail("expected a number");
    return std::string(text_.substr(start, pos_ - start));
  }

  SxFormula Primary() {
    Depth depth(*this);
    SkipSpace();
    const std::size_t start = pos_;
    if (pos_ >= text_.size()) Fail("expected an expression");
    const char c = text_[pos_];
    if (IsDigit(c) || c == '.') return Node(SxFormula::Kind::kNumber, NumberText(), start);
    if (IsNameStart(c)) {
      std::string name = NameText();
      if (Accept("(")) return Call(std::move(name), start);
      SxFormula n = Node(SxFormula::Kind::kName, std::move(name), start);
      n.primed = Accept("'");
      return n;
    }
    if (Accept("(")) {
      SxFormula inner = Expr();
      Expect(")");
      return inner;
    }
    Fail(std::string("unexpected '") + c + "'");
  }
  SxFormula Call(std::string name, std::size_t start) {
    SxFormula call = Node(SxFormula::Kind::kCall, std::move(name), start);
    call.children.push_back(Expr());
    while (Accept(",")) call.children.push_back(Expr());
    Expect(")");
    return call;
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

// Binding strength of an expression node for WriteExpression (higher binds tighter).
int Strength(const SxFormula& e) {
  using K = SxFormula::Kind;
  if (e.kind == K::kBinary) {
    if (e.text == "+" || e.text == "-") return 1;
    if (e.text == "*" || e.text == "/") return 2;
    return 4;  // ^
  }
  if (e.kind == K::kNegate) return 3;
  return 5;
}

}  // namespace

SxFormula SxFormula::Parse(std::string_view text) { return Reader(text).Whole(false); }

SxFormula SxFormula::ParseExpression(std::string_view text) { return Reader(text).Whole(true); }

std::vector<const SxFormula*> SxFormula::Conjuncts() const {
  std::vector<const SxFormula*> out;
  if (kind == Kind::kTrue) return out;
  if (kind != Kind::kAnd) return {this};
  for (const SxFormula& c : children) {
    for (const SxFormula* leaf : c.Conjuncts()) out.push_back(leaf);
  }
  return out;
}

bool SxFormula::HasPrime() const {
  if (kind == Kind::kName && primed) return true;
  for (const SxFormula& c : children) {
    if (kind != Kind::kLocation && c.HasPrime()) return true;
  }
  return false;
}

void SxFormula::ForEachName(const std::function<void(const SxFormula&)>& visit) const {
  if (kind == Kind::kLocation) return;
  if (kind == Kind::kName) visit(*this);
  for (const SxFormula& c : children) c.ForEachName(visit);
}

std::string WriteExpression(const SxFormula& e,
                            const std::function<std::string(const SxFormula&)>& rename) {
  using K = SxFormula::Kind;
  // wrap: the operand in parentheses when it binds more loosely than `need`.
  auto wrap = [&](const SxFormula& operand, int need) {
    std::string s = WriteExpression(operand, rename);
    if (Strength(operand) >= need) return s;
    std::string wrapped(1, '(');
    wrapped.append(s).push_back(')');
    return wrapped;
  };
  switch (e.kind) {
    case K::kNumber: {
      // `1.` and `1.e3` are numbers in SpaceEx; the model language wants a digit after a point.
      std::string n = e.text;
      const std::size_t point = n.find('.');
      if (point != std::string::npos && (point + 1 == n.size() || !IsDigit(n[point + 1]))) {
        n.insert(point + 1, 1, '0');
      }
      return n;
    }
    case K::kName:
      return rename(e);
    case K::kNegate: {
      std::string negated(1, '-');
      return negated.append(wrap(e.children[0], 3));
    }
    case K::kCall: {
      std::string s = e.text + "(";
      for (std::size_t i = 0; i < e.children.size(); ++i) {
        s += (i ? ", " : "") + WriteExpression(e.children[i], rename);
      }
      return s + ")";
    }
    case K::kBinary: {
      const int s = Strength(e);
      // Left associative + - * /: the right operand needs to bind tighter; ^ is right
      // associative: the left one does, and a negated exponent is parenthesised: 2 ^ (-3).
      const int left = e.text == "^" ? s + 1 : s;
      const int right = e.text == "^" ? s : s + 1;
      return wrap(e.children[0], left) + " " + e.text + " " + wrap(e.children[1], right);
    }
    default:
      throw std::logic_error("writing a SpaceEx formula: a node that is not an expression");
  }
}

}  // namespace hybrid::spaceex
