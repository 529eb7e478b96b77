#include "solvers/diagnosis/profile_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hybrid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kGolden = 0.3819660112501051;  // 2 - the golden ratio

double Total(const std::vector<double>& losses, const std::vector<char>& use) {
  double total = 0.0;
  for (size_t r = 0; r < losses.size(); ++r) {
    if (use.empty() || use[r]) total += losses[r];
  }
  return std::isnan(total) ? kInf : total;
}

// The vertex of the parabola through three points (x0 < x1 < x2), if it opens upwards.
std::optional<double> Vertex(double x0, double y0, double x1, double y1, double x2, double y2) {
  if (!std::isfinite(y0) || !std::isfinite(y1) || !std::isfinite(y2)) return std::nullopt;
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1);
  const double curvature = (d12 - d01) / (x2 - x0);
  if (!(curvature > 0)) return std::nullopt;
  const double slope_at_x1 = d01 + curvature * (x1 - x0);
  return std::clamp(x1 - slope_at_x1 / (2.0 * curvature), x0, x2);
}

// The next value of the bracketing and whether it is a parabolic step: the vertex of the
// parabola through the best point and its neighbours when `parabola_ok` and it lands well inside
// the bracket, else the golden section of the larger side. nullopt when the bracket collapsed.
std::optional<std::pair<double, bool>> NextValue(const std::vector<std::pair<double, double>>& pts,
                                                 double lo, double hi, bool parabola_ok) {
  size_t b = 0;
  for (size_t i = 1; i < pts.size(); ++i) {
    if (pts[i].second < pts[b].second) b = i;
  }
  const double x = pts[b].first;
  const double left = b > 0 ? pts[b - 1].first : lo;
  const double right = b + 1 < pts.size() ? pts[b + 1].first : hi;
  if (right - left <= 1e-9 * std::max(1.0, std::abs(hi - lo))) return std::nullopt;
  if (parabola_ok && b > 0 && b + 1 < pts.size()) {
    const auto v = Vertex(pts[b - 1].first, pts[b - 1].second, x, pts[b].second, pts[b + 1].first,
                          pts[b + 1].second);
    const double margin = 0.05 * (right - left);
    if (v && *v > left + margin && *v < right - margin && std::abs(*v - x) > margin) {
      return std::pair{*v, true};
    }
  }
  if (right - x >= x - left) return std::pair{x + kGolden * (right - x), false};
  return std::pair{x - kGolden * (x - left), false};
}

// The first value the bracketing around grid[i] (neighbours a and c) tries: the vertex of the
// parabola through the three grid points' losses `own` (of the horizon that chose the start)
// when it lies well inside the bracket, else the golden section towards the lower neighbour.
std::optional<double> FirstProbe(const std::vector<double>& grid, const std::vector<double>& own,
                                 int a, int i, int c) {
  if (a == i || c == i) return std::nullopt;  // at an end: the golden section decides
  const double margin = 0.05 * (grid[c] - grid[a]);
  const auto v = Vertex(grid[a], own[a], grid[i], own[i], grid[c], own[c]);
  if (v && *v > grid[a] + margin && *v < grid[c] - margin &&
      std::abs(*v - grid[i]) > 0.01 * (grid[c] - grid[a])) {
    return v;
  }
  return own[a] < own[c] ? grid[i] - kGolden * (grid[i] - grid[a])
                         : grid[i] + kGolden * (grid[c] - grid[i]);
}

}  // namespace

void Profile::Add(double value, std::vector<double> run_losses) {
  const auto it = std::lower_bound(grid.begin(), grid.end(), value);
  if (it != grid.end() && *it == value) return;
  const auto at = it - grid.begin();
  grid.insert(it, value);
  losses.insert(losses.begin() + at, std::move(run_losses));
}

std::optional<double> Minimise(const Profile& p, const std::vector<char>& use) {
  const size_t m = p.grid.size();
  std::vector<double> total(m);
  for (size_t i = 0; i < m; ++i) total[i] = Total(p.losses[i], use);
  const size_t best = std::min_element(total.begin(), total.end()) - total.begin();
  if (m == 0 || !std::isfinite(total[best])) return std::nullopt;
  if (best == 0 || best + 1 == m || p.grid[best + 1] - p.grid[best - 1] > p.coarse_step) {
    return p.grid[best];
  }
  const auto v = Vertex(p.grid[best - 1], total[best - 1], p.grid[best], total[best],
                        p.grid[best + 1], total[best + 1]);
  return v ? *v : p.grid[best];
}

