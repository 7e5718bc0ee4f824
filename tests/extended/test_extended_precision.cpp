// The extended-precision build (TSI_PRECISION=long-double): the same core, schemes and models
// with tsi::Real = x87 long double (64-bit significand, unit roundoff 5.4e-20). What a double
// build cannot show: the uniform orders observed below double's rounding floor, against
// references computed another way (the linear test's exact solution in __float128; rk78 on the
// filtered problem for Henon-Heiles), and the building blocks exact to the last bits of Real.
// The same assertions fail in a double build: its errors stop at 1e-16 .. 1e-13.
#include <doctest/doctest.h>

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

__extension__ typedef __float128 Quad;

// 2 pi in quad, as the sum of its long-double head and tail (2 pi to 1e-38).
const Quad two_pi_quad = Quad(6.2831853071795864770256179188123724088654853403568267822265625L) +
                         Quad(-1.0033115225336664047114654160661514e-19L);

constexpr Real unit_roundoff = std::numeric_limits<Real>::epsilon() / 2;

TEST_CASE("extended precision: Real is x87 long double, and the plugins were built for it") {
  CHECK(std::numeric_limits<Real>::digits == 64);
  CHECK(sizeof(Complex) == 2 * sizeof(Real));
  // The plugins loaded (the layout check refuses a double plugin): the schemes these tests use.
  const auto& registry = Harness::instance().registry();
  CHECK_NOTHROW(registry.scheme("eab"));
  CHECK_NOTHROW(registry.scheme("collocation"));
  CHECK_NOTHROW(registry.model("henon-heiles"));
}

TEST_CASE("extended precision: the fast phase t/eps mod 2 pi is exact to the rounding of its result") {
  // Against __float128: t and eps are exact in quad, and so is the reduction's multiple of 2 pi.
  Real worst = 0;
  for (const Real eps : {0.015L, 1.5e-7L, 1e-3L, 0.1L})
    for (const Real t : {0.0L, 0.1L, 1.0L, 3.0L, 0.7L}) {
      const Quad x = Quad(t) / Quad(eps);
      const Real periods = std::floor(static_cast<Real>(x / two_pi_quad));
      Quad r = x - Quad(periods) * two_pi_quad;
      if (r < 0) r += two_pi_quad;
      if (r >= two_pi_quad) r -= two_pi_quad;
      worst = std::max(worst, std::abs(tsi::fast_phase(t, eps) - static_cast<Real>(r)));
    }
  MESSAGE("fast phase: largest difference from quad " << static_cast<double>(worst));
  // A few ulp of 2 pi (ulp = 8.7e-19), whatever the number of periods (up to 2e7 here).
  CHECK(worst <= 4 * 2 * tsi::two_pi * unit_roundoff);
}

// sum_m z^m / (m + k)! in quad (complex as a pair), 90 terms: |z| <= 4 leaves 4^90 / 90! < 1e-80.
Complex phi_quad(int k, Complex z) {
  Quad re = 0, im = 0, inv = 1;  // 1/(m + k)!
  for (int n = 2; n <= 90 + k; ++n) inv /= n;
  const Quad zr = z.real(), zi = z.imag();
  for (int m = 90; m >= 0; --m) {
    const Quad nr = re * zr - im * zi + inv, ni = re * zi + im * zr;
    re = nr, im = ni;
    inv *= (m + k);
  }
  return {static_cast<Real>(re), static_cast<Real>(im)};
}

TEST_CASE("extended precision: phi_k(z) to the last bits of Real (the weights of eab and collocation)") {
  Real worst = 0;
  for (int k = 1; k <= 8; ++k)
    for (const Complex z : {Complex(0.3L, 0), Complex(0, 1.7L), Complex(-2.5L, 1.1L), Complex(0.5L, -3.9L),
                            Complex(0, 3.999L), Complex(1e-6L, 0)}) {
      const Complex exact = phi_quad(k, z);
      worst = std::max(worst, std::abs(tsi::phi(k, z) - exact) / std::abs(exact));
    }
  MESSAGE("phi_k: largest relative difference from quad " << static_cast<double>(worst));
  CHECK(worst < 1e-17);  // 200 units of long double's roundoff; double's own is 1.1e-16
}

// The least-squares order over the errors, h = t_end / steps.
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
// relative error at t = 1 against its exact solution (quad precision: e^{tZ} of the augmented matrix).
double linear_test_error(const Json& scheme, double eps, long n) {
  const Json config = {{"model", {{"name", "matrix"}, {"f", "linear"}, {"eps", eps}}},
                       {"reformulation", {{"name", "two-scale"}, {"n_tau", 32}}},
                       {"scheme", scheme}};
  tsi::Assembly a = Harness::instance().assemble(config);
  const Vector x = run(a, 1, n);
  const auto exact = a.model->exact_solution()->at(a.model->to_physical(a.u0), 1);
  return static_cast<double>((x - exact.x).norm() / exact.x.norm());
}

