#include "commands/check_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "commands/command_error.h"
#include "commands/initial_values.h"
#include "commands/model_file.h"
#include "commands/output.h"
#include "commands/progress.h"
#include "commands/reach_plot.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/checking/property_checker.h"
#include "hybrid/flowpipe/flowpipe_checker.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "hybrid/reachability/reach_checker.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"
#include "hybrid/verification/property_sampler.h"
#include "hybrid/verification/prove_checker.h"
#include "hybrid/verification/sample_checker.h"

namespace hybrid::cli {
namespace {

using json = nlohmann::ordered_json;

// Whether event `e` of the trace's run happened before its reported state: earlier, or at the
// same instant up to the jump that produced the state (samples and events are recorded in order).
bool EventBeforeState(const Trace& t, const EventRecord& e) {
  if (t.state_index < 0) return true;
  const StateSample& s = t.run.samples[t.state_index];
  if (e.time < s.time) return true;
  if (e.time > s.time) return false;
  // Same instant: count the after-event samples at this time up to the state.
  int after_events = 0;
  for (int i = 0; i <= t.state_index; ++i) {
    const StateSample& x = t.run.samples[i];
    if (x.time == s.time && x.kind == StateSample::Kind::kAfterEvent) ++after_events;
  }
  int earlier = 0;  // events at this instant before e
  for (const EventRecord& o : t.run.events) {
    if (&o == &e) break;
    if (o.time == s.time) ++earlier;
  }
  return earlier < after_events;
}

json StateJson(const Simulator& sim, const Eigen::VectorXd& x) {
  json j = json::object();
  for (std::size_t i = 0; i < sim.variable_names().size(); ++i) {
    j[sim.variable_names()[i]] = x[static_cast<int>(i)];
  }
  return j;
}

// A component as traces name it: its instance name, or its automaton's for an unnamed one.
std::string ComponentName(const Component& c) {
  return c.instance.empty() ? c.source.name() : c.instance;
}

json TraceJson(const System& system, const Simulator& sim, const Trace& t) {
  json params = json::object(), inits = json::object(), inputs = json::object();
  for (const auto& [n, v] : t.parameters) params[n] = v;
  for (const auto& [n, v] : t.initial_values) inits[n] = v;
  for (const InputSignal& s : t.inputs.inputs) {
    json pts = json::array();
    for (const auto& [time, value] : s.points) pts.push_back({time, value});
    inputs[system.symbols()[s.slot].name] = pts;
  }
  json events = json::array();
  for (const EventRecord& e : t.run.events) {
    if (!EventBeforeState(t, e)) break;
    events.push_back({{"time", e.time},
                      {"transitions", e.transitions},
                      {"mode_before", sim.ModeLabel(e.modes_before)},
                      {"mode_after", sim.ModeLabel(e.modes_after)}});
  }
  json starts = json::array();
  for (const auto& [c, index] : t.initial_states) {
    const Component& component = system.components()[static_cast<std::size_t>(c)];
    const InitialState& init =
        component.automaton.initial_states()[static_cast<std::size_t>(index)];
    starts.push_back({{"component", ComponentName(component)},
                      {"init", index},
                      {"mode", system.QualifiedModeName(c, init.mode)}});
  }
  json out = {{"parameters", params},    {"initial_states", starts},
              {"initial_values", inits}, {"until", t.inputs.until},
              {"inputs", inputs},        {"replay_status", std::string(StatusName(t.run.status))},
              {"events", events}};
  if (!t.run.samples.empty()) {
    const StateSample& s = t.run.samples.front();
    out["start"] = {
        {"time", s.time}, {"mode", sim.ModeLabel(s.modes)}, {"values", StateJson(sim, s.x)}};
  }
  if (t.state_index >= 0) {
    const StateSample& s = t.run.samples[t.state_index];
    out["state"] = {
        {"time", s.time}, {"mode", sim.ModeLabel(s.modes)}, {"values", StateJson(sim, s.x)}};
  }
  return out;
}

// " x = 1; y = 2;" (10 significant digits).
std::string ValuesText(const Simulator& sim, const Eigen::VectorXd& x) {
  std::ostringstream out;
  out.precision(10);
  for (std::size_t i = 0; i < sim.variable_names().size(); ++i) {
    out << " " << sim.variable_names()[i] << " = " << x[static_cast<int>(i)] << ";";
  }
  return out.str();
}

std::string TraceText(const System& system, const Simulator& sim, const Trace& t) {
  std::ostringstream out;
  out.precision(10);
  if (!t.parameters.empty()) {
    out << "    parameters:";
    for (const auto& [n, v] : t.parameters) out << " " << n << " = " << v << ";";
    out << "\n";
  }
  if (!t.run.samples.empty()) {  // the start, and which init declarations it comes from
    out << "    start in " << sim.ModeLabel(t.run.samples.front().modes) << ":"
        << ValuesText(sim, t.run.samples.front().x);
    for (const auto& [c, index] : t.initial_states) {
      const Component& component = system.components()[static_cast<std::size_t>(c)];
      if (component.automaton.initial_states().size() < 2) continue;
      out << " (init " << index + 1 << " of " << component.automaton.initial_states().size()
          << " of " << ComponentName(component) << ")";
    }
    out << "\n";
  }
  for (const InputSignal& s : t.inputs.inputs) {
    out << "    input " << system.symbols()[s.slot].name << " = step(";
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      out << (i ? ", " : "") << s.points[i].first << ": " << s.points[i].second;
    }
    out << ") until " << t.inputs.until << "\n";
  }
  for (const EventRecord& e : t.run.events) {
    if (!EventBeforeState(t, e)) break;
    out << "    t = " << e.time << "  ";
    for (std::size_t i = 0; i < e.transitions.size(); ++i)
      out << (i ? "+" : "") << e.transitions[i];
    out << "  " << sim.ModeLabel(e.modes_before) << " -> " << sim.ModeLabel(e.modes_after) << "\n";
  }
  if (t.state_index >= 0) {
    const StateSample& s = t.run.samples[t.state_index];
    out << "    at t = " << s.time << " in " << sim.ModeLabel(s.modes) << ":"
        << ValuesText(sim, s.x) << "\n";
  }
  return out.str();
}

// What the methods of `hybrid check` are made with: the command's options, and the prover's
// budget, the progress line and reachability's usage once CheckReport has them (null before:
// a registry for --method's validation only).
struct MethodContext {
  const CheckArgs& args;
  PropertyProver::Options prove;
  SolverBudget* budget = nullptr;
  ProgressLine* progress = nullptr;
  std::optional<PolyhedralReachability::Usage>* usage = nullptr;
  FlowpipeReachability::ReachSet* reach_set = nullptr;
};

CheckerRegistry Methods(MethodContext& context);

// The two variables of --axes ("x,y"), or empty names when it is not two non-empty names.
std::pair<std::string, std::string> AxesOf(const CheckArgs& args) {
  const std::size_t comma = args.axes.find(',');
  if (comma == std::string::npos || args.axes.find(',', comma + 1) != std::string::npos) return {};
  std::string x = args.axes.substr(0, comma), y = args.axes.substr(comma + 1);
  if (x.empty() || y.empty()) return {};
  return {x, y};
}

// Throws OptionError for an argument value out of its range (in the order of the checks: method,
// depth, induction, runs, budget), in the command's name on the command line.
void CheckOptions(const CheckArgs& args) {
  constexpr auto kCommand = OptionError::Scope::kCommand;
  MethodContext names_only{args, {}};
  const CheckerRegistry methods = Methods(names_only);
  if (!methods.Has(args.method)) {
    const std::vector<std::string> names = methods.Names();
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i) {
      list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("'" + names[i] + "'");
    }
    throw OptionError("method", Arg("method") + " must be " + list + ", not '" + args.method + "'",
                      kCommand);
  }
  if (args.depth < 0 || args.depth > 1000) {
    throw OptionError("depth", Arg("depth") + " must be in [0, 1000]", kCommand);
  }
  if (args.induction < 1 || args.induction > 100) {
    throw OptionError("induction", Arg("induction") + " must be in [1, 100]", kCommand);
  }
  if (args.runs < 1) throw OptionError("runs", Arg("runs") + " must be positive", kCommand);
  if (args.order < 1 || args.order > 12) {
    throw OptionError("order", Arg("order") + " must be in [1, 12]", kCommand);
  }
  if (!(args.step >= 0) || !std::isfinite(args.step)) {
    throw OptionError("step", Arg("step") + " must be a non-negative number (0: automatic)",
                      kCommand);
  }
  if (!args.plot_reach.empty() && AxesOf(args).first.empty()) {
    throw OptionError(
        "axes", Arg("axes") + " must name two variables as X,Y (with " + Arg("plot_reach") + ")",
        kCommand);
  }
  if (!(args.budget > 0) || !(args.budget <= 1e6)) {
    throw OptionError("budget", Arg("budget") + " must be a number of budget seconds in (0, 1e6]",
                      kCommand);
  }
}

