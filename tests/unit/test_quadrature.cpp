// Gauss-Legendre on [0, 1]: exact for degree 2n - 1, not for degree 2n.
#include <doctest/doctest.h>

#include <cmath>

#include "tsi/quadrature.hpp"

TEST_CASE("n-point Gauss-Legendre integrates x^k exactly up to k = 2n - 1 and no further") {
  for (int n = 1; n <= 8; ++n) {
    const auto rule = tsi::gauss_legendre(n);
    CAPTURE(n);
    for (int k = 0; k <= 2 * n; ++k) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += rule.weights[i] * std::pow(rule.nodes[i], k);
      const double exact = 1.0 / (k + 1);
      CAPTURE(k);
      if (k <= 2 * n - 1)
        CHECK(std::abs(sum - exact) < 1e-15);
      else
        CHECK(std::abs(sum - exact) > 1e-12);  // the degree-2n error, far above rounding
    }
  }
}
