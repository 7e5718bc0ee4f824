#pragma once
#include <memory>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// f_tau on a run's tau grid on the device (tsi/device.hpp): the model's kernels.
class TSI_API DeviceTauGridField {
 public:
  virtual ~DeviceTauGridField();
  /// grid: device memory, dim x n_tau values column by column (column j the state at taus[j]
  /// of the binding), replaced by scale * f_tau there (the field's coefficients in the
  /// model's coordinates, as TauGridField::evaluate; `scale` folds the caller's 1/n_tau in).
  virtual void evaluate(Complex* grid, Real scale) = 0;
  /// Optionally the whole evaluation, coefficients to coefficients: out = scale * the tau
  /// transforms' forward of f_tau(values of y) (device memory, dim x n_tau each; out may be y),
  /// the tau transforms fused into the field's own passes. Returns false (the default) when the
  /// field does not: the core then transforms around evaluate().
  virtual bool evaluate_coefficients(const Complex* y, Complex* out, Real scale);
};

/// The capability of a model whose f_tau runs on the device. A model declares it by deriving
/// from this class; the core finds it by dynamic_cast (not a Model getter, so that adding it
/// kept the plugin ABI). Only a build with TSI_WITH_CUDA calls it.
class TSI_API DeviceKernels {
 public:
  virtual ~DeviceKernels();
  /// f_tau on the grid taus (n_tau points), on the device.
  virtual std::unique_ptr<DeviceTauGridField> bind_device_tau_grid(const RealVector& taus) const = 0;
};

}  // namespace tsi
