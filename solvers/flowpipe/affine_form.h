#pragma once

#include <cstddef>
#include <vector>

#include "solvers/flowpipe/tight_interval.h"

namespace hybrid::flowpipe_internal {

/// An affine form x = c + sum_i g_i e_i + [-err, err] over noise symbols e_i in [-1, 1]
/// (Stolfi and de Figueiredo's affine arithmetic), with sound rounding: every operation adds the
/// exact rounding errors of its coefficients (rounding.h) and the bound of its non-affine part to
/// `err`, an independent error term. A vector of forms over shared symbols is a zonotope plus a
/// box, so linear maps keep the correlations between variables (no wrapping effect).
///
/// The symbols are indexed 0..n-1; a form with fewer coefficients has zeros beyond them.
class AffineForm {
 public:
  AffineForm() = default;
  explicit AffineForm(double c) : center_(c) {}
  /// c + r e_symbol (a fresh symbol for an interval of radius r).
  static AffineForm Symbol(double c, int symbol, double r);
  /// The form of an interval with no symbol: mid +- radius as error.
  static AffineForm OfInterval(const TightInterval& x);

  double center() const { return center_; }
  double err() const { return err_; }
  const std::vector<double>& coefficients() const { return g_; }
  double coefficient(std::size_t i) const { return i < g_.size() ? g_[i] : 0.0; }
  /// Whether the form is a single number (no symbol, no error).
  bool IsPoint() const;

  /// sum |g_i| + err, rounded up.
  double RadiusUp() const;
  /// [c - radius, c + radius].
  TightInterval Range() const;

  AffineForm operator+(const AffineForm& b) const;
  AffineForm operator-(const AffineForm& b) const;
  AffineForm operator-() const;
  /// this * k for a number k.
  AffineForm Scaled(double k) const;
  /// this * k for an interval k: this * mid(k) + range(this) * (k - mid(k)).
  AffineForm Scaled(const TightInterval& k) const;
  /// The product: affine part c_a b + c_b a, the rest bounded into err.
  AffineForm operator*(const AffineForm& b) const;
  /// this * this, using that the square of the non-affine part lies in [0, R^2] (R its
  /// radius): half the error of the general product.
  AffineForm Square() const;
  /// this / b: this * (1/b) with 1/b taken as an interval over b's range (coarse; Entire when
  /// the range contains 0).
  AffineForm operator/(const AffineForm& b) const;
  /// this + [lo, hi] (an independent interval).
  AffineForm PlusInterval(const TightInterval& x) const;

  /// The form with symbol `symbol`'s coefficient set to 0.
  AffineForm WithoutSymbol(std::size_t symbol) const;
  /// The form with its error term set to 0 (its affine part).
  AffineForm WithoutError() const;

  /// Moves the coefficient of every symbol in `merge` (flags, true to merge) into err.
  void MergeSymbols(const std::vector<char>& merge);
  /// Keeps the symbols in `keep` (old index -> new index or -1 to merge into err).
  void Reindex(const std::vector<int>& new_index, std::size_t new_size);
  /// Turns err into a new symbol `symbol` (coefficient err) and sets err to 0.
  void ErrorToSymbol(int symbol);

 private:
  double center_ = 0.0;
  std::vector<double> g_;
  double err_ = 0.0;
};

}  // namespace hybrid::flowpipe_internal
