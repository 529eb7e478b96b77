#include "hybrid/checking/property_checker.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace hybrid {
namespace {

// Still worth asking a later engine: undecided, or decided only up to a time (`within`).
bool IsOpen(const CheckResult& r) { return r.verdict == Verdict::kUnknown || r.within.has_value(); }

// Whether `later` says more than `earlier`: a decision where there was none, a decision for
// all time where there was one up to a time, or one up to a later time.
bool Improves(const CheckResult& later, const CheckResult& earlier) {
  if (later.verdict == Verdict::kUnknown) return false;
  if (earlier.verdict == Verdict::kUnknown || !later.within) return true;
  return earlier.within && *later.within > *earlier.within;
}

}  // namespace

bool PropertyChecker::Handles(const System&, std::span<const Property>, std::string*) const {
  return true;
}

FallbackChecker::FallbackChecker(std::string name,
                                 std::vector<std::unique_ptr<PropertyChecker>> checkers)
    : name_(std::move(name)), checkers_(std::move(checkers)) {
  if (checkers_.empty()) throw std::invalid_argument("a fallback checker needs a checker");
  for (const auto& c : checkers_) {
    if (!c) throw std::invalid_argument("a fallback checker's checkers must not be null");
  }
}

bool FallbackChecker::Handles(const System& system, std::span<const Property> properties,
                              std::string* why) const {
  std::string reasons;
  for (const auto& c : checkers_) {
    std::string reason;
    if (c->Handles(system, properties, &reason)) return true;
    reasons += (reasons.empty() ? "" : "; ") + std::string(c->name()) + ": " + reason;
  }
  if (why) *why = reasons;
  return false;
}

std::vector<CheckResult> FallbackChecker::Check(const System& system,
                                                std::span<const Property> properties) {
  std::vector<CheckResult> results;
  for (const auto& checker : checkers_) {
    if (!checker->Handles(system, properties, nullptr)) continue;
    if (results.empty()) {  // the first that applies decides what it can
      results = checker->Check(system, properties);
      continue;
    }
    std::vector<Property> left;
    std::vector<std::size_t> where;
    bool open = false;
    for (std::size_t i = 0; i < results.size(); ++i) {
      if (!IsOpen(results[i])) continue;
      open = true;
      if (results[i].states_met && !checker->Falsifies()) continue;  // it could not decide it
      left.push_back(properties[i]);
      where.push_back(i);
    }
    if (!open) break;
    if (left.empty()) continue;
    const std::vector<CheckResult> later = checker->Check(system, left);
    for (std::size_t k = 0; k < later.size() && k < where.size(); ++k) {
      CheckResult& r = results[where[k]];
      if (Improves(later[k], r)) {
        r = later[k];
      } else if (r.verdict == Verdict::kUnknown) {
        r.reason += "; " + std::string(checker->name()) + ": " + later[k].reason;
        r.seconds += later[k].seconds;
      }
    }
  }
  if (results.empty()) {  // none applies: every property unknown, saying why
    std::string why;
    Handles(system, properties, &why);
    for (const Property& p : properties) {
      CheckResult r;
      r.property = p.name;
      r.kind = p.kind;
      r.method = name_;
      r.reason = "no method applies: " + why;
      results.push_back(std::move(r));
    }
  }
  return results;
}

void CheckerRegistry::Add(std::string name, std::string summary, Factory factory) {
  if (name.empty()) throw std::invalid_argument("a checking method needs a name");
  if (Has(name)) throw std::invalid_argument("duplicate checking method '" + name + "'");
  if (!factory) throw std::invalid_argument("checking method '" + name + "' has no factory");
  entries_.push_back({std::move(name), std::move(summary), std::move(factory)});
}

bool CheckerRegistry::Has(std::string_view name) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [name](const Entry& e) { return e.name == name; });
}

std::unique_ptr<PropertyChecker> CheckerRegistry::Make(std::string_view name) const {
  for (const Entry& e : entries_) {
    if (e.name == name) return e.factory();
  }
  throw std::invalid_argument("unknown method '" + std::string(name) +
                              "'; the methods are: " + NameList());
}

std::vector<std::string> CheckerRegistry::Names() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.name);
  return out;
}

std::string CheckerRegistry::NameList() const {
  std::string out;
  for (const Entry& e : entries_) out += (out.empty() ? "" : ", ") + e.name;
  return out;
}

std::string CheckerRegistry::Summary(std::string_view name) const {
  for (const Entry& e : entries_) {
    if (e.name == name) return e.summary;
  }
  return "";
}

}  // namespace hybrid
