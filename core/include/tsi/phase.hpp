#pragma once
#include "tsi/export.hpp"

namespace tsi {

inline constexpr double two_pi = 6.283185307179586476925286766559;

/// The fast phase t/eps reduced to [0, 2*pi), with a rounding error of the order of the
/// result's ulp: neither the quotient's rounding (ulp(t/eps)) nor the number of periods enters.
TSI_API double fast_phase(double t, double eps);

/// Time of step n: t_n = n h, computed, never accumulated.
inline double step_time(long n, double h) { return static_cast<double>(n) * h; }

}  // namespace tsi
