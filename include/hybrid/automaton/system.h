#pragma once

#include <map>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/automaton.h"

namespace hybrid {

/// A declaration of a component being added to a System that contradicts a declaration of an
/// earlier component (System::AddComponent): a parser reports it at both declarations.
class ConflictError : public std::invalid_argument {
 public:
  /// `other`: the index of the earlier component in System::components().
  ConflictError(const std::string& message, int other)
      : std::invalid_argument(message), other_(other) {}
  /// The index of the earlier component whose declaration this one contradicts.
  int other_component() const { return other_; }

 private:
  int other_;
};

/// One automaton inside a System.
struct Component {
  /// Instance name, or empty for a component whose names are not qualified.
  std::string instance;
  /// The component with its names qualified ("A.theta1") except shared ones; its own slots.
  Automaton automaton;
  /// automaton slot -> System slot.
  std::vector<int> global_slot;
  /// The automaton as declared, before renaming (what a printer writes back).
  Automaton source;
  /// Names of `source` (symbols or transition labels) bound to the System names they take in
  /// place of the default renaming (`g` -> `A.g`); see System::AddComponent.
  std::map<std::string, std::string> binds;
  friend bool operator==(const Component&, const Component&) = default;
};

/// Parallel composition of automata.
///
/// Names: a component added with instance name `A` has every symbol `x` and every transition
/// label `l` renamed to `A.x` and `A.l`, unless the name is shared (Share) or bound (a bind
/// `x -> B.y` gives it the name `B.y`, so one instance can read another's variable and
/// synchronise on its labels); a component with an empty instance name keeps its names. Equal names
/// after renaming denote one thing: shared variables are one state variable (at most one component
/// may give it a flow), shared inputs one input, shared parameters must agree.
///
/// Semantics: the state is the tuple of component modes plus the union of the variables. A
/// transition with an empty label, or with a label no other component uses, is taken alone
/// (interleaving). A transition labelled `l` where other components also have transitions
/// labelled `l` is taken only together with one such transition of each of them, all guards
/// holding; the resets then apply together (a variable reset by two of them is an error of the
/// product).
class System {
 public:
  /// `name` must be non-empty.
  explicit System(std::string name);
  /// `automaton` as a system of one unqualified component, with its properties and scenario.
  static System Of(const Automaton& automaton);

  const std::string& name() const { return name_; }
  /// Declares `name` (a symbol or a label) shared by every component added afterwards.
  void Share(std::string name);
  /// Adds a renamed copy of `automaton` (see the class comment); parameter ranges are renamed
  /// with it. `binds` maps names of `automaton` (a symbol, a transition label, or both) to the
  /// System names they take instead of the default renaming. Throws std::invalid_argument on a
  /// duplicate instance name, a shared name used with different kinds, a shared variable given a
  /// flow by two components, a shared parameter whose value or declared range (evaluated; both
  /// absent counts as equal) differs from the one it already has, a bind of a name `automaton`
  /// does not declare or of a shared name, or binds that give two symbols of `automaton` one
  /// name. Throws ConflictError (naming the earlier component) where the new component and an
  /// earlier one would give one System symbol two meanings: a shared (or bound) variable
  /// started at different values, an input with different bounds, a discrete variable given
  /// different values by the modes of both, or synchronised transitions (one label) that both
  /// reset one variable. So every engine reads one initial condition, one bound and one owner per
  /// shared symbol.
  void AddComponent(std::string instance, const Automaton& automaton,
                    std::map<std::string, std::string> binds = {});
  /// A system-level property over System slots; `in` atoms name component modes qualified by the
  /// instance (`A.open`) or, for an unqualified component, plainly.
  void AddProperty(Property property);
  /// The system's default run; inputs are System slots. Validated like Automaton::SetScenario
  /// (inputs each at most once, points finite and strictly increasing in time and within the
  /// input's bounds, until > 0 and finite); throws std::invalid_argument (a message naming the
  /// input) otherwise.
  void SetScenario(Scenario scenario);
  /// Sets parameter `name` (a System name: "A.gob1", or a shared or unqualified "gob1") to
  /// `value` in every component that declares it (Automaton::SetParameter). Throws
  /// std::invalid_argument ("no component has a parameter 'NAME'") if no component declares such
  /// a parameter, or as Automaton::SetParameter does (e.g. `value` outside the parameter's
  /// declared range); the system is then unchanged.
  void SetParameter(std::string_view name, double value);
  /// Sets the initial value of continuous variable `variable` (a System name: "A.theta1", or a
  /// shared or unqualified "theta1") to the point `value` in every initial state of every
  /// component that declares it (Automaton::SetInitialValue, in both `automaton` and `source`).
  /// Throws std::invalid_argument (a message naming the variable) if `value` is not finite or no
  /// component has such a continuous variable.
  void SetInitialValue(std::string_view variable, double value);
  /// Makes initial state `index` (declaration order) of component `component` its only one, in
  /// both `automaton` and `source` (Automaton::KeepInitialState). Throws std::invalid_argument if
  /// there is no such component or initial state.
  void SelectInitialState(int component, int index);

