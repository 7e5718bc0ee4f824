#pragma once
#include <complex>
#include <memory>
#include <vector>

#include "tsi/context.hpp"
#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// In-place complex FFTs along the tau direction of a batch of states stored column by
/// column (howmany rows, n columns; entry (i, j) at i + howmany * j). Plans are made once
/// in the constructor (planning is serialised across threads) and reused by every call.
/// With `parts` > 1 the rows are also split into that many contiguous ranges, so that threads
/// can transform disjoint rows of the one buffer at the same time. `fftw_threads`: the threads
/// FFTW itself may use for the whole batch (Context::fft; 1, the default, for none: small
/// batches stay on one thread, where splitting costs more than it saves).
///
/// Large batches (at least 32 rows of an even number, at least 32, of points) go through a small contiguous
/// buffer, a few rows at a time: FFTW_ESTIMATE's plan for the strided batch walks the whole
/// buffer once per transform (2.7 ms for 256 x 256 here), the buffered one stays in cache
/// (0.32 ms), and unlike FFTW_MEASURE it is the same plan in every process, so results do
/// not depend on timings. A buffered batch allocates its howmany x n buffer only when data() is
/// first called: transform() works on the caller's memory through the blocks alone.
class TSI_API FftBatch {
 public:
  FftBatch(int n, int howmany, int parts = 1, ThreadLimit fftw_threads = {});
  ~FftBatch();
  FftBatch(const FftBatch&) = delete;
  FftBatch& operator=(const FftBatch&) = delete;

  /// The work buffer, howmany x n (a buffered batch allocates it here, on the first call).
  Eigen::Map<Matrix> data();
  /// Transforms howmany x n values at `from` into `to` (the buffer's layout; `to` may be `from`)
  /// without the batch's buffer where it is buffered: forward (direction 0, unnormalised) or
  /// backward (1), with `shift` (howmany values, or null) added to column 0 on the way in and
  /// every result multiplied by `scale` on the way out (the same products as a pass after).
  /// With `part` (0 <= part < parts()) only that part's rows, through its own block: parts may
  /// be transformed at the same time on different threads.
  void transform(const Complex* from, Complex* to, int direction, Real scale = 1, const Complex* shift = nullptr,
                 int part = -1);
  /// Values at tau_j = 2*pi*j/n -> Fourier coefficients (normalised by 1/n).
  void forward();
  /// The same without the 1/n: for callers that fold the normalisation into their next pass.
  void forward_unnormalised();
  /// Fourier coefficients -> values at tau_j.
  void backward();
  /// The same on the rows of part p only (0 <= p < parts; unnormalised both ways).
  void forward_part(int p);
  void backward_part(int p);
  int parts() const { return static_cast<int>(part_rows_.size()) - 1; }
  /// Rows of part p: [part_begin(p), part_begin(p + 1)).
  int part_begin(int p) const { return part_rows_[static_cast<std::size_t>(p)]; }

  int n() const { return n_; }
  int howmany() const { return howmany_; }
  /// True when the batch goes through the contiguous buffers (see above).
  bool buffered() const { return !blocks_.empty(); }
  /// True when a batch of these sizes goes through the small buffers; false when it holds a
  /// whole howmany x n buffer (the memory of a run: a vector of the state's size more).
  /// `fftw_split`: FFTW's own threads split its transforms (they then go strided).
  static bool buffers(int n, int howmany, bool fftw_split = false);

 private:
  /// The buffer, allocated (and zeroed) on first use.
  Complex* buffer();
  /// transform() of the buffer's rows (part `part`, -1: all) into itself.
  void buffer_transform(int direction, int part);
  void release();

  int n_, howmany_;
  Complex* buffer_ = nullptr;
  void* plans_[2] = {nullptr, nullptr};     // forward, backward: every row (strided)
  std::vector<int> part_rows_;              // parts + 1 row boundaries
  std::vector<void*> part_plans_;           // strided: forward and backward plan of each part
  std::vector<Complex*> blocks_;            // buffered: n x block_rows contiguous, one per part
  void* block_plans_[2] = {nullptr, nullptr};  // buffered: block_rows transforms, contiguous
  void* row_plans_[2] = {nullptr, nullptr};    // buffered: one transform (a part's last rows)
};

}  // namespace tsi
