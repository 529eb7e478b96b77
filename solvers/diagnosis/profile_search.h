#pragma once

// The one-parameter search of the diagnosis engine (DiagnoseModel, step 2), model-independent:
// the losses of every run at the values tried (a profile), the minimiser of any subset of runs'
// losses among them (leave-one-run-out folds), and the multi-start bracketing search that fills
// the profile.

#include <functional>
#include <optional>
#include <vector>

namespace hybrid {

/// The losses of every run at every value of one parameter tried so far.
struct Profile {
  /// Sorted, distinct.
  std::vector<double> grid;
  /// losses[i][r]: run r's loss at grid[i]; +inf where the run could not be predicted.
  std::vector<std::vector<double>> losses;
  /// The spacing of the coarse grid the search started from (0: unknown). The minimiser refines
  /// by a parabola only between points closer than this.
  double coarse_step = 0.0;

  /// Records run losses `run_losses` at `value` (kept sorted; a value already recorded is left
  /// as it is).
  void Add(double value, std::vector<double> run_losses);
};

/// The value among p.grid of least total loss over the runs with use[r] != 0, refined by the
/// vertex of the parabola through it and its two neighbours when both are finite, the curvature
/// is positive and the neighbours are close (x2 - x0 <= p.coarse_step, i.e. the point was
/// refined, not a coarse grid point between coarse neighbours); nullopt when no point has a
/// finite total.
std::optional<double> Minimise(const Profile& p, const std::vector<char>& use);

/// The losses of a search at a list of values: [value][horizon][run], the horizons those of
/// SearchSettings (the last the full one).
using HorizonLosses = std::vector<std::vector<std::vector<double>>>;

/// How SearchProfile searches one parameter.
struct SearchSettings {
  double lo = 0.0, hi = 1.0;
  /// Points of the coarse grid over [lo, hi] (>= 2).
  int coarse = 9;
  /// Number of horizons the evaluation reports (their losses select starts); >= 1.
  int horizons = 1;
  /// Further starts: local minima of the full-horizon loss on the coarse grid, best first.
  int extra_starts = 0;
  /// Evaluations of the bracketing search around each start.
  int evaluations = 7;
};

/// Multi-start bracketing search of one parameter. `evaluate` gives the losses at a list of
/// values (for every horizon and run, +inf where a run cannot be predicted); it is called once
/// with the whole coarse grid and then once per evaluation of the bracketing. The starts are the
/// best coarse point of each horizon (the total over runs of that horizon's losses) and
/// `extra_starts` further local minima of the full horizon's; around each start the search
/// brackets between its grid neighbours (BracketSearch, on the full horizon's total loss),
/// first trying the vertex of the parabola through the start's horizon's losses at the three
/// grid points (or the golden section towards the lower neighbour), where a narrow basin that
/// the short horizon sees wide is.
/// Returns every value tried with its full-horizon run losses (coarse_step set).
Profile SearchProfile(const SearchSettings& settings,
                      const std::function<HorizonLosses(const std::vector<double>&)>& evaluate);

/// The bracketing alone: narrows the bracket [lo, hi] by `evaluations` calls of `loss` (a
/// total, +inf where it cannot be computed): each step looks between the best point so far and
/// its neighbours (the bracket's ends where it has none): the vertex of the parabola through the
/// three when it lands well inside and the last parabolic step improved, else the golden section
/// of the larger side. `known` holds (value, total) points already evaluated inside the bracket
/// (at least the start; the ends are bounds, not candidates, unless given here); `first`, if
/// inside, is the first value tried. Every call of `loss` is the caller's record.
void BracketSearch(double lo, double hi, std::vector<std::pair<double, double>> known,
                   int evaluations, const std::function<double(double)>& loss,
                   std::optional<double> first = std::nullopt);

}  // namespace hybrid