// The properties `properties` names, in the order given (every declared one without any); throws
// OptionError for a name that is not declared.
std::vector<Property> ChosenProperties(const CheckArgs& args,
                                       const std::vector<Property>& declared) {
  if (args.properties.empty()) return declared;
  std::vector<Property> chosen;
  for (const std::string& name : args.properties) {
    auto it = std::find_if(declared.begin(), declared.end(),
                           [&](const Property& p) { return p.name == name; });
    if (it == declared.end()) {
      std::string known;
      for (const Property& p : declared) known += " " + p.name;
      throw OptionError("properties",
                        Arg("properties") + ": '" + name + "' is not a property of " + args.model +
                            " (properties:" + (known.empty() ? " none" : known) + ")",
                        OptionError::Scope::kCommand);
    }
    chosen.push_back(*it);
  }
  return chosen;
}

// What the check found: per chosen property its result, and with --modes per component the
// reachability of its discrete states; `seconds` is the wall-clock time from parsing on; `reach`
// what polyhedral reachability spent, when it ran.
struct Findings {
  std::vector<Property> chosen;
  std::vector<CheckResult> results;
  std::vector<std::vector<PropertyProver::ModeReachability>> modes;
  double seconds = 0.0;
  std::optional<PolyhedralReachability::Usage> reach;
  FlowpipeReachability::ReachSet reach_set;  ///< with --plot-reach
};

