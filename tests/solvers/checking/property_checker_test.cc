// Tests of the checking layer (include/hybrid/checking/property_checker.h): the registry makes
// checkers by name and names the methods in its errors; a fallback asks each later checker only
// what the earlier ones left unknown, and skips checkers that do not apply. The checkers here are
// scripted fakes (a verdict per property name), so what is tested is the layer's bookkeeping alone.

#include "hybrid/checking/property_checker.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace hybrid {
namespace {

// A checker that gives each property the verdict its script names (unknown otherwise) and
// records what it was asked.
class ScriptedChecker : public PropertyChecker {
 public:
  ScriptedChecker(std::string name, std::map<std::string, Verdict> script, bool handles = true)
      : name_(std::move(name)), script_(std::move(script)), handles_(handles) {}
  std::string_view name() const override { return name_; }
  bool Handles(const System&, std::span<const Property>, std::string* why) const override {
    if (!handles_ && why) *why = "not my kind of model";
    return handles_;
  }
  bool Falsifies() const override { return falsifies_; }
  std::vector<CheckResult> Check(const System&, std::span<const Property> properties) override {
    std::vector<CheckResult> out;
    for (const Property& p : properties) {
      asked->push_back(name_ + ":" + p.name);
      CheckResult r;
      r.property = p.name;
      r.kind = p.kind;
      r.method = name_;
      r.seconds = 1.0;
      const auto it = script_.find(p.name);
      r.verdict = it == script_.end() ? Verdict::kUnknown : it->second;
      if (const auto w = within_.find(p.name); w != within_.end()) r.within = w->second;
      r.states_met = met_.count(p.name) > 0;
      r.reason = name_ + " says so";
      out.push_back(r);
    }
    return out;
  }
  std::shared_ptr<std::vector<std::string>> asked = std::make_shared<std::vector<std::string>>();
  /// Properties whose verdict covers the runs up to a time only (CheckResult::within).
  std::map<std::string, double> within_;
  /// Properties whose reachable states it found to meet their bad states (states_met).
  std::set<std::string> met_;
  bool falsifies_ = true;

