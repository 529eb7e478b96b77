#pragma once

// Internal to hybrid::verification: includes Z3's C++ API, which no public header exposes.

#include <z3++.h>

#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/predicate.h"

namespace hybrid {

/// How the encoding follows a mode's flow between two consecutive states of a path.
enum class FlowClass {
  /// Every variable is constant.
  kStill,
  /// Every flow is affine in the inputs with constant coefficients, x' = r0 + sum_j r_j u_j: the
  /// endpoint relation x1 = x0 + r0 d + sum_j r_j V_j with lo_j d <= V_j <= hi_j d is exact (any
  /// V is reached by a constant input), and the invariant, if convex, holds on the straight path
  /// between two points that satisfy it.
  kConstantRate,
  /// One input u, no drift: a driver variable w with w' = c u (c constant) and other flows
  /// v' = K(y) phi(w) u with K reading only variables constant in the mode. Each v is monotone
  /// along a segment (when phi has one sign on w's domain), and where phi has a closed-form
  /// antiderivative Phi (sums of constant multiples of (a + b w)^n, n != -1, also under
  /// max(., eps)), v1 - v0 = K (Phi(w1) - Phi(w0)) / c exactly.
  kSeparable,
  /// Anything else: the moving variables may take any values allowed by the invariant (a sound
  /// over-approximation), except those whose flow is a constant, x' = c, which follow
  /// x1 = x0 + c d exactly (e.g. a motor driven at a set speed beside a finger whose rates read
  /// a variable).
  kGeneral,
};

/// "still", "constant_rate", "separable", "general".
std::string FlowClassName(FlowClass c);

/// The bounded-path encoding of one Automaton into Z3 formulas: the states s_0 .. s_n of a path
/// (mode as one Boolean per mode, continuous variables, the input applied from s_k), and the
/// transition relation T(s_k, s_k+1), which is either a flow of the current mode or a jump.
///
/// Semantics (an over-approximation of the simulator's runs with piecewise-constant inputs, so
/// that a formula unsatisfiable for every path proves a property for every such run):
/// - every state satisfies its mode's invariant; parameters declared with a range take any value
///   in it (the same on the whole path), others their nominal value;
/// - a jump: source mode, guard at s_k with input u_k, resets, target mode at s_k+1;
/// - a flow: as FlowClass says, for the input u_k held constant during the segment;
/// - urgency: an urgent transition whose guard holds somewhere on the segment (before its end)
///   forbids the segment. Encoded exactly where every state comparison of the guard is affine
///   with constant coefficients along the segment (kConstantRate with one input and no drift,
///   or drift and no input; kSeparable when the comparisons read one moving variable; kGeneral
///   when the comparisons read only variables with a constant flow); other
///   urgent transitions are not encoded (sound: more paths);
/// - lazy transitions, declaration-order priority and Zeno limits are not encoded (more paths).
///
/// Names: every Z3 constant is named from a fixed kind and indices only ("x.3@2": continuous
/// variable 3 at s_2; "u.", "V." inputs and their integrals, "d@", "flow@", "mode.", "jump.",
/// "amo." at-most-one auxiliaries, "p." parameters by slot, "aux." auxiliaries), never from a
/// name of the model: no model name can meet one of the encoding's, whatever it is called. The
/// names are unique within one encoding, so `ctx` must not hold the constants of another
/// SmtEncoding (one context per encoding).
///
/// Size: linear in the numbers of modes and transitions per step (exactly-one-mode by a ladder
/// of auxiliary Booleans, transitions indexed by source mode); State(k) and Transition(k) are
/// built once and reused.
class SmtEncoding {
 public:
  /// The encoding of `automaton` in `ctx`; both are borrowed and must outlive the encoding.
  /// Throws std::invalid_argument if `automaton` has no initial state.
  SmtEncoding(z3::context& ctx, const Automaton& automaton);

  const Automaton& automaton() const { return automaton_; }
  /// The context of the encoding's formulas (borrowed at construction).
  z3::context& context() const { return ctx_; }
  FlowClass flow_class(ModeId m) const { return modes_[m.value()].flow_class; }

