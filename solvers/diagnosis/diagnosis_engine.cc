#include "hybrid/diagnosis/diagnosis_engine.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include "hybrid/diagnosis/parallel_for.h"
#include "hybrid/diagnosis/spike_filter.h"
#include "solvers/diagnosis/profile_search.h"

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Robust loss of one normalised residual (Huber): z^2 inside +-d, linear outside.
double Rho(double z, double d) {
  const double a = std::abs(z);
  return a <= d ? z * z : 2.0 * d * a - d * d;
}

// Signed square root of Rho: its square is Rho (Ceres minimises the sum of squares).
double RootRho(double z, double d) {
  const double a = std::abs(z);
  const double r = a <= d ? a : std::sqrt(2.0 * d * a - d * d);
  return z < 0 ? -r : r;
}

// The score of one run's prediction: robust loss and per-channel sums of squared residuals, of
// all residuals and of those that are not spikes (SpikeMask).
struct RunScore {
  double loss = 0.0;  // robust, chi-square units; +inf when the run could not be predicted
  std::vector<double> sse, clean_sse;
  std::vector<int> n, clean_n;
};

// `values` with (parameter, value) appended.
ParameterValues With(ParameterValues values, int parameter, double value) {
  values.emplace_back(parameter, value);
  return values;
}

// The first failure of a search: how many predictions failed and the first message.
struct Failures {
  std::mutex mutex;
  int count = 0;
  std::string message;
  void Record(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    if (count++ == 0) message = what;
  }
};

void CheckOptions(const DiagnosisOptions& o) {
  const std::vector<double>& h = o.horizons;
  bool ok = !h.empty() && h.back() == 1.0;
  for (size_t i = 0; i < h.size(); ++i) ok = ok && h[i] > 0.0 && (i == 0 || h[i] > h[i - 1]);
  if (!ok) {
    throw std::invalid_argument("the horizons must ascend in (0, 1] and end with 1");
  }
  if (!(o.main_fraction >= 0.0 && o.main_fraction <= 1.0)) {
    throw std::invalid_argument("main_fraction must lie in [0, 1]");
  }
}

// The validated inputs of DiagnoseModel and the operations every step needs: predictions
// (counted against the budget; a failure of the model can be caught), scores, and the tests
// on held-out residuals.
class Engine {
 public:
  Engine(const DiagnosisModel& model, const std::vector<DiagnosisRun>& runs,
         const ChannelNoise& noise, const DiagnosisOptions& o)
      : model_(model), runs_(runs), o_(o) {
    if (runs.empty()) throw std::invalid_argument("the data have no runs");
    CheckOptions(o);
    const size_t channels = noise.variance.size();
    if (channels == 0 || noise.dof.size() != channels) {
      throw std::invalid_argument("the noise floor needs one entry per channel");
    }
    for (size_t c = 0; c < channels; ++c) {
      sigma_.push_back(std::sqrt(std::max(noise.variance[c], 1e-12)));
    }
    dof_ = noise.dof;
    for (const DiagnosisRun& run : runs) {
      if (run.channels.size() != channels) {
        throw std::invalid_argument("run '" + run.label + "' has " +
                                    std::to_string(run.channels.size()) + " channels, not " +
                                    std::to_string(channels));
      }
      for (const std::vector<double>& channel : run.channels) {
        if (channel.size() != run.input.size()) {
          throw std::invalid_argument(
              "run '" + run.label + "' has " + std::to_string(run.input.size()) +
              " input samples but a channel of " + std::to_string(channel.size()));
        }
      }
      samples_ += static_cast<int>(run.input.size());
      std::vector<size_t> ends;
      for (double h : o.horizons) {
        ends.push_back(static_cast<size_t>(std::ceil(h * static_cast<double>(run.input.size()))));
      }
      horizon_ends_.push_back(ends);
    }
  }

  int runs() const { return static_cast<int>(runs_.size()); }
  int channels() const { return static_cast<int>(sigma_.size()); }
  int samples() const { return samples_; }
  int horizons() const { return static_cast<int>(o_.horizons.size()); }
  double sigma(int c) const { return sigma_[c]; }
  const DiagnosisRun& run(int r) const { return runs_[r]; }
  const DiagnosisModel& model() const { return model_; }
  const DiagnosisOptions& options() const { return o_; }
  const CandidateParameter& parameter(int p) const { return model_.Parameters()[p]; }
  long predictions() const { return predictions_; }
  bool OverBudget() const { return predictions_ > o_.max_predictions; }

  // The model's prediction of run r; a std::exception of the model propagates.
  RunPrediction Predict(int r, const ParameterValues& values) const {
    ++predictions_;
    RunPrediction p = model_.Predict(r, values);
    CheckShape(r, p);
    return p;
  }

  // Predict, with a failure of the model (any std::exception it throws) recorded in `failures`
  // instead of thrown: nullopt then.
  std::optional<RunPrediction> TryPredict(int r, const ParameterValues& values,
                                          Failures& failures) const {
    ++predictions_;
    std::optional<RunPrediction> p;
    try {
      p = model_.Predict(r, values);
    } catch (const std::exception& e) {
      failures.Record(e.what());
      return std::nullopt;
    }
    CheckShape(r, *p);
    return p;
  }

  // The predictions of every run under `values` (in parallel); throws as Predict does.
  std::vector<RunPrediction> PredictAll(const ParameterValues& values) const {
    std::vector<RunPrediction> predictions(runs());
    ParallelFor(runs(), o_.threads, [&](int r) { predictions[r] = Predict(r, values); });
    return predictions;
  }

