#pragma once

#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"

namespace hybrid {

/// One way of deciding properties of a system: what every engine of `hybrid check` is to the
/// command, the Python module and the `auto` method (polyhedral reachability, the SMT prover,
/// the sampler, and any engine to come).
///
/// Contract: Check returns one CheckResult per property, in order, each with `method` set to
/// name(). A definite verdict is never wrong for the model's one meaning (the IR's: strictness,
/// tolerance, composition): `proved` and `unreachable` hold for every run, `violated` and
/// `reachable` come with a trace the simulator replays (ConfirmTrace). What the engine cannot
/// decide is `unknown` with the reason.
class PropertyChecker {
 public:
  virtual ~PropertyChecker() = default;
  /// The method's name, as users select it ("reach", "prove", "sample").
  virtual std::string_view name() const = 0;
  /// Whether the engine applies to `properties` of `system` at all (e.g. reachability needs a
  /// linear hybrid automaton); when it does not, `why` (if given) says why. Defaults to true.
  virtual bool Handles(const System& system, std::span<const Property> properties,
                       std::string* why) const;
  /// The verdicts of `properties` (System slots, as System::properties() has them).
  virtual std::vector<CheckResult> Check(const System& system,
                                         std::span<const Property> properties) = 0;
  /// Whether the engine can find violations (and witnesses) at all; false for one that only
  /// proves by enclosing the reachable states. Defaults to true.
  virtual bool Falsifies() const { return true; }
};

/// Checkers in order: the first that handles the properties decides what it can, and each later
/// one is asked what is still open: `unknown` (its reason appended to the earlier ones' as
/// "; NAME: reason", its time added), or decided only up to a time (CheckResult::within, a
/// bounded answer to an unbounded question), except that a checker that does not falsify is not
/// asked about a property whose reachable states an earlier one found to meet its bad states
/// (CheckResult::states_met). A later result replaces the earlier one where it
/// decides and the earlier did not, or decides for all time (a violation found by simulation, a
/// proof without a bound), or up to a later time.
/// The method of `hybrid check --method auto` (reachability, then the prover).
class FallbackChecker : public PropertyChecker {
 public:
  /// `name`: the method's name ("auto"); `checkers`: tried in order (none null).
  FallbackChecker(std::string name, std::vector<std::unique_ptr<PropertyChecker>> checkers);
  std::string_view name() const override { return name_; }
  bool Handles(const System& system, std::span<const Property> properties,
               std::string* why) const override;
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override;

 private:
  std::string name_;
  std::vector<std::unique_ptr<PropertyChecker>> checkers_;
};

/// The checking methods by name: each made on demand by its factory (which holds the options
/// the caller gave it: budgets, seeds, progress). `hybrid check`, the Python module and `auto`
/// choose from it, so that a new engine is one more entry, not a new branch in their code.
class CheckerRegistry {
 public:
  using Factory = std::function<std::unique_ptr<PropertyChecker>()>;
  /// Adds method `name` with a one-line `summary` (for --help and errors). Throws
  /// std::invalid_argument for an empty or duplicate name.
  void Add(std::string name, std::string summary, Factory factory);
  /// Whether there is a method `name`.
  bool Has(std::string_view name) const;
  /// A new checker of method `name`. Throws std::invalid_argument ("unknown method 'x'; the
  /// methods are: auto, reach, prove, sample") for an unknown name.
  std::unique_ptr<PropertyChecker> Make(std::string_view name) const;
  /// The methods' names in the order they were added.
  std::vector<std::string> Names() const;
  /// "auto, reach, prove, sample".
  std::string NameList() const;
  /// The summary of method `name` ("" for an unknown one).
  std::string Summary(std::string_view name) const;

 private:
  struct Entry {
    std::string name;
    std::string summary;
    Factory factory;
  };
  std::vector<Entry> entries_;
};

}  // namespace hybrid
