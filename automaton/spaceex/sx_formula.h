#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hybrid::spaceex {

/// A syntax error in a SpaceEx formula: `offset` is the byte in the formula's text where it is.
class FormulaError : public std::runtime_error {
 public:
  FormulaError(std::size_t offset, const std::string& message)
      : std::runtime_error(message), offset_(offset) {}
  std::size_t offset() const { return offset_; }

 private:
  std::size_t offset_;
};

/// A parsed SpaceEx formula (the text of a `<flow>`, `<invariant>`, `<guard>` or `<assignment>`
/// element, or of the `initially` and `forbidden` options of a configuration file).
///
/// Grammar, loosest first:
///   formula    := conj ( ('|' | '||') conj )*
///   conj       := atom ( ('&' | '&&') atom )*
///   atom       := 'true' | 'false' | '(' formula ')' | 'loc' '(' [name] ')' '==' name
///               | expr REL expr | name ':=' expr        REL one of == <= >= < >
///   expr       := term (('+' | '-') term)* ;  term := unary (('*' | '/') unary)*
///   unary      := '-' unary | power ;  power := primary ['^' unary]
///   primary    := number | name ["'"] | name '(' expr {',' expr} ')' | '(' expr ')'
/// Names are [A-Za-z_][A-Za-z0-9_.]* (dots qualify names of instances: `P1.x`); `x'` is the
/// derivative of x in a flow, its new value in an assignment. A parenthesis opens an expression
/// or a formula, whichever parses. Nesting is limited to 200 levels (a FormulaError beyond).
class SxFormula {
 public:
  enum class Kind {
    kNumber,    ///< text: the number as written
    kName,      ///< text: the name; primed: written with a prime
    kNegate,    ///< -children[0]
    kBinary,    ///< children[0] text children[1], text one of + - * / ^
    kCall,      ///< text(children...)
    kCompare,   ///< children[0] text children[1], text one of == <= >= < >
    kAssign,    ///< children[0] (a name) := children[1]
    kLocation,  ///< loc(text) == children[0] (a name); text empty for `loc()`
    kAnd,       ///< conjunction of children
    kOr,        ///< disjunction of children
    kTrue,
    kFalse,
  };

  Kind kind = Kind::kTrue;
  std::string text;
  bool primed = false;
  /// Byte offset of the node's first token in the formula's text.
  std::size_t offset = 0;
  std::vector<SxFormula> children;

  /// Parses `text`; throws FormulaError at the offending byte.
  static SxFormula Parse(std::string_view text);
  /// Parses `text` as one expression (`expr` above: the value of a `<map>`).
  static SxFormula ParseExpression(std::string_view text);

  /// The conjuncts of this formula: itself unless it is a conjunction (nested ones flattened);
  /// `true` has none.
  std::vector<const SxFormula*> Conjuncts() const;
  /// True if some name of this subtree is primed.
  bool HasPrime() const;
  /// Calls `visit` on every kName node of this subtree (loc() atoms excluded).
  void ForEachName(const std::function<void(const SxFormula&)>& visit) const;
};

/// Writes an expression (kNumber, kName, kNegate, kBinary, kCall) in the model language with the
/// fewest parentheses that keep its structure, each name written as `rename` gives it.
std::string WriteExpression(const SxFormula& e,
                            const std::function<std::string(const SxFormula&)>& rename);

}  // namespace hybrid::spaceex
