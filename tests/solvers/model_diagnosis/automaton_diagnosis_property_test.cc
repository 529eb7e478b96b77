// Property test of DiagnoseAutomaton (the must-show): random small models (the
// differential test's generator, tests/test_utilities/random_hybrid_automata.h, flows affine in the
// state), one hidden edit of the candidate vocabulary drawn at random, Gaussian noise added; the
// diagnosis sees only the model and the CSV; the hidden edit must be named in >= 90% of the draws,
// and no cause may be named on clean data.
//
// The oracle is independent of the code under test: the hidden edit is applied to the generator's
// own description of the automaton (a parameter's nominal value, a comparison constant, the
// coefficients of a flow), to the input signal the truth is driven by (an offset the CSV does not
// show), or to the samples written to the CSV (sensor bias and gain); the truth is then printed,
// parsed and simulated with the Simulator (hybrid::simulation, not under test), sampled at fixed
// times, and noise is added. Neither ApplyEdits nor CandidateEdits makes the truth.
//
// The draws take the seven kinds of edit in turn (a parameter, a sensor bias, a sensor gain, a
// flow gain, an urgent guard's threshold, an invariant's threshold, an input offset), so that hard
// kinds are not drawn away. Every draw keeps only a detectable edit inside the range the
// diagnosis searches: the chi-square between truth and baseline (the sum of squared differences
// over sigma^2, all runs and channels) exceeds 200, and both simulate to the end; otherwise the
// edit (or the model) is drawn again, and the redraws are counted. The data of a draw: two input
// settings (step signals in the middle half of each input's bounds), each run twice (the noise
// floor comes from the repeats), or three repeats of one run for a model without inputs; 61
// samples per run (t = 0 to 6), noise sd 2% of the variable's range (at least 0.01).
//
// A hit: the hidden edit's name is among the causes. Otherwise the draw is an equivalent
// extension when the hidden edit's held-out loss is within the engine's significance (25 chi-square
// units) of the named cause's (the data cannot tell them apart, e.g. two inputs that enter one
// flow as `u + v`), else a miss; both are printed with the leading candidates and the model.
//
// build/tests/automaton_diagnosis_property_test prints one line per draw and the counts.
// HYBRID_MODEL_DIAGNOSE_DRAWS=N: N edited draws (default 56) and N / 4 clean ones (at least 4).
// HYBRID_MODEL_DIAGNOSE_DUMP=DIR: each draw's model and trace written to DIR (to replay one with
// `hybrid diagnose DIR/draw7.ha DIR/draw7.csv`).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/model_diagnosis/automaton_diagnosis.h"
#include "hybrid/model_diagnosis/trace_data.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/random_hybrid_automata.h"