  /// s_0 is an initial state (parameters in their ranges, and s_0 in some InitialState(j)).
  z3::expr Initial();
  /// s_0 is in the automaton's initial state number `index` (declaration order): its mode, its
  /// points and boxes.
  z3::expr InitialState(int index);
  /// The first initial state whose InitialState holds at s_0 in `model`, or -1 if none (a path
  /// not from an initial state, e.g. of an induction step).
  int InitialIndex(const z3::model& model);
  /// Well-formedness of s_k: exactly one mode, its invariant, inputs within bounds.
  z3::expr State(int k);
  /// State(k) with s_k in one of the modes flagged in `modes` (a flag per mode): the same as
  /// State(k) and "not InMode(k, n)" for each mode n not flagged, but of the size of the flagged
  /// modes (their invariants only), so that a query about a few modes of a large automaton does
  /// not carry the others. Built anew on each call.
  z3::expr StateIn(int k, const std::vector<bool>& modes);
  /// T(s_k, s_k+1).
  z3::expr Transition(int k);
  /// T(s_k, s_k+1) with s_k in mode `m` (smaller than Transition(k) and InMode(k, m)).
  z3::expr TransitionFrom(int k, ModeId m);
  /// T(s_k, s_k+1) with s_k in mode `m`, by one move: m's flow (`jump` empty) or the jump by the
  /// transition `jump` (one from m). TransitionFrom(k, m) is the disjunction of m's moves.
  z3::expr MoveFrom(int k, ModeId m, std::optional<TransitionId> jump);
  /// `p` at s_k, evaluated leniently within `tolerance` (comparisons in positive position hold
  /// within it, under `not` they must hold with that margin; tolerance 0 is exact).
  z3::expr Holds(const Predicate& p, int k, double tolerance = 0.0);
  /// Holds(p, k, tolerance) where s_k is in one of the modes flagged in `modes` (a flag per
  /// mode; StateIn(k, modes) holds): the discrete variables are read from the flagged modes
  /// only and "in" an unflagged mode is false, so that the formula has the size of the flagged
  /// modes, not of the automaton.
  z3::expr HoldsIn(const Predicate& p, int k, const std::vector<bool>& modes,
                   double tolerance = 0.0);
  /// s_k is in mode `m`.
  z3::expr InMode(int k, ModeId m);
  /// Every uncertain parameter at its nominal value.
  z3::expr NominalParameters();
  /// Definitions of the auxiliary variables introduced by the formulas built since the last call
  /// (a quotient q = a / b becomes b q = a): assert them at the top level, outside any negation,
  /// next to the formulas that use them.
  z3::expr TakeDefinitions();
  /// Uncertain parameters: name -> Z3 constant (nominal ones are numbers).
  const std::vector<std::pair<std::string, z3::expr>>& uncertain() const { return uncertain_; }

  /// One step of a satisfying path, read back from a model.
  struct PathStep {
    int mode = 0;
    std::vector<double> x;      // continuous variables by automaton slot order of variables()
    std::vector<double> input;  // inputs (order of automaton().inputs())
    bool flow = false;          // the step from this state to the next is a flow
    double duration = 0.0;      // of that flow
    int transition = -1;        // or the jump taken
  };
  /// States s_0 .. s_n of a model of a path of length n. For a flow step, `input` and
  /// `duration` give a constant input that follows the encoded segment: where the flow has a
  /// drift or reads several inputs, each read input at its mean V_i / d for the model's d (the
  /// exact endpoint); where it reads one input and has no drift (the path depends only on V),
  /// the model's input if it has V's sign and is not very slow, else full speed towards V, for
  /// V / u; inputs the flow does not read (and all inputs of a kGeneral flow) keep the model's
  /// values.
  std::vector<PathStep> ReadPath(const z3::model& model, int n);
  /// Values of the uncertain parameters in `model`.
  std::vector<std::pair<std::string, double>> ReadParameters(const z3::model& model);

  /// The Z3 name of a constant of the encoding: `kind` (one of the fixed kinds listed in the
  /// class comment), `index` (>= 0, or -1 for none) and `step` (>= 0, or -1 for none), e.g.
  /// ConstantName("x", 3, 2) == "x.3@2". Exposed for tests.
  static std::string ConstantName(std::string_view kind, int index, int step);

