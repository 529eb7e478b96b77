#include "solvers/reachability/convex_polyhedron.h"

#include <gmpxx.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <ppl.hh>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

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

// The double nearest to `q` (ties to even). GMP's get_d truncates towards zero, so the rational
// ToRational(1.8) = 9/5 would come back as 1.7999999999999998: a trace would then start 1 ulp
// outside an initial point (`out = 1.8`) and take a guard `out < 1.8` the model never takes.
double NearestDouble(const mpq_class& q) {
  const double truncated = q.get_d();
  if (!std::isfinite(truncated) || mpq_class(truncated) == q) return truncated;
  const double away = std::nextafter(truncated, sgn(q) > 0 ? INFINITY : -INFINITY);
  if (!std::isfinite(away)) return truncated;
  const mpq_class below = abs(q - mpq_class(truncated));
  const mpq_class above = abs(mpq_class(away) - q);
  if (below != above) return below < above ? truncated : away;
  std::uint64_t bits = 0;
  std::memcpy(&bits, &truncated, sizeof bits);
  return (bits & 1u) == 0 ? truncated : away;
}

// The rational written by the shortest decimal that reads back as `value` (finite).
mpq_class ToRational(double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("a coefficient is not finite");
  if (value == std::trunc(value) && std::fabs(value) < 1e15) {
    return mpq_class(static_cast<long>(value));  // an integer (the common case), exactly
  }
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
// denominators (so the sign, hence the relation, is kept), and that lcm.
std::pair<ppl::Linear_Expression, mpz_class> ScaledForm(std::span<const double> a, double b) {
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
  return {std::move(e), std::move(lcm)};
}

ppl::Linear_Expression IntegerForm(std::span<const double> a, double b) {
  return ScaledForm(a, b).first;
}

mpz_class ToInteger(const ppl::Coefficient& c) {
  mpz_class z;
  ppl::assign_r(z, c, ppl::ROUND_NOT_NEEDED);
  return z;
}

// The coordinates of point (or closure point) g.
std::vector<mpq_class> Coordinates(const ppl::Generator& g) {
  const mpz_class divisor = ToInteger(g.divisor());
  std::vector<mpq_class> x(g.space_dimension());
  for (ppl::dimension_type i = 0; i < g.space_dimension(); ++i) {
    x[i] = mpq_class(ToInteger(g.coefficient(ppl::Variable(i))), divisor);
    x[i].canonicalize();
  }
  return x;
}

// The point generator of x.
ppl::Generator PointOf(const std::vector<mpq_class>& x) {
  mpz_class lcm = 1;
  for (const mpq_class& v : x) mpz_lcm(lcm.get_mpz_t(), lcm.get_mpz_t(), v.get_den_mpz_t());
  ppl::Linear_Expression e;
  for (size_t i = 0; i < x.size(); ++i) {
    const mpz_class c = x[i].get_num() * (lcm / x[i].get_den());
    if (c != 0) {
      e += ppl::Coefficient(c.get_mpz_t()) * ppl::Variable(static_cast<ppl::dimension_type>(i));
    }
  }
  e.set_space_dimension(x.size());  // trailing zero coordinates count too
  return ppl::point(e, ppl::Coefficient(lcm.get_mpz_t()));
}

// A permutation of the dimensions for NNC_Polyhedron::map_space_dimensions.
struct Permutation {
  std::vector<ppl::dimension_type> to;
  bool has_empty_codomain() const { return to.empty(); }
  ppl::dimension_type max_in_codomain() const { return to.size() - 1; }
  bool maps(ppl::dimension_type i, ppl::dimension_type& j) const {
    j = to[i];
    return true;
  }
};

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
  return NearestDouble(mpq_class(ToInteger(numerator), ToInteger(denominator)));
}

}  // namespace

// PPL's polyhedron: closed (C_Polyhedron) as long as every constraint it was given is non-strict,
// else not necessarily closed (NNC_Polyhedron, converted exactly on the first strict constraint
// or on meeting an NNC one). A closed polyhedron needs no epsilon dimension, so its operations
// cost less (30 to 40% of reachability's time on the bundled benchmarks, whose explorations are
// closed: invariants and guards are read in their closure; only bad states may be strict).
struct ConvexPolyhedron::Impl {
  std::variant<ppl::C_Polyhedron, ppl::NNC_Polyhedron> p;

