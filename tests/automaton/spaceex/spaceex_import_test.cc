#include "hybrid/spaceex/spaceex_import.h"

#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "tests/test_utilities/command_line.h"

namespace hybrid::spaceex {
namespace {

using hybrid::testing::ReadAll;

std::string SpecFile(const std::string& name) {
  return ReadAll(std::string(HYBRID_SOURCE_DIR) + "/spec/spaceex/" + name);
}

Translation Translate(const std::string& xml, const std::string& cfg) {
  return TranslateSpaceEx(xml, "m.xml", cfg, "m.cfg");
}

std::string Error(const std::string& xml, const std::string& cfg) {
  try {
    (void)Translate(xml, cfg).Parse("m.xml");
  } catch (const ParseError& e) {
    return e.what();
  }
  return "no error";
}

// The verdict of exact reachability on the translation's property `forbidden`.
Verdict ForbiddenVerdict(const std::string& xml, const std::string& cfg) {
  const System system = Translate(xml, cfg).Parse("m.xml");
  const std::vector<Property> properties(system.properties().begin(), system.properties().end());
  const std::vector<CheckResult> results = PolyhedralReachability().Check(system, properties);
  EXPECT_EQ(results.size(), 1u);
  return results.at(0).verdict;
}

// A one-component model: parameters (name, dynamics), then locations and transitions as XML.
std::string Base(const std::string& params, const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<sspaceex>\n<component id=\"c\">\n" + params + body +
         "</component>\n</sspaceex>\n";
}
std::string Var(const std::string& name) {
  return "<param name=\"" + name + "\" type=\"real\" local=\"false\" dynamics=\"any\"/>\n";
}
std::string Const(const std::string& name) {
  return "<param name=\"" + name + "\" type=\"real\" local=\"false\" dynamics=\"const\"/>\n";
}

// Fischer's protocol guarantees mutual exclusion exactly when Delta > delta (the waiting time
// exceeds the longest write delay): the published analysis, an oracle written apart from the
// import. The SpaceEx model has delta = 1; Delta comes from the configuration.
TEST(SpaceExImportTest, FischerIsSafeExactlyWhenDeltaExceedsDelta) {
  const std::string xml = SpecFile("fischer_2.xml");
  for (const double big_delta : {0.5, 1.0, 1.5, 3.0}) {
    const std::string cfg =
        "system = \"fischer\"\ninitially = \"loc(P1)==idle & loc(P2)==idle & "
        "P1.x==0 & P2.x==0 & k==0 & delta==1 & Delta==" +
        std::to_string(big_delta) + "\"\nforbidden = \"loc(P1)==cs & loc(P2)==cs\"\n";
    EXPECT_EQ(ForbiddenVerdict(xml, cfg), big_delta > 1.0 ? Verdict::kProved : Verdict::kViolated)
        << "Delta = " << big_delta;
  }
}

// The water-level monitor's level stays in [1, 12] and reaches both ends (spec/benchmarks/
// water_tank.ha, with the arithmetic in its header). A forbidden set the level only touches
// (y >= 12) is `unknown`: no run meets it with a margin the simulator can confirm.
TEST(SpaceExImportTest, WaterTankLevelsAreExactlyOneToTwelve) {
  const std::string xml = SpecFile("water_tank.xml");
  auto cfg = [](const std::string& forbidden) {
    return "initially = \"loc()==on & y==1 & x==0 & delay==2 & high==10 & low==5\"\n"
           "forbidden = \"" +
           forbidden + "\"\n";
  };
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("y >= 12.01")), Verdict::kProved);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("y >= 11.9")), Verdict::kViolated);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("y <= 0.99")), Verdict::kProved);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("y <= 1.1 & loc(water_tank) == switching_on")),
            Verdict::kViolated);
  // The bundled configuration: the level never leaves [0.5, 12.5].
  EXPECT_EQ(ForbiddenVerdict(xml, SpecFile("water_tank.cfg")), Verdict::kProved);
}

