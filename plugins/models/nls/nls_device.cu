// The NLS model's device kernels (nls_device.hpp): the phases in, cuFFT's batched inverse
// transform of every tau column, the cubic term, the forward transform, the phases out (and
// the 2/3 rule) — the host's fused_field, pass for pass.
#include <cuda_runtime_api.h>
#include <cufft.h>

#include <algorithm>
#include <complex>
#include <stdexcept>
#include <string>

#include "nls_device.hpp"

namespace nls_device {
namespace {

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}
void check(cufftResult status, const char* what) {
  if (status != CUFFT_SUCCESS)
    throw std::runtime_error(std::string("cuFFT: ") + what + ": error " + std::to_string(static_cast<int>(status)));
}

constexpr int threads = 256;

// a b and a conj(b) rounded as the host's written-out products (no fused multiply-adds), so
// that the phases are the host's to the bit.
__device__ inline double2 times(double2 a, double2 b) {
  return {__dsub_rn(__dmul_rn(a.x, b.x), __dmul_rn(a.y, b.y)), __dadd_rn(__dmul_rn(a.x, b.y), __dmul_rn(a.y, b.x))};
}
__device__ inline double2 times_conj(double2 a, double2 b) {
  return {__dadd_rn(__dmul_rn(a.x, b.x), __dmul_rn(a.y, b.y)), __dsub_rn(__dmul_rn(a.y, b.x), __dmul_rn(a.x, b.y))};
}

struct Geometry {
  int dims = 1;
  unsigned n[3] = {1, 1, 1};
  const int* folded[3] = {nullptr, nullptr, nullptr};
  const double2* phases[3] = {nullptr, nullptr, nullptr};  // (n_i/2 + 1) x n_tau by columns
  unsigned points = 1;
};

// e^{-i |m|^2 tau_j} at point p, for any j: the product of the directions' phases, in the host's
// order (the point's folded indices found once).
struct PointPhase {
  int dims;
  // each direction's phases at the point's |m_i| (lead: the first, middle: the second of three,
  // last: the last direction's): entry j at table[stride * j]
  const double2 *lead = nullptr, *middle = nullptr, *last = nullptr;
  unsigned lead_stride = 0, middle_stride = 0, last_stride = 0;
  // (constant indices into the kernel's parameters: a run-time one would copy them to local memory)
  __device__ PointPhase(const Geometry& g, unsigned p) : dims(g.dims) {
    if (g.dims == 1) {
      last = g.phases[0] + g.folded[0][p];
      last_stride = g.n[0] / 2 + 1;
      return;
    }
    const unsigned n_last = g.dims == 2 ? g.n[1] : g.n[2], r = p / n_last;
    last = (g.dims == 2 ? g.phases[1] : g.phases[2]) + (g.dims == 2 ? g.folded[1] : g.folded[2])[p % n_last];
    last_stride = n_last / 2 + 1;
    lead = g.phases[0] + g.folded[0][g.dims == 3 ? r / g.n[1] : r];
    lead_stride = g.n[0] / 2 + 1;
    if (g.dims == 3) {
      middle = g.phases[1] + g.folded[1][r % g.n[1]];
      middle_stride = g.n[1] / 2 + 1;
    }
  }
  __device__ double2 operator()(unsigned j) const {
    if (dims == 1) return last[last_stride * j];
    double2 e = lead[lead_stride * j];
    if (dims == 3) e = times(e, middle[middle_stride * j]);
    return times(e, last[last_stride * j]);
  }
};

__device__ inline double2 phase(const Geometry& g, unsigned p, unsigned j) { return PointPhase(g, p)(j); }

// The tau transforms fused with the phases (n_tau = N, a power of two up to 32): each thread
// holds one point's N tau values in registers and transforms them there (radix 2, every index
// known at compile time), so that coefficients to phased grid values, and back, is one pass over
// memory each instead of two (cuFFT's strided transform and a phase pass).
template <int N>
struct Twiddles {
  double2 w[N / 2 > 0 ? N / 2 : 1];  // e^{2 pi i m / N}, m < N/2
};

__host__ __device__ constexpr int bit_reversed(int i, int n) {
  int r = 0;
  for (int bit = 1; bit < n; bit <<= 1, i >>= 1) r = (r << 1) | (i & 1);
  return r;
}

// The DFT of a (given in bit-reversed order) with e^{sign 2 pi i j k / N} (sign +1: FFTW's
// backward, -1: its forward), unnormalised, in natural order: radix-2 stages in place.
// One radix-2 stage of butterflies of length `len` (then the next, by recursion: every index a
// compile-time constant, so that the values stay in registers).
template <int M, int sign, int len, int stride>
__device__ inline void butterflies(double2 (&a)[M], const double2* w) {
  if constexpr (len <= M) {
#pragma unroll
    for (int i = 0; i < M; i += len) {
#pragma unroll
      for (int k = 0; k < len / 2; ++k) {
        double2 t_w = w[k * (M / len) * stride];
        if (sign < 0) t_w.y = -t_w.y;
        const double2 u = a[i + k], v = a[i + k + len / 2];
        const double2 t = {__fma_rn(v.x, t_w.x, -v.y * t_w.y), __fma_rn(v.x, t_w.y, v.y * t_w.x)};
        a[i + k] = {u.x + t.x, u.y + t.y};
        a[i + k + len / 2] = {u.x - t.x, u.y - t.y};
      }
    }
    butterflies<M, sign, 2 * len, stride>(a, w);
  }
}

// a * w (sign +1) or a * conj(w) (sign -1), in fused multiply-adds.
template <int sign>
__device__ inline double2 rotate(double2 a, double2 w) {
  if (sign < 0) w.y = -w.y;
  return {__fma_rn(a.x, w.x, -a.y * w.y), __fma_rn(a.x, w.y, a.y * w.x)};
}

__device__ inline double2 exchange(double2 v) {
  return {__shfl_xor_sync(0xffffffffu, v.x, 1), __shfl_xor_sync(0xffffffffu, v.y, 1)};
}

// Coefficients y (dim x N) -> out(p, j) = e^{-i |m_p|^2 tau_j} sum_k y(p, k) e^{i k tau_j}.
template <int N>
__global__ void tau_inverse_phased(Geometry g, Twiddles<N> tw, const double2* y, double2* out) {
  for (unsigned p = blockIdx.x * blockDim.x + threadIdx.x; p < g.points; p += gridDim.x * blockDim.x) {
    double2 a[N];  // in bit-reversed order, for the radix-2 stages
#pragma unroll
    for (int k = 0; k < N; ++k) a[bit_reversed(k, N)] = y[p + static_cast<size_t>(g.points) * k];
    butterflies<N, 1, 2, 1>(a, tw.w);
    const PointPhase e(g, p);
#pragma unroll
    for (int j = 0; j < N; ++j) out[p + static_cast<size_t>(g.points) * j] = times(a[j], e(static_cast<unsigned>(j)));
  }
}

// Grid values w (dim x N) -> w(p, k) = sum_j mask_p conj(e^{-i |m_p|^2 tau_j}) w(p, j) e^{-i k tau_j}.
template <int N>
__global__ void phased_tau_forward(Geometry g, Twiddles<N> tw, double2* w, const double* mask) {
  for (unsigned p = blockIdx.x * blockDim.x + threadIdx.x; p < g.points; p += gridDim.x * blockDim.x) {
    const PointPhase e(g, p);
    const double m = mask ? mask[p] : 1.0;
    double2 a[N];  // in bit-reversed order, for the radix-2 stages
#pragma unroll
    for (int j = 0; j < N; ++j) a[bit_reversed(j, N)] = w[p + static_cast<size_t>(g.points) * j];
#pragma unroll
    for (int j = 0; j < N; ++j) {
      double2& v = a[bit_reversed(j, N)];
      v = times_conj(v, e(static_cast<unsigned>(j)));
      if (mask) v = {v.x * m, v.y * m};
    }
    butterflies<N, -1, 2, 1>(a, tw.w);
#pragma unroll
    for (int k = 0; k < N; ++k) w[p + static_cast<size_t>(g.points) * k] = a[k];
  }
}

// Column blockIdx.y of the grid: w = c e^{-i |m|^2 tau_j}.
__global__ void phases_in(Geometry g, double2* grid) {
  const unsigned j = blockIdx.y;
  double2* column = grid + static_cast<size_t>(g.points) * j;
  for (unsigned p = blockIdx.x * blockDim.x + threadIdx.x; p < g.points; p += gridDim.x * blockDim.x)
    column[p] = times(column[p], phase(g, p, j));
}

// -i a w with a = scale |w|^2, in real arithmetic as the host: (a im, -a re).
__global__ void cubic(double2* w, size_t n, double scale) {
  for (size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<size_t>(gridDim.x) * blockDim.x) {
    const double2 v = w[i];
    const double a = scale * (v.x * v.x + v.y * v.y);
    w[i] = {a * v.y, -a * v.x};
  }
}

// Column blockIdx.y: out = w conj(e^{-i |m|^2 tau_j}), times the 2/3 rule's mask where given.
__global__ void phases_out(Geometry g, double2* grid, const double* mask) {
  const unsigned j = blockIdx.y;
  double2* column = grid + static_cast<size_t>(g.points) * j;
  for (unsigned p = blockIdx.x * blockDim.x + threadIdx.x; p < g.points; p += gridDim.x * blockDim.x) {
    double2 v = times_conj(column[p], phase(g, p, j));
    if (mask) v = {v.x * mask[p], v.y * mask[p]};
    column[p] = v;
  }
}

// The same two passes with each point's N values split over two neighbouring lanes (N >= 16):
// half the registers per thread (the one-lane kernels need 166 and 255 at N = 32, and then only
// 12 to 18% of the warps a multiprocessor holds are active). One radix-2 stage goes between the
// lanes by shuffles, the rest are N/2-point transforms in registers. Lane h of a pair:
//   inverse (decimation in time): the DFT of the inputs of parity h; lane 1 turns its by W^m;
//     then lane 0 writes X[m] = E[m] + W^m O[m], lane 1 X[m + N/2] = E[m] - W^m O[m];
//   forward (decimation in frequency): lane h holds values j + h N/2; then lane 0 transforms
//     v[j] + v[j + N/2] into the even outputs, lane 1 (v[j] - v[j + N/2]) W^-j into the odd ones.
// Every read of a point comes before the shuffles, so out may be y.
template <int N>
__global__ void tau_inverse_phased_pairs(Geometry g, Twiddles<N> tw, const double2* y, double2* out) {
  constexpr int M = N / 2;
  const unsigned h = threadIdx.x & 1u;
  const unsigned first = (blockIdx.x * blockDim.x + threadIdx.x) >> 1, stride = (gridDim.x * blockDim.x) >> 1;
  const unsigned rounds = (g.points + stride - 1) / stride;  // the same in every lane: the shuffles need them all
  for (unsigned r = 0; r < rounds; ++r) {
    const unsigned p = first + r * stride;
    const bool active = p < g.points;
    double2 a[M];  // bit-reversed, for the radix-2 stages
#pragma unroll
    for (int m = 0; m < M; ++m)
      a[bit_reversed(m, M)] = active ? y[p + static_cast<size_t>(g.points) * (2 * m + h)] : double2{0.0, 0.0};
    butterflies<M, 1, 2, 2>(a, tw.w);
#pragma unroll
    for (int m = 0; m < M; ++m) {
      if (h) a[m] = rotate<1>(a[m], tw.w[m]);
      const double2 other = exchange(a[m]);
      a[m] = h ? double2{other.x - a[m].x, other.y - a[m].y} : double2{a[m].x + other.x, a[m].y + other.y};
    }
    if (!active) continue;
    const PointPhase e(g, p);
#pragma unroll
    for (int m = 0; m < M; ++m) {
      const unsigned j = static_cast<unsigned>(m) + h * M;
      out[p + static_cast<size_t>(g.points) * j] = times(a[m], e(j));
    }
  }
}

template <int N>
__global__ void phased_tau_forward_pairs(Geometry g, Twiddles<N> tw, double2* w, const double* mask) {
  constexpr int M = N / 2;
  const unsigned h = threadIdx.x & 1u;
  const unsigned first = (blockIdx.x * blockDim.x + threadIdx.x) >> 1, stride = (gridDim.x * blockDim.x) >> 1;
  const unsigned rounds = (g.points + stride - 1) / stride;
  for (unsigned r = 0; r < rounds; ++r) {
    const unsigned p = first + r * stride;
    const bool active = p < g.points;
    double2 a[M];
    if (active) {
      const PointPhase e(g, p);
      const double m = mask ? mask[p] : 1.0;
#pragma unroll
      for (int j = 0; j < M; ++j) {
        const unsigned row = static_cast<unsigned>(j) + h * M;
        double2 v = times_conj(w[p + static_cast<size_t>(g.points) * row], e(row));
        if (mask) v = {v.x * m, v.y * m};
        a[j] = v;
      }
    } else {
#pragma unroll
      for (int j = 0; j < M; ++j) a[j] = {0.0, 0.0};
    }
    double2 b[M];  // bit-reversed
#pragma unroll
    for (int j = 0; j < M; ++j) {
      const double2 other = exchange(a[j]);
      b[bit_reversed(j, M)] = h ? rotate<-1>(double2{other.x - a[j].x, other.y - a[j].y}, tw.w[j])
                                : double2{a[j].x + other.x, a[j].y + other.y};
    }
    butterflies<M, -1, 2, 2>(b, tw.w);
    if (!active) continue;
#pragma unroll
    for (int k = 0; k < M; ++k) w[p + static_cast<size_t>(g.points) * (2 * k + h)] = b[k];
  }
}

template <class T>
T* upload(const std::vector<T>& host) {
  T* device = nullptr;
  check(cudaMalloc(&device, sizeof(T) * host.size()), "cudaMalloc");
  check(cudaMemcpy(device, host.data(), sizeof(T) * host.size(), cudaMemcpyHostToDevice), "cudaMemcpy");
  return device;
}

class CudaKernels final : public Kernels {
 public:
  explicit CudaKernels(const Setup& s) : field_scale_(s.field_scale), n_tau_(s.n_tau) {
    if (s.n_tau > 65535) throw std::runtime_error("--device cuda: NLS kernels take n_tau up to 65535");
    g_.dims = static_cast<int>(s.shape.size());
    long long n[3] = {1, 1, 1};
    for (int i = 0; i < g_.dims; ++i) {
      g_.n[i] = static_cast<unsigned>(s.shape[static_cast<size_t>(i)]);
      n[i] = s.shape[static_cast<size_t>(i)];
      g_.points *= g_.n[i];
      folded_[i] = upload(s.folded[static_cast<size_t>(i)]);
      phases_[i] = upload(s.phases[static_cast<size_t>(i)]);
      g_.folded[i] = folded_[i];
      g_.phases[i] = reinterpret_cast<const double2*>(phases_[i]);
    }
    if (!s.dealias_mask.empty()) mask_ = upload(s.dealias_mask);
    size_t work = 0;
    check(cufftCreate(&plan_), "cufftCreate");
    // Every tau column's d-dimensional transform in one batched plan (C order, contiguous).
    check(cufftMakePlanMany64(plan_, g_.dims, n, nullptr, 1, static_cast<long long>(g_.points), nullptr, 1,
                              static_cast<long long>(g_.points), CUFFT_Z2Z, n_tau_, &work),
          "cufftMakePlanMany64");
    check(cufftSetStream(plan_, cudaStreamPerThread), "cufftSetStream");
  }
  ~CudaKernels() override {
    cufftDestroy(plan_);
    for (int i = 0; i < 3; ++i) {
      cudaFree(folded_[i]);
      cudaFree(phases_[i]);
    }
    cudaFree(mask_);
  }