 private:
  // State(k) (allowed: null) or StateIn(k, *allowed).
  z3::expr StateOf(int k, const std::vector<bool>* allowed);
  // Holds (modes: null) or HoldsIn(p, k, *modes, tolerance).
  z3::expr HoldsOf(const Predicate& p, int k, const std::vector<bool>* modes, double tolerance);
  // The value of discrete variable `slot` at s_k, where s_k is in a mode flagged in `modes`
  // (empty: any mode): an ite over those modes' values, the value itself for one mode.
  z3::expr DiscreteIn(int k, int slot, const std::vector<bool>& modes);

  struct StepVars {
    std::vector<z3::expr> mode;  // one Bool per mode
    std::vector<z3::expr> x;     // per continuous variable (index in variables())
    std::vector<z3::expr> u;     // per input (index in inputs())
    std::vector<z3::expr> v;     // input integral over the flow from this state
    z3::expr d;                  // duration of the flow from this state
    z3::expr flow;               // Bool: the step from here is a flow
    std::vector<z3::expr> jump;  // Bool per transition: the step from here is that jump
    std::vector<z3::expr> amo;   // ladder: amo[m] = some mode <= m holds (at most one mode)
  };
  // A formula built once, with the definitions of the auxiliaries it introduced.
  struct Built {
    z3::expr formula;
    std::vector<z3::expr> definitions;
  };
  struct SeparableFlow {
    int var = -1;                              // variable index
    Expression k;                              // mode-constant factor K
    double sign_phi = 0.0;                     // sign of phi on the driver's domain (0: unknown)
    std::optional<Expression> antiderivative;  // Phi(w), over the driver's slot
    std::vector<Comparison> domain;            // where Phi' = phi (evaluated at both ends)
    // max(B^n, eps) with B = alpha + beta w: (alpha, beta, eps^(1/n)).
    std::optional<std::tuple<double, double, double>> saturation;
  };
  struct ModeInfo {
    FlowClass flow_class = FlowClass::kGeneral;
    std::vector<int> moving;  // variable indices with a nonzero flow
    // kConstantRate: per moving variable, r0 and r_j (per input index).
    std::vector<double> drift;              // by variable index
    std::vector<std::vector<double>> rate;  // [variable index][input index]
    // kSeparable
    int input = -1;
    int driver = -1;
    double driver_rate = 0.0;
    std::vector<SeparableFlow> separable;
    // kGeneral: by variable index, whether the flow is a constant (x' = drift[x]), which the
    // encoding follows exactly whatever the other flows are (x1 = x0 + drift d).
    std::vector<bool> constant_drift;
  };
  // The nonzero flows of a mode: (variable index, right-hand side with nominal parameters folded).
  using Flows = std::vector<std::pair<int, Expression>>;
  // The two ends s_k, s_k+1 of a flow segment and their environments.
  struct Segment {
    const StepVars& a;
    const StepVars& b;
    const std::vector<std::optional<z3::expr>>& env0;
    const std::vector<std::optional<z3::expr>>& env1;
  };
  // The terms of a separable variable's exact law c (v1 - v0) = K (Phi(w1) - Phi(w0)).
  struct Law {
    const z3::expr& k;     // K
    const z3::expr& dv;    // v1 - v0
    const z3::expr& phi0;  // Phi(w0)
    const z3::expr& phi1;  // Phi(w1)
    const z3::expr& c;     // the driver's rate
  };
  // One comparison of an urgent guard along a segment: alpha + beta sigma REL 0.
  struct GuardAtom {
    z3::expr alpha;
    double beta;      // sign and magnitude (for the case split)
    z3::expr beta_q;  // the exact rational value
    Relation rel;
  };

