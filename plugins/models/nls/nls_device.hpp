#pragma once
// The NLS model's device kernels (TSI_WITH_CUDA): f_tau on a run's tau grid, on the GPU. Plain
// types only: nvcc compiles nls_device.cu without Eigen.
#include <complex>
#include <memory>
#include <vector>

namespace nls_device {

struct Setup {
  std::vector<int> shape;                                   // n_x [, n_y [, n_z]]
  std::vector<std::vector<int>> folded;                     // per direction: |m| of each FFT index
  std::vector<std::vector<std::complex<double>>> phases;    // per direction: e^{-i m^2 tau_j}, (n/2 + 1) x n_tau by columns
  std::vector<double> dealias_mask;                         // per point, or empty: none
  double field_scale = 1.0;                                 // 1 / ((2 pi)^d N)
  int n_tau = 0;
};

/// f_tau(W) = e^{i |m|^2 tau} F[-i |w|^2 w] (w = F^{-1}[e^{-i |m|^2 tau} W]) on every column of a
/// device grid, in place, times `scale`: the same passes as Nls::fused_field on the host.
class Kernels {
 public:
  virtual ~Kernels() = default;
  virtual void evaluate(std::complex<double>* grid, double scale) = 0;
  /// Coefficients y to scale * the coefficients of f_tau (out may be y), the tau transforms
  /// fused with the phases (n_tau a power of two up to 32); false for other n_tau.
  virtual bool evaluate_coefficients(const std::complex<double>* y, std::complex<double>* out, double scale) = 0;
};

std::unique_ptr<Kernels> make_kernels(const Setup& setup);

}  // namespace nls_device