  // PredictAll, nullopt when a run cannot be predicted.
  std::optional<std::vector<RunPrediction>> TryPredictAll(const ParameterValues& values) const {
    Failures failures;
    std::vector<std::optional<RunPrediction>> p(runs());
    ParallelFor(runs(), o_.threads, [&](int r) { p[r] = TryPredict(r, values, failures); });
    if (failures.count > 0) return std::nullopt;
    std::vector<RunPrediction> out;
    for (auto& x : p) out.push_back(std::move(*x));
    return out;
  }

  // The robust loss of run r's first ceil(h n) samples for each horizon h.
  std::vector<double> HorizonLoss(int r, const RunPrediction& p) const {
    const DiagnosisRun& run = runs_[r];
    const std::vector<size_t>& ends = horizon_ends_[r];
    const size_t n = run.input.size();
    // Each sample's terms first (sample-major), a channel at a time, then added up sample by
    // sample and channel by channel up to each horizon's end: the sums of one pass over both,
    // bit for bit (a missing sample adds +0, and every term is >= +0).
    const size_t J = static_cast<size_t>(channels());
    std::vector<double> terms(n * J);
    for (size_t j = 0; j < J; ++j) {
      const double* m = run.channels[j].data();
      const double* q = p.channels[j].data();
      const double sigma = sigma_[j], huber = o_.huber;
      for (size_t k = 0; k < n; ++k)
        terms[k * J + j] = std::isnan(m[k]) ? 0.0 : Rho((m[k] - q[k]) / sigma, huber);
    }
    std::vector<double> out(ends.size());
    double loss = 0.0;
    size_t done = 0;  // terms added so far
    for (size_t h = 0; h < ends.size(); ++h) {
      const size_t end = std::min(ends[h], n) * J;
      for (; done < end; ++done) loss += terms[done];
      out[h] = loss;
    }
    return out;
  }

  // A prediction that does not have the run's shape is a misuse of the interface.
  void CheckShape(int r, const RunPrediction& p) const {
    const size_t n = runs_[r].input.size();
    bool fits = p.channels.size() == sigma_.size() && p.mode.size() == n && p.direction.size() == n;
    for (const std::vector<double>& channel : p.channels) fits = fits && channel.size() == n;
    if (!fits) {
      throw std::logic_error("the model's prediction of run '" + runs_[r].label +
                             "' does not have the run's channels and samples");
    }
  }

  // Residuals of run r against `p`, channel by channel (NaN where missing), and their spikes.
  std::vector<std::vector<char>> Spikes(int r, const RunPrediction& p) const {
    std::vector<std::vector<char>> spikes;
    const DiagnosisRun& run = runs_[r];
    for (int j = 0; j < channels(); ++j) {
      std::vector<double> residual(run.input.size());
      for (size_t k = 0; k < residual.size(); ++k)
        residual[k] = run.channels[j][k] - p.channels[j][k];
      spikes.push_back(SpikeMask(residual, o_.spike_sigmas * sigma_[j]));
    }
    return spikes;
  }

  // The full score of run r's prediction `p`: loss, and squared residuals with and without
  // spikes.
  RunScore Score(int r, const RunPrediction& p) const {
    RunScore s;
    s.sse.assign(channels(), 0.0);
    s.clean_sse.assign(channels(), 0.0);
    s.n.assign(channels(), 0);
    s.clean_n.assign(channels(), 0);
    const DiagnosisRun& run = runs_[r];
    const std::vector<std::vector<char>> spikes = Spikes(r, p);
    for (int j = 0; j < channels(); ++j) {
      for (size_t k = 0; k < run.input.size(); ++k) {
        const double m = run.channels[j][k];
        if (std::isnan(m)) continue;
        const double res = m - p.channels[j][k];
        s.loss += Rho(res / sigma_[j], o_.huber);
        s.sse[j] += res * res;
        ++s.n[j];
        if (spikes[j][k]) continue;
        s.clean_sse[j] += res * res;
        ++s.clean_n[j];
      }
    }
    return s;
  }

  // The score of a run that could not be predicted: infinite loss, no residuals.
  RunScore Unpredictable() const {
    RunScore s;
    s.loss = kInf;
    s.sse.assign(channels(), 0.0);
    s.clean_sse.assign(channels(), 0.0);
    s.n.assign(channels(), 0);
    s.clean_n.assign(channels(), 0);
    return s;
  }

  // Held-out mean squared error per channel of per-run scores (all residuals).
  std::vector<double> MeanSquaredErrors(const std::vector<RunScore>& scores) const {
    std::vector<double> mse(channels());
    for (int j = 0; j < channels(); ++j) {
      double sse = 0;
      int n = 0;
      for (const RunScore& x : scores) {
        sse += x.sse[j];
        n += x.n[j];
      }
      mse[j] = n > 0 ? sse / n : kNaN;
    }
    return mse;
  }

  // Whether the residuals of `scores` are systematic: on some channel the mean square of the
  // residuals that are not spikes exceeds the noise variance by more than systematic_sigmas
  // standard errors (of the mean square and of the noise estimate) plus systematic_margin.
  bool Systematic(const std::vector<RunScore>& scores) const {
    for (int j = 0; j < channels(); ++j) {
      double sse = 0;
      int n = 0;
      for (const RunScore& s : scores) {
        sse += s.clean_sse[j];
        n += s.clean_n[j];
      }
      if (n == 0) continue;
      const double se = std::sqrt(2.0 / n + 2.0 / std::max(dof_[j], 1));
      const double ratio = sse / n / (sigma_[j] * sigma_[j]) - 1.0;
      if (ratio > o_.systematic_sigmas * se + o_.systematic_margin) return true;
    }
    return false;
  }

