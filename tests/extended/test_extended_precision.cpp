// The extended-precision builds (TSI_PRECISION=long-double or quad): the same core, schemes and
// models with tsi::Real = x87 long double (64-bit significand, unit roundoff 5.4e-20) or IEEE
// quadruple precision (113 bits, 9.6e-35). What a double build cannot show: the orders
// observed below double's rounding floor, against references computed another way (the
// linear test's exact solution, e^{tZ} in __float128; rk78 on the filtered problem for
// Henon-Heiles), and the building blocks exact to the last bits of Real against 50-digit
// arithmetic. The same assertions fail in a double build: its errors stop at 1e-16 .. 1e-13.
#include <doctest/doctest.h>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "numerics/harness.hpp"
#include "tsi/convergence.hpp"
#include "tsi/phi.hpp"

namespace {

using tsi::Complex;
using tsi::Json;
using tsi::Real;
using tsi::Vector;
using tsi::test::Harness;

// 50 decimal digits (166 bits): the independent arithmetic of the building blocks' tests.
using Wide = boost::multiprecision::cpp_bin_float_50;

constexpr bool quad = std::numeric_limits<Real>::digits > 64;
const Real unit_roundoff = std::numeric_limits<Real>::epsilon() / 2;

double as_double(const Wide& x) { return static_cast<double>(x); }

TEST_CASE("extended precision: Real is the configured type, and the plugins were built for it") {
  CHECK(std::numeric_limits<Real>::digits == (quad ? 113 : 64));
  CHECK(sizeof(Complex) == 2 * sizeof(Real));
  // The plugins loaded (the layout check refuses one of another precision).
  const auto& registry = Harness::instance().registry();
  CHECK_NOTHROW(registry.scheme("eab"));
  CHECK_NOTHROW(registry.scheme("collocation"));
  CHECK_NOTHROW(registry.scheme("rk78"));
  CHECK_NOTHROW(registry.model("henon-heiles"));
}

TEST_CASE("extended precision: the fast phase t/eps mod 2 pi is exact to the rounding of its result") {
  const Wide two_pi = 2 * boost::math::constants::pi<Wide>();
  double worst = 0;
  for (const double eps : {0.015, 1.5e-7, 1e-3, 0.1})
    for (const double t : {0.0, 0.1, 1.0, 3.0, 0.7}) {
      // t and eps as the run has them (doubles from JSON), the reduction in 50 digits.
      const Wide x = Wide(t) / Wide(eps);
      Wide r = x - floor(x / two_pi) * two_pi;
      worst = std::max(worst, std::abs(as_double(Wide(tsi::fast_phase(Real(t), Real(eps))) - r)));
    }
  MESSAGE("fast phase: largest difference from 50 digits " << worst << " (unit roundoff "
                                                           << tsi::to_double(unit_roundoff) << ")");
  // A few ulp of 2 pi, whatever the number of periods (up to 1e6 here).
  CHECK(worst <= tsi::to_double(4 * 2 * tsi::two_pi * unit_roundoff));
}

// sum_m z^m / (m + k)! in 50 digits, 110 terms: |z| <= 4 leaves 4^110 / 110! < 1e-110.
std::pair<Wide, Wide> phi_wide(int k, const Complex& z) {
  Wide re = 0, im = 0, inv = 1;  // 1/(m + k)!
  for (int n = 2; n <= 110 + k; ++n) inv /= n;
  const Wide zr(z.real()), zi(z.imag());
  for (int m = 110; m >= 0; --m) {
    const Wide nr = re * zr - im * zi + inv, ni = re * zi + im * zr;
    re = nr, im = ni;
    inv *= (m + k);
  }
  return {re, im};
}

TEST_CASE("extended precision: phi_k(z) to the last bits of Real (the weights of eab and collocation)") {
  double worst = 0;
  for (int k = 1; k <= 8; ++k)
    for (const Complex& z : {Complex(0.3, 0), Complex(0, 1.7), Complex(-2.5, 1.1), Complex(0.5, -3.9),
                            Complex(0, 3.999), Complex(1e-6, 0)}) {
      const auto [re, im] = phi_wide(k, z);
      const Complex value = tsi::phi(k, z);
      const Wide dr = Wide(value.real()) - re, di = Wide(value.imag()) - im;
      worst = std::max(worst, as_double(sqrt(dr * dr + di * di) / sqrt(re * re + im * im)));
    }
  MESSAGE("phi_k: largest relative difference from 50 digits " << worst);
  CHECK(worst < tsi::to_double(256 * unit_roundoff));  // measured: 2 units in long double
}

// The least-squares order over the errors, h = 1 / steps.
double order_of(const std::vector<long>& steps, const std::vector<double>& errors) {
  std::vector<double> h;
  for (long n : steps) h.push_back(1.0 / static_cast<double>(n));
  return tsi::least_squares_order(h, errors);
}

// n steps of h = t_end / n from the assembly's u0: u(t_end) in physical variables.
Vector run(tsi::Assembly& a, Real t_end, long n) {
  Vector y = a.reformulation->prepare(a.u0);
  const Real h = t_end / static_cast<Real>(n);
  tsi::integrate(a.bind(h), y, n, {}, a.reformulation->repreparation());
  return a.model->to_physical(a.reformulation->read_back(y, tsi::step_time(n, h)));
}

// HOODESolver.jl's linear test (u' = A u / eps + B u + t a + b, the core's "linear" field),
// relative error at t = 1 against its exact solution (e^{tZ} of the augmented matrix in quad).
double linear_test_error(const Json& scheme, double eps, long n) {
  const Json config = {{"model", {{"name", "matrix"}, {"f", "linear"}, {"eps", eps}}},
                       {"reformulation", {{"name", "two-scale"}, {"n_tau", 32}}},
                       {"scheme", scheme}};
  tsi::Assembly a = Harness::instance().assemble(config);
  const Vector x = run(a, 1, n);
  const auto exact = a.model->exact_solution()->at(a.model->to_physical(a.u0), 1);
  return tsi::to_double((x - exact.x).norm() / exact.x.norm());
}

const Json collocation = {{"name", "collocation"}, {"tol", quad ? 1e-33 : 1e-19}, {"max_iter", 1000}};

TEST_CASE("extended precision: eab of orders 3 to 6 on the linear test, uniform in eps, below double's floor") {
  // Measured in double (examples/general/linear-test-extended.json, docs/benchmarks/extended-precision.md): eab
  // r = 6 stops at 1e-15 .. 6e-13 from h = 1/128 on (rounding, amplified near resonances); in long double
  // it falls to 1.3e-18 .. 6e-18 at h = 1/512, in quad to 8.1e-19 .. 6.0e-18 there.
  const std::vector<long> steps = {16, 32, 64, 128, 256, 512};
  for (int r = 3; r <= 6; ++r)
    for (const double eps : {0.15, 1.5e-5}) {
      std::vector<double> errors;
      for (long n : steps) errors.push_back(linear_test_error({{"name", "eab"}, {"order", r}}, eps, n));
      const double order = order_of(steps, errors);
      CAPTURE(r);
      CAPTURE(eps);
      CAPTURE(errors.back());
      MESSAGE("eab r = " << r << ", eps = " << eps << ": order " << order << ", error at h = 1/512 " << errors.back());
      CHECK(std::abs(order - r) < 0.15);  // measured: 3.00 .. 6.03
      // Below what double reaches at all for r = 5, 6 (its floor here: 1e-15 .. 6e-13).
      if (r == 6) CHECK(errors.back() < 1e-17);
      if (r == 5) CHECK(errors.back() < 2e-15);
    }
}

TEST_CASE("extended precision: exponential Gauss collocation reaches its order 2s at eps = 0.15") {
  // s = 3, order 6 at fixed eps: 2.5e-9 at h = 1/8 down to 2.6e-18 at h = 1/256 (double: 1.0e-15).
  // In quad also s = 4, order 8: 3.6e-11 at h = 1/8 down to 3.5e-23 at h = 1/256 and 1.4e-25 at 1/512.
  const std::vector<long> steps = {8, 16, 32, 64, 128, 256};
  for (int s = 3; s <= (quad ? 4 : 3); ++s) {
    std::vector<long> these = steps;
    if (s == 4) these.push_back(512);
    std::vector<double> errors;
    Json scheme = collocation;
    scheme["stages"] = s;
    for (long n : these) errors.push_back(linear_test_error(scheme, 0.15, n));
    const double order = order_of(these, errors);
    CAPTURE(s);
    MESSAGE("collocation s = " << s << ", eps = 0.15: order " << order << ", smallest error " << errors.back());
    CHECK(std::abs(order - 2 * s) < 0.15);
    CHECK(errors.back() < (s == 4 ? 1e-24 : 1e-17));
  }
}

TEST_CASE("extended precision: eab of order 6 on the linear test down to 1e-23 in quad" * doctest::skip(!quad)) {
  // Measured: 2.3e-23 at eps = 0.15 and 5.6e-24 at eps = 1.5e-5 for h = 1/4096 (order 6.00 and,
  // at its last step, 5.14: the exact solution's |tZ| = 7e4 there).
  const std::vector<long> steps = {256, 512, 1024, 2048, 4096};
  for (const double eps : {0.15, 1.5e-5}) {
    std::vector<double> errors;
    for (long n : steps) errors.push_back(linear_test_error({{"name", "eab"}, {"order", 6}}, eps, n));
    const double order = order_of(steps, errors);
    CAPTURE(eps);
    MESSAGE("eab r = 6, eps = " << eps << ", h = 1/256 .. 1/4096: order " << order << ", error " << errors.back());
    CHECK(std::abs(order - 6) < 0.2);
    CHECK(errors.back() < 1e-22);
  }
}

// Henon-Heiles against rk78 on the filtered problem in this precision: another reformulation
// and another scheme. n_tau 64, data of order 8.
Vector hh_reference(double eps, double tol) {
  const Json config = {{"model", {{"name", "henon-heiles"}, {"eps", eps}}},
                       {"reformulation", {{"name", "filtered"}}},
                       {"scheme", {{"name", "rk78"}, {"tol", tol}}}};
  tsi::Assembly a = Harness::instance().assemble(config);
  return run(a, 1, 64);
}

double hh_error(const Json& scheme, double eps, long n, const Vector& reference) {
  const Json config = {{"model", {{"name", "henon-heiles"}, {"eps", eps}}},
                       {"reformulation", {{"name", "two-scale"}, {"n_tau", 64}, {"initial_data_order", 8}}},
                       {"scheme", scheme}};
  tsi::Assembly a = Harness::instance().assemble(config);
  const Vector x = run(a, 1, n);
  return tsi::to_double((x - reference).norm() / reference.norm());
}

TEST_CASE("extended precision: Henon-Heiles against rk78 on the filtered problem, below double's floor") {
  // rk78's error grows with its substeps. In long double tol 1e-19 and 1e-20 differ by 5.6e-18
  // at eps = 0.1 and 7.3e-17 at eps = 0.01; eab r = 6 falls to 3.7e-17 (h = 1/512) at eps = 0.1;
  // at eps = 0.01 its rounding, amplified, stops it at 2e-16 .. 5e-16 from h = 1/512, so the
  // fit ends at h = 1/256 there (docs/benchmarks/extended-precision.md, "Extended precision"). In quad, collocation
  // with 4 stages (order 8 at fixed eps) falls to 1.8e-26 at h = 1/512 against rk78 at tol 1e-33.
  struct Case {
    double eps;
    Json scheme;
    std::vector<long> steps;
    int order;
    double below;
  };
  Json colloc4 = collocation;
  colloc4["stages"] = 4;
  const std::vector<Case> cases =
      quad ? std::vector<Case>{{0.1, colloc4, {32, 64, 128, 256, 512}, 8, 1e-25},
                               {0.1, {{"name", "eab"}, {"order", 6}}, {32, 64, 128, 256, 512}, 6, 1e-16}}
           : std::vector<Case>{{0.1, {{"name", "eab"}, {"order", 6}}, {32, 64, 128, 256, 512}, 6, 1e-16},
                               {0.01, {{"name", "eab"}, {"order", 6}}, {32, 64, 128, 256}, 6, 4e-15}};
  const double tol = quad ? 1e-33 : 1e-20;
  for (const Case& c : cases) {
    const Vector reference = hh_reference(c.eps, tol), looser = hh_reference(c.eps, 10 * tol);
    const double reference_change = tsi::to_double((looser - reference).norm() / reference.norm());
    std::vector<double> errors;
    for (long n : c.steps) errors.push_back(hh_error(c.scheme, c.eps, n, reference));
    const double order = order_of(c.steps, errors);
    CAPTURE(c.eps);
    CAPTURE(c.scheme.dump());
    MESSAGE(c.scheme.dump() << " on Henon-Heiles, eps = " << c.eps << ": order " << order << ", smallest error "
                            << errors.back() << " (rk78 tol x10: " << reference_change << ")");
    CHECK(reference_change < errors.back() / 4);  // the reference is not what is measured
    CHECK(std::abs(order - c.order) < 0.2);
    CHECK(errors.back() < c.below);
  }
}

}  // namespace
