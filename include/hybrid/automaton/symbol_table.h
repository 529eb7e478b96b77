#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace hybrid {

/// What a name in a model denotes.
enum class SymbolKind {
  kVariable,   ///< continuous state variable, evolves by the mode's flow
  kDiscrete,   ///< discrete state variable: a constant integer in each mode
  kInput,      ///< bounded external input, set by the scenario or the caller
  kParameter,  ///< named constant, defined by an expression over earlier parameters
};

/// Human-readable kind ("variable", "discrete variable", "input", "parameter").
std::string_view KindName(SymbolKind kind);

/// A declared name.
struct Symbol {
  std::string name;
  SymbolKind kind = SymbolKind::kVariable;
  /// Display unit (e.g. "deg", "count", "s"); metadata only, values are never converted.
  std::string unit;
  friend bool operator==(const Symbol&, const Symbol&) = default;
};

/// The names of a model and their slots. A symbol's slot is its index in declaration order; it is
/// the position of its value in every evaluation environment (see Expression).
class SymbolTable {
 public:
  /// Adds `symbol` and returns its slot; throws std::invalid_argument if the name is empty or
  /// already declared (the message names the earlier kind).
  int Add(Symbol symbol);
  /// The slot of `name`, or nullopt.
  std::optional<int> Find(std::string_view name) const;
  const Symbol& operator[](int slot) const { return symbols_.at(slot); }
  int size() const { return static_cast<int>(symbols_.size()); }
  /// Slots of the given kind, in declaration order.
  std::vector<int> SlotsOfKind(SymbolKind kind) const;

  friend bool operator==(const SymbolTable& a, const SymbolTable& b) {
    return a.symbols_ == b.symbols_;
  }

 private:
  std::vector<Symbol> symbols_;
  std::unordered_map<std::string, int> index_;
};

}  // namespace hybrid
