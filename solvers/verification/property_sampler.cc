#include "hybrid/verification/property_sampler.h"

#include <rapidcheck.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid {
namespace {

[[noreturn]] void Fail(const std::string& message) {
  throw std::invalid_argument("sampling: " + message);
}

// ---------------------------------------------------------------------------------------------
// Generators. Values are drawn relative to three anchors (a "center", the lower and the upper
// end), so that one generator and one shrinking order serve inputs (center: 0 clamped into the
// bounds), parameters (center: the nominal value) and initial values (center: the midpoint), and
// so that a drawn value stays meaningful when the anchors move with drawn parameter values.

// Interior positions are k / kGrid of the way from the center to an end.
constexpr int kGrid = 1 << 20;

struct Level {
  // Declared from simplest to most complex: shrinking goes towards lower kinds.
  enum Kind : int { kCenter = 0, kHigh = 1, kLow = 2, kInterior = 3 };
  int kind = kCenter;
  // kInterior: in (-kGrid, kGrid); > 0 towards the upper end, < 0 towards the lower end.
  int k = 0;
};

// Frequencies of the kinds, in Level::Kind order.
using KindWeights = std::array<int, 4>;
constexpr KindWeights kInputWeights = {15, 30, 30, 25};
constexpr KindWeights kParameterWeights = {25, 25, 25, 25};
constexpr KindWeights kInitialWeights = {20, 30, 30, 20};

// The value of `level` for anchors center in [lo, hi].
double Resolve(const Level& level, double center, double lo, double hi) {
  switch (level.kind) {
    case Level::kCenter:
      return center;
    case Level::kHigh:
      return hi;
    case Level::kLow:
      return lo;
    default: {
      const double f = static_cast<double>(level.k) / kGrid;
      const double v = f >= 0 ? center + (hi - center) * f : center + (center - lo) * f;
      return std::clamp(v, lo, hi);
    }
  }
}

// Simpler levels: every simpler kind, then (for an interior value) positions towards the center.
rc::Seq<Level> ShrinkLevel(const Level& level) {
  std::vector<Level> kinds;
  for (int kind = Level::kCenter; kind < std::min<int>(level.kind, Level::kInterior); ++kind) {
    kinds.push_back({kind, 0});
  }
  rc::Seq<Level> simpler = rc::seq::fromContainer(std::move(kinds));
  if (level.kind != Level::kInterior) return simpler;
  return rc::seq::concat(
      std::move(simpler),
      rc::seq::map(rc::seq::filter(rc::shrink::towards(level.k, 0), [](int k) { return k != 0; }),
                   [](int k) {
                     return Level{Level::kInterior, k};
                   }));
}

// Levels with kinds drawn by `weights`; an interior value lies above the center with
// probability `above` (the share of the range above the center at nominal parameter values, so
// that interior values are uniform in the range) and uniformly within its side.
rc::Gen<Level> LevelGen(KindWeights weights, double above) {
  return [weights, above](const rc::Random& random, int /*size*/) {
    rc::Random r = random;
    int total = 0;
    for (int w : weights) total += w;
    int pick = static_cast<int>(r.next() % static_cast<std::uint64_t>(total));
    Level level;
    for (int kind = 0; kind < static_cast<int>(weights.size()); ++kind) {
      if (pick < weights[kind]) {
        level.kind = kind;
        break;
      }
      pick -= weights[kind];
    }
    if (level.kind == Level::kInterior) {
      const double side = static_cast<double>(r.next() % (1u << 30)) / (1u << 30);
      const int magnitude = 1 + static_cast<int>(r.next() % (kGrid - 1));
      level.k = side < above ? magnitude : -magnitude;
    }
    return rc::shrinkable::shrinkRecur(level, &ShrinkLevel);
  };
}

// One of `count` > 0 choices, uniformly; shrinking towards the first. (Not rc::gen::inRange,
// whose failure path would link a part of Debian's rapidcheck that is not position-independent,
// which the Python module, a shared object, cannot link.)
rc::Gen<int> ChoiceGen(int count) {
  return [count](const rc::Random& random, int /*size*/) {
    rc::Random r = random;
    const int pick = static_cast<int>(r.next() % static_cast<std::uint64_t>(count));
    return rc::shrinkable::shrinkRecur(pick, [](int k) { return rc::shrink::towards(k, 0); });
  };
}

// One piece of a step signal: its value and its share of the horizon.
struct Piece {
  Level level;
  int weight = 1;
};
constexpr int kMaxWeight = 20;

rc::Gen<int> WeightGen() {
  return [](const rc::Random& random, int /*size*/) {
    const int w = 1 + static_cast<int>(rc::Random(random).next() % kMaxWeight);
    return rc::shrinkable::shrinkRecur(w, [](int v) { return rc::shrink::towards(v, 1); });
  };
}

template <typename T>
std::vector<T> Values(const std::vector<rc::Shrinkable<T>>& shrinkables) {
  std::vector<T> out;
  out.reserve(shrinkables.size());
  for (const auto& s : shrinkables) out.push_back(s.value());
  return out;
}

// A step signal of 1 to `max_segments` pieces (fewer for small sizes). Shrinks by removing
// pieces (largest chunks first, never all), then by shrinking each piece (value, then weight).
rc::Gen<std::vector<Piece>> ScheduleGen(int max_segments, double above) {
  const rc::Gen<Piece> piece =
      rc::gen::map(rc::gen::pair(LevelGen(kInputWeights, above), WeightGen()),
                   [](const std::pair<Level, int>& p) {
                     return Piece{p.first, p.second};
                   });
  return [piece, max_segments](const rc::Random& random, int size) {
    using Pieces = std::vector<rc::Shrinkable<Piece>>;
    rc::Random r = random;
    const int scaled = std::clamp(size, 0, rc::kNominalSize);
    const int most = 1 + (max_segments - 1) * scaled / rc::kNominalSize;
    const int n = 1 + static_cast<int>(r.split().next() % static_cast<std::uint64_t>(most));
    Pieces pieces;
    for (int i = 0; i < n; ++i) pieces.push_back(piece(r.split(), size));
    return rc::shrinkable::map(
        rc::shrinkable::shrinkRecur(
            std::move(pieces),
            [](const Pieces& p) {
              return rc::seq::concat(rc::seq::filter(rc::shrink::removeChunks(p),
                                                     [](const Pieces& q) { return !q.empty(); }),
                                     rc::shrink::eachElement(p, [](const rc::Shrinkable<Piece>& s) {
                                       return s.shrinks();
                                     }));
            }),
        &Values<Piece>);
  };
}

// One value per generator, shrinking each element in turn (a tuple of run-time length).
template <typename T>
rc::Gen<std::vector<T>> Each(std::vector<rc::Gen<T>> gens) {
  return [gens = std::move(gens)](const rc::Random& random, int size) {
    using Items = std::vector<rc::Shrinkable<T>>;
    rc::Random r = random;
    Items items;
    for (const rc::Gen<T>& g : gens) items.push_back(g(r.split(), size));
    return rc::shrinkable::map(rc::shrinkable::shrinkRecur(std::move(items),
                                                           [](const Items& e) {
                                                             return rc::shrink::eachElement(
                                                                 e, [](const rc::Shrinkable<T>& s) {
                                                                   return s.shrinks();
                                                                 });
                                                           }),
                               &Values<T>);
  };
}

// A drawn run: input schedules (one per input), parameter levels, initial-value levels. The
// tuple order is the shrinking priority.
// Input schedules, parameter levels, initial-value levels (one per box), and the init
// declaration of each component that has several (Space::inits order).
using Draw = std::tuple<std::vector<std::vector<Piece>>, std::vector<Level>, std::vector<Level>,
                        std::vector<int>>;

// ---------------------------------------------------------------------------------------------
// What can vary in a system.

// The share of [lo, hi] above `center`.
double Above(double center, double lo, double hi) {
  return hi > lo ? std::clamp((hi - center) / (hi - lo), 0.0, 1.0) : 0.5;
}

struct InputSpace {
  int slot = -1;
  std::string name;
  double above = 0.5;  // at nominal parameter values, for LevelGen
};

struct InitialBox {
  std::string name;  // System name of the variable
  int component = 0;
  int init = 0;  // the component's init declaration that gives it this box
  Range range;
};

// A component with several init declarations: a run starts from one of them.
struct InitChoice {
  int component = 0;
  int count = 0;
};

struct Space {
  std::vector<InputSpace> inputs;
  std::vector<UncertainParameter> parameters;
  std::vector<InitialBox> boxes;
  std::vector<InitChoice> inits;
  // Whether anything varies at nominal parameter values (otherwise one run is enough).
  bool random = false;
};

Space SpaceOf(const System& system) {
  Space space;
  for (int slot : system.symbols().SlotsOfKind(SymbolKind::kInput)) {
    const auto [lo, hi] = system.InputBounds(slot);
    const std::string& name = system.symbols()[slot].name;
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo <= hi)) {
      Fail("input '" + name + "' has bounds [" + std::to_string(lo) + ", " + std::to_string(hi) +
           "]: sampling needs finite, non-empty bounds");
    }
    space.inputs.push_back({slot, name, Above(std::clamp(0.0, lo, hi), lo, hi)});
    if (lo < hi) space.random = true;
  }
  space.parameters = UncertainParameters(system);
  for (const UncertainParameter& p : space.parameters) {
    if (!std::isfinite(p.lo) || !std::isfinite(p.hi) || !(p.lo <= p.nominal && p.nominal <= p.hi)) {
      Fail("parameter '" + p.name + "' = " + std::to_string(p.nominal) +
           " is not within its range [" + std::to_string(p.lo) + ", " + std::to_string(p.hi) + "]");
    }
    space.random = true;
  }
  for (std::size_t c = 0; c < system.components().size(); ++c) {
    const Component& component = system.components()[c];
    const Automaton& a = component.automaton;
    const int count = static_cast<int>(a.initial_states().size());
    if (count > 1) {
      space.inits.push_back({static_cast<int>(c), count});
      space.random = true;
    }
    const std::vector<double> env = a.ParameterEnvironment();
    for (int init = 0; init < count; ++init) {
      for (const InitialValue& v : a.initial_states()[static_cast<std::size_t>(init)].values) {
        if (v.is_point) continue;
        const std::string& name = system.symbols()[component.global_slot[v.slot]].name;
        space.boxes.push_back({name, static_cast<int>(c), init, v.range});
        if (v.range.lo.Evaluate(env) < v.range.hi.Evaluate(env)) space.random = true;
      }
    }
  }
  return space;
}

