#pragma once
#include <vector>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Gauss-Legendre rule on [0, 1]: exact for polynomials of degree 2n - 1.
struct TSI_API QuadratureRule {
  std::vector<Real> nodes, weights;
};

/// The n-point Gauss-Legendre rule on [0, 1] (n >= 1), nodes ascending.
TSI_API QuadratureRule gauss_legendre(int n);

}  // namespace tsi
