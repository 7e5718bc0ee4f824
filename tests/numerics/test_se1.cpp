// SE1-TSI on Henon-Heiles (SPEC.md section 5): uniform second order against an rk78
// reference on the filtered problem, and exact time symmetry.
#include <doctest/doctest.h>

#include <cmath>

#include <map>

#include "harness.hpp"
#include "tsi/convergence.hpp"

namespace {

using tsi::Vector;
using tsi::test::Harness;

double se1_error(double eps, long steps, const Vector& ref) {
  auto& h = Harness::instance();
  auto model = h.model("henon-heiles", eps);
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", 2}});
  auto se1 = h.scheme("se1", {{"tol", 1e-12}});
  const Vector u = tsi::test::solve(*model, *two_scale, *se1, 1.0, steps);
  return (u - ref).norm() / ref.norm();
}

}  // namespace

TEST_CASE("SE1 two-scale is uniformly second order on Henon-Heiles at T = 1") {
  const std::vector<double> epsilons = {1.0, 0.25, 1.0 / 16, 1.0 / 64, 1.0 / 256, 1.0 / 1024, 1e-6};
  const std::vector<long> steps = {2, 4, 8, 16, 32, 64};  // h = 1/2 .. 1/64
  std::vector<double> hs;
  for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
  std::map<double, std::vector<double>> errors;
  for (double eps : epsilons) {
    const Vector& ref = tsi::test::reference_solution("henon-heiles", eps, 1.0);
    for (long n : steps) errors[eps].push_back(se1_error(eps, n, ref));
  }
  for (double eps : epsilons) {
    // Asymptotic range: h <= 1/4 (the h = 1/2 point is still pre-asymptotic for some eps).
    const std::vector<double> h_range(hs.begin() + 1, hs.end());
    const std::vector<double> e_range(errors[eps].begin() + 1, errors[eps].end());
    const double order = tsi::least_squares_order(h_range, e_range);
    CAPTURE(eps);
    CAPTURE(order);
    CHECK(std::abs(order - 2.0) <= 0.15);
  }
  for (size_t i = 0; i < hs.size(); ++i) {
    double lo = 1e300, hi = 0.0;
    for (double eps : epsilons) lo = std::min(lo, errors[eps][i]), hi = std::max(hi, errors[eps][i]);
    CAPTURE(hs[i]);
    CAPTURE(lo);
    CAPTURE(hi);
    CHECK(hi <= 1.5 * lo);  // uniform in eps: the error does not grow as eps -> 0
  }
  // The size of the error, against an independent implementation (SPEC.md section 5):
  // the maximum over eps is 9.7e-3 at h = 1/2 and 9.9e-6 at h = 1/64.
  double max_coarse = 0.0, max_fine = 0.0;
  for (double eps : epsilons) max_coarse = std::max(max_coarse, errors[eps].front()),
                              max_fine = std::max(max_fine, errors[eps].back());
  CHECK(std::abs(max_coarse / 9.7e-3 - 1.0) <= 0.05);
  CHECK(std::abs(max_fine / 9.9e-6 - 1.0) <= 0.05);
}

TEST_CASE("one SE1 step with h and one with -h return the two-scale state") {
  auto& h = Harness::instance();
  for (double eps : {1.0, 1e-2, 1e-6}) {
    for (double step : {0.5, 0.1}) {
      auto model = h.model("henon-heiles", eps);
      auto two_scale = h.reformulation("two-scale", model);
      auto se1 = h.scheme("se1", {{"tol", 1e-15}, {"max_iter", 500}});
      const Vector start = two_scale->prepare(model->initial_value());
      Vector y = start;
      se1->bind(*two_scale, step)->step(0.0, y);
      const double moved = tsi::max_norm(y - start);
      se1->bind(*two_scale, -step)->step(step, y);
      CAPTURE(eps);
      CAPTURE(step);
      CHECK(moved > 1e-3);  // the step did something
      CHECK(tsi::max_norm(y - start) <= 1e-10 * tsi::max_norm(start));
    }
  }
}
