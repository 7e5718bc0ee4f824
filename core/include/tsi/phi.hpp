#pragma once
#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// e^z - 1 without cancellation for small |z|.
TSI_API Complex expm1(Complex z);
/// phi1(z) = (e^z - 1)/z, phi1(0) = 1; full precision of Real for |z| from 0 to 1e8.
TSI_API Complex phi1(Complex z);
/// phi2(z) = (e^z - 1 - z)/z^2, phi2(0) = 1/2; full precision of Real for |z| from 0 to 1e8.
TSI_API Complex phi2(Complex z);
/// phi_k(z) = sum_{m>=0} z^m / (m + k)!  (phi_0 = e^z, phi_{k+1}(z) = (phi_k(z) - 1/k!) / z),
/// for k from 0 to 20: the series where |z| <= max(1, k), the recurrence above, where each of its
/// steps divides the error by |z| / (j + 1) > 1. Exponential Adams-Bashforth weights use it.
TSI_API Complex phi(int k, Complex z);

}  // namespace tsi
