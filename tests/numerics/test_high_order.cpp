// Higher order (SPEC.md, "Higher order"): the phi functions and interpolatory weights the
// exponential schemes are built from, prepared data of any order by the derivative-free
// recursion, and the orders of exponential Adams-Bashforth, the compositions and exponential
// Gauss collocation, each measured against an independent expectation.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "harness.hpp"
#include "tsi/convergence.hpp"
#include "tsi/exponential_weights.hpp"
#include "tsi/phi.hpp"

namespace {

using tsi::Complex;
using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

// Relative error at T = 1 on Henon-Heiles (rk78 reference) for a scheme section and data order.
double hh_error(const Json& scheme, double eps, long steps, int data_order) {
  auto& h = Harness::instance();
  auto model = h.model("henon-heiles", eps);
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", data_order}});
  Json params = scheme;
  const std::string name = params["name"];
  params.erase("name");
  auto stepper = h.scheme(name, params, "henon-heiles");
  const Vector& ref = tsi::test::reference_solution("henon-heiles", eps, 1.0);
  return (tsi::test::solve(*model, *two_scale, *stepper, 1.0, steps) - ref).norm() / ref.norm();
}

std::vector<double> step_sizes(const std::vector<long>& steps) {
  std::vector<double> hs;
  for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
  return hs;
}

Vector prepared(const std::string& model_name, double eps, int order, const std::string& method = "auto") {
  auto& h = Harness::instance();
  auto model = h.model(model_name, eps);
  auto two_scale = h.reformulation(
      "two-scale", model, {{"n_tau", 64}, {"initial_data_order", order}, {"initial_data_method", method}});
  return two_scale->prepare(model->initial_value());
}

}  // namespace

TEST_CASE("phi functions: phi(k, z) agrees with phi1, phi2 and the recurrence phi_k = z phi_{k+1} + 1/k!") {
  const std::vector<double> radii = {1e-8, 0.3, 0.999, 1.001, 2.5, 3.999, 4.001, 7.5, 40.0, 1e4, 1e8};
  // The recurrence is checked where it is well conditioned (|z| <= 40: beyond, z phi_{k+1}
  // cancels 1/k! to the size of phi_k, and the check measures its own rounding).
  const std::vector<double> angles = {0.5 * M_PI, 0.75 * M_PI, M_PI, 0.6 * M_PI};  // Re z <= 0, as e^{hL}
  double worst_12 = 0.0, worst_rec = 0.0;
  for (double r : radii)
    for (double a : angles) {
      const Complex z = std::polar(r, a);
      worst_12 = std::max(worst_12, std::abs(tsi::phi(1, z) - tsi::phi1(z)) / std::abs(tsi::phi1(z)));
      worst_12 = std::max(worst_12, std::abs(tsi::phi(2, z) - tsi::phi2(z)) / std::abs(tsi::phi2(z)));
      double factorial = 1.0;
      for (int k = 1; k <= 7 && r <= 40.0; ++k) {
        factorial *= k;
        const Complex lhs = tsi::phi(k, z), rhs = z * tsi::phi(k + 1, z) + 1.0 / factorial;
        worst_rec = std::max(worst_rec, std::abs(lhs - rhs) / std::abs(lhs));
      }
    }
  CHECK(worst_12 < 1e-14);
  CHECK(worst_rec < 1e-13);
  // Continuous across the switch from the series to the recurrence at |z| = k (the two
  // neighbouring doubles of k).
  for (int k = 2; k <= 7; ++k) {
    const Complex below(0.0, std::nextafter(double(k), 0.0)), above(0.0, std::nextafter(double(k), 10.0));
    CAPTURE(k);
    CHECK(std::abs(tsi::phi(k, below) - tsi::phi(k, above)) < 1e-13 * std::abs(tsi::phi(k, below)));
  }
}

