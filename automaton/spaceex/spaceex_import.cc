#include "hybrid/spaceex/spaceex_import.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include "automaton/number_syntax.h"
#include "automaton/quoted_text.h"
#include "automaton/spaceex/spaceex_config.h"
#include "automaton/spaceex/spaceex_document.h"
#include "automaton/spaceex/sx_formula.h"
#include "hybrid/automaton/parser.h"

namespace hybrid::spaceex {
namespace {

using Kind = SxFormula::Kind;

// The model language's keywords (docs/model_language.md, "Lexical rules").
const std::set<std::string, std::less<>> kKeywords = {
    "automaton", "system", "import",     "var",    "discrete", "param",  "input",
    "mode",      "inv",    "transition", "guard",  "reset",    "label",  "urgent",
    "lazy",      "init",   "scenario",   "until",  "step",     "linear", "property",
    "always",    "never",  "reach",      "within", "instance", "share",  "and",
    "or",        "not",    "in",         "true",   "false"};

std::string Trimmed(std::string_view s) {
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return std::string(s);
}

bool IsIdentifier(std::string_view s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

[[noreturn]] void Fail(const Origin& at, const std::string& message) {
  throw ParseError(at.file, at.line, at.column, message);
}

// A formula with the way back to the file it was read from.
struct Located {
  SxFormula formula;
  std::function<Origin(std::size_t)> where;
  Origin At(const SxFormula& node) const { return where(node.offset); }
};

// Model-language lines with the origin of each.
struct Lines {
  std::vector<std::string> text;
  std::vector<Origin> origins;
  void Add(std::string line, Origin origin) {
    text.push_back(std::move(line));
    origins.push_back(std::move(origin));
  }
  void Append(const Lines& other) {
    text.insert(text.end(), other.text.begin(), other.text.end());
    origins.insert(origins.end(), other.origins.begin(), other.origins.end());
  }
};

// Names of one namespace: SpaceEx names to model-language names (keywords get a '_' appended).
class Names {
 public:
  // Adds `name` (checked at `at`), returning its model-language spelling.
  const std::string& Add(const std::string& name, const Origin& at, const char* what) {
    if (!IsIdentifier(name)) {
      Fail(at, std::string(what) + " '" + name +
                   "' is not a name of the model language (letters, digits and '_', not "
                   "starting with a digit)");
    }
    if (map_.count(name)) Fail(at, std::string("duplicate ") + what + " '" + name + "'");
    std::string ours = name;
    while (kKeywords.count(ours) || taken_.count(ours)) ours += '_';
    taken_.insert(ours);
    return map_.emplace(name, ours).first->second;
  }
  const std::string* Find(const std::string& name) const {
    const auto it = map_.find(name);
    return it == map_.end() ? nullptr : &it->second;
  }

 private:
  std::map<std::string, std::string> map_;
  std::set<std::string> taken_;
};

// True if `e` is a number equal to 0.
bool IsZero(const SxFormula& e) {
  return e.kind == Kind::kNumber && std::strtod(e.text.c_str(), nullptr) == 0.0;
}

// The flow of one variable in one location: `x' == e` or bounds `lo <= x' <= hi`.
struct Flow {
  const SxFormula* equal = nullptr;
  const SxFormula* lo = nullptr;
  const SxFormula* hi = nullptr;
  Origin at;
};

// A base component with its formulas parsed and its names translated.
struct Template {
  const SxComponent* sx = nullptr;
  Names names;                                     // params
  Names modes;                                     // location names
  std::map<std::string, std::string> mode_of_id;   // location id -> our mode name
  std::vector<std::optional<Located>> invariants;  // per location
  std::vector<std::map<std::string, Flow>> flows;  // per location: variable -> flow
  std::vector<std::optional<Located>> flow_formulas;
  std::vector<std::optional<Located>> guards;  // per transition
  std::vector<std::optional<Located>> assignments;
  std::set<std::string> used;  // params read or written somewhere, and non-local labels
  std::set<std::string> transition_labels;  // labels some transition takes
};

// Where a parameter of an instance goes: a name of the system or a constant.
struct Target {
  std::string sx_name;   // the SpaceEx name in the network ("k", "P1.x"); empty for a constant
  std::string our_name;  // the model-language name in the system
  std::string constant;  // the constant's text (model language) when mapped to a number
};

struct Instance {
  const SxBind* bind = nullptr;  // nullptr: the system is this base component alone
  const Template* tmpl = nullptr;
  std::string sx_name;  // `as`
  std::string name;     // our instance name ("" alone)
  Origin at;
  std::map<std::string, Target> targets;  // template param -> where it goes
  std::set<std::string> dropped_flows;    // template variables whose (zero) flows are left out
};

// An initial bound: a point (lo == hi, point) or an interval.
struct Bound {
  std::string lo;
  std::string hi;
  bool point = false;
};

class Translator {
 public:
  Translator(const SpaceExDocument& doc, const SpaceExConfig* cfg) : doc_(doc), cfg_(cfg) {}

  Translation Run();

 private:
  Origin At(std::size_t offset) const {
    const auto [line, column] = doc_.LineColumn(offset);
    return {doc_.file(), line, column};
  }
  Origin CfgAt(std::size_t offset) const {
    const auto [line, column] = cfg_->LineColumn(offset);
    return {cfg_->file(), line, column};
  }
  Located Parse(const SxText& text, bool expression = false) const;
  Located ParseOption(const SpaceExConfig::Value& value) const;

  const SxComponent& ChooseSystem();
  Template& TemplateOf(const SxComponent& c, const Origin& used_at);
  void ReadFlows(Template& t, std::size_t location, const Located& flow) const;
  void ReadTransition(Template& t, const SxTransition& tr) const;
  void CheckNames(const Template& t, const Located& f, bool allow_primes) const;
  void BuildInstances(const SxComponent& system);
  Target MapParam(const Instance& inst, const SxParam& p, const SxMap* map) const;
  void ReadForbidden();
  void ReadHorizon();
  void AssignFlows();
  void ReadInitially();
  std::string InitialBoundSide(const Located& f, const SxFormula& side) const;

  std::string TemplateName(const Template& t, const std::string& name) const;
  static std::string Expr(const Template& t, const SxFormula& e);
  static std::string Conjunction(const Template& t, const Located& f);
  Lines AutomatonBody(const Instance& inst) const;
  void ModeLines(const Instance& inst, std::size_t l, Lines& out) const;
  void TransitionLines(const Instance& inst, std::size_t i, Lines& out) const;
  void InitLines(const Instance& inst, Lines& out) const;
  void DeclaredLabelLines(const Instance& inst, Lines& out) const;
  std::string ParamLine(const Instance& inst, const SxParam& p) const;
  const Bound& InitialBound(const Instance& inst, const std::string& param) const;
  std::string Forbidden(const Located& f, const SxFormula& node) const;
  void PropertyAndScenarioLines(Lines& out) const;
  std::string ForbiddenName(const Located& f, const SxFormula& n) const;
  Lines SystemLines(const SxComponent& system, const std::vector<std::string>& automaton_of) const;
  Translation Emit(const SxComponent& system);

  const SpaceExDocument& doc_;
  const SpaceExConfig* cfg_;
  const SxComponent* instance_network_ = nullptr;  // the system, when it is a network
  std::map<std::string, Template> templates_;
  std::vector<Instance> instances_;
  Names network_;  // network parameters
  Names instance_names_;
  std::map<std::string, std::string> our_system_names_;  // SpaceEx system name -> ours
  std::map<std::string, Bound> initial_;                 // SpaceEx system name -> bound
  std::map<std::string, std::string> initial_location_;  // instance `as` -> location name
  std::optional<Origin> initially_at_;
  std::optional<Located> forbidden_;    // the option `forbidden`, if given
  std::optional<std::string> horizon_;  // a positive `time-horizon`, in the model language
  Origin horizon_at_;
  std::set<std::string> declared_;  // SpaceEx system names some instance declares
  std::vector<std::string> notes_;
};

Located Translator::Parse(const SxText& text, bool expression) const {
  Located located;
  located.where = [this, text](std::size_t i) { return At(doc_.OffsetOf(text, i)); };
  try {
    located.formula =
        expression ? SxFormula::ParseExpression(text.value) : SxFormula::Parse(text.value);
  } catch (const FormulaError& e) {
    Fail(located.where(e.offset()), e.what());
  }
  return located;
}

Located Translator::ParseOption(const SpaceExConfig::Value& value) const {
  Located located;
  const std::size_t start = value.offset;
  located.where = [this, start](std::size_t i) { return CfgAt(start + i); };
  try {
    located.formula = SxFormula::Parse(value.text);
  } catch (const FormulaError& e) {
    Fail(located.where(e.offset()), e.what());
  }
  return located;
}

const SxComponent& Translator::ChooseSystem() {
  const std::optional<SpaceExConfig::Value> chosen = cfg_ ? cfg_->Find("system") : std::nullopt;
  if (!chosen) return doc_.components().back();
  const SxComponent* c = doc_.Find(chosen->text);
  if (!c) Fail(CfgAt(chosen->offset), "no component '" + chosen->text + "' in " + doc_.file());
  return *c;
}

// Checks that every name of `f` is a variable or constant of `t` and, unless `allow_primes`,
// that none is primed.
void Translator::CheckNames(const Template& t, const Located& f, bool allow_primes) const {
  f.formula.ForEachName([&](const SxFormula& n) {
    const SxParam* p = t.sx->FindParam(n.text);
    if (!p)
      Fail(f.At(n),
           "undefined name '" + n.text + "' (not a parameter of component '" + t.sx->id + "')");
    if (p->type == SxParam::Type::kLabel) Fail(f.At(n), "label '" + n.text + "' used as a value");
    if (n.primed && !allow_primes) Fail(f.At(n), "'" + n.text + "'' (primed) is not allowed here");
  });
}

void Translator::ReadFlows(Template& t, std::size_t location, const Located& flow) const {
  CheckNames(t, flow, true);
  std::map<std::string, Flow>& flows = t.flows[location];
  for (const SxFormula* c : flow.formula.Conjuncts()) {
    const bool compare = c->kind == Kind::kCompare && c->children.size() == 2;
    const SxFormula* lhs = compare ? &c->children[0] : nullptr;
    const SxFormula* rhs = compare ? &c->children[1] : nullptr;
    std::string op = compare ? c->text : "";
    if (compare && !lhs->primed && rhs->kind == Kind::kName && rhs->primed) {
      std::swap(lhs, rhs);
      op = op == "<=" ? ">=" : op == ">=" ? "<=" : op == "<" ? ">" : op == ">" ? "<" : op;
    }
    if (!compare || lhs->kind != Kind::kName || !lhs->primed || rhs->HasPrime()) {
      Fail(flow.At(*c), "unsupported flow constraint: write x' == e, or bounds x' >= a & x' <= b");
    }
    if (t.sx->FindParam(lhs->text)->type != SxParam::Type::kVariable) {
      Fail(flow.At(*lhs), "'" + lhs->text + "' is a constant: it has no flow");
    }
    if (op == "<" || op == ">")
      Fail(flow.At(*c), "strict bounds on a rate are not supported: use <= or >=");
    Flow& f = flows[lhs->text];
    f.at = flow.At(*c);
    const SxFormula** slot = op == "==" ? &f.equal : op == "<=" ? &f.hi : &f.lo;
    if (*slot)
      Fail(flow.At(*c),
           "a second " + std::string(op == "==" ? "flow" : "bound") + " for '" + lhs->text + "''");
    *slot = rhs;
  }
  for (const auto& [name, f] : flows) {
    if (f.equal && (f.lo || f.hi))
      Fail(f.at, "flow of '" + name + "' given both as x' == e and as bounds");
    if (!f.equal && !(f.lo && f.hi)) {
      Fail(f.at, "rate of '" + name + "' needs both bounds (x' >= a & x' <= b)");
    }
    for (const SxFormula* bound : {f.lo, f.hi}) {
      if (!bound) continue;
      bound->ForEachName([&](const SxFormula& n) {
        if (t.sx->FindParam(n.text)->type != SxParam::Type::kConstant) {
          Fail(flow.At(n), "a rate bound may read constants only, not '" + n.text + "'");
        }
      });
    }
  }
}

// Checks that `f` is a conjunction of comparisons over unprimed names (a guard or invariant).
void CheckConjunction(const Located& f, const char* what) {
  for (const SxFormula* c : f.formula.Conjuncts()) {
    if (c->kind == Kind::kOr) {
      Fail(f.At(*c), std::string("'|' is not supported in ") + what + ": split the transition");
    }
    if (c->kind != Kind::kCompare && c->kind != Kind::kFalse) {
      Fail(f.At(*c), std::string("expected a comparison in ") + what);
    }
  }
}

// Reads transition `tr` of template `t`: its guard and assignment, checked, and its label.
void Translator::ReadTransition(Template& t, const SxTransition& tr) const {
  const SxComponent& c = *t.sx;
  for (const std::string* id : {&tr.source, &tr.target}) {
    if (!c.FindLocation(*id))
      Fail(At(tr.offset), "no location with id '" + *id + "' in '" + c.id + "'");
  }
  auto use = [&t](const Located& f) {
    f.formula.ForEachName([&t](const SxFormula& n) { t.used.insert(n.text); });
  };
  std::optional<Located> guard, assignment;
  if (tr.guard) {
    guard = Parse(*tr.guard);
    CheckNames(t, *guard, false);
    CheckConjunction(*guard, "guards");
    use(*guard);
  }
  if (tr.assignment) {
    assignment = Parse(*tr.assignment);
    CheckNames(t, *assignment, true);
    use(*assignment);
  }
  if (tr.label) {
    const std::string label = Trimmed(tr.label->value);
    const SxParam* p = c.FindParam(label);
    if (!p || p->type != SxParam::Type::kLabel) {
      Fail(At(doc_.OffsetOf(*tr.label, 0)),
           "'" + label + "' is not a label of component '" + c.id + "'");
    }
    t.used.insert(label);
    t.transition_labels.insert(label);
  }
  t.guards.push_back(std::move(guard));
  t.assignments.push_back(std::move(assignment));
}

Template& Translator::TemplateOf(const SxComponent& c, const Origin& used_at) {
  if (c.IsNetwork()) {
    Fail(used_at, "component '" + c.id + "' is a network: nested networks are not supported");
  }
  const auto [it, added] = templates_.try_emplace(c.id);
  Template& t = it->second;
  if (!added) return t;
  t.sx = &c;
  for (const SxParam& p : c.params) t.names.Add(p.name, At(p.offset), "parameter");
  t.invariants.resize(c.locations.size());
  t.flows.resize(c.locations.size());
  t.flow_formulas.resize(c.locations.size());
  auto use = [&t](const Located& f) {
    f.formula.ForEachName([&t](const SxFormula& n) { t.used.insert(n.text); });
  };
  for (std::size_t l = 0; l < c.locations.size(); ++l) {
    const SxLocation& loc = c.locations[l];
    t.mode_of_id[loc.id] = t.modes.Add(loc.name, At(loc.offset), "location");
    if (loc.invariant) {
      t.invariants[l] = Parse(*loc.invariant);
      CheckNames(t, *t.invariants[l], false);
      CheckConjunction(*t.invariants[l], "invariants");
      use(*t.invariants[l]);
    }
    if (loc.flow) {
      t.flow_formulas[l] = Parse(*loc.flow);
      ReadFlows(t, l, *t.flow_formulas[l]);
      use(*t.flow_formulas[l]);
    }
  }
  for (const SxTransition& tr : c.transitions) ReadTransition(t, tr);
  // A non-local label is in the component's alphabet whether or not a transition takes it: in a
  // network it blocks the other components' transitions on it (AutomatonBody declares it).
  for (const SxParam& p : c.params) {
    if (p.type == SxParam::Type::kLabel && !p.local) t.used.insert(p.name);
  }
  return t;
}

void Translator::BuildInstances(const SxComponent& system) {
  if (!system.IsNetwork()) {
    Instance inst;
    inst.tmpl = &TemplateOf(system, At(system.offset));
    inst.at = At(system.offset);
    for (const SxParam& p : system.params) {
      const std::string& ours = *inst.tmpl->names.Find(p.name);
      inst.targets[p.name] = {p.name, ours, ""};
      if (p.type != SxParam::Type::kLabel) our_system_names_[p.name] = ours;
    }
    instances_.push_back(std::move(inst));
    return;
  }
  instance_network_ = &system;
  for (const SxParam& p : system.params) {
    const std::string& ours = network_.Add(p.name, At(p.offset), "parameter");
    if (p.type != SxParam::Type::kLabel) our_system_names_[p.name] = ours;
  }
  for (const SxBind& b : system.binds) {
    const SxComponent* c = doc_.Find(b.component);
    if (!c) Fail(At(b.offset), "bind '" + b.as + "' of unknown component '" + b.component + "'");
    Instance inst;
    inst.bind = &b;
    inst.tmpl = &TemplateOf(*c, At(b.offset));
    inst.sx_name = b.as;
    inst.name = instance_names_.Add(b.as, At(b.offset), "instance");
    inst.at = At(b.offset);
    for (const SxMap& m : b.maps) {
      if (!c->FindParam(m.key))
        Fail(At(m.offset), "component '" + c->id + "' has no parameter '" + m.key + "'");
    }
    for (const SxParam& p : c->params) {
      const auto map = std::find_if(b.maps.begin(), b.maps.end(),
                                    [&p](const SxMap& m) { return m.key == p.name; });
      inst.targets[p.name] = MapParam(inst, p, map == b.maps.end() ? nullptr : &*map);
      const Target& target = inst.targets[p.name];
      for (const auto& [other, other_target] : inst.targets) {
        if (other == p.name || target.sx_name.empty() || other_target.sx_name != target.sx_name)
          continue;
        Fail(map == b.maps.end() ? inst.at : At(map->offset),
             "'" + other + "' and '" + p.name + "' of '" + b.as + "' are both mapped to '" +
                 target.sx_name + "'");
      }
      if (p.local && p.type != SxParam::Type::kLabel)
        our_system_names_[target.sx_name] = target.our_name;
    }
    instances_.push_back(std::move(inst));
  }
}

Target Translator::MapParam(const Instance& inst, const SxParam& p, const SxMap* map) const {
  const std::string& ours = *inst.tmpl->names.Find(p.name);
  if (p.local) {
    if (map)
      Fail(At(map->offset),
           "'" + p.name + "' is local to '" + inst.tmpl->sx->id + "': it cannot be mapped");
    return {inst.sx_name + "." + p.name, inst.name + "." + ours, ""};
  }
  const SxParam* target = nullptr;
  if (!map) {
    target = instance_network_->FindParam(p.name);
    if (!target) {
      Fail(inst.at, "bind '" + inst.sx_name + "' does not map '" + p.name + "' of component '" +
                        inst.tmpl->sx->id + "'");
    }
  } else {
    const Located value = Parse(map->value, true);
    const SxFormula& f = value.formula;
    if (f.kind == Kind::kName && !f.primed) {
      target = instance_network_->FindParam(f.text);
      if (!target)
        Fail(value.At(f), "undefined name '" + f.text + "' (not a parameter of '" +
                              instance_network_->id + "')");
    } else {
      bool constant = p.type == SxParam::Type::kConstant && f.kind != Kind::kCompare &&
                      f.kind != Kind::kAssign && f.kind != Kind::kAnd && f.kind != Kind::kOr &&
                      f.kind != Kind::kLocation && f.kind != Kind::kTrue && f.kind != Kind::kFalse;
      f.ForEachName([&](const SxFormula&) { constant = false; });
      if (!constant) {
        Fail(value.where(0), "'" + p.name + "' must be mapped to a parameter of '" +
                                 instance_network_->id + "'" +
                                 (p.type == SxParam::Type::kConstant ? " or a number" : ""));
      }
      return {"", "", WriteExpression(f, [](const SxFormula& n) { return n.text; })};
    }
  }
  if (target->type != p.type) {
    Fail(map ? At(map->offset) : inst.at, "'" + p.name + "' of '" + inst.tmpl->sx->id + "' and '" +
                                              target->name + "' of '" + instance_network_->id +
                                              "' are of different kinds");
  }
  return {target->name, *network_.Find(target->name), ""};
}

// Reads the option `time-horizon`, SpaceEx's bound on the time its analysis explores. A positive
// number becomes the horizon of the default run (the scenario's `until`) and of the property
// `forbidden` (`within`), so that the simulator and every checking engine read the same bound; a
// negative one (SpaceEx writes -1) means no bound. Anything else is an error at the value.
void Translator::ReadHorizon() {
  const std::optional<SpaceExConfig::Value> value = cfg_->Find("time-horizon");
  if (!value) return;
  const std::string quoted = EscapedForMessage(value->text);
  const NumberRead<double> r = ReadDecimal(value->text);
  if (!r.ok() || r.value == 0.0) {
    Fail(CfgAt(value->offset),
         "time-horizon: " +
             (r.ok() ? "'" + quoted + "' is zero" : NumberErrorMessage(quoted, r.error)) +
             ": give the time the analysis covers as a positive number (negative: no bound)");
  }
  if (r.value < 0.0) {
    notes_.push_back("time-horizon = " + quoted +
                     " (negative) sets no bound: properties hold over unbounded time, and a "
                     "simulation needs a horizon of its own.");
    return;
  }
  horizon_ = FormatNumber(r.value);
  horizon_at_ = CfgAt(value->offset);
  notes_.push_back("time-horizon = " + quoted + " is the horizon of the default run (until " +
                   *horizon_ + ")" +
                   (forbidden_ ? " and of 'forbidden' (within " + *horizon_ + ")" : "") + ".");
}

// Reads the option `forbidden`. The names it reads count as used by every instance whose
// parameter they name, so that a constant or variable read only there is declared (and then
// needs a value, or a flow, like any other); declared_ collects the names declared.
void Translator::ReadForbidden() {
  std::set<std::string> read;
  if (const auto value = cfg_ ? cfg_->Find("forbidden") : std::nullopt) {
    forbidden_ = ParseOption(*value);
    forbidden_->formula.ForEachName([&](const SxFormula& n) { read.insert(n.text); });
  }
  for (const Instance& inst : instances_) {
    Template& t = templates_.at(inst.tmpl->sx->id);
    for (const SxParam& p : t.sx->params) {
      const std::string& sx_name = inst.targets.at(p.name).sx_name;
      if (p.type != SxParam::Type::kLabel && read.count(sx_name)) t.used.insert(p.name);
    }
  }
  for (const Instance& inst : instances_) {
    for (const auto& [param, target] : inst.targets) {
      if (inst.tmpl->used.count(param) && !target.sx_name.empty()) declared_.insert(target.sx_name);
    }
  }
}

// Decides which instance gives each variable its flow. SpaceEx leaves a variable that no flow
// constrains free to change arbitrarily, the model language keeps it constant: so a component
// that gives a variable a flow must give it one in every location, and some component must.
// Several components may constrain a variable only to x' == 0 (all but the first are dropped).
void Translator::AssignFlows() {
  std::map<std::string, std::vector<std::size_t>> owners;  // system variable -> instances
  std::map<std::string, Origin> first_use;
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const Instance& inst = instances_[i];
    const Template& t = *inst.tmpl;
    for (const SxParam& p : t.sx->params) {
      if (p.type != SxParam::Type::kVariable || !t.used.count(p.name)) continue;
      const std::string& sx_name = inst.targets.at(p.name).sx_name;
      first_use.try_emplace(sx_name, At(p.offset));
      std::size_t with_flow = 0;
      for (const auto& flows : t.flows) with_flow += flows.count(p.name);
      if (with_flow == 0) continue;
      for (std::size_t l = 0; l < t.flows.size(); ++l) {
        if (t.flows[l].count(p.name)) continue;
        Fail(At(t.sx->locations[l].offset),
             "location '" + t.sx->locations[l].name + "' gives no flow for '" + p.name +
                 "', which SpaceEx leaves free to change there (add " + p.name +
                 "' == 0 to keep it constant)");
      }
      owners[sx_name].push_back(i);
    }
  }
  for (const auto& [sx_name, at] : first_use) {
    const std::vector<std::size_t>& own = owners[sx_name];
    if (own.empty()) {
      Fail(at, "no component gives '" + sx_name +
                   "' a flow: SpaceEx lets it change arbitrarily, which the import does not "
                   "support (add " +
                   sx_name +
                   "' == 0 to the flows of one component to keep it "
                   "constant)");
    }
    for (std::size_t k = 1; k < own.size(); ++k) {
      for (const std::size_t i : {own[0], own[k]}) {
        const Instance& inst = instances_[i];
        for (const auto& flows : inst.tmpl->flows) {
          for (const auto& [name, flow] : flows) {
            if (inst.targets.at(name).sx_name != sx_name || (flow.equal && IsZero(*flow.equal)))
              continue;
            Fail(flow.at,
                 "'" + sx_name + "' is given a flow by '" + instances_[own[0]].sx_name +
                     "' and by '" + instances_[own[k]].sx_name +
                     "': the import supports one component per variable (or x' == 0 in all)");
          }
        }
      }
      Instance& dropped = instances_[own[k]];
      for (const auto& [name, target] : dropped.targets) {
        if (target.sx_name == sx_name) dropped.dropped_flows.insert(name);
      }
    }
  }
}

// The constant side of a bound in `initially`: numbers and arithmetic only.
std::string Translator::InitialBoundSide(const Located& f, const SxFormula& side) const {
  side.ForEachName([&](const SxFormula& n) {
    Fail(f.At(n),
         "a bound in 'initially' must be a number here, not an expression of '" + n.text + "'");
  });
  return WriteExpression(side, [](const SxFormula& n) { return n.text; });
}

void Translator::ReadInitially() {
  const std::optional<SpaceExConfig::Value> value = cfg_ ? cfg_->Find("initially") : std::nullopt;
  if (!value) return;
  const Located f = ParseOption(*value);
  initially_at_ = f.where(0);
  for (const SxFormula* c : f.formula.Conjuncts()) {
    if (c->kind == Kind::kOr)
      Fail(f.At(*c), "'|' in 'initially' is not supported: give one initial set (a conjunction)");
    if (c->kind == Kind::kLocation) {
      const Instance* inst = nullptr;
      for (const Instance& i : instances_) {
        if (i.sx_name == c->text || (!i.bind && c->text == i.tmpl->sx->id)) inst = &i;
      }
      if (!inst) Fail(f.At(*c), "no instance '" + c->text + "' in loc(" + c->text + ")");
      const std::string& loc = c->children[0].text;
      if (!inst->tmpl->modes.Find(loc))
        Fail(f.At(c->children[0]), "'" + inst->tmpl->sx->id + "' has no location '" + loc + "'");
      if (!initial_location_.emplace(inst->sx_name, loc).second)
        Fail(f.At(*c), "a second initial location for '" + c->text + "'");
      continue;
    }
    if (c->kind != Kind::kCompare || c->HasPrime()) {
      Fail(f.At(*c), "expected loc(...) == location or a bound of one variable in 'initially'");
    }
    const bool left = c->children[0].kind == Kind::kName;
    const SxFormula& name = c->children[left ? 0 : 1];
    if (name.kind != Kind::kName)
      Fail(f.At(*c),
           "only bounds of single variables are supported in 'initially' (x == c, x >= c, x <= c)");
    if (!our_system_names_.count(name.text))
      Fail(f.At(name), "undefined name '" + name.text + "' in 'initially'");
    const std::string side = InitialBoundSide(f, c->children[left ? 1 : 0]);
    if (c->text == "<" || c->text == ">")
      Fail(f.At(*c), "strict bounds are not supported in 'initially': use <= or >=");
    Bound& b = initial_[name.text];
    const bool upper = (c->text == "<=") == left;
    if (c->text == "==") {
      if (!b.lo.empty() || !b.hi.empty())
        Fail(f.At(*c), "'" + name.text + "' is bounded twice in 'initially'");
      b = {side, side, true};
    } else {
      std::string& slot = upper ? b.hi : b.lo;
      if (!slot.empty()) Fail(f.At(*c), "'" + name.text + "' is bounded twice in 'initially'");
      slot = side;
    }
  }
}

std::string Translator::Expr(const Template& t, const SxFormula& e) {
  return WriteExpression(e, [&t](const SxFormula& n) { return *t.names.Find(n.text); });
}

// A guard or invariant: comparisons joined by `and`.
std::string Translator::Conjunction(const Template& t, const Located& f) {
  std::string out;
  for (const SxFormula* c : f.formula.Conjuncts()) {
    if (!out.empty()) out += " and ";
    out += c->kind == Kind::kFalse
               ? "1 < 0"
               : Expr(t, c->children[0]) + " " + c->text + " " + Expr(t, c->children[1]);
  }
  return out;
}

std::string Translator::ParamLine(const Instance& inst, const SxParam& p) const {
  const Target& target = inst.targets.at(p.name);
  const std::string& ours = *inst.tmpl->names.Find(p.name);
  if (!target.constant.empty()) return "  param " + ours + " = " + target.constant + ";";
  const auto b = initial_.find(target.sx_name);
  if (b == initial_.end() || b->second.lo.empty() || b->second.hi.empty()) {
    Fail(At(p.offset), "constant '" + p.name + "' has no value" +
                           (inst.bind ? " in '" + inst.sx_name + "'" : std::string()) +
                           ": map it to a number in the bind, or give it one in 'initially' (" +
                           target.sx_name + " == 2, or 1 <= " + target.sx_name + " & " +
                           target.sx_name + " <= 2)");
  }
  if (b->second.point) return "  param " + ours + " = " + b->second.lo + ";";
  return "  param " + ours + " = (" + b->second.lo + " + " + b->second.hi + ") / 2 in [" +
         b->second.lo + ", " + b->second.hi + "];";
}

void Translator::ModeLines(const Instance& inst, std::size_t l, Lines& out) const {
  const Template& t = *inst.tmpl;
  const SxLocation& loc = t.sx->locations[l];
  const Origin at = At(loc.offset);
  out.Add("  mode " + t.mode_of_id.at(loc.id) + " {", at);
  for (const SxParam& p : t.sx->params) {
    const auto it = t.flows[l].find(p.name);
    if (it == t.flows[l].end() || inst.dropped_flows.count(p.name) || !t.used.count(p.name))
      continue;
    const Flow& f = it->second;
    const std::string& x = *t.names.Find(p.name);
    out.Add(f.equal ? "    " + x + "' = " + Expr(t, *f.equal) + ";"
                    : "    " + x + "' in [" + Expr(t, *f.lo) + ", " + Expr(t, *f.hi) + "];",
            f.at);
  }
  if (t.invariants[l] && !t.invariants[l]->formula.Conjuncts().empty()) {
    out.Add("    inv " + Conjunction(t, *t.invariants[l]) + ";", t.invariants[l]->where(0));
  }
  out.Add("  }", at);
}

void Translator::TransitionLines(const Instance& inst, std::size_t i, Lines& out) const {
  const Template& t = *inst.tmpl;
  const SxTransition& tr = t.sx->transitions[i];
  const Origin at = At(tr.offset);
  out.Add("  transition " + t.mode_of_id.at(tr.source) + " -> " + t.mode_of_id.at(tr.target) + " {",
          at);
  if (const auto& guard = t.guards[i]; guard && !guard->formula.Conjuncts().empty()) {
    out.Add("    guard " + Conjunction(t, *guard) + ";", guard->where(0));
  }
  if (const auto& assignment = t.assignments[i]) {
    std::string resets;
    for (const SxFormula* c : assignment->formula.Conjuncts()) {
      const bool assign =
          c->kind == Kind::kAssign || (c->kind == Kind::kCompare && c->text == "==" &&
                                       c->children[0].kind == Kind::kName && c->children[0].primed);
      if (!assign || c->children[1].HasPrime()) {
        Fail(assignment->At(*c), "expected an assignment x := e (or x' == e)");
      }
      const SxFormula& x = c->children[0];
      if (t.sx->FindParam(x.text)->type != SxParam::Type::kVariable) {
        Fail(assignment->At(x), "'" + x.text + "' is a constant: it cannot be assigned");
      }
      const SxFormula& e = c->children[1];
      if (e.kind == Kind::kName && e.text == x.text && !e.primed) continue;  // x := x
      resets += (resets.empty() ? "" : ", ") + *t.names.Find(x.text) + " := " + Expr(t, e);
    }
    if (!resets.empty()) out.Add("    reset " + resets + ";", assignment->where(0));
  }
  if (tr.label) out.Add("    label " + *t.names.Find(Trimmed(tr.label->value)) + ";", at);
  if (!tr.asap) out.Add("    lazy;", at);
  out.Add("  }", at);
}

const Bound& Translator::InitialBound(const Instance& inst, const std::string& param) const {
  const std::string& sx_name = inst.targets.at(param).sx_name;
  const auto b = initial_.find(sx_name);
  if (b == initial_.end() || b->second.lo.empty() || b->second.hi.empty()) {
    Fail(*initially_at_,
         "'initially' gives no value to '" + sx_name +
             "' (each variable needs a point, x == c, or bounds, c1 <= x & x <= c2)");
  }
  return b->second;
}

void Translator::InitLines(const Instance& inst, Lines& out) const {
  const Template& t = *inst.tmpl;
  std::string values;
  for (const SxParam& p : t.sx->params) {
    if (p.type != SxParam::Type::kVariable || !t.used.count(p.name)) continue;
    const Bound& b = InitialBound(inst, p.name);
    const std::string& x = *t.names.Find(p.name);
    values +=
        b.point ? " " + x + " = " + b.lo + ";" : " " + x + " in [" + b.lo + ", " + b.hi + "];";
  }
  const auto chosen = initial_location_.find(inst.sx_name);
  for (const SxLocation& loc : t.sx->locations) {
    if (chosen != initial_location_.end() && chosen->second != loc.name) continue;
    out.Add("  init " + t.mode_of_id.at(loc.id) + " {" + values + " }", *initially_at_);
  }
}

// `label l1, l2;` for the non-local labels of an instance that none of its transitions takes:
// SpaceEx puts them in its alphabet, so that the others' transitions on them are blocked.
void Translator::DeclaredLabelLines(const Instance& inst, Lines& out) const {
  const Template& t = *inst.tmpl;
  std::string labels;
  std::optional<Origin> at;
  for (const SxParam& p : t.sx->params) {
    if (p.type != SxParam::Type::kLabel || p.local || t.transition_labels.count(p.name)) continue;
    labels += (labels.empty() ? "" : ", ") + *t.names.Find(p.name);
    if (!at) at = At(p.offset);
  }
  if (!labels.empty()) out.Add("  label " + labels + ";", *at);
}

Lines Translator::AutomatonBody(const Instance& inst) const {
  const Template& t = *inst.tmpl;
  Lines out;
  std::string vars;
  for (const SxParam& p : t.sx->params) {
    if (!t.used.count(p.name)) continue;
    if (p.type == SxParam::Type::kConstant) out.Add(ParamLine(inst, p), At(p.offset));
    if (p.type == SxParam::Type::kVariable)
      vars += (vars.empty() ? "" : ", ") + *t.names.Find(p.name);
  }
  if (!vars.empty()) out.Add("  var " + vars + ";", At(t.sx->offset));
  for (std::size_t l = 0; l < t.sx->locations.size(); ++l) ModeLines(inst, l, out);
  for (std::size_t i = 0; i < t.sx->transitions.size(); ++i) TransitionLines(inst, i, out);
  if (inst.bind) DeclaredLabelLines(inst, out);
  if (initially_at_) InitLines(inst, out);
  return out;
}

// A name read by `forbidden`, written in the model language: the system's name for it, or, for a
// parameter of the network that no instance declares, its value when `initially` gives it one.
std::string Translator::ForbiddenName(const Located& f, const SxFormula& n) const {
  const auto it = our_system_names_.find(n.text);
  if (it == our_system_names_.end())
    Fail(f.At(n), "undefined name '" + n.text + "' in 'forbidden'");
  if (n.primed) Fail(f.At(n), "'" + n.text + "'' (primed) is not allowed in 'forbidden'");
  if (declared_.count(n.text)) return it->second;
  const SxParam* p = instance_network_ ? instance_network_->FindParam(n.text) : nullptr;
  if (p && p->type == SxParam::Type::kVariable) {
    Fail(f.At(n), "no component gives '" + n.text +
                      "' a flow: SpaceEx lets it change arbitrarily, which the import does not "
                      "support (map it into a component that gives it a flow)");
  }
  const auto b = initial_.find(n.text);
  if (b == initial_.end() || !b->second.point) {
    Fail(f.At(n), "constant '" + n.text +
                      "' read in 'forbidden' is declared by no component: give it one value in "
                      "'initially' (" +
                      n.text + " == 2), or map it into a component");
  }
  return "(" + b->second.lo + ")";
}

// The predicate of `forbidden` over system names.
std::string Translator::Forbidden(const Located& f, const SxFormula& node) const {
  auto name = [&](const SxFormula& n) { return ForbiddenName(f, n); };
  switch (node.kind) {
    case Kind::kTrue:
      return "true";
    case Kind::kFalse:
      return "false";
    case Kind::kCompare:
      return WriteExpression(node.children[0], name) + " " + node.text + " " +
             WriteExpression(node.children[1], name);
    case Kind::kLocation: {
      for (const Instance& inst : instances_) {
        if (inst.sx_name != node.text && (inst.bind || node.text != inst.tmpl->sx->id)) continue;
        const std::string* mode = inst.tmpl->modes.Find(node.children[0].text);
        if (!mode)
          Fail(f.At(node.children[0]),
               "'" + inst.tmpl->sx->id + "' has no location '" + node.children[0].text + "'");
        return "in " + (inst.name.empty() ? "" : inst.name + ".") + *mode;
      }
      Fail(f.At(node), "no instance '" + node.text + "' in loc(" + node.text + ")");
    }
    case Kind::kAnd:
    case Kind::kOr: {
      std::string out;
      for (const SxFormula& c : node.children) {
        const std::string part = Forbidden(f, c);
        const bool wrap = node.kind == Kind::kAnd && c.kind == Kind::kOr;
        out += (out.empty()               ? ""
                : node.kind == Kind::kAnd ? " and "
                                          : " or ") +
               (wrap ? "(" + part + ")" : part);
      }
      return out;
    }
    default:
      Fail(f.At(node), "expected comparisons and loc(...) == location in 'forbidden'");
  }
}

std::string Join(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// The property `forbidden` (within the horizon, if there is one) and the default run to the
// horizon: the lines that end the translated system.
void Translator::PropertyAndScenarioLines(Lines& out) const {
  const std::string within = horizon_ ? " within " + *horizon_ : "";
  if (forbidden_) {
    out.Add(
        "  property forbidden: never " + Forbidden(*forbidden_, forbidden_->formula) + within + ";",
        forbidden_->where(0));
  }
  if (horizon_) out.Add("  scenario { until " + *horizon_ + "; }", horizon_at_);
}

// The `system` block of a network: one instance per bind, then the property and the scenario.
Lines Translator::SystemLines(const SxComponent& system,
                              const std::vector<std::string>& automaton_of) const {
  Lines out;
  out.Add("", {doc_.file(), 1, 1});
  out.Add("system " + Names().Add(system.id, At(system.offset), "component") + " {",
          At(system.offset));
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const Instance& inst = instances_[i];
    std::string binds;
    for (const SxParam& p : inst.tmpl->sx->params) {
      const Target& target = inst.targets.at(p.name);
      const std::string& ours = *inst.tmpl->names.Find(p.name);
      if (!inst.tmpl->used.count(p.name) || !target.constant.empty() ||
          target.our_name == inst.name + "." + ours) {
        continue;
      }
      binds += " " + ours + " = " + target.our_name + ";";
    }
    out.Add("  instance " + inst.name + " = " + automaton_of[i] +
                (binds.empty() ? ";" : " {" + binds + " }"),
            inst.at);
  }
  PropertyAndScenarioLines(out);
  out.Add("}", At(system.offset));
  return out;
}

Translation Translator::Emit(const SxComponent& system) {
  Lines out;
  const Origin top{doc_.file(), 1, 1};
  // File names may hold any byte: escaped, so that none ends the comment line.
  out.Add(
      "# Translated from the SpaceEx model " + EscapedForMessage(doc_.file()) +
          (cfg_ ? " with the configuration " + EscapedForMessage(cfg_->file()) : std::string()) +
          " (docs/spaceex.md).",
      top);
  for (const std::string& note : notes_) out.Add("# " + note, top);
  // One automaton per template, or per instance where the bodies differ.
  Names automata;
  std::vector<std::string> automaton_of(instances_.size());
  std::map<std::string, std::string> name_of_body;  // template id + body -> automaton name
  std::vector<Lines> body_of;
  std::map<const Template*, std::set<std::string>> bodies;  // distinct bodies per template
  for (const Instance& inst : instances_) {
    body_of.push_back(AutomatonBody(inst));
    bodies[inst.tmpl].insert(Join(body_of.back().text));
  }
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const Instance& inst = instances_[i];
    const Lines& body = body_of[i];
    const std::string key = inst.tmpl->sx->id + "\n" + Join(body.text);
    if (const auto it = name_of_body.find(key); it != name_of_body.end()) {
      automaton_of[i] = it->second;
      continue;
    }
    const std::string name = automata.Add(
        bodies[inst.tmpl].size() == 1 ? inst.tmpl->sx->id : inst.tmpl->sx->id + "_" + inst.sx_name,
        At(inst.tmpl->sx->offset), "component");
    name_of_body[key] = automaton_of[i] = name;
    out.Add("", top);
    out.Add("automaton " + name + " {", At(inst.tmpl->sx->offset));
    out.Append(body);
    if (!system.IsNetwork()) PropertyAndScenarioLines(out);
    out.Add("}", At(inst.tmpl->sx->offset));
  }
  if (system.IsNetwork()) out.Append(SystemLines(system, automaton_of));
  return {Join(out.text), out.origins, notes_};
}

Translation Translator::Run() {
  const SxComponent& system = ChooseSystem();
  BuildInstances(system);
  ReadForbidden();
  AssignFlows();
  ReadInitially();
  if (!cfg_) {
    notes_.push_back("No configuration file: the model has no initial states and no property.");
  } else {
    if (!initially_at_)
      notes_.push_back("The configuration has no 'initially': the model has no initial states.");
    ReadHorizon();
  }
  for (const Instance& inst : instances_) {
    if (!inst.dropped_flows.empty()) {
      notes_.push_back("'" + inst.sx_name + "' constrains " + *inst.dropped_flows.begin() +
                       "' == 0 like another component: that flow is given once.");
    }
  }
  return Emit(system);
}

}  // namespace

