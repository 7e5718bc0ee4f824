#pragma once
#include <memory>

#include "tsi/model.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// TauGrid::nonlinear on the device (tsi/device.hpp): the tau transforms (cuFFT, batched over
/// the state's dim rows) around the model's device kernels (tsi::DeviceKernels). Built on the
/// first evaluation in a device scope; in a build without CUDA make_device_tau_grid throws.
class DeviceTauGrid {
 public:
  virtual ~DeviceTauGrid() = default;
  /// out = f_tau(y), coefficients to coefficients (device memory, dim x n_tau); out may be y.
  virtual void nonlinear(const Complex* y, Complex* out) = 0;
};

/// The complex layout only; a model without device kernels is refused (tsi::Error naming it).
std::unique_ptr<DeviceTauGrid> make_device_tau_grid(const Model& model, const RealVector& taus, Index dim, int n_tau);

}  // namespace tsi
