// Prepared initial data for the two-scale problem (SPEC.md section 2): U(0, 0) = u0 for
// every order, and with data of order k the time derivatives of U at t = 0 up to order k
// stay bounded as eps -> 0 while derivative k + 1 grows like 1/eps. The derivatives are
// measured on the two-scale flow itself, dU/dt = L U + N(U):
//   d1 = L U + N(U),  d2 = L d1 + DN(U) d1,  d3 = L d2 + DN(U) d2 + D2N(U)[d1, d1].
// Data of any order by the recursion along an averaged trajectory (docs/explanation/high-order.md,
// "Prepared data of any order") against the central difference quotients.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness.hpp"
#include "tsi/convergence.hpp"

namespace {

using tsi::Vector;

struct Prepared {
  Vector y;          // U(0, .) as coefficients
  long evaluations;  // of the field on the tau grid, by prepare() alone
  int order_reached;
};

/// Prepared data of `order` on n_tau = 64 by `method` ("auto", "recursion" or "central").
Prepared prepared(const std::string& model_name, double eps, int order, const std::string& method) {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model(model_name, eps);
  auto two_scale = h.reformulation(
      "two-scale", model, {{"n_tau", 64}, {"initial_data_order", order}, {"initial_data_method", method}});
  const long before = two_scale->evaluations();
  Vector y = two_scale->prepare(model->initial_value());
  return {y, two_scale->evaluations() - before, two_scale->two_scale_diagnostics()->data_order_reached()};
}

double relative_difference(const Vector& a, const Vector& b) { return (a - b).norm() / b.norm(); }

struct Derivatives {
  double d1, d2, d3;
};

Derivatives time_derivatives(double eps, int order) {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model("henon-heiles", eps);
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", order}});
  const Vector u = two_scale->prepare(model->initial_value());
  const Vector lambda = two_scale->linear_multipliers().expanded();
  Vector n(u.size()), dn(u.size());
  two_scale->rhs(0.0, u, n);
  const Vector d1 = n;
  two_scale->nonlinear_derivative(0.0, u, d1, dn);
  const Vector d2 = lambda.cwiseProduct(d1) + dn;
  two_scale->nonlinear_derivative(0.0, u, d2, dn);
  // D2N(U)[d1, d1] by a central difference of DN along d1: exact up to rounding for the
  // quadratic Henon-Heiles field.
  const double delta = 1e-3 / std::max(1.0, tsi::max_norm(d1));
  Vector plus(u.size()), minus(u.size());
  two_scale->nonlinear_derivative(0.0, u + delta * d1, d1, plus);
  two_scale->nonlinear_derivative(0.0, u - delta * d1, d1, minus);
  const Vector d3 = lambda.cwiseProduct(d2) + dn + (plus - minus) / (2.0 * delta);
  return {tsi::max_norm(d1), tsi::max_norm(d2), tsi::max_norm(d3)};
}

}  // namespace

TEST_CASE("prepared data of every order satisfies U(0, 0) = u0") {
  auto& h = tsi::test::Harness::instance();
  for (double eps : {1.0, 0.1, 1e-3, 1e-6}) {
    auto model = h.model("henon-heiles", eps);
    for (int order : {1, 2, 3}) {
      auto two_scale = h.reformulation("two-scale", model, {{"initial_data_order", order}});
      const Vector u0 = model->initial_value();
      const Vector back = two_scale->read_back(two_scale->prepare(u0), 0.0);
      CAPTURE(eps);
      CAPTURE(order);
      CHECK((back - u0).norm() <= 4e-16 * u0.norm());
    }
  }
}

TEST_CASE("data of order k keeps the first k time derivatives bounded as eps -> 0") {
  for (int order : {1, 2, 3}) {
    const Derivatives coarse = time_derivatives(1e-2, order), fine = time_derivatives(1e-5, order);
    const double coarse_d[3] = {coarse.d1, coarse.d2, coarse.d3};
    const double fine_d[3] = {fine.d1, fine.d2, fine.d3};
    CAPTURE(order);
    for (int k = 0; k < 3; ++k) {
      CAPTURE(k + 1);
      CAPTURE(coarse_d[k]);
      CAPTURE(fine_d[k]);
      if (k < order)  // bounded: eps fell 1000-fold, the derivative may not grow
        CHECK(fine_d[k] < 2.0 * coarse_d[k] + 1e-3);
      else if (k == order)  // the next one is O(1/eps): it grows with 1/eps
        CHECK(fine_d[k] > 100.0 * coarse_d[k]);
    }
  }
}