namespace hybrid {
namespace {

using testing::DecimalText;
using testing::RandomChance;
using testing::RandomComparison;
using testing::RandomHybridAutomaton;
using testing::RandomSum;
using testing::RandomTransition;
using testing::UniformInt;
using testing::UniformReal;

// The sampling of every run: times 0, 0.1, ..., 6.
constexpr int kSamples = 61;
constexpr double kMinChiSquare = 200.0;

double SampleTime(int k) { return k / 10.0; }  // the double nearest to k * 0.1

// A standard normal deviate by Box-Muller from the generator's own uniform draws (the standard
// distributions' output is left to the library; this is the same everywhere).
double Gaussian(std::mt19937_64& rng) {
  const double u1 = 1.0 - UniformReal(rng, 0.0, 1.0);  // (0, 1]
  const double u2 = UniformReal(rng, 0.0, 1.0);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// ---- the models ----

// A generator's automaton as the diagnosis gets it: rectangular rates replaced by their midpoint
// (a flow the candidate vocabulary can scale), one initial state, no properties.
void Simplify(RandomHybridAutomaton& a) {
  for (testing::RandomMode& m : a.modes) {
    for (const testing::RandomRate& r : m.rates) {
      const double mid = std::round((r.lo + r.hi) * 5) / 10;
      m.flows.emplace_back(r.variable, RandomSum{{{mid, {}}}});
    }
    m.rates.clear();
  }
  a.inits.resize(1);
  a.properties.clear();
}

// Whether a name clashes with a reserved column of the trace format (`run`, `time`, `mode`).
bool ReservedColumn(const RandomHybridAutomaton& a) {
  const std::set<std::string> reserved = {"run", "time", "mode"};
  for (const auto& v : a.variables) {
    if (reserved.contains(v.name)) return true;
  }
  for (const auto& in : a.inputs) {
    if (reserved.contains(in.name)) return true;
  }
  return false;
}

bool IsVariable(const RandomHybridAutomaton& a, const std::string& name) {
  return std::any_of(a.variables.begin(), a.variables.end(),
                     [&](const auto& v) { return v.name == name; });
}

bool Reads(const RandomSum& s, const std::string& name) {
  for (const auto& t : s.terms) {
    if (std::find(t.factors.begin(), t.factors.end(), name) != t.factors.end()) return true;
  }
  return false;
}

bool ReadsAny(const std::vector<RandomComparison>& cs, const std::string& name) {
  return std::any_of(cs.begin(), cs.end(), [&](const auto& c) { return Reads(c.lhs, name); });
}

// Whether the automaton reads `name` anywhere (flows, invariants, guards, resets).
bool ReadsName(const RandomHybridAutomaton& a, const std::string& name) {
  for (const auto& m : a.modes) {
    for (const auto& [x, f] : m.flows) {
      if (Reads(f, name)) return true;
    }
    if (ReadsAny(m.invariant, name)) return true;
  }
  for (const auto& t : a.transitions) {
    if (ReadsAny(t.guard, name)) return true;
    for (const auto& [x, r] : t.resets) {
      if (Reads(r, name)) return true;
    }
  }
  return false;
}

// A comparison `x REL c` of one variable with coefficient 1 (the candidate's range is then a
// quarter of x's measured range either side).
std::optional<std::string> SingleVariable(const RandomHybridAutomaton& a,
                                          const RandomComparison& c) {
  if (c.lhs.terms.size() != 1 || c.lhs.terms[0].coef != 1.0 || c.lhs.terms[0].factors.size() != 1)
    return std::nullopt;
  const std::string& x = c.lhs.terms[0].factors[0];
  if (!IsVariable(a, x)) return std::nullopt;
  return x;
}

bool NonZero(const RandomSum& s) {
  return std::any_of(s.terms.begin(), s.terms.end(), [](const auto& t) { return t.coef != 0.0; });
}

// ---- the data ----

// One run's setting: the input values at the sample times ([input][k]).
struct Setting {
  std::vector<std::vector<double>> inputs;
};

// Step signals in the middle half of each input's bounds (constant for a degenerate input): two
// settings when some input can vary, else one.
std::vector<Setting> DrawSettings(std::mt19937_64& rng, const RandomHybridAutomaton& a) {
  const bool varying =
      std::any_of(a.inputs.begin(), a.inputs.end(), [](const auto& in) { return in.hi > in.lo; });
  std::vector<Setting> settings(varying ? 2 : 1);
  for (Setting& s : settings) {
    for (const auto& in : a.inputs) {
      const double w = in.hi - in.lo;
      const double v0 = UniformReal(rng, in.lo + 0.25 * w, in.hi - 0.25 * w);
      const double v1 = UniformReal(rng, in.lo + 0.25 * w, in.hi - 0.25 * w);
      const int jump = UniformInt(rng, kSamples * 3 / 10, kSamples * 7 / 10);
      std::vector<double> u(kSamples);
      for (int k = 0; k < kSamples; ++k) u[k] = w > 0 ? (k < jump ? v0 : v1) : in.lo;
      s.inputs.push_back(std::move(u));
    }
  }
  return settings;
}

// samples[setting][variable][k], variables in the automaton's order.
using Samples = std::vector<std::vector<std::vector<double>>>;

// Per mode entered (at an instant or longer) and variable: the least and greatest value recorded
// in it (samples and both sides of every event).
using Extremes = std::map<std::string, std::vector<std::pair<double, double>>>;

// The automaton's `text` simulated for every setting, each input read as its value plus
// `offset` (by input name); nullopt (and `why`) when it does not parse or a run does not complete.
std::optional<Samples> Simulate(const RandomHybridAutomaton& a, const std::string& text,
                                const std::vector<Setting>& settings,
                                const std::map<std::string, double>& offset, std::string& why,
                                Extremes* visited = nullptr) {
  try {
    const System system = ParseModel(text, "truth.ha");
    const Simulator simulator(system);
    std::vector<int> index;
    for (const auto& v : a.variables) {
      const auto& names = simulator.variable_names();
      index.push_back(
          static_cast<int>(std::find(names.begin(), names.end(), v.name) - names.begin()));
    }
    SimulationOptions options;
    options.until = SampleTime(kSamples - 1);
    for (int k = 0; k < kSamples; ++k) options.sample_times.push_back(SampleTime(k));
    Samples out;
    for (const Setting& s : settings) {
      std::vector<InputSignal> signals;
      for (size_t i = 0; i < a.inputs.size(); ++i) {
        InputSignal signal;
        signal.slot = *system.symbols().Find(a.inputs[i].name);
        signal.shape = InputSignal::Shape::kLinear;
        const auto it = offset.find(a.inputs[i].name);
        const double d = it == offset.end() ? 0.0 : it->second;
        for (int k = 0; k < kSamples; ++k)
          signal.points.emplace_back(SampleTime(k), s.inputs[i][k] + d);
        signals.push_back(std::move(signal));
      }
      const SimulationResult r = simulator.Run(options, signals);
      if (r.status != SimulationStatus::kCompleted) {
        why = std::string(StatusName(r.status)) + ": " + r.message;
        return std::nullopt;
      }
      std::vector<std::vector<double>> xs(a.variables.size());
      for (const StateSample& sample : r.samples) {
        if (visited) {
          auto [it, fresh] = visited->try_emplace(simulator.ModeName(0, sample.modes[0]),
                                                  index.size(), std::pair{INFINITY, -INFINITY});
          for (size_t v = 0; v < index.size(); ++v) {
            it->second[v].first = std::min(it->second[v].first, sample.x[index[v]]);
            it->second[v].second = std::max(it->second[v].second, sample.x[index[v]]);
          }
        }
        if (sample.kind != StateSample::Kind::kSample) continue;
        for (size_t v = 0; v < index.size(); ++v) xs[v].push_back(sample.x[index[v]]);
      }
      for (const auto& x : xs) {
        if (x.size() != kSamples) {
          why = "not one state per sample";
          return std::nullopt;
        }
        for (double y : x) {
          if (!std::isfinite(y) || std::abs(y) > 1e6) {
            why = "state beyond 1e6";
            return std::nullopt;
          }
        }
      }
      out.push_back(std::move(xs));
    }
    return out;
  } catch (const std::exception& e) {
    why = e.what();
    return std::nullopt;
  }
}

size_t VariableIndex(const RandomHybridAutomaton& a, const std::string& x) {
  size_t v = 0;
  while (v < a.variables.size() && a.variables[v].name != x) ++v;
  return v;
}

// [min, max] of variable v over every setting.
std::pair<double, double> Range(const Samples& s, size_t v) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& setting : s) {
    for (double y : setting[v]) {
      lo = std::min(lo, y);
      hi = std::max(hi, y);
    }
  }
  return {lo, hi};
}

double Span(const Samples& s, size_t v) {
  const auto [lo, hi] = Range(s, v);
  return hi - lo;
}

// The trace CSV: per setting `repeats` runs of the truth with fresh noise of sd sigma[v].
struct Trace {
  std::string csv;
  Samples noisy;  // [run][variable][k]
};

Trace WriteTrace(std::mt19937_64& rng, const RandomHybridAutomaton& a,
                 const std::vector<Setting>& settings, const Samples& truth, int repeats,
                 const std::vector<double>& sigma) {
  Trace t;
  std::ostringstream out;
  out << "run,time";
  for (const auto& in : a.inputs) out << "," << in.name;
  for (const auto& v : a.variables) out << "," << v.name;
  out << "\n";
  for (size_t s = 0; s < settings.size(); ++s) {
    for (int r = 0; r < repeats; ++r) {
      std::vector<std::vector<double>> run(a.variables.size(), std::vector<double>(kSamples));
      for (int k = 0; k < kSamples; ++k) {
        out << "s" << s << "r" << r << "," << DecimalText(SampleTime(k));
        for (size_t i = 0; i < a.inputs.size(); ++i)
          out << "," << DecimalText(settings[s].inputs[i][k]);
        for (size_t v = 0; v < a.variables.size(); ++v) {
          run[v][k] = truth[s][v][k] + sigma[v] * Gaussian(rng);
          out << "," << DecimalText(run[v][k]);
        }
        out << "\n";
      }
      t.noisy.push_back(std::move(run));
    }
  }
  t.csv = out.str();
  return t;
}

// ---- the hidden edits ----

enum class Kind { kParameter, kSensorBias, kSensorGain, kFlowGain, kGuard, kInvariant, kInput };

const char* KindName(Kind k) {
  switch (k) {
    case Kind::kParameter:
      return "parameter";
    case Kind::kSensorBias:
      return "sensor bias";
    case Kind::kSensorGain:
      return "sensor gain";
    case Kind::kFlowGain:
      return "flow gain";
    case Kind::kGuard:
      return "guard threshold";
    case Kind::kInvariant:
      return "invariant threshold";
    case Kind::kInput:
      return "input offset";
  }
  return "?";
}

// An edit the test can make: its kind, the candidate name the diagnosis should give, and where.
struct Site {
  Kind kind;
  std::string name;
  int index = 0;              // parameter, variable, mode, transition or input
  std::string variable = {};  // sensor, flow gain, thresholds: the variable concerned
};

std::vector<Site> Sites(const RandomHybridAutomaton& a) {
  std::vector<Site> sites;
  for (int p = 0; p < static_cast<int>(a.parameters.size()); ++p) {
    const auto& par = a.parameters[p];
    if (par.definition || !ReadsName(a, par.name)) continue;
    if (par.range && !(par.range->second > par.range->first)) continue;
    sites.push_back({Kind::kParameter, par.name, p});
  }
  for (int v = 0; v < static_cast<int>(a.variables.size()); ++v) {
    sites.push_back({Kind::kSensorBias, a.variables[v].name + "_bias", v, a.variables[v].name});
    sites.push_back({Kind::kSensorGain, a.variables[v].name + "_gain", v, a.variables[v].name});
  }
  for (int m = 0; m < static_cast<int>(a.modes.size()); ++m) {
    for (const auto& [x, f] : a.modes[m].flows) {
      if (NonZero(f)) sites.push_back({Kind::kFlowGain, a.modes[m].name + "." + x + "_gain", m, x});
    }
    if (!a.modes[m].invariant.empty()) {
      if (auto x = SingleVariable(a, a.modes[m].invariant[0]))
        sites.push_back({Kind::kInvariant, a.modes[m].name + ".invariant", m, *x});
    }
  }
  for (int t = 0; t < static_cast<int>(a.transitions.size()); ++t) {
    const RandomTransition& tr = a.transitions[t];
    if (tr.urgency == RandomTransition::Urgency::kLazy || tr.guard.empty()) continue;
    if (auto x = SingleVariable(a, tr.guard[0]))
      sites.push_back({Kind::kGuard, tr.name + ".threshold", t, *x});
  }
  for (int i = 0; i < static_cast<int>(a.inputs.size()); ++i) {
    if (a.inputs[i].hi > a.inputs[i].lo)
      sites.push_back({Kind::kInput, a.inputs[i].name + "_offset", i});
  }
  return sites;
}

constexpr Kind kKinds[] = {Kind::kParameter, Kind::kSensorBias, Kind::kSensorGain, Kind::kFlowGain,
                           Kind::kGuard,     Kind::kInvariant,  Kind::kInput};
constexpr int kKindCount = sizeof kKinds / sizeof kKinds[0];

// The sites of `kind`.
std::vector<Site> OfKind(const std::vector<Site>& sites, Kind kind) {
  std::vector<Site> out;
  for (const Site& s : sites) {
    if (s.kind == kind) out.push_back(s);
  }
  return out;
}

double Sign(std::mt19937_64& rng) { return RandomChance(rng, 50) ? 1.0 : -1.0; }
double Hundredths(double x) { return std::round(x * 100) / 100; }

// One draw's data and what was hidden in it.
struct Draw {
  RandomHybridAutomaton model;
  std::string text;
  std::optional<Site> site = {};  // none: clean
  double value = 0.0;             // the hidden edit's number (as the candidate reads it)
  double chi_square = 0.0;
  std::string csv = {};
};

struct Redraws {
  int reserved = 0;    // a variable or input named like a reserved column
  int unsuitable = 0;  // the baseline does not simulate to the end
  int no_site = 0;     // no site of the kind wanted
  int truth_failed = 0;
  int undetectable = 0;
  int out_of_range = 0;
  std::map<std::string, int> by_kind;  // truth failed, undetectable or out of range, per kind
};

// The truth for `site` with a value drawn from `rng`: an edited copy of the model (text) or
// signals, simulated; applies sensor edits to the samples. nullopt when it fails.
struct Truth {
  Samples samples;
  double value = 0.0;    // the number the hidden edit's candidate reads
  double neutral = 0.0;  // its value in the model as given
};

std::optional<Truth> MakeTruth(std::mt19937_64& rng, const RandomHybridAutomaton& a,
                               const Site& site, const std::vector<Setting>& settings,
                               const Samples& baseline, std::string& why) {
  RandomHybridAutomaton edited = a;
  std::map<std::string, double> offset;
  Truth t;
  switch (site.kind) {
    case Kind::kParameter: {
      testing::RandomParameter& p = edited.parameters[site.index];
      double lo, hi;
      if (p.range) {
        lo = p.range->first;
        hi = p.range->second;
      } else {
        const double h = p.nominal == 0.0 ? 1.0 : 0.5 * std::abs(p.nominal);
        lo = p.nominal - h;
        hi = p.nominal + h;
      }
      t.neutral = p.nominal;
      const double w = hi - lo;
      double v = p.nominal;
      for (int attempt = 0; attempt < 100 && std::abs(v - p.nominal) < 0.25 * w; ++attempt) {
        v = Hundredths(UniformReal(rng, lo + 0.05 * w, hi - 0.05 * w));
      }
      if (std::abs(v - p.nominal) < 0.25 * w) {
        why = "no parameter value";
        return std::nullopt;
      }
      p.nominal = v;
      t.value = v;
      break;
    }
    case Kind::kSensorBias: {
      const double span = std::max(Span(baseline, site.index), 0.2);
      t.value = Sign(rng) * UniformReal(rng, 0.05, 0.3) * span;
      break;
    }
    case Kind::kSensorGain:
      t.neutral = 1.0;
      t.value = 1.0 + Sign(rng) * UniformReal(rng, 0.05, 0.18);
      break;
    case Kind::kFlowGain: {
      t.neutral = 1.0;
      t.value = 1.0 + Sign(rng) * UniformReal(rng, 0.15, 0.4);
      for (auto& [x, f] : edited.modes[site.index].flows) {
        if (x != site.variable) continue;
        for (auto& term : f.terms) term.coef *= t.value;
      }
      break;
    }
    case Kind::kGuard:
    case Kind::kInvariant: {
      RandomComparison& c = site.kind == Kind::kGuard ? edited.transitions[site.index].guard[0]
                                                      : edited.modes[site.index].invariant[0];
      const double span = std::max(Span(baseline, VariableIndex(a, site.variable)), 0.2);
      t.neutral = c.rhs;
      c.rhs = c.rhs + Sign(rng) * UniformReal(rng, 0.05, 0.2) * span;
      t.value = c.rhs;
      break;
    }
    case Kind::kInput: {
      const auto& in = a.inputs[site.index];
      t.value = Sign(rng) * UniformReal(rng, 0.08, 0.22) * (in.hi - in.lo);
      offset[in.name] = t.value;
      break;
    }
  }
  std::optional<Samples> s = Simulate(edited, edited.Text(), settings, offset, why);
  if (!s) return std::nullopt;
  if (site.kind == Kind::kSensorBias || site.kind == Kind::kSensorGain) {
    for (auto& setting : *s) {
      for (double& y : setting[site.index]) {
        y = site.kind == Kind::kSensorBias ? y + t.value : t.value * y;
      }
    }
  }
  t.samples = std::move(*s);
  return t;
}

double ChiSquare(const Samples& a, const Samples& b, const std::vector<double>& sigma,
                 int repeats) {
  double chi = 0.0;
  for (size_t s = 0; s < a.size(); ++s) {
    for (size_t v = 0; v < sigma.size(); ++v) {
      for (int k = 0; k < kSamples; ++k) {
        const double d = (a[s][v][k] - b[s][v][k]) / sigma[v];
        chi += repeats * d * d;
      }
    }
  }
  return chi;
}

// The measured span of variable `x` in the noisy runs.
double NoisySpan(const Trace& t, size_t x) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& run : t.noisy) {
    for (double y : run[x]) {
      lo = std::min(lo, y);
      hi = std::max(hi, y);
    }
  }
  return hi - lo;
}

