#pragma once
#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// e^z - 1 without cancellation for small |z|.
TSI_API Complex expm1(Complex z);
/// phi1(z) = (e^z - 1)/z, phi1(0) = 1; full double precision for |z| from 0 to 1e8.
TSI_API Complex phi1(Complex z);
/// phi2(z) = (e^z - 1 - z)/z^2, phi2(0) = 1/2; full double precision for |z| from 0 to 1e8.
TSI_API Complex phi2(Complex z);

}  // namespace tsi
