// phi1 and phi2 against an independent evaluation in long double (series near 0, the
// closed form elsewhere), over |z| from 1e-12 to 1e8.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>

#include "tsi/phi.hpp"

namespace {

using LComplex = std::complex<long double>;

// sum z^k / (k + shift)!, enough terms for |z| <= 2 in long double.
LComplex series(LComplex z, int shift) {
  LComplex sum = 0, term = 1;
  for (int j = 1; j <= shift; ++j) term /= static_cast<long double>(j);
  for (int k = 0; k < 60; ++k) {
    sum += term;
    term *= z / static_cast<long double>(k + shift + 1);
  }
  return sum;
}

LComplex reference(LComplex z, int which) {
  if (std::abs(z) <= 2.0L) return series(z, which);
  const LComplex e = std::exp(z);
  return which == 1 ? (e - 1.0L) / z : (e - 1.0L - z) / (z * z);
}

double relative_error(tsi::Complex got, LComplex want) {
  const LComplex diff = LComplex(got.real(), got.imag()) - want;
  return static_cast<double>(std::abs(diff) / std::abs(want));
}

}  // namespace

TEST_CASE("phi1 and phi2 are exact at 0") {
  CHECK(tsi::phi1(0.0) == tsi::Complex(1.0, 0.0));
  CHECK(tsi::phi2(0.0) == tsi::Complex(0.5, 0.0));
}

TEST_CASE("phi1 and phi2 have full precision near 0, where the closed form cancels") {
  for (double r : {1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5, 0.99, 1.01, 1.5}) {
    for (double angle : {0.0, 0.7, 1.5707963267948966, 2.5, 3.141592653589793, -1.2}) {
      const tsi::Complex z = std::polar(r, angle);
      const LComplex lz(z.real(), z.imag());
      CAPTURE(z);
      CHECK(relative_error(tsi::phi1(z), reference(lz, 1)) < 4e-16);
      CHECK(relative_error(tsi::phi2(z), reference(lz, 2)) < 4e-16);
    }
  }
}

TEST_CASE("phi1 and phi2 are accurate for large |z| on the imaginary axis and the left half-plane") {
  // The two-scale multipliers are z = -i k h / eps: purely imaginary, |z| up to 1e8.
  for (double y : {2.0, 10.0, 1e3, 1e5, 12345.678, 1e8, -1e8, -3.3e6}) {
    const tsi::Complex z(0.0, y);
    const LComplex lz(0.0L, static_cast<long double>(y));
    CAPTURE(y);
    // Absolute accuracy relative to the size 1/|z| of the terms (phi1 has zeros at 2 pi i k).
    const tsi::Complex p1 = tsi::phi1(z);
    CHECK(static_cast<double>(std::abs(LComplex(p1.real(), p1.imag()) - reference(lz, 1))) * std::abs(y) < 1e-15);
    CHECK(relative_error(tsi::phi2(z), reference(lz, 2)) < 1e-15);
  }
  for (double x : {-2.0, -50.0, -1e4}) {
    const tsi::Complex z(x, 0.3);
    const LComplex lz(static_cast<long double>(x), 0.3L);
    CHECK(relative_error(tsi::phi1(z), reference(lz, 1)) < 1e-15);
    CHECK(relative_error(tsi::phi2(z), reference(lz, 2)) < 1e-15);
  }
}

TEST_CASE("phi identities used by the symmetry of SE1 and SE2 hold") {
  // e^{-z} phi1(z) = phi1(-z) and phi1(z) = 1 + z phi2(z).
  for (double y : {1e-8, 0.3, 1.0, 7.0, 1e4}) {
    const tsi::Complex z(0.0, y);
    CHECK(std::abs(std::exp(-z) * tsi::phi1(z) - tsi::phi1(-z)) < 1e-15);
    CHECK(std::abs(tsi::phi1(z) - (1.0 + z * tsi::phi2(z))) < 1e-15);
  }
}
