#include "solvers/reachability/convex_polyhedron.h"

#include <gmpxx.h>

#include <charconv>
#include <cmath>
#include <ppl.hh>
#include <stdexcept>
#include <string>

namespace hybrid {
namespace {

namespace ppl = Parma_Polyhedra_Library;

// PPL's initialisation (when libppl is loaded, before main) sets the FPU to round towards +inf
// for its floating-point abstractions. This library uses only its exact (integer coefficient)
// polyhedra and MIP problems, which do not depend on the rounding mode, while every other
// computation of the process (parsing numbers, integration) needs round-to-nearest: restored
// here, at static initialisation, before any thread is made (threads inherit it).
[[maybe_unused]] const bool kRoundingRestored = [] {
  ppl::restore_pre_PPL_rounding();
  return true;
}();

// The rational written by the shortest decimal that reads back as `value` (finite).
mpq_class ToRational(double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("a coefficient is not finite");
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (ec != std::errc()) throw std::invalid_argument("a coefficient cannot be written");
  const std::string text(buffer, end);
  const size_t e = text.find('e');
  std::string mantissa = text.substr(0, e);
  long exponent = e == std::string::npos ? 0 : std::stol(text.substr(e + 1));
  if (const size_t dot = mantissa.find('.'); dot != std::string::npos) {
    exponent -= static_cast<long>(mantissa.size() - dot - 1);
    mantissa.erase(dot, 1);
  }
  mpq_class q(mpz_class(mantissa, 10));
  mpz_class scale;
  mpz_ui_pow_ui(scale.get_mpz_t(), 10, static_cast<unsigned long>(std::labs(exponent)));
  if (exponent >= 0) {
    q *= scale;
  } else {
    q /= scale;
  }
  q.canonicalize();
  return q;
}

// sum a[i] x_i + b with integer coefficients: the rational one times the positive lcm of its
// denominators (so the sign, hence the relation, is kept).
ppl::Linear_Expression IntegerForm(std::span<const double> a, double b) {
  std::vector<mpq_class> q;
  q.reserve(a.size() + 1);
  mpz_class lcm = 1;
  for (const double v : a) q.push_back(ToRational(v));
  q.push_back(ToRational(b));
  for (const mpq_class& x : q) mpz_lcm(lcm.get_mpz_t(), lcm.get_mpz_t(), x.get_den_mpz_t());
  ppl::Linear_Expression e;
  for (size_t i = 0; i + 1 < q.size(); ++i) {
    const mpz_class c = q[i].get_num() * (lcm / q[i].get_den());
    if (c != 0)
      e += ppl::Coefficient(c.get_mpz_t()) * ppl::Variable(static_cast<ppl::dimension_type>(i));
  }
  const mpz_class c = q.back().get_num() * (lcm / q.back().get_den());
  e += ppl::Coefficient(c.get_mpz_t());
  return e;
}

ppl::Constraint ToPpl(const LinearConstraint& c, bool closed) {
  const ppl::Linear_Expression e = IntegerForm(c.a, c.b);
  switch (c.kind) {
    case LinearConstraint::Kind::kLess:
      if (!closed) return e < 0;
      [[fallthrough]];
    case LinearConstraint::Kind::kLessEqual:
      return e <= 0;
    case LinearConstraint::Kind::kEqual:
      break;
  }
  return e == 0;
}

double ToDouble(const ppl::Coefficient& numerator, const ppl::Coefficient& denominator) {
  mpz_class n, d;
  ppl::assign_r(n, numerator, ppl::ROUND_NOT_NEEDED);
  ppl::assign_r(d, denominator, ppl::ROUND_NOT_NEEDED);
  return mpq_class(n, d).get_d();
}

}  // namespace

struct ConvexPolyhedron::Impl {
  ppl::NNC_Polyhedron p;
};

ConvexPolyhedron::ConvexPolyhedron(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ConvexPolyhedron ConvexPolyhedron::Universe(int dims) {
  if (dims < 0) throw std::invalid_argument("negative dimension");
  return ConvexPolyhedron(std::make_unique<Impl>(
      Impl{ppl::NNC_Polyhedron(static_cast<ppl::dimension_type>(dims), ppl::UNIVERSE)}));
}

ConvexPolyhedron ConvexPolyhedron::Empty(int dims) {
  if (dims < 0) throw std::invalid_argument("negative dimension");
  return ConvexPolyhedron(std::make_unique<Impl>(
      Impl{ppl::NNC_Polyhedron(static_cast<ppl::dimension_type>(dims), ppl::EMPTY)}));
}

ConvexPolyhedron::ConvexPolyhedron(const ConvexPolyhedron& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
ConvexPolyhedron& ConvexPolyhedron::operator=(const ConvexPolyhedron& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
ConvexPolyhedron::ConvexPolyhedron(ConvexPolyhedron&&) noexcept = default;
ConvexPolyhedron& ConvexPolyhedron::operator=(ConvexPolyhedron&&) noexcept = default;
ConvexPolyhedron::~ConvexPolyhedron() = default;

int ConvexPolyhedron::dims() const { return static_cast<int>(impl_->p.space_dimension()); }

void ConvexPolyhedron::AddConstraint(const LinearConstraint& c) {
  if (static_cast<int>(c.a.size()) != dims()) {
    throw std::invalid_argument("a constraint over " + std::to_string(c.a.size()) +
                                " dimensions added to a polyhedron of " + std::to_string(dims()));
  }
  impl_->p.add_constraint(ToPpl(c, false));
}

void ConvexPolyhedron::Intersect(const ConvexPolyhedron& other) {
  impl_->p.intersection_assign(other.impl_->p);
}

bool ConvexPolyhedron::IsEmpty() const { return impl_->p.is_empty(); }

bool ConvexPolyhedron::Contains(const ConvexPolyhedron& other) const {
  return impl_->p.contains(other.impl_->p);
}

bool ConvexPolyhedron::Intersects(const ConvexPolyhedron& other) const {
  return !impl_->p.is_disjoint_from(other.impl_->p);
}

void ConvexPolyhedron::TimeElapse(const ConvexPolyhedron& rates) {
  impl_->p.time_elapse_assign(rates.impl_->p);
}

void ConvexPolyhedron::Assign(std::span<const std::pair<int, AffineMap>> maps) {
  if (maps.empty()) return;
  if (maps.size() == 1) {
    const auto& [d, f] = maps.front();
    // x_d := (integer form) / lcm: PPL takes the denominator separately; IntegerForm scales by
    // a positive lcm, recovered from the rational coefficients.
    std::vector<mpq_class> q;
    mpz_class lcm = 1;
    for (const double v : f.a) q.push_back(ToRational(v));
    q.push_back(ToRational(f.b));
    for (const mpq_class& x : q) mpz_lcm(lcm.get_mpz_t(), lcm.get_mpz_t(), x.get_den_mpz_t());
    impl_->p.affine_image(ppl::Variable(static_cast<ppl::dimension_type>(d)), IntegerForm(f.a, f.b),
                          ppl::Coefficient(lcm.get_mpz_t()));
    return;
  }
  // Simultaneous: y_j = f_j(x) in fresh dimensions, then x_{d_j} := y_j, then drop the y_j.
  const int n = dims();
  const int k = static_cast<int>(maps.size());
  impl_->p.add_space_dimensions_and_embed(static_cast<ppl::dimension_type>(k));
  for (int j = 0; j < k; ++j) {
    std::vector<double> a = maps[j].second.a;
    a.resize(static_cast<size_t>(n + k), 0.0);
    a[static_cast<size_t>(n + j)] = -1.0;
    impl_->p.add_constraint(ToPpl({a, maps[j].second.b, LinearConstraint::Kind::kEqual}, false));
  }
  for (int j = 0; j < k; ++j) {
    const ppl::Variable x(static_cast<ppl::dimension_type>(maps[j].first));
    impl_->p.unconstrain(x);
    impl_->p.add_constraint(x == ppl::Variable(static_cast<ppl::dimension_type>(n + j)));
  }
  impl_->p.remove_higher_space_dimensions(static_cast<ppl::dimension_type>(n));
}

void ConvexPolyhedron::Unconstrain(int d) {
  impl_->p.unconstrain(ppl::Variable(static_cast<ppl::dimension_type>(d)));
}

void ConvexPolyhedron::AddDimensions(int count) {
  impl_->p.add_space_dimensions_and_embed(static_cast<ppl::dimension_type>(count));
}

void ConvexPolyhedron::KeepDimensions(int dims) {
  impl_->p.remove_higher_space_dimensions(static_cast<ppl::dimension_type>(dims));
}

void ConvexPolyhedron::Hull(const ConvexPolyhedron& other) {
  impl_->p.poly_hull_assign(other.impl_->p);
}

void ConvexPolyhedron::Widen(const ConvexPolyhedron& previous) {
  impl_->p.H79_widening_assign(previous.impl_->p);
}

std::vector<LinearConstraint> ConvexPolyhedron::Constraints() const {
  std::vector<LinearConstraint> out;
  for (const ppl::Constraint& c : impl_->p.minimized_constraints()) {
    LinearConstraint lc;
    // PPL writes e >= 0 / e > 0 / e == 0; ours is -e <= 0 / -e < 0 / e == 0.
    const double sign = c.is_equality() ? 1.0 : -1.0;
    for (int i = 0; i < dims(); ++i) {
      lc.a.push_back(
          sign * ToDouble(c.coefficient(ppl::Variable(static_cast<ppl::dimension_type>(i))), 1));
    }
    lc.b = sign * ToDouble(c.inhomogeneous_term(), 1);
    lc.kind = c.is_equality()            ? LinearConstraint::Kind::kEqual
              : c.is_strict_inequality() ? LinearConstraint::Kind::kLess
                                         : LinearConstraint::Kind::kLessEqual;
    out.push_back(std::move(lc));
  }
  return out;
}

int ConvexPolyhedron::NumConstraints() const {
  int count = 0;
  for (auto it = impl_->p.minimized_constraints().begin();
       it != impl_->p.minimized_constraints().end(); ++it) {
    ++count;
  }
  return count;
}

std::optional<std::vector<double>> MaximizeLinear(int dims,
                                                  std::span<const LinearConstraint> constraints,
                                                  std::span<const double> objective) {
  ppl::Constraint_System cs;
  for (const LinearConstraint& c : constraints) cs.insert(ToPpl(c, true));
  ppl::MIP_Problem mip(static_cast<ppl::dimension_type>(dims));
  mip.add_constraints(cs);
  mip.set_objective_function(IntegerForm(objective, 0.0));
  mip.set_optimization_mode(ppl::MAXIMIZATION);
  const ppl::MIP_Problem_Status status = mip.solve();
  if (status == ppl::UNFEASIBLE_MIP_PROBLEM) return std::nullopt;
  const ppl::Generator& g =
      status == ppl::OPTIMIZED_MIP_PROBLEM ? mip.optimizing_point() : mip.feasible_point();
  std::vector<double> x(static_cast<size_t>(dims));
  for (int i = 0; i < dims; ++i) {
    x[static_cast<size_t>(i)] =
        ToDouble(g.coefficient(ppl::Variable(static_cast<ppl::dimension_type>(i))), g.divisor());
  }
  return x;
}

}  // namespace hybrid
