#include "tsi/fft.hpp"
#include "tsi/real_fft.hpp"

#include <fmt/format.h>


#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>

#include "fftw_planner.hpp"
#include "fftw_precision.hpp"
#include "tsi/error.hpp"

namespace tsi {
namespace detail {
std::mutex& fftw_planner_mutex() {
  static std::mutex mutex;
  return mutex;
}
bool fftw_threads_ready() {
  static const bool ready = TSI_FFTW(init_threads)() != 0;
  return ready;
}
}  // namespace detail

namespace {

// Rows per contiguous block of a buffered batch, and the smallest batch that is buffered
// (measured, 256-point transforms: 4 rows best from 64 to 1024 rows; at 16 rows the strided
// plan is faster, at 32 the buffered one by 1.7x).
constexpr int block_rows = 4;
constexpr int buffered_min_rows = 32;
constexpr int buffered_min_points = 32;

TSI_FFTW(plan) as_plan(void* p) { return static_cast<TSI_FFTW(plan)>(p); }
TSI_FFTW(complex)* raw(Complex* p) { return reinterpret_cast<TSI_FFTW(complex)*>(p); }
}  // namespace

bool FftBatch::buffers(int n, int howmany, bool fftw_split) {
  return !fftw_split && howmany >= buffered_min_rows && n >= buffered_min_points && n % 2 == 0;
}

FftBatch::FftBatch(int n, int howmany, int parts, ThreadLimit fftw_threads) : n_(n), howmany_(howmany) {
  if (n <= 0 || howmany <= 0) throw Error("FftBatch: sizes must be positive");
  if (parts < 1 || parts > howmany) throw Error("FftBatch: parts must be from 1 to the number of rows");
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  const bool threads_ready = detail::fftw_threads_ready();
  const long values = static_cast<long>(n) * howmany;
  const int fftw_team = threads_ready ? fftw_threads.for_size(values) : 1;
  const bool fftw_split = fftw_team > 1;
  if (threads_ready) TSI_FFTW(plan_with_nthreads)(fftw_team);
  for (int p = 0; p <= parts; ++p) part_rows_.push_back(static_cast<int>(static_cast<long>(howmany) * p / parts));
  const int signs[2] = {FFTW_FORWARD, FFTW_BACKWARD};
  bool planned = true;
  // FFTW's own threads (tsi --fft-threads) split the strided plans; otherwise large batches
  // are buffered.
  // n even: every row of a block then has the block's alignment, as fftw_execute_dft needs.
  const bool buffered = buffers(n, howmany, fftw_split);
  if (!buffered) {  // the strided plans are made on the buffer itself
    buffer_ = reinterpret_cast<Complex*>(TSI_FFTW(alloc_complex)(static_cast<size_t>(n) * howmany));
    if (!buffer_)
      throw Error(fmt::format("FftBatch: cannot allocate {} x {} complex values ({:.3g} GB)", n, howmany,
                              static_cast<double>(sizeof(Complex)) * static_cast<double>(values) / 1e9));
  }
  if (buffered) {
    for (int p = 0; p < parts && planned; ++p) {
      blocks_.push_back(reinterpret_cast<Complex*>(TSI_FFTW(alloc_complex)(static_cast<size_t>(n) * block_rows)));
      planned = blocks_.back() != nullptr;
    }
    for (int d = 0; d < 2 && planned; ++d) {  // on block 0; executed on every block (same alignment)
      block_plans_[d] = TSI_FFTW(plan_many_dft)(1, &n_, block_rows, raw(blocks_[0]), nullptr, 1, n_, raw(blocks_[0]),
                                           nullptr, 1, n_, signs[d], FFTW_ESTIMATE);
      row_plans_[d] = TSI_FFTW(plan_dft_1d)(n_, raw(blocks_[0]), raw(blocks_[0]), signs[d], FFTW_ESTIMATE);
      planned = block_plans_[d] && row_plans_[d];
    }
  } else {
    // Transform along tau: n points with stride howmany, one transform per row; and the same
    // per part, on that part's rows.
    for (int d = 0; d < 2 && planned; ++d) {
      plans_[d] = TSI_FFTW(plan_many_dft)(1, &n_, howmany_, raw(buffer_), nullptr, howmany_, 1, raw(buffer_), nullptr,
                                     howmany_, 1, signs[d], FFTW_ESTIMATE);
      planned = plans_[d] != nullptr;
    }
    if (parts > 1 && threads_ready) TSI_FFTW(plan_with_nthreads)(1);  // the threads are the caller's
    for (int p = 0; parts > 1 && p < parts && planned; ++p) {
      const int rows = part_rows_[static_cast<std::size_t>(p) + 1] - part_rows_[static_cast<std::size_t>(p)];
      TSI_FFTW(complex)* first = raw(buffer_ + part_rows_[static_cast<std::size_t>(p)]);
      for (int d = 0; d < 2 && planned; ++d) {
        part_plans_.push_back(
            TSI_FFTW(plan_many_dft)(1, &n_, rows, first, nullptr, howmany_, 1, first, nullptr, howmany_, 1, signs[d], FFTW_ESTIMATE));
        planned = part_plans_.back() != nullptr;
      }
    }
  }
  if (!planned) {  // the destructor will not run: release what was made
    release();
    throw Error(fmt::format("FftBatch: FFTW could not make a plan (or allocate a block) for {} x {}", n, howmany));
  }
  if (buffer_) data().setZero();
}

Complex* FftBatch::buffer() {
  if (!buffer_) {
    const auto count = static_cast<size_t>(n_) * static_cast<size_t>(howmany_);
    buffer_ = reinterpret_cast<Complex*>(TSI_FFTW(alloc_complex)(count));
    if (!buffer_)
      throw Error(fmt::format("FftBatch: cannot allocate {} x {} complex values ({:.3g} GB)", n_, howmany_,
                              static_cast<double>(sizeof(Complex)) * static_cast<double>(count) / 1e9));
    std::fill(buffer_, buffer_ + count, Complex(0.0));
  }
  return buffer_;
}

void FftBatch::release() {
  for (void* plan : {plans_[0], plans_[1], block_plans_[0], block_plans_[1], row_plans_[0], row_plans_[1]})
    if (plan) TSI_FFTW(destroy_plan)(as_plan(plan));
  for (void* plan : part_plans_)
    if (plan) TSI_FFTW(destroy_plan)(as_plan(plan));
  for (Complex* block : blocks_)
    if (block) TSI_FFTW(free)(block);
  if (buffer_) TSI_FFTW(free)(buffer_);
}

FftBatch::~FftBatch() {
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  release();
}

Eigen::Map<Matrix> FftBatch::data() { return Eigen::Map<Matrix>(buffer(), howmany_, n_); }

void FftBatch::transform(const Complex* from, Complex* to, int direction, Real scale, const Complex* shift,
                         int part) {
  const std::size_t stride = static_cast<std::size_t>(howmany_);
  const int first = part < 0 ? 0 : part_rows_[static_cast<std::size_t>(part)];
  const int last = part < 0 ? howmany_ : part_rows_[static_cast<std::size_t>(part) + 1];
  if (blocks_.empty()) {  // strided
    const bool whole = part < 0 || part_plans_.empty();
    const int r0 = whole ? 0 : first, rows = whole ? howmany_ : last - first;
    void* plan = whole ? plans_[direction] : part_plans_[2 * static_cast<std::size_t>(part) + direction];
    // The in-place plans run on `to` itself where it has the alignment they were made with:
    // one copy (from -> to) instead of two through the buffer.
    const auto alignment = [](const Complex* p) { return TSI_FFTW(alignment_of)(detail::fftw_real(reinterpret_cast<const Real*>(p))); };
    const bool on_to = to != buffer_ && alignment(to + r0) == alignment(buffer_ + r0);
    if (rows == howmany_) {  // the whole array: contiguous passes (a block of rows is strided)
      Complex* work = on_to ? to : buffer_;
      const Index size = static_cast<Index>(howmany_) * n_;
      if (from != work) std::copy(from, from + size, work);
      if (shift) Eigen::Map<Vector>(work, howmany_) += Eigen::Map<const Vector>(shift, howmany_);
      TSI_FFTW(execute_dft)(as_plan(plan), raw(work), raw(work));
      if (scale != 1)  // the doubles scaled: a real factor, not a complex product
        Eigen::Map<RealVector>(reinterpret_cast<Real*>(to), 2 * size) =
            Eigen::Map<const RealVector>(reinterpret_cast<const Real*>(work), 2 * size) * scale;
      else if (to != work)
        std::copy(work, work + size, to);
      return;
    }
    if (on_to) {
      auto rows_of_to = Eigen::Map<Matrix>(to, howmany_, n_).middleRows(r0, rows);
      if (from != to) rows_of_to = Eigen::Map<const Matrix>(from, howmany_, n_).middleRows(r0, rows);
      if (shift) rows_of_to.col(0) += Eigen::Map<const Vector>(shift, howmany_).segment(r0, rows);
      TSI_FFTW(execute_dft)(as_plan(plan), raw(to + r0), raw(to + r0));
      if (scale != 1) rows_of_to *= scale;
      return;
    }
    Eigen::Map<Matrix> buf = data();
    auto part_rows = buf.middleRows(r0, rows);
    if (from != buffer_) part_rows = Eigen::Map<const Matrix>(from, howmany_, n_).middleRows(r0, rows);
    if (shift) part_rows.col(0) += Eigen::Map<const Vector>(shift, howmany_).segment(r0, rows);
    TSI_FFTW(execute)(as_plan(plan));
    if (scale != 1)
      Eigen::Map<Matrix>(to, howmany_, n_).middleRows(r0, rows) = part_rows * scale;
    else if (to != buffer_)
      Eigen::Map<Matrix>(to, howmany_, n_).middleRows(r0, rows) = part_rows;
    return;
  }
  // Rows r .. r + k - 1 into the block, transposed (each row's n points contiguous), and back.
  Complex* b = blocks_[part < 0 ? 0 : static_cast<std::size_t>(part)];
  for (int r = first; r < last; r += block_rows) {
    const int k = std::min(block_rows, last - r);
    const Complex* in = from + r;
    for (int j = 0; j < n_; ++j)
      for (int i = 0; i < k; ++i) b[static_cast<std::size_t>(i) * n_ + j] = in[j * stride + i];
    if (shift)
      for (int i = 0; i < k; ++i) b[static_cast<std::size_t>(i) * n_] += shift[r + i];
    if (k == block_rows) {
      TSI_FFTW(execute_dft)(as_plan(block_plans_[direction]), raw(b), raw(b));
    } else {
      for (int i = 0; i < k; ++i) {
        Complex* row = b + static_cast<std::size_t>(i) * n_;
        TSI_FFTW(execute_dft)(as_plan(row_plans_[direction]), raw(row), raw(row));
      }
    }
    Complex* out = to + r;
    if (scale != 1)
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < k; ++i) out[j * stride + i] = b[static_cast<std::size_t>(i) * n_ + j] * scale;
    else
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < k; ++i) out[j * stride + i] = b[static_cast<std::size_t>(i) * n_ + j];
  }
}