// The bounds of polyhedral reachability: --budget budget seconds of its deterministic reach
// units, and its default CPU-time safety net (max(60 s, 10 s per budget second), as the
// prover's); its state count goes to `progress`.
PolyhedralReachability::Options ReachOptions(const CheckArgs& args, ProgressLine& progress) {
  PolyhedralReachability::Options options;
  options.budget = args.budget;
  if (progress.enabled()) {
    options.progress = [&progress](int states, int queued) {
      progress.Report("reachability: " + std::to_string(states) + " symbolic states, " +
                      std::to_string(queued) + " queued");
    };
  }
  return options;
}

std::unique_ptr<PropertyChecker> MakeReach(MethodContext& c) {
  return std::make_unique<ReachChecker>(ReachOptions(c.args, *c.progress), c.usage);
}

std::unique_ptr<PropertyChecker> MakeProve(MethodContext& c) {
  return std::make_unique<ProveChecker>(c.prove, *c.budget);
}

// The bounds of the flowpipe engine: --budget budget seconds of its deterministic Taylor steps
// (kFlowpipeStepsPerBudgetSecond each), the Taylor order and the step.
std::unique_ptr<PropertyChecker> MakeFlowpipe(MethodContext& c) {
  FlowpipeReachability::Options options;
  options.max_steps =
      static_cast<std::int64_t>(std::ceil(c.args.budget * kFlowpipeStepsPerBudgetSecond));
  options.max_entries =
      std::max(50, static_cast<int>(c.args.budget * kFlowpipeEntriesPerBudgetSecond));
  options.order = c.args.order;
  options.step = c.args.step;
  // Before splitting initial sets for a property, a few simulations: a violation they find
  // makes the refinement pointless (the falsifier of `auto` then reports it with its trace).
  options.evidently_false = [seed = c.args.seed](const System& system,
                                                 std::span<const Property> properties) {
    PropertySampler::Options quick;
    quick.runs = 8;
    quick.seed = seed;
    std::vector<bool> out;
    for (const CheckResult& r : SampleChecker(quick).Check(system, properties)) {
      out.push_back(r.verdict == Verdict::kViolated || r.verdict == Verdict::kReachable);
    }
    return out;
  };
  if (c.progress && c.progress->enabled()) {
    ProgressLine& progress = *c.progress;
    options.progress = [&progress](std::int64_t steps, int queued) {
      progress.Report("flowpipe: " + std::to_string(steps) + " Taylor steps, " +
                      std::to_string(queued) + " sets queued");
    };
  }
  return std::make_unique<FlowpipeChecker>(options, c.reach_set);
}

