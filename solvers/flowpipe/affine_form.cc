#include "solvers/flowpipe/affine_form.h"

#include <algorithm>
#include <cmath>

namespace hybrid::flowpipe_internal {
namespace {

// Adds |e| to err, rounding up (inf stays inf).
void AddError(double& err, double e) { err = AddUp(err, std::fabs(e)); }

// The exact error of the product p = fl(a b), or a bound of it near underflow.
double ProductError(double a, double b, double p) {
  if (a == 0 || b == 0) return 0.0;
  if (!std::isfinite(p)) return kInf;
  if (std::fabs(p) < kTiny) return 1e-300;
  return std::fma(a, b, -p);
}

// The exact error of s = fl(a + b) (inf when the sum overflowed).
double AdditionError(double a, double b, double s) {
  if (!std::isfinite(s)) return kInf;
  return SumError(a, b, s);
}

}  // namespace

AffineForm AffineForm::Symbol(double c, int symbol, double r) {
  AffineForm f(c);
  f.g_.assign(static_cast<std::size_t>(symbol) + 1, 0.0);
  f.g_[static_cast<std::size_t>(symbol)] = r;
  return f;
}

AffineForm AffineForm::OfInterval(const TightInterval& x) {
  if (!x.IsFinite()) {
    AffineForm f(0.0);
    f.err_ = kInf;
    return f;
  }
  AffineForm f(x.Mid());
  f.err_ = x.RadiusUp();
  return f;
}

bool AffineForm::IsPoint() const {
  return err_ == 0 && std::all_of(g_.begin(), g_.end(), [](double g) { return g == 0; });
}

double AffineForm::RadiusUp() const {
  double r = err_;
  for (double g : g_) r += std::fabs(g);
  return SumUp(r, g_.size() + 1);
}

TightInterval AffineForm::Range() const {
  const double r = RadiusUp();
  if (!std::isfinite(r) || !std::isfinite(center_)) return TightInterval::Entire();
  return {SubDown(center_, r), AddUp(center_, r)};
}

AffineForm AffineForm::operator+(const AffineForm& b) const {
  AffineForm z;
  z.center_ = center_ + b.center_;
  z.err_ = AddUp(err_, b.err_);
  AddError(z.err_, AdditionError(center_, b.center_, z.center_));
  z.g_.resize(std::max(g_.size(), b.g_.size()), 0.0);
  for (std::size_t i = 0; i < z.g_.size(); ++i) {
    const double x = coefficient(i), y = b.coefficient(i);
    z.g_[i] = x + y;
    AddError(z.err_, AdditionError(x, y, z.g_[i]));
  }
  return z;
}

AffineForm AffineForm::operator-() const {
  AffineForm z = *this;
  z.center_ = -z.center_;
  for (double& g : z.g_) g = -g;
  return z;
}

AffineForm AffineForm::operator-(const AffineForm& b) const { return *this + (-b); }

AffineForm AffineForm::Scaled(double k) const {
  AffineForm z;
  z.center_ = center_ * k;
  z.err_ = MulUp(err_, std::fabs(k));
  AddError(z.err_, ProductError(center_, k, z.center_));
  z.g_.resize(g_.size());
  for (std::size_t i = 0; i < g_.size(); ++i) {
    z.g_[i] = g_[i] * k;
    AddError(z.err_, ProductError(g_[i], k, z.g_[i]));
  }
  return z;
}

AffineForm AffineForm::Scaled(const TightInterval& k) const {
  if (!k.IsFinite()) return OfInterval(TightInterval::Entire());
  AffineForm z = Scaled(k.Mid());
  const double r = k.RadiusUp();
  if (r > 0) z.err_ = AddUp(z.err_, MulUp(Range().MagnitudeUp(), r));
  return z;
}

AffineForm AffineForm::operator*(const AffineForm& b) const {
  AffineForm z;
  z.center_ = center_ * b.center_;
  AddError(z.err_, ProductError(center_, b.center_, z.center_));
  z.g_.resize(std::max(g_.size(), b.g_.size()), 0.0);
  for (std::size_t i = 0; i < z.g_.size(); ++i) {
    const double p1 = center_ * b.coefficient(i), p2 = b.center_ * coefficient(i);
    AddError(z.err_, ProductError(center_, b.coefficient(i), p1));
    AddError(z.err_, ProductError(b.center_, coefficient(i), p2));
    z.g_[i] = p1 + p2;
    AddError(z.err_, AdditionError(p1, p2, z.g_[i]));
  }
  z.err_ = AddUp(z.err_, MulUp(std::fabs(center_), b.err_));
  z.err_ = AddUp(z.err_, MulUp(std::fabs(b.center_), err_));
  const double ra = RadiusUp(), rb = b.RadiusUp();
  if (ra != 0 && rb != 0) z.err_ = AddUp(z.err_, MulUp(ra, rb));
  return z;
}

AffineForm AffineForm::Square() const {
  // (c + X)^2 = c^2 + 2 c X + X^2 with X^2 in [0, R^2]: the affine part c^2 + 2 c g e, plus
  // R^2 / 2 on the centre and +- R^2 / 2 as error (|2 c| err is in 2 c X's error).
  AffineForm z = Scaled(2.0 * center_);  // 2 c (c + X)
  z.center_ = 0.0;
  AffineForm c2(center_ * center_);
  AddError(c2.err_, ProductError(center_, center_, c2.center_));
  z = z + c2;  // c^2 + 2 c X (2 c is exact)
  const double r = RadiusUp();
  if (r != 0) {
    const double half = MulUp(MulUp(r, r), 0.5);
    const double shifted = z.center_ + half;
    AddError(z.err_, AdditionError(z.center_, half, shifted));
    z.center_ = shifted;
    z.err_ = AddUp(z.err_, half);
  }
  return z;
}

AffineForm AffineForm::operator/(const AffineForm& b) const {
  if (b.IsPoint()) {
    const TightInterval inv = TightInterval(1.0) / TightInterval(b.center_);
    return Scaled(inv);
  }
  return *this * OfInterval(TightInterval(1.0) / b.Range());
}

AffineForm AffineForm::PlusInterval(const TightInterval& x) const { return *this + OfInterval(x); }

AffineForm AffineForm::WithoutSymbol(std::size_t symbol) const {
  AffineForm f = *this;
  if (symbol < f.g_.size()) f.g_[symbol] = 0.0;
  return f;
}

AffineForm AffineForm::WithoutError() const {
  AffineForm f = *this;
  f.err_ = 0.0;
  return f;
}

void AffineForm::MergeSymbols(const std::vector<char>& merge) {
  for (std::size_t i = 0; i < g_.size() && i < merge.size(); ++i) {
    if (merge[i] && g_[i] != 0) {
      err_ = AddUp(err_, std::fabs(g_[i]));
      g_[i] = 0.0;
    }
  }
}

void AffineForm::Reindex(const std::vector<int>& new_index, std::size_t new_size) {
  std::vector<double> g(new_size, 0.0);
  for (std::size_t i = 0; i < g_.size(); ++i) {
    const int j = i < new_index.size() ? new_index[i] : -1;
    if (j >= 0) {
      g[static_cast<std::size_t>(j)] = g_[i];
    } else if (g_[i] != 0) {
      err_ = AddUp(err_, std::fabs(g_[i]));
    }
  }
  g_ = std::move(g);
}

void AffineForm::ErrorToSymbol(int symbol) {
  if (err_ == 0) return;
  if (g_.size() <= static_cast<std::size_t>(symbol))
    g_.resize(static_cast<std::size_t>(symbol) + 1, 0.0);
  g_[static_cast<std::size_t>(symbol)] = err_;
  err_ = 0.0;
}

}  // namespace hybrid::flowpipe_internal