// Rate bounds become a rectangular rate: with x' in [1, 2] and a clock t, x <= 2 t exactly.
TEST(SpaceExImportTest, RateBoundsBecomeRectangularRates) {
  const std::string xml =
      Base(Var("x") + Var("t"),
           "<location id=\"1\" name=\"go\"><invariant>t &lt;= 5</invariant>"
           "<flow>x' &gt;= 1 &amp; 2 &gt;= x' &amp; t' == 1</flow></location>\n");
  const std::string init = "initially = \"x == 0 & t == 0\"\n";
  EXPECT_NE(Translate(xml, init).text.find("x' in [1, 2];"), std::string::npos);
  EXPECT_EQ(ForbiddenVerdict(xml, init + "forbidden = \"x >= 2*t + 0.001\""), Verdict::kProved);
  EXPECT_EQ(ForbiddenVerdict(xml, init + "forbidden = \"x <= t - 0.001\""), Verdict::kProved);
  EXPECT_EQ(ForbiddenVerdict(xml, init + "forbidden = \"x >= 1.9*t & t >= 1\""),
            Verdict::kViolated);
}

TEST(SpaceExImportTest, InstancesWithDifferentConstantsGetAutomataOfTheirOwn) {
  const Translation t = Translate(SpecFile("fischer_2.xml"), SpecFile("fischer_2.cfg"));
  EXPECT_NE(t.text.find("automaton process_P1 {\n  param id = 1;"), std::string::npos);
  EXPECT_NE(t.text.find("automaton process_P2 {\n  param id = 2;"), std::string::npos);
  EXPECT_NE(t.text.find("instance P1 = process_P1 { k = k; delta = delta; Delta = Delta; }"),
            std::string::npos);
  // Both processes constrain k' == 0: the flow is given by P1 only, and the notes say so.
  EXPECT_EQ(t.notes.size(), 2u);
  const System system = t.Parse("m.xml");
  EXPECT_EQ(system.components().size(), 2u);
}

TEST(SpaceExImportTest, KeywordsAreRenamedAndTheTranslationParses) {
  const std::string xml =
      Base(Var("input") + Const("mode"),
           "<location id=\"1\" name=\"in\"><invariant>input &lt;= mode</invariant>"
           "<flow>input' == 1</flow></location>\n");
  const Translation t = Translate(xml,
                                  "initially = \"input == 0 & mode == 3\"\n"
                                  "forbidden = \"input >= mode & loc() == in\"\n");
  EXPECT_NE(t.text.find("param mode_ = 3;"), std::string::npos);
  EXPECT_NE(t.text.find("inv input_ <= mode_;"), std::string::npos);
  EXPECT_NE(t.text.find("property forbidden: never input_ >= mode_ and in in_;"),
            std::string::npos);
  EXPECT_NO_THROW(t.Parse("m.xml"));
}

TEST(SpaceExImportTest, ConfigurationErrorsNameTheConfigurationFile) {
  const std::string xml = SpecFile("water_tank.xml");
  const std::string init = "initially = \"loc()==on & y==1 & x==0 & delay==2 & high==10 & low==5\"";
  EXPECT_EQ(Error(xml, "initially = \"y == 1 & z == 0\"\n"),
            "m.cfg:1:23: undefined name 'z' in 'initially'");
  EXPECT_EQ(Error(xml, init + "\nforbidden = \"level >= 3\""),
            "m.cfg:2:14: undefined name 'level' in 'forbidden'");
  EXPECT_EQ(Error(xml, "initially = \"loc()==full & y == 1\""),
            "m.cfg:1:21: 'water_tank' has no location 'full'");
  EXPECT_EQ(Error(xml, "initially = \"y == 1 | y == 2\""),
            "m.cfg:1:14: '|' in 'initially' is not supported: give one initial set (a "
            "conjunction)");
  EXPECT_EQ(Error(xml, "initially = \"y + x <= 1\""),
            "m.cfg:1:14: only bounds of single variables are supported in 'initially' (x == c, "
            "x >= c, x <= c)");
  EXPECT_EQ(Error(xml, "initially = \"y == 1 & x == 0 & delay == 2 & high == 10\""),
            "m.xml:11:5: constant 'low' has no value: map it to a number in the bind, or give it "
            "one in 'initially' (low == 2, or 1 <= low & low <= 2)");
  EXPECT_EQ(Error(xml, "system = \"tank\""), "m.cfg:1:11: no component 'tank' in m.xml");
  EXPECT_EQ(Error(xml, "initially = \"y == \n 1 &\""), "m.cfg:2:5: expected an expression");
  EXPECT_EQ(Error(xml, "initially = \"y == \n 1 &"), "m.cfg:1:13: unterminated '\"'");
}