  // The excess of `scores` over the noise: sum over channels of n_c (ms_c / sigma_c^2 - 1) of
  // the residuals that are not spikes.
  double Excess(const std::vector<RunScore>& scores) const {
    double excess = 0.0;
    for (const RunScore& s : scores) {
      for (int j = 0; j < channels(); ++j) {
        excess += s.clean_sse[j] / (sigma_[j] * sigma_[j]) - s.clean_n[j];
      }
    }
    return excess;
  }

 private:
  const DiagnosisModel& model_;
  const std::vector<DiagnosisRun>& runs_;
  DiagnosisOptions o_;
  std::vector<double> sigma_;
  std::vector<int> dof_;
  std::vector<std::vector<size_t>> horizon_ends_;  // [run][horizon]
  int samples_ = 0;
  mutable std::atomic<long> predictions_{0};
};

double TotalLoss(const std::vector<RunScore>& scores) {
  double total = 0.0;
  for (const RunScore& s : scores) total += s.loss;
  return total;
}

// One candidate cross-validated: its fit, the held-out score of every run and the values fitted
// without each run ([run][parameter of the fit]).
struct Evaluated {
  ParameterFit fit;
  std::vector<RunScore> heldout;  // per run
  std::vector<std::vector<double>> fold_values;
  Profile profile;
};

// What a candidate is evaluated against: the setting it is added to (`base`, the first cause at
// its all-data value for pairs), the first cause and its per-fold values (pairs), and the
// reference's held-out scores and predictions.
struct Reference {
  ParameterValues base;
  std::optional<int> first;
  std::vector<double> first_folds;
  std::vector<RunScore> scores;
  std::vector<RunPrediction> predictions;
};

// "<cause> (<name>)" of parameter p.
std::string Describe(const Engine& e, int p) {
  return e.parameter(p).cause + " (" + e.parameter(p).name + ")";
}

// The fit's summary from its held-out scores: errors, gain over the reference, BIC.
void Summarise(const Engine& e, double reference_loss, double in_sample, Evaluated& ev) {
  ParameterFit& fit = ev.fit;
  fit.heldout_loss = TotalLoss(ev.heldout);
  fit.heldout_mse = e.MeanSquaredErrors(ev.heldout);
  fit.gain = reference_loss - fit.heldout_loss;
  fit.bic = in_sample + static_cast<double>(fit.parameters.size()) * std::log(e.samples());
  fit.significant = fit.gain > e.options().significance;
}

// Cross-validation of one candidate parameter `p` against `ref` (DiagnoseModel, step 2).
class CandidateEvaluation {
 public:
  // `threads` (>= 1): the worker threads of its own simulations (1 when candidates are
  // evaluated side by side).
  CandidateEvaluation(const Engine& engine, int p, const Reference& ref, int threads)
      : e_(engine), p_(p), ref_(ref), param_(engine.parameter(p)) {
    affected_.resize(e_.runs());
    reference_losses_.resize(e_.runs());
    for (int r = 0; r < e_.runs(); ++r) {
      affected_[r] = e_.model().Affects(p, r, ref.predictions[r]);
      if (!affected_[r]) reference_losses_[r] = e_.HorizonLoss(r, ref.predictions[r]);
    }
    threads_ = param_.cheap ? 1 : threads;
  }

  // The candidate's evaluation, or nullopt (with a note) when it could not be predicted at any
  // value; a note also when it failed at some values.
  std::optional<Evaluated> Run(std::vector<std::string>& notes) const {
    Evaluated ev;
    SearchSettings s;
    s.lo = param_.lo;
    s.hi = param_.hi;
    s.coarse = param_.grid_points > 0 ? param_.grid_points
               : ref_.first           ? e_.options().pair_grid_points
                                      : e_.options().grid_points;
    s.horizons = e_.horizons();
    s.extra_starts = e_.options().extra_starts;
    s.evaluations = kEvaluationsPerStart;
    ev.profile = SearchProfile(s, [&](const std::vector<double>& v) { return LossesAt(v); });
    const std::optional<double> value = Minimise(ev.profile, std::vector<char>(e_.runs(), 1));
    if (failures_.count > 0) {
      const std::string what = Describe(e_, p_) + ": could not be simulated";
      notes.push_back(value ? what + " at " + std::to_string(failures_.count) + " of " +
                                  std::to_string(ev.profile.grid.size() * e_.runs()) +
                                  " run predictions (loss +inf there): " + failures_.message
                            : what + ": " + failures_.message);
    }
    if (!value) return std::nullopt;
    LeaveOneRunOut(ev);
    double in_sample = kInf;
    for (const std::vector<double>& losses : ev.profile.losses) {
      double total = 0.0;
      for (double l : losses) total += l;
      in_sample = std::min(in_sample, total);
    }
    if (ref_.first) {
      ev.fit.parameters.push_back(*ref_.first);
      ev.fit.values.push_back(ref_.base.back().second);
    }
    ev.fit.parameters.push_back(p_);
    ev.fit.values.push_back(*value);
    Summarise(e_, TotalLoss(ref_.scores), in_sample, ev);
    return ev;
  }

  static constexpr int kEvaluationsPerStart = 6;

 private:
  // The losses of every run at each value of `values` and horizon (runs the candidate cannot
  // affect keep the reference's loss; a run that cannot be predicted has +inf).
  HorizonLosses LossesAt(const std::vector<double>& values) const {
    const int R = e_.runs(), H = e_.horizons();
    HorizonLosses losses(values.size(),
                         std::vector<std::vector<double>>(H, std::vector<double>(R)));
    std::vector<std::pair<int, int>> tasks;
    for (size_t i = 0; i < values.size(); ++i) {
      for (int r = 0; r < R; ++r) {
        if (affected_[r]) {
          tasks.emplace_back(static_cast<int>(i), r);
        } else {
          for (int h = 0; h < H; ++h) losses[i][h][r] = reference_losses_[r][h];
        }
      }
    }
    ParallelFor(static_cast<int>(tasks.size()), threads_, [&](int t) {
      const auto [i, r] = tasks[t];
      const auto p = e_.TryPredict(r, With(ref_.base, p_, values[i]), failures_);
      const std::vector<double> l = p ? e_.HorizonLoss(r, *p) : std::vector<double>(H, kInf);
      for (int h = 0; h < H; ++h) losses[i][h][r] = l[h];
    });
    return losses;
  }

