#include "tsi/phi.hpp"

#include <array>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tsi {
namespace {

// Below this modulus the Taylor series is used: 1/(k+2)! < 2^-64 for k >= 19 and < 2^-113
// for k >= 32, and the terms fall at least geometrically, so 24 terms (34 in quad) leave
// the sum exact to rounding.
constexpr Real series_radius = 1.0;
constexpr int series_terms = std::numeric_limits<Real>::digits > 64 ? 34 : 24;

// 1/n! for n = 0 .. series_terms + 2, each from the previous by one division.
const std::array<Real, series_terms + 3>& inverse_factorials() {
  static const auto table = [] {
    std::array<Real, series_terms + 3> t{};
    t[0] = 1.0;
    for (int n = 1; n < static_cast<int>(t.size()); ++n) t[n] = t[n - 1] / n;
    return t;
  }();
  return table;
}

// sum_{k>=0} z^k / (k + shift)!  for |z| <= 1, by Horner from the tail.
Complex series(Complex z, int shift) {
  const auto& c = inverse_factorials();
  Complex sum(0);
  for (int k = series_terms; k >= 0; --k) sum = sum * z + c[k + shift];
  return sum;
}

}  // namespace

Complex expm1(Complex z) {
  // Re(e^z - 1) = expm1(x) cos y - 2 sin^2(y/2); Im = e^x sin y: no cancellation near 0.
  const Real x = z.real(), y = z.imag();
  const Real s = std::sin(0.5 * y);
  return {std::expm1(x) * std::cos(y) - 2.0 * s * s, std::exp(x) * std::sin(y)};
}

Complex phi1(Complex z) {
  if (std::abs(z) <= series_radius) return series(z, 1);
  return expm1(z) / z;
}

Complex phi2(Complex z) {
  if (std::abs(z) <= series_radius) return series(z, 2);
  return (expm1(z) - z) / (z * z);
}

Complex phi(int k, Complex z) {
  if (k < 0 || k > 20) throw std::invalid_argument("tsi::phi: k = " + std::to_string(k) + ", expected 0 to 20");
  if (k == 0) return std::exp(z);
  const Real r = std::abs(z);
  if (r <= std::max(Real(1), static_cast<Real>(k))) {
    // Terms |z|^m / (m + k)! with |z| <= k fall below 2^-60 of the first within 60 terms
    // (at k = 20: 20^60 / 80! ~ 1e-41); the sum of their moduli is within a factor 10 of
    // |phi_k| there, so no digits cancel.
    constexpr int terms = 64;
    Real inv = 1.0;  // 1 / (terms + k)!
    for (int n = 2; n <= terms + k; ++n) inv /= n;
    Complex sum(0);
    for (int m = terms; m >= 0; --m) {
      sum = sum * z + inv;
      inv *= (m + k);  // 1/(m + k - 1)!
    }
    return sum;
  }
  Complex value = phi1(z);
  Real inv_factorial = 1.0;  // 1/j!
  for (int j = 1; j < k; ++j) {
    inv_factorial /= j;
    value = (value - inv_factorial) / z;
  }
  return value;
}

}  // namespace tsi