TEST(SpaceExImportTest, UnsupportedModelsAreReportedWhereTheyAre) {
  const std::string cfg = "initially = \"x == 0\"\n";
  // A location without the flow of a variable its component drives elsewhere.
  EXPECT_EQ(Error(Base(Var("x"),
                       "<location id=\"1\" name=\"a\"><flow>x' == 1</flow></location>\n"
                       "<location id=\"2\" name=\"b\"/>\n"),
                  cfg),
            "m.xml:6:1: location 'b' gives no flow for 'x', which SpaceEx leaves free to change "
            "there (add x' == 0 to keep it constant)");
  EXPECT_EQ(Error(Base(Var("x"),
                       "<location id=\"1\" name=\"a\"><invariant>x &lt;= 1</invariant>"
                       "</location>\n"),
                  cfg),
            "m.xml:4:1: no component gives 'x' a flow: SpaceEx lets it change arbitrarily, which "
            "the import does not support (add x' == 0 to the flows of one component to keep it "
            "constant)");
  EXPECT_EQ(
      Error(Base(Var("x"), "<location id=\"1\" name=\"a\"><flow>x' == y</flow></location>\n"), cfg),
      "m.xml:5:39: undefined name 'y' (not a parameter of component 'c')");
  EXPECT_EQ(
      Error(Base(Var("x"), "<location id=\"1\" name=\"a\"><flow>x' &gt;= 1</flow></location>\n"),
            cfg),
      "m.xml:5:33: rate of 'x' needs both bounds (x' >= a & x' <= b)");
  EXPECT_EQ(Error(Base(Var("x"),
                       "<location id=\"1\" name=\"a\"><flow>x' == 1</flow></location>\n"
                       "<transition source=\"1\" target=\"1\"><guard>x &lt;= 0 | x &gt;= 2"
                       "</guard></transition>\n"),
                  cfg),
            "m.xml:6:42: '|' is not supported in guards: split the transition");
  EXPECT_EQ(Error(Base(Var("x"),
                       "<location id=\"1\" name=\"a\"><flow>x' == 1</flow></location>\n"
                       "<transition source=\"1\" target=\"7\"/>\n"),
                  cfg),
            "m.xml:6:1: no location with id '7' in 'c'");
  EXPECT_EQ(Error(Base(Var("x-1"), ""), cfg),
            "m.xml:4:1: parameter 'x-1' is not a name of the model language (letters, digits and "
            "'_', not starting with a digit)");
}

TEST(SpaceExImportTest, NetworkErrorsPointAtTheBind) {
  const std::string tank = "<component id=\"t\">" + Var("x") + Var("y") +
                           "<location id=\"1\" name=\"a\"><flow>x' == 1 &amp; y' == 0</flow>"
                           "</location></component>\n";
  auto network = [&](const std::string& binds) {
    return "<?xml version=\"1.0\"?>\n<sspaceex>\n" + tank + "<component id=\"n\">" + Var("k") +
           Var("j") + "\n" + binds + "</component>\n</sspaceex>\n";
  };
  EXPECT_EQ(Error(network("<bind component=\"nope\" as=\"A\"/>"), ""),
            "m.xml:9:1: bind 'A' of unknown component 'nope'");
  EXPECT_EQ(Error(network("<bind component=\"n\" as=\"A\"/>"), ""),
            "m.xml:9:1: component 'n' is a network: nested networks are not supported");
  EXPECT_EQ(Error(network("<bind component=\"t\" as=\"A\"><map key=\"x\">k</map></bind>"), ""),
            "m.xml:9:1: bind 'A' does not map 'y' of component 't'");
  EXPECT_EQ(Error(network("<bind component=\"t\" as=\"A\"><map key=\"x\">k</map>"
                          "<map key=\"y\">q</map></bind>"),
                  ""),
            "m.xml:9:61: undefined name 'q' (not a parameter of 'n')");
  EXPECT_EQ(Error(network("<bind component=\"t\" as=\"A\"><map key=\"x\">k</map>"
                          "<map key=\"y\">k</map></bind>"),
                  ""),
            "m.xml:9:48: 'x' and 'y' of 'A' are both mapped to 'k'");
  // Two instances driving one variable.
  EXPECT_EQ(Error(network("<bind component=\"t\" as=\"A\"><map key=\"x\">k</map>"
                          "<map key=\"y\">j</map></bind>\n"
                          "<bind component=\"t\" as=\"B\"><map key=\"x\">k</map>"
                          "<map key=\"y\">j</map></bind>"),
                  ""),
            "m.xml:5:33: 'k' is given a flow by 'A' and by 'B': the import supports one component "
            "per variable (or x' == 0 in all)");
}

