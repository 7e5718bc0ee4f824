#pragma once
#include <vector>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// The weights of exponential schemes that integrate y' = L y + N with N replaced by its
/// interpolation polynomial: for nodes s_0 .. s_{r-1} (in units of the step h) and a target
/// kappa,  y(kappa h) = e^{kappa z} y(0) + h sum_j w_j N(s_j h),  z = h L (one multiplier),
///     w_j = int_0^kappa e^{(kappa - s) z} l_j(s) ds = sum_m c_jm kappa^{m+1} m! phi_{m+1}(kappa z),
/// l_j the Lagrange polynomials on the nodes and c_jm their monomial coefficients. Exponential
/// Adams-Bashforth uses the nodes 0, -1, .., -(r-1); exponential collocation the Gauss nodes.
class TSI_API InterpolatoryWeights {
 public:
  explicit InterpolatoryWeights(std::vector<Real> nodes);
  /// w_j(kappa, z) for j = 0 .. nodes - 1.
  std::vector<Complex> operator()(Real kappa, Complex z) const;
  const std::vector<Real>& nodes() const { return nodes_; }

 private:
  std::vector<Real> nodes_;
  std::vector<std::vector<Real>> monomials_;  // [j][m]: coefficient of s^m in l_j(s)
};

}  // namespace tsi
