#include "real_fft_rows.hpp"

#include <fmt/format.h>

#include <climits>
#include <mutex>

#include "fftw_planner.hpp"
#include "fftw_precision.hpp"
#include "tsi/error.hpp"

namespace tsi {
namespace {
TSI_FFTW(plan) as_plan(void* p) { return static_cast<TSI_FFTW(plan)>(p); }
}  // namespace

RealFftRows::RealFftRows(int n, Index howmany, Index block_rows)
    : n_(n), howmany_(howmany), block_rows_(std::min(block_rows, howmany)) {
  if (n <= 0 || n % 2 != 0 || howmany <= 0 || block_rows <= 0 || howmany > INT_MAX)
    throw Error(fmt::format("RealFftRows: n = {} must be positive and even, howmany = {} and block_rows = {} "
                            "positive (howmany at most {})",
                            n, howmany, block_rows, INT_MAX));
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  if (detail::fftw_threads_ready()) TSI_FFTW(plan_with_nthreads)(1);  // the callers' threads take blocks
  // As RealFftBatch: FFTW_ESTIMATE plans never touch the arrays they are made with, and
  // FFTW_UNALIGNED ones run on any, so small stand-ins serve for planning.
  detail::FftwReal* real_standin = TSI_FFTW(alloc_real)(2);
  TSI_FFTW(complex)* complex_standin = TSI_FFTW(alloc_complex)(2);
  bool planned = real_standin && complex_standin;
  const unsigned flags = FFTW_ESTIMATE | FFTW_UNALIGNED;
  const int stride = static_cast<int>(howmany);
  const Index last = howmany % block_rows_;
  for (const Index rows : {block_rows_, last}) {
    if (!planned || rows == 0) continue;
    void** plans = rows == block_rows_ ? full_ : last_;
    const int r = static_cast<int>(rows);
    // The coefficients: stride `howmany` between modes, rows adjacent; the values: rows x n.
    plans[0] = TSI_FFTW(plan_many_dft_r2c)(1, &n_, r, real_standin, nullptr, r, 1, complex_standin, nullptr, stride, 1,
                                      flags);
    plans[1] = TSI_FFTW(plan_many_dft_c2r)(1, &n_, r, complex_standin, nullptr, stride, 1, real_standin, nullptr, r, 1,
                                      flags | FFTW_PRESERVE_INPUT);
    planned = plans[0] && plans[1];
  }
  if (real_standin) TSI_FFTW(free)(real_standin);
  if (complex_standin) TSI_FFTW(free)(complex_standin);
  if (!planned) {
    release();
    throw Error(fmt::format("RealFftRows: FFTW could not make a plan for {} x {} by blocks of {}", n, howmany,
                            block_rows_));
  }
}

void RealFftRows::release() {
  for (void* p : {full_[0], full_[1], last_[0], last_[1]})
    if (p) TSI_FFTW(destroy_plan)(as_plan(p));
}

RealFftRows::~RealFftRows() {
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  release();
}

void* RealFftRows::plan(int direction, Index b) const {
  return rows_of(b) == block_rows_ ? full_[direction] : last_[direction];
}

void RealFftRows::backward(const Complex* coefficients, Index b, Real* values) const {
  // FFTW_PRESERVE_INPUT: the coefficients are only read.
  TSI_FFTW(execute_dft_c2r)(as_plan(plan(1, b)),
                       reinterpret_cast<TSI_FFTW(complex)*>(const_cast<Complex*>(coefficients + block_begin(b))),
                       detail::fftw_real(values));
}

void RealFftRows::forward_unnormalised(const Real* values, Index b, Complex* coefficients) const {
  TSI_FFTW(execute_dft_r2c)(as_plan(plan(0, b)), detail::fftw_real(values),
                       reinterpret_cast<TSI_FFTW(complex)*>(coefficients + block_begin(b)));
}

}  // namespace tsi