std::unique_ptr<PropertyChecker> MakeSample(MethodContext& c) {
  PropertySampler::Options options;
  options.runs = c.args.runs;
  options.seed = c.args.seed;
  ProgressLine& progress = *c.progress;
  return std::make_unique<SampleChecker>(
      options, [&progress](std::size_t i, std::size_t n, const Property& p) {
        progress.Report("sample: property " + std::to_string(i + 1) + " of " + std::to_string(n) +
                            " (" + p.name + ")",
                        true);
      });
}

// auto on a linear hybrid automaton: where reachability has explored kAutoPauseBudget budget
// seconds without deciding every property, it pauses for the prover's quick proof
// (QuickProveChecker) of those left, then goes on where it was. The quick proof takes 0.02 to
// 0.1 s on the bundled benchmarks, so it adds at most about a tenth to the work of a model that
// reaches the pause (a budget second is about one second of exploration).
constexpr double kAutoPauseBudget = 1.0;
// The quick proof: 1-induction and witnesses one step deep, within this many budget seconds of
// its own (charged to the command's budget afterwards).
constexpr double kQuickProveBudget = 1.0;

// The prover at depth 1 and 1-induction within a budget of its own of at most
// kQuickProveBudget budget seconds: a proof by induction that costs a fraction of an exploration
// that would not end soon (DISC03: 0.1 s against reachability's 60 budget seconds).
class QuickProveChecker : public PropertyChecker {
 public:
  QuickProveChecker(PropertyProver::Options options, SolverBudget& command_budget)
      : options_(Quick(options)), command_budget_(command_budget) {}
  std::string_view name() const override { return "prove"; }
  // A budget of its own per call (its CPU-time safety net counted from there).
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    SolverBudget budget(std::min(kQuickProveBudget, command_budget_.seconds()));
    std::vector<CheckResult> results = ProveChecker(options_, budget).Check(system, properties);
    command_budget_.Charge(budget.used());
    return results;
  }

 private:
  static PropertyProver::Options Quick(PropertyProver::Options options) {
    options.max_depth = 1;
    options.max_induction = 1;
    return options;
  }
  PropertyProver::Options options_;
  SolverBudget& command_budget_;
};