  bool evaluate_coefficients(const std::complex<double>* y, std::complex<double>* out, double scale) override {
    switch (n_tau_) {
      case 2: return fused<2>(y, out, scale);
      case 4: return fused<4>(y, out, scale);
      case 8: return fused<8>(y, out, scale);
      case 16: return fused<16>(y, out, scale);
      case 32: return fused<32>(y, out, scale);
      default: return false;  // the core's cuFFT tau transforms around evaluate()
    }
  }

  void evaluate(std::complex<double>* grid, double scale) override {
    auto* w = reinterpret_cast<double2*>(grid);
    auto* c = reinterpret_cast<cufftDoubleComplex*>(grid);
    const dim3 columns(blocks(g_.points), static_cast<unsigned>(n_tau_));
    phases_in<<<columns, threads, 0, cudaStreamPerThread>>>(g_, w);
    check(cudaGetLastError(), "phases_in");
    check(cufftExecZ2Z(plan_, c, c, CUFFT_INVERSE), "cufftExecZ2Z (inverse)");
    const size_t n = static_cast<size_t>(g_.points) * static_cast<size_t>(n_tau_);
    cubic<<<blocks(n), threads, 0, cudaStreamPerThread>>>(w, n, field_scale_ * scale);
    check(cudaGetLastError(), "cubic");
    check(cufftExecZ2Z(plan_, c, c, CUFFT_FORWARD), "cufftExecZ2Z (forward)");
    phases_out<<<columns, threads, 0, cudaStreamPerThread>>>(g_, w, mask_);
    check(cudaGetLastError(), "phases_out");
  }

