#include "hybrid/diagnosis/diagnosis_engine.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include "hybrid/diagnosis/parallel_for.h"

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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

// The score of one run's prediction: robust loss and per-channel sums of squared residuals.
struct RunScore {
  double loss = 0.0;  // robust, chi-square units
  std::vector<double> sse;
  std::vector<int> n;
};

// Per-candidate profile: losses of every run at every grid value.
struct Profile {
  std::vector<double> grid;                 // sorted
  std::vector<std::vector<double>> losses;  // [grid][run]
};

// Minimiser of sum_{runs in mask} losses over the grid, refined by the parabola through the
// best point and its neighbours.
double Minimise(const Profile& p, const std::vector<char>& use) {
  const size_t m = p.grid.size();
  std::vector<double> total(m, 0.0);
  for (size_t i = 0; i < m; ++i) {
    for (size_t r = 0; r < use.size(); ++r) {
      if (use[r]) total[i] += p.losses[i][r];
    }
  }
  const size_t best = std::min_element(total.begin(), total.end()) - total.begin();
  if (best == 0 || best + 1 == m) return p.grid[best];
  const double x0 = p.grid[best - 1], x1 = p.grid[best], x2 = p.grid[best + 1];
  const double y0 = total[best - 1], y1 = total[best], y2 = total[best + 1];
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1);
  const double curvature = (d12 - d01) / (x2 - x0);
  if (!(curvature > 0)) return x1;
  // Vertex of the parabola through the three points: x1 - (slope at x1) / (2 c).
  const double slope_at_x1 = d01 + curvature * (x1 - x0);
  const double v = x1 - slope_at_x1 / (2.0 * curvature);
  return std::clamp(v, x0, x2);
}

// The profile sorted by grid value, repeated values dropped.
Profile Sorted(const Profile& profile) {
  std::vector<size_t> order(profile.grid.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return profile.grid[a] < profile.grid[b]; });
  Profile sorted;
  for (size_t i : order) {
    if (!sorted.grid.empty() && sorted.grid.back() == profile.grid[i]) continue;
    sorted.grid.push_back(profile.grid[i]);
    sorted.losses.push_back(profile.losses[i]);
  }
  return sorted;
}

// `values` with (parameter, value) appended.
ParameterValues With(ParameterValues values, int parameter, double value) {
  values.emplace_back(parameter, value);
  return values;
}

// The validated inputs of DiagnoseModel and the operations every step needs: predictions,
// scores, and the cross-validation of one candidate.
class Engine {
 public:
  Engine(const DiagnosisModel& model, const std::vector<DiagnosisRun>& runs,
         const ChannelNoise& noise, const DiagnosisOptions& o)
      : model_(model), runs_(runs), o_(o) {
    if (runs.empty()) throw std::invalid_argument("the data have no runs");
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
    }
  }

  int runs() const { return static_cast<int>(runs_.size()); }
  int channels() const { return static_cast<int>(sigma_.size()); }
  int samples() const { return samples_; }
  double sigma(int c) const { return sigma_[c]; }
  int dof(int c) const { return dof_[c]; }
  const DiagnosisRun& run(int r) const { return runs_[r]; }
  const DiagnosisModel& model() const { return model_; }
  const DiagnosisOptions& options() const { return o_; }
  const CandidateParameter& parameter(int p) const { return model_.Parameters()[p]; }

  // The model's prediction of run r, checked to have the run's shape (a model that returns
  // another is misused: std::logic_error).
  RunPrediction Predict(int r, const ParameterValues& values) const {
    RunPrediction p = model_.Predict(r, values);
    const size_t n = runs_[r].input.size();
    bool fits = p.channels.size() == sigma_.size() && p.mode.size() == n && p.direction.size() == n;
    for (const std::vector<double>& channel : p.channels) fits = fits && channel.size() == n;
    if (!fits) {
      throw std::logic_error("the model's prediction of run '" + runs_[r].label +
                             "' does not have the run's channels and samples");
    }
    return p;
  }

  // The predictions of every run under `values` (in parallel).
  std::vector<RunPrediction> PredictAll(const ParameterValues& values) const {
    std::vector<RunPrediction> predictions(runs());
    ParallelFor(runs(), o_.threads, [&](int r) { predictions[r] = Predict(r, values); });
    return predictions;
  }

  RunScore Score(int r, const RunPrediction& p) const {
    RunScore s;
    s.sse.assign(channels(), 0.0);
    s.n.assign(channels(), 0);
    const DiagnosisRun& run = runs_[r];
    for (int j = 0; j < channels(); ++j) {
      for (size_t k = 0; k < run.input.size(); ++k) {
        const double m = run.channels[j][k];
        if (std::isnan(m)) continue;
        const double res = m - p.channels[j][k];
        s.loss += Rho(res / sigma_[j], o_.huber);
        s.sse[j] += res * res;
        ++s.n[j];
      }
    }
    return s;
  }

  // Held-out mean squared error per channel of per-run scores.
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

  // Whether a residual of mean squares `mse` (per channel, over `scores`) is systematic: its
  // excess over the noise variance is beyond systematic_sigmas standard errors (of the mean
  // square and of the noise estimate) plus systematic_margin.
  bool Systematic(const std::vector<double>& mse, const std::vector<RunScore>& scores) const {
    for (int j = 0; j < channels(); ++j) {
      int n = 0;
      for (const RunScore& s : scores) n += s.n[j];
      if (n == 0) continue;
      const double se = std::sqrt(2.0 / n + 2.0 / std::max(dof_[j], 1));
      const double ratio = mse[j] / (sigma_[j] * sigma_[j]) - 1.0;
      if (ratio > o_.systematic_sigmas * se + o_.systematic_margin) return true;
    }
    return false;
  }

 private:
  const DiagnosisModel& model_;
  const std::vector<DiagnosisRun>& runs_;
  DiagnosisOptions o_;
  std::vector<double> sigma_;
  std::vector<int> dof_;
  int samples_ = 0;
};

