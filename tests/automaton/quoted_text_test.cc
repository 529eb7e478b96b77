// Tests of EscapedForMessage and QuotedForMessage (automaton/quoted_text.h): what a message may
// quote of its input.
#include "automaton/quoted_text.h"

#include <gtest/gtest.h>

#include <string>

namespace hybrid {
namespace {

TEST(QuotedText, ControlCharactersBecomeEscapes) {
  EXPECT_EQ(EscapedForMessage("a\x1b[2Jb"), "a\\x1b[2Jb");
  EXPECT_EQ(EscapedForMessage("line\nnext\r\tend"), "line\\nnext\\r\\tend");
  EXPECT_EQ(EscapedForMessage(std::string("nul\0", 4)), "nul\\x00");
  EXPECT_EQ(EscapedForMessage("\x7f\x01\x1f"), "\\x7f\\x01\\x1f");
}

TEST(QuotedText, PrintableTextIsUnchanged) {
  const std::string printable = "theta1 >= 0.5 & x' == 1 (C:\\dir\\m.xml) \"q\" 'a'";
  EXPECT_EQ(EscapedForMessage(printable), printable);
  EXPECT_EQ(EscapedForMessage(""), "");
  // Well-formed UTF-8 is kept: degree sign, theta, an emoji (four bytes).
  EXPECT_EQ(EscapedForMessage("25 \xc2\xb0, \xce\xb8, \xf0\x9f\x99\x82"),
            "25 \xc2\xb0, \xce\xb8, \xf0\x9f\x99\x82");
}

TEST(QuotedText, MalformedUtf8AndC1ControlsAreEscaped) {
  // A lone continuation byte, a truncated sequence, an overlong '/', a surrogate, and a Latin-1
  // degree sign: bytes, each \xHH.
  EXPECT_EQ(EscapedForMessage("\x80"), "\\x80");
  EXPECT_EQ(EscapedForMessage("\xe2\x82"), "\\xe2\\x82");
  EXPECT_EQ(EscapedForMessage("\xc0\xaf"), "\\xc0\\xaf");
  EXPECT_EQ(EscapedForMessage("\xed\xa0\x80"), "\\xed\\xa0\\x80");
  EXPECT_EQ(EscapedForMessage("25\xb0"), "25\\xb0");
  // CSI (U+009B), which some terminals take for ESC [.
  EXPECT_EQ(EscapedForMessage("a\xc2\x9b"
                              "2Jb"),
            "a\\u009b2Jb");
  EXPECT_EQ(EscapedForMessage("\xc2\x80"), "\\u0080");
}

TEST(QuotedText, EscapingIsIdempotent) {
  for (const std::string text : {"a\x1b[31mred", "x\ny\tz", "\xc2\x9b\xff", "plain"}) {
    const std::string once = EscapedForMessage(text);
    EXPECT_EQ(EscapedForMessage(once), once) << once;
    for (const char c : once) {
      const auto byte = static_cast<unsigned char>(c);
      EXPECT_TRUE(byte >= 0x20 && byte != 0x7f) << once;
    }
  }
}

TEST(QuotedText, QuotedForMessageAddsSingleQuotes) {
  EXPECT_EQ(QuotedForMessage("run\x1b"), "'run\\x1b'");
  EXPECT_EQ(QuotedForMessage(""), "''");
}

}  // namespace
}  // namespace hybrid