rc::Gen<Draw> DrawGen(const Space& space, int max_segments) {
  std::vector<rc::Gen<std::vector<Piece>>> schedules;
  for (const InputSpace& in : space.inputs) {
    schedules.push_back(ScheduleGen(max_segments, in.above));
  }
  std::vector<rc::Gen<Level>> parameters;
  for (const UncertainParameter& p : space.parameters) {
    parameters.push_back(LevelGen(kParameterWeights, Above(p.nominal, p.lo, p.hi)));
  }
  std::vector<rc::Gen<Level>> initials;
  // The center of an initial interval is its midpoint: interior values are as likely on each side.
  for (std::size_t i = 0; i < space.boxes.size(); ++i) {
    initials.push_back(LevelGen(kInitialWeights, 0.5));
  }
  std::vector<rc::Gen<int>> inits;
  for (const InitChoice& choice : space.inits) inits.push_back(ChoiceGen(choice.count));
  return rc::gen::tuple(Each(std::move(schedules)), Each(std::move(parameters)),
                        Each(std::move(initials)), Each(std::move(inits)));
}

// The trace of `draw` (inputs, parameters, initial values; not yet replayed). Input bounds and
// initial boxes are evaluated under the drawn parameter values. Throws std::invalid_argument when
// the model rejects the parameter values.
Trace ToTrace(const System& system, const Space& space, const Draw& draw, double horizon) {
  const auto& [schedules, parameter_levels, initial_levels, init_choices] = draw;
  Trace trace;
  for (std::size_t i = 0; i < space.parameters.size(); ++i) {
    const UncertainParameter& p = space.parameters[i];
    trace.parameters.emplace_back(p.name, Resolve(parameter_levels[i], p.nominal, p.lo, p.hi));
  }
  // The system under the drawn parameters (only needed when there are any).
  std::optional<System> drawn;
  if (!trace.parameters.empty()) {
    drawn = system;
    for (const auto& [name, value] : trace.parameters) drawn->SetParameter(name, value);
  }
  const System& model = drawn ? *drawn : system;

  // The init declaration of each component (its first unless drawn), named in the trace.
  std::vector<int> chosen(system.components().size(), 0);
  for (std::size_t i = 0; i < space.inits.size(); ++i) {
    chosen[static_cast<std::size_t>(space.inits[i].component)] = init_choices[i];
    trace.initial_states.emplace_back(space.inits[i].component, init_choices[i]);
  }
  for (std::size_t i = 0; i < space.boxes.size(); ++i) {
    const InitialBox& box = space.boxes[i];
    if (box.init != chosen[static_cast<std::size_t>(box.component)]) continue;
    if (std::any_of(trace.initial_values.begin(), trace.initial_values.end(),
                    [&](const auto& v) { return v.first == box.name; })) {
      continue;  // a shared variable: one value (the first component's)
    }
    const std::vector<double> env =
        model.components()[box.component].automaton.ParameterEnvironment();
    const double lo = box.range.lo.Evaluate(env);
    const double hi = box.range.hi.Evaluate(env);
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo <= hi)) {
      Fail("the initial interval of '" + box.name + "' is empty or not finite");
    }
    trace.initial_values.emplace_back(box.name,
                                      Resolve(initial_levels[i], 0.5 * (lo + hi), lo, hi));
  }

  trace.inputs.until = horizon;
  for (std::size_t i = 0; i < space.inputs.size(); ++i) {
    const auto [lo, hi] = model.InputBounds(space.inputs[i].slot);
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo <= hi)) {
      Fail("the bounds of input '" + space.inputs[i].name + "' are empty or not finite");
    }
    const double zero = std::clamp(0.0, lo, hi);
    const std::vector<Piece>& pieces = schedules[i];
    double total = 0;
    for (const Piece& p : pieces) total += p.weight;
    InputSignal signal;
    signal.slot = space.inputs[i].slot;
    signal.shape = InputSignal::Shape::kStep;
    double elapsed = 0;
    for (const Piece& p : pieces) {
      const double value = Resolve(p.level, zero, lo, hi);
      const double t = horizon * (elapsed / total);
      elapsed += p.weight;
      if (!signal.points.empty() && signal.points.back().second == value) continue;  // merge
      signal.points.emplace_back(t, value);
    }
    trace.inputs.inputs.push_back(std::move(signal));
  }
  return trace;
}

