#include "hybrid/automaton/symbol_table.h"

#include <stdexcept>

namespace hybrid {

std::string_view KindName(SymbolKind kind) {
  switch (kind) {
    case SymbolKind::kVariable:
      return "variable";
    case SymbolKind::kDiscrete:
      return "discrete variable";
    case SymbolKind::kInput:
      return "input";
    case SymbolKind::kParameter:
      return "parameter";
  }
  return "symbol";
}

int SymbolTable::Add(Symbol symbol) {
  if (symbol.name.empty()) throw std::invalid_argument("empty name");
  if (auto it = index_.find(symbol.name); it != index_.end()) {
    throw std::invalid_argument("duplicate name '" + symbol.name + "' (already declared as " +
                                std::string(KindName(symbols_[it->second].kind)) + ")");
  }
  const int slot = size();
  index_.emplace(symbol.name, slot);
  symbols_.push_back(std::move(symbol));
  return slot;
}

std::optional<int> SymbolTable::Find(std::string_view name) const {
  auto it = index_.find(std::string(name));
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

std::vector<int> SymbolTable::SlotsOfKind(SymbolKind kind) const {
  std::vector<int> slots;
  for (int i = 0; i < size(); ++i) {
    if (symbols_[i].kind == kind) slots.push_back(i);
  }
  return slots;
}

}  // namespace hybrid
