#pragma once
#include "tsi/export.hpp"

namespace tsi {

inline constexpr double two_pi = 6.283185307179586476925286766559;

/// The fast phase t/eps reduced to [0, 2*pi), with a rounding error of the order of
/// ulp(t/eps) rather than ulp(t/eps) times the number of periods (SPEC.md section 3).
TSI_API double fast_phase(double t, double eps);

/// Time of step n: t_n = n h, computed, never accumulated.
inline double step_time(long n, double h) { return static_cast<double>(n) * h; }

}  // namespace tsi