  // Each run's value fitted on the others and its held-out score there.
  void LeaveOneRunOut(Evaluated& ev) const {
    const int R = e_.runs();
    ev.fold_values.assign(R, {});
    ev.heldout.assign(R, RunScore{});
    std::vector<int> todo;
    for (int r = 0; r < R; ++r) {
      std::vector<char> train(R, 1);
      train[r] = 0;
      const std::optional<double> fold = Minimise(ev.profile, train);
      if (ref_.first) ev.fold_values[r].push_back(ref_.first_folds[r]);
      ev.fold_values[r].push_back(fold.value_or(kNaN));
      if (!fold) {
        ev.heldout[r] = e_.Unpredictable();
      } else if (affected_[r]) {
        todo.push_back(r);
      } else {
        ev.heldout[r] = ref_.scores[r];
      }
    }
    ParallelFor(static_cast<int>(todo.size()), threads_, [&](int t) {
      const int r = todo[t];
      ParameterValues values = ref_.base;
      if (ref_.first) values.emplace_back(*ref_.first, ref_.first_folds[r]);
      values.emplace_back(p_, ev.fold_values[r].back());
      const auto p = e_.TryPredict(r, values, failures_);
      ev.heldout[r] = p ? e_.Score(r, *p) : e_.Unpredictable();
    });
  }

  const Engine& e_;
  const int p_;
  const Reference& ref_;
  const CandidateParameter& param_;
  std::vector<char> affected_;
  std::vector<std::vector<double>> reference_losses_;  // [run][horizon], unaffected runs
  int threads_ = 1;
  mutable Failures failures_;
};

// The joint fit of a pair (DiagnoseModel, step 2): the first cause f and a second p, from the
// screen of p with f fixed, by coordinate search (f | p, then p | f, each a bracketing search
// around the current best point), every point evaluated on all runs and recorded; then
// cross-validated on the recorded points (each fold at the point of least training loss).
class PairFit {
 public:
  PairFit(const Engine& e, const Evaluated& first, const Evaluated& screen, const Reference& ref)
      : e_(e), first_(first), screen_(screen), ref_(ref) {
    f_ = screen.fit.parameters[0];
    p_ = screen.fit.parameters[1];
    const bool cheap = e.parameter(f_).cheap && e.parameter(p_).cheap;
    threads_ = cheap ? 1 : e.options().threads;
  }

  Evaluated Run() const {
    const double a0 = screen_.fit.values[0];
    for (size_t i = 0; i < screen_.profile.grid.size(); ++i) {
      Record(a0, screen_.profile.grid[i], screen_.profile.losses[i]);
    }
    const Point p1 = Best();
    Coordinate(0, first_.profile.coarse_step);
    Coordinate(1, screen_.profile.coarse_step);
    Pattern(p1, Best());
    return CrossValidated();
  }

 private:
  struct Point {
    double a, b;  // the values of f and p
    std::vector<double> losses;
    double total;
  };

  double Record(double a, double b, std::vector<double> losses) const {
    double total = 0.0;
    for (double l : losses) total += l;
    if (std::isnan(total)) total = kInf;
    points_.push_back(Point{a, b, std::move(losses), total});
    return total;
  }

  // The recorded point of least loss over the runs with use[r] (all when empty).
  const Point& Best(const std::vector<char>& use = {}) const {
    const Point* best = &points_.front();
    double best_total = kInf;
    for (const Point& p : points_) {
      double total = 0.0;
      for (size_t r = 0; r < p.losses.size(); ++r) total += use.empty() || use[r] ? p.losses[r] : 0;
      if (total < best_total) best = &p, best_total = total;
    }
    return *best;
  }

  // One step of the coordinate search: parameter `which` (0: f, 1: p) searched within `step`
  // of the best point, the other held there.
  void Coordinate(int which, double step) const {
    const Point best = Best();
    const CandidateParameter& param = e_.parameter(which == 0 ? f_ : p_);
    const double x = which == 0 ? best.a : best.b;
    BracketSearch(std::max(param.lo, x - step), std::min(param.hi, x + step), {{x, best.total}},
                  CandidateEvaluation::kEvaluationsPerStart, [&](double v) {
                    const double a = which == 0 ? v : best.a, b = which == 0 ? best.b : v;
                    return Record(a, b, LossesAt(a, b));
                  });
  }

  // The conjugate-direction step: p1 and p3 (the best points after the first and the third
  // coordinate step) both minimise over the second parameter, and so does the pair's minimum
  // where the loss is quadratic: a line search along p3 - p1, from p3 on, within the ranges.
  void Pattern(const Point& p1, const Point& p3) const {
    const double da = p3.a - p1.a, db = p3.b - p1.b;
    if (da == 0.0 && db == 0.0) return;
    double t_max = kPatternReach;  // in units of p3 - p1, from p3
    const auto limit = [&](double x, double d, const CandidateParameter& param) {
      if (d > 0) t_max = std::min(t_max, (param.hi - x) / d);
      if (d < 0) t_max = std::min(t_max, (param.lo - x) / d);
    };
    limit(p3.a, da, e_.parameter(f_));
    limit(p3.b, db, e_.parameter(p_));
    if (!(t_max > 0)) return;
    BracketSearch(0.0, t_max, {{0.0, p3.total}}, CandidateEvaluation::kEvaluationsPerStart,
                  [&](double t) {
                    const double a = p3.a + t * da, b = p3.b + t * db;
                    return Record(a, b, LossesAt(a, b));
                  });
  }

