#pragma once
#include <map>
#include <memory>

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
  /// `fftw_threads`: FFTW's own threads for the batch (the run's Context::fft).
  GridFft(int n, Index columns, ThreadLimit fftw_threads = {})
      : fft_(n, static_cast<int>(columns), 1, fftw_threads), n_(n), columns_(columns) {}

  /// columns x n: row j is state j (grid samples or Fourier coefficients).
  Eigen::Map<Matrix> data() { return fft_.data(); }
  /// Unnormalised: sum_j a_j e^{-2 pi i j k / n}.
  void forward() { fft_.forward_unnormalised(); }
  /// Unnormalised: sum_k a_k e^{+2 pi i j k / n}.
  void backward() { fft_.backward(); }
  /// Work space of the same shape (a second grid, as a derivative needs), allocated on first use.
  Matrix& scratch() {
    if (scratch_.size() == 0) scratch_.resize(columns_, n_);
    return scratch_;
  }
  /// Columns (states) it transforms at once.
  Index columns() const { return columns_; }

 private:
  FftBatch fft_;
  int n_;
  Index columns_;
  Matrix scratch_;
};

/// GridFft for every batch size a model meets, planned on first use and kept: a run sees two
/// or three sizes (1 and n_tau), so nothing is planned inside a step after the first call. Not
/// synchronised: the model serialises its calls (its buffers are shared work space).
class GridFftPool {
 public:
  explicit GridFftPool(int n, ThreadLimit fftw_threads = {}) : n_(n), fftw_threads_(fftw_threads) {}
  GridFft& get(Index columns) {
    auto it = batches_.find(columns);
    if (it == batches_.end())
      it = batches_.emplace(columns, std::make_unique<GridFft>(n_, columns, fftw_threads_)).first;
    return *it->second;
  }
  ThreadLimit fftw_threads() const { return fftw_threads_; }

 private:
  int n_;
  ThreadLimit fftw_threads_;
  std::map<Index, std::unique_ptr<GridFft>> batches_;
};

}  // namespace tsi
