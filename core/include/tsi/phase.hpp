#pragma once
#include <numbers>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

inline TSI_REAL_CONSTEXPR Real two_pi = 2 * std::numbers::pi_v<Real>;

/// The fast phase t/eps reduced to [0, 2*pi), with a rounding error of the order of the
/// result's ulp: neither the quotient's rounding (ulp(t/eps)) nor the number of periods enters.
TSI_API Real fast_phase(Real t, Real eps);

/// Time of step n: t_n = n h, computed, never accumulated.
inline Real step_time(long n, Real h) { return static_cast<Real>(n) * h; }

}  // namespace tsi
