// The shared verification arithmetic on synthetic data with known answers: an order fitted
// only over the contiguous errors above the floor, never across a failure, and drift lines.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "tsi/convergence.hpp"

TEST_CASE("fit_order: the order of a power law down to a plateau, and no fit across a failure") {
  const std::vector<double> h = {1.0 / 4, 1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128};
  std::vector<double> e;
  for (double x : h) e.push_back(std::max(5.0 * x * x, 2e-3));  // order 2, then a plateau at 2e-3
  const tsi::OrderFit plateau = tsi::fit_order(h, e, 3e-3);
  CHECK(plateau.finite);
  CHECK(plateau.measurable);
  CHECK(plateau.first == 0);
  CHECK(plateau.used == 4);  // 0.31, 0.078, 0.020, 0.0049; then 2e-3 twice
  CHECK(plateau.order == doctest::Approx(2.0).epsilon(1e-12));
  // Fitting the plateau in would bend the order: the filter is what keeps it at 2.
  CHECK(tsi::least_squares_order(h, e) < 1.7);

  std::vector<double> gap = e;
  gap[1] = std::numeric_limits<double>::quiet_NaN();  // a blow-up at h = 1/8
  const tsi::OrderFit failed = tsi::fit_order(h, gap, 0.0);
  CHECK_FALSE(failed.finite);
  CHECK_FALSE(failed.measurable);
  CHECK(std::isnan(failed.order));

  // Too few errors above the floor: nothing to observe.
  const tsi::OrderFit floor = tsi::fit_order(h, e, 0.05);
  CHECK(floor.finite);
  CHECK_FALSE(floor.measurable);
}

TEST_CASE("drift_fit: the slope and the noise about the line, over the window only") {
  std::vector<double> t, y;
  for (int i = 0; i <= 200; ++i) {
    t.push_back(i);
    y.push_back((i < 50 ? 1.0 : 0.0) + 1e-3 * i + (i % 2 ? 1e-4 : -1e-4));
  }
  const tsi::DriftFit f = tsi::drift_fit(t, y, 50.0);
  CHECK(f.points == 151);
  CHECK(f.slope == doctest::Approx(1e-3).epsilon(1e-3));
  CHECK(f.residual_rms == doctest::Approx(1e-4).epsilon(1e-2));
  CHECK(std::isnan(tsi::drift_fit(t, y, 1e9).slope));
}
