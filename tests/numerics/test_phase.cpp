// The fast phase t/eps mod 2 pi keeps a rounding error of a few ulp of 2 pi, whatever t/eps:
// checked against the same reduction of the exact quotient in quadruple precision.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "tsi/phase.hpp"

namespace {
__extension__ typedef __float128 Quad;
// 2 pi as three doubles: 2 pi to 1e-48, far beyond what the reduction below needs.
const Quad two_pi_q = Quad(6.283185307179586) + Quad(2.4492935982947064e-16) + Quad(-5.989539619436679e-33);
}  // namespace

TEST_CASE("fast_phase reduces t/eps with an error of a few ulp of 2 pi") {
  const double ulp = std::nextafter(tsi::two_pi, INFINITY) - tsi::two_pi;
  double worst = 0.0;
  for (double eps : {1.0, 0.1, 1e-3, 1.5e-7, 1e-6, 1e-9}) {
    for (long n : {1L, 7L, 1000L, 123457L, 10000000L}) {
      for (double h : {1.0 / 64.0, 0.1}) {
        const double t = tsi::step_time(n, h);
        // t / eps exactly (t and eps are doubles: quad holds their quotient to 1e-34), reduced.
        const Quad x = Quad(t) / Quad(eps);
        const auto k = static_cast<long long>(static_cast<double>(x / two_pi_q));
        Quad exact = x - Quad(k) * two_pi_q;
        while (exact < 0) exact += two_pi_q;
        while (exact >= two_pi_q) exact -= two_pi_q;
        const double got = tsi::fast_phase(t, eps);
        CAPTURE(eps);
        CAPTURE(n);
        CAPTURE(h);
        CHECK(got >= 0.0);
        CHECK(got < tsi::two_pi);
        // Compare on the circle: 0 and 2 pi are the same phase.
        Quad diff = Quad(got) - exact;
        if (diff < 0) diff = -diff;
        if (two_pi_q - diff < diff) diff = two_pi_q - diff;
        worst = std::max(worst, static_cast<double>(diff));
        CHECK(static_cast<double>(diff) <= 4.0 * ulp);
      }
    }
  }
  MESSAGE("largest phase error " << worst << " (ulp(2 pi) = " << ulp << ")");
}

TEST_CASE("step_time computes n h, never an accumulated sum") {
  double accumulated = 0.0;
  const double h = 0.1;
  for (long n = 0; n < 1000000; ++n) accumulated += h;
  CHECK(tsi::step_time(1000000, h) == 1000000 * 0.1);
  CHECK(std::abs(accumulated - 100000.0) > std::abs(tsi::step_time(1000000, h) - 100000.0));
}
