// Prepared initial data for the two-scale problem (SPEC.md section 2): U(0, 0) = u0 for
// every order, and with data of order k the time derivatives of U at t = 0 up to order k
// stay bounded as eps -> 0 while derivative k + 1 grows like 1/eps. The derivatives are
// measured on the two-scale flow itself, dU/dt = L U + N(U):
//   d1 = L U + N(U),  d2 = L d1 + DN(U) d1,  d3 = L d2 + DN(U) d2 + D2N(U)[d1, d1].
#include <doctest/doctest.h>

#include "harness.hpp"

namespace {

using tsi::Vector;

struct Derivatives {
  double d1, d2, d3;
};

Derivatives time_derivatives(double eps, int order) {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model("henon-heiles", eps);
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", order}});
  const Vector u = two_scale->prepare(model->initial_value());
  const Vector& lambda = two_scale->linear_multipliers();
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
