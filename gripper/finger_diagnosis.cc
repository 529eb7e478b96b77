#include "gripper/finger_diagnosis.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

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

struct RunScore {
  double loss = 0.0;  // robust, chi-square units
  std::array<double, 3> sse = {0, 0, 0};
  std::array<int, 3> n = {0, 0, 0};
};

void ParallelFor(int count, int threads, const std::function<void(int)>& body) {
  if (threads <= 1 || count <= 1) {
    for (int i = 0; i < count; ++i) body(i);
    return;
  }
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (int i = next++; i < count; i = next++) {
      try {
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, count); ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// The range searched for each parameter.
std::pair<double, double> SearchRange(const EffectParameter& p) {
  switch (p.cause) {
    case Cause::kBacklash:
      return {0.0, 30.0};
    case Cause::kMotorOffset:
      return {-30.0, 30.0};
    case Cause::kJointRange:
      return p.index == 0   ? std::pair{45.0, 95.0}
             : p.index == 1 ? std::pair{60.0, 120.0}
                            : std::pair{20.0, 66.0};
    case Cause::kSensorBias:
      return {-15.0, 15.0};
    case Cause::kCompliance:
      return {0.0, 0.3};
    case Cause::kTheta3Law:
      return {0.2, 0.85};
  }
  return {0.0, 1.0};
}

bool HasReversal(const MeasuredRun& run) {
  int direction = 0;
  double last = 0.0;
  for (double g : run.g) {
    const int d = g > last ? 1 : g < last ? -1 : 0;
    if (d != 0 && direction != 0 && d != direction) return true;
    if (d != 0) direction = d;
    last = g;
  }
  return false;
}

FingerEffects WithoutBias(FingerEffects e) {
  e.sensor_bias = {0.0, 0.0, 0.0};
  return e;
}

bool NeutralDrive(const FingerEffects& e) {
  return e.backlash == 0.0 && e.motor_offset == 0.0 && e.SameDynamics(FingerEffects{});
}

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

class Engine {
 public:
  // `baseline`: the model's predictions of every run with no effect (Diagnose computes them
  // once, before cleaning).
  Engine(const FingerPredictor& predictor, const MeasuredData& data, const DiagnosisOptions& o,
         const NoiseFloor& noise, std::vector<FingerPrediction> baseline)
      : predictor_(predictor), data_(data), o_(o) {
    for (int j = 0; j < 3; ++j) {
      sigma_[j] = std::sqrt(std::max(noise.variance[j], 1e-12));
    }
    const int runs = static_cast<int>(data.runs.size());
    representative_.resize(runs);
    for (int r = 0; r < runs; ++r) {
      representative_[r] = r;
      for (int s = 0; s < r; ++s) {
        const MeasuredRun &a = data.runs[r], &b = data.runs[s];
        if (a.g == b.g && a.gob == b.gob && a.contact_link == b.contact_link) {
          representative_[r] = s;
          break;
        }
      }
    }
    baseline_ = std::move(baseline);
    for (const MeasuredRun& run : data.runs) samples_ += static_cast<int>(run.g.size());
  }

  int runs() const { return static_cast<int>(data_.runs.size()); }
  const FingerPrediction& baseline(int r) const { return baseline_[r]; }
  const std::array<double, 3>& sigma() const { return sigma_; }

  FingerPrediction Checked(int r, const FingerEffects& e) const {
    FingerPrediction p = predictor_.Predict(data_.runs[r], e);
    if (p.status != SimulationStatus::kCompleted) {
      throw std::invalid_argument("Diagnose: the model stopped on run '" + data_.runs[r].label +
                                  "': " + p.message);
    }
    return p;
  }

  // The prediction of run r under e (the baseline's, shifted, when only biases differ).
  // Predictions depend only on the run's motor path and object, so runs that repeat one another
  // share them (memoised per representative run and effects).
  FingerPrediction Predict(int r, const FingerEffects& e) const {
    const FingerEffects dynamic = WithoutBias(e);
    FingerPrediction p;
    if (NeutralDrive(dynamic)) {
      p = baseline_[r];
    } else {
      std::string key = std::to_string(representative_[r]) + ":";
      char buffer[40];
      auto add = [&](double v) {
        std::snprintf(buffer, sizeof buffer, "%.17g;", v);
        key += buffer;
      };
      add(dynamic.backlash);
      add(dynamic.motor_offset);
      for (const auto& m : dynamic.joint_max) add(m ? *m : kNaN);
      for (double k : dynamic.compliance) add(k);
      add(dynamic.theta3_fraction ? *dynamic.theta3_fraction : kNaN);
      {
        std::lock_guard<std::mutex> lock(memo_mutex_);
        const auto it = memo_.find(key);
        if (it != memo_.end()) p = *it->second;
      }
      if (p.theta[0].empty()) {
        p = Checked(representative_[r], dynamic);
        std::lock_guard<std::mutex> lock(memo_mutex_);
        memo_.emplace(key, std::make_shared<const FingerPrediction>(p));
      }
    }
    for (int j = 0; j < 3; ++j) {
      for (double& v : p.theta[j]) v += e.sensor_bias[j];
    }
    return p;
  }

  RunScore Score(int r, const FingerPrediction& p) const {
    RunScore s;
    const MeasuredRun& run = data_.runs[r];
    for (int j = 0; j < 3; ++j) {
      for (size_t k = 0; k < run.g.size(); ++k) {
        const double m = run.theta[j][k];
        if (std::isnan(m)) continue;
        const double res = m - p.theta[j][k];
        s.loss += Rho(res / sigma_[j], o_.huber);
        s.sse[j] += res * res;
        ++s.n[j];
      }
    }
    return s;
  }

  // Whether changing p (from `reference`'s predictions) can change run r's prediction.
  bool Affected(const EffectParameter& p, int r, const FingerPrediction& reference) const {
    const MeasuredRun& run = data_.runs[r];
    auto visits = [&](const std::function<bool(const Mode&)>& f) {
      for (int m : reference.mode) {
        if (m >= 0 && f(predictor_.finger().modes()[m])) return true;
      }
      return false;
    };
    const Automaton& a = predictor_.finger();
    auto value = [&](const Mode& m, const char* name) {
      return m.DiscreteValueOf(*a.symbols().Find(name)).value_or(0);
    };
    switch (p.cause) {
      case Cause::kBacklash:
        return HasReversal(run);
      case Cause::kCompliance:
        return visits([&](const Mode& m) { return value(m, p.index == 0 ? "c1" : "c2") == 1; });
      case Cause::kTheta3Law:
        return visits([&](const Mode& m) { return value(m, "c2") == 1 || value(m, "l2") == 1; });
      default:
        return true;
    }
  }

  struct Evaluated {
    CandidateFit fit;
    std::vector<RunScore> heldout;  // per run
    std::vector<double> fold_values;
    std::vector<double> fold_first;  // the first cause's fold values (pairs)
    Profile profile;
  };

  // Cross-validates parameter p on top of `base` (the first cause fixed at its all-data value
  // for the profile, at its fold values `base_folds` for the held-out predictions), against the
  // reference held-out scores `reference`.
  Evaluated Evaluate(const EffectParameter& p, const FingerEffects& base,
                     const std::optional<EffectParameter>& first,
                     const std::vector<double>& first_folds, const std::vector<RunScore>& reference,
                     const std::vector<FingerPrediction>& reference_predictions) const {
    const int R = runs();
    std::vector<char> affected(R);
    for (int r = 0; r < R; ++r) affected[r] = Affected(p, r, reference_predictions[r]);
    Evaluated ev;
    const auto [lo, hi] = SearchRange(p);
    const bool cheap = p.cause == Cause::kSensorBias;
    const int coarse = cheap ? 121 : first ? o_.pair_grid_points : o_.grid_points;
    std::vector<double> grid;
    for (int i = 0; i < coarse; ++i) grid.push_back(lo + (hi - lo) * i / (coarse - 1));
    auto profile_at = [&](const std::vector<double>& values) {
      std::vector<std::vector<double>> losses(values.size(), std::vector<double>(R, 0.0));
      std::vector<std::pair<int, int>> tasks;
      for (size_t i = 0; i < values.size(); ++i) {
        for (int r = 0; r < R; ++r) {
          if (affected[r]) {
            tasks.emplace_back(static_cast<int>(i), r);
          } else {
            losses[i][r] = Score(r, reference_predictions[r]).loss;
          }
        }
      }
      ParallelFor(static_cast<int>(tasks.size()), cheap ? 1 : o_.threads, [&](int t) {
        const auto [i, r] = tasks[t];
        FingerEffects e = base;
        SetEffect(e, p, values[i]);
        losses[i][r] = Score(r, Predict(r, e)).loss;
      });
      return losses;
    };
    ev.profile.grid = grid;
    ev.profile.losses = profile_at(grid);
    // Fine pass around the all-data best.
    const std::vector<char> all(R, 1);
    const double best = Minimise(ev.profile, all);
    const double h = (hi - lo) / (coarse - 1);
    std::vector<double> fine;
    for (double f : {-0.6, -0.3, 0.3, 0.6}) {
      const double v = best + f * h;
      if (v > lo && v < hi) fine.push_back(v);
    }
    const auto fine_losses = profile_at(fine);
    for (size_t i = 0; i < fine.size(); ++i) {
      ev.profile.grid.push_back(fine[i]);
      ev.profile.losses.push_back(fine_losses[i]);
    }
    {
      std::vector<size_t> order(ev.profile.grid.size());
      for (size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::sort(order.begin(), order.end(),
                [&](size_t a, size_t b) { return ev.profile.grid[a] < ev.profile.grid[b]; });
      Profile sorted;
      for (size_t i : order) {
        if (!sorted.grid.empty() && sorted.grid.back() == ev.profile.grid[i]) continue;
        sorted.grid.push_back(ev.profile.grid[i]);
        sorted.losses.push_back(ev.profile.losses[i]);
      }
      ev.profile = std::move(sorted);
    }
    const double value = Minimise(ev.profile, all);
    // Leave one run out.
    ev.fold_values.assign(R, value);
    ev.heldout.assign(R, RunScore{});
    std::vector<int> todo;
    for (int r = 0; r < R; ++r) {
      std::vector<char> train(R, 1);
      train[r] = 0;
      ev.fold_values[r] = Minimise(ev.profile, train);
      if (affected[r]) {
        todo.push_back(r);
      } else {
        ev.heldout[r] = reference[r];
      }
    }
    ParallelFor(static_cast<int>(todo.size()), cheap ? 1 : o_.threads, [&](int t) {
      const int r = todo[t];
      FingerEffects e = base;
      if (first) SetEffect(e, *first, first_folds[r]);
      SetEffect(e, p, ev.fold_values[r]);
      ev.heldout[r] = Score(r, Predict(r, e));
    });
    // All-data fit's in-sample loss for the BIC.
    double in_sample = std::numeric_limits<double>::infinity();
    for (const std::vector<double>& losses : ev.profile.losses) {
      double total = 0.0;
      for (double l : losses) total += l;
      in_sample = std::min(in_sample, total);
    }
    CandidateFit& fit = ev.fit;
    if (first) {
      fit.parameters.push_back(*first);
      fit.values.push_back(GetEffect(base, *first, predictor_.finger()));
    }
    fit.parameters.push_back(p);
    fit.values.push_back(value);
    double ref_loss = 0.0;
    std::array<double, 3> sse = {0, 0, 0};
    std::array<int, 3> n = {0, 0, 0};
    for (int r = 0; r < R; ++r) {
      ref_loss += reference[r].loss;
      fit.heldout_loss += ev.heldout[r].loss;
      for (int j = 0; j < 3; ++j) {
        sse[j] += ev.heldout[r].sse[j];
        n[j] += ev.heldout[r].n[j];
      }
    }
    for (int j = 0; j < 3; ++j) fit.heldout_mse[j] = n[j] > 0 ? sse[j] / n[j] : kNaN;
    fit.gain = ref_loss - fit.heldout_loss;
    fit.bic = in_sample + static_cast<double>(fit.parameters.size()) * std::log(samples_);
    fit.significant = fit.gain > o_.significance;
    return ev;
  }

  int samples() const { return samples_; }

 private:
  const FingerPredictor& predictor_;
  const MeasuredData& data_;
  DiagnosisOptions o_;
  std::array<double, 3> sigma_{};
  std::vector<FingerPrediction> baseline_;
  std::vector<int> representative_;  // the first run with the same motor path and object
  mutable std::mutex memo_mutex_;
  mutable std::map<std::string, std::shared_ptr<const FingerPrediction>> memo_;
  int samples_ = 0;
};

}  // namespace

Diagnosis Diagnose(const FingerPredictor& predictor, MeasuredData data,
                   const DiagnosisOptions& options) {
  if (data.runs.empty()) throw std::invalid_argument("Diagnose: the data have no runs");
  Diagnosis d;
  // The report's outlier rule, applied to the residual against the baseline model: "a change in
  // sensed angle of more than 5 degrees from one value of g to the next" cannot happen on the
  // robot, except where the model itself moves that fast (the phase-3 law near g = 255 does),
  // so the rule looks at changes beyond the model's.
  const int runs = static_cast<int>(data.runs.size());
  std::vector<FingerPrediction> base(runs);
  {
    ParallelFor(runs, options.threads, [&](int r) {
      base[r] = predictor.Predict(data.runs[r], FingerEffects{});
      if (base[r].status != SimulationStatus::kCompleted) {
        throw std::invalid_argument("Diagnose: the model stopped on run '" + data.runs[r].label +
                                    "': " + base[r].message);
      }
    });
    MeasuredData residual = data;
    for (int r = 0; r < runs; ++r) {
      for (int j = 0; j < 3; ++j) {
        for (size_t k = 0; k < data.runs[r].g.size(); ++k) {
          residual.runs[r].theta[j][k] -= base[r].theta[j][k];
        }
      }
    }
    d.outliers = CleanOutliers(residual, options.outlier_threshold);
    for (int r = 0; r < runs; ++r) {
      for (int j = 0; j < 3; ++j) {
        for (size_t k = 0; k < data.runs[r].g.size(); ++k) {
          data.runs[r].theta[j][k] = residual.runs[r].theta[j][k] + base[r].theta[j][k];
        }
      }
    }
    // Entries back in measured angles.
    for (OutlierReport::Entry& e : d.outliers.entries) {
      for (int r = 0; r < runs; ++r) {
        const MeasuredRun& run = data.runs[r];
        if (run.label != e.run) continue;
        const auto it = std::find(run.lines.begin(), run.lines.end(), e.line);
        if (it == run.lines.end()) continue;
        const double model = base[r].theta[e.joint - 1][it - run.lines.begin()];
        e.measured += model;
        e.cleaned += model;
      }
    }
  }
  d.noise = EstimateNoiseFloor(data);
  d.samples = data.samples();
  const Engine engine(predictor, data, options, d.noise, std::move(base));
  const int R = engine.runs();
  const std::array<double, 3> sigma = engine.sigma();

  // Baseline residuals.
  std::vector<RunScore> base_scores(R);
  std::vector<FingerPrediction> base_predictions(R);
  for (int r = 0; r < R; ++r) {
    base_predictions[r] = engine.baseline(r);
    base_scores[r] = engine.Score(r, base_predictions[r]);
  }
  auto mse_of = [](const std::vector<RunScore>& s) {
    std::array<double, 3> mse{};
    for (int j = 0; j < 3; ++j) {
      double sse = 0;
      int n = 0;
      for (const RunScore& x : s) {
        sse += x.sse[j];
        n += x.n[j];
      }
      mse[j] = n > 0 ? sse / n : kNaN;
    }
    return mse;
  };
  d.baseline_mse = mse_of(base_scores);

  // Residual analysis per joint, mode and direction; change points; direction dependence.
  auto analyse = [&](const std::vector<FingerPrediction>& preds) {
    struct Acc {
      int n = 0;
      double s = 0, ss = 0, sg = 0, sgg = 0, sgr = 0, gmin = 1e300, gmax = -1e300;
    };
    std::map<std::tuple<int, int, int>, Acc> acc;
    for (int r = 0; r < R; ++r) {
      const MeasuredRun& run = data.runs[r];
      for (int j = 0; j < 3; ++j) {
        for (size_t k = 0; k < run.g.size(); ++k) {
          const double m = run.theta[j][k];
          if (std::isnan(m)) continue;
          const double res = m - preds[r].theta[j][k];
          Acc& a = acc[{j, preds[r].mode[k], preds[r].direction[k]}];
          const double g = run.g[k];
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
    std::vector<ResidualGroup> groups;
    for (const auto& [key, a] : acc) {
      const auto [j, mode, dir] = key;
      ResidualGroup gr;
      gr.joint = j;
      gr.mode = mode >= 0 ? predictor.ModeName(mode) : "?";
      gr.direction = dir;
      gr.samples = a.n;
      gr.mean = a.s / a.n;
      const double var_g = a.sgg / a.n - (a.sg / a.n) * (a.sg / a.n);
      gr.slope = var_g > 1e-9 ? (a.sgr / a.n - (a.sg / a.n) * gr.mean) / var_g : 0.0;
      gr.rms = std::sqrt(a.ss / a.n);
      gr.excess = a.ss / a.n / (sigma[j] * sigma[j]) - 1.0;
      gr.g_min = a.gmin;
      gr.g_max = a.gmax;
      groups.push_back(gr);
    }
    return groups;
  };
  d.residuals = analyse(base_predictions);
  {
    std::array<double, 3> sum_c{}, sum_o{};
    std::array<int, 3> n_c{}, n_o{};
    for (const ResidualGroup& g : d.residuals) {
      if (g.direction > 0) {
        sum_c[g.joint] += g.mean * g.samples;
        n_c[g.joint] += g.samples;
      } else {
        sum_o[g.joint] += g.mean * g.samples;
        n_o[g.joint] += g.samples;
      }
    }
    for (int j = 0; j < 3; ++j) {
      d.direction_difference[j] =
          n_c[j] > 0 && n_o[j] > 0 ? sum_c[j] / n_c[j] - sum_o[j] / n_o[j] : 0.0;
    }
    constexpr int kWindow = 10;
    for (int r = 0; r < R; ++r) {
      const MeasuredRun& run = data.runs[r];
      const FingerPrediction& p = base_predictions[r];
      for (size_t k = 1; k < run.g.size(); ++k) {
        if (p.mode[k] == p.mode[k - 1]) continue;
        for (int j = 0; j < 3; ++j) {
          auto mean = [&](size_t from, size_t to) {
            double s = 0;
            int n = 0;
            for (size_t i = from; i < to && i < run.g.size(); ++i) {
              if (std::isnan(run.theta[j][i])) continue;
              s += run.theta[j][i] - p.theta[j][i];
              ++n;
            }
            return n > 0 ? s / n : kNaN;
          };
          const double before = mean(k >= kWindow ? k - kWindow : 0, k);
          const double after = mean(k, k + kWindow);
          const double jump = after - before;
          if (std::isnan(jump) || std::abs(jump) < 3.0 * sigma[j] * std::sqrt(2.0 / kWindow)) {
            continue;
          }
          d.change_points.push_back(ChangePoint{run.label, static_cast<int>(k), run.g[k],
                                                predictor.ModeName(p.mode[k - 1]),
                                                predictor.ModeName(p.mode[k]), j, jump});
        }
      }
    }
    std::sort(d.change_points.begin(), d.change_points.end(),
              [](const ChangePoint& a, const ChangePoint& b) {
                return std::abs(a.jump) > std::abs(b.jump);
              });
    if (d.change_points.size() > 50) d.change_points.resize(50);
  }

  // A residual is systematic when its mean square exceeds the noise floor significantly.
  auto systematic = [&](const std::array<double, 3>& mse, const std::vector<RunScore>& scores) {
    for (int j = 0; j < 3; ++j) {
      int n = 0;
      for (const RunScore& s : scores) n += s.n[j];
      if (n == 0) continue;
      const double se = std::sqrt(2.0 / n + 2.0 / std::max(d.noise.dof[j], 1));
      const double ratio = mse[j] / (sigma[j] * sigma[j]) - 1.0;
      if (ratio > options.systematic_sigmas * se + options.systematic_margin) return true;
    }
    return false;
  };
  // Single candidates.
  const std::vector<EffectParameter> all = AllEffectParameters();
  std::vector<Engine::Evaluated> singles;
  for (const EffectParameter& p : all) {
    singles.push_back(
        engine.Evaluate(p, FingerEffects{}, std::nullopt, {}, base_scores, base_predictions));
    d.candidates.push_back(singles.back().fit);
  }
  auto pick = [&](const std::vector<Engine::Evaluated>& evs) -> int {
    int best = -1;
    for (size_t i = 0; i < evs.size(); ++i) {
      if (!evs[i].fit.significant) continue;
      if (best < 0 || evs[i].fit.heldout_loss < evs[best].fit.heldout_loss) best = i;
    }
    if (best < 0) return -1;
    // Ties (held-out losses within `tie`): the lower BIC.
    for (size_t i = 0; i < evs.size(); ++i) {
      if (!evs[i].fit.significant || static_cast<int>(i) == best) continue;
      if (evs[i].fit.heldout_loss - evs[best].fit.heldout_loss < options.tie &&
          evs[i].fit.bic < evs[best].fit.bic) {
        best = i;
      }
    }
    return best;
  };
  const int first = pick(singles);
  std::vector<EffectParameter> named;
  std::vector<double> values;
  std::vector<RunScore> final_scores = base_scores;
  if (first >= 0) {
    const Engine::Evaluated& one = singles[first];
    named = one.fit.parameters;
    values = one.fit.values;
    final_scores = one.heldout;
  }
  // Pairs with the first cause, when it leaves a systematic residual (otherwise the residual is
  // at the noise floor, and a second cause is not looked for).
  if (first >= 0 && systematic(singles[first].fit.heldout_mse, singles[first].heldout)) {
    const Engine::Evaluated& one = singles[first];
    FingerEffects base;
    SetEffect(base, all[first], one.fit.values[0]);
    std::vector<FingerPrediction> ref_predictions(R);
    ParallelFor(R, options.threads, [&](int r) { ref_predictions[r] = engine.Predict(r, base); });
    std::vector<Engine::Evaluated> pairs;
    for (const EffectParameter& p : all) {
      if (p == all[first]) continue;
      pairs.push_back(
          engine.Evaluate(p, base, all[first], one.fold_values, one.heldout, ref_predictions));
      d.candidates.push_back(pairs.back().fit);
    }
    const int second = pick(pairs);
    if (second >= 0) {
      named = pairs[second].fit.parameters;
      values = pairs[second].fit.values;
      final_scores = pairs[second].heldout;
    }
  }

  // Unexplained: the best extension (or the baseline, when nothing is significant) still leaves
  // a systematic residual. No extension is adopted then; `where` locates the residual.
  const bool base_systematic = systematic(d.baseline_mse, base_scores);
  const bool unexplained =
      systematic(mse_of(final_scores), final_scores) || (named.empty() && base_systematic);
  if (unexplained) {
    named.clear();
    values.clear();
    final_scores = base_scores;
  }

  // Refine the named parameters on all runs (Ceres; Huber loss per sample).
  FingerEffects effects;
  for (size_t i = 0; i < named.size(); ++i) SetEffect(effects, named[i], values[i]);
  if (options.refine && !named.empty()) {
    struct Cost {
      const Engine* engine;
      const MeasuredData* data;
      FingerEffects base;
      std::vector<EffectParameter> params;
      double huber;
      int threads;
      bool operator()(double const* const* x, double* residuals) const {
        FingerEffects e = base;
        for (size_t i = 0; i < params.size(); ++i) SetEffect(e, params[i], x[0][i]);
        const int R = engine->runs();
        std::vector<FingerPrediction> p(R);
        try {
          ParallelFor(R, threads, [&](int r) { p[r] = engine->Predict(r, e); });
        } catch (const std::exception&) {
          return false;
        }
        int k = 0;
        for (int r = 0; r < R; ++r) {
          const MeasuredRun& run = data->runs[r];
          for (int j = 0; j < 3; ++j) {
            for (size_t s = 0; s < run.g.size(); ++s) {
              const double m = run.theta[j][s];
              residuals[k++] =
                  std::isnan(m) ? 0.0 : RootRho((m - p[r].theta[j][s]) / engine->sigma()[j], huber);
            }
          }
        }
        return true;
      }
    };
    const int residual_count = 3 * d.samples;
    std::vector<std::vector<double>> starts = {values};
    double best_cost = std::numeric_limits<double>::infinity();
    std::vector<double> best = values;
    for (std::vector<double> x : starts) {
      ceres::Problem problem;
      auto* cost = new ceres::DynamicNumericDiffCostFunction<Cost, ceres::CENTRAL>(
          new Cost{&engine, &data, FingerEffects{}, named, options.huber, options.threads});
      cost->AddParameterBlock(static_cast<int>(x.size()));
      cost->SetNumResiduals(residual_count);
      problem.AddResidualBlock(cost, nullptr, x.data());
      for (size_t i = 0; i < named.size(); ++i) {
        const auto [lo, hi] = SearchRange(named[i]);
        problem.SetParameterLowerBound(x.data(), static_cast<int>(i), lo);
        problem.SetParameterUpperBound(x.data(), static_cast<int>(i), hi);
      }
      ceres::Solver::Options so;
      so.max_num_iterations = 12;
      so.linear_solver_type = ceres::DENSE_QR;
      so.logging_type = ceres::SILENT;
      ceres::Solver::Summary summary;
      ceres::Solve(so, &problem, &summary);
      if (summary.IsSolutionUsable() && summary.final_cost < best_cost) {
        best_cost = summary.final_cost;
        best = x;
      }
    }
    values = best;
    effects = FingerEffects{};
    for (size_t i = 0; i < named.size(); ++i) SetEffect(effects, named[i], values[i]);
  }
  d.effects = effects;
  for (size_t i = 0; i < named.size(); ++i) d.parameters.emplace_back(named[i], values[i]);
  d.extended_mse = mse_of(final_scores);

  // Final predictions and curves.
  std::vector<FingerPrediction> final_predictions(R);
  ParallelFor(R, options.threads,
              [&](int r) { final_predictions[r] = engine.Predict(r, effects); });
  for (int r = 0; r < R; ++r) {
    RunCurves c;
    c.label = data.runs[r].label;
    c.g = data.runs[r].g;
    c.measured = data.runs[r].theta;
    c.baseline = base_predictions[r].theta;
    c.extended = final_predictions[r].theta;
    d.curves.push_back(std::move(c));
  }
  if (unexplained) {
    d.cause = {"unexplained"};
    const std::vector<ResidualGroup> groups = analyse(final_predictions);
    const ResidualGroup* worst = nullptr;
    for (const ResidualGroup& g : groups) {
      if (!worst || g.excess * g.samples > worst->excess * worst->samples) worst = &g;
    }
    if (worst) {
      ResidualLocation w;
      w.joint = worst->joint;
      w.mode = worst->mode;
      w.direction = worst->direction;
      w.mean_residual = worst->mean;
      w.excess = worst->excess;
      // The g range where the running mean (9 samples) of the residual exceeds one sigma.
      double lo = 1e300, hi = -1e300;
      for (int r = 0; r < R; ++r) {
        const MeasuredRun& run = data.runs[r];
        const FingerPrediction& p = final_predictions[r];
        const int n = static_cast<int>(run.g.size());
        for (int k = 0; k < n; ++k) {
          if (p.mode[k] < 0 || predictor.ModeName(p.mode[k]) != worst->mode ||
              p.direction[k] != worst->direction) {
            continue;
          }
          double s = 0;
          int c = 0;
          for (int i = std::max(0, k - 4); i <= std::min(n - 1, k + 4); ++i) {
            const double m = run.theta[worst->joint][i];
            if (std::isnan(m)) continue;
            s += m - p.theta[worst->joint][i];
            ++c;
          }
          if (c > 0 && std::abs(s / c) > sigma[worst->joint]) {
            lo = std::min(lo, run.g[k]);
            hi = std::max(hi, run.g[k]);
          }
        }
      }
      w.g_min = lo <= hi ? lo : worst->g_min;
      w.g_max = lo <= hi ? hi : worst->g_max;
      d.where = w;
    }
  } else if (named.empty()) {
    d.cause = {"none"};
  } else {
    for (const EffectParameter& p : named) {
      const std::string name(CauseName(p.cause));
      if (std::find(d.cause.begin(), d.cause.end(), name) == d.cause.end()) {
        d.cause.push_back(name);
      }
    }
  }
  return d;
}

}  // namespace hybrid
