#include "tsi/quadrature.hpp"

#include <cmath>
#include <limits>

#include "tsi/error.hpp"
#include "tsi/phase.hpp"

namespace tsi {

QuadratureRule gauss_legendre(int n) {
  if (n < 1) throw Error("gauss_legendre: the number of nodes must be positive");
  QuadratureRule rule;
  rule.nodes.resize(n);
  rule.weights.resize(n);
  // Newton's method on P_n from Chebyshev-like guesses; P_n by its three-term recurrence.
  for (int i = 0; i < n; ++i) {
    Real x = std::cos(0.5 * two_pi * (i + 0.75) / (n + 0.5));
    Real derivative = 1.0;
    for (int iter = 0; iter < 100; ++iter) {
      Real p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const Real p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1, p1 = p2;
      }
      if (n == 1) p0 = 1.0, p1 = x;
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const Real dx = p1 / derivative;
      x -= dx;
      if (std::abs(dx) < std::numeric_limits<Real>::epsilon() / 2) break;
    }
    // Map [-1, 1] to [0, 1]; nodes ascending.
    rule.nodes[n - 1 - i] = 0.5 * (x + 1.0);
    rule.weights[n - 1 - i] = 1.0 / ((1.0 - x * x) * derivative * derivative);
  }
  return rule;
}

}  // namespace tsi