System Translation::Parse(const std::string& name) const {
  try {
    return ParseModel(text, name);
  } catch (const ParseError& e) {
    if (e.file() != name || e.line() < 1 || static_cast<std::size_t>(e.line()) > origins.size())
      throw;
    const Origin& o = origins[static_cast<std::size_t>(e.line()) - 1];
    throw ParseError(o.file, o.line, o.column, e.message());
  }
}

Translation TranslateSpaceEx(std::string_view xml, const std::string& xml_file,
                             std::string_view cfg, const std::string& cfg_file) {
  const SpaceExDocument doc(xml, xml_file);
  std::optional<SpaceExConfig> config;
  if (!cfg_file.empty()) config.emplace(cfg, cfg_file);
  return Translator(doc, config ? &*config : nullptr).Run();
}

std::optional<std::filesystem::path> DefaultConfigFile(const std::filesystem::path& xml) {
  std::filesystem::path guess = xml;
  guess.replace_extension(".cfg");
  std::error_code ec;
  if (std::filesystem::is_regular_file(guess, ec)) return guess;
  return std::nullopt;
}

Translation ImportSpaceExFile(const std::filesystem::path& xml,
                              const std::optional<std::filesystem::path>& cfg) {
  const std::optional<std::filesystem::path> cfg_path = cfg ? cfg : DefaultConfigFile(xml);
  const std::string xml_text = ReadModelText(xml);
  if (!cfg_path) {
    // Without a configuration the model has neither initial states nor values for its
    // constants, which the translation would report in the model's terms: name the file looked
    // for instead, once the XML itself has been read without error.
    (void)SpaceExDocument(xml_text, xml.string());
    std::filesystem::path beside = xml;
    beside.replace_extension(".cfg");
    throw ParseError(beside.string(), 0, 0,
                     "missing: the SpaceEx model " + xml.string() +
                         " needs its configuration (initial states, forbidden set) in this file");
  }
  return TranslateSpaceEx(xml_text, xml.string(), ReadModelText(*cfg_path), cfg_path->string());
}

bool IsSpaceExFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".xml";
}

System ReadModelFile(const std::filesystem::path& path,
                     const std::optional<std::filesystem::path>& config) {
  if (!IsSpaceExFile(path)) {
    if (config) {
      throw std::invalid_argument("a configuration is read with a SpaceEx model (.xml) only, and " +
                                  path.string() + " is not one");
    }
    return ParseModelFile(path);
  }
  return ImportSpaceExFile(path, config).Parse(path.string());
}

}  // namespace hybrid::spaceex