// auto: reachability (pausing for the quick proof, see kAutoPauseBudget), then the flowpipe, the
// prover and the sampler on what is left.
std::unique_ptr<PropertyChecker> MakeAuto(MethodContext& c) {
  PolyhedralReachability::Options reach = ReachOptions(c.args, *c.progress);
  auto quick = std::make_shared<QuickProveChecker>(c.prove, *c.budget);
  reach.pause_units = static_cast<std::uint64_t>(kAutoPauseBudget * kReachUnitsPerBudgetSecond);
  reach.pause = [quick](const System& system, const std::vector<Property>& open) {
    try {
      return quick->Check(system, open);
    } catch (const std::exception&) {  // no answer: the exploration goes on, and so does auto
      return std::vector<CheckResult>{};
    }
  };
  std::vector<std::unique_ptr<PropertyChecker>> checkers;
  checkers.push_back(std::make_unique<ReachChecker>(reach, c.usage));
  checkers.push_back(MakeFlowpipe(c));
  checkers.push_back(MakeProve(c));
  checkers.push_back(MakeSample(c));
  return std::make_unique<FallbackChecker>("auto", std::move(checkers));
}

// The methods of `hybrid check`, by name (--method): each engine is one entry; `auto` is
// reachability for a linear hybrid automaton, then the prover on what it leaves unknown (the
// prover alone otherwise). `context` must outlive the registry.
CheckerRegistry Methods(MethodContext& context) {
  CheckerRegistry r;
  r.Add("auto",
        "reach for a linear hybrid automaton, then flowpipe, prove, and sample to falsify what is "
        "left unknown",
        [&context] { return MakeAuto(context); });
  r.Add("reach", "exact polyhedral reachability (linear hybrid automata)",
        [&context] { return MakeReach(context); });
  r.Add("flowpipe", "Taylor flowpipes (affine and polynomial dynamics)",
        [&context] { return MakeFlowpipe(context); });
  r.Add("prove", "SMT bounded model checking and k-induction",
        [&context] { return MakeProve(context); });
  r.Add("sample", "random simulations, shrunk counterexamples (never proves)",
        [&context] { return MakeSample(context); });
  return r;
}

// The exit code: kViolated if a property is violated or a reach target unreachable, else
// kUnknown if a verdict is unknown, else kOk.
ExitCode ExitCodeOf(const std::vector<CheckResult>& results) {
  ExitCode code = ExitCode::kOk;
  for (const CheckResult& r : results) {
    if (r.verdict == Verdict::kViolated || r.verdict == Verdict::kUnreachable) {
      code = ExitCode::kViolated;
    }
  }
  if (code == ExitCode::kOk) {
    for (const CheckResult& r : results) {
      if (r.verdict == Verdict::kUnknown) code = ExitCode::kUnknown;
    }
  }
  return code;
}

// The "properties" array of the JSON report.
json PropertiesJson(const System& system, const Simulator& sim, const Findings& found) {
  json props = json::array();
  for (std::size_t i = 0; i < found.results.size(); ++i) {
    const CheckResult& r = found.results[i];
    json j = {{"name", r.property},
              {"kind", std::string(KindKeyword(r.kind))},
              {"predicate", found.chosen[i].predicate.ToString()}};
    if (found.chosen[i].horizon) j["within"] = *found.chosen[i].horizon;  // as info has it
    j["verdict"] = std::string(VerdictName(r.verdict));
    if (r.within) j["verdict_within"] = *r.within;
    j["method"] = r.method;
    j["seconds"] = r.seconds;
    j["reason"] = r.reason;
    if (r.trace) j["trace"] = TraceJson(system, sim, *r.trace);
    props.push_back(j);
  }
  return props;
}

// The "modes" array of the JSON report (`modes`): every component's discrete states in order.
json ModesJson(const System& system, const Simulator& sim, const Findings& found) {
  json ms = json::array();
  for (const auto& comp : found.modes) {
    for (const auto& m : comp) {
      json d = json::object();
      for (const auto& [n, v] : m.discrete) d[n] = v;
      json e = {{"mode", m.mode},
                {"discrete", d},
                {"verdict", std::string(VerdictName(m.verdict))},
                {"reason", m.reason}};
      if (m.trace) e["trace"] = TraceJson(system, sim, *m.trace);
      ms.push_back(e);
    }
  }
  return ms;
}

