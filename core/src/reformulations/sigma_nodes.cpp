#include "sigma_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "tsi/error.hpp"
#include "tsi/types.hpp"

namespace tsi {
namespace {

Real chebyshev(int k, Real t) { return std::cos(k * std::acos(std::clamp<Real>(t, -1, 1))); }

/// An antiderivative of T_k at t: T_{k+1}/(2(k+1)) - T_{k-1}/(2(k-1)) for k >= 2.
Real chebyshev_integral(int k, Real t) {
  if (k == 0) return t;
  if (k == 1) return 0.5 * t * t;
  return chebyshev(k + 1, t) / (2.0 * (k + 1)) - chebyshev(k - 1, t) / (2.0 * (k - 1));
}

}  // namespace

SigmaNodes::SigmaNodes(int m) : x(m), differentiate(m, m), integrate(m, m), center(m / 2) {
  if (m < 3 || m % 2 == 0) throw Error("SigmaNodes: expected an odd number of points from 3");
  for (int i = 0; i < m; ++i) x(i) = -std::cos(std::numbers::pi_v<Real> * i / (m - 1));
  x(center) = 0.0;  // exactly, not cos(pi/2)
  // Differentiation from the barycentric weights (Berrut and Trefethen); the diagonal makes
  // each row sum to zero, exact for constants.
  RealVector w = RealVector::Ones(m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      if (j != i) w(i) /= x(i) - x(j);
  for (int i = 0; i < m; ++i) {
    differentiate(i, i) = 0.0;
    for (int j = 0; j < m; ++j)
      if (j != i) {
        differentiate(i, j) = w(j) / w(i) / (x(i) - x(j));
        differentiate(i, i) -= differentiate(i, j);
      }
  }
  // Integration: the Lagrange basis in Chebyshev polynomials (V c = I, V_ik = T_k(x_i)),
  // each T_k integrated exactly from 0.
  RealMatrix values(m, m), integrals(m, m);
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < m; ++k) {
      values(i, k) = chebyshev(k, x(i));
      integrals(i, k) = chebyshev_integral(k, x(i)) - chebyshev_integral(k, 0);
    }
  integrate = integrals * values.inverse();
}

}  // namespace tsi