  // How far the pattern step looks beyond p3, in units of p3 - p1: coordinate search on a
  // quadratic whose two parameters are correlated by rho advances by a factor 1 - rho^2 per
  // cycle, so the minimum lies 1 / (1 - rho^2) - 1 further (7 for rho = 0.94).
  static constexpr double kPatternReach = 8.0;

  std::vector<double> LossesAt(double a, double b) const {
    std::vector<double> losses(e_.runs());
    ParallelFor(e_.runs(), threads_, [&](int r) {
      const auto p = e_.TryPredict(r, {{f_, a}, {p_, b}}, failures_);
      losses[r] = p ? e_.HorizonLoss(r, *p).back() : kInf;
    });
    return losses;
  }

  Evaluated CrossValidated() const {
    Evaluated ev;
    const int R = e_.runs();
    ev.heldout.assign(R, RunScore{});
    ev.fold_values.assign(R, {});
    for (int r = 0; r < R; ++r) {
      std::vector<char> train(R, 1);
      train[r] = 0;
      const Point& fold = Best(train);
      ev.fold_values[r] = {fold.a, fold.b};
    }
    ParallelFor(R, threads_, [&](int r) {
      const auto p =
          e_.TryPredict(r, {{f_, ev.fold_values[r][0]}, {p_, ev.fold_values[r][1]}}, failures_);
      ev.heldout[r] = p ? e_.Score(r, *p) : e_.Unpredictable();
    });
    const Point& all = Best();
    ev.fit.parameters = {f_, p_};
    ev.fit.values = {all.a, all.b};
    Summarise(e_, TotalLoss(ref_.scores), all.total, ev);
    return ev;
  }

  const Engine& e_;
  const Evaluated& first_;
  const Evaluated& screen_;
  const Reference& ref_;
  int f_ = 0, p_ = 0, threads_ = 1;
  mutable std::vector<Point> points_;
  mutable Failures failures_;
};
// Residuals per channel, mode and direction of travel (std::map order: channel, mode index,
// direction); without the spikes (SpikeMask) when `skip_spikes`.
std::vector<ChannelResiduals> GroupResiduals(const Engine& e,
                                             const std::vector<RunPrediction>& preds,
                                             bool skip_spikes = false) {
  struct Acc {
    int n = 0;
    double s = 0, ss = 0, sg = 0, sgg = 0, sgr = 0, gmin = 1e300, gmax = -1e300;
  };
  std::map<std::tuple<int, int, int>, Acc> acc;
  for (int r = 0; r < e.runs(); ++r) {
    const DiagnosisRun& run = e.run(r);
    const std::vector<std::vector<char>> spikes =
        skip_spikes ? e.Spikes(r, preds[r]) : std::vector<std::vector<char>>{};
    for (int j = 0; j < e.channels(); ++j) {
      for (size_t k = 0; k < run.input.size(); ++k) {
        const double m = run.channels[j][k];
        if (std::isnan(m) || (skip_spikes && spikes[j][k])) continue;
        const double res = m - preds[r].channels[j][k];
        Acc& a = acc[{j, preds[r].mode[k], preds[r].direction[k]}];
        const double g = run.input[k];
        ++a.n;
        a.s += res;
        a.ss += res * res;
        a.sg += g;
        a.sgg += g * g;
        a.sgr += g * res;
        a.gmin = std::min(a.gmin, g);
        a.gmax = std::max(a.gmax, g);
      }
    }
  }
  std::vector<ChannelResiduals> groups;
  for (const auto& [key, a] : acc) {
    const auto [j, mode, dir] = key;
    ChannelResiduals gr;
    gr.channel = j;
    gr.mode = mode >= 0 ? e.model().ModeName(mode) : "?";
    gr.direction = dir;
    gr.samples = a.n;
    gr.mean = a.s / a.n;
    const double var_g = a.sgg / a.n - (a.sg / a.n) * (a.sg / a.n);
    gr.slope = var_g > 1e-9 ? (a.sgr / a.n - (a.sg / a.n) * gr.mean) / var_g : 0.0;
    gr.rms = std::sqrt(a.ss / a.n);
    gr.excess = a.ss / a.n / (e.sigma(j) * e.sigma(j)) - 1.0;
    gr.input_min = a.gmin;
    gr.input_max = a.gmax;
    groups.push_back(gr);
  }
  return groups;
}

// Mean residual with the input rising minus falling, per channel (0 without both).
std::vector<double> DirectionDifference(const std::vector<ChannelResiduals>& groups, int channels) {
  std::vector<double> sum_c(channels, 0.0), sum_o(channels, 0.0), difference(channels, 0.0);
  std::vector<int> n_c(channels, 0), n_o(channels, 0);
  for (const ChannelResiduals& g : groups) {
    if (g.direction > 0) {
      sum_c[g.channel] += g.mean * g.samples;
      n_c[g.channel] += g.samples;
    } else {
      sum_o[g.channel] += g.mean * g.samples;
      n_o[g.channel] += g.samples;
    }
  }
  for (int j = 0; j < channels; ++j) {
    difference[j] = n_c[j] > 0 && n_o[j] > 0 ? sum_c[j] / n_c[j] - sum_o[j] / n_o[j] : 0.0;
  }
  return difference;
}