// The "budget" member of the JSON report: `budget`, and what polyhedral reachability spent of
// its deterministic units (only when it ran).
json BudgetJson(const CheckArgs& args, const PolyhedralReachability::Usage& reach) {
  using Stop = PolyhedralReachability::Usage::Stop;
  const char* stop = reach.stop == Stop::kBudget       ? "budget"
                     : reach.stop == Stop::kStateBound ? "state_bound"
                     : reach.stop == Stop::kSafetyNet  ? "cpu_safety_net"
                                                       : "none";
  return {{"budget_seconds", args.budget},
          {"reach",
           {{"units_used", reach.units_used},
            {"units_total", reach.units_total},
            {"units_per_budget_second", kReachUnitsPerBudgetSecond},
            {"symbolic_states", reach.states},
            {"stopped_by", stop}}}};
}

// The report of `hybrid check --json`.
json ReportJson(const CheckArgs& args, const System& system, const Simulator& sim,
                const Findings& found) {
  json out = {{"model", args.model},
              {"method", args.method},
              {"seconds", found.seconds},
              {"properties", PropertiesJson(system, sim, found)}};
  if (args.modes) out["modes"] = ModesJson(system, sim, found);
  if (found.reach) out["budget"] = BudgetJson(args, *found.reach);
  return out;
}

// The report of `hybrid check` as text: a summary line, a line per property (with its trace),
// and with --modes a line per discrete state.
std::string ReportText(const CheckArgs& args, const System& system, const Simulator& sim,
                       const Findings& found) {
  std::ostringstream out;
  out.precision(4);
  const std::size_t count = found.results.size();
  out << args.model << ": " << count << (count == 1 ? " property" : " properties") << ", method "
      << args.method << ", " << found.seconds << " s\n";
  for (const CheckResult& r : found.results) {
    out << "  " << VerdictName(r.verdict);
    if (r.within) out << " within " << *r.within;
    out << "  " << r.property << " (" << KindKeyword(r.kind) << ", " << r.seconds
        << " s): " << r.reason << "\n";
    if (r.trace) out << TraceText(system, sim, *r.trace);
  }
  if (args.modes) {
    out << "modes (discrete states):\n";
    for (const auto& comp : found.modes) {
      for (const auto& m : comp) {
        out << "  " << VerdictName(m.verdict) << "  " << m.mode << " (";
        for (std::size_t i = 0; i < m.discrete.size(); ++i) {
          out << (i ? ", " : "") << m.discrete[i].first << " = " << m.discrete[i].second;
        }
        out << ")\n";
      }
    }
  }
  return out.str();
}

}  // namespace

namespace {

// --plot-reach: the flowpipe on --axes, the property bounds and the traces found.
void WriteReachPlot(const CheckArgs& args, const Simulator& sim, const Findings& found) {
  const auto [x, y] = AxesOf(args);
  const std::vector<std::string>& names = sim.variable_names();
  const auto column = [&](const std::string& v) {
    return static_cast<long>(std::find(names.begin(), names.end(), v) - names.begin());
  };
  std::vector<ReachPlotTrace> traces;
  for (const CheckResult& r : found.results) {
    if (!r.trace || column(x) >= static_cast<long>(names.size()) ||
        column(y) >= static_cast<long>(names.size())) {
      continue;
    }
    ReachPlotTrace t{r.property + " (" + std::string(VerdictName(r.verdict)) + ")", {}, {}};
    for (int i = 0; i <= r.trace->state_index && i < static_cast<int>(r.trace->run.samples.size());
         ++i) {
      t.xs.push_back(r.trace->run.samples[static_cast<std::size_t>(i)].x[column(x)]);
      t.ys.push_back(r.trace->run.samples[static_cast<std::size_t>(i)].x[column(y)]);
    }
    traces.push_back(std::move(t));
  }
  std::string svg;
  try {
    svg = ReachPlotSvg(found.reach_set, x, y, found.chosen, traces, args.model + ": flowpipe");
  } catch (const std::invalid_argument& e) {
    throw OptionError("axes", Arg("axes") + ": " + e.what(), OptionError::Scope::kCommand);
  }
  WriteOutput(args.plot_reach, svg);
}

// A checker that runs `inner` on the properties not named in `skip` and leaves those unknown
// without looking at them: --modes' lemmas, which sampling cannot prove, are not sampled.
class SkippingChecker : public PropertyChecker {
 public:
  SkippingChecker(std::unique_ptr<PropertyChecker> inner, std::set<std::string> skip)
      : inner_(std::move(inner)), skip_(std::move(skip)) {}
  std::string_view name() const override { return inner_->name(); }
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    std::vector<Property> checked;
    for (const Property& p : properties) {
      if (!skip_.contains(p.name)) checked.push_back(p);
    }
    std::vector<CheckResult> inner = inner_->Check(system, checked);
    std::vector<CheckResult> out;
    std::size_t next = 0;
    for (const Property& p : properties) {
      if (skip_.contains(p.name)) {
        CheckResult r;
        r.property = p.name;
        r.kind = p.kind;
        r.method = std::string(name());
        r.reason = "not checked here";
        out.push_back(std::move(r));
      } else {
        out.push_back(std::move(inner.at(next++)));
      }
    }
    return out;
  }

