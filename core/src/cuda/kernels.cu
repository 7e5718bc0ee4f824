// The algebra's kernels (kernels.hpp): memory-bound passes, one thread per complex entry,
// double2 loads (16 bytes) coalesced across the warp.
#include <cmath>

#include "cuda_check.hpp"
#include "kernels.hpp"

namespace tsi::cuda {
namespace {

constexpr int threads = 256;

__device__ inline double2 mul(double2 a, double2 b) { return {a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x}; }

// The coefficient of term t at entry i of run b (b = i / run, computed by the caller).
__device__ inline double2 coefficient(const Term& t, long long i, long long b) {
  if (!t.d) return {t.scalar, 0.0};
  return reinterpret_cast<const double2*>(t.d)[t.run == 1 ? i : b];
}

__device__ inline void combine_at(const Combination& c, double2* out, long long i, long long b) {
  double2 acc = c.start ? reinterpret_cast<const double2*>(c.start)[i] : double2{0.0, 0.0};
  for (int j = 0; j < c.count; ++j) {
    const double2 p = mul(coefficient(c.terms[j], i, b), reinterpret_cast<const double2*>(c.terms[j].x)[i]);
    acc.x += p.x;
    acc.y += p.y;
  }
  out[i] = acc;
}

// Every coefficient of one value per entry (or a scalar): a flat grid.
__global__ void combine_flat(Combination c, double2* out, long long n) {
  for (long long i = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<long long>(gridDim.x) * blockDim.x)
    combine_at(c, out, i, 0);
}

// Coefficients of one value per run of `run` entries (the two-scale L: one per tau mode): run
// b is the grid's row blockIdx.y, so no thread divides.
__global__ void combine_runs(Combination c, double2* out, long long run) {
  const long long b = blockIdx.y;
  for (long long k = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; k < run;
       k += static_cast<long long>(gridDim.x) * blockDim.x)
    combine_at(c, out, b * run + k, b);
}

// Runs that differ between terms: each term divides.
__global__ void combine_divided(Combination c, double2* out, long long n) {
  for (long long i = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<long long>(gridDim.x) * blockDim.x) {
    double2 acc = c.start ? reinterpret_cast<const double2*>(c.start)[i] : double2{0.0, 0.0};
    for (int j = 0; j < c.count; ++j) {
      const Term& t = c.terms[j];
      const double2 p = mul(coefficient(t, i, t.run > 1 ? i / t.run : i), reinterpret_cast<const double2*>(t.x)[i]);
      acc.x += p.x;
      acc.y += p.y;
    }
    out[i] = acc;
  }
}

unsigned flat_blocks(long long n) {
  const long long blocks = (n + threads - 1) / threads;
  return static_cast<unsigned>(blocks < 65536 * 16 ? blocks : 65536 * 16);
}

enum class Reduction { finite, inner, max_abs2, increment };

// Per-block partials of a reduction: out[2 * block + lane].
__global__ void reduce_partials(Reduction kind, const double2* a, const double2* b, long long n, double* out) {
  __shared__ double s0[threads], s1[threads];
  double r0 = 0.0, r1 = 0.0;
  for (long long i = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<long long>(gridDim.x) * blockDim.x) {
    const double2 u = a[i];
    switch (kind) {
      case Reduction::finite:  // counts the non-finite entries
        r0 += (isfinite(u.x) && isfinite(u.y)) ? 0.0 : 1.0;
        break;
      case Reduction::inner: {
        const double2 v = b[i];
        r0 += u.x * v.x + u.y * v.y;
        break;
      }
      case Reduction::max_abs2:
        r0 = fmax(r0, u.x * u.x + u.y * u.y);
        break;
      case Reduction::increment: {
        const double2 v = b[i];
        const double dr = u.x - v.x, di = u.y - v.y;
        // a NaN entry makes the increment NaN, as the host's comparison chain does not: NaN
        // must not pass a convergence test
        const double dd = dr * dr + di * di;
        r0 = (dd > r0 || dd != dd) ? dd : r0;
        r1 = fmax(r1, u.x * u.x + u.y * u.y);
        break;
      }
    }
  }
  s0[threadIdx.x] = r0;
  s1[threadIdx.x] = r1;
  __syncthreads();
  for (int stride = threads / 2; stride > 0; stride /= 2) {
    if (threadIdx.x < stride) {
      if (kind == Reduction::finite || kind == Reduction::inner) {
        s0[threadIdx.x] += s0[threadIdx.x + stride];
      } else {
        const double x = s0[threadIdx.x + stride];
        s0[threadIdx.x] = (x > s0[threadIdx.x] || x != x) ? x : s0[threadIdx.x];
        s1[threadIdx.x] = fmax(s1[threadIdx.x], s1[threadIdx.x + stride]);
      }
    }
    __syncthreads();
  }
  if (threadIdx.x == 0) {
    out[2 * blockIdx.x] = s0[0];
    out[2 * blockIdx.x + 1] = s1[0];
  }
}

// The partials on the host, combined there in block order.
void reduce(Reduction kind, const double* a, const double* b, long long n, double* scratch, double* host,
            double result[2]) {
  result[0] = result[1] = 0.0;
  if (n <= 0) return;
  long long blocks = (n + threads - 1) / threads;
  if (blocks > reduction_blocks) blocks = reduction_blocks;
  reduce_partials<<<static_cast<unsigned>(blocks), threads, 0, cudaStreamPerThread>>>(
      kind, reinterpret_cast<const double2*>(a), reinterpret_cast<const double2*>(b), n, scratch);
  TSI_CUDA_LAUNCHED();
  TSI_CUDA(cudaMemcpyAsync(host, scratch, sizeof(double) * 2 * static_cast<size_t>(blocks), cudaMemcpyDeviceToHost,
                           cudaStreamPerThread));
  TSI_CUDA(cudaStreamSynchronize(cudaStreamPerThread));
  for (long long k = 0; k < blocks; ++k) {
    const double x = host[2 * k], y = host[2 * k + 1];
    if (kind == Reduction::finite || kind == Reduction::inner) {
      result[0] += x;
    } else {
      result[0] = (x > result[0] || x != x) ? x : result[0];
      result[1] = std::fmax(result[1], y);
    }
  }
}

}  // namespace

void combine(const Combination& c, double* out, long long n) {
  if (n <= 0) return;
  long long run = 1;  // the run every coefficient term shares (1: none longer than an entry)
  bool common = true;
  for (int j = 0; j < c.count; ++j) {
    const Term& t = c.terms[j];
    if (!t.d || t.run == 1) continue;
    if (run == 1)
      run = t.run;
    else if (t.run != run)
      common = false;
  }
  for (int j = 0; j < c.count && common && run > 1; ++j)  // a per-entry term among runs: divide
    if (c.terms[j].d && c.terms[j].run == 1) common = false;
  double2* o = reinterpret_cast<double2*>(out);
  if (run == 1) {
    combine_flat<<<flat_blocks(n), threads, 0, cudaStreamPerThread>>>(c, o, n);
  } else if (common && n % run == 0 && n / run <= 65535) {
    const long long x_blocks = (run + threads - 1) / threads;
    const dim3 grid(static_cast<unsigned>(x_blocks < 65536 ? x_blocks : 65535), static_cast<unsigned>(n / run));
    combine_runs<<<grid, threads, 0, cudaStreamPerThread>>>(c, o, run);
  } else {
    combine_divided<<<flat_blocks(n), threads, 0, cudaStreamPerThread>>>(c, o, n);
  }
  TSI_CUDA_LAUNCHED();
}

bool all_finite(const double* x, long long n, double* scratch, double* host) {
  double r[2];
  reduce(Reduction::finite, x, nullptr, n, scratch, host, r);
  return r[0] == 0.0;
}

double inner(const double* x, const double* y, long long n, double* scratch, double* host) {
  double r[2];
  reduce(Reduction::inner, x, y, n, scratch, host, r);
  return r[0];
}

double max_abs2(const double* x, long long n, double* scratch, double* host) {
  double r[2];
  reduce(Reduction::max_abs2, x, nullptr, n, scratch, host, r);
  return r[0];
}

void increment_maxima(const double* next, const double* x, long long n, double m[2], double* scratch, double* host) {
  reduce(Reduction::increment, next, x, n, scratch, host, m);
}

}  // namespace tsi::cuda