  StepVars& Vars(int k);
  // The duration and representative inputs of the flow from `v` (s.mode, s.input set).
  void ReadFlow(const z3::model& model, const StepVars& v, PathStep& s);
  const std::vector<std::optional<z3::expr>>& Env(int k);
  z3::expr Reuse(std::deque<std::optional<Built>>& cache, int k,
                 const std::function<z3::expr()>& build);
  z3::expr Translate(const Expression& e, const std::vector<std::optional<z3::expr>>& env);
  // Translate's num / den: exact for a numeral den, else an auxiliary q with the definition
  // den q = num where den != 0.
  z3::expr Quotient(const z3::expr& num, const z3::expr& den);
  // Translate's base^ex: a product for an integer exponent of magnitude at most 16 (its reciprocal
  // for a negative one), else an unconstrained auxiliary. `translate` translates `base`.
  z3::expr Power(const Expression& base, const Expression& ex,
                 const std::function<z3::expr(const Expression&)>& translate);
  // r lies in `band` (its ends as z3 comparisons; an absent end is no constraint).
  static z3::expr InBand(const z3::expr& r, const ResidualBand& band);
  // c within the signed margin (ResidualBand: LenientBand for a margin, ResidualBand::Of with
  // `boundary` for 0), encoded over the translated residual.
  z3::expr Compare(const Comparison& c, const std::vector<std::optional<z3::expr>>& env,
                   double margin, Boundary boundary = Boundary::kExact);
  z3::expr Conjunction(const Constraint& c, const std::vector<std::optional<z3::expr>>& env,
                       Boundary boundary = Boundary::kExact);
  z3::expr Flow(int k, int mode);
  // The representative constant input u_k has the sign of the input's integral V_k, and V_k lies
  // within the input's bounds times d.
  z3::expr InputLink(const StepVars& a, int i);
  // Adds to `out` the kConstantRate flow from s_k: the inputs' links and the exact endpoints.
  void ConstantRateFlow(int k, const ModeInfo& info, z3::expr& out);
  // Adds to `out` the kSeparable flow from s_k: the input's link, the driver's endpoint and, per
  // separable variable, SeparableVariable.
  void SeparableFlowStep(int k, const ModeInfo& info, z3::expr& out);
  // Adds to `out` what bounds one separable variable over `segment`: monotonicity (where phi has
  // one sign) and the exact law (where there is an antiderivative).
  void SeparableVariable(const Segment& segment, const ModeInfo& info, const SeparableFlow& sf,
                         z3::expr& out);
  // Adds to `out` the exact law of `sf` where both ends lie in its domain, and SaturationCrossing.
  void SeparableLaw(const Segment& segment, const ModeInfo& info, const SeparableFlow& sf,
                    const z3::expr& K, const z3::expr& dv, double s, z3::expr& out);
  // Adds to `out` the segments with one end inside the law's domain and the other in the
  // saturation of max(B^n, eps): the law holds up to the edge, v moves on monotonically beyond it.
  void SaturationCrossing(const Segment& segment, const ModeInfo& info, const SeparableFlow& sf,
                          const Law& law, z3::expr& out);
  z3::expr NoUrgentGuardOnSegment(int k, int mode);
  // For kConstantRate: the segment from `a` as x(sigma) = x_k + dir sigma with sigma = V_i (one
  // input, no drift) or d (drift, no input); false where it is neither (urgency not encoded).
  bool StraightSegment(const ModeInfo& info, const StepVars& a,
                       std::optional<z3::expr>& const_sigma, std::vector<double>& dir) const;
  // The comparisons of urgent transition `tr`'s guard as affine functions of the segment's
  // parameter sigma (const_sigma set: along `dir`; else kSeparable, sigma the change of the one
  // moving variable read, set in `sep_var`); nullopt when a comparison is not of that form.
  std::optional<std::vector<GuardAtom>> GuardAtoms(const hybrid::Transition& tr,
                                                   const std::vector<bool>& moving,
                                                   const std::optional<z3::expr>& const_sigma,
                                                   const std::vector<double>& dir,
                                                   const std::vector<std::optional<z3::expr>>& env,
                                                   int& sep_var);
  // The guard `atoms` hold at some sigma of the segment ending at `sigma_end`; sign: +1 for
  // [0, end), -1 for (end, 0], 0 for {0}.
  z3::expr GuardMeets(const std::vector<GuardAtom>& atoms, const z3::expr& sigma_end, int sign);
  // fixed && (at.alpha REL 0): the atom at sigma = 0 (or where it does not depend on sigma).
  static z3::expr AndHoldsAtStart(const z3::expr& fixed, const GuardAtom& at);
  // Adds the bound on sigma that `at` gives (beta != 0) to `lower` or `upper` (bound, strict).
  static void AddSigmaBound(const GuardAtom& at, std::vector<std::pair<z3::expr, bool>>& lower,
                            std::vector<std::pair<z3::expr, bool>>& upper);
  z3::expr Jump(int k, int t);
  // The moves of TransitionFrom: the flow in `mode` (s_k+1 in it too), the jump by transition t.
  z3::expr FlowMove(int k, int mode);
  z3::expr JumpMove(int k, int t);
  // Whether `c` reads a continuous variable with a flow in mode `mode`.
  bool ReadsMovingVariable(const Comparison& c, int mode) const;
  z3::expr Discrete(int k, int slot);
  Expression Fold(const Expression& e) const;
  void Classify();
  // The nonzero flows of `mode`, recorded as moving in `info`.
  Flows MovingFlows(const Mode& mode, ModeInfo& info) const;
  // Whether every flow is affine in the inputs with constant coefficients; records the drifts
  // and rates in `info` (as far as it got).
  bool ConstantRates(const Flows& flows, ModeInfo& info) const;
  // Makes `info` kSeparable if its flows are: one input u, a driver w' = c u, others K phi(w) u.
  void ClassifySeparable(const Flows& flows, ModeInfo& info) const;
  // kGeneral: records the flows that are constants (ModeInfo::constant_drift).
  void ConstantDrifts(const Flows& flows, ModeInfo& info) const;
  // The separable form of variable v's flow f (input slot u, driver slot w, still: slots that do
  // not move in the mode), or nullopt if f has none.
  std::optional<SeparableFlow> Separate(int v, const Expression& f, int u, int w,
                                        const std::vector<bool>& still, int driver) const;
  // Splits the factors of h into the mode-constant K and phi(w); false if a factor reads a moving
  // variable other than w or an input, or mixes w with other symbols.
  bool SplitFactors(const Expression& h, int w, const std::vector<bool>& still, Expression& k,
                    Expression& phi) const;
  // The sign of phi on the domain of variable `driver` at nominal parameters (0: unknown).
  double SignOnDomain(const Expression& phi, int driver) const;
  z3::expr Fresh();