// Jumps of the mean residual (10 samples after minus 10 before) where the prediction switches
// mode, beyond 3 standard errors of the noise; the 50 largest, largest first.
std::vector<ResidualJump> ChangePoints(const Engine& e, const std::vector<RunPrediction>& preds) {
  constexpr int kWindow = 10;
  std::vector<ResidualJump> points;
  for (int r = 0; r < e.runs(); ++r) {
    const DiagnosisRun& run = e.run(r);
    const RunPrediction& p = preds[r];
    for (size_t k = 1; k < run.input.size(); ++k) {
      if (p.mode[k] == p.mode[k - 1]) continue;
      for (int j = 0; j < e.channels(); ++j) {
        auto mean = [&](size_t from, size_t to) {
          double s = 0;
          int n = 0;
          for (size_t i = from; i < to && i < run.input.size(); ++i) {
            if (std::isnan(run.channels[j][i])) continue;
            s += run.channels[j][i] - p.channels[j][i];
            ++n;
          }
          return n > 0 ? s / n : kNaN;
        };
        const double jump = mean(k, k + kWindow) - mean(k >= kWindow ? k - kWindow : 0, k);
        if (std::isnan(jump) || std::abs(jump) < 3.0 * e.sigma(j) * std::sqrt(2.0 / kWindow)) {
          continue;
        }
        points.push_back(ResidualJump{run.label, static_cast<int>(k), run.input[k],
                                      e.model().ModeName(p.mode[k - 1]),
                                      e.model().ModeName(p.mode[k]), j, jump});
      }
    }
  }
  std::sort(points.begin(), points.end(), [](const ResidualJump& a, const ResidualJump& b) {
    return std::abs(a.jump) > std::abs(b.jump);
  });
  if (points.size() > 50) points.resize(50);
  return points;
}

// The significant candidate of lowest held-out loss (ties within `tie`: the lower BIC), or -1.
int Pick(const std::vector<Evaluated>& evs, double tie) {
  int best = -1;
  for (size_t i = 0; i < evs.size(); ++i) {
    if (!evs[i].fit.significant) continue;
    if (best < 0 || evs[i].fit.heldout_loss < evs[best].fit.heldout_loss) best = i;
  }
  if (best < 0) return -1;
  for (size_t i = 0; i < evs.size(); ++i) {
    if (!evs[i].fit.significant || static_cast<int>(i) == best) continue;
    if (evs[i].fit.heldout_loss - evs[best].fit.heldout_loss < tie &&
        evs[i].fit.bic < evs[best].fit.bic) {
      best = i;
    }
  }
  return best;
}

// The causes selected by cross-validation and their held-out scores.
struct Selection {
  std::vector<int> named;
  std::vector<double> values;
  std::vector<RunScore> scores;
};

// The evaluations of `candidates` against `ref` (nullopt for one that could not be evaluated
// or was not searched), side by side on the engine's threads (each candidate's simulations on
// one): the candidates' searches are sequential (a bracket evaluates one value after another),
// so parallel candidates keep both threads busy where parallel runs of one value do not.
// Progress is reported from the worker threads, one call at a time; notes are appended in
// candidate order. Results do not depend on the threads, except which candidates are left out
// once the prediction budget is spent.
std::vector<std::optional<Evaluated>> EvaluateAll(const Engine& e,
                                                  const std::vector<int>& candidates,
                                                  const Reference& ref, const std::string& stage,
                                                  std::vector<std::string>& notes) {
  const int n = static_cast<int>(candidates.size());
  std::vector<std::optional<Evaluated>> out(n);
  std::vector<std::vector<std::string>> own_notes(n);
  std::atomic<int> started{0};
  std::mutex progress_mutex;
  ParallelFor(n, e.options().threads, [&](int i) {
    if (e.OverBudget()) {
      own_notes[i].push_back("prediction budget spent (max_predictions " +
                             std::to_string(e.options().max_predictions) +
                             "): " + Describe(e, candidates[i]) + " not searched");
      return;
    }
    if (e.options().progress) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      e.options().progress(stage, started++, n);
    }
    out[i] = CandidateEvaluation(e, candidates[i], ref, 1).Run(own_notes[i]);
  });
  for (const auto& list : own_notes) notes.insert(notes.end(), list.begin(), list.end());
  return out;
}

// Every single candidate against the baseline `base` (those that could be evaluated).
std::vector<Evaluated> Singles(const Engine& e, const Reference& base, ModelDiagnosis& d) {
  std::vector<int> all(e.model().Parameters().size());
  for (size_t p = 0; p < all.size(); ++p) all[p] = static_cast<int>(p);
  std::vector<Evaluated> singles;
  for (std::optional<Evaluated>& ev : EvaluateAll(e, all, base, "single causes", d.notes)) {
    if (!ev) continue;
    singles.push_back(std::move(*ev));
    d.candidates.push_back(singles.back().fit);
  }
  return singles;
}

constexpr size_t kJointPairs = 3;

// Every other candidate with `one` (the first cause) fixed, the best of them (by held-out loss)
// and its rivals (at most kJointPairs in all, each within `significance` of the best's held-out
// loss and with a positive gain) then fitted jointly; the pairs' fits appended to the
// candidates. Returns the joint fits. (A pair whose screen is beaten by more than the
// significance cannot overtake the best by a joint fit that starts from its screen unless the
// screen was far off; the rivals bound the cost: a joint fit costs about 3 screens.)
std::vector<Evaluated> Pairs(const Engine& e, const Evaluated& one, ModelDiagnosis& d) {
  const int first = one.fit.parameters[0];
  Reference ref;
  ref.base = {{first, one.fit.values[0]}};
  ref.first = first;
  for (const std::vector<double>& fold : one.fold_values) ref.first_folds.push_back(fold[0]);
  ref.scores = one.heldout;
  ref.predictions = e.PredictAll(ref.base);
  std::vector<int> others;
  for (int p = 0; p < static_cast<int>(e.model().Parameters().size()); ++p) {
    if (p != first) others.push_back(p);
  }
  std::vector<Evaluated> screens;
  for (std::optional<Evaluated>& ev :
       EvaluateAll(e, others, ref, "pairs with the best single cause", d.notes)) {
    if (ev) screens.push_back(std::move(*ev));
  }
  std::vector<size_t> order(screens.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return screens[a].fit.heldout_loss < screens[b].fit.heldout_loss;
  });
  std::vector<Evaluated> joint;
  for (size_t k = 0; k < order.size() && k < kJointPairs; ++k) {
    // A second cause that does not help with the first fixed is not fitted jointly.
    if (!std::isfinite(screens[order[k]].fit.heldout_loss) || !(screens[order[k]].fit.gain > 0)) {
      break;
    }
    if (k > 0 && screens[order[k]].fit.heldout_loss >
                     screens[order[0]].fit.heldout_loss + e.options().significance) {
      break;
    }
    joint.push_back(PairFit(e, one, screens[order[k]], ref).Run());
    screens[order[k]].fit = joint.back().fit;  // reported as fitted jointly
  }
  for (const Evaluated& s : screens) d.candidates.push_back(s.fit);
  return joint;
}