// `asap="1"` (and TRUE, True) is urgent like `asap="true"`: it used to be read as false, which
// made the transition lazy.
TEST(SpaceExImportTest, AsapWrittenOneIsUrgent) {
  auto lazy_count = [](const std::string& asap) {
    const std::string xml = Base(Var("x"),
                                 "<location id=\"1\" name=\"a\"><flow>x' == 1</flow></location>\n"
                                 "<transition source=\"1\" target=\"1\" asap=\"" +
                                     asap + "\"><guard>x &gt;= 1</guard></transition>\n");
    const std::string text = Translate(xml, "initially = \"x == 0\"\n").text;
    std::size_t count = 0;
    for (std::size_t at = text.find("lazy;"); at != std::string::npos;
         at = text.find("lazy;", at + 1))
      ++count;
    return count;
  };
  for (const char* urgent : {"true", "1", "TRUE", "True"})
    EXPECT_EQ(lazy_count(urgent), 0u) << urgent;
  for (const char* lazy : {"false", "0", "FALSE"}) EXPECT_EQ(lazy_count(lazy), 1u) << lazy;
}

// A constant read only by `forbidden` is declared by its component and takes its value from
// `initially` (it used to be left out, and the property then read an undefined name).
TEST(SpaceExImportTest, ConstantReadOnlyInForbiddenIsDeclared) {
  const std::string xml = Base(Var("x") + Const("limit"),
                               "<location id=\"1\" name=\"a\"><invariant>x &lt;= 3</invariant>"
                               "<flow>x' == 1</flow></location>\n");
  auto cfg = [](const std::string& limit) {
    return "initially = \"x == 0 & limit == " + limit + "\"\nforbidden = \"x >= limit\"\n";
  };
  EXPECT_NE(Translate(xml, cfg("2")).text.find("param limit = 2;"), std::string::npos);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("2")), Verdict::kViolated);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("4")), Verdict::kProved);
}

// The same in a network: a constant of the network that its instance declares but does not
// read, and one that no component declares (its value from `initially` is then written in the
// property); a range for the latter has no place to go and is an error at the name.
TEST(SpaceExImportTest, NetworkConstantReadOnlyInForbiddenResolves) {
  const std::string xml =
      "<?xml version=\"1.0\"?>\n<sspaceex>\n<component id=\"t\">" + Var("x") + Const("c") +
      "<location id=\"1\" name=\"a\"><invariant>x &lt;= 3</invariant><flow>x' == 1</flow>"
      "</location></component>\n<component id=\"n\">" +
      Var("x") + Const("c") + Const("d") +
      "<bind component=\"t\" as=\"A\"/></component>\n</sspaceex>\n";
  auto cfg = [](const std::string& values, const std::string& forbidden) {
    return "initially = \"x == 0 & " + values + "\"\nforbidden = \"" + forbidden + "\"\n";
  };
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("c == 2 & d == 9", "x >= c")), Verdict::kViolated);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("c == 4 & d == 9", "x >= c")), Verdict::kProved);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("c == 4 & d == 2", "x >= d")), Verdict::kViolated);
  EXPECT_EQ(ForbiddenVerdict(xml, cfg("c == 4 & d == 5", "x >= d")), Verdict::kProved);
  EXPECT_EQ(Error(xml, cfg("c == 4 & 1 <= d & d <= 2", "x >= d")),
            "m.cfg:2:19: constant 'd' read in 'forbidden' is declared by no component: give it "
            "one value in 'initially' (d == 2), or map it into a component");
}