  const SymbolTable& symbols() const { return symbols_; }
  std::span<const Component> components() const { return components_; }
  std::span<const Property> properties() const { return properties_; }
  const std::optional<Scenario>& scenario() const { return scenario_; }
  const std::set<std::string>& shared() const { return shared_; }
  /// The value of parameter `slot` (a System slot) as the function of the uncertain parameters
  /// (those declared with a range) that it is: an uncertain parameter is its own symbol; any
  /// other is its definition with every parameter it reads resolved in turn, constants folded,
  /// so that one that reads no uncertain parameter is its nominal value as a constant
  /// (`param q = 2 * p;` with `p` uncertain gives `2 * p`). Every engine that covers the
  /// uncertain parameters reads derived ones through this. Throws std::invalid_argument if
  /// `slot` is not a parameter.
  Expression ResolvedParameter(int slot) const;
  /// Why the system has no run, when that is decided by evaluation: a component none of whose
  /// `init` declarations satisfies its mode's invariant (read in its closure, within 1e-9
  /// relative), judged on declarations with point values and invariants that read no input
  /// ("component 'A': the initial state of mode m violates its invariant 'x <= 1'"). Nullopt when
  /// some start may be admissible. A verdict on a system without runs holds vacuously; `hybrid
  /// check` says so.
  std::optional<std::string> NoAdmissibleStart() const;
  /// The labels component `c` synchronises on (System names): those of its transitions and
  /// those its automaton declares (Automaton::DeclareLabel). A
  /// transition labelled `l` fires only together with an `l`-transition of every other
  /// component whose alphabet has `l`. Throws std::out_of_range for a bad index.
  std::set<std::string> Alphabet(int c) const;
  /// Component index and mode of a qualified mode name, or nullopt.
  std::optional<std::pair<int, ModeId>> FindMode(std::string_view qualified) const;
  /// The name of mode `m` of component `c` as written at system level ("A.open" or "open").
  std::string QualifiedModeName(int c, ModeId m) const;
  /// The bounds [lo, hi] of the input at System slot `slot`, evaluated in the first component
  /// that declares it. Throws std::invalid_argument if `slot` is not an input.
  std::pair<double, double> InputBounds(int slot) const;

  /// The product automaton over System slots: one mode per tuple of component modes reachable
  /// from the initial tuples through the transition graph (guards are not evaluated), named by
  /// joining the component mode names with "__"; flows are the union of the components' flows,
  /// invariants their conjunction; transitions follow the synchronisation rule above. Throws
  /// std::invalid_argument ("the composed system has more than N product modes") past
  /// `max_modes` modes. With `tuples`, also
  /// gives the component modes (ModeId values, in component order) of each product mode.
  Automaton Product(int max_modes = 100000, std::vector<std::vector<int>>* tuples = nullptr) const;

  /// One step of the composed system (see the class comment) from a tuple of component modes.
  struct Step {
    /// The joint transition over System slots: guards conjoined, resets joined, urgent if one
    /// participant is, labelled; named by the participants' qualified names joined with "__"
    /// ('.' becoming '_'); source and target are left 0 (the tuples say where).
    Transition transition;
    /// The component modes after the step (ModeId values, in component order).
    std::vector<int> target;
    /// The component transitions taken together, in component order.
    std::vector<std::pair<int, TransitionId>> participants;
  };
  /// Every step from `tuple` (ModeId values, one per component), in the order Product adds
  /// them, without building the product: what on-the-fly exploration needs. Throws
  /// std::invalid_argument if `tuple` does not have one mode per component, or if synchronised
  /// transitions reset one variable twice.
  std::vector<Step> StepsFrom(std::span<const int> tuple) const;
  /// The product mode of `tuple` as Product makes it (flows and invariants over System slots).
  Mode ProductModeOf(std::span<const int> tuple) const;

  /// For each component, the smallest index of its interaction group: the least set of
  /// components closed under sharing a variable (continuous or discrete) or a synchronisation
  /// label. Groups meet only through inputs (free) and parameters (constant along runs): a step
  /// of the system is a step of one group's components, and every run projects onto a run of
  /// each group alone (Restricted), so the reachable states of the system lie in the product of
  /// those of its groups.
  std::vector<int> InteractionGroups() const;
  /// The system of components `which` (indices into components()) alone, with their names,
  /// shared names and binds, and no properties or scenario; its slots are numbered afresh in the
  /// order the components first use them (look a name up in symbols() to map them back). Throws
  /// std::out_of_range for an index out of range.
  System Restricted(std::span<const int> which) const;

  friend bool operator==(const System&, const System&) = default;

 private:
  std::string name_;
  std::set<std::string> shared_;
  SymbolTable symbols_;
  std::vector<Component> components_;
  std::vector<Property> properties_;
  std::optional<Scenario> scenario_;
};

}  // namespace hybrid
