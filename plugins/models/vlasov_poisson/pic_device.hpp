#pragma once
// The particle-in-cell field of vlasov-poisson-2d on the device (TSI_WITH_CUDA): every tau
// column's deposition, Poisson solve and interpolation (pic_field.cpp's Field, tau_field
// "per-tau") in batched kernels and cuFFT transforms. Plain types only: nvcc compiles
// pic_device.cu without Eigen.
#include <memory>
#include <vector>

namespace pic_device {

struct Setup {
  int n_x = 16, n_y = 16;
  int width = 6, offset = 2;         // the shape's stencil: M6 (6, 2) or CIC (2, 0)
  long long particles = 0;
  double inverse_dx = 1, inverse_dy = 1;
  double weight = 1;                 // |box| / N
  double inverse_cell = 1;           // 1 / (dx dy)
  std::vector<double> k1, k2, inverse_k2;  // per point of the half spectrum ((n_y, n_x/2 + 1), x fastest)
  std::vector<double> cos_tau, sin_tau;    // per tau column
};

/// f_tau on a device grid of the complex layout (4 N rows, particle k's x1, x2, v1, v2 at
/// 4k .. 4k + 3, real parts; one column per tau), in place, times `scale`:
/// (R(tau) y, R(-tau) E(x)) with E the field of the column's own positions.
class Kernels {
 public:
  virtual ~Kernels() = default;
  virtual void evaluate(void* grid, double scale) = 0;
};

std::unique_ptr<Kernels> make_kernels(const Setup& setup);

}  // namespace pic_device
