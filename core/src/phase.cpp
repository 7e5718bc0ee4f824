#include "tsi/phase.hpp"

#include <cmath>

namespace tsi {

Real fast_phase(Real t, Real eps) {
  const Real x = t / eps;
  // What that quotient rounded off: t - x eps is exact in one fma, so t/eps = x + residual to
  // the rounding of residual alone (at eps = 1e-7 and t = 1, ulp(x) would be 1e-9 of phase).
  const Real residual = std::fma(-x, eps, t) / eps;
  // 2*pi as hi + lo (Cody-Waite): x - k*hi is exact within one fma, and k*lo carries the
  // rest, so the reduction adds only an error of the order of ulp of the result.
  // hi is 2*pi rounded to Real, lo the next digits of 2*pi - hi.
#if defined(TSI_PRECISION_QUAD)
  static const Real hi("6.283185307179586476925286766559005594958136196274591146009008663748593437325951072125462815165519714");
  static const Real lo("1.7343620260247562049594088052086704e-34");
#elif defined(TSI_PRECISION_LONG_DOUBLE)
  constexpr Real hi = 6.2831853071795864770256179188123724088654853403568267822265625L;
  constexpr Real lo = -1.0033115225336664047114654160661514e-19L;
#else
  constexpr Real hi = 6.283185307179586;
  constexpr Real lo = 2.4492935982947064e-16;
#endif
  const Real k = std::floor(x / two_pi);
  Real r = std::fma(-k, hi, x);
  r = std::fma(-k, lo, r) + residual;
  if (r < 0) r += two_pi;
  if (r >= two_pi) r -= two_pi;
  return r;
}

}  // namespace tsi