// Whether two traces apply the same run (before replay).
bool SameRun(const Trace& a, const Trace& b) {
  return a.parameters == b.parameters && a.initial_states == b.initial_states &&
         a.initial_values == b.initial_values && a.inputs == b.inputs;
}

int InputPieces(const Trace& trace) {
  int n = 0;
  for (const InputSignal& s : trace.inputs.inputs) n += static_cast<int>(s.points.size());
  return n;
}

std::string Plural(int n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

// The horizon of every run: the option, else the property's `within T`, else the system's
// scenario horizon, else 100. Fails unless it is positive and finite.
double SampleHorizon(const PropertySampler::Options& options, const System& system,
                     const Property& property) {
  double horizon = 100.0;
  if (options.horizon) {
    horizon = *options.horizon;
  } else if (property.horizon) {
    horizon = *property.horizon;
  } else if (system.scenario()) {
    horizon = system.scenario()->until;
  }
  if (!(horizon > 0) || !std::isfinite(horizon)) {
    Fail("the horizon of property '" + property.name + "' must be positive and finite");
  }
  return horizon;
}

// Fails for a system the simulator rejects (e.g. without initial state).
void RequireSimulable(const System& system) {
  try {
    const Simulator probe(system);  // rejects a system without initial state
  } catch (const std::invalid_argument& e) {
    Fail(e.what());
  }
}

// The rapidcheck size of run `run` of `runs`: sizes ramp up over the first half of the runs, so
// that early runs have few pieces.
int RunSize(int run, int runs) {
  return runs == 1 ? rc::kNominalSize
                   : std::min(rc::kNominalSize,
                              static_cast<int>(2LL * rc::kNominalSize * (run + 1) / runs));
}

// The runs of one property: draws turned into traces and replayed.
struct Sampling {
  const System& system;
  const Property& property;
  const Space& space;
  double horizon;
  std::string first_error;  // the first rejection's message

  // Replays `draw` into `trace`: whether it hits (a counterexample or witness); nullopt when the
  // model rejects it (message kept in first_error).
  std::optional<bool> Attempt(const Draw& draw, Trace& trace) {
    try {
      trace = ToTrace(system, space, draw, horizon);
      return ReplayTrace(system, property, trace);
    } catch (const std::invalid_argument& e) {
      if (first_error.empty()) first_error = e.what();
      return std::nullopt;
    }
  }
};

// Greedy shrinking of a hit (`current`, replayed as `best`): moves to the first simpler candidate
// that still hits, until none does or the options' limits are reached. Returns the number of
// steps taken (candidates that denote the same run are taken without counting a step).
int Shrink(Sampling& sampling, const PropertySampler::Options& options,
           rc::Shrinkable<Draw>& current, Trace& best) {
  int steps = 0;
  int examined = 0;
  bool progress = true;
  while (progress && steps < options.max_shrink_steps && examined < options.max_shrink_replays) {
    progress = false;
    rc::Seq<rc::Shrinkable<Draw>> candidates = current.shrinks();
    while (examined < options.max_shrink_replays) {
      rc::Maybe<rc::Shrinkable<Draw>> candidate = candidates.next();
      if (!candidate) break;
      ++examined;
      const Draw draw = candidate->value();
      Trace trace;
      try {
        trace = ToTrace(sampling.system, sampling.space, draw, sampling.horizon);
      } catch (const std::invalid_argument&) {
        continue;
      }
      if (SameRun(trace, best)) {
        // Structurally simpler, the same run (e.g. a value at an anchor that coincides with
        // another): take it without replaying and without counting a step.
        current = std::move(*candidate);
        progress = true;
        break;
      }
      const std::optional<bool> still = sampling.Attempt(draw, trace);
      if (still && *still) {
        current = std::move(*candidate);
        best = std::move(trace);
        ++steps;
        progress = true;
        break;
      }
    }
  }
  return steps;
}

// The reason of a verdict found in run `run` of `runs` ("counterexample in run 17 of 200, shrunk
// in 12 steps from 6 to 2 input pieces"); pieces: the hit's input pieces as found and as shrunk.
std::string FoundReason(const std::string& found_what, int run, int runs, int steps,
                        int pieces_found, int pieces, bool has_inputs) {
  std::string reason =
      found_what + " in run " + std::to_string(run + 1) + " of " + std::to_string(runs);
  if (steps > 0) {
    reason += ", shrunk in " + Plural(steps, "step");
    if (has_inputs) {
      reason += pieces != pieces_found ? " from " + std::to_string(pieces_found) + " to " +
                                             Plural(pieces, "input piece")
                                       : " (" + Plural(pieces, "input piece") + ")";
    }
  } else if (has_inputs) {
    reason += ", " + Plural(pieces, "input piece");
  }
  return reason;
}

}  // namespace