  z3::context& ctx_;
  const Automaton& automaton_;
  std::vector<int> var_slots_;  // slot of each continuous variable
  std::vector<int> var_index_;  // slot -> variable index, -1 otherwise
  std::vector<int> input_slots_;
  std::vector<int> input_index_;  // slot -> input index, -1 otherwise
  std::vector<double> input_lo_, input_hi_;
  std::vector<std::optional<z3::expr>> params_;  // per slot (parameters only)
  std::vector<bool> uncertain_slot_;             // parameter depends on an uncertain one
  std::vector<double> nominal_;                  // ParameterEnvironment()
  std::vector<std::pair<std::string, z3::expr>> uncertain_;
  std::vector<ModeInfo> modes_;
  std::vector<z3::expr> definitions_;
  std::vector<z3::expr> parameter_definitions_;  // asserted with every State
  std::deque<StepVars> steps_;                   // deque: references stay valid as steps are added
  std::deque<std::vector<std::optional<z3::expr>>> envs_;  // Env(k), per step
  std::deque<std::optional<Built>> states_, transitions_;  // State(k), Transition(k)
  std::vector<std::vector<int>> outgoing_;                 // per mode: transitions from it
  int fresh_ = 0;
};

/// A path read back from a model (SmtEncoding::ReadPath, ReadParameters) in words, for the debug
/// log: a line with the uncertain parameters' values, then one line per state (mode, continuous
/// variables, inputs, and the step that follows: a flow and its duration, or a jump). Uses no Z3
/// context: describing a path changes nothing the solver counts.
std::vector<std::string> DescribePath(
    const Automaton& automaton, const std::vector<SmtEncoding::PathStep>& path,
    const std::vector<std::pair<std::string, double>>& parameters);

}  // namespace hybrid