TEST_CASE("prepared data along the trajectory: the central quotients' data to rounding at eps = 1e-4, to O(eps^k) above") {
  // They differ by the central data's O(eps^k) error (their base point one order behind, the
  // quotients' truncation at order 3), below 1e-2 eps^k, and at eps = 1e-4 from order 4 on
  // agree to rounding (measured at most 6e-19 on Henon-Heiles, 5e-18 on NLS: the central
  // quotients' own noise at order 8). Measured at eps = 1e-2, Henon-Heiles: 3.2e-9, 1.8e-11,
  // 1.4e-13, 1.2e-15, 2.3e-16 for k = 3 .. 7; NLS: 1.3e-10, 1.5e-13, 4.2e-16, 2.5e-16, 1.1e-16.
  for (const std::string model : {"henon-heiles", "nls"}) {
    const int top = model == "nls" ? 7 : 8;  // the central quotients at NLS order 8: 3 s
    for (int k = 2; k <= top; ++k) {
      CAPTURE(model);
      CAPTURE(k);
      for (double eps : {1e-4, 1e-2}) {
        const double difference =
            relative_difference(prepared(model, eps, k, "recursion").y, prepared(model, eps, k, "central").y);
        CAPTURE(eps);
        CAPTURE(difference);
        CHECK(difference <= std::max(1e-2 * std::pow(eps, k), 1e-15));
      }
    }
  }
  // The difference is of order k (Henon-Heiles, eps = 1/16 .. 1/128; measured slopes 2.99,
  // 3.98, 4.96).
  for (int k = 3; k <= 5; ++k) {
    std::vector<double> epsilons, differences;
    for (double eps : {1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128}) {
      epsilons.push_back(eps);
      differences.push_back(relative_difference(prepared("henon-heiles", eps, k, "recursion").y,
                                                prepared("henon-heiles", eps, k, "central").y));
    }
    const double slope = tsi::least_squares_order(epsilons, differences);
    CAPTURE(k);
    CAPTURE(slope);
    CHECK(slope >= k - 0.2);
  }
}

TEST_CASE("prepared data along the trajectory: corrections of order k - 1, U(0, 0) = u0, O(p^2) evaluations") {
  auto& h = tsi::test::Harness::instance();
  // Order k corrects order k - 1 by O(eps^(k-1)), up to order 8 on Henon-Heiles and 6 on NLS
  // (beyond, NLS's corrections are at rounding at these eps), eps where they stand above it.
  // Measured slopes: 2.00, 3.00, 4.00, 4.99, 5.98, 6.99 (Henon-Heiles), 2.00, 3.00, 4.00, 5.04.
  for (const std::string model : {"henon-heiles", "nls"})
    for (int k = 3; k <= (model == "nls" ? 6 : 8); ++k) {
      const std::vector<double> epsilons = k <= 5 ? std::vector<double>{1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128}
                                                  : std::vector<double>{1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64};
      std::vector<double> corrections;
      for (double eps : epsilons)
        corrections.push_back(relative_difference(prepared(model, eps, k, "recursion").y,
                                                  prepared(model, eps, k - 1, "recursion").y));
      const double slope = tsi::least_squares_order(epsilons, corrections);
      CAPTURE(model);
      CAPTURE(k);
      CAPTURE(slope);
      CHECK(std::abs(slope - (k - 1)) < 0.3);
    }
  // U(0, 0) = u0 at every order, on every model, also where the trajectory gives way to the
  // central quotients (the charged particle at eps = 1, Klein-Gordon at eps >= 0.25), to the
  // rounding of data of the size of u0 (2.7e-15 at eps = 1, 4e-16 below).
  for (const std::string model : {"henon-heiles", "nls", "cpd", "klein-gordon"})
    for (double eps : {1.0, 1e-2, 1e-4})
      for (int order = 1; order <= 8; ++order) {
        auto m = h.model(model, eps);
        auto two_scale = h.reformulation("two-scale", m, {{"n_tau", 64}, {"initial_data_order", order}});
        const Vector u0 = m->initial_value();
        CAPTURE(model);
        CAPTURE(eps);
        CAPTURE(order);
        CHECK((two_scale->read_back(two_scale->prepare(u0), 0.0) - u0).norm() <= (eps < 1.0 ? 1e-15 : 4e-15) * u0.norm());
      }
  // The work: (p - 2) levels and the sweeps that find the trajectory (at most p + 4), each one
  // evaluation of the batched field per point (5, 7 above order 6), plus one at u0: at most
  // 5 p^2 for p = 3 .. 8 (measured at most 42, 52, 62, 72, 113, 128), one at order 2. The
  // central quotients take 1.25 5^(p-2) (24412 at order 8).
  for (const std::string model : {"henon-heiles", "nls"})
    for (double eps : {1e-4, 1e-2, 0.1, 1.0})
      for (int p = 2; p <= 8; ++p) {
        const Prepared data = prepared(model, eps, p, "recursion");
        CAPTURE(model);
        CAPTURE(eps);
        CAPTURE(p);
        CAPTURE(data.evaluations);
        CHECK(data.evaluations <= (p == 2 ? 1 : 5 * p * p));
      }
}