void BracketSearch(double lo, double hi, std::vector<std::pair<double, double>> known,
                   int evaluations, const std::function<double(double)>& loss,
                   std::optional<double> first) {
  if (first && evaluations > 0 && *first > lo && *first < hi) {
    known.emplace_back(*first, loss(*first));
    --evaluations;
  }
  std::sort(known.begin(), known.end());
  known.erase(std::unique(known.begin(), known.end(),
                          [](const auto& a, const auto& b) { return a.first == b.first; }),
              known.end());
  for (auto& point : known) {
    if (std::isnan(point.second)) point.second = kInf;
  }
  bool parabola_ok = true;
  for (int e = 0; e < evaluations && !known.empty(); ++e) {
    const auto next = NextValue(known, lo, hi, parabola_ok);
    if (!next) return;
    const auto [x, parabolic] = *next;
    double best = kInf;
    for (const auto& point : known) best = std::min(best, point.second);
    double f = loss(x);
    if (std::isnan(f)) f = kInf;
    // A parabolic step that did not improve on the best point: the next step is golden.
    parabola_ok = !(parabolic && !(f < best));
    known.insert(std::upper_bound(known.begin(), known.end(), std::make_pair(x, f)), {x, f});
  }
}

Profile SearchProfile(const SearchSettings& s,
                      const std::function<HorizonLosses(const std::vector<double>&)>& evaluate) {
  Profile profile;
  const int m = std::max(2, s.coarse);
  profile.coarse_step = (s.hi - s.lo) / (m - 1);
  std::vector<double> grid;
  for (int i = 0; i < m; ++i) grid.push_back(s.lo + (s.hi - s.lo) * i / (m - 1));
  const HorizonLosses coarse = evaluate(grid);
  std::vector<std::vector<double>> totals(s.horizons, std::vector<double>(m));
  for (int i = 0; i < m; ++i) {
    for (int h = 0; h < s.horizons; ++h) totals[h][i] = Total(coarse[i][h], {});
    profile.Add(grid[i], coarse[i].back());
  }
  std::vector<int> starts, horizon_of;
  const auto add_start = [&](int i) {
    if (!std::isfinite(totals.back()[i]) ||
        std::find(starts.begin(), starts.end(), i) != starts.end()) {
      return false;
    }
    starts.push_back(i);
    return true;
  };
  for (int h = 0; h < s.horizons; ++h) {
    if (add_start(std::min_element(totals[h].begin(), totals[h].end()) - totals[h].begin())) {
      horizon_of.push_back(h);
    }
  }
  std::vector<int> minima;
  const std::vector<double>& full = totals.back();
  for (int i = 0; i < m; ++i) {
    if ((i == 0 || full[i] <= full[i - 1]) && (i + 1 == m || full[i] <= full[i + 1]))
      minima.push_back(i);
  }
  std::sort(minima.begin(), minima.end(), [&](int a, int b) { return full[a] < full[b]; });
  const size_t wanted = starts.size() + std::max(0, s.extra_starts);
  for (size_t k = 0; k < minima.size() && starts.size() < wanted; ++k) add_start(minima[k]);
  for (size_t k = 0; k < starts.size(); ++k) {
    const int i = starts[k];
    const int a = std::max(0, i - 1), c = std::min(m - 1, i + 1);
    // The start's own horizon (the full one for the extra starts) says where to look first.
    const std::vector<double>& own = totals[k < horizon_of.size() ? horizon_of[k] : s.horizons - 1];
    BracketSearch(
        grid[a], grid[c], {{grid[i], full[i]}}, s.evaluations,
        [&](double x) {
          HorizonLosses l = evaluate({x});
          profile.Add(x, l[0].back());
          return Total(l[0].back(), {});
        },
        FirstProbe(grid, own, a, i, c));
  }
  return profile;
}

}  // namespace hybrid