TEST_CASE("extended precision: eab of orders 3 to 6 on the linear test, uniform in eps, below double's floor") {
  // Measured in double (examples/general/linear-test-extended.json, docs/high-order.md): eab
  // r = 6 stops at 1e-13 .. 6e-13 from h = 1/128 on (rounding amplified by its weights); in
  // long double its errors fall to 1.3e-18 .. 6e-18 at h = 1/512.
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

TEST_CASE("extended precision: exponential Gauss collocation reaches its order 2s at eps = 0.15 below 1e-16") {
  // s = 3, order 6 at fixed eps: 2.5e-9 at h = 1/8 down to 2.6e-18 at h = 1/256 (double: 1.0e-15).
  const std::vector<long> steps = {8, 16, 32, 64, 128, 256};
  std::vector<double> errors;
  for (long n : steps)
    errors.push_back(linear_test_error({{"name", "collocation"}, {"stages", 3}, {"tol", 1e-19}, {"max_iter", 1000}},
                                       0.15, n));
  const double order = order_of(steps, errors);
  MESSAGE("collocation s = 3, eps = 0.15: order " << order << ", error at h = 1/256 " << errors.back());
  CHECK(std::abs(order - 6) < 0.15);
  CHECK(errors.back() < 1e-17);
}

// Henon-Heiles at eps: relative error at t = 1 against rk78 on the filtered problem (tol 1e-20:
// another reformulation and another scheme), n_tau 64 and data of order r + 2.
double hh_error(int r, double eps, long n, const Vector& reference) {
  const Json config = {{"model", {{"name", "henon-heiles"}, {"eps", eps}}},
                       {"reformulation", {{"name", "two-scale"}, {"n_tau", 64}, {"initial_data_order", r + 2}}},
                       {"scheme", {{"name", "eab"}, {"order", r}}}};
  tsi::Assembly a = Harness::instance().assemble(config);
  const Vector x = run(a, 1, n);
  return static_cast<double>((x - reference).norm() / reference.norm());
}

Vector hh_reference(double eps, double tol) {
  const Json config = {{"model", {{"name", "henon-heiles"}, {"eps", eps}}},
                       {"reformulation", {{"name", "filtered"}}},
                       {"scheme", {{"name", "rk78"}, {"tol", tol}}}};
  tsi::Assembly a = Harness::instance().assemble(config);
  return run(a, 1, 64);
}

TEST_CASE("extended precision: eab on Henon-Heiles against rk78 on the filtered problem, below 1e-16") {
  // rk78's error grows with the number of its substeps: tol 1e-19 and 1e-20 differ by 5.6e-18 at
  // eps = 0.1 and 7.3e-17 at eps = 0.01 (8e-16 at eps = 1e-3, too coarse for this test). eab r = 6
  // then falls from 9.4e-12 (h = 1/64) to 3.7e-17 (h = 1/512) at eps = 0.1. At eps = 0.01 its
  // rounding, amplified, stops it at 2e-16 .. 5e-16 from h = 1/512 (1.3e-15 at h = 1/1024): the
  // fit ends at h = 1/256 there (docs/high-order.md, "Extended precision").
  const std::vector<std::pair<double, std::vector<long>>> cases = {{0.1, {32, 64, 128, 256, 512}},
                                                                   {0.01, {32, 64, 128, 256}}};
  for (const auto& [eps, steps] : cases) {
    const Vector reference = hh_reference(eps, 1e-20), looser = hh_reference(eps, 1e-19);
    const double reference_change = static_cast<double>((looser - reference).norm() / reference.norm());
    std::vector<double> errors;
    for (long n : steps) errors.push_back(hh_error(6, eps, n, reference));
    const double order = order_of(steps, errors);
    CAPTURE(eps);
    MESSAGE("eab r = 6 on Henon-Heiles, eps = " << eps << ": order " << order << ", smallest error "
                                                << errors.back() << " (rk78 tol 1e-19 to 1e-20: " << reference_change
                                                << ")");
    CHECK(reference_change < errors.back() / 4);  // the reference is not what is measured
    CHECK(std::abs(order - 6) < 0.2);
    CHECK(errors.back() < (eps == 0.1 ? 1e-16 : 4e-15));
  }
}

}  // namespace
