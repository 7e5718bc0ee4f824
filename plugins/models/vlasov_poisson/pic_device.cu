// The particle-in-cell field on the device (pic_device.hpp), pass for pass as pic_field.cpp
// computes it on the host for each tau column:
//   1. deposition: each particle's shape-function weights onto its column's grid, through a
//      copy of the grid in shared memory per block (a column's grid is small and every particle
//      of the column adds to it: global atomics would contend), then one atomic add per node;
//   2. the Poisson solve: cuFFT's real-to-complex transform of every column's density, E^ =
//      -i k rho^ / (|k|^2 |cell| N) on the half spectrum, and the complex-to-real transforms of E1
//      and E2 (the host's real transforms, so that the Nyquist modes are treated alike);
//   3. interpolation at the particles with the same weights, the y weights first as on the
//      host, and the rotations (R(tau) y, R(-tau) E) written in place.
// The deposition's sums come in the order the atomics land: the density differs from the
// host's by rounding, and from run to run.
#include <cuda_runtime.h>
#include <cufft.h>

#include <stdexcept>
#include <string>

#include "pic_device.hpp"

namespace pic_device {
namespace {

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}
void check(cufftResult status, const char* what) {
  if (status != CUFFT_SUCCESS)
    throw std::runtime_error(std::string("cuFFT: ") + what + ": error " + std::to_string(static_cast<int>(status)));
}

constexpr int threads = 256;

struct Geometry {
  int n_x, n_y, width, offset;
  long long particles;
  double inverse_dx, inverse_dy, weight;
};

__device__ inline double fifth(double z) {
  const double z2 = z * z;
  return z2 * z2 * z;
}

// The host's weights (pic_field.cpp), M6 or CIC, of the nodes first .. first + W - 1.
template <int W>
__device__ inline void weights(double d, double (&w)[W]) {
  if constexpr (W == 2) {
    w[0] = 1.0 - d;
    w[1] = d;
  } else {
    constexpr double c = 1.0 / 120.0;
    const double a = 1.0 - d;
    const double a5 = fifth(a), d5 = fifth(d), a1 = fifth(1.0 + a), d1 = fifth(1.0 + d);
    w[0] = a5 * c;
    w[1] = (a1 - 6.0 * a5) * c;
    w[2] = (fifth(2.0 + a) - 6.0 * a1 + 15.0 * a5) * c;
    w[3] = (fifth(2.0 + d) - 6.0 * d1 + 15.0 * d5) * c;
    w[4] = (d1 - 6.0 * d5) * c;
    w[5] = d5 * c;
  }
}

// floor(x / h) wrapped into 0 .. n - 1 as the host's wrapped_cell (a non-finite coordinate:
// cell 0 and a NaN fraction, so NaN weights).
__device__ inline double wrapped_cell(double i, double n) {
  const double w = i - n * floor(i / n);
  return w >= 0.0 && w < n ? w : 0.0;
}

// Particle k of a column (complex layout: real parts at 8k + 2c doubles): its first node in x
// and y (the host's padded index less the offset, wrapped) and weights.
template <int W>
struct Stencil {
  int first_x, first_y;
  double wx[W], wy[W];
  __device__ Stencil(const Geometry& g, const double* column, long long k) {
    const double p1 = column[8 * k] * g.inverse_dx, p2 = column[8 * k + 2] * g.inverse_dy;
    const double f1 = floor(p1), f2 = floor(p2);
    first_x = static_cast<int>(wrapped_cell(f1, g.n_x)) - g.offset;
    first_y = static_cast<int>(wrapped_cell(f2, g.n_y)) - g.offset;
    weights<W>(p1 - f1, wx);
    weights<W>(p2 - f2, wy);
  }
};

__device__ inline int wrap(int i, int n) { return i < 0 ? i + n : i >= n ? i - n : i; }

// A particle's charge onto the n_y x n_x nodes of its stencil in `rho` (shared or device memory).
template <int W>
__device__ inline void deposit(const Geometry& g, const Stencil<W>& s, double* rho) {
#pragma unroll
  for (int b = 0; b < W; ++b) {
    const int row = wrap(s.first_y + b, g.n_y) * g.n_x;
    const double wy = g.weight * s.wy[b];
#pragma unroll
    for (int a = 0; a < W; ++a) atomicAdd(&rho[row + wrap(s.first_x + a, g.n_x)], wy * s.wx[a]);
  }
}

// Column blockIdx.y, particles by a grid-stride loop over blockIdx.x: the block's sums in shared
// memory (the column's n_y x n_x grid), then added to the column's density.
template <int W>
__global__ void deposit_shared(Geometry g, const double* grid, long long dim, double* rho) {
  extern __shared__ double local[];
  const int cells = g.n_x * g.n_y;
  for (int i = threadIdx.x; i < cells; i += blockDim.x) local[i] = 0.0;
  __syncthreads();
  const double* column = grid + 2 * dim * blockIdx.y;
  for (long long k = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; k < g.particles;
       k += static_cast<long long>(gridDim.x) * blockDim.x) {
    deposit(g, Stencil<W>(g, column, k), local);
  }
  __syncthreads();
  double* out = rho + static_cast<long long>(cells) * blockIdx.y;
  for (int i = threadIdx.x; i < cells; i += blockDim.x)
    if (local[i] != 0.0) atomicAdd(&out[i], local[i]);
}

// The same straight into device memory, for a grid too large for shared memory.
template <int W>
__global__ void deposit_global(Geometry g, const double* grid, long long dim, double* rho) {
  const int cells = g.n_x * g.n_y;
  const double* column = grid + 2 * dim * blockIdx.y;
  double* out = rho + static_cast<long long>(cells) * blockIdx.y;
  for (long long k = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; k < g.particles;
       k += static_cast<long long>(gridDim.x) * blockDim.x) {
    deposit(g, Stencil<W>(g, column, k), out);
  }
}

// E^ on the half spectrum of every column: rho^ (columns j) -> E1^ (2j), E2^ (2j + 1).
__global__ void field_spectrum(const double2* rho_hat, long long half, int columns, const double* k1,
                               const double* k2, const double* inverse_k2, double scale, double2* e_hat) {
  const long long n = half * columns;
  for (long long i = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<long long>(gridDim.x) * blockDim.x) {
    const long long j = i / half, p = i % half;
    const double s = scale * inverse_k2[p];
    const double2 r = {rho_hat[i].x * s, rho_hat[i].y * s};
    e_hat[(2 * j) * half + p] = {k1[p] * r.y, -k1[p] * r.x};  // -i k1 r
    e_hat[(2 * j + 1) * half + p] = {k2[p] * r.y, -k2[p] * r.x};
  }
}

// Thread (k, column blockIdx.y): E at the particle (rows first, as the host), then
// (R(tau) y, R(-tau) E) times scale, in place (real parts; imaginary parts 0).
template <int W>
__global__ void interpolate_rotate(Geometry g, double* grid, long long dim, const double* e, const double* cos_tau,
                                   const double* sin_tau, double scale) {
  const int cells = g.n_x * g.n_y;
  const unsigned j = blockIdx.y;
  double* column = grid + 2 * dim * j;
  const double* e1 = e + static_cast<long long>(cells) * (2 * j);
  const double* e2 = e1 + cells;
  const double c = cos_tau[j], sn = sin_tau[j];
  for (long long k = blockIdx.x * static_cast<long long>(blockDim.x) + threadIdx.x; k < g.particles;
       k += static_cast<long long>(gridDim.x) * blockDim.x) {
    const Stencil<W> s(g, column, k);
    double acc1[W], acc2[W];
#pragma unroll
    for (int a = 0; a < W; ++a) acc1[a] = acc2[a] = 0.0;
#pragma unroll
    for (int b = 0; b < W; ++b) {
      const int row = wrap(s.first_y + b, g.n_y) * g.n_x;
#pragma unroll
      for (int a = 0; a < W; ++a) {
        const int node = row + wrap(s.first_x + a, g.n_x);
        acc1[a] += s.wy[b] * e1[node];
        acc2[a] += s.wy[b] * e2[node];
      }
    }
    double E1 = 0.0, E2 = 0.0;
#pragma unroll
    for (int a = 0; a < W; ++a) {
      E1 += s.wx[a] * acc1[a];
      E2 += s.wx[a] * acc2[a];
    }
    double* p = column + 8 * k;
    const double y1 = p[4], y2 = p[6];
    p[0] = scale * (c * y1 + sn * y2);
    p[2] = scale * (-sn * y1 + c * y2);
    p[4] = scale * (c * E1 - sn * E2);
    p[6] = scale * (sn * E1 + c * E2);
    p[1] = p[3] = p[5] = p[7] = 0.0;
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
  explicit CudaKernels(const Setup& s)
      : g_{s.n_x, s.n_y, s.width, s.offset, s.particles, s.inverse_dx, s.inverse_dy, s.weight},
        columns_(static_cast<int>(s.cos_tau.size())),
        cells_(static_cast<long long>(s.n_x) * s.n_y),
        half_(static_cast<long long>(s.n_x / 2 + 1) * s.n_y),
        spectrum_scale_(s.inverse_cell / static_cast<double>(cells_)) {
    if (columns_ > 65535) throw std::runtime_error("--device cuda: particle-in-cell kernels take n_tau up to 65535");
    k1_ = upload(s.k1);
    k2_ = upload(s.k2);
    inverse_k2_ = upload(s.inverse_k2);
    cos_ = upload(s.cos_tau);
    sin_ = upload(s.sin_tau);
    check(cudaMalloc(&rho_, sizeof(double) * static_cast<size_t>(cells_ * columns_)), "cudaMalloc");
    check(cudaMalloc(&e_, sizeof(double) * static_cast<size_t>(2 * cells_ * columns_)), "cudaMalloc");
    check(cudaMalloc(&rho_hat_, sizeof(double2) * static_cast<size_t>(half_ * columns_)), "cudaMalloc");
    check(cudaMalloc(&e_hat_, sizeof(double2) * static_cast<size_t>(2 * half_ * columns_)), "cudaMalloc");
    int n[2] = {s.n_y, s.n_x};  // C order: x the last direction, halved by the real transforms
    check(cufftPlanMany(&forward_, 2, n, nullptr, 1, static_cast<int>(cells_), nullptr, 1, static_cast<int>(half_),
                        CUFFT_D2Z, columns_),
          "cufftPlanMany (D2Z)");
    check(cufftPlanMany(&backward_, 2, n, nullptr, 1, static_cast<int>(half_), nullptr, 1, static_cast<int>(cells_),
                        CUFFT_Z2D, 2 * columns_),
          "cufftPlanMany (Z2D)");
    check(cufftSetStream(forward_, cudaStreamPerThread), "cufftSetStream");
    check(cufftSetStream(backward_, cudaStreamPerThread), "cufftSetStream");
    int device = 0, shared = 0;
    check(cudaGetDevice(&device), "cudaGetDevice");
    check(cudaDeviceGetAttribute(&shared, cudaDevAttrMaxSharedMemoryPerBlockOptin, device), "shared memory");
    shared_bytes_ = sizeof(double) * static_cast<size_t>(cells_);
    use_shared_ = shared_bytes_ <= static_cast<size_t>(shared);
    if (use_shared_) {
      const int bytes = static_cast<int>(shared_bytes_);
      check(cudaFuncSetAttribute(deposit_shared<2>, cudaFuncAttributeMaxDynamicSharedMemorySize, bytes), "attribute");
      check(cudaFuncSetAttribute(deposit_shared<6>, cudaFuncAttributeMaxDynamicSharedMemorySize, bytes), "attribute");
    }
  }
  ~CudaKernels() override {
    cufftDestroy(forward_);
    cufftDestroy(backward_);
    for (void* p : {static_cast<void*>(k1_), static_cast<void*>(k2_), static_cast<void*>(inverse_k2_),
                    static_cast<void*>(cos_), static_cast<void*>(sin_), static_cast<void*>(rho_),
                    static_cast<void*>(e_), static_cast<void*>(rho_hat_), static_cast<void*>(e_hat_)})
      cudaFree(p);
  }

  void evaluate(void* grid, double scale) override {
    if (g_.width == 2)
      run<2>(static_cast<double*>(grid), scale);
    else
      run<6>(static_cast<double*>(grid), scale);
  }

 private:
  template <int W>
  void run(double* grid, double scale) {
    const long long dim = 4 * g_.particles;
    cudaStream_t stream = cudaStreamPerThread;
    check(cudaMemsetAsync(rho_, 0, sizeof(double) * static_cast<size_t>(cells_ * columns_), stream), "cudaMemset");
    const long long blocks = (g_.particles + threads - 1) / threads;
    if (use_shared_) {
      // Enough blocks per column to fill the device a few times over; each sums many particles.
      const unsigned per_column = static_cast<unsigned>(blocks < 64 ? blocks : 64);
      deposit_shared<W><<<dim3(per_column, static_cast<unsigned>(columns_)), threads, shared_bytes_, stream>>>(
          g_, grid, dim, rho_);
    } else {
      const unsigned per_column = static_cast<unsigned>(blocks < 65535 ? blocks : 65535);
      deposit_global<W><<<dim3(per_column, static_cast<unsigned>(columns_)), threads, 0, stream>>>(g_, grid, dim, rho_);
    }
    check(cudaGetLastError(), "deposit");
    check(cufftExecD2Z(forward_, rho_, rho_hat_), "cufftExecD2Z");
    const long long n = half_ * columns_;
    const unsigned spectrum_blocks = static_cast<unsigned>((n + threads - 1) / threads < 65536 * 16 ? (n + threads - 1) / threads : 65536 * 16);
    field_spectrum<<<spectrum_blocks, threads, 0, stream>>>(rho_hat_, half_, columns_, k1_, k2_, inverse_k2_,
                                                             spectrum_scale_, e_hat_);
    check(cudaGetLastError(), "field_spectrum");
    check(cufftExecZ2D(backward_, e_hat_, e_), "cufftExecZ2D");
    const unsigned per_column = static_cast<unsigned>(blocks < 65535 ? blocks : 65535);
    interpolate_rotate<W><<<dim3(per_column, static_cast<unsigned>(columns_)), threads, 0, stream>>>(
        g_, grid, dim, e_, cos_, sin_, scale);
    check(cudaGetLastError(), "interpolate_rotate");
  }

  Geometry g_;
  int columns_;
  long long cells_, half_;
  double spectrum_scale_;
  double *k1_ = nullptr, *k2_ = nullptr, *inverse_k2_ = nullptr, *cos_ = nullptr, *sin_ = nullptr;
  double *rho_ = nullptr, *e_ = nullptr;
  double2 *rho_hat_ = nullptr, *e_hat_ = nullptr;
  cufftHandle forward_ = 0, backward_ = 0;
  size_t shared_bytes_ = 0;
  bool use_shared_ = false;
};

}  // namespace

std::unique_ptr<Kernels> make_kernels(const Setup& setup) { return std::make_unique<CudaKernels>(setup); }

}  // namespace pic_device
