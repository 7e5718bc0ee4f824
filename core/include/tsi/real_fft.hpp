#pragma once
#include <vector>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Real-to-complex FFTs along the tau direction of a batch of real rows (howmany rows, n
/// columns, entry (i, j) at i + howmany * j), for the two-scale problem of a real model: its
/// U(tau) is real, so its Fourier coefficients are Hermitian (c_{-k} = conj c_k) and the modes
/// k = 0 .. n/2 carry all of them: half the memory and half the transform work of FftBatch.
/// The coefficients are howmany x (n/2 + 1), column k = mode k, with the same row stride.
///
/// The transforms read and write the caller's arrays (any alignment), a block of rows at a
/// time: the plans are made once in the constructor. With `parts` > 1 the rows are split into
/// that many contiguous ranges that threads may transform at the same time.
class TSI_API RealFftBatch {
 public:
  RealFftBatch(int n, int howmany, int parts = 1);
  ~RealFftBatch();
  RealFftBatch(const RealFftBatch&) = delete;
  RealFftBatch& operator=(const RealFftBatch&) = delete;

  /// Values at tau_j = 2 pi j / n -> coefficients, unnormalised (n times the Fourier
  /// coefficients): for callers that fold the 1/n into their next pass. Part p (-1: all rows).
  void forward_unnormalised(const Real* values, Complex* coefficients, int part = -1) const;
  /// Coefficients -> values at tau_j. The coefficients are left as they were; the imaginary
  /// parts of modes 0 and n/2 are taken as zero (as they are for a real U).
  void backward(const Complex* coefficients, Real* values, int part = -1) const;

  int n() const { return n_; }
  int howmany() const { return howmany_; }
  /// Stored modes, n/2 + 1.
  int modes() const { return n_ / 2 + 1; }
  int parts() const { return static_cast<int>(part_rows_.size()) - 1; }
  int part_begin(int p) const { return part_rows_[static_cast<std::size_t>(p)]; }

 private:
  void transform(const void* from, void* to, int direction, int part) const;
  void release();

  int n_, howmany_, block_;
  std::vector<int> part_rows_;
  void* block_plans_[2] = {nullptr, nullptr};  // forward (r2c), backward (c2r): block_ rows
  void* row_plans_[2] = {nullptr, nullptr};    // the same for one row (a part's last rows)
};

}  // namespace tsi
