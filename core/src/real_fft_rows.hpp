#pragma once
#include <algorithm>

#include "tsi/types.hpp"

namespace tsi {

/// The real tau transforms of RealFftBatch for one block of rows at a time, between the
/// state's layout (coefficients: rows x (n/2 + 1), row stride `howmany`) and a small buffer of
/// grid values (rows x n, leading dimension rows): the tau grid's fused path, which keeps a
/// block's values in cache from one transform through the field to the other. Plans for full
/// blocks of `block_rows` rows and for the last, shorter block are made once; executions of
/// them on different arrays may run on several threads at once.
class RealFftRows {
 public:
  RealFftRows(int n, Index howmany, Index block_rows);
  ~RealFftRows();
  RealFftRows(const RealFftRows&) = delete;
  RealFftRows& operator=(const RealFftRows&) = delete;

  Index block_rows() const { return block_rows_; }
  Index blocks() const { return (howmany_ + block_rows_ - 1) / block_rows_; }
  Index block_begin(Index b) const { return b * block_rows_; }
  Index rows_of(Index b) const { return std::min(block_rows_, howmany_ - b * block_rows_); }

  /// Block b's coefficients (left as they were) -> its values at tau_j, in `values`.
  void backward(const Complex* coefficients, Index b, Real* values) const;
  /// Block b's values -> its coefficients, unnormalised (n times the Fourier coefficients).
  void forward_unnormalised(const Real* values, Index b, Complex* coefficients) const;

 private:
  void* plan(int direction, Index b) const;
  void release();

  int n_;
  Index howmany_, block_rows_;
  void* full_[2] = {nullptr, nullptr};  // forward (r2c), backward (c2r): block_rows_ rows
  void* last_[2] = {nullptr, nullptr};  // the same for a shorter last block
};

}  // namespace tsi
