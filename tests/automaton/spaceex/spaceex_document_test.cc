#include "automaton/spaceex/spaceex_document.h"

#include <gtest/gtest.h>

#include <string>

#include "automaton/parser.h"

namespace hybrid::spaceex {
namespace {

std::string Error(const std::string& xml) {
  try {
    SpaceExDocument(xml, "m.xml");
  } catch (const ParseError& e) {
    return e.what();
  }
  return "no error";
}

const char* const kHead = "<?xml version=\"1.0\"?>\n<sspaceex>\n";

TEST(SpaceExDocumentTest, ReadsComponentsWithTheirParts) {
  const std::string xml =
      std::string(kHead) +
      "<component id=\"c\">\n"
      "  <param name=\"x\" type=\"real\" local=\"false\" d1=\"1\" d2=\"1\" dynamics=\"any\"/>\n"
      "  <param name=\"a\" type=\"real\" dynamics=\"const\"/>\n"
      "  <param name=\"go\" type=\"label\" local=\"true\"/>\n"
      "  <location id=\"1\" name=\"on\"><invariant>x &lt;= a</invariant>"
      "<flow>x' == 1</flow></location>\n"
      "  <transition source=\"1\" target=\"1\" asap=\"true\"><label>go</label>"
      "<guard>x &gt;= 1</guard><assignment>x := 0</assignment>"
      "<labelposition x=\"1\" y=\"2\"/></transition>\n"
      "</component>\n"
      "<component id=\"n\"><bind component=\"c\" as=\"A\"><map "
      "key=\"a\">2</map></bind></component>\n"
      "</sspaceex>\n";
  const SpaceExDocument doc(xml, "m.xml");
  ASSERT_EQ(doc.components().size(), 2u);
  const SxComponent& c = doc.components()[0];
  ASSERT_EQ(c.params.size(), 3u);
  EXPECT_EQ(c.params[1].type, SxParam::Type::kConstant);
  EXPECT_TRUE(c.params[2].local);
  EXPECT_EQ(c.locations[0].invariant->value, "x <= a");
  EXPECT_TRUE(c.transitions[0].asap);
  EXPECT_EQ(c.transitions[0].guard->value, "x >= 1");
  EXPECT_TRUE(doc.components()[1].IsNetwork());
  EXPECT_EQ(doc.components()[1].binds[0].maps[0].value.value, "2");
  EXPECT_EQ(doc.LineColumn(c.offset), std::make_pair(3, 1));
}

TEST(SpaceExDocumentTest, OffsetsOfTextCountEntitiesAsOneCharacter) {
  const std::string xml =
      std::string(kHead) +
      "<component id=\"c\"><location id=\"1\"><flow>a &amp;&amp; b' == 1</flow></location>"
      "</component></sspaceex>";
  const SpaceExDocument doc(xml, "m.xml");
  const SxText& flow = *doc.components()[0].locations[0].flow;
  EXPECT_EQ(flow.value, "a && b' == 1");
  // Character 5 of the text ('b') is after two 5-byte entities: column 70 of line 3.
  EXPECT_EQ(xml.substr(doc.OffsetOf(flow, 5), 1), "b");
  EXPECT_EQ(doc.LineColumn(doc.OffsetOf(flow, 5)).first, 3);
}

TEST(SpaceExDocumentTest, BadDocumentsAreReportedWithLineAndColumn) {
  EXPECT_EQ(Error("<sspaceex>\n<component id=\"c\">\n</sspaceex>"),
            "m.xml:3:3: malformed XML: Start-end tags mismatch");
  EXPECT_EQ(Error("<model/>"),
            "m.xml:1:1: not a SpaceEx model: the root element is <model>, "
            "expected <sspaceex>");
  EXPECT_EQ(Error(std::string(kHead) + "</sspaceex>"), "m.xml:2:1: the model has no <component>");
  EXPECT_EQ(Error(std::string(kHead) + "<component id=\"c\"><foo/></component></sspaceex>"),
            "m.xml:3:19: unsupported element <foo> in <component>");
  EXPECT_EQ(Error(std::string(kHead) + "<component><param/></component></sspaceex>"),
            "m.xml:3:1: <component> needs the attribute 'id'");
  EXPECT_EQ(Error(std::string(kHead) +
                  "<component id=\"c\"><param name=\"M\" type=\"real\" d1=\"2\"/></component>"
                  "</sspaceex>"),
            "m.xml:3:51: matrix parameters are not supported (d1 must be 1)");
  EXPECT_EQ(Error(std::string(kHead) + "<component id=\"c\"/>\n<component id=\"c\"/></sspaceex>"),
            "m.xml:4:16: duplicate component 'c'");
  EXPECT_EQ(Error(std::string(kHead) +
                  "<component id=\"c\"><transition source=\"1\" target=\"1\" priority=\"2\"/>"
                  "</component></sspaceex>"),
            "m.xml:3:63: transition attribute 'priority' is not supported");
}

}  // namespace
}  // namespace hybrid::spaceex
