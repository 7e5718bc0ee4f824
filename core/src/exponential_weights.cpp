#include "tsi/exponential_weights.hpp"

#include <stdexcept>

#include "tsi/phi.hpp"

namespace tsi {

InterpolatoryWeights::InterpolatoryWeights(std::vector<Real> nodes) : nodes_(std::move(nodes)) {
  const int r = static_cast<int>(nodes_.size());
  if (r < 1 || r > 20) throw std::invalid_argument("InterpolatoryWeights: 1 to 20 nodes");
  monomials_.assign(r, std::vector<Real>(r, 0.0));
  for (int j = 0; j < r; ++j) {
    std::vector<Real> poly{1.0};  // increasing degree
    Real denominator = 1.0;
    for (int i = 0; i < r; ++i) {
      if (i == j) continue;
      std::vector<Real> next(poly.size() + 1, 0.0);  // times (s - s_i)
      for (size_t m = 0; m < poly.size(); ++m) {
        next[m] -= nodes_[i] * poly[m];
        next[m + 1] += poly[m];
      }
      poly.swap(next);
      denominator *= nodes_[j] - nodes_[i];
    }
    for (int m = 0; m < r; ++m) monomials_[j][m] = poly[m] / denominator;
  }
}

std::vector<Complex> InterpolatoryWeights::operator()(Real kappa, Complex z) const {
  const int r = static_cast<int>(nodes_.size());
  std::vector<Complex> moments(r);  // int_0^kappa e^{(kappa - s) z} s^m ds
  Real factorial = 1.0, power = kappa;
  for (int m = 0; m < r; ++m) {
    if (m > 0) factorial *= m, power *= kappa;
    moments[m] = power * factorial * phi(m + 1, kappa * z);
  }
  std::vector<Complex> w(r, Complex(0));
  for (int j = 0; j < r; ++j)
    for (int m = 0; m < r; ++m) w[j] += monomials_[j][m] * moments[m];
  return w;
}

}  // namespace tsi
