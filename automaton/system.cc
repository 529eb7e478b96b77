#include "hybrid/automaton/system.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <map>
#include <stdexcept>

#include "automaton/tree_walk.h"

namespace hybrid {
namespace {

// Messages speak of the model (instances, names, values), never of this API: they reach users as
// they are.
[[noreturn]] void Fail(const std::string& message) { throw std::invalid_argument(message); }

// `context` names what is wrong ("property 'p'").
[[noreturn]] void Fail(std::string_view context, const std::string& message) {
  throw std::invalid_argument(std::string(context) + ": " + message);
}

// "a variable", "an input", ...
std::string WithArticle(std::string_view noun) {
  const bool vowel =
      !noun.empty() && std::string_view("aeiou").find(noun.front()) != std::string_view::npos;
  return (vowel ? "an " : "a ") + std::string(noun);
}

// The evaluated range of parameter `slot` of `a` ("[0, 256]"), or "none".
std::string RangeText(const Automaton& a, int slot) {
  const std::optional<Range> r = a.ParameterRange(slot);
  if (!r) return "none";
  const std::vector<double> env = a.ParameterEnvironment();
  return "[" + FormatNumber(r->lo.Evaluate(env)) + ", " + FormatNumber(r->hi.Evaluate(env)) + "]";
}

// Rewrites every symbol of `e` through `slot_map` (old slot -> new slot) with new names.
Expression Remap(const Expression& e, const std::vector<int>& slot_map, const SymbolTable& names) {
  return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
    const int s = slot_map.at(slot);
    return Expression::Symbol(names[s].name, s);
  });
}

Comparison Remap(const Comparison& c, const std::vector<int>& m, const SymbolTable& n) {
  return {Remap(c.lhs, m, n), c.relation, Remap(c.rhs, m, n)};
}

Constraint Remap(const Constraint& c, const std::vector<int>& m, const SymbolTable& n) {
  Constraint out;
  for (const Comparison& x : c.comparisons) out.comparisons.push_back(Remap(x, m, n));
  return out;
}

Predicate Remap(const Predicate& p, const std::vector<int>& m, const SymbolTable& n,
                const std::function<std::string(const std::string&)>& mode_name) {
  return internal::PostOrder<Predicate>(
      p, [](const Predicate& x) { return x.operands(); },
      [&](const Predicate& x) -> std::optional<Predicate> {
        switch (x.kind()) {
          case Predicate::Kind::kComparison:
            return Predicate::Compare(Remap(x.comparison(), m, n));
          case Predicate::Kind::kInMode:
            return Predicate::InMode(mode_name(x.mode()));
          case Predicate::Kind::kTrue:
          case Predicate::Kind::kFalse:
            return x;
          default:
            return std::nullopt;
        }
      },
      [](const Predicate& x, std::span<Predicate> operands) {
        switch (x.kind()) {
          case Predicate::Kind::kNot:
            return Predicate::Not(operands[0]);
          case Predicate::Kind::kAnd:
            return Predicate::And(operands[0], operands[1]);
          default:
            return Predicate::Or(operands[0], operands[1]);
        }
      });
}

// Copies `a` into a new automaton whose symbols are renamed by `rename`; slots are preserved.
Automaton Renamed(const Automaton& a, const std::function<std::string(const std::string&)>& rename,
                  const std::function<std::string(const std::string&)>& rename_label) {
  Automaton out(a.name());
  const SymbolTable& old = a.symbols();
  SymbolTable names;
  for (int s = 0; s < old.size(); ++s) names.Add({rename(old[s].name), old[s].kind, old[s].unit});
  std::vector<int> identity(old.size());
  for (int s = 0; s < old.size(); ++s) identity[s] = s;
  auto expr = [&](const Expression& e) { return Remap(e, identity, names); };
  auto range = [&](const Range& r) { return Range{expr(r.lo), expr(r.hi)}; };
  size_t next_var = 0, next_input = 0, next_param = 0;
  for (int s = 0; s < old.size(); ++s) {
    const Symbol& sym = names[s];
    switch (sym.kind) {
      case SymbolKind::kVariable: {
        const auto& info = a.variables()[next_var++];
        std::optional<Range> domain;
        if (info.domain) domain = range(*info.domain);
        out.AddVariable(sym.name, sym.unit, domain);
        break;
      }
      case SymbolKind::kDiscrete:
        out.AddDiscreteVariable(sym.name);
        break;
      case SymbolKind::kInput:
        out.AddInput(sym.name, range(a.inputs()[next_input++].bounds), sym.unit);
        break;
      case SymbolKind::kParameter: {
        std::optional<Range> declared = a.ParameterRange(s);
        if (declared) declared = range(*declared);
        out.AddParameter(sym.name, expr(a.parameters()[next_param++].second), sym.unit, declared);
        break;
      }
    }
  }
  for (const Mode& m : a.modes()) {
    Mode copy = m;
    for (auto& [slot, rhs] : copy.flows) rhs = expr(rhs);
    copy.invariant = Remap(m.invariant, identity, names);
    out.AddMode(std::move(copy));
  }
  for (const Transition& t : a.transitions()) {
    Transition copy = t;
    copy.guard = Remap(t.guard, identity, names);
    for (Reset& r : copy.resets) r.value = expr(r.value);
    if (!copy.label.empty()) copy.label = rename_label(copy.label);
    out.AddTransition(std::move(copy));
  }
  for (const std::string& label : a.declared_labels()) out.DeclareLabel(rename_label(label));
  for (const InitialState& init : a.initial_states()) {
    InitialState copy = init;
    for (InitialValue& v : copy.values) v.range = range(v.range);
    out.AddInitialState(std::move(copy));
  }
  auto same_mode = [](const std::string& m) { return m; };
  for (const Property& p : a.properties()) {
    Property copy = p;
    copy.predicate = Remap(p.predicate, identity, names, same_mode);
    out.AddProperty(std::move(copy));
  }
  if (a.scenario()) out.SetScenario(*a.scenario());
  return out;
}

