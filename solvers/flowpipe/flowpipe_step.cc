#include "solvers/flowpipe/flowpipe_step.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hybrid::flowpipe_internal {
namespace {

std::vector<TightInterval> Ranges(const std::vector<AffineForm>& x) {
  std::vector<TightInterval> out;
  out.reserve(x.size());
  for (const AffineForm& f : x) out.push_back(f.Range());
  return out;
}

// exp(x) rounded up: libm's exp is within 1 ulp; two ulps up cover it.
double ExpUp(double x) { return NextUp(NextUp(std::exp(x))); }

}  // namespace

FlowpipeStep::FlowpipeStep(const TaylorTape& tape, std::vector<TightInterval> inputs, int order,
                           std::vector<char> protected_symbols, int max_symbols)
    : tape_(tape),
      inputs_(std::move(inputs)),
      order_(order),
      protected_(std::move(protected_symbols)),
      max_symbols_(max_symbols) {
  for (const TightInterval& u : inputs_) {
    // The midpoint need not be exact: it is one admissible input value.
    const double c = std::isfinite(u.lo) && std::isfinite(u.hi) ? u.Mid() : 0.0;
    input_centres_.push_back(AffineForm(c));
    input_centre_boxes_.push_back(TightInterval(c));
  }
}

std::optional<std::vector<TightInterval>> FlowpipeStep::Apriori(
    const std::vector<TightInterval>& box, double h) const {
  const TightInterval span(0.0, h);
  std::vector<TightInterval> f = tape_.Evaluate(box, inputs_);
  std::vector<TightInterval> b(box.size());
  for (std::size_t i = 0; i < box.size(); ++i) b[i] = box[i] + span * f[i];
  for (int attempt = 0; attempt < 10; ++attempt) {
    // Widen the guess, then test the Picard operator: box + [0, h] f(B) inside B.
    for (TightInterval& x : b) {
      const double w = std::max(x.hi - x.lo, 0.0);
      const double pad = 0.05 * w * (1 << attempt) + 1e-12 * (1.0 + x.MagnitudeUp());
      x = {SubDown(x.lo, pad), AddUp(x.hi, pad)};
    }
    f = tape_.Evaluate(b, inputs_);
    bool inside = true;
    std::vector<TightInterval> image(box.size());
    for (std::size_t i = 0; i < box.size(); ++i) {
      image[i] = box[i] + span * f[i];
      if (!(image[i].IsFinite() && b[i].Contains(image[i]))) inside = false;
    }
    if (inside) {
      // Every solution stays in B, so also in box + [0, h] f(B) = image, and so on: two more
      // Picard iterations tighten the enclosure (an attained bound such as a drop height is
      // then not exceeded by the guess's padding).
      for (int refine = 0; refine < 2; ++refine) {
        f = tape_.Evaluate(image, inputs_);
        for (std::size_t i = 0; i < box.size(); ++i) {
          const TightInterval next = box[i] + span * f[i];
          image[i] = {std::max(image[i].lo, next.lo), std::min(image[i].hi, next.hi)};
        }
      }
      return image;
    }
    for (std::size_t i = 0; i < box.size(); ++i) b[i] = Hull(b[i], image[i]);
    if (std::any_of(b.begin(), b.end(), [](const TightInterval& x) { return !x.IsFinite(); }))
      break;
  }
  return std::nullopt;
}

std::vector<double> FlowpipeStep::InputDeviation(const std::vector<TightInterval>& apriori,
                                                 double h) const {
  const std::size_t n = apriori.size();
  std::vector<double> d(n, 0.0);
  if (!tape_.reads_inputs()) return d;
  const auto gain = tape_.InputGainMagnitude(apriori);
  std::vector<double> w(n, 0.0);
  double w_max = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < inputs_.size(); ++j) {
      if (gain[i][j] != 0) w[i] = AddUp(w[i], MulUp(gain[i][j], inputs_[j].RadiusUp()));
    }
    w_max = std::max(w_max, w[i]);
  }
  if (w_max == 0) return d;
  // The difference e between a solution under any input signal in U and the one under the
  // midpoint inputs obeys e' = J e + B (u - u_c) with J in the Jacobian's enclosure over the
  // a-priori box: |e_i|' <= J_ii |e_i| + sum_{j != i} |J_ij| |e_j| + w_i. With mu the
  // (infinity-norm) logarithmic norm bound max_i (sup J_ii + sum_{j != i} |J_ij|),
  // |e| <= E = |w| (exp(mu h) - 1) / mu <= |w| h exp(max(mu, 0) h), and per component
  // |e_i| <= h (w_i + max(sup J_ii, 0) E + sum_{j != i} |J_ij| E).
  const auto jac = tape_.Jacobian(apriori, inputs_);
  double mu = -kInf;
  for (std::size_t i = 0; i < n; ++i) {
    double s = jac[i][i].hi;
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) s = AddUp(s, jac[i][j].MagnitudeUp());
    }
    mu = std::max(mu, s);
  }
  const double E = MulUp(MulUp(w_max, h), ExpUp(MulUp(std::max(mu, 0.0), h)));
  for (std::size_t i = 0; i < n; ++i) {
    double s = AddUp(w[i], MulUp(std::max(jac[i][i].hi, 0.0), E));
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) s = AddUp(s, MulUp(jac[i][j].MagnitudeUp(), E));
    }
    d[i] = MulUp(h, s);
  }
  return d;
}