// Step 2 of DiagnoseModel: every single candidate against the baseline `base`; then, when the
// best significant one leaves a systematic residual, the pairs with it.
Selection SelectCauses(const Engine& e, const Reference& base, ModelDiagnosis& d) {
  const std::vector<Evaluated> singles = Singles(e, base, d);
  const int first = Pick(singles, e.options().tie);
  Selection s{{}, {}, base.scores};
  if (first < 0) return s;
  const Evaluated& one = singles[first];
  s = Selection{one.fit.parameters, one.fit.values, one.heldout};
  if (!e.Systematic(one.heldout)) return s;
  const std::vector<Evaluated> pairs = Pairs(e, one, d);
  const int second = Pick(pairs, e.options().tie);
  if (second >= 0) {
    s = Selection{pairs[second].fit.parameters, pairs[second].fit.values, pairs[second].heldout};
  }
  return s;
}

// Ceres cost of a setting of the named parameters: the signed root of the Huber loss of every
// sample of every run (0 for missing samples).
struct RefinementCost {
  const Engine* engine;
  std::vector<int> params;
  bool operator()(double const* const* x, double* residuals) const {
    ParameterValues values;
    for (size_t i = 0; i < params.size(); ++i) values.emplace_back(params[i], x[0][i]);
    const std::optional<std::vector<RunPrediction>> p = engine->TryPredictAll(values);
    if (!p) return false;
    int k = 0;
    for (int r = 0; r < engine->runs(); ++r) {
      const DiagnosisRun& run = engine->run(r);
      for (int j = 0; j < engine->channels(); ++j) {
        for (size_t s = 0; s < run.input.size(); ++s) {
          const double m = run.channels[j][s];
          residuals[k++] = std::isnan(m) ? 0.0
                                         : RootRho((m - (*p)[r].channels[j][s]) / engine->sigma(j),
                                                   engine->options().huber);
        }
      }
    }
    return true;
  }
};

// Ceres on the named parameters, on all runs, bounded by the search ranges, from `values`;
// `values` when no solution is usable.
std::vector<double> CeresRefine(const Engine& e, const std::vector<int>& named,
                                const std::vector<double>& values) {
  std::vector<double> x = values;
  ceres::Problem problem;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<RefinementCost, ceres::CENTRAL>(
      new RefinementCost{&e, named});
  cost->AddParameterBlock(static_cast<int>(x.size()));
  cost->SetNumResiduals(e.channels() * e.samples());
  problem.AddResidualBlock(cost, nullptr, x.data());
  for (size_t i = 0; i < named.size(); ++i) {
    problem.SetParameterLowerBound(x.data(), static_cast<int>(i), e.parameter(named[i]).lo);
    problem.SetParameterUpperBound(x.data(), static_cast<int>(i), e.parameter(named[i]).hi);
  }
  ceres::Solver::Options so;
  so.max_num_iterations = 12;
  so.linear_solver_type = ceres::DENSE_QR;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  return summary.IsSolutionUsable() ? x : values;
}

// An extension of the model: the named parameters' values and its predictions of every run.
struct Extension {
  std::vector<double> values;
  std::vector<RunPrediction> predictions;
};

ParameterValues Setting(const std::vector<int>& named, const std::vector<double>& values) {
  ParameterValues setting;
  for (size_t i = 0; i < named.size(); ++i) setting.emplace_back(named[i], values[i]);
  return setting;
}

double AllDataLoss(const Engine& e, const std::vector<RunPrediction>& predictions) {
  double loss = 0.0;
  for (int r = 0; r < e.runs(); ++r) loss += e.HorizonLoss(r, predictions[r]).back();
  return loss;
}

// Step 3 of DiagnoseModel: `ext` refined with Ceres, kept only when its all-data loss drops.
Extension Refined(const Engine& e, const std::vector<int>& named, Extension ext) {
  if (!e.options().refine) return ext;
  const std::vector<double> x = CeresRefine(e, named, ext.values);
  if (x == ext.values) return ext;
  std::optional<std::vector<RunPrediction>> p = e.TryPredictAll(Setting(named, x));
  if (!p || !(AllDataLoss(e, *p) < AllDataLoss(e, ext.predictions))) return ext;
  return Extension{x, std::move(*p)};
}

