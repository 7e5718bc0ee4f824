#include "tsi/fft.hpp"

#include <fmt/format.h>

#include <fftw3.h>

#include <atomic>
#include <mutex>
#include <string>

#include "tsi/error.hpp"

namespace tsi {
namespace {
// FFTW's planner is not thread-safe; execution of distinct plans is.
std::mutex planner_mutex;
std::atomic<int> threads_setting{1};
std::atomic<long> threads_min_values{65536};
}  // namespace

void set_fft_threads(int threads, long min_values) {
  if (threads < 1) throw ConfigError("fft threads", "got " + std::to_string(threads) + ", expected at least 1");
  threads_setting = threads;
  threads_min_values = min_values;
}

FftBatch::FftBatch(int n, int howmany, int parts) : n_(n), howmany_(howmany) {
  if (n <= 0 || howmany <= 0) throw Error("FftBatch: sizes must be positive");
  if (parts < 1 || parts > howmany) throw Error("FftBatch: parts must be from 1 to the number of rows");
  std::lock_guard<std::mutex> lock(planner_mutex);
  static const bool threads_ready = fftw_init_threads() != 0;
  const long values = static_cast<long>(n) * howmany;
  fftw_plan_with_nthreads(threads_ready && values >= threads_min_values ? threads_setting.load() : 1);
  buffer_ = reinterpret_cast<Complex*>(fftw_alloc_complex(static_cast<size_t>(n) * howmany));
  if (!buffer_)
    throw Error(fmt::format("FftBatch: cannot allocate {} x {} complex values ({:.3g} GB)", n, howmany,
                            16.0 * static_cast<double>(values) / 1e9));
  auto* raw = reinterpret_cast<fftw_complex*>(buffer_);
  // Transform along tau: n points with stride howmany, one transform per component.
  forward_plan_ = fftw_plan_many_dft(1, &n_, howmany_, raw, nullptr, howmany_, 1, raw, nullptr,
                                     howmany_, 1, FFTW_FORWARD, FFTW_ESTIMATE);
  backward_plan_ = fftw_plan_many_dft(1, &n_, howmany_, raw, nullptr, howmany_, 1, raw, nullptr,
                                      howmany_, 1, FFTW_BACKWARD, FFTW_ESTIMATE);
  // Parts: the same transforms on a contiguous range of rows each (stride howmany between
  // tau points, as above), planned on one thread: the threads are the caller's.
  bool planned = forward_plan_ && backward_plan_;
  if (parts > 1 && planned) {
    if (threads_ready) fftw_plan_with_nthreads(1);
    for (int p = 0; p <= parts; ++p) part_rows_.push_back(static_cast<int>(static_cast<long>(howmany) * p / parts));
    for (int p = 0; p < parts && planned; ++p) {
      const int rows = part_rows_[static_cast<std::size_t>(p) + 1] - part_rows_[static_cast<std::size_t>(p)];
      fftw_complex* first = raw + part_rows_[static_cast<std::size_t>(p)];
      for (int sign : {FFTW_FORWARD, FFTW_BACKWARD}) {
        part_plans_.push_back(
            fftw_plan_many_dft(1, &n_, rows, first, nullptr, howmany_, 1, first, nullptr, howmany_, 1, sign, FFTW_ESTIMATE));
        planned = planned && part_plans_.back();
      }
    }
  }
  if (!planned) {  // the destructor will not run: release what was made
    if (forward_plan_) fftw_destroy_plan(static_cast<fftw_plan>(forward_plan_));
    if (backward_plan_) fftw_destroy_plan(static_cast<fftw_plan>(backward_plan_));
    for (void* plan : part_plans_)
      if (plan) fftw_destroy_plan(static_cast<fftw_plan>(plan));
    fftw_free(buffer_);
    throw Error("FftBatch: FFTW could not make a plan");
  }
  if (part_rows_.empty()) part_rows_ = {0, howmany};
  data().setZero();
}

FftBatch::~FftBatch() {
  std::lock_guard<std::mutex> lock(planner_mutex);
  fftw_destroy_plan(static_cast<fftw_plan>(forward_plan_));
  fftw_destroy_plan(static_cast<fftw_plan>(backward_plan_));
  for (void* plan : part_plans_) fftw_destroy_plan(static_cast<fftw_plan>(plan));
  fftw_free(buffer_);
}

Eigen::Map<Matrix> FftBatch::data() { return Eigen::Map<Matrix>(buffer_, howmany_, n_); }

void FftBatch::forward() {
  fftw_execute(static_cast<fftw_plan>(forward_plan_));
  data() *= 1.0 / n_;
}

void FftBatch::forward_unnormalised() { fftw_execute(static_cast<fftw_plan>(forward_plan_)); }

void FftBatch::backward() { fftw_execute(static_cast<fftw_plan>(backward_plan_)); }

void FftBatch::forward_part(int p) {
  if (part_plans_.empty()) return forward_unnormalised();
  fftw_execute(static_cast<fftw_plan>(part_plans_[2 * static_cast<std::size_t>(p)]));
}

void FftBatch::backward_part(int p) {
  if (part_plans_.empty()) return backward();
  fftw_execute(static_cast<fftw_plan>(part_plans_[2 * static_cast<std::size_t>(p) + 1]));
}

}  // namespace tsi