 private:
  template <int N>
  bool fused(const std::complex<double>* y, std::complex<double>* out, double scale) {
    Twiddles<N> tw;
    for (int m = 0; m < N / 2; ++m) {
      const std::complex<double> w = std::polar(1.0, 2.0 * 3.14159265358979323846 * m / N);
      tw.w[m] = {w.real(), w.imag()};
    }
    auto* o = reinterpret_cast<double2*>(out);
    auto* c = reinterpret_cast<cufftDoubleComplex*>(out);
    constexpr int fused_threads = 128;  // a thread holds N values: more blocks of fewer threads fill the SMs
    // from N = 16 two lanes share a point (twice the threads)
    constexpr bool pairs = N >= 16;
    const unsigned b = static_cast<unsigned>(
        std::min<size_t>(((pairs ? 2 : 1) * static_cast<size_t>(g_.points) + fused_threads - 1) / fused_threads, 65536u * 16));
    if constexpr (pairs)
      tau_inverse_phased_pairs<N><<<b, fused_threads, 0, cudaStreamPerThread>>>(g_, tw, reinterpret_cast<const double2*>(y), o);
    else
      tau_inverse_phased<N><<<b, fused_threads, 0, cudaStreamPerThread>>>(g_, tw, reinterpret_cast<const double2*>(y), o);
    check(cudaGetLastError(), "tau_inverse_phased");
    check(cufftExecZ2Z(plan_, c, c, CUFFT_INVERSE), "cufftExecZ2Z (inverse)");
    const size_t n = static_cast<size_t>(g_.points) * static_cast<size_t>(n_tau_);
    cubic<<<blocks(n), threads, 0, cudaStreamPerThread>>>(o, n, field_scale_ * scale);
    check(cudaGetLastError(), "cubic");
    check(cufftExecZ2Z(plan_, c, c, CUFFT_FORWARD), "cufftExecZ2Z (forward)");
    if constexpr (pairs)
      phased_tau_forward_pairs<N><<<b, fused_threads, 0, cudaStreamPerThread>>>(g_, tw, o, mask_);
    else
      phased_tau_forward<N><<<b, fused_threads, 0, cudaStreamPerThread>>>(g_, tw, o, mask_);
    check(cudaGetLastError(), "phased_tau_forward");
    return true;
  }

  static unsigned blocks(size_t n) {
    const size_t b = (n + threads - 1) / threads;
    return static_cast<unsigned>(b < 65536 * 16 ? b : 65536 * 16);
  }
  Geometry g_;
  double field_scale_;
  int n_tau_;
  int* folded_[3] = {nullptr, nullptr, nullptr};
  std::complex<double>* phases_[3] = {nullptr, nullptr, nullptr};
  double* mask_ = nullptr;
  cufftHandle plan_ = 0;
};

}  // namespace

std::unique_ptr<Kernels> make_kernels(const Setup& setup) { return std::make_unique<CudaKernels>(setup); }

}  // namespace nls_device