  bool closed() const { return p.index() == 0; }
  ppl::C_Polyhedron& c() { return std::get<0>(p); }
  const ppl::C_Polyhedron& c() const { return std::get<0>(p); }
  // The polyhedron as an NNC one from now on.
  ppl::NNC_Polyhedron& Nnc() {
    if (closed()) p = ppl::NNC_Polyhedron(c());
    return std::get<1>(p);
  }
  // Calls f on the polyhedron, whichever kind it is.
  template <class F>
  decltype(auto) Visit(F&& f) {
    return std::visit(std::forward<F>(f), p);
  }
  template <class F>
  decltype(auto) Visit(F&& f) const {
    return std::visit(std::forward<F>(f), p);
  }

  // Calls f(x, y) on the polyhedra of `a` and `b` as one kind: closed if both are, else NNC (`a`
  // made NNC for good, a closed `b` converted for the call).
  template <class F>
  static decltype(auto) Both(Impl& a, const Impl& b, F&& f) {
    if (a.closed() && b.closed()) return f(a.c(), b.c());
    ppl::NNC_Polyhedron& x = a.Nnc();
    if (!b.closed()) return f(x, std::get<1>(b.p));
    const ppl::NNC_Polyhedron y(b.c());
    return f(x, y);
  }

  // The same for reading only: closed ones converted for the call.
  template <class F>
  static decltype(auto) Both(const Impl& a, const Impl& b, F&& f) {
    if (a.closed() && b.closed()) return f(a.c(), b.c());
    std::optional<ppl::NNC_Polyhedron> ca, cb;
    if (a.closed()) ca.emplace(a.c());
    if (b.closed()) cb.emplace(b.c());
    return f(ca ? *ca : std::get<1>(a.p), cb ? *cb : std::get<1>(b.p));
  }

  // The minimized generators and constraints of either kind (a closed polyhedron has no closure
  // points and no strict inequalities).
  const ppl::Generator_System& Generators() const {
    return Visit(
        [](const auto& q) -> const ppl::Generator_System& { return q.minimized_generators(); });
  }
  const ppl::Constraint_System& Constraints() const {
    return Visit(
        [](const auto& q) -> const ppl::Constraint_System& { return q.minimized_constraints(); });
  }
};