// Without a configuration the model has no initial states: the error names the file looked for
// (after the errors of the model itself).
TEST(SpaceExImportTest, MissingConfigurationNamesTheFileLookedFor) {
  hybrid::testing::TempDir dir;
  const std::string xml = dir.Write("tank.xml", SpecFile("water_tank.xml")).string();
  for (const auto& read : {std::function<void()>([&] { (void)ImportSpaceExFile(xml); }),
                           std::function<void()>([&] { (void)ReadModelFile(xml); })}) {
    try {
      read();
      ADD_FAILURE() << "no error";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), dir.File("tank.cfg"));
      EXPECT_EQ(e.line(), 0);
      EXPECT_EQ(e.message(), "missing: the SpaceEx model " + xml +
                                 " needs its configuration (initial states, forbidden set) in "
                                 "this file");
    }
  }
  const std::string broken = dir.Write("broken.xml", "<sspaceex>\n<component>\n").string();
  try {
    (void)ImportSpaceExFile(broken);
    ADD_FAILURE() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), broken);
    EXPECT_EQ(e.message().rfind("malformed XML: ", 0), 0u) << e.what();
  }
}

// Names and option values with control characters (written as character references in XML)
// are quoted escaped, in errors and in notes, and cannot break the translation's lines.
TEST(SpaceExImportTest, ControlCharactersInNamesAndOptionsAreEscaped) {
  EXPECT_EQ(Error(Base(Var("x&#27;[2J"), ""), ""),
            "m.xml:4:1: parameter 'x\\x1b[2J' is not a name of the model language (letters, "
            "digits and '_', not starting with a digit)");
  const std::string tank = SpecFile("water_tank.xml");
  const std::string init =
      "initially = \"loc()==on & y==1 & x==0 & delay==2 & high==10 & low==5\"\n";
  EXPECT_EQ(Error(tank, init + "time-horizon = \"1\x1b[2J\nautomaton injected { }\"\n"),
            "m.cfg:2:17: time-horizon: '1\\x1b[2J\\nautomaton injected { }' is not a decimal "
            "number: give the time the analysis covers as a positive number (negative: no bound)");
}

// The configuration's time-horizon bounds both the default run and the property, as SpaceEx's
// analysis stops there. The oracle is the water tank's arithmetic: from y = 1 the level rises at
// 1 cm/s until y = high = 10, so y(t) = 1 + t for t <= 9: y reaches 7 at t = 6 and never within
// 5 (y(5) = 6), while over unbounded time it reaches 12.
TEST(SpaceExImportTest, TimeHorizonBoundsTheDefaultRunAndForbidden) {
  const std::string tank = SpecFile("water_tank.xml");
  const std::string cfg =
      "initially = \"loc()==on & y==1 & x==0 & delay==2 & high==10 & low==5\"\n"
      "forbidden = \"y >= 7\"\n";
  const Translation bounded = Translate(tank, cfg + "time-horizon = 5\n");
  const System system = bounded.Parse("m.xml");
  ASSERT_TRUE(system.scenario().has_value());
  EXPECT_EQ(system.scenario()->until, 5.0);
  ASSERT_EQ(system.properties().size(), 1u);
  EXPECT_EQ(system.properties()[0].horizon, std::optional<double>(5.0));
  EXPECT_EQ(bounded.notes.at(0),
            "time-horizon = 5 is the horizon of the default run (until 5) and of 'forbidden' "
            "(within 5).");
  EXPECT_EQ(ForbiddenVerdict(tank, cfg + "time-horizon = 5\n"), Verdict::kProved);
  EXPECT_EQ(ForbiddenVerdict(tank, cfg + "time-horizon = 6.5\n"), Verdict::kViolated);
  // No time-horizon, or a negative one (SpaceEx's -1): no bound, no default run.
  for (const std::string& none : {std::string(), std::string("time-horizon = -1\n")}) {
    const System unbounded = Translate(tank, cfg + none).Parse("m.xml");
    EXPECT_FALSE(unbounded.scenario().has_value()) << none;
    EXPECT_EQ(unbounded.properties()[0].horizon, std::nullopt) << none;
    EXPECT_EQ(ForbiddenVerdict(tank, cfg + none), Verdict::kViolated) << none;
  }
  // In a network, the scenario is the system's.
  const System fischer =
      Translate(SpecFile("fischer_2.xml"), SpecFile("fischer_2.cfg")).Parse("m.xml");
  ASSERT_TRUE(fischer.scenario().has_value());
  EXPECT_EQ(fischer.properties()[0].horizon, std::optional<double>(fischer.scenario()->until));
  EXPECT_EQ(Error(tank, cfg + "time-horizon = 0\n"),
            "m.cfg:3:16: time-horizon: '0' is zero: give the time the analysis covers as a "
            "positive number (negative: no bound)");
  EXPECT_EQ(Error(tank, cfg + "time-horizon = 1e999\n"),
            "m.cfg:3:16: time-horizon: '1e999' is out of range (beyond the largest double, about "
            "1.8e308): give the time the analysis covers as a positive number (negative: no "
            "bound)");
}