// Draws a model, its data and (unless `kind` is empty: clean data) a detectable hidden edit of
// `kind`, from `seed` on.
Draw MakeDraw(uint64_t& seed, std::optional<Kind> kind, Redraws& redraws) {
  for (;;) {
    std::mt19937_64 rng(seed++);
    RandomHybridAutomaton a =
        testing::GenerateRandomAutomaton(rng, {testing::RandomDynamics::kAffine});
    Simplify(a);
    if (ReservedColumn(a)) {
      ++redraws.reserved;
      continue;
    }
    const std::vector<Setting> settings = DrawSettings(rng, a);
    const int repeats = settings.size() > 1 ? 2 : 3;
    std::string why;
    const std::string text = a.Text();
    Extremes visited;  // the modes the baseline enters, with the range of each variable there
    const std::optional<Samples> baseline = Simulate(a, text, settings, {}, why, &visited);
    if (!baseline) {
      ++redraws.unsuitable;
      continue;
    }
    std::vector<double> sigma;  // the noise sd per variable
    for (size_t v = 0; v < a.variables.size(); ++v) {
      sigma.push_back(std::max(0.02 * Span(*baseline, v), 0.01));
    }
    Draw d{a, text};
    if (!kind) {
      d.csv = WriteTrace(rng, a, settings, *baseline, repeats, sigma).csv;
      return d;
    }
    std::vector<Site> sites = OfKind(Sites(a), *kind);
    // A mode the baseline never enters: its flow, invariant and outgoing guards cannot change
    // the trace (the test's own reading of the simulation, not the code under test's).
    // A threshold that x never comes near in its mode (farther than the largest shift drawn,
    // with a margin for the states between samples) cannot either.
    std::erase_if(sites, [&](const Site& site) {
      if (site.kind == Kind::kFlowGain) return !visited.contains(a.modes[site.index].name);
      if (site.kind != Kind::kGuard && site.kind != Kind::kInvariant) return false;
      const std::string& mode =
          site.kind == Kind::kGuard ? a.transitions[site.index].source : a.modes[site.index].name;
      const double c = site.kind == Kind::kGuard ? a.transitions[site.index].guard[0].rhs
                                                 : a.modes[site.index].invariant[0].rhs;
      const auto it = visited.find(mode);
      if (it == visited.end()) return true;
      const size_t x = VariableIndex(a, site.variable);
      const auto [lo, hi] = it->second[x];
      const double distance = c < lo ? lo - c : c > hi ? c - hi : 0.0;
      return distance > 0.3 * std::max(Span(*baseline, x), 0.2);
    });
    if (sites.empty()) {
      ++redraws.no_site;
      continue;
    }
    // A few edits of this model before drawing another.
    for (int attempt = 0; attempt < 4; ++attempt) {
      const Site site = sites[UniformInt(rng, 0, static_cast<int>(sites.size()) - 1)];
      const std::optional<Truth> truth = MakeTruth(rng, a, site, settings, *baseline, why);
      ++redraws.by_kind[KindName(site.kind)];
      if (!truth) {
        ++redraws.truth_failed;
        continue;
      }
      const double chi = ChiSquare(truth->samples, *baseline, sigma, repeats);
      if (!(chi > kMinChiSquare)) {
        ++redraws.undetectable;
        continue;
      }
      const Trace trace = WriteTrace(rng, a, settings, truth->samples, repeats, sigma);
      // Inside the searched range: a threshold within a quarter of its variable's measured span,
      // a bias within half of it (model_edit.h, CandidateEdits).
      if (site.kind == Kind::kGuard || site.kind == Kind::kInvariant) {
        const double shift = std::abs(truth->value - truth->neutral);
        if (!(shift < 0.25 * NoisySpan(trace, VariableIndex(a, site.variable)))) {
          ++redraws.out_of_range;
          continue;
        }
      }
      if (site.kind == Kind::kSensorBias &&
          !(std::abs(truth->value) < 0.5 * NoisySpan(trace, site.index))) {
        ++redraws.out_of_range;
        continue;
      }
      --redraws.by_kind[KindName(site.kind)];
      d.site = site;
      d.value = truth->value;
      d.chi_square = chi;
      d.csv = trace.csv;
      return d;
    }
  }
}

