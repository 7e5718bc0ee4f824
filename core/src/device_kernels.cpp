#include "tsi/device_kernels.hpp"

namespace tsi {

// Key functions: the classes' type information lives in the core, where every plugin's
// dynamic_cast finds the same one.
DeviceTauGridField::~DeviceTauGridField() = default;
bool DeviceTauGridField::evaluate_coefficients(const Complex*, Complex*, Real) { return false; }
DeviceKernels::~DeviceKernels() = default;

}  // namespace tsi
