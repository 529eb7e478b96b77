// Tests of the set a guard cuts out of a flowpipe (solvers/flowpipe/crossing_form.h) against
// closed forms: with constant rates the crossing states are known exactly (the time at which
// each start state meets the guard is a linear function of it), so the forms must hold them and,
// once the time symbol is eliminated, lie close to them.
#include "solvers/flowpipe/crossing_form.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "hybrid/automaton/parser.h"
#include "solvers/flowpipe/flowpipe_step.h"

namespace hybrid::flowpipe_internal {
namespace {

// The value of f's affine part at the symbol values e (its error term left out).
double Evaluate(const AffineForm& f, const std::vector<double>& e) {
  double v = f.center();
  for (std::size_t i = 0; i < f.coefficients().size() && i < e.size(); ++i)
    v += f.coefficients()[i] * e[i];
  return v;
}

// x' = 1, y' = 1/2 in `move` (inv x <= 1) and a jump at x >= 1; the start set x0 in [0, 0.25],
// y0 in [0, 1]. State x0 meets the guard at time 1 - x0, at y = y0 + (1 - x0) / 2.
struct Ramp {
  System system = ParseModel(R"(automaton ramp {
  var x in [-10, 10];
  var y in [-10, 10];
  mode move { x' = 1; y' = 0.5; inv x <= 1; }
  mode done { }
  transition leave: move -> done { guard x >= 1; }
  init move { x in [0, 0.25]; y in [0, 1]; }
})",
                             "ramp.ha");
  FlowpipeModel model{system};
  int mode = 0;

  Ramp() {
    mode = model.Initials().at(0).mode;
    model.MakeJumps(mode);
  }
  const FlowpipeModel::CompiledMode& Mode() { return model.Mode(mode); }
  // One step of length 2 from the start set (symbols 0 and 1 for x0 and y0).
  Segment Step() {
    const FlowpipeStep stepper(*Mode().tape, model.input_box(), 4, {0, 0}, 20);
    const std::vector<AffineForm> x = {AffineForm::Symbol(0.125, 0, 0.125),
                                       AffineForm::Symbol(0.5, 1, 0.5)};
    std::optional<StepResult> step = stepper.Take(x, 2.0);
    EXPECT_TRUE(step.has_value());
    return step->segment;
  }
};

TEST(CrossingForm, RestrictedSegmentHoldsTheShiftedPolynomial) {
  // x(s) = (1 + 0.1 e0) + 2 s + 3 s^2, s in [0, 1]; over s = 0.25 + u:
  // x = 1.6875 + 0.1 e0 + 3.5 u + 3 u^2, u in [0, 0.25].
  Segment s;
  s.h = 1.0;
  s.series = {{AffineForm::Symbol(1.0, 0, 0.1)}, {AffineForm(2.0)}, {AffineForm(3.0)}};
  s.remainder = {TightInterval(0.0)};
  s.box = {TightInterval(1.0 - 0.1, 6.1)};
  const Segment r = s.Restricted(0.25, 0.5);
  EXPECT_EQ(r.h, 0.25);
  ASSERT_EQ(r.series.size(), 3u);
  EXPECT_TRUE(r.series[0][0].Range().Contains(TightInterval(1.6875 - 0.1, 1.6875 + 0.1)));
  EXPECT_NEAR(r.series[0][0].center(), 1.6875, 1e-15);
  EXPECT_NEAR(r.series[0][0].coefficient(0), 0.1, 1e-15);
  EXPECT_TRUE(r.series[1][0].Range().Contains(3.5));
  EXPECT_LT(r.series[1][0].RadiusUp(), 1e-14);
  EXPECT_TRUE(r.series[2][0].Range().Contains(3.0));
  // The exact range over the restriction is [x(0.25) - 0.1, x(0.5) + 0.1] = [1.5875, 2.85].
  EXPECT_TRUE(r.box[0].Contains(TightInterval(1.5875, 2.85)));
  EXPECT_LT(r.box[0].hi - r.box[0].lo, (2.85 - 1.5875) + 1e-12);
}

TEST(CrossingForm, WindowKeepsTheTimesOfTheCrossing) {
  Ramp ramp;
  const Segment step = ramp.Step();
  const CrossingForm crossing(ramp.model, ramp.Mode().env);
  const std::optional<Segment> window =
      crossing.Window(step, ramp.Mode().jumps.at(0).guard_and_invariant);
  ASSERT_TRUE(window.has_value());
  // The crossing happens for s in [0.75, 1]: the window holds it, with at most a piece of the
  // first round (2 / 32) on either side, and its states reach x = 1.
  EXPECT_LE(window->h, 0.25 + 2 * (2.0 / 32));
  EXPECT_GE(window->h, 0.25);
  EXPECT_TRUE(window->box[0].Contains(1.0));
}

TEST(CrossingForm, WindowIsEmptyWhenTheGuardIsNeverMet) {
  Ramp ramp;
  Segment step = ramp.Step();
  step = step.Restricted(0.0, 0.5);  // x <= 0.75 throughout
  const CrossingForm crossing(ramp.model, ramp.Mode().env);
  EXPECT_FALSE(crossing.Window(step, ramp.Mode().jumps.at(0).guard_and_invariant).has_value());
}

TEST(CrossingForm, EliminatingTimeLeavesTheCrossingStates) {
  Ramp ramp;
  const Segment step = ramp.Step();
  const CrossingForm crossing(ramp.model, ramp.Mode().env);
  const auto& atoms = ramp.Mode().jumps.at(0).guard_and_invariant;
  const std::optional<Segment> window = crossing.Window(step, atoms);
  ASSERT_TRUE(window.has_value());
  int time_symbol = -1;
  const std::vector<AffineForm> y = CrossingForm::OfSegment(*window, time_symbol);
  EXPECT_EQ(time_symbol, 2);
  const std::vector<TightInterval> box = {TightInterval(1.0), TightInterval(0.0, 1.5)};
  const std::vector<AffineForm> on = crossing.OnGuard(y, time_symbol, atoms, box);
  // x is pinned to the guard's boundary, up to rounding.
  EXPECT_LT(on[0].RadiusUp(), 1e-12);
  EXPECT_NEAR(on[0].center(), 1.0, 1e-12);
  // y = y0 + (1 - x0) / 2 as a function of the start symbols: for random start states, the
  // forms at their symbols (the eliminated time symbol at its centre) give the crossing state
  // within the error terms.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 100; ++k) {
    const std::vector<double> e = {unit(rng), unit(rng), 0.0};
    const double x0 = 0.125 + 0.125 * e[0], y0 = 0.5 + 0.5 * e[1];
    const double exact = y0 + (1 - x0) / 2;
    const double slack = on[1].err() + std::fabs(on[1].coefficient(2));
    EXPECT_NEAR(Evaluate(on[1], e), exact, slack + 1e-12);
  }
  // The time symbol's part is small: the crossing time is a function of the start state.
  EXPECT_LT(std::fabs(on[1].coefficient(2)) + on[1].err(), 1e-9);
}

}  // namespace
}  // namespace hybrid::flowpipe_internal