// ---- judging ----

const ParameterFit* SingleFit(const AutomatonDiagnosis& d, const std::string& name) {
  for (const ParameterFit& f : d.result.candidates) {
    if (f.parameters.size() == 1 && d.edits[f.parameters[0]].name == name) return &f;
  }
  return nullptr;
}

std::string Describe(const AutomatonDiagnosis& d) {
  std::ostringstream out;
  out << "cause {";
  for (size_t i = 0; i < d.result.cause.size(); ++i) out << (i ? ", " : "") << d.result.cause[i];
  out << "}";
  for (const auto& [name, v] : d.named) out << " " << name << "=" << v;
  out << " explained " << d.result.explained_fraction;
  return out.str();
}

// The best candidates by held-out loss, with the baseline's loss (gain + held-out loss).
std::string Leaders(const AutomatonDiagnosis& d, const std::string& hidden) {
  std::vector<const ParameterFit*> fits;
  for (const ParameterFit& f : d.result.candidates) {
    if (f.parameters.size() == 1) fits.push_back(&f);
  }
  std::sort(fits.begin(), fits.end(),
            [](const auto* a, const auto* b) { return a->heldout_loss < b->heldout_loss; });
  std::ostringstream out;
  if (!fits.empty())
    out << "    baseline held-out loss " << fits[0]->heldout_loss + fits[0]->gain << "\n";
  for (size_t i = 0; i < fits.size() && i < 4; ++i) {
    out << "    " << d.edits[fits[i]->parameters[0]].name << ": held-out loss "
        << fits[i]->heldout_loss << " gain " << fits[i]->gain << " value " << fits[i]->values[0]
        << (fits[i]->significant ? " significant" : "") << "\n";
  }
  if (const ParameterFit* h = SingleFit(d, hidden)) {
    out << "    hidden " << hidden << ": held-out loss " << h->heldout_loss << " gain " << h->gain
        << " value " << h->values[0] << "\n";
  } else {
    out << "    hidden " << hidden << ": not among the candidates searched\n";
  }
  for (const std::string& n : d.notes) out << "    note: " << n << "\n";
  return out.str();
}

