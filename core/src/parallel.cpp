#include "tsi/algebra.hpp"
#include "tsi/parallel.hpp"

#include <algorithm>

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace tsi::algebra::detail {

void for_ranges(int threads, Index n, FunctionRef<void(Index, Index)> body) {
  // Below 2^16 entries (1 MB) a parallel region costs more than the pass it splits.
  constexpr Index smallest = Index(1) << 16;
  if (threads <= 1 || n < smallest) return body(0, n);
#if defined(_OPENMP)
  // Contiguous ranges, multiples of 8 entries (whole cache lines of doubles) but the last.
  const Index per_thread = ((n + threads - 1) / threads + 7) / 8 * 8;
#pragma omp parallel num_threads(threads)
  {
    const Index begin = std::min(n, static_cast<Index>(omp_get_thread_num()) * per_thread);
    const Index end = std::min(n, begin + per_thread);
    if (begin < end) body(begin, end);
  }
#else
  body(0, n);
#endif
}

}  // namespace tsi::algebra::detail

namespace tsi {

void parallel_for(int threads, Index count, FunctionRef<void(Index)> body) {
  if (threads <= 1 || count <= 1) {
    for (Index i = 0; i < count; ++i) body(i);
    return;
  }
#if defined(_OPENMP)
#pragma omp parallel for num_threads(threads) schedule(static)
  for (Index i = 0; i < count; ++i) body(i);
#else
  for (Index i = 0; i < count; ++i) body(i);
#endif
}

}  // namespace tsi