TEST_CASE("interpolatory weights: exact for polynomials at z = 0, phi1 for a constant field") {
  const tsi::InterpolatoryWeights past({0.0, -1.0, -2.0, -3.0});
  for (double kappa : {1.0, -1.0, -3.0}) {
    const std::vector<Complex> w = past(kappa, 0.0);
    for (int m = 0; m < 4; ++m) {  // sum_j w_j s_j^m = int_0^kappa s^m ds
      Complex sum = 0.0;
      for (int j = 0; j < 4; ++j) sum += w[j] * std::pow(past.nodes()[j], m);
      CAPTURE(kappa);
      CAPTURE(m);
      CHECK(std::abs(sum - std::pow(kappa, m + 1) / (m + 1)) < 1e-13);
    }
  }
  const Complex z(0.0, -37.5);
  const std::vector<Complex> w = past(1.0, z);
  Complex sum = 0.0;
  for (const Complex& v : w) sum += v;
  CHECK(std::abs(sum - tsi::phi1(z)) < 1e-14);
}

TEST_CASE("prepared data: the recursion gives the closed formula at order 2, and at order 3 the same order") {
  for (const char* model : {"henon-heiles", "cpd", "klein-gordon"}) {
    CAPTURE(model);
    const Vector closed = prepared(model, 0.01, 2), recursion = prepared(model, 0.01, 2, "recursion");
    CHECK((closed - recursion).norm() <= 1e-14 * closed.norm());
  }
  // Order 3: the closed formula takes r2 from the derivative at u0, the recursion a difference
  // quotient at its base point: two approximations of the data to O(eps^3), which differ by
  // O(eps^3) (measured slope 3.00), not by rounding.
  std::vector<double> epsilons, differences;
  for (double eps : {1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128}) {
    const Vector closed = prepared("henon-heiles", eps, 3), recursion = prepared("henon-heiles", eps, 3, "recursion");
    epsilons.push_back(eps);
    differences.push_back((closed - recursion).norm() / closed.norm());
  }
  const double slope = tsi::least_squares_order(epsilons, differences);
  CAPTURE(slope);
  CHECK(std::abs(slope - 3.0) < 0.2);
}

TEST_CASE("prepared data: order k corrects order k - 1 by O(eps^(k-1)), and U(0, 0) = u0 exactly") {
  auto& h = Harness::instance();
  for (int k = 3; k <= 6; ++k) {
    std::vector<double> epsilons, corrections;
    for (double eps : {1.0 / 32, 1.0 / 64, 1.0 / 128, 1.0 / 256}) {
      const Vector lower = prepared("henon-heiles", eps, k - 1, "recursion"), upper = prepared("henon-heiles", eps, k);
      epsilons.push_back(eps);
      corrections.push_back((upper - lower).norm());
    }
    const double slope = tsi::least_squares_order(epsilons, corrections);
    CAPTURE(k);
    CAPTURE(slope);
    CHECK(std::abs(slope - (k - 1)) < 0.2);  // data of order k - 1 is off by O(eps^(k-1))
  }
  for (int order = 1; order <= 8; ++order) {
    auto model = h.model("cpd", 1.0 / 64);
    auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", order}});
    const Vector u0 = model->initial_value();
    const Vector back = two_scale->read_back(two_scale->prepare(u0), 0.0);
    CAPTURE(order);
    CHECK((back - u0).norm() <= 1e-15 * u0.norm());
    CHECK(two_scale->two_scale_diagnostics()->data_order_reached() == order);
  }
}

TEST_CASE("prepared data: at eps = 1 the recursion stops where its corrections stop decreasing") {
  auto& h = Harness::instance();
  auto model = h.model("henon-heiles", 1.0);
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", 8}});
  const Vector y = two_scale->prepare(model->initial_value());
  CHECK(y.allFinite());
  // Measured: corrections 1.1e-2, 6.2e-3, 4.0e-3, 2.3e-3, then 2.6e-3 (and 4.0 at order 8).
  CHECK(two_scale->two_scale_diagnostics()->data_order_reached() == 5);
}

TEST_CASE("eab: uniform order r on Henon-Heiles, errors within 2x across eps") {
  const std::vector<long> steps = {16, 32, 64, 128};
  const std::vector<double> epsilons = {1.0, 1.0 / 256, 1e-6};
  for (int r = 2; r <= 5; ++r) {
    std::vector<std::vector<double>> errors;
    for (double eps : epsilons) {
      errors.emplace_back();
      for (long n : steps) errors.back().push_back(hh_error({{"name", "eab"}, {"order", r}}, eps, n, std::min(r + 2, 8)));
    }
    CAPTURE(r);
    for (size_t k = 0; k < epsilons.size(); ++k) {
      const tsi::OrderFit fit = tsi::fit_order(step_sizes(steps), errors[k], 1e-10);
      CAPTURE(epsilons[k]);
      CAPTURE(fit.order);
      REQUIRE(fit.measurable);
      CHECK(std::abs(fit.order - r) < 0.3);
    }
    for (size_t i = 0; i < steps.size(); ++i)
      for (const auto& e : errors) CHECK(e[i] <= 2.0 * std::max(errors[0][i], 1e-10));
  }
}