void FftBatch::forward() {
  forward_unnormalised();
  data() *= Real(1) / n_;
}

// The buffer's own transforms: transform() from the buffer into itself (allocated first).
void FftBatch::forward_unnormalised() { buffer_transform(0, -1); }

void FftBatch::backward() { buffer_transform(1, -1); }

void FftBatch::forward_part(int p) { buffer_transform(0, p); }

void FftBatch::backward_part(int p) { buffer_transform(1, p); }

void FftBatch::buffer_transform(int direction, int part) {
  Complex* b = buffer();
  transform(b, b, direction, 1.0, nullptr, part);
}

}  // namespace tsi

namespace tsi {
namespace {
// Rows per plan execution of a RealFftBatch: the rows of a block are adjacent in memory, so
// each tau point of the block is one contiguous run of values.
constexpr int real_block_rows = 8;
}  // namespace

RealFftBatch::RealFftBatch(int n, int howmany, int parts)
    : n_(n), howmany_(howmany), block_(std::min(howmany, real_block_rows)) {
  if (n <= 0 || n % 2 != 0 || howmany <= 0) throw Error("RealFftBatch: n must be positive and even, howmany positive");
  if (parts < 1 || parts > howmany) throw Error("RealFftBatch: parts must be from 1 to the number of rows");
  for (int p = 0; p <= parts; ++p) part_rows_.push_back(static_cast<int>(static_cast<long>(howmany) * p / parts));
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  const bool threads_ready = detail::fftw_threads_ready();
  if (threads_ready) TSI_FFTW(plan_with_nthreads)(1);  // the callers' threads split the rows
  // FFTW_ESTIMATE plans never touch the arrays they are made with, and FFTW_UNALIGNED plans
  // run on any: small stand-ins serve for planning, the callers' arrays at execution.
  detail::FftwReal* real_standin = TSI_FFTW(alloc_real)(2);
  TSI_FFTW(complex)* complex_standin = TSI_FFTW(alloc_complex)(2);
  bool planned = real_standin && complex_standin;
  const unsigned flags = FFTW_ESTIMATE | FFTW_UNALIGNED;
  for (int rows : {block_, 1}) {  // a block, and single rows for a part's last ones
    if (!planned) break;
    void** plans = rows == block_ ? block_plans_ : row_plans_;
    if (rows == 1 && block_ == 1) break;  // the block plans are the row plans
    plans[0] = TSI_FFTW(plan_many_dft_r2c)(1, &n_, rows, real_standin, nullptr, howmany_, 1, complex_standin, nullptr,
                                      howmany_, 1, flags);
    plans[1] = TSI_FFTW(plan_many_dft_c2r)(1, &n_, rows, complex_standin, nullptr, howmany_, 1, real_standin, nullptr,
                                      howmany_, 1, flags | FFTW_PRESERVE_INPUT);
    planned = plans[0] && plans[1];
  }
  if (real_standin) TSI_FFTW(free)(real_standin);
  if (complex_standin) TSI_FFTW(free)(complex_standin);
  if (!planned) {
    release();
    throw Error(fmt::format("RealFftBatch: FFTW could not make a plan for {} x {}", n, howmany));
  }
}

void RealFftBatch::release() {
  for (void* plan : {block_plans_[0], block_plans_[1], row_plans_[0], row_plans_[1]})
    if (plan) TSI_FFTW(destroy_plan)(as_plan(plan));
}

RealFftBatch::~RealFftBatch() {
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  release();
}

void RealFftBatch::transform(const void* from, void* to, int direction, int part) const {
  const int first = part < 0 ? 0 : part_rows_[static_cast<std::size_t>(part)];
  const int last = part < 0 ? howmany_ : part_rows_[static_cast<std::size_t>(part) + 1];
  const auto execute = [&](void* plan, int row) {
    if (direction == 0)
      TSI_FFTW(execute_dft_r2c)(as_plan(plan), detail::fftw_real(static_cast<const Real*>(from) + row),
                           reinterpret_cast<TSI_FFTW(complex)*>(static_cast<Complex*>(to) + row));
    else  // FFTW_PRESERVE_INPUT: the coefficients are only read
      TSI_FFTW(execute_dft_c2r)(as_plan(plan),
                           reinterpret_cast<TSI_FFTW(complex)*>(const_cast<Complex*>(static_cast<const Complex*>(from)) + row),
                           detail::fftw_real(static_cast<Real*>(to) + row));
  };
  int row = first;
  for (; row + block_ <= last; row += block_) execute(block_plans_[direction], row);
  for (; row < last; ++row) execute(block_ == 1 ? block_plans_[direction] : row_plans_[direction], row);
}

void RealFftBatch::forward_unnormalised(const Real* values, Complex* coefficients, int part) const {
  transform(values, coefficients, 0, part);
}

void RealFftBatch::backward(const Complex* coefficients, Real* values, int part) const {
  transform(coefficients, values, 1, part);
}

}  // namespace tsi