 private:
  std::string name_;
  std::map<std::string, Verdict> script_;
  bool handles_;
};

// The fallback "auto" over `checkers`, in order.
template <class... Checkers>
FallbackChecker Auto(std::unique_ptr<Checkers>... checkers) {
  std::vector<std::unique_ptr<PropertyChecker>> all;
  (all.push_back(std::move(checkers)), ...);
  return FallbackChecker("auto", std::move(all));
}

std::vector<Property> Named(const std::vector<std::string>& names) {
  std::vector<Property> out;
  for (const std::string& n : names) out.push_back({n, Property::Kind::kAlways, Predicate::True()});
  return out;
}

TEST(CheckerRegistry, MakesByNameAndListsTheMethods) {
  CheckerRegistry registry;
  registry.Add("first", "the first way", [] {
    return std::make_unique<ScriptedChecker>("first", std::map<std::string, Verdict>{});
  });
  registry.Add("second", "the second way", [] {
    return std::make_unique<ScriptedChecker>("second", std::map<std::string, Verdict>{});
  });
  EXPECT_TRUE(registry.Has("second"));
  EXPECT_FALSE(registry.Has("third"));
  EXPECT_EQ(registry.Make("second")->name(), "second");
  EXPECT_EQ(registry.Names(), (std::vector<std::string>{"first", "second"}));
  EXPECT_EQ(registry.Summary("first"), "the first way");
  try {
    registry.Make("third");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown method 'third'; the methods are: first, second");
  }
  EXPECT_THROW(registry.Add("first", "", [] { return nullptr; }), std::invalid_argument);
  EXPECT_THROW(registry.Add("", "", [] { return nullptr; }), std::invalid_argument);
}

TEST(FallbackChecker, AsksLaterCheckersOnlyWhatIsUnknown) {
  auto reach = std::make_unique<ScriptedChecker>(
      "reach", std::map<std::string, Verdict>{{"a", Verdict::kProved}});
  auto prove = std::make_unique<ScriptedChecker>(
      "prove", std::map<std::string, Verdict>{{"b", Verdict::kViolated}});
  const auto reach_asked = reach->asked, prove_asked = prove->asked;
  FallbackChecker fallback = Auto(std::move(reach), std::move(prove));
  const System system("s");
  const std::vector<CheckResult> results = fallback.Check(system, Named({"a", "b", "c"}));
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(*reach_asked, (std::vector<std::string>{"reach:a", "reach:b", "reach:c"}));
  EXPECT_EQ(*prove_asked, (std::vector<std::string>{"prove:b", "prove:c"}));
  EXPECT_EQ(results[0].verdict, Verdict::kProved);
  EXPECT_EQ(results[0].method, "reach");
  EXPECT_EQ(results[1].verdict, Verdict::kViolated);
  EXPECT_EQ(results[1].method, "prove");
  EXPECT_EQ(results[2].verdict, Verdict::kUnknown);
  EXPECT_EQ(results[2].reason, "reach says so; prove: prove says so");
  EXPECT_DOUBLE_EQ(results[2].seconds, 2.0);
}

// A proof up to a time only (a flowpipe's `proved within T`) stays open: a later checker is asked,
// and a violation it finds, or a proof for longer, replaces it; its `unknown` does not.
TEST(FallbackChecker, BoundedProofsAreAskedAgainAndImprovedOnly) {
  auto flowpipe = std::make_unique<ScriptedChecker>(
      "flowpipe", std::map<std::string, Verdict>{{"a", Verdict::kProved},
                                                 {"b", Verdict::kProved},
                                                 {"c", Verdict::kProved},
                                                 {"d", Verdict::kProved}});
  flowpipe->within_ = {{"a", 5.0}, {"b", 5.0}, {"c", 5.0}};
  auto sample = std::make_unique<ScriptedChecker>(
      "sample", std::map<std::string, Verdict>{{"a", Verdict::kViolated}, {"c", Verdict::kProved}});
  sample->within_ = {{"c", 9.0}};
  const auto sample_asked = sample->asked;
  FallbackChecker fallback = Auto(std::move(flowpipe), std::move(sample));
  const System system("s");
  const std::vector<CheckResult> r = fallback.Check(system, Named({"a", "b", "c", "d"}));
  EXPECT_EQ(*sample_asked, (std::vector<std::string>{"sample:a", "sample:b", "sample:c"}));
  EXPECT_EQ(r[0].verdict, Verdict::kViolated);
  EXPECT_EQ(r[0].method, "sample");
  EXPECT_EQ(r[1].verdict, Verdict::kProved);  // sample's unknown leaves the bounded proof
  EXPECT_EQ(r[1].within, 5.0);
  EXPECT_EQ(r[1].reason, "flowpipe says so");
  EXPECT_EQ(r[2].within, 9.0);  // proved for longer
  EXPECT_FALSE(r[3].within.has_value());
  EXPECT_EQ(r[3].method, "flowpipe");
}

// A checker that only proves (a flowpipe) is not asked about a property whose exact reachable
// states met its bad states; one after it that can falsify is.
TEST(FallbackChecker, AsksNoProofOnlyCheckerWhatTheStatesMet) {
  auto reach = std::make_unique<ScriptedChecker>("reach", std::map<std::string, Verdict>{});
  reach->met_ = {"a"};
  auto flowpipe = std::make_unique<ScriptedChecker>(
      "flowpipe", std::map<std::string, Verdict>{{"b", Verdict::kProved}});
  flowpipe->falsifies_ = false;
  auto prove = std::make_unique<ScriptedChecker>(
      "prove", std::map<std::string, Verdict>{{"a", Verdict::kReachable}});
  const auto flowpipe_asked = flowpipe->asked, prove_asked = prove->asked;
  FallbackChecker fallback = Auto(std::move(reach), std::move(flowpipe), std::move(prove));
  const System system("s");
  const std::vector<CheckResult> r = fallback.Check(system, Named({"a", "b", "c"}));
  EXPECT_EQ(*flowpipe_asked, (std::vector<std::string>{"flowpipe:b", "flowpipe:c"}));
  EXPECT_EQ(*prove_asked, (std::vector<std::string>{"prove:a", "prove:c"}));
  EXPECT_EQ(r[0].verdict, Verdict::kReachable);
  EXPECT_EQ(r[0].method, "prove");
  EXPECT_EQ(r[1].verdict, Verdict::kProved);
  EXPECT_EQ(r[2].reason, "reach says so; flowpipe: flowpipe says so; prove: prove says so");
}

// With only a met property left open, the proof-only checker is skipped and the next one asked.
TEST(FallbackChecker, GoesPastAProofOnlyCheckerWhenOnlyMetPropertiesAreOpen) {
  auto reach = std::make_unique<ScriptedChecker>("reach", std::map<std::string, Verdict>{});
  reach->met_ = {"a"};
  auto flowpipe = std::make_unique<ScriptedChecker>("flowpipe", std::map<std::string, Verdict>{});
  flowpipe->falsifies_ = false;
  auto sample = std::make_unique<ScriptedChecker>("sample", std::map<std::string, Verdict>{});
  const auto flowpipe_asked = flowpipe->asked, sample_asked = sample->asked;
  FallbackChecker fallback = Auto(std::move(reach), std::move(flowpipe), std::move(sample));
  const System system("s");
  const std::vector<CheckResult> r = fallback.Check(system, Named({"a"}));
  EXPECT_TRUE(flowpipe_asked->empty());
  EXPECT_EQ(*sample_asked, (std::vector<std::string>{"sample:a"}));
  EXPECT_EQ(r[0].reason, "reach says so; sample: sample says so");
}

TEST(FallbackChecker, SkipsCheckersThatDoNotApply) {
  auto reach = std::make_unique<ScriptedChecker>(
      "reach", std::map<std::string, Verdict>{{"a", Verdict::kProved}}, false);
  auto prove = std::make_unique<ScriptedChecker>("prove", std::map<std::string, Verdict>{});
  const auto reach_asked = reach->asked;
  FallbackChecker fallback = Auto(std::move(reach), std::move(prove));
  const System system("s");
  const std::vector<CheckResult> results = fallback.Check(system, Named({"a"}));
  EXPECT_TRUE(reach_asked->empty());
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].method, "prove");
  EXPECT_EQ(results[0].reason, "prove says so");  // nothing appended: prove decided first
}

TEST(FallbackChecker, NoCheckerThatAppliesLeavesEveryPropertyUnknownSayingWhy) {
  FallbackChecker fallback =
      Auto(std::make_unique<ScriptedChecker>("reach", std::map<std::string, Verdict>{}, false));
  const System system("s");
  const std::vector<CheckResult> results = fallback.Check(system, Named({"a"}));
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].verdict, Verdict::kUnknown);
  EXPECT_EQ(results[0].reason, "no method applies: reach: not my kind of model");
  EXPECT_THROW(FallbackChecker("auto", {}), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid
