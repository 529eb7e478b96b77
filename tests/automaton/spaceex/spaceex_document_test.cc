#include "automaton/spaceex/spaceex_document.h"

#include <gtest/gtest.h>

#include <string>

#include "hybrid/automaton/parser.h"

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

// `asap`, `local` and `controlled` are booleans written true/false or 1/0, in any case (SpaceEx
// files in the wild use all of these); `asap="1"` and `local="TRUE"` used to be read as false.
TEST(SpaceExDocumentTest, BooleanAttributesAreTrueFalseOneOrZeroInAnyCase) {
  for (const char* yes : {"true", "TRUE", "True", "1"}) {
    for (const char* no : {"false", "FALSE", "False", "0"}) {
      const std::string xml =
          std::string(kHead) + "<component id=\"c\">" +
          "<param name=\"l\" type=\"label\" local=\"" + yes + "\" controlled=\"" + yes + "\"/>" +
          "<param name=\"m\" type=\"label\" local=\"" + no + "\"/>" +
          "<transition source=\"1\" target=\"1\" asap=\"" + yes + "\"/>" +
          "<transition source=\"1\" target=\"1\" asap=\"" + no + "\"/>" + "</component></sspaceex>";
      const SpaceExDocument doc(xml, "m.xml");
      const SxComponent& c = doc.components().at(0);
      EXPECT_TRUE(c.params.at(0).local) << yes;
      EXPECT_FALSE(c.params.at(1).local) << no;
      EXPECT_TRUE(c.transitions.at(0).asap) << yes;
      EXPECT_FALSE(c.transitions.at(1).asap) << no;
    }
  }
}

TEST(SpaceExDocumentTest, OtherBooleanValuesAreErrorsAtTheValue) {
  const std::string head = std::string(kHead) + "<component id=\"c\">";
  EXPECT_EQ(Error(head + "<transition source=\"1\" target=\"1\" asap=\"yes\"/></component>"
                         "</sspaceex>"),
            "m.xml:3:59: attribute 'asap' of <transition> must be true or false (or 1 or 0), "
            "not 'yes'");
  EXPECT_EQ(Error(head + "<param name=\"x\" type=\"real\" local=\"\"/></component></sspaceex>"),
            "m.xml:3:54: attribute 'local' of <param> must be true or false (or 1 or 0), not ''");
  // An uncontrolled variable may change at the component's jumps: refused, not ignored.
  EXPECT_EQ(Error(head + "<param name=\"x\" type=\"real\" controlled=\"0\"/></component>"
                         "</sspaceex>"),
            "m.xml:3:59: controlled=\"false\" is not supported: parameters are controlled by their "
            "component");
}

// An attribute SpaceEx does not give an element is refused at its name: a misspelt `dynamics`
// would otherwise make a constant a variable unseen. Layout attributes are known.
TEST(SpaceExDocumentTest, UnknownAttributesAreErrorsAtTheirName) {
  const std::string head = std::string(kHead) + "<component id=\"c\">";
  EXPECT_EQ(Error(head + "<param name=\"a\" type=\"real\" dynamic=\"const\"/></component>"
                         "</sspaceex>"),
            "m.xml:3:47: unknown attribute 'dynamic' of <param> (known: name, type, local, d1, "
            "d2, dynamics, controlled)");
  EXPECT_EQ(Error(head + "<transition source=\"1\" target=\"1\" urgent=\"true\"/></component>"
                         "</sspaceex>"),
            "m.xml:3:53: unknown attribute 'urgent' of <transition> (known: source, target, asap, "
            "timedriven, priority, bezier)");
  EXPECT_EQ(Error(head + "<location id=\"1\"><flow\n type=\"x\">x' == 1</flow></location>"
                         "</component></sspaceex>"),
            "m.xml:4:2: unknown attribute 'type' of <flow> (it takes none)");
  EXPECT_EQ(Error("<sspaceex version=\"0.2\" lang=\"x\"><component id=\"c\"/></sspaceex>"),
            "m.xml:1:25: unknown attribute 'lang' of <sspaceex> (known: xmlns, version, math)");
  EXPECT_EQ(Error(head + "</component><component id=\"n\"><bind component=\"c\" as=\"A\">"
                         "<map key=\"a\" value=\"1\">2</map></bind></component></sspaceex>"),
            "m.xml:3:89: unknown attribute 'value' of <map> (known: key)");
  // Namespaces, layout and notes are fine.
  EXPECT_EQ(Error("<sspaceex xmlns=\"http://www-verimag.imag.fr/xml-namespaces/sspaceex\" "
                  "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" version=\"0.2\" "
                  "math=\"SpaceEx\"><component id=\"c\"><note>any text</note>"
                  "<location id=\"1\" name=\"a\" x=\"1\" y=\"2\" width=\"3\" height=\"4\"/>"
                  "<transition source=\"1\" target=\"1\" bezier=\"true\"><labelposition "
                  "x=\"1\" y=\"2\" width=\"3\" height=\"4\"/><middlepoint x=\"1\" y=\"2\"/>"
                  "</transition></component></sspaceex>"),
            "no error");
}

// Names may hold any character through character references: what a message quotes of them
// is escaped.
TEST(SpaceExDocumentTest, ControlCharactersInNamesAreEscapedInMessages) {
  EXPECT_EQ(Error(std::string(kHead) + "<component id=\"c&#27;[2J\"/>\n"
                                       "<component id=\"c&#27;[2J\"/></sspaceex>"),
            "m.xml:4:16: duplicate component 'c\\x1b[2J'");
}

}  // namespace
}  // namespace hybrid::spaceex
