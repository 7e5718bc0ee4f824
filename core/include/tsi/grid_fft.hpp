#pragma once
#include "tsi/fft.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Transforms along a spatial grid of n points for `columns` states at once, one batched
/// transform each way (the spatial models' helper: NLS, Klein-Gordon). tsi::FftBatch
/// transforms along the second index of a (howmany x n) buffer, so the states are stored
/// transposed, one per row. Sign convention (FFTW's): forward is sum_j a_j e^{-2 pi i jk/n},
/// backward sum_k a_k e^{+2 pi i jk/n}, neither normalised, so that
/// backward(forward(a)) = n a; index k >= n/2 holds the wave number k - n.
class GridFft {
 public:
  GridFft(int n, Index columns) : fft_(n, static_cast<int>(columns)), scratch_(columns, n) {}

  /// columns x n: row j is state j (grid samples or Fourier coefficients).
  Eigen::Map<Matrix> data() { return fft_.data(); }
  /// Unnormalised: sum_j a_j e^{-2 pi i j k / n}.
  void forward() { fft_.forward_unnormalised(); }
  /// Unnormalised: sum_k a_k e^{+2 pi i j k / n}.
  void backward() { fft_.backward(); }
  /// Work space of the same shape (a second grid, as a derivative needs).
  Matrix& scratch() { return scratch_; }

 private:
  FftBatch fft_;
  Matrix scratch_;
};

}  // namespace tsi
