// The fast phase t/eps mod 2 pi keeps a rounding error of the order of ulp(t/eps), checked
// against the same reduction in long double.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "tsi/phase.hpp"

namespace {
constexpr long double two_pi_l = 6.283185307179586476925286766559005768L;
}

TEST_CASE("fast_phase reduces t/eps with an error of a few ulp of t/eps") {
  for (double eps : {1.0, 0.1, 1e-3, 1e-6, 1e-9}) {
    for (long n : {1L, 7L, 1000L, 123457L, 10000000L}) {
      const double h = 1.0 / 64.0;
      const double t = tsi::step_time(n, h);
      const double x = t / eps;
      const long double exact = std::fmod(static_cast<long double>(x), two_pi_l);
      const double got = tsi::fast_phase(t, eps);
      CAPTURE(eps);
      CAPTURE(n);
      CHECK(got >= 0.0);
      CHECK(got < tsi::two_pi);
      // Compare on the circle: 0 and 2 pi are the same phase.
      long double diff = std::fabs(static_cast<long double>(got) - exact);
      diff = std::min(diff, two_pi_l - diff);
      const double scale = std::max(x, tsi::two_pi);
      const double ulp = std::nextafter(scale, INFINITY) - scale;
      CHECK(static_cast<double>(diff) <= 4.0 * ulp);
    }
  }
}

TEST_CASE("step_time computes n h, never an accumulated sum") {
  double accumulated = 0.0;
  const double h = 0.1;
  for (long n = 0; n < 1000000; ++n) accumulated += h;
  CHECK(tsi::step_time(1000000, h) == 1000000 * 0.1);
  CHECK(std::abs(accumulated - 100000.0) > std::abs(tsi::step_time(1000000, h) - 100000.0));
}