// In SpaceEx a label is in the alphabet of every component that declares it: a component that
// declares `l` but has no transition labelled `l` blocks the `l` transitions of the others. The
// translation declares it (`label l;`, Automaton::DeclareLabel); it used to drop it, and B's `l`
// transition was then taken alone (`violated`). A local label is no one else's: not declared.
TEST(SpaceExImportTest, DeclaredButUnusedLabelBlocksOtherComponents) {
  const std::string label = "<param name=\"l\" type=\"label\" local=\"false\"/>\n";
  const std::string xml =
      "<?xml version=\"1.0\"?>\n<sspaceex>\n<component id=\"a\">" + label +
      "<location id=\"1\" name=\"idle\"/></component>\n<component id=\"b\">" + Var("x") + label +
      "<location id=\"1\" name=\"p\"><flow>x' == 1</flow></location>"
      "<location id=\"2\" name=\"q\"><flow>x' == 1</flow></location>"
      "<transition source=\"1\" target=\"2\"><label>l</label></transition></component>\n"
      "<component id=\"n\">" +
      Var("x") + label +
      "<bind component=\"a\" as=\"A\"/><bind component=\"b\" as=\"B\"/></component>\n"
      "</sspaceex>\n";
  const std::string cfg = "initially = \"loc(B) == p & x == 0\"\nforbidden = \"loc(B) == q\"\n";
  EXPECT_EQ(ForbiddenVerdict(xml, cfg), Verdict::kProved);
  const std::string text = Translate(xml, cfg).text;
  EXPECT_NE(text.find("automaton a {\n  mode idle {\n  }\n  label l;\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("instance A = a { l = l; }"), std::string::npos) << text;
  // Local to A, the label blocks nothing.
  std::string local = xml;
  local.replace(local.find("local=\"false\""), 13, "local=\"true\"");
  EXPECT_EQ(Translate(local, cfg).text.find("\n  label l;"), std::string::npos);
  EXPECT_EQ(ForbiddenVerdict(local, cfg), Verdict::kViolated);
}

TEST(SpaceExImportTest, ReadModelFileReadsBothLanguages) {
  const System imported =
      ReadModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/spaceex/fischer_2.xml");
  EXPECT_EQ(imported.properties().size(), 1u);
  // Another configuration in place of the one beside the model; none for a model-language file.
  const std::string tank = std::string(HYBRID_SOURCE_DIR) + "/spec/spaceex/water_tank.xml";
  const std::string fischer_cfg = std::string(HYBRID_SOURCE_DIR) + "/spec/spaceex/fischer_2.cfg";
  try {  // fischer_2.cfg chooses `system = "fischer"`, which water_tank.xml has not
    (void)ReadModelFile(tank, fischer_cfg);
    ADD_FAILURE() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), fischer_cfg);
    EXPECT_EQ(e.message(), "no component 'fischer' in " + tank);
  }
  EXPECT_THROW(
      (void)ReadModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/thermostat.ha", fischer_cfg),
      std::invalid_argument);
  EXPECT_TRUE(IsSpaceExFile("a/b.XML"));
  EXPECT_FALSE(IsSpaceExFile("a/b.ha"));
  try {
    (void)ReadModelFile("/nonexistent/m.xml");
    ADD_FAILURE() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 0);
  }
}

}  // namespace
}  // namespace hybrid::spaceex