// One candidate cross-validated: its fit, the held-out score of every run and the value fitted
// without each run.
struct Evaluated {
  ParameterFit fit;
  std::vector<RunScore> heldout;  // per run
  std::vector<double> fold_values;
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

// Cross-validation of one candidate parameter `p` against `ref` (DiagnoseModel, step 2).
class CandidateEvaluation {
 public:
  CandidateEvaluation(const Engine& engine, int p, const Reference& ref)
      : e_(engine), p_(p), ref_(ref), param_(engine.parameter(p)) {
    affected_.resize(e_.runs());
    for (int r = 0; r < e_.runs(); ++r) {
      affected_[r] = e_.model().Affects(p, r, ref.predictions[r]);
    }
    threads_ = param_.cheap ? 1 : e_.options().threads;
  }

  Evaluated Run() const {
    Evaluated ev;
    ev.profile = FittedProfile();
    LeaveOneRunOut(ev);
    Summarise(ev);
    return ev;
  }

 private:
  // The losses of every run at each value of `values` (runs the candidate cannot affect keep
  // the reference's loss).
  std::vector<std::vector<double>> LossesAt(const std::vector<double>& values) const {
    const int R = e_.runs();
    std::vector<std::vector<double>> losses(values.size(), std::vector<double>(R, 0.0));
    std::vector<std::pair<int, int>> tasks;
    for (size_t i = 0; i < values.size(); ++i) {
      for (int r = 0; r < R; ++r) {
        if (affected_[r]) {
          tasks.emplace_back(static_cast<int>(i), r);
        } else {
          losses[i][r] = e_.Score(r, ref_.predictions[r]).loss;
        }
      }
    }
    ParallelFor(static_cast<int>(tasks.size()), threads_, [&](int t) {
      const auto [i, r] = tasks[t];
      losses[i][r] = e_.Score(r, e_.Predict(r, With(ref_.base, p_, values[i]))).loss;
    });
    return losses;
  }

  // The coarse grid over the search range, then four points around its all-data best.
  Profile FittedProfile() const {
    const double lo = param_.lo, hi = param_.hi;
    const int coarse = param_.grid_points > 0 ? param_.grid_points
                       : ref_.first           ? e_.options().pair_grid_points
                                              : e_.options().grid_points;
    Profile profile;
    for (int i = 0; i < coarse; ++i) profile.grid.push_back(lo + (hi - lo) * i / (coarse - 1));
    profile.losses = LossesAt(profile.grid);
    const std::vector<char> all(e_.runs(), 1);
    const double best = Minimise(profile, all);
    const double h = (hi - lo) / (coarse - 1);
    std::vector<double> fine;
    for (double f : {-0.6, -0.3, 0.3, 0.6}) {
      const double v = best + f * h;
      if (v > lo && v < hi) fine.push_back(v);
    }
    const auto fine_losses = LossesAt(fine);
    for (size_t i = 0; i < fine.size(); ++i) {
      profile.grid.push_back(fine[i]);
      profile.losses.push_back(fine_losses[i]);
    }
    return Sorted(profile);
  }