int DrawsFromEnvironment(int fallback) {
  const char* env = std::getenv("HYBRID_MODEL_DIAGNOSE_DRAWS");
  if (!env) return fallback;
  const int n = std::atoi(env);
  return n > 0 ? n : fallback;
}

// HYBRID_MODEL_DIAGNOSE_DUMP=DIR: each draw's model and trace are written to DIR/LABEL.ha and
// DIR/LABEL.csv before the diagnosis (to replay one with `hybrid diagnose`).
void Dump(const Draw& draw, const std::string& label) {
  const char* dir = std::getenv("HYBRID_MODEL_DIAGNOSE_DUMP");
  if (!dir) return;
  std::ofstream(std::string(dir) + "/" + label + ".ha") << draw.text;
  std::ofstream(std::string(dir) + "/" + label + ".csv") << draw.csv;
}

AutomatonDiagnosis Diagnose(const Draw& draw) {
  const System model = ParseModel(draw.text, "model.ha");
  std::istringstream in(draw.csv);
  const TraceData data = ReadTraceData(in, "trace.csv", model);
  return DiagnoseAutomaton(model, data);
}

TEST(AutomatonDiagnosisProperty, HiddenEditOfRandomModelIsNamed) {
  const int draws = DrawsFromEnvironment(56);
  uint64_t seed = 20261128;
  Redraws redraws;
  int hits = 0, equivalent = 0, misses = 0, errors = 0;
  double diagnosing = 0.0;                             // seconds in DiagnoseAutomaton
  std::map<std::string, std::pair<int, int>> by_kind;  // kind -> (hits, draws)
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < draws; ++i) {
    // The kinds in turn, so that each is tried as often (hard ones are not drawn away).
    const Draw draw = MakeDraw(seed, kKinds[i % kKindCount], redraws);
    const std::string& hidden = draw.site->name;
    std::ostringstream line;
    line << "draw " << i << " (seed " << seed - 1 << "): " << KindName(draw.site->kind) << " "
         << hidden << " = " << draw.value << ", chi-square " << draw.chi_square << ": ";
    const auto t0 = std::chrono::steady_clock::now();
    Dump(draw, "draw" + std::to_string(i));
    std::cout << std::flush;
    AutomatonDiagnosis d;
    try {
      d = Diagnose(draw);
    } catch (const std::exception& e) {
      ++errors;
      std::cout << line.str() << "ERROR " << e.what() << "\n" << draw.text;
      ADD_FAILURE() << "draw " << i << ": " << e.what();
      continue;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    diagnosing += seconds;
    auto& kind = by_kind[KindName(draw.site->kind)];
    ++kind.second;
    const auto& cause = d.result.cause;
    if (std::find(cause.begin(), cause.end(), hidden) != cause.end()) {
      ++hits;
      ++kind.first;
      std::cout << line.str() << "hit, " << Describe(d) << " (" << seconds << " s)\n";
      continue;
    }
    // An equivalent extension: a named cause whose held-out loss the hidden edit's matches
    // within the engine's significance (the data cannot tell them apart).
    const ParameterFit* h = SingleFit(d, hidden);
    const ParameterFit* named = cause.empty() ? nullptr : SingleFit(d, cause[0]);
    const bool same =
        h && named &&
        h->heldout_loss - named->heldout_loss < AnyModelDiagnosisOptions().significance;
    if (same) {
      ++equivalent;
    } else {
      ++misses;
    }
    std::cout << line.str() << (same ? "EQUIVALENT" : "MISS") << ", " << Describe(d) << " ("
              << seconds << " s)\n"
              << Leaders(d, hidden) << draw.text;
  }
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "edited draws " << draws << ": hits " << hits << ", equivalent extensions "
            << equivalent << ", misses " << misses << ", errors " << errors
            << "; redraws: " << redraws.reserved << " models with a reserved name, "
            << redraws.unsuitable << " whose baseline stopped, " << redraws.no_site
            << " without a site of the kind, " << redraws.truth_failed << " truths failed, "
            << redraws.undetectable << " undetectable (chi-square <= " << kMinChiSquare << "), "
            << redraws.out_of_range << " outside the searched range; " << total << " s ("
            << diagnosing << " s diagnosing)\n";
  for (const auto& [kind, counts] : by_kind) {
    std::cout << "  " << kind << ": " << counts.first << " hits of " << counts.second
              << " draws; edits redrawn " << redraws.by_kind[kind] << "\n";
  }
  RecordProperty("draws", draws);
  RecordProperty("hits", hits);
  RecordProperty("equivalent", equivalent);
  RecordProperty("misses", misses);
  RecordProperty("errors", errors);
  RecordProperty("redraws_undetectable", redraws.undetectable);
  EXPECT_GE(hits, 0.9 * draws) << "hits " << hits << " of " << draws << " draws";
}

