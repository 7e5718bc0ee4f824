// tsi::FftBatch against a direct DFT in long double: the strided path (few rows), the buffered
// one (at least 32 rows, a last block of fewer than 4 rows), and the parts threads use.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <tuple>

#include "tsi/fft.hpp"

namespace {

using tsi::Complex;
using tsi::Matrix;

// Row i of the result: sum_j a(i, j) e^{sign 2 pi i j k / n}, unnormalised.
Matrix direct_dft(const Matrix& a, int sign) {
  const long n = a.cols();
  Matrix out(a.rows(), n);
  for (long i = 0; i < a.rows(); ++i)
    for (long k = 0; k < n; ++k) {
      std::complex<long double> sum = 0.0L;
      for (long j = 0; j < n; ++j) {
        const long double angle = sign * 2.0L * std::numbers::pi_v<long double> * static_cast<long double>((j * k) % n) /
                                  static_cast<long double>(n);
        sum += std::complex<long double>(a(i, j).real(), a(i, j).imag()) * std::polar(1.0L, angle);
      }
      out(i, k) = Complex(static_cast<double>(sum.real()), static_cast<double>(sum.imag()));
    }
  return out;
}

double relative(const Matrix& a, const Matrix& b) { return (a - b).norm() / b.norm(); }

}  // namespace

TEST_CASE("fft batch: strided and buffered batches and their parts agree with a direct DFT") {
  // 6 rows: strided. 37 rows of 64 points: buffered, 9 blocks of 4 and a last row alone.
  for (const auto& [rows, n, parts] : {std::tuple{6, 64, 1}, std::tuple{37, 64, 1}, std::tuple{37, 64, 3},
                                       std::tuple{64, 256, 2}, std::tuple{6, 64, 2}}) {
    CAPTURE(rows);
    CAPTURE(n);
    CAPTURE(parts);
    tsi::FftBatch batch(n, rows, parts);
    CHECK(batch.buffered() == (rows >= 32));
    const Matrix a = Matrix::Random(rows, n);
    batch.data() = a;
    batch.forward_unnormalised();
    const Matrix forward = batch.data();
    CHECK(relative(forward, direct_dft(a, -1)) < 1e-14);
    batch.data() = a;
    batch.backward();
    CHECK(relative(batch.data(), direct_dft(a, +1)) < 1e-14);
    // forward() normalises; backward undoes it.
    batch.data() = a;
    batch.forward();
    batch.backward();
    CHECK(relative(batch.data(), a) < 1e-14);
    // The parts, one after the other, transform every row exactly as the whole batch does.
    batch.data() = a;
    for (int p = 0; p < batch.parts(); ++p) batch.forward_part(p);
    CHECK(batch.data() == forward);
    CHECK(batch.part_begin(0) == 0);
    CHECK(batch.part_begin(batch.parts()) == rows);
  }
}

TEST_CASE("fft batch: transform works from and into the caller's memory, by parts, with a shift and a scale") {
  // The same numbers as the buffer's own transforms (bit for bit), for the strided and the
  // buffered batch, whole and by parts, and in place.
  for (const auto& [rows, n, parts] : {std::tuple{6, 64, 1}, std::tuple{6, 64, 2}, std::tuple{37, 64, 1},
                                       std::tuple{37, 64, 3}}) {
    CAPTURE(rows);
    CAPTURE(parts);
    tsi::FftBatch reference(n, rows), batch(n, rows, parts);
    Matrix a(rows, n);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < n; ++j) a(i, j) = Complex(std::sin(0.3 * i + 0.7 * j), std::cos(1.1 * i - 0.2 * j));
    tsi::Vector shift(rows);
    for (int i = 0; i < rows; ++i) shift(i) = Complex(0.01 * i, -0.02 * i);
    for (int direction = 0; direction < 2; ++direction) {
      CAPTURE(direction);
      // The reference: the shift added to column 0, the buffer's transform, then the scale.
      reference.data() = a;
      reference.data().col(0) += shift;
      if (direction == 0)
        reference.forward_unnormalised();
      else
        reference.backward();
      const Matrix expected = reference.data() * (1.0 / n);
      Matrix out(rows, n);
      if (parts == 1) {
        batch.transform(a.data(), out.data(), direction, 1.0 / n, shift.data());
      } else {
        for (int p = 0; p < parts; ++p) batch.transform(a.data(), out.data(), direction, 1.0 / n, shift.data(), p);
      }
      CHECK(out == expected);
      Matrix in_place = a;
      batch.transform(in_place.data(), in_place.data(), direction, 1.0 / n, shift.data());
      CHECK(in_place == expected);
    }
  }
}