TEST_CASE("compositions: classical order at eps = 1 and in the averaged regime, order 2 in between") {
  struct Case {
    const char* method;
    double order;
  };
  const auto fitted = [](const char* method, double eps, const std::vector<long>& steps, double floor) {
    std::vector<double> errors;
    for (long n : steps)
      errors.push_back(hh_error({{"name", "composition"}, {"method", method}, {"tol", 1e-14}}, eps, n, 4));
    return tsi::fit_order(step_sizes(steps), errors, floor);
  };
  for (const Case c : {Case{"triple-jump", 4}, Case{"suzuki5", 4}, Case{"yoshida6", 6}}) {
    const tsi::OrderFit fit = fitted(c.method, 1.0, {4, 8, 16, 32}, 1e-12);
    CAPTURE(std::string(c.method));
    CAPTURE(fit.order);
    REQUIRE(fit.measurable);
    CHECK(std::abs(fit.order - c.order) < 0.5);
  }
  // eps = 1e-6, h = 1/2 .. 1/16: order 4 down to 1e-9; below, the substeps' phases h g_i / eps
  // scatter the errors (Yoshida 6: 1.3e-10 at h = 1/16, 1.3e-9 at 1/32).
  for (const char* method : {"triple-jump", "suzuki5"}) {
    const tsi::OrderFit fit = fitted(method, 1e-6, {2, 4, 8, 16}, 1e-9);
    CAPTURE(std::string(method));
    CAPTURE(fit.order);
    REQUIRE(fit.measurable);
    CHECK(std::abs(fit.order - 4.0) < 0.3);
  }
  // Between eps ~ h and h / 100 the substeps' phase-dependent errors do not cancel: at
  // eps = 1/256 the triple jump's error from h = 1/8 to 1/16 barely falls (measured 2.3e-5 to
  // 1.7e-5, with data of order 2 to 6 alike), where order 4 would divide it by 16.
  const double coarse = hh_error({{"name", "composition"}, {"tol", 1e-14}}, 1.0 / 256, 8, 4);
  const double fine = hh_error({{"name", "composition"}, {"tol", 1e-14}}, 1.0 / 256, 16, 4);
  CHECK(coarse / fine < 4.0);
}

TEST_CASE("collocation: one stage is SE1, three stages bound the error by C h^4 uniformly on Henon-Heiles") {
  for (double eps : {1.0, 1.0 / 64}) {
    const double se1 = hh_error({{"name", "se1"}, {"tol", 1e-14}}, eps, 8, 2);
    const double one_stage = hh_error({{"name", "collocation"}, {"stages", 1}, {"tol", 1e-14}}, eps, 8, 2);
    CHECK(std::abs(one_stage - se1) <= 1e-9 * se1);
  }
  const std::vector<long> steps = {2, 4, 8, 16, 32};
  std::vector<double> worst(steps.size(), 0.0);
  for (int j = 0; j <= 12; j += 2) {  // eps = 1, 1/4, ..., 1/4096, and 1e-6
    for (double eps : j == 12 ? std::vector<double>{std::ldexp(1.0, -j), 1e-6} : std::vector<double>{std::ldexp(1.0, -j)})
      for (size_t i = 0; i < steps.size(); ++i)
        worst[i] = std::max(worst[i], hh_error({{"name", "collocation"}, {"stages", 3}, {"tol", 1e-14}}, eps, steps[i], 4));
  }
  const tsi::OrderFit fit = tsi::fit_order(step_sizes(steps), worst, 1e-10);
  CAPTURE(fit.order);
  REQUIRE(fit.measurable);
  CHECK(fit.order > 3.7);  // measured 4.0 over 16 eps (docs/benchmarks/high-order.md)
}