ConvexPolyhedron::ConvexPolyhedron(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ConvexPolyhedron ConvexPolyhedron::Universe(int dims) {
  if (dims < 0) throw std::invalid_argument("negative dimension");
  return ConvexPolyhedron(std::make_unique<Impl>(
      Impl{ppl::C_Polyhedron(static_cast<ppl::dimension_type>(dims), ppl::UNIVERSE)}));
}

ConvexPolyhedron ConvexPolyhedron::Empty(int dims) {
  if (dims < 0) throw std::invalid_argument("negative dimension");
  return ConvexPolyhedron(std::make_unique<Impl>(
      Impl{ppl::C_Polyhedron(static_cast<ppl::dimension_type>(dims), ppl::EMPTY)}));
}

ConvexPolyhedron ConvexPolyhedron::Point(std::span<const double> x) {
  std::vector<mpq_class> q;
  q.reserve(x.size());
  for (const double v : x) q.push_back(ToRational(v));
  return ConvexPolyhedron(
      std::make_unique<Impl>(Impl{ppl::C_Polyhedron(ppl::Generator_System(PointOf(q)))}));
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

int ConvexPolyhedron::dims() const {
  return static_cast<int>(impl_->Visit([](const auto& q) { return q.space_dimension(); }));
}

void ConvexPolyhedron::AddConstraint(const LinearConstraint& c) {
  if (static_cast<int>(c.a.size()) != dims()) {
    throw std::invalid_argument("a constraint over " + std::to_string(c.a.size()) +
                                " dimensions added to a polyhedron of " + std::to_string(dims()));
  }
  if (c.kind == LinearConstraint::Kind::kLess) {
    impl_->Nnc().add_constraint(ToPpl(c, false));
    return;
  }
  impl_->Visit([&](auto& q) { q.add_constraint(ToPpl(c, false)); });
}

void ConvexPolyhedron::Intersect(const ConvexPolyhedron& other) {
  Impl::Both(*impl_, *other.impl_, [](auto& x, const auto& y) { x.intersection_assign(y); });
}

bool ConvexPolyhedron::IsEmpty() const {
  return impl_->Visit([](const auto& q) { return q.is_empty(); });
}

bool ConvexPolyhedron::Contains(const ConvexPolyhedron& other) const {
  const Impl& self = *impl_;
  return Impl::Both(self, *other.impl_, [](const auto& x, const auto& y) { return x.contains(y); });
}

namespace {

// How closed polyhedron x lies with respect to one constraint: disjoint from its set, included
// in it, or neither (PPL's Poly_Con_Relation, the two parts used here).
enum class Relation { kDisjoint, kIncluded, kOther };

Relation Relate(const ppl::C_Polyhedron& x, const ppl::Constraint& c) {
  const ppl::Poly_Con_Relation r = x.relation_with(c);
  if (r.implies(ppl::Poly_Con_Relation::is_disjoint())) return Relation::kDisjoint;
  if (r.implies(ppl::Poly_Con_Relation::is_included())) return Relation::kIncluded;
  return Relation::kOther;
}

// Whether closed, non-empty x meets the set of `constraints`, each related to x by `relate`:
// one that x lies outside of settles it (disjoint); those that x lies inside of drop out; if at
// most one is left, x meets the set (x meets that constraint's set, and lies in the others');
// else nullopt (undecided).
template <class Relate>
std::optional<bool> MeetsByRelations(const ppl::Constraint_System& constraints, Relate&& relate) {
  int left = 0;
  for (const ppl::Constraint& c : constraints) {
    const Relation r = relate(c);
    if (r == Relation::kDisjoint) return false;
    if (r != Relation::kIncluded) ++left;
  }
  if (left <= 1) return true;
  return std::nullopt;
}

// Integers below 2^58 in magnitude: a scalar product of two rows of at most 1024 of them is
// below 2^126, exact in 128 bits.
constexpr int kSmallBits = 58;
__extension__ typedef __int128 Int128;  // GCC's and Clang's, on the 64-bit targets built for
constexpr std::size_t kMaxSmallRow = 1024;

bool Small(const mpz_class& z, std::int64_t* out) {
  if (mpz_sizeinbase(z.get_mpz_t(), 2) > static_cast<std::size_t>(kSmallBits)) return false;
  *out = z.get_si();
  return true;
}

// Whether generator g's n coefficients (and divisor, for a point) are all below 2^kSmallBits.
bool SmallRow(const ppl::Generator& g, size_t n) {
  std::int64_t v = 0;
  if ((g.is_point() || g.is_closure_point()) && !Small(g.divisor(), &v)) return false;
  for (size_t i = 0; i < n; ++i) {
    if (!Small(g.coefficient(ppl::Variable(i)), &v)) return false;
  }
  return true;
}

int Compare(Int128 a, Int128 b) { return (a > b) - (a < b); }
int Compare(const mpz_class& a, const mpz_class& b) {
  const int c = cmp(a, b);
  return (c > 0) - (c < 0);
}
mpz_class ToMpz(Int128 v) {  // |v| < 2^58 here
  return mpz_class(static_cast<long>(v));
}
mpz_class ToMpz(const mpz_class& v) { return v; }

// A closed polyhedron's generators as machine integers, every coefficient and divisor small
// (Small): per generator its kind, its divisor (points) and its dims() coefficients.
struct SmallGenerators {
  enum class Kind { kPoint, kRay, kLine };
  std::size_t dims = 0;
  std::vector<Kind> kinds;
  std::vector<std::int64_t> divisors;
  std::vector<std::int64_t> coefficients;  // row-major, dims per generator
};

std::optional<SmallGenerators> SmallGeneratorsOf(const ppl::C_Polyhedron& x) {
  SmallGenerators g;
  g.dims = x.space_dimension();
  if (g.dims + 1 > kMaxSmallRow) return std::nullopt;
  for (const ppl::Generator& gen : x.generators()) {
    std::int64_t divisor = 0;
    if (gen.is_point()) {
      if (!Small(gen.divisor(), &divisor)) return std::nullopt;
      g.kinds.push_back(SmallGenerators::Kind::kPoint);
    } else {
      g.kinds.push_back(gen.is_ray() ? SmallGenerators::Kind::kRay : SmallGenerators::Kind::kLine);
    }
    g.divisors.push_back(divisor);
    for (ppl::dimension_type i = 0; i < g.dims; ++i) {
      std::int64_t v = 0;
      if (!Small(gen.coefficient(ppl::Variable(i)), &v)) return std::nullopt;
      g.coefficients.push_back(v);
    }
  }
  return g;
}

// Relate(x, c) from x's small generators `g` (nullopt where c's coefficients are not small). For
// c's form f (c is f >= 0, f > 0 or f = 0): f(p) at each point p has the sign of
// f's integer form times p's divisor; along a line f is constant or takes every value (then
// neither relation holds); its infimum over x is its least value at a point unless it decreases
// along some ray (then minus infinity), its supremum likewise. x lies in c's set iff the
// infimum satisfies c (attained at a point, so strictly for f > 0); x misses it iff the
// supremum fails f >= 0 or f > 0 (for f = 0: the supremum is negative or the infimum positive).
std::optional<Relation> RelateSmall(const SmallGenerators& g, const ppl::Constraint& c) {
  std::int64_t b = 0;
  if (!Small(c.inhomogeneous_term(), &b)) return std::nullopt;
  std::vector<std::int64_t> a(g.dims, 0);
  for (ppl::dimension_type i = 0; i < c.space_dimension(); ++i) {
    if (!Small(c.coefficient(ppl::Variable(i)), &a[i])) return std::nullopt;
  }
  // Over the points: every f(p) >= 0, > 0, <= 0, < 0; over the rays: f never decreasing, never
  // increasing.
  bool p_ge = true, p_gt = true, p_le = true, p_lt = true, r_ge = true, r_le = true;
  for (std::size_t k = 0; k < g.kinds.size(); ++k) {
    Int128 s = 0;
    const std::int64_t* row = &g.coefficients[k * g.dims];
    for (std::size_t i = 0; i < g.dims; ++i) s += static_cast<Int128>(a[i]) * row[i];
    const int sign = (s > 0) - (s < 0);
    switch (g.kinds[k]) {
      case SmallGenerators::Kind::kLine:
        if (sign != 0) return Relation::kOther;
        break;
      case SmallGenerators::Kind::kRay:
        r_ge = r_ge && sign >= 0;
        r_le = r_le && sign <= 0;
        break;
      case SmallGenerators::Kind::kPoint: {
        s += static_cast<Int128>(b) * g.divisors[k];
        const int at = (s > 0) - (s < 0);
        p_ge = p_ge && at >= 0;
        p_gt = p_gt && at > 0;
        p_le = p_le && at <= 0;
        p_lt = p_lt && at < 0;
        break;
      }
    }
  }
  bool included = false, disjoint = false;
  switch (c.type()) {
    case ppl::Constraint::NONSTRICT_INEQUALITY:
      included = p_ge && r_ge;
      disjoint = p_lt && r_le;
      break;
    case ppl::Constraint::STRICT_INEQUALITY:
      included = p_gt && r_ge;
      disjoint = p_le && r_le;
      break;
    case ppl::Constraint::EQUALITY:
      included = p_ge && p_le && r_ge && r_le;
      disjoint = (p_lt && r_le) || (p_gt && r_ge);
      break;
  }
  if (disjoint) return Relation::kDisjoint;
  if (included) return Relation::kIncluded;
  return Relation::kOther;
}

}  // namespace

bool ConvexPolyhedron::Intersects(const ConvexPolyhedron& other) const {
  if (other.dims() != dims()) throw std::invalid_argument("polyhedra of different dimensions");
  // With a closed one, x: each constraint of the other against the generators of x (PPL's
  // relation test, exact, with no intersection to convert and no not-necessarily-closed copy
  // of x; MeetsByRelations). A property's bad part is usually one half-space, its other bounds
  // kept by the state, so the intersection is seldom built.
  const Impl* closed = impl_.get();
  const Impl* rest = other.impl_.get();
  if (!closed->closed()) std::swap(closed, rest);
  if (closed->closed()) {
    const ppl::C_Polyhedron& x = closed->c();
    if (x.is_empty()) return false;
    const std::optional<bool> meets = MeetsByRelations(
        rest->Constraints(), [&x](const ppl::Constraint& c) { return Relate(x, c); });
    if (meets) return *meets;
  }
  return Impl::Both(*impl_, *other.impl_,
                    [](const auto& x, const auto& y) { return !x.is_disjoint_from(y); });
}

std::vector<bool> ConvexPolyhedron::IntersectsEach(
    std::span<const ConvexPolyhedron* const> others) const {
  std::vector<bool> meets;
  meets.reserve(others.size());
  std::optional<SmallGenerators> small;
  if (impl_->closed() && !impl_->c().is_empty()) small = SmallGeneratorsOf(impl_->c());
  for (const ConvexPolyhedron* other : others) {
    if (other->dims() != dims()) throw std::invalid_argument("polyhedra of different dimensions");
    if (!small) {
      meets.push_back(Intersects(*other));
      continue;
    }
    const ppl::C_Polyhedron& x = impl_->c();
    const std::optional<bool> decided =
        MeetsByRelations(other->impl_->Constraints(), [&](const ppl::Constraint& c) {
          const std::optional<Relation> r = RelateSmall(*small, c);
          return r ? *r : Relate(x, c);
        });
    // Undecided: the intersection, this set kept closed for the others (a copy made NNC).
    meets.push_back(
        decided ? *decided
                : Impl::Both(std::as_const(*impl_), *other->impl_,
                             [](const auto& p, const auto& q) { return !p.is_disjoint_from(q); }));
  }
  return meets;
}

void ConvexPolyhedron::TimeElapse(const ConvexPolyhedron& rates) {
  Impl::Both(*impl_, *rates.impl_, [](auto& x, const auto& y) { x.time_elapse_assign(y); });
}

void ConvexPolyhedron::TimeElapseBackward(const ConvexPolyhedron& rates) {
  Impl negated = *rates.impl_;
  negated.Visit([](auto& q) {
    for (ppl::dimension_type i = 0; i < q.space_dimension(); ++i) {
      q.affine_image(ppl::Variable(i), -ppl::Variable(i));
    }
  });
  Impl::Both(*impl_, negated, [](auto& x, const auto& y) { x.time_elapse_assign(y); });
}

void ConvexPolyhedron::Assign(std::span<const std::pair<int, AffineMap>> maps) {
  if (maps.empty()) return;
  if (maps.size() == 1) {
    // x_d := (integer form) / lcm: PPL takes the denominator separately.
    const auto& [d, f] = maps.front();
    const auto [e, lcm] = ScaledForm(f.a, f.b);
    impl_->Visit([&](auto& q) {
      q.affine_image(ppl::Variable(static_cast<ppl::dimension_type>(d)), e,
                     ppl::Coefficient(lcm.get_mpz_t()));
    });
    return;
  }
  // Where no f_j reads a dimension another map writes (resets to constants, a clock shifted by
  // a parameter), the simultaneous assignment is the maps one after another: PPL's affine
  // images, without the fresh dimensions below.
  const auto reads_another = [&](std::size_t j) {
    for (std::size_t i = 0; i < maps.size(); ++i) {
      const int written = maps[i].first;
      if (i != j && written >= 0 && written < static_cast<int>(maps[j].second.a.size()) &&
          maps[j].second.a[static_cast<std::size_t>(written)] != 0.0) {
        return true;
      }
    }
    return false;
  };
  bool independent = true;
  for (std::size_t j = 0; j < maps.size() && independent; ++j) independent = !reads_another(j);
  if (independent) {
    for (const auto& map : maps) Assign(std::span<const std::pair<int, AffineMap>>(&map, 1));
    return;
  }
  // Simultaneous: y_j = f_j(x) in fresh dimensions, then x_{d_j} := y_j, then drop the y_j.
  const int n = dims();
  const int k = static_cast<int>(maps.size());
  impl_->Visit([&](auto& q) {
    q.add_space_dimensions_and_embed(static_cast<ppl::dimension_type>(k));
    for (int j = 0; j < k; ++j) {
      std::vector<double> a = maps[j].second.a;
      a.resize(static_cast<size_t>(n + k), 0.0);
      a[static_cast<size_t>(n + j)] = -1.0;
      q.add_constraint(ToPpl({a, maps[j].second.b, LinearConstraint::Kind::kEqual}, false));
    }
    for (int j = 0; j < k; ++j) {
      const ppl::Variable x(static_cast<ppl::dimension_type>(maps[j].first));
      q.unconstrain(x);
      q.add_constraint(x == ppl::Variable(static_cast<ppl::dimension_type>(n + j)));
    }
    q.remove_higher_space_dimensions(static_cast<ppl::dimension_type>(n));
  });
}

void ConvexPolyhedron::AssignPreimage(std::span<const std::pair<int, AffineMap>> maps) {
  if (maps.empty()) return;
  if (maps.size() == 1) {
    const auto& [d, f] = maps.front();
    const auto [e, lcm] = ScaledForm(f.a, f.b);
    impl_->Visit([&](auto& q) {
      q.affine_preimage(ppl::Variable(static_cast<ppl::dimension_type>(d)), e,
                        ppl::Coefficient(lcm.get_mpz_t()));
    });
    return;
  }
  // Simultaneous: fresh dimensions z_j take the place of x_{d_j} in this set (swapped in, the
  // x_{d_j} becoming free), then z_j = f_j(x) is imposed and the z_j projected away.
  const int n = dims();
  const int k = static_cast<int>(maps.size());
  Permutation swap;
  for (int i = 0; i < n + k; ++i) swap.to.push_back(static_cast<ppl::dimension_type>(i));
  for (int j = 0; j < k; ++j) {
    const int d = maps[j].first;
    if (d < 0 || d >= n || swap.to[static_cast<size_t>(d)] != static_cast<size_t>(d)) {
      throw std::invalid_argument("a simultaneous assignment writes a dimension twice");
    }
    std::swap(swap.to[static_cast<size_t>(d)], swap.to[static_cast<size_t>(n + j)]);
  }
  impl_->Visit([&](auto& q) {
    q.add_space_dimensions_and_embed(static_cast<ppl::dimension_type>(k));
    q.map_space_dimensions(swap);
    for (int j = 0; j < k; ++j) {
      std::vector<double> a = maps[j].second.a;
      a.resize(static_cast<size_t>(n + k), 0.0);
      a[static_cast<size_t>(n + j)] = -1.0;
      q.add_constraint(ToPpl({a, maps[j].second.b, LinearConstraint::Kind::kEqual}, false));
    }
    q.remove_higher_space_dimensions(static_cast<ppl::dimension_type>(n));
  });
}

void ConvexPolyhedron::Unconstrain(int d) {
  impl_->Visit([&](auto& q) { q.unconstrain(ppl::Variable(static_cast<ppl::dimension_type>(d))); });
}

void ConvexPolyhedron::AddDimensions(int count) {
  impl_->Visit(
      [&](auto& q) { q.add_space_dimensions_and_embed(static_cast<ppl::dimension_type>(count)); });
}

void ConvexPolyhedron::KeepDimensions(int dims) {
  impl_->Visit(
      [&](auto& q) { q.remove_higher_space_dimensions(static_cast<ppl::dimension_type>(dims)); });
}

ConvexPolyhedron ConvexPolyhedron::Embedded(int dims, std::span<const int> to) const {
  const auto n = static_cast<std::size_t>(this->dims());
  if (to.size() != n || dims < this->dims()) {
    throw std::invalid_argument("an embedding needs one target per dimension, within the space");
  }
  // Dimensions n .. dims-1 (added unconstrained) take the targets `to` leaves free, in order.
  std::vector<bool> taken(static_cast<std::size_t>(dims), false);
  Permutation permutation;
  std::vector<ppl::dimension_type>& perm = permutation.to;
  for (const int t : to) {
    if (t < 0 || t >= dims || taken[static_cast<std::size_t>(t)]) {
      throw std::invalid_argument("an embedding needs distinct targets within the space");
    }
    taken[static_cast<std::size_t>(t)] = true;
    perm.push_back(static_cast<ppl::dimension_type>(t));
  }
  for (int t = 0; t < dims; ++t) {
    if (!taken[static_cast<std::size_t>(t)]) perm.push_back(static_cast<ppl::dimension_type>(t));
  }
  auto impl = std::make_unique<Impl>(*impl_);
  impl->Visit([&](auto& q) {
    q.add_space_dimensions_and_embed(static_cast<ppl::dimension_type>(dims) - n);
    q.map_space_dimensions(permutation);
  });
  return ConvexPolyhedron(std::move(impl));
}

void ConvexPolyhedron::Hull(const ConvexPolyhedron& other) {
  Impl::Both(*impl_, *other.impl_, [](auto& x, const auto& y) { x.poly_hull_assign(y); });
}

void ConvexPolyhedron::ConstraintHull(const ConvexPolyhedron& other) {
  Impl::Both(*impl_, *other.impl_, [](auto& x, const auto& y) {
    using Poly = std::remove_cvref_t<decltype(x)>;
    if (y.is_empty()) return;
    if (x.is_empty()) {
      x = y;
      return;
    }
    ppl::Constraint_System kept;
    const auto keep = [&kept](const Poly& on, const ppl::Constraint& c) {
      if (on.relation_with(c).implies(ppl::Poly_Con_Relation::is_included())) kept.insert(c);
    };
    // Each equality e == 0 as its two halves e >= 0 and e <= 0, either of which may hold on
    // the other set alone.
    const auto keep_valid = [&](const Poly& from, const Poly& on) {
      for (const ppl::Constraint& c : from.minimized_constraints()) {
        if (!c.is_equality()) {
          keep(on, c);
          continue;
        }
        ppl::Linear_Expression e(c.inhomogeneous_term());
        for (ppl::dimension_type i = 0; i < c.space_dimension(); ++i) {
          e += c.coefficient(ppl::Variable(i)) * ppl::Variable(i);
        }
        keep(on, e >= 0);
        keep(on, e <= 0);
      }
    };
    keep_valid(x, y);
    keep_valid(y, x);
    Poly hull(x.space_dimension(), ppl::UNIVERSE);
    hull.add_constraints(kept);
    x = std::move(hull);
  });
}

void ConvexPolyhedron::Widen(const ConvexPolyhedron& previous) {
  Impl::Both(*impl_, *previous.impl_, [](auto& x, const auto& y) { x.H79_widening_assign(y); });
}

std::optional<double> ConvexPolyhedron::Supremum(std::span<const double> objective,
                                                 bool* attained) const {
  if (static_cast<int>(objective.size()) != dims()) {
    throw std::invalid_argument("an objective of the wrong dimension");
  }
  const auto [e, lcm] = ScaledForm(objective, 0.0);
  ppl::Coefficient n, d;
  bool maximum = false;
  if (!impl_->Visit([&](const auto& q) { return q.maximize(e, n, d, maximum); })) {
    return std::nullopt;
  }
  if (attained) *attained = maximum;
  return NearestDouble(mpq_class(ToInteger(n), ToInteger(d) * lcm));
}

bool ConvexPolyhedron::RestrictToMaximum(std::span<const double> objective) {
  if (static_cast<int>(objective.size()) != dims()) {
    throw std::invalid_argument("an objective of the wrong dimension");
  }
  const ppl::Linear_Expression e = IntegerForm(objective, 0.0);
  ppl::Coefficient n, d;
  bool maximum = false;
  const bool found = impl_->Visit([&](auto& q) {
    if (!q.maximize(e, n, d, maximum) || !maximum) return false;
    q.add_constraint(d * e == n);
    return true;
  });
  if (!found) return false;
  return true;
}

ConvexPolyhedron ConvexPolyhedron::CentralPoint() const {
  if (IsEmpty()) throw std::logic_error("a point of an empty polyhedron");
  std::vector<mpq_class> centre(static_cast<size_t>(dims()));
  std::vector<mpq_class> rays(centre.size());
  long count = 0;
  for (const ppl::Generator& g : impl_->Generators()) {
    if (g.is_point() || g.is_closure_point()) {
      const std::vector<mpq_class> x = Coordinates(g);
      for (size_t i = 0; i < x.size(); ++i) centre[i] += x[i];
      ++count;
    } else if (g.is_ray()) {
      mpz_class largest = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        const mpz_class c = abs(ToInteger(g.coefficient(ppl::Variable(i))));
        if (c > largest) largest = c;
      }
      for (size_t i = 0; i < rays.size(); ++i) {
        rays[i] += mpq_class(ToInteger(g.coefficient(ppl::Variable(i))), largest);
      }
    }
  }
  std::vector<double> rounded;
  for (size_t i = 0; i < centre.size(); ++i) {
    centre[i] = centre[i] / count + rays[i];
    centre[i].canonicalize();
    rounded.push_back(NearestDouble(centre[i]));
  }
  if (std::all_of(rounded.begin(), rounded.end(), [](double v) { return std::isfinite(v); })) {
    ConvexPolyhedron simple = Point(rounded);
    if (Contains(simple)) return simple;
  }
  return ConvexPolyhedron(
      std::make_unique<Impl>(Impl{ppl::C_Polyhedron(ppl::Generator_System(PointOf(centre)))}));
}

namespace {

// Each dimension's least and greatest value over generators `gens` (of a non-empty polyhedron in
// n dimensions, points and closure points alike), each extreme as the coefficient and divisor of
// the point that has it (c / d, d > 0), compared by cross-multiplication: no rational made
// canonical (a gcd) per coordinate. In 128-bit integers where every coefficient is below 2^58
// (exact: each product is below 2^116), else GMP's.
template <class Int, class Read>
std::vector<std::pair<double, double>> ExtremesOf(const ppl::Generator_System& gens, size_t n,
                                                  Read&& read) {
  struct Extreme {
    Int c{}, d{};
    bool set = false;
  };
  std::vector<Extreme> lo(n), hi(n);
  std::vector<bool> below(n, false), above(n, false);  // unbounded that way
  for (const ppl::Generator& g : gens) {
    if (g.is_point() || g.is_closure_point()) {
      const Int d = read(g.divisor());
      for (size_t i = 0; i < n; ++i) {
        const Int c = read(g.coefficient(ppl::Variable(i)));
        // c / d below lo (side -1) or above hi (side 1) replaces it.
        for (auto [e, side] : {std::pair{&lo[i], -1}, std::pair{&hi[i], 1}}) {
          if (e->set && !(side * Compare(Int(c * e->d), Int(e->c * d)) > 0)) continue;
          e->c = c;
          e->d = d;
          e->set = true;
        }
      }
      continue;
    }
    for (size_t i = 0; i < n; ++i) {  // a ray or a line
      const int sign = sgn(ToInteger(g.coefficient(ppl::Variable(i))));
      below[i] = below[i] || sign < 0 || (sign != 0 && g.is_line());
      above[i] = above[i] || sign > 0 || (sign != 0 && g.is_line());
    }
  }
  const auto value = [](const Extreme& e) {
    mpq_class q(ToMpz(e.c), ToMpz(e.d));
    q.canonicalize();
    return NearestDouble(q);
  };
  std::vector<std::pair<double, double>> out(n);
  for (size_t i = 0; i < n; ++i) {
    out[i].first = below[i] ? -INFINITY : value(lo[i]);
    out[i].second = above[i] ? INFINITY : value(hi[i]);
  }
  return out;
}

}  // namespace

std::vector<std::pair<double, double>> ConvexPolyhedron::Bounds() const {
  const size_t n = static_cast<size_t>(dims());
  if (IsEmpty()) return std::vector<std::pair<double, double>>(n, {INFINITY, -INFINITY});
  const ppl::Generator_System& gens = impl_->Generators();
  bool small = true;
  for (auto g = gens.begin(); small && g != gens.end(); ++g) small = SmallRow(*g, n);
  if (small) {
    return ExtremesOf<Int128>(gens, n, [](const ppl::Coefficient& c) {
      return static_cast<Int128>(ppl::raw_value(c).get_si());
    });
  }
  return ExtremesOf<mpz_class>(gens, n, [](const ppl::Coefficient& c) { return ToInteger(c); });
}

bool ConvexPolyhedron::IsPoint() const {
  return impl_->Visit([](const auto& q) { return !q.is_empty() && q.affine_dimension() == 0; });
}

std::vector<double> ConvexPolyhedron::PointCoordinates() const {
  for (const ppl::Generator& g : impl_->Generators()) {
    if (!g.is_point()) continue;
    std::vector<double> x;
    for (const mpq_class& v : Coordinates(g)) x.push_back(NearestDouble(v));
    return x;
  }
  throw std::logic_error("the coordinates of a point of an empty polyhedron");
}

std::vector<LinearConstraint> ConvexPolyhedron::Constraints() const {
  std::vector<LinearConstraint> out;
  for (const ppl::Constraint& c : impl_->Constraints()) {
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
  const ppl::Constraint_System& constraints = impl_->Constraints();
  for (auto it = constraints.begin(); it != constraints.end(); ++it) ++count;
  return count;
}

std::size_t ConvexPolyhedron::LargestCoefficientBits() const {
  std::size_t bits = 0;
  const auto size = [](const ppl::Coefficient& c) {
    return mpz_sizeinbase(ppl::raw_value(c).get_mpz_t(), 2);
  };
  for (const ppl::Constraint& c : impl_->Constraints()) {
    for (int i = 0; i < dims(); ++i) {
      bits =
          std::max(bits, size(c.coefficient(ppl::Variable(static_cast<ppl::dimension_type>(i)))));
    }
    bits = std::max(bits, size(c.inhomogeneous_term()));
  }
  return bits;
}

std::size_t ConvexPolyhedron::RepresentationBytes() const {
  return static_cast<std::size_t>(
      impl_->Visit([](const auto& q) { return q.external_memory_in_bytes(); }));
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