  // Each run's value fitted on the others and its held-out score there.
  void LeaveOneRunOut(Evaluated& ev) const {
    const int R = e_.runs();
    ev.fold_values.assign(R, 0.0);
    ev.heldout.assign(R, RunScore{});
    std::vector<int> todo;
    for (int r = 0; r < R; ++r) {
      std::vector<char> train(R, 1);
      train[r] = 0;
      ev.fold_values[r] = Minimise(ev.profile, train);
      if (affected_[r]) {
        todo.push_back(r);
      } else {
        ev.heldout[r] = ref_.scores[r];
      }
    }
    ParallelFor(static_cast<int>(todo.size()), threads_, [&](int t) {
      const int r = todo[t];
      ParameterValues values = ref_.base;
      if (ref_.first) values.emplace_back(*ref_.first, ref_.first_folds[r]);
      values.emplace_back(p_, ev.fold_values[r]);
      ev.heldout[r] = e_.Score(r, e_.Predict(r, values));
    });
  }

  // The fit: all-data values, held-out loss and errors, gain over the reference, BIC.
  void Summarise(Evaluated& ev) const {
    const std::vector<char> all(e_.runs(), 1);
    const double value = Minimise(ev.profile, all);
    // All-data fit's in-sample loss for the BIC.
    double in_sample = std::numeric_limits<double>::infinity();
    for (const std::vector<double>& losses : ev.profile.losses) {
      double total = 0.0;
      for (double l : losses) total += l;
      in_sample = std::min(in_sample, total);
    }
    ParameterFit& fit = ev.fit;
    if (ref_.first) {
      fit.parameters.push_back(*ref_.first);
      fit.values.push_back(ref_.base.back().second);
    }
    fit.parameters.push_back(p_);
    fit.values.push_back(value);
    double ref_loss = 0.0;
    for (int r = 0; r < e_.runs(); ++r) {
      ref_loss += ref_.scores[r].loss;
      fit.heldout_loss += ev.heldout[r].loss;
    }
    fit.heldout_mse = e_.MeanSquaredErrors(ev.heldout);
    fit.gain = ref_loss - fit.heldout_loss;
    fit.bic = in_sample + static_cast<double>(fit.parameters.size()) * std::log(e_.samples());
    fit.significant = fit.gain > e_.options().significance;
  }

