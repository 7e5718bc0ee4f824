#include "tsi/phase.hpp"

#include <cmath>

namespace tsi {

double fast_phase(double t, double eps) {
  const double x = t / eps;
  // What that quotient rounded off: t - x eps is exact in one fma, so t/eps = x + residual to
  // the rounding of residual alone (at eps = 1e-7 and t = 1, ulp(x) would be 1e-9 of phase).
  const double residual = std::fma(-x, eps, t) / eps;
  // 2*pi as hi + lo (Cody-Waite): x - k*hi is exact within one fma, and k*lo carries the
  // rest, so the reduction adds only an error of the order of ulp of the result.
  constexpr double hi = 6.283185307179586;
  constexpr double lo = 2.4492935982947064e-16;
  const double k = std::floor(x / two_pi);
  double r = std::fma(-k, hi, x);
  r = std::fma(-k, lo, r) + residual;
  if (r < 0.0) r += two_pi;
  if (r >= two_pi) r -= two_pi;
  return r;
}

}  // namespace tsi