PropertySampler::PropertySampler() : PropertySampler(Options{}) {}

PropertySampler::PropertySampler(Options options) : options_(std::move(options)) {
  if (options_.runs < 1) Fail("runs must be at least 1");
  if (options_.max_segments < 1) Fail("max_segments must be at least 1");
  if (options_.max_shrink_steps < 0) Fail("max_shrink_steps must not be negative");
  if (options_.max_shrink_replays < 0) Fail("max_shrink_replays must not be negative");
  if (options_.horizon && !(*options_.horizon > 0 && std::isfinite(*options_.horizon))) {
    Fail("the horizon must be positive and finite");
  }
}

CheckResult PropertySampler::Check(const System& system, const Property& property) const {
  const auto start = std::chrono::steady_clock::now();
  const bool reach = property.kind == Property::Kind::kReach;
  const std::string found_what = reach ? "witness" : "counterexample";
  const double horizon = SampleHorizon(options_, system, property);
  RequireSimulable(system);

  const Space space = SpaceOf(system);
  const int runs = space.random ? options_.runs : 1;
  const rc::Gen<Draw> gen = DrawGen(space, options_.max_segments);

  CheckResult result;
  result.property = property.name;
  result.kind = property.kind;
  result.method = "sample";
  auto finish = [&](CheckResult r) {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  };

  Sampling sampling{system, property, space, horizon, {}};
  rc::Random random(options_.seed);
  int rejected = 0;
  for (int run = 0; run < runs; ++run) {
    const int size = RunSize(run, runs);
    rc::Shrinkable<Draw> current = gen(random.split(), size);
    Trace best;
    const std::optional<bool> hit = sampling.Attempt(current.value(), best);
    if (!hit) {
      ++rejected;
      continue;
    }
    if (!*hit) continue;
    const int pieces_found = InputPieces(best);
    const int steps = Shrink(sampling, options_, current, best);
    result.verdict = reach ? Verdict::kReachable : Verdict::kViolated;
    result.reason = FoundReason(found_what, run, runs, steps, pieces_found, InputPieces(best),
                                !space.inputs.empty());
    result.trace = std::move(best);
    ConfirmTrace(system, property, result);  // the gate of every reported trace
    return finish(std::move(result));
  }

  if (rejected == runs) {
    Fail("the model rejected every sampled run of property '" + property.name +
         "': " + sampling.first_error);
  }
  result.verdict = Verdict::kUnknown;
  result.reason = "no " + found_what + " in " + Plural(runs - rejected, "sampled run") +
                  " (sampling never proves)";
  if (rejected > 0) {
    result.reason += "; " + std::to_string(rejected) +
                     " draws rejected by the model, first: " + sampling.first_error;
  }
  return finish(std::move(result));
}

}  // namespace hybrid