// The running means (9 samples, spikes and missing ones left out) of channel j's residual at
// the samples of run r in group `g` (mode and direction), with their inputs.
std::vector<std::pair<double, double>> RunningMeans(const Engine& e, int r, const RunPrediction& p,
                                                    const ChannelResiduals& g) {
  const DiagnosisRun& run = e.run(r);
  const int j = g.channel;
  const std::vector<char> spikes = e.Spikes(r, p)[j];
  const int n = static_cast<int>(run.input.size());
  std::vector<std::pair<double, double>> means;  // (input, running mean)
  for (int k = 0; k < n; ++k) {
    if (p.mode[k] < 0 || e.model().ModeName(p.mode[k]) != g.mode || p.direction[k] != g.direction) {
      continue;
    }
    double s = 0;
    int c = 0;
    for (int i = std::max(0, k - 4); i <= std::min(n - 1, k + 4); ++i) {
      if (std::isnan(run.channels[j][i]) || spikes[i]) continue;
      s += run.channels[j][i] - p.channels[j][i];
      ++c;
    }
    if (c > 0) means.emplace_back(run.input[k], s / c);
  }
  return means;
}

// Where a residual is systematic: the group (channel, mode, direction) of largest total excess
// of its residuals that are not spikes; the input range where the running mean (9 samples,
// spikes left out) of its residual exceeds one sigma and half its largest magnitude in the
// group (so a bump on a residual offset is located on the bump), and the mean of those running
// means (the whole group's range and mean when none does).
std::optional<SystematicResidual> Locate(const Engine& e,
                                         const std::vector<RunPrediction>& predictions) {
  const std::vector<ChannelResiduals> groups = GroupResiduals(e, predictions, true);
  const ChannelResiduals* worst = nullptr;
  for (const ChannelResiduals& g : groups) {
    if (!worst || g.excess * g.samples > worst->excess * worst->samples) worst = &g;
  }
  if (!worst) return std::nullopt;
  std::vector<std::pair<double, double>> means;
  for (int r = 0; r < e.runs(); ++r) {
    for (const auto& m : RunningMeans(e, r, predictions[r], *worst)) means.push_back(m);
  }
  double peak = 0.0;
  for (const auto& m : means) peak = std::max(peak, std::abs(m.second));
  const double threshold = std::max(e.sigma(worst->channel), 0.5 * peak);
  SystematicResidual w{worst->channel,   worst->mode, worst->direction, worst->input_min,
                       worst->input_max, worst->mean, worst->excess};
  double lo = 1e300, hi = -1e300, sum = 0.0;
  int count = 0;
  for (const auto& [input, mean] : means) {
    if (std::abs(mean) <= threshold) continue;
    lo = std::min(lo, input);
    hi = std::max(hi, input);
    sum += mean;
    ++count;
  }
  if (count > 0) w.input_min = lo, w.input_max = hi, w.mean_residual = sum / count;
  return w;
}

// Step 1 of DiagnoseModel: the baseline's predictions, scores and residual analysis.
Reference AnalyseBaseline(const Engine& e, ModelDiagnosis& d) {
  Reference base;
  Failures failures;
  base.predictions.resize(e.runs());
  ParallelFor(e.runs(), e.options().threads, [&](int r) {
    if (auto p = e.TryPredict(r, {}, failures)) base.predictions[r] = std::move(*p);
  });
  if (failures.count > 0) {
    throw std::invalid_argument(failures.message);  // the model's own words
  }
  for (int r = 0; r < e.runs(); ++r) base.scores.push_back(e.Score(r, base.predictions[r]));
  d.baseline_mse = e.MeanSquaredErrors(base.scores);
  d.residuals = GroupResiduals(e, base.predictions);
  d.direction_difference = DirectionDifference(d.residuals, e.channels());
  d.change_points = ChangePoints(e, base.predictions);
  d.baseline = base.predictions;
  return base;
}

// Step 4 of DiagnoseModel without an adopted extension: "unexplained" located on `located`
// (the best extension's predictions, or the baseline's), or "none".
void NotAdopted(const Engine& e, const std::vector<RunPrediction>& located, bool systematic,
                ModelDiagnosis& d) {
  d.extended_mse = d.baseline_mse;
  d.extended = d.baseline;
  if (systematic) {
    d.cause = {"unexplained"};
    d.where = Locate(e, located);
  } else {
    d.cause = {"none"};
  }
}

// Step 4 of DiagnoseModel: the verdict on the selection `s` (see the header).
void Conclude(const Engine& e, const Reference& base, const Selection& s, ModelDiagnosis& d) {
  if (s.named.empty()) return NotAdopted(e, base.predictions, e.Systematic(base.scores), d);
  Extension ext{s.values, e.PredictAll(Setting(s.named, s.values))};
  const double e_base = e.Excess(base.scores), e_ext = e.Excess(s.scores);
  d.explained_fraction = e_base > 0 ? std::clamp((e_base - e_ext) / e_base, 0.0, 1.0) : 0.0;
  const bool systematic = e.Systematic(s.scores);
  if (systematic && d.explained_fraction < e.options().main_fraction) {
    return NotAdopted(e, ext.predictions, true, d);
  }
  ext = Refined(e, s.named, std::move(ext));
  d.parameters = Setting(s.named, ext.values);
  d.extended_mse = e.MeanSquaredErrors(s.scores);
  d.extended = std::move(ext.predictions);
  for (int p : s.named) {
    const std::string& cause = e.parameter(p).cause;
    if (std::find(d.cause.begin(), d.cause.end(), cause) == d.cause.end()) d.cause.push_back(cause);
  }
  if (systematic) d.remainder = Locate(e, d.extended);
}

}  // namespace

ModelDiagnosis DiagnoseModel(const DiagnosisModel& model, const std::vector<DiagnosisRun>& runs,
                             const ChannelNoise& noise, const DiagnosisOptions& options) {
  const Engine e(model, runs, noise, options);
  ModelDiagnosis d;
  const Reference base = AnalyseBaseline(e, d);
  const Selection s = SelectCauses(e, base, d);
  Conclude(e, base, s, d);
  return d;
}

}  // namespace hybrid