// The local slot of System slot `g` in component `c`, or -1 if `c` does not have it.
int LocalSlot(const Component& c, int g) {
  auto it = std::find(c.global_slot.begin(), c.global_slot.end(), g);
  return it == c.global_slot.end() ? -1 : static_cast<int>(it - c.global_slot.begin());
}

// Throws unless no component of `components` has the instance name `instance`.
void CheckNewInstance(std::span<const Component> components, const std::string& instance) {
  for (const Component& c : components) {
    if (c.instance == instance) {
      Fail(instance.empty() ? "two unnamed instances (at most one instance may keep its names)"
                            : "duplicate instance '" + instance + "'");
    }
  }
}

// Throws unless every name `binds` binds is a symbol or a transition label of `a`, not shared,
// and bound to a name.
void CheckBinds(const Automaton& a, const std::map<std::string, std::string>& binds,
                const std::set<std::string>& shared) {
  for (const auto& bind : binds) {
    const std::string& from = bind.first;
    const std::string& to = bind.second;
    const bool label = a.declared_labels().count(from) ||
                       std::any_of(a.transitions().begin(), a.transitions().end(),
                                   [&from](const Transition& t) { return t.label == from; });
    if (!a.symbols().Find(from) && !label) {
      Fail("bind '" + from + "': '" + a.name() + "' has no variable, input, parameter or label '" +
           from + "'");
    }
    if (shared.count(from)) Fail("bind '" + from + "': the name is shared; it cannot be bound");
    if (to.empty()) Fail("bind '" + from + "': bound to an empty name");
  }
}

// Throws if `rename` gives two symbols of `a` one name (two binds to one name, or a bind to the
// name another symbol takes anyway).
void CheckDistinctNames(const Automaton& a,
                        const std::function<std::string(const std::string&)>& rename) {
  std::map<std::string, std::string> seen;  // new name -> old name
  for (int s = 0; s < a.symbols().size(); ++s) {
    const std::string& old = a.symbols()[s].name;
    auto [it, added] = seen.emplace(rename(old), old);
    if (!added) {
      Fail("'" + it->second + "' and '" + old + "' of '" + a.name() + "' would both be named '" +
           it->first + "'");
    }
  }
}

// A shared parameter is one constant: throws unless parameter `s` of the new component `c`
// (value `value`, System slot `g`) has the value and declared range it has in the first of
// `components` that declares `g`.
// Whether parameter `slot` of `a` has no range of its own but is defined from one that has
// (directly or through other parameters).
bool DerivedFromUncertain(const Automaton& a, int slot) {
  for (const auto& [s, value] : a.parameters()) {
    if (s != slot) continue;
    if (a.ParameterRange(s)) return false;
    for (const int read : value.Slots()) {
      if (a.ParameterRange(read) || DerivedFromUncertain(a, read)) return true;
    }
  }
  return false;
}

// The defining expression of parameter `slot` of `c` over System slots (`global_slot` must map
// every parameter it reads: those are declared before it).
Expression DefinitionOf(const Component& c, int slot, const SymbolTable& symbols) {
  for (const auto& [s, value] : c.automaton.parameters()) {
    if (s == slot) return Remap(value, c.global_slot, symbols);
  }
  return Expression();
}

void CheckSharedParameter(const Component& c, int s, double value, int g,
                          std::span<const Component> components, const SymbolTable& symbols) {
  const std::string& name = c.automaton.symbols()[s].name;
  for (const Component& other : components) {
    const int other_slot = LocalSlot(other, g);
    if (other_slot < 0) continue;
    const double theirs = other.automaton.ParameterEnvironment()[other_slot];
    if (theirs != value) {
      Fail("shared parameter '" + name + "' is " + FormatNumber(value) + " in '" + c.source.name() +
           "' but " + FormatNumber(theirs) + " in '" + other.automaton.name() + "'");
    }
    const std::string ours = RangeText(c.automaton, s);
    const std::string their_range = RangeText(other.automaton, other_slot);
    if (ours != their_range) {
      Fail("shared parameter '" + name + "' has range " + ours + " in '" + c.source.name() +
           "' but " + their_range + " in '" + other.automaton.name() + "'");
    }
    // A derived parameter is a function of uncertain ones: one function for every instance.
    const bool derived =
        DerivedFromUncertain(c.automaton, s) || DerivedFromUncertain(other.automaton, other_slot);
    if (derived && !(DefinitionOf(c, s, symbols) == DefinitionOf(other, other_slot, symbols))) {
      Fail("shared parameter '" + name + "' is defined from uncertain parameters as " +
           DefinitionOf(c, s, symbols).ToString() + " in '" + c.source.name() + "' but as " +
           DefinitionOf(other, other_slot, symbols).ToString() + " in '" + other.automaton.name() +
           "': share what it is defined from, or give it a range");
    }
    break;
  }
}

// Whether some mode of `a` gives a flow to slot `slot`.
bool HasFlow(const Automaton& a, int slot) {
  return std::any_of(a.modes().begin(), a.modes().end(),
                     [slot](const Mode& m) { return m.FlowOf(slot).has_value(); });
}