TEST(AutomatonDiagnosisPropertyClean, CleanDataOfRandomModelHasNoCause) {
  const int draws = std::max(4, DrawsFromEnvironment(56) / 4);
  uint64_t seed = 99261128;
  Redraws redraws;
  int none = 0, false_cause = 0, unexplained = 0, errors = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < draws; ++i) {
    const Draw draw = MakeDraw(seed, std::nullopt, redraws);
    Dump(draw, "clean" + std::to_string(i));
    AutomatonDiagnosis d;
    try {
      d = Diagnose(draw);
    } catch (const std::exception& e) {
      ++errors;
      std::cout << "clean draw " << i << " (seed " << seed - 1 << "): ERROR " << e.what() << "\n"
                << draw.text;
      ADD_FAILURE() << "clean draw " << i << ": " << e.what();
      continue;
    }
    const auto& cause = d.result.cause;
    if (cause == std::vector<std::string>{"none"}) {
      ++none;
      std::cout << "clean draw " << i << " (seed " << seed - 1 << "): none\n";
      continue;
    }
    if (cause == std::vector<std::string>{"unexplained"}) {
      ++unexplained;
    } else {
      ++false_cause;
    }
    std::cout << "clean draw " << i << " (seed " << seed - 1 << "): FALSE ALARM, " << Describe(d)
              << "\n"
              << Leaders(d, "") << draw.text;
  }
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "clean draws " << draws << ": none " << none << ", false causes " << false_cause
            << ", unexplained " << unexplained << ", errors " << errors << "; " << total << " s\n";
  RecordProperty("clean_draws", draws);
  RecordProperty("clean_false_causes", false_cause);
  RecordProperty("clean_unexplained", unexplained);
  EXPECT_EQ(false_cause, 0);
  EXPECT_EQ(unexplained, 0);
}

}  // namespace
}  // namespace hybrid