  const Engine& e_;
  const int p_;
  const Reference& ref_;
  const CandidateParameter& param_;
  std::vector<char> affected_;
  int threads_ = 1;
};

// Residuals per channel, mode and direction of travel (std::map order: channel, mode index,
// direction).
std::vector<ChannelResiduals> GroupResiduals(const Engine& e,
                                             const std::vector<RunPrediction>& preds) {
  struct Acc {
    int n = 0;
    double s = 0, ss = 0, sg = 0, sgg = 0, sgr = 0, gmin = 1e300, gmax = -1e300;
  };
  std::map<std::tuple<int, int, int>, Acc> acc;
  for (int r = 0; r < e.runs(); ++r) {
    const DiagnosisRun& run = e.run(r);
    for (int j = 0; j < e.channels(); ++j) {
      for (size_t k = 0; k < run.input.size(); ++k) {
        const double m = run.channels[j][k];
        if (std::isnan(m)) continue;
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

// Step 2 of DiagnoseModel: every single candidate against the baseline `base`; then, when the
// best significant one leaves a systematic residual, every other candidate paired with it.
// Appends every fit to `candidates`.
Selection SelectCauses(const Engine& e, const Reference& base,
                       std::vector<ParameterFit>& candidates) {
  const int count = static_cast<int>(e.model().Parameters().size());
  std::vector<Evaluated> singles;
  const auto& progress = e.options().progress;
  for (int p = 0; p < count; ++p) {
    if (progress) progress("single causes", p, count);
    singles.push_back(CandidateEvaluation(e, p, base).Run());
    candidates.push_back(singles.back().fit);
  }
  const int first = Pick(singles, e.options().tie);
  Selection s{{}, {}, base.scores};
  if (first < 0) return s;
  const Evaluated& one = singles[first];
  s = Selection{one.fit.parameters, one.fit.values, one.heldout};
  if (!e.Systematic(one.fit.heldout_mse, one.heldout)) return s;
  Reference ref;
  ref.base = {{first, one.fit.values[0]}};
  ref.first = first;
  ref.first_folds = one.fold_values;
  ref.scores = one.heldout;
  ref.predictions = e.PredictAll(ref.base);
  std::vector<Evaluated> pairs;
  for (int p = 0; p < count; ++p) {
    if (p == first) continue;
    if (progress)
      progress("pairs with the best single cause", static_cast<int>(pairs.size()), count - 1);
    pairs.push_back(CandidateEvaluation(e, p, ref).Run());
    candidates.push_back(pairs.back().fit);
  }
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
    std::vector<RunPrediction> p;
    try {
      p = engine->PredictAll(values);
    } catch (const std::exception&) {
      return false;
    }
    int k = 0;
    for (int r = 0; r < engine->runs(); ++r) {
      const DiagnosisRun& run = engine->run(r);
      for (int j = 0; j < engine->channels(); ++j) {
        for (size_t s = 0; s < run.input.size(); ++s) {
          const double m = run.channels[j][s];
          residuals[k++] = std::isnan(m) ? 0.0
                                         : RootRho((m - p[r].channels[j][s]) / engine->sigma(j),
                                                   engine->options().huber);
        }
      }
    }
    return true;
  }
};

// Step 3 of DiagnoseModel: the named parameters refined on all runs (Ceres, bounded by the
// search ranges, from the cross-validated values); `values` when no solution is usable.
std::vector<double> Refine(const Engine& e, const std::vector<int>& named,
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

// Step 4 of DiagnoseModel for an unexplained residual: the group of largest total excess, and
// the input range where the running mean (9 samples) of its residual exceeds one sigma.
std::optional<SystematicResidual> Locate(const Engine& e,
                                         const std::vector<RunPrediction>& final_predictions) {
  const std::vector<ChannelResiduals> groups = GroupResiduals(e, final_predictions);
  const ChannelResiduals* worst = nullptr;
  for (const ChannelResiduals& g : groups) {
    if (!worst || g.excess * g.samples > worst->excess * worst->samples) worst = &g;
  }
  if (!worst) return std::nullopt;
  SystematicResidual w{worst->channel, worst->mode,  worst->direction, 0.0, 0.0,
                       worst->mean,    worst->excess};
  const int j = worst->channel;
  double lo = 1e300, hi = -1e300;
  for (int r = 0; r < e.runs(); ++r) {
    const DiagnosisRun& run = e.run(r);
    const RunPrediction& p = final_predictions[r];
    const int n = static_cast<int>(run.input.size());
    for (int k = 0; k < n; ++k) {
      if (p.mode[k] < 0 || e.model().ModeName(p.mode[k]) != worst->mode ||
          p.direction[k] != worst->direction) {
        continue;
      }
      double s = 0;
      int c = 0;
      for (int i = std::max(0, k - 4); i <= std::min(n - 1, k + 4); ++i) {
        const double m = run.channels[j][i];
        if (std::isnan(m)) continue;
        s += m - p.channels[j][i];
        ++c;
      }
      if (c > 0 && std::abs(s / c) > e.sigma(j)) {
        lo = std::min(lo, run.input[k]);
        hi = std::max(hi, run.input[k]);
      }
    }
  }
  w.input_min = lo <= hi ? lo : worst->input_min;
  w.input_max = lo <= hi ? hi : worst->input_max;
  return w;
}

// Step 1 of DiagnoseModel: the baseline's predictions, scores and residual analysis.
Reference AnalyseBaseline(const Engine& e, ModelDiagnosis& d) {
  Reference base;
  base.predictions = e.PredictAll({});
  for (int r = 0; r < e.runs(); ++r) base.scores.push_back(e.Score(r, base.predictions[r]));
  d.baseline_mse = e.MeanSquaredErrors(base.scores);
  d.residuals = GroupResiduals(e, base.predictions);
  d.direction_difference = DirectionDifference(d.residuals, e.channels());
  d.change_points = ChangePoints(e, base.predictions);
  return base;
}

}  // namespace

ModelDiagnosis DiagnoseModel(const DiagnosisModel& model, const std::vector<DiagnosisRun>& runs,
                             const ChannelNoise& noise, const DiagnosisOptions& options) {
  const Engine e(model, runs, noise, options);
  ModelDiagnosis d;
  const Reference base = AnalyseBaseline(e, d);
  Selection s = SelectCauses(e, base, d.candidates);
  // Unexplained: the best extension (or the baseline, when nothing is significant) still leaves
  // a systematic residual. No extension is adopted then; `where` locates the residual.
  const bool unexplained = e.Systematic(e.MeanSquaredErrors(s.scores), s.scores) ||
                           (s.named.empty() && e.Systematic(d.baseline_mse, base.scores));
  if (unexplained) s = Selection{{}, {}, base.scores};
  if (options.refine && !s.named.empty()) s.values = Refine(e, s.named, s.values);
  for (size_t i = 0; i < s.named.size(); ++i) d.parameters.emplace_back(s.named[i], s.values[i]);
  d.extended_mse = e.MeanSquaredErrors(s.scores);
  d.baseline = base.predictions;
  d.extended = e.PredictAll(d.parameters);
  if (unexplained) {
    d.cause = {"unexplained"};
    d.where = Locate(e, d.extended);
  } else if (s.named.empty()) {
    d.cause = {"none"};
  } else {
    for (int p : s.named) {
      const std::string& cause = e.parameter(p).cause;
      if (std::find(d.cause.begin(), d.cause.end(), cause) == d.cause.end()) {
        d.cause.push_back(cause);
      }
    }
  }
  return d;
}

}  // namespace hybrid