// At most one component may define the flow of a shared variable: throws if a variable the new
// component `c` (its System slots bound) gives a flow also has one in one of `components`.
void CheckSharedFlows(const Component& c, std::span<const Component> components) {
  const SymbolTable& local = c.automaton.symbols();
  for (int s = 0; s < local.size(); ++s) {
    if (local[s].kind != SymbolKind::kVariable) continue;
    if (!HasFlow(c.automaton, s)) continue;
    for (const Component& other : components) {
      const int other_slot = LocalSlot(other, c.global_slot[s]);
      if (other_slot < 0) continue;
      if (HasFlow(other.automaton, other_slot)) {
        Fail("shared variable '" + local[s].name + "' has flows in two components");
      }
    }
  }
}

// How component `c` is named in messages: "instance 'A'", or the automaton's name.
std::string Named(const Component& c) {
  return c.instance.empty() ? "'" + c.source.name() + "'" : "instance '" + c.instance + "'";
}

// The evaluated ranges "lo" or "[lo, hi]" that the initial states of `c` give System slot `g`.
std::set<std::string> InitialTexts(const Component& c, int g) {
  std::set<std::string> out;
  const int local = LocalSlot(c, g);
  if (local < 0) return out;
  const std::vector<double> env = c.automaton.ParameterEnvironment();
  for (const InitialState& init : c.automaton.initial_states()) {
    for (const InitialValue& v : init.values) {
      if (v.slot != local) continue;
      const double lo = v.range.lo.Evaluate(env), hi = v.range.hi.Evaluate(env);
      out.insert(lo == hi ? FormatNumber(lo)
                          : "[" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
    }
  }
  return out;
}

// "0" or "0 or 5".
std::string Alternatives(const std::set<std::string>& texts) {
  std::string out;
  for (const std::string& t : texts) out += (out.empty() ? "" : " or ") + t;
  return out;
}

// The values the modes of `c` give discrete System slot `g`.
std::set<int> DiscreteValues(const Component& c, int g) {
  std::set<int> out;
  const int local = LocalSlot(c, g);
  if (local < 0) return out;
  for (const Mode& m : c.automaton.modes()) {
    for (const auto& [slot, value] : m.discrete_values) {
      if (slot == local) out.insert(value);
    }
  }
  return out;
}

// The evaluated bounds of input System slot `g` in `c`, or nullopt if `c` has no such input.
std::optional<std::pair<double, double>> InputBoundsIn(const Component& c, int g) {
  const int local = LocalSlot(c, g);
  const std::vector<double> env = c.automaton.ParameterEnvironment();
  for (const InputInfo& in : c.automaton.inputs()) {
    if (in.slot == local)
      return std::make_pair(in.bounds.lo.Evaluate(env), in.bounds.hi.Evaluate(env));
  }
  return std::nullopt;
}

// Throws ConflictError unless the new component `c` and every earlier one agree on the initial
// values, input bounds and discrete values of the System symbols they both have.
void CheckSharedMeaning(const Component& c, std::span<const Component> components,
                        const SymbolTable& symbols) {
  for (int s = 0; s < c.automaton.symbols().size(); ++s) {
    const int g = c.global_slot[s];
    const std::string& name = symbols[g].name;
    for (int o = 0; o < static_cast<int>(components.size()); ++o) {
      const Component& other = components[o];
      if (LocalSlot(other, g) < 0) continue;
      switch (symbols[g].kind) {
        case SymbolKind::kVariable: {
          std::set<std::string> ours = InitialTexts(c, g), theirs = InitialTexts(other, g);
          std::set<std::string> both = ours;
          both.insert(theirs.begin(), theirs.end());
          if (!ours.empty() && !theirs.empty() && both.size() > 1) {
            throw ConflictError("shared variable '" + name + "' starts at " + Alternatives(ours) +
                                    " in " + Named(c) + " but at " + Alternatives(theirs) + " in " +
                                    Named(other) + ": give every instance one start",
                                o);
          }
          break;
        }
        case SymbolKind::kInput: {
          const auto ours = InputBoundsIn(c, g), theirs = InputBoundsIn(other, g);
          if (ours && theirs && *ours != *theirs) {
            throw ConflictError("shared input '" + name + "' is in [" + FormatNumber(ours->first) +
                                    ", " + FormatNumber(ours->second) + "] in " + Named(c) +
                                    " but in [" + FormatNumber(theirs->first) + ", " +
                                    FormatNumber(theirs->second) + "] in " + Named(other) +
                                    ": declare the same bounds",
                                o);
          }
          break;
        }
        case SymbolKind::kDiscrete: {
          std::set<int> ours = DiscreteValues(c, g), theirs = DiscreteValues(other, g);
          std::set<int> both = ours;
          both.insert(theirs.begin(), theirs.end());
          if (!ours.empty() && !theirs.empty() && both.size() > 1) {
            throw ConflictError("shared discrete variable '" + name +
                                    "' is given values by the modes of both " + Named(c) + " and " +
                                    Named(other) + ": one instance must own it",
                                o);
          }
          break;
        }
        case SymbolKind::kParameter:
          break;  // CheckSharedParameter
      }
      break;  // the first earlier component that has it stands for all
    }
  }
}

// Throws ConflictError if a transition of the new component `c` and one of an earlier component
// carry one label and both reset one variable: they would fire together and write it twice.
void CheckSynchronisedResets(const Component& c, std::span<const Component> components,
                             const SymbolTable& symbols) {
  for (const Transition& t : c.automaton.transitions()) {
    if (t.label.empty() || t.resets.empty()) continue;
    for (int o = 0; o < static_cast<int>(components.size()); ++o) {
      for (const Transition& u : components[o].automaton.transitions()) {
        if (u.label != t.label) continue;
        for (const Reset& r : t.resets) {
          const int g = c.global_slot[r.slot];
          for (const Reset& q : u.resets) {
            if (components[o].global_slot[q.slot] != g) continue;
            throw ConflictError("transition '" + t.name + "' of " + Named(c) + " and '" + u.name +
                                    "' of " + Named(components[o]) + " synchronise on '" + t.label +
                                    "' and both reset '" + symbols[g].name +
                                    "': only one of them may write it",
                                o);
          }
        }
      }
    }
  }
}

// Expression `e` of component `c` over System slots.
Expression Global(const Component& c, const Expression& e, const SymbolTable& symbols) {
  return Remap(e, c.global_slot, symbols);
}

// Declares in `out` the System symbol `sym`, which is slot `local` of component `c`, with the
// domain, bounds or value and declared range it has in `c`.
void DeclareSymbol(const Symbol& sym, const Component& c, int local, const SymbolTable& symbols,
                   Automaton& out) {
  const Automaton& a = c.automaton;
  auto global = [&](const Expression& e) { return Global(c, e, symbols); };
  switch (sym.kind) {
    case SymbolKind::kVariable: {
      std::optional<Range> domain;
      for (const VariableInfo& v : a.variables()) {
        if (v.slot == local && v.domain) domain = Range{global(v.domain->lo), global(v.domain->hi)};
      }
      out.AddVariable(sym.name, sym.unit, domain);
      break;
    }
    case SymbolKind::kDiscrete:
      out.AddDiscreteVariable(sym.name);
      break;
    case SymbolKind::kInput:
      for (const InputInfo& in : a.inputs()) {
        if (in.slot == local) {
          out.AddInput(sym.name, {global(in.bounds.lo), global(in.bounds.hi)}, sym.unit);
        }
      }
      break;
    case SymbolKind::kParameter:
      for (const auto& [slot, value] : a.parameters()) {
        if (slot != local) continue;
        std::optional<Range> range = a.ParameterRange(slot);
        if (range) range = Range{global(range->lo), global(range->hi)};
        out.AddParameter(sym.name, global(value), sym.unit, range);
      }
      break;
  }
}

// Declares every symbol of `symbols` in `out`, in slot order so that slots coincide, as the
// first of `components` that has it declares it.
void DeclareSymbols(const SymbolTable& symbols, std::span<const Component> components,
                    Automaton& out) {
  for (int s = 0; s < symbols.size(); ++s) {
    for (const Component& c : components) {
      const int local = LocalSlot(c, s);
      if (local < 0) continue;
      DeclareSymbol(symbols[s], c, local, symbols, out);
      break;
    }
  }
}

// Product modes are tuples of component modes (ModeId values, one per component).
using Tuple = std::vector<int>;
// A transition of the component with the given index.
using Participant = std::pair<int, const Transition*>;

// The product mode of `tuple`: component mode names joined with "__", the components' flows
// (sorted by slot) and invariants, and their discrete values (sorted, without repeats).
Mode ProductMode(const Tuple& tuple, std::span<const Component> components,
                 const SymbolTable& symbols) {
  Mode m;
  for (int i = 0; i < static_cast<int>(components.size()); ++i) {
    const Component& c = components[i];
    const Mode& local = c.automaton.mode(ModeId(tuple[i]));
    m.name += (i > 0 ? "__" : "") + local.name;
    for (const auto& [slot, rhs] : local.flows) {
      m.flows.emplace_back(c.global_slot[slot], Global(c, rhs, symbols));
    }
    for (const Comparison& x : local.invariant.comparisons) {
      m.invariant.comparisons.push_back(Remap(x, c.global_slot, symbols));
    }
    for (const auto& [slot, value] : local.discrete_values) {
      m.discrete_values.emplace_back(c.global_slot[slot], value);
    }
  }
  std::sort(m.flows.begin(), m.flows.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::sort(m.discrete_values.begin(), m.discrete_values.end());
  m.discrete_values.erase(std::unique(m.discrete_values.begin(), m.discrete_values.end()),
                          m.discrete_values.end());
  return m;
}

// The initial tuples, the cartesian product of the components' initial states (the first
// component varying slowest), each with its initial values over System slots: for a slot
// several components initialise, the first component's value (values in the order given).
std::vector<std::pair<Tuple, std::vector<InitialValue>>> InitialTuples(
    std::span<const Component> components, const SymbolTable& symbols) {
  std::vector<std::pair<Tuple, std::vector<InitialValue>>> inits = {{{}, {}}};
  for (const Component& c : components) {
    std::vector<std::pair<Tuple, std::vector<InitialValue>>> next;
    for (const auto& [tuple, values] : inits) {
      for (const InitialState& s : c.automaton.initial_states()) {
        auto t = tuple;
        t.push_back(s.mode.value());
        auto v = values;
        for (const InitialValue& iv : s.values) {
          const int g = c.global_slot[iv.slot];
          if (std::none_of(v.begin(), v.end(),
                           [g](const InitialValue& x) { return x.slot == g; })) {
            v.push_back({g,
                         {Global(c, iv.range.lo, symbols), Global(c, iv.range.hi, symbols)},
                         iv.is_point});
          }
        }
        next.emplace_back(std::move(t), std::move(v));
      }
    }
    inits = std::move(next);
  }
  return inits;
}

// Every way of picking one transition from each non-empty `choices[j]`, in lexicographic order
// (lower j varying slowest), each as its participants in increasing component order.
std::vector<std::vector<Participant>> Combinations(
    const std::vector<std::vector<const Transition*>>& choices) {
  std::vector<std::vector<Participant>> combos = {{}};
  for (int j = 0; j < static_cast<int>(choices.size()); ++j) {
    if (choices[j].empty()) continue;
    std::vector<std::vector<Participant>> next;
    for (const auto& combo : combos) {
      for (const Transition* u : choices[j]) {
        auto c = combo;
        c.emplace_back(j, u);
        next.push_back(std::move(c));
      }
    }
    combos = std::move(next);
  }
  return combos;
}

// The labels each component synchronises on: its declared labels and its transitions'.
std::vector<std::set<std::string>> Alphabets(std::span<const Component> components) {
  std::vector<std::set<std::string>> alphabet;
  for (const Component& c : components) {
    std::set<std::string>& labels = alphabet.emplace_back(c.automaton.declared_labels());
    for (const Transition& t : c.automaton.transitions()) {
      if (!t.label.empty()) labels.insert(t.label);
    }
  }
  return alphabet;
}

// The transitions that can take part in a step of transition `t` of component `i` from
// `tuple`: `t` for `i`, and for every other component whose alphabet has t's label its
// transitions from its mode with that label (empty for components not taking part). Nullopt
// if one of those has none (the step is blocked) or if a lower component takes part (a
// synchronised step is generated once, from its first participant).
std::optional<std::vector<std::vector<const Transition*>>> Choices(
    std::span<const Component> components, std::span<const std::set<std::string>> alphabet,
    std::span<const int> tuple, int i, const Transition& t) {
  const int n = static_cast<int>(components.size());
  std::vector<std::vector<const Transition*>> choices(n);
  bool blocked = false;
  bool leader = true;
  for (int j = 0; j < n && !blocked; ++j) {
    if (j == i || t.label.empty() || !alphabet[j].count(t.label)) continue;
    if (j < i) leader = false;
    for (const Transition& u : components[j].automaton.transitions()) {
      if (u.source.value() == tuple[j] && u.label == t.label) choices[j].push_back(&u);
    }
    blocked = choices[j].empty();
  }
  if (blocked || !leader) return std::nullopt;
  choices[i] = {&t};
  return choices;
}

// The step that takes the participants of `combo` together from `tuple`, labelled `label`:
// guards conjoined, resets joined (throws if two reset one variable), urgent if one of them
// is, named by the participants' qualified names joined with "__" ('.' becoming '_').
System::Step JointStep(std::span<const Component> components, const SymbolTable& symbols,
                       std::span<const int> tuple, const std::string& label,
                       const std::vector<Participant>& combo) {
  System::Step step;
  step.target.assign(tuple.begin(), tuple.end());
  Transition& joint = step.transition;
  joint.label = label;
  joint.urgency = Urgency::kLazy;
  for (const auto& [j, u] : combo) {
    const Component& c = components[j];
    step.target[j] = u->target.value();
    step.participants.emplace_back(
        j, TransitionId(static_cast<int>(u - c.automaton.transitions().data())));
    joint.name += (joint.name.empty() ? "" : "__") +
                  (c.instance.empty() ? u->name : c.instance + "." + u->name);
    for (const Comparison& x : u->guard.comparisons) {
      joint.guard.comparisons.push_back(Remap(x, c.global_slot, symbols));
    }
    for (const Reset& r : u->resets) {
      const int g = c.global_slot[r.slot];
      if (std::any_of(joint.resets.begin(), joint.resets.end(),
                      [g](const Reset& x) { return x.slot == g; })) {
        Fail("synchronised transitions reset '" + symbols[g].name + "' twice");
      }
      joint.resets.push_back({g, Global(c, r.value, symbols)});
    }
    if (u->urgency == Urgency::kUrgent) joint.urgency = Urgency::kUrgent;
  }
  std::sort(joint.resets.begin(), joint.resets.end(),
            [](const Reset& a, const Reset& b) { return a.slot < b.slot; });
  for (char& ch : joint.name) {
    if (ch == '.') ch = '_';
  }
  return step;
}

// Every step of the composed system from `tuple` (System::StepsFrom).
std::vector<System::Step> StepsFrom(std::span<const Component> components,
                                    const SymbolTable& symbols,
                                    std::span<const std::set<std::string>> alphabet,
                                    std::span<const int> tuple) {
  std::vector<System::Step> steps;
  for (int i = 0; i < static_cast<int>(components.size()); ++i) {
    for (const Transition& t : components[i].automaton.transitions()) {
      if (t.source.value() != tuple[i]) continue;
      const auto choices = Choices(components, alphabet, tuple, i, t);
      if (!choices) continue;
      for (const auto& combo : Combinations(*choices)) {
        steps.push_back(JointStep(components, symbols, tuple, t.label, combo));
      }
    }
  }
  return steps;
}

// Builds the reachable part of the product of `components` into `out` (whose symbols are the
// System's, declared in slot order): product modes are created when first reached and explored
// breadth first; transitions are numbered in the order they are added.
class ProductBuilder {
 public:
  ProductBuilder(const SymbolTable& symbols, std::span<const Component> components, int max_modes,
                 Automaton& out)
      : symbols_(symbols),
        components_(components),
        max_modes_(max_modes),
        out_(out),
        alphabet_(Alphabets(components)) {}

  // Adds the initial states (InitialTuples, values sorted by slot) and their product modes.
  void AddInitialStates() {
    for (auto& [tuple, values] : InitialTuples(components_, symbols_)) {
      std::sort(values.begin(), values.end(),
                [](const InitialValue& a, const InitialValue& b) { return a.slot < b.slot; });
      out_.AddInitialState({ModeOf(tuple), std::move(values)});
    }
  }

  // Adds the transitions of every product mode reached, and the modes they reach, until no new
  // mode is reached; transition names are StepsFrom's prefixed by "t<number>_".
  void Explore() {
    while (!queue_.empty()) {
      const Tuple tuple = queue_.front();
      queue_.pop_front();
      const ModeId source = index_.at(tuple);
      for (System::Step& step : StepsFrom(components_, symbols_, alphabet_, tuple)) {
        Transition joint = std::move(step.transition);
        joint.name = "t" + std::to_string(transition_count_++) + "_" + joint.name;
        joint.source = source;
        joint.target = ModeOf(step.target);
        out_.AddTransition(std::move(joint));
      }
    }
  }

 private:
  // The product mode of `tuple`, added (and queued for exploration) if new; throws past
  // `max_modes_` modes.
  ModeId ModeOf(const Tuple& tuple) {
    if (auto it = index_.find(tuple); it != index_.end()) return it->second;
    if (static_cast<int>(index_.size()) >= max_modes_) {
      Fail("the composed system has more than " + std::to_string(max_modes_) + " product modes");
    }
    const ModeId id = out_.AddMode(ProductMode(tuple, components_, symbols_));
    index_.emplace(tuple, id);
    queue_.push_back(tuple);
    return id;
  }

  const SymbolTable& symbols_;
  std::span<const Component> components_;
  const int max_modes_;
  Automaton& out_;
  std::vector<std::set<std::string>> alphabet_;  // per component

 public:
  // The component modes of each product mode (by ModeId).
  std::vector<std::vector<int>> Tuples() const {
    std::vector<std::vector<int>> out(index_.size());
    for (const auto& [tuple, id] : index_) out[static_cast<size_t>(id.value())] = tuple;
    return out;
  }

 private:
  std::map<Tuple, ModeId> index_;
  std::deque<Tuple> queue_;  // product modes added but not explored yet
  int transition_count_ = 0;
};

// Adds to `out` the system properties without `in` atoms. Product modes are tuples; an `in A.m`
// atom holds in every product mode containing A.m. It cannot be expressed as one product mode
// name, so product properties keep only comparisons; properties with `in` atoms are checked on
// the System, not the product.
void AddProductProperties(std::span<const Property> properties, Automaton& out) {
  for (const Property& p : properties) {
    Property copy = p;
    bool has_mode_atom = false;
    p.predicate.ForEachMode([&](const std::string&) { has_mode_atom = true; });
    if (!has_mode_atom) out.AddProperty(std::move(copy));
  }
}

}  // namespace

System::System(std::string name) : name_(std::move(name)) {
  if (name_.empty()) Fail("a system needs a name");
}

System System::Of(const Automaton& automaton) {
  System s(automaton.name());
  s.AddComponent("", automaton);
  const Component& c = s.components_.front();
  auto same = [](const std::string& m) { return m; };
  for (const Property& p : automaton.properties()) {
    Property copy = p;
    copy.predicate = Remap(p.predicate, c.global_slot, s.symbols_, same);
    s.properties_.push_back(std::move(copy));
  }
  if (automaton.scenario()) s.scenario_ = automaton.scenario();  // slots coincide
  return s;
}

void System::Share(std::string name) { shared_.insert(std::move(name)); }

void System::AddComponent(std::string instance, const Automaton& automaton,
                          std::map<std::string, std::string> binds) {
  CheckNewInstance(components_, instance);
  CheckBinds(automaton, binds, shared_);
  auto rename = [&](const std::string& n) {
    if (auto it = binds.find(n); it != binds.end()) return it->second;
    return instance.empty() || shared_.count(n) ? n : instance + "." + n;
  };
  // An unnamed instance without binds keeps every name: a plain copy (System::Of does this for
  // every automaton it is given, e.g. each model a diagnosis simulates).
  const bool keeps_names = instance.empty() && binds.empty();
  if (!keeps_names) CheckDistinctNames(automaton, rename);
  Component c{instance,
              keeps_names ? automaton : Renamed(automaton, rename, rename),
              {},
              automaton,
              std::move(binds)};
  const SymbolTable& local = c.automaton.symbols();
  const std::vector<double> parameters = c.automaton.ParameterEnvironment();
  for (int s = 0; s < local.size(); ++s) {
    if (auto g = symbols_.Find(local[s].name)) {
      if (symbols_[*g].kind != local[s].kind) {
        Fail("'" + local[s].name + "' is " + WithArticle(KindName(local[s].kind)) + " in '" +
             automaton.name() + "' but " + WithArticle(KindName(symbols_[*g].kind)) + " elsewhere");
      }
      if (local[s].kind == SymbolKind::kParameter) {
        CheckSharedParameter(c, s, parameters[s], *g, components_, symbols_);
      }
      c.global_slot.push_back(*g);
    } else {
      c.global_slot.push_back(symbols_.Add(local[s]));
    }
  }
  CheckSharedFlows(c, components_);
  CheckSharedMeaning(c, components_, symbols_);
  CheckSynchronisedResets(c, components_, symbols_);
  components_.push_back(std::move(c));
}

std::vector<System::Step> System::StepsFrom(std::span<const int> tuple) const {
  if (tuple.size() != components_.size()) Fail("a mode tuple needs one mode per component");
  return hybrid::StepsFrom(components_, symbols_, Alphabets(components_), tuple);
}

Mode System::ProductModeOf(std::span<const int> tuple) const {
  if (tuple.size() != components_.size()) Fail("a mode tuple needs one mode per component");
  return ProductMode(Tuple(tuple.begin(), tuple.end()), components_, symbols_);
}

Expression System::ResolvedParameter(int slot) const {
  if (slot < 0 || slot >= symbols_.size() || symbols_[slot].kind != SymbolKind::kParameter) {
    Fail("slot " + std::to_string(slot) + " is not a parameter");
  }
  for (const Component& c : components_) {
    const int local = LocalSlot(c, slot);
    if (local < 0) continue;
    if (c.automaton.ParameterRange(local)) return Expression::Symbol(symbols_[slot].name, slot);
    for (const auto& [s, value] : c.automaton.parameters()) {
      if (s != local) continue;
      // Parameters are defined from earlier ones only, so this recursion ends.
      const Expression resolved =
          Global(c, value, symbols_)
              .Substitute([&](const std::string&, int g) -> std::optional<Expression> {
                if (symbols_[g].kind != SymbolKind::kParameter) return std::nullopt;
                return ResolvedParameter(g);
              })
              .FoldConstants();
      if (resolved.Slots().empty()) {
        return Expression::Constant(c.automaton.ParameterEnvironment()[local]);
      }
      return resolved;
    }
  }
  Fail("no component declares parameter '" + symbols_[slot].name + "'");
}

namespace {

// Whether initial state `init` of automaton `a` may satisfy its mode's invariant: false only
// when its values are points and a comparison that reads no input fails clearly; `violated`
// gets that comparison's text.
bool MayStartIn(const Automaton& a, const InitialState& init, std::string& violated) {
  std::vector<double> env = a.ParameterEnvironment();
  for (const InitialValue& v : init.values) {
    if (!v.is_point) return true;
    env[static_cast<std::size_t>(v.slot)] = v.range.lo.Evaluate(env);
  }
  const Mode& mode = a.mode(init.mode);
  for (const auto& [slot, value] : mode.discrete_values)
    env[static_cast<std::size_t>(slot)] = value;
  for (const Comparison& c : mode.invariant.comparisons) {
    bool reads_input = false;
    for (const Expression* side : {&c.lhs, &c.rhs}) {
      for (const int s : side->Slots()) {
        reads_input = reads_input || a.symbols()[s].kind == SymbolKind::kInput;
      }
    }
    if (reads_input) continue;
    const double scale = 1.0 + std::abs(c.lhs.Evaluate(env)) + std::abs(c.rhs.Evaluate(env));
    if (!c.Holds(env, 1e-9 * scale, Boundary::kClosure)) {
      violated = "the initial state of mode " + mode.name + " violates its invariant '" +
                 c.ToString() + "'";
      return false;
    }
  }
  return true;
}

}  // namespace

std::optional<std::string> System::NoAdmissibleStart() const {
  for (const Component& c : components_) {
    std::string violated;
    bool may = c.automaton.initial_states().empty();  // no init: the engines say so themselves
    for (const InitialState& init : c.automaton.initial_states()) {
      may = may || MayStartIn(c.automaton, init, violated);
    }
    if (!may) return Named(c) + ": " + violated;
  }
  return std::nullopt;
}

std::set<std::string> System::Alphabet(int c) const {
  return Alphabets(std::span<const Component>(&components_.at(static_cast<std::size_t>(c)), 1))
      .front();
}

std::optional<std::pair<int, ModeId>> System::FindMode(std::string_view qualified) const {
  for (int i = 0; i < static_cast<int>(components_.size()); ++i) {
    const Component& c = components_[i];
    std::string_view local = qualified;
    if (!c.instance.empty()) {
      if (!qualified.starts_with(c.instance + ".")) continue;
      local = qualified.substr(c.instance.size() + 1);
    }
    if (auto m = c.automaton.FindMode(local)) return std::make_pair(i, *m);
  }
  return std::nullopt;
}

std::string System::QualifiedModeName(int c, ModeId m) const {
  const Component& comp = components_.at(c);
  const std::string& local = comp.automaton.mode(m).name;
  return comp.instance.empty() ? local : comp.instance + "." + local;
}

void System::AddProperty(Property property) {
  const std::string context = "property '" + property.name + "'";
  if (property.predicate.depth() > kMaxExpressionDepth) {
    Fail(context, "expression too long or nested too deeply (" +
                      std::to_string(property.predicate.depth()) + " levels, more than " +
                      std::to_string(kMaxExpressionDepth) + ")");
  }
  for (const Property& p : properties_) {
    if (p.name == property.name) Fail("duplicate property '" + p.name + "'");
  }
  property.predicate.ForEachComparison([&](const Comparison& c) {
    for (int slot : c.Residual().Slots()) {
      if (slot >= symbols_.size()) Fail(context, "reads an undeclared slot");
      if (symbols_[slot].kind == SymbolKind::kInput) {
        Fail(context, "input '" + symbols_[slot].name + "' is not allowed here");
      }
    }
  });
  property.predicate.ForEachMode([&](const std::string& m) {
    if (!FindMode(m)) Fail(context, "unknown mode '" + m + "'");
  });
  properties_.push_back(std::move(property));
}

std::pair<double, double> System::InputBounds(int slot) const {
  if (slot < 0 || slot >= symbols_.size() || symbols_[slot].kind != SymbolKind::kInput) {
    Fail("bounds asked for something that is not an input of system '" + name_ + "'");
  }
  for (const Component& c : components_) {
    auto it = std::find(c.global_slot.begin(), c.global_slot.end(), slot);
    if (it == c.global_slot.end()) continue;
    const int local = static_cast<int>(it - c.global_slot.begin());
    for (const InputInfo& in : c.automaton.inputs()) {
      if (in.slot != local) continue;
      const std::string context = "bounds of input '" + symbols_[slot].name + "'";
      return {c.automaton.EvaluateConstant(in.bounds.lo, context),
              c.automaton.EvaluateConstant(in.bounds.hi, context)};
    }
  }
  Fail("no component declares input '" + symbols_[slot].name + "'");
}

void System::SetParameter(std::string_view name, double value) {
  // Set on copies and commit only if every component accepts the value: a shared parameter must
  // not be left set in some components only.
  std::vector<Component> updated = components_;
  int found = 0;
  for (Component& c : updated) {
    const std::optional<int> slot = c.automaton.symbols().Find(name);
    if (!slot || c.automaton.symbols()[*slot].kind != SymbolKind::kParameter) continue;
    try {
      c.automaton.SetParameter(name, value);
      c.source.SetParameter(c.source.symbols()[*slot].name, value);
    } catch (const std::invalid_argument& e) {
      Fail(e.what());
    }
    ++found;
  }
  if (found == 0) Fail("no component has a parameter '" + std::string(name) + "'");
  components_ = std::move(updated);
}

void System::SetInitialValue(std::string_view variable, double value) {
  if (!std::isfinite(value)) {
    Fail("initial value of '" + std::string(variable) + "' is not finite");
  }
  int found = 0;
  for (Component& c : components_) {
    const std::optional<int> slot = c.automaton.symbols().Find(variable);
    if (!slot || c.automaton.symbols()[*slot].kind != SymbolKind::kVariable) continue;
    // Renaming preserves slots, so the slot is also the variable's slot in `source`.
    const Expression point = Expression::Constant(value);
    const InitialValue initial{*slot, Range{point, point}, true};
    try {
      c.automaton.SetInitialValue(*slot, initial);
      c.source.SetInitialValue(*slot, initial);
    } catch (const std::invalid_argument& e) {
      Fail(e.what());
    }
    ++found;
  }
  if (found == 0) {
    Fail("no component has a continuous variable '" + std::string(variable) + "'");
  }
}

void System::SelectInitialState(int component, int index) {
  if (component < 0 || component >= static_cast<int>(components_.size())) {
    Fail("no component number " + std::to_string(component + 1));
  }
  Component& c = components_[static_cast<std::size_t>(component)];
  try {
    c.automaton.KeepInitialState(index);
    c.source.KeepInitialState(index);
  } catch (const std::invalid_argument& e) {
    Fail(e.what());
  }
}

void System::SetScenario(Scenario scenario) {
  if (!(scenario.until > 0.0) || !std::isfinite(scenario.until)) {
    Fail("'until' must be positive and finite");
  }
  std::set<int> seen;
  for (const InputSignal& s : scenario.inputs) {
    if (s.slot < 0 || s.slot >= symbols_.size() || symbols_[s.slot].kind != SymbolKind::kInput) {
      Fail("signal for something that is not an input");
    }
    const std::string& name = symbols_[s.slot].name;
    if (!seen.insert(s.slot).second) Fail("input '" + name + "' driven twice");
    if (s.points.empty()) Fail("signal for '" + name + "' has no points");
    const auto [lo, hi] = InputBounds(s.slot);
    for (size_t i = 0; i < s.points.size(); ++i) {
      const auto [t, v] = s.points[i];
      if (!std::isfinite(t) || !std::isfinite(v)) {
        Fail("signal for '" + name + "' has a non-finite point");
      }
      if (i > 0 && !(s.points[i - 1].first < t)) {
        Fail("signal for '" + name + "': times must increase strictly");
      }
      if (v < lo || v > hi) {
        Fail("signal for '" + name + "' takes value " + FormatNumber(v) + " outside its bounds [" +
             FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
      }
    }
  }
  scenario_ = std::move(scenario);
}

std::vector<int> System::InteractionGroups() const {
  std::vector<int> parent(components_.size());
  for (std::size_t c = 0; c < parent.size(); ++c) parent[c] = static_cast<int>(c);
  auto find = [&](int c) {
    while (parent[c] != c) c = parent[c] = parent[parent[c]];
    return c;
  };
  auto join = [&](int a, int b) {  // the smaller root stays the root
    const int ra = find(a);
    const int rb = find(b);
    parent[std::max(ra, rb)] = std::min(ra, rb);
  };
  std::map<int, int> slot_user;           // System slot -> a component that has it
  std::map<std::string, int> label_user;  // label -> a component that uses it
  for (int c = 0; c < static_cast<int>(components_.size()); ++c) {
    for (const int g : components_[c].global_slot) {
      const SymbolKind kind = symbols_[g].kind;
      if (kind != SymbolKind::kVariable && kind != SymbolKind::kDiscrete) continue;
      const auto [it, added] = slot_user.emplace(g, c);
      if (!added) join(c, it->second);
    }
    for (const std::string& label : Alphabet(c)) {
      const auto [it, added] = label_user.emplace(label, c);
      if (!added) join(c, it->second);
    }
  }
  std::vector<int> group(components_.size());
  for (std::size_t c = 0; c < group.size(); ++c) group[c] = find(static_cast<int>(c));
  return group;
}

System System::Restricted(std::span<const int> which) const {
  System out(name_);
  out.shared_ = shared_;
  for (const int c : which) {
    Component copy = components_.at(static_cast<std::size_t>(c));
    for (int& g : copy.global_slot) {
      const Symbol& symbol = symbols_[g];
      const auto found = out.symbols_.Find(symbol.name);
      g = found ? *found : out.symbols_.Add(symbol);
    }
    out.components_.push_back(std::move(copy));
  }
  return out;
}

Automaton System::Product(int max_modes, std::vector<std::vector<int>>* tuples) const {
  if (components_.empty()) Fail("system '" + name_ + "' has no components");
  Automaton out(name_);
  DeclareSymbols(symbols_, components_, out);
  ProductBuilder builder(symbols_, components_, max_modes, out);
  builder.AddInitialStates();
  builder.Explore();
  if (tuples) *tuples = builder.Tuples();
  AddProductProperties(properties_, out);
  if (scenario_) out.SetScenario(*scenario_);
  return out;
}

}  // namespace hybrid