 private:
  std::unique_ptr<PropertyChecker> inner_;
  std::set<std::string> skip_;
};

// Up to how many modes --modes samples runs first (see ModesOf).
constexpr std::size_t kModesSampledFirst = 500;

// --modes: `reach in MODE` for every mode of every component (PropertyProver::ModeQueries), with
// the model's declared invariants beside them as lemmas for the prover's induction (their verdicts
// are not reported again). Sampled runs first, on the modes alone: most modes are reached by some
// run, whose replayed trace decides them at a fraction of a proof's cost. Then --method on what
// they leave open (auto: reach, flowpipe, prove), its prover searching witnesses one step deep
// only (the samples searched the longer paths): what is left is mostly unreachable, which
// induction with the invariants proves or not. Last, with auto and prove, the prover's deep
// search on the few modes still open.
std::vector<std::vector<PropertyProver::ModeReachability>> ModesOf(const MethodContext& context,
                                                                   const System& system) {
  std::vector<Property> queries;
  std::set<std::string> lemma_names;
  for (const Property& p : DeclaredProperties(system)) {
    if (p.kind == Property::Kind::kReach) continue;
    queries.push_back(p);
    lemma_names.insert(p.name);
  }
  const std::size_t lemmas = queries.size();
  for (std::size_t c = 0; c < system.components().size(); ++c) {
    const std::vector<Property> modes = PropertyProver::ModeQueries(system, static_cast<int>(c));
    queries.insert(queries.end(), modes.begin(), modes.end());
  }
  MethodContext shallow = context;
  shallow.prove.max_depth = 1;
  shallow.reach_set = nullptr;
  std::vector<std::unique_ptr<PropertyChecker>> checkers;
  // Each witness a sampled run finds is replayed on the model compiled again, which costs in
  // proportion to its modes: past kModesSampledFirst modes, sampling first would take a time
  // quadratic in them (a chain of 10^4 modes: over 10 minutes), so there it runs only as the
  // method asked for.
  const std::size_t mode_queries = queries.size() - lemmas;
  if (mode_queries <= kModesSampledFirst || context.args.method == "sample") {
    checkers.push_back(std::make_unique<SkippingChecker>(MakeSample(shallow), lemma_names));
  }
  if (context.args.method == "auto") {  // auto's engines, its sampling done (or left out) above
    checkers.push_back(MakeReach(shallow));
    checkers.push_back(MakeFlowpipe(shallow));
    checkers.push_back(MakeProve(shallow));
  } else if (context.args.method != "sample") {
    checkers.push_back(Methods(shallow).Make(context.args.method));
  }
  // The few modes left open: witnesses searched as deep as --depth, which sampling missed (a
  // mode reached only for a narrow choice of the parameters).
  if (context.args.method == "auto" || context.args.method == "prove") {
    MethodContext deep = context;
    deep.reach_set = nullptr;
    checkers.push_back(MakeProve(deep));
  }
  const std::vector<CheckResult> results =
      FallbackChecker("modes", std::move(checkers)).Check(system, queries);
  std::vector<std::vector<PropertyProver::ModeReachability>> out;
  std::size_t next = lemmas;
  for (std::size_t c = 0; c < system.components().size(); ++c) {
    const std::size_t count =
        static_cast<std::size_t>(system.components()[c].automaton.num_modes());
    out.push_back(PropertyProver::ModeResults(system, static_cast<int>(c),
                                              std::span(results).subspan(next, count)));
    next += count;
  }
  return out;
}

