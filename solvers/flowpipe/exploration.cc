#include "solvers/flowpipe/exploration.h"

#include <algorithm>
#include <cmath>

#include "solvers/flowpipe/crossing_form.h"

namespace hybrid::flowpipe_internal {
namespace {

constexpr double kSmallestStep = 1.0 / (1 << 20);
constexpr int kInvariantBoxEvery = 32;  // steps between tries of a positively invariant box (and
                                        // after 1, 2, 4, 8 and 16 steps)
constexpr std::size_t kMaxRecordedBoxes = 400000;

// The largest power of two <= x (x > 0).
double PowerOfTwoBelow(double x) {
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  return m == 0.5 ? x : std::ldexp(1.0, e - 1);
}

Segment BoxSegment(std::vector<TightInterval> box) {
  Segment s;
  s.box = std::move(box);
  return s;
}

// The smallest power of two >= x (x > 0).
double PowerOfTwoAbove(double x) {
  const double below = PowerOfTwoBelow(x);
  return below == x ? x : 2 * below;
}

// Replaces the form of every component whose range is more than twice as wide as the box by
// a fresh symbol over the box (a point when the box is one): the box's states in the forms
// stay, each component's correlations are kept only where they are worth more than the box.
void ClipToBox(std::vector<AffineForm>& form, const std::vector<TightInterval>& box) {
  std::size_t next_symbol = 0;
  for (const AffineForm& f : form) next_symbol = std::max(next_symbol, f.coefficients().size());
  for (std::size_t i = 0; i < form.size(); ++i) {
    const TightInterval r = form[i].Range();
    if (r.hi - r.lo <= 2 * (box[i].hi - box[i].lo)) continue;
    form[i] =
        box[i].lo == box[i].hi
            ? AffineForm(box[i].lo)
            : AffineForm::Symbol(box[i].Mid(), static_cast<int>(next_symbol++), box[i].RadiusUp());
  }
}

}  // namespace

Exploration::Exploration(FlowpipeModel& model, std::span<const Property> properties,
                         const FlowpipeReachability::Options& options, double time_cap,
                         FlowpipeReachability::ReachSet* reach_set)
    : model_(model),
      properties_(properties),
      options_(options),
      time_cap_(time_cap),
      reach_set_(reach_set),
      findings_(properties.size()) {
  if (reach_set_) {
    reach_set_->variables.clear();
    reach_set_->boxes.clear();
    for (int i = 0; i < model_.num_variables(); ++i)
      reach_set_->variables.push_back(model_.ComponentName(i));
  }
}

void Exploration::StopAt(double t, const std::string& why) {
  frontier_ = std::min(frontier_, t);
  if (stop_reason_.empty()) stop_reason_ = why;
}

void Exploration::Run(std::vector<FlowpipeModel::Initial> initials) {
  for (FlowpipeModel::Initial& init : initials) Push({init.mode, std::move(init.box), 0.0, {}});
  while (!queue_.empty()) {
    const Entry entry = queue_.top();
    queue_.pop();
    if (AlreadyExplored(entry)) continue;
    if (entry.t0 > time_cap_) {
      frontier_ = std::min(frontier_, entry.t0);
      continue;
    }
    if (steps_ >= options_.max_steps) {
      StopAt(entry.t0, "the step budget (" + std::to_string(options_.max_steps) +
                           " Taylor steps) was used up");
      break;
    }
    if (entries_ >= options_.max_entries) {
      StopAt(entry.t0,
             "the bound of " + std::to_string(options_.max_entries) + " mode entries was reached");
      break;
    }
    explored_[entry.mode].push_back(entry);
    ++entries_;
    Explore(entry);
    if (options_.progress && entries_ % 16 == 0)
      options_.progress(steps_, static_cast<int>(queue_.size()));
  }
  for (; !queue_.empty(); queue_.pop()) frontier_ = std::min(frontier_, queue_.top().t0);
}

bool Exploration::AlreadyExplored(const Entry& entry) const {
  return Covering(entry, /*boxes_only=*/true) != nullptr;
}

const Exploration::Entry* Exploration::Covering(const Entry& entry, bool boxes_only) const {
  const auto it = explored_.find(entry.mode);
  if (it == explored_.end()) return nullptr;
  for (const Entry& old : it->second) {
    if (old.t0 > entry.t0 || (boxes_only && !old.form.empty())) continue;
    bool inside = true;
    for (std::size_t i = 0; i < entry.box.size() && inside; ++i)
      inside = old.box[i].Contains(entry.box[i]);
    if (inside) return &old;
  }
  return nullptr;
}

void Exploration::Push(Entry entry) {
  if (AlreadyExplored(entry)) return;
  if (!entry.form.empty()) {
    // An entry explored from its forms covers only the part of its box they hold, so a later
    // set inside that box is not known to be covered: it is explored from the whole box instead
    // (once: that box then covers every later set inside it), which keeps the fixpoint.
    if (const Entry* old = Covering(entry, /*boxes_only=*/false)) {
      entry.box = old->box;
      entry.form.clear();
    }
  }
  queue_.push(std::move(entry));
}

bool Exploration::InsideUrgentGuard(const Segment& segment,
                                    const FlowpipeModel::CompiledMode& mode) const {
  for (const FlowpipeModel::Jump& jump : mode.jumps) {
    if (!jump.urgent) continue;
    // Read exactly: a state on the boundary of a strict guard does not jump at once.
    bool all = true;
    for (const Residual& r : jump.guard) {
      if (model_.Holds(r, segment, mode.env, /*closure=*/false) != Truth::kTrue) {
        all = false;
        break;
      }
    }
    if (all) return true;
  }
  return false;
}

bool Exploration::MayMeetUrgentGuard(const Segment& segment,
                                     const FlowpipeModel::CompiledMode& mode) const {
  for (const FlowpipeModel::Jump& jump : mode.jumps) {
    if (jump.urgent && model_.HoldsAll(jump.guard, segment, mode.env) == Truth::kMaybe) return true;
  }
  return false;
}

void Exploration::Explore(const Entry& entry) {
  model_.MakeJumps(entry.mode);
  const FlowpipeModel::CompiledMode& mode = model_.Mode(entry.mode);
  if (!mode.tape) {
    StopAt(entry.t0, "mode " + mode.name + ": " + mode.unsupported);
    return;
  }
  std::vector<TightInterval> box = entry.box;
  if (!model_.Contract(mode.invariant, box, mode.env)) return;
  const std::size_t dim = box.size();
  std::optional<std::vector<AffineForm>> start_forms = StartForms(entry, box);
  if (!start_forms) return;
  std::vector<AffineForm> x = std::move(*start_forms);
  std::vector<char> protect(dim, 0);
  for (std::size_t i = 0; i < dim; ++i) protect[i] = static_cast<int>(i) >= model_.num_variables();
  const int max_symbols =
      options_.max_symbols > 0 ? options_.max_symbols : 10 * static_cast<int>(dim);
  const FlowpipeStep stepper(*mode.tape, model_.input_box(), options_.order, protect, max_symbols);
  stepper_ = &stepper;
  const double h0 = options_.step > 0 ? PowerOfTwoBelow(options_.step) : stepper.SuggestedStep(box);
  double h = h0, t = 0.0;
  std::vector<Crossing> crossings(mode.jumps.size());
  std::vector<TightInterval> known = box;  // holds the current start set
  std::vector<TightInterval> hull;
  int local_steps = 0;
  while (true) {
    if (steps_ >= options_.max_steps) {
      StopAt(entry.t0 + t, "the step budget (" + std::to_string(options_.max_steps) +
                               " Taylor steps) was used up");
      break;
    }
    if (entry.t0 + t > time_cap_) {
      frontier_ = std::min(frontier_, entry.t0 + t);
      break;
    }
    Segment start;
    start.series = {x};
    start.remainder.assign(dim, TightInterval(0.0));
    start.ComputeBox(known);
    if (model_.HoldsAll(mode.invariant, start, mode.env) == Truth::kFalse) break;
    if (local_steps == 0) CheckProperties(start, mode, entry.t0, entry.t0);  // the entry itself
    if (InsideUrgentGuard(start, mode)) {
      if (local_steps == 0)
        Visit(start, entry.mode, entry.t0, entry.t0, crossings, &hull, {&x, &known});
      break;
    }
    // A step ends at the next horizon of a `within T` property, so that no segment reaches past it.
    const double length = std::min(h, UntilNextHorizon(entry.t0 + t));
    std::optional<StepResult> step = stepper.Take(x, length, known);
    if (!step) {
      if (h > kSmallestStep) {
        h /= 2;
        continue;
      }
      StopAt(entry.t0 + t, "no enclosure of the flow of mode " + mode.name +
                               " was found at t = " + std::to_string(entry.t0 + t));
      break;
    }
    const bool near_guard = MayMeetUrgentGuard(step->segment, mode);
    if (near_guard && h > h0 / 8) {
      h = std::max(h0 / 8, kSmallestStep);  // refine the crossing
      continue;
    }
    ++steps_;
    ++local_steps;
    if (!Visit(step->segment, entry.mode, entry.t0 + t, entry.t0 + t + length, crossings, &hull,
               {&x, &known}))
      break;
    x = std::move(step->end);
    known = std::move(step->segment.box);  // holds the next start set too
    t += length;
    if (!near_guard && h < h0) h *= 2;
    if (local_steps % kInvariantBoxEvery == 0 || (local_steps & (local_steps - 1)) == 0) {
      std::vector<TightInterval> invariant_box = hull;
      if (InvariantBox(entry.mode, invariant_box, entry.t0 + t)) {
        Visit(BoxSegment(invariant_box), entry.mode, entry.t0 + t,
              std::numeric_limits<double>::infinity(), crossings, nullptr, {});
        break;
      }
    }
  }
  for (std::size_t j = 0; j < crossings.size(); ++j) {
    if (crossings[j].open) CloseCrossing(entry.mode, static_cast<int>(j), crossings[j]);
  }
  stepper_ = nullptr;
}

std::optional<std::vector<AffineForm>> Exploration::StartForms(
    const Entry& entry, const std::vector<TightInterval>& box) {
  std::vector<AffineForm> x(box.size());
  for (std::size_t i = 0; i < box.size(); ++i) {
    if (!box[i].IsFinite()) {
      StopAt(entry.t0, "the set entering mode " + model_.Mode(entry.mode).name +
                           " is unbounded in '" + model_.ComponentName(static_cast<int>(i)) + "'");
      return std::nullopt;
    }
    if (!entry.form.empty()) {
      x[i] = entry.form[i];
    } else {
      // Symbol i for component i: the uncertain parameters' symbols are then protected.
      x[i] = box[i].lo == box[i].hi
                 ? AffineForm(box[i].lo)
                 : AffineForm::Symbol(box[i].Mid(), static_cast<int>(i), box[i].RadiusUp());
    }
  }
  return x;
}

bool Exploration::Visit(const Segment& segment, int mode_index, double t, double t_end,
                        std::vector<Crossing>& crossings, std::vector<TightInterval>* hull,
                        const StepStart& from) {
  const FlowpipeModel::CompiledMode& mode = model_.Mode(mode_index);
  Segment s = segment;
  const Truth inside = model_.HoldsAll(mode.invariant, s, mode.env);
  if (inside == Truth::kFalse) return false;
  if (inside == Truth::kMaybe && !model_.ContractSegment(mode.invariant, s, s.box, mode.env)) {
    return false;
  }
  CheckProperties(s, mode, t, t_end);
  Record(s, mode, t, t_end);
  if (hull) {
    if (hull->empty()) *hull = s.box;
    for (std::size_t i = 0; i < s.box.size(); ++i) (*hull)[i] = Hull((*hull)[i], s.box[i]);
  }
  for (std::size_t j = 0; j < mode.jumps.size(); ++j) {
    const FlowpipeModel::Jump& jump = mode.jumps[j];
    Crossing& c = crossings[j];
    std::vector<TightInterval> box = s.box;
    const bool meets = model_.HoldsAll(jump.guard, s, mode.env) != Truth::kFalse &&
                       model_.ContractSegment(jump.guard_and_invariant, s, box, mode.env);
    if (!meets) {
      if (c.open) CloseCrossing(mode_index, static_cast<int>(j), c);
      continue;
    }
    if (!c.open) {
      c.open = true;
      c.box = box;
      c.t0 = t;
      c.formless = from.x == nullptr;
      c.start = from.x ? *from.x : std::vector<AffineForm>{};
      c.start_known = from.known ? *from.known : std::vector<TightInterval>{};
    } else {
      for (std::size_t i = 0; i < box.size(); ++i) c.box[i] = Hull(c.box[i], box[i]);
      c.formless = c.formless || from.x == nullptr;
    }
    c.t_end = t_end;
  }
  return true;
}

double Exploration::UntilNextHorizon(double t) const {
  double next = std::numeric_limits<double>::infinity();
  for (const Property& p : properties_) {
    if (p.horizon && *p.horizon > t) next = std::min(next, *p.horizon - t);
  }
  // A gap below a millionth of the horizon is not worth a step of its own.
  return next > 1e-6 * (1.0 + t) ? next : std::numeric_limits<double>::infinity();
}

bool Exploration::WouldMeetNewly(const Segment& segment, const FlowpipeModel::CompiledMode& mode,
                                 double t) const {
  for (std::size_t k = 0; k < properties_.size(); ++k) {
    const Property& p = properties_[k];
    if (findings_[k].met || (p.horizon && t >= *p.horizon)) continue;
    const Truth holds = model_.Evaluate(p.predicate, segment, mode);
    if (p.kind == Property::Kind::kAlways ? holds != Truth::kTrue : holds != Truth::kFalse)
      return true;
  }
  return false;
}

void Exploration::CheckProperties(const Segment& segment, const FlowpipeModel::CompiledMode& mode,
                                  double t, double t_end) {
  for (std::size_t k = 0; k < properties_.size(); ++k) {
    const Property& p = properties_[k];
    // A segment of positive length from T on holds only states after T, except its start, which
    // the segment before it (or the entry's start set, checked at its own) holds.
    if (p.horizon && (t > *p.horizon || (t == *p.horizon && t_end > t))) continue;
    const Truth holds = model_.Evaluate(p.predicate, segment, mode);
    const bool bad =
        p.kind == Property::Kind::kAlways ? holds != Truth::kTrue : holds != Truth::kFalse;
    Finding& f = findings_[k];
    if (bad && (!f.met || t < f.met_time)) {
      f.met = true;
      f.met_time = t;
      f.met_mode = mode.name;
    }
  }
}

void Exploration::CloseCrossing(int mode_index, int jump_index, Crossing& crossing) {
  crossing.open = false;
  const FlowpipeModel::CompiledMode& mode = model_.Mode(mode_index);
  const FlowpipeModel::Jump& jump = mode.jumps[static_cast<std::size_t>(jump_index)];
  std::vector<TightInterval> next = crossing.box;
  for (const auto& [component, value] : jump.resets) {
    if (component >= 0)
      next[static_cast<std::size_t>(component)] = model_.Value(value, crossing.box, mode.env);
  }
  std::optional<std::vector<AffineForm>> crossing_form =
      FormOfCrossing(mode_index, jump_index, crossing);
  if (!crossing_form) return;  // no state of the flow meets the guard
  std::vector<AffineForm> form = std::move(*crossing_form);
  if (!form.empty()) {
    // The same reset over the forms: it keeps the correlations the box above loses.
    std::vector<AffineForm> after = form;
    for (const auto& [component, value] : jump.resets) {
      if (component >= 0)
        after[static_cast<std::size_t>(component)] = model_.FormValue(value, form, mode.env);
    }
    // Both enclose the states after the jump.
    for (std::size_t i = 0; i < next.size(); ++i) {
      const TightInterval r = after[i].Range();
      next[i] = {std::max(next[i].lo, r.lo), std::min(next[i].hi, r.hi)};
      if (next[i].lo > next[i].hi) return;
    }
    form = std::move(after);
  }
  const FlowpipeModel::CompiledMode& target = model_.Mode(jump.target);
  if (!model_.Contract(target.invariant, next, target.env)) return;
  if (!form.empty()) ClipToBox(form, next);
  Push({jump.target, std::move(next), crossing.t0, std::move(form)});
}

std::optional<std::vector<AffineForm>> Exploration::FormOfCrossing(int mode_index, int jump_index,
                                                                   const Crossing& crossing) {
  if (crossing.formless || crossing.start.empty() || !stepper_) return std::vector<AffineForm>{};
  if (crossing.t_end <= crossing.t0) return crossing.start;
  // One step from the crossing's first start set over the whole crossing (or a little more):
  // its segment holds every crossing state, over the symbols of that one start set.
  const double h = PowerOfTwoAbove(crossing.t_end - crossing.t0);
  std::optional<StepResult> step = stepper_->Take(crossing.start, h, crossing.start_known);
  if (!step) return std::vector<AffineForm>{};
  ++steps_;
  const FlowpipeModel::CompiledMode& mode = model_.Mode(mode_index);
  const FlowpipeModel::Jump& jump = mode.jumps[static_cast<std::size_t>(jump_index)];
  const CrossingForm crossing_form(model_, mode.env);
  const std::optional<Segment> window =
      crossing_form.Window(step->segment, jump.guard_and_invariant);
  if (!window) return std::nullopt;
  int time_symbol = 0;
  const std::vector<AffineForm> y = CrossingForm::OfSegment(*window, time_symbol);
  return crossing_form.OnGuard(y, time_symbol, jump.guard_and_invariant, crossing.box);
}

bool Exploration::InvariantBox(int mode_index, std::vector<TightInterval>& box, double t) const {
  const FlowpipeModel::CompiledMode& mode = model_.Mode(mode_index);
  if (box.empty()) return false;
  for (double widen : {0.0, 0.001, 0.02, 0.1, 0.3}) {
    std::vector<TightInterval> b = box;
    for (TightInterval& x : b) {
      const double pad = widen == 0 ? 0.0 : widen * (x.hi - x.lo) + 1e-9 * (1.0 + x.MagnitudeUp());
      x = {SubDown(x.lo, pad), AddUp(x.hi, pad)};
    }
    bool inward = true;
    for (int i = 0; i < model_.num_variables() && inward; ++i) {
      const auto k = static_cast<std::size_t>(i);
      for (int side = 0; side < 2 && inward; ++side) {
        std::vector<TightInterval> face = b;
        face[k] = TightInterval(side == 0 ? b[k].lo : b[k].hi);
        // A face the invariant excludes is never reached in this mode.
        if (model_.HoldsAll(mode.invariant, BoxSegment(face), mode.env) == Truth::kFalse) continue;
        const TightInterval f = mode.tape->Evaluate(face, model_.input_box())[k];
        inward = side == 0 ? f.lo >= 0 : f.hi <= 0;
      }
    }
    // A box that would meet a property the flow so far does not meet is not worth taking: the
    // flow goes on instead (always sound).
    if (inward && !WouldMeetNewly(BoxSegment(b), mode, t)) {
      box = b;
      return true;
    }
  }
  return false;
}

void Exploration::Record(const Segment& segment, const FlowpipeModel::CompiledMode& mode, double t,
                         double t_end) {
  if (!reach_set_ || reach_set_->boxes.size() >= kMaxRecordedBoxes) return;
  FlowpipeReachability::ReachBox box;
  box.mode = mode.name;
  box.t_lo = t;
  box.t_hi = t_end;
  for (int i = 0; i < model_.num_variables(); ++i) {
    const TightInterval& x = segment.box[static_cast<std::size_t>(i)];
    box.box.emplace_back(x.lo, x.hi);
  }
  reach_set_->boxes.push_back(std::move(box));
}

}  // namespace hybrid::flowpipe_internal