void FlowpipeStep::Reduce(std::vector<AffineForm>& x) const {
  std::size_t m = 0;
  for (const AffineForm& f : x) m = std::max(m, f.coefficients().size());
  const std::size_t n = x.size();
  const auto limit = static_cast<std::size_t>(std::max(max_symbols_, static_cast<int>(2 * n)));
  if (m + n <= limit) return;
  // Keep the protected symbols and the largest others (by their column's 1-norm); box the rest.
  std::vector<double> score(m, 0.0);
  for (const AffineForm& f : x) {
    for (std::size_t s = 0; s < f.coefficients().size(); ++s)
      score[s] += std::fabs(f.coefficients()[s]);
  }
  std::vector<std::size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return score[a] > score[b]; });
  std::vector<int> new_index(m, -1);
  std::size_t kept = 0;
  for (std::size_t s = 0; s < m && s < protected_.size(); ++s) {
    if (protected_[s]) new_index[s] = static_cast<int>(s);
  }
  std::size_t next = protected_.size();
  const std::size_t room = limit - n;
  for (std::size_t s : order) {
    if (new_index[s] >= 0) continue;
    if (kept + protected_.size() >= room || score[s] == 0) continue;
    new_index[s] = static_cast<int>(next++);
    ++kept;
  }
  for (AffineForm& f : x) f.Reindex(new_index, next);
}

std::optional<StepResult> FlowpipeStep::Take(const std::vector<AffineForm>& x, double h,
                                             const std::vector<TightInterval>& known) const {
  std::vector<TightInterval> box = Ranges(x);
  for (std::size_t i = 0; i < known.size() && i < box.size(); ++i) {
    const TightInterval both{std::max(box[i].lo, known[i].lo), std::min(box[i].hi, known[i].hi)};
    if (both.lo <= both.hi) box[i] = both;
  }
  const std::optional<std::vector<TightInterval>> apriori = Apriori(box, h);
  if (!apriori) return std::nullopt;
  const std::size_t n = x.size();
  StepResult out;
  out.segment.h = h;
  out.segment.series = tape_.Series(x, input_centres_, order_);
  const std::vector<TightInterval> tail =
      tape_.Series(*apriori, input_centre_boxes_, order_ + 1)[static_cast<std::size_t>(order_) + 1];
  TightInterval hk1(1.0);  // h^{K+1}
  for (int k = 0; k <= order_; ++k) hk1 = hk1 * TightInterval(h);
  const std::vector<double> deviation = InputDeviation(*apriori, h);
  out.segment.remainder.resize(n);
  std::vector<TightInterval> end_remainder(n);
  for (std::size_t i = 0; i < n; ++i) {
    const TightInterval dev(-deviation[i], deviation[i]);
    out.segment.remainder[i] = TightInterval(0.0, hk1.hi) * tail[i] + dev;
    end_remainder[i] = hk1 * tail[i] + dev;
  }
  out.segment.ComputeBox(*apriori);
  // The set at h: sum_k h^k x_k + the remainder; the error terms become new symbols.
  out.end.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    AffineForm sum = out.segment.series[0][i];
    TightInterval hk(1.0);  // h^k (a point when h is a power of two)
    for (int k = 1; k <= order_; ++k) {
      hk = hk * TightInterval(h);
      const AffineForm& xk = out.segment.series[static_cast<std::size_t>(k)][i];
      sum = sum + (hk.lo == hk.hi ? xk.Scaled(hk.lo) : xk.Scaled(hk));
    }
    out.end[i] = sum.PlusInterval(end_remainder[i]);
  }
  Reduce(out.end);
  std::size_t m = 0;
  for (const AffineForm& f : out.end) m = std::max(m, f.coefficients().size());
  for (std::size_t i = 0; i < n; ++i) out.end[i].ErrorToSymbol(static_cast<int>(m + i));
  return out;
}

double FlowpipeStep::SuggestedStep(const std::vector<TightInterval>& box) const {
  std::vector<TightInterval> b = box;
  for (TightInterval& x : b) {
    if (!x.IsFinite()) x = TightInterval(0.0);
  }
  double L = 0.0;
  // |df/dx| at the box, from the Jacobian tape when there is one, else by the growth of f.
  const auto jac = tape_.Jacobian(b, inputs_);
  for (const auto& row : jac) {
    double s = 0.0;
    for (const TightInterval& v : row) s += v.MagnitudeUp();
    L = std::max(L, s);
  }
  double h = 0.5;
  while (h > 1.0 / 16384 && h * L > 0.2) h /= 2;
  return h;
}

}  // namespace hybrid::flowpipe_internal
