#include "hybrid/automaton/symbol_table.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace hybrid {
namespace {

TEST(SymbolTableTest, SlotsAreDeclarationOrder) {
  SymbolTable t;
  EXPECT_EQ(t.Add({"x", SymbolKind::kVariable, "m"}), 0);
  EXPECT_EQ(t.Add({"u", SymbolKind::kInput, ""}), 1);
  EXPECT_EQ(t.Add({"k", SymbolKind::kParameter, ""}), 2);
  EXPECT_EQ(t.size(), 3);
  EXPECT_EQ(t.Find("u"), 1);
  EXPECT_FALSE(t.Find("nope").has_value());
  EXPECT_EQ(t[0].unit, "m");
  EXPECT_EQ(t.SlotsOfKind(SymbolKind::kInput), std::vector<int>{1});
}

TEST(SymbolTableTest, RejectsDuplicatesAndEmptyNames) {
  SymbolTable t;
  t.Add({"x", SymbolKind::kVariable, ""});
  EXPECT_THROW(t.Add({"x", SymbolKind::kParameter, ""}), std::invalid_argument);
  EXPECT_THROW(t.Add({"", SymbolKind::kParameter, ""}), std::invalid_argument);
  EXPECT_EQ(t.size(), 1);
}

TEST(SymbolTableTest, KindNames) {
  EXPECT_EQ(KindName(SymbolKind::kDiscrete), "discrete variable");
  EXPECT_EQ(KindName(SymbolKind::kParameter), "parameter");
}

}  // namespace
}  // namespace hybrid