// Checks the chosen properties of `system` (and with --modes its discrete states).
Findings FindingsOf(const CheckArgs& args, const System& system) {
  CheckOptions(args);
  const auto start = std::chrono::steady_clock::now();
  Findings found;
  found.chosen = ChosenProperties(args, DeclaredProperties(system));
  // One solver budget for the whole command: the properties, then --modes, draw from it.
  SolverBudget budget(args.budget);
  ProgressLine progress("check", args.progress);
  std::string stage = "prove";
  if (progress.enabled()) {
    budget.SetObserver([&progress, &stage](const SolverBudget& b) {
      progress.Report(stage + ": " +
                      std::to_string(b.used() * 100 / std::max<std::uint64_t>(b.total(), 1)) +
                      "% of the solver budget used");
    });
  }
  PropertyProver::Options prove;
  prove.max_depth = args.depth;
  prove.max_induction = args.induction;
  MethodContext context{args, prove, &budget, &progress, &found.reach};
  if (!args.plot_reach.empty()) context.reach_set = &found.reach_set;
  found.results = Methods(context).Make(args.method)->Check(system, found.chosen);
  if (!args.plot_reach.empty() && found.reach_set.boxes.empty()) {
    // The method decided without a flowpipe: compute one for the picture.
    std::string why;
    if (!FlowpipeReachability::Handles(system, found.chosen, &why)) {
      throw OptionError("plot_reach",
                        Arg("plot_reach") + ": no flowpipe for this model (" + why + ")",
                        OptionError::Scope::kCommand);
    }
    MakeFlowpipe(context)->Check(system, found.chosen);
  }
  if (const std::optional<std::string> none = system.NoAdmissibleStart()) {
    // A verdict about a model without runs holds vacuously: say so in every reason.
    for (CheckResult& r : found.results) {
      r.reason = "vacuous, the model has no run (" + *none + "); " + r.reason;
    }
  }
  if (args.modes) {
    stage = "modes";
    found.modes = ModesOf(context, system);
  }
  found.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return found;
}

}  // namespace

json CheckReport(const CheckArgs& args, const System& system, ExitCode* exit_code) {
  const Findings found = FindingsOf(args, system);
  const Simulator sim(system);
  if (exit_code) *exit_code = ExitCodeOf(found.results);
  return ReportJson(args, system, sim, found);
}

ExitCode RunCheck(const CheckArgs& args) {
  CheckOptions(args);
  const std::vector<InitialValueSetting> init = ParseInitialValues(args.init);
  System system = ReadModelArgument(args.model, args.config);
  SetInitialValues(init, system);
  const Findings found = FindingsOf(args, system);
  const Simulator sim(system);
  const ExitCode code = ExitCodeOf(found.results);
  if (!args.plot_reach.empty()) WriteReachPlot(args, sim, found);
  if (args.json) {
    // The model path may be any bytes: replace invalid UTF-8 rather than throw.
    const json out = ReportJson(args, system, sim, found);
    WriteOutput("-", out.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
    return code;
  }
  WriteOutput("-", ReportText(args, system, sim, found));
  return code;
}

}  // namespace hybrid::cli
