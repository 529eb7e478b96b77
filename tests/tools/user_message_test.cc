// Tests of the messages of the command line (tools/user_message.h): the C++ API prefixes of
// lower layers are removed, plain text is kept, and messages naming C++ internals are spotted.

#include "tools/user_message.h"

#include <gtest/gtest.h>

#include <string>

namespace hybrid::cli {
namespace {

TEST(UserMessage, RemovesQualifiedNamePrefixes) {
  EXPECT_EQ(UserMessage("System::SetParameter: no component has a parameter 'nope'"),
            "no component has a parameter 'nope'");
  EXPECT_EQ(UserMessage("Simulator::Run: the horizon must be positive and finite, got -1"),
            "the horizon must be positive and finite, got -1");
  EXPECT_EQ(UserMessage("--set x: System::SetParameter: no parameter"), "--set x: no parameter");
  EXPECT_EQ(UserMessage("hybrid::detail::Foo: bar"), "bar");
  EXPECT_EQ(UserMessage("Hand::ComposedAutomata: finger A: GeometricFinger: object overlaps"),
            "finger A: object overlaps");
}

TEST(UserMessage, RemovesClassPrefixesAtTheStartOfASegment) {
  EXPECT_EQ(UserMessage("Hand: finger A: GeometricFinger: object 1 overlaps the palm"),
            "finger A: object 1 overlaps the palm");
  EXPECT_EQ(UserMessage("Obstacle: a circle needs a finite centre"),
            "a circle needs a finite centre");
  EXPECT_EQ(UserMessage("Synthesize: free_runs is negative"), "free_runs is negative");
  // Not at the start of a segment: kept.
  EXPECT_EQ(UserMessage("the Hand: model"), "the Hand: model");
}

TEST(UserMessage, KeepsPlainMessages) {
  for (const std::string plain :
       {"--g must be a motor position in [0, 255] (got 300)", "m.ha:3:7: expected ';'",
        "a::b is not a name: x", "times 1:2 and 3::4", ""}) {
    EXPECT_EQ(UserMessage(plain), plain);
  }
}

TEST(NamesCppInternals, SpotsTypeAndFunctionNames) {
  for (const std::string internal :
       {"std::bad_alloc", "vector::_M_realloc_insert", "basic_string::_M_create", "map::at",
        "bad_optional_access", "[json.exception.type_error.302] type must be number", ""}) {
    EXPECT_TRUE(NamesCppInternals(internal)) << internal;
  }
  for (const std::string plain : {"cannot write 'x.csv'", "the solver failed at t = 3"}) {
    EXPECT_FALSE(NamesCppInternals(plain)) << plain;
  }
}

}  // namespace
}  // namespace hybrid::cli
