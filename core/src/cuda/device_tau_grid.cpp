#include "../reformulations/device_tau_grid.hpp"

#include "cuda_check.hpp"
#include "tsi/device_kernels.hpp"

namespace tsi {
namespace {

class CudaTauGrid final : public DeviceTauGrid {
 public:
  CudaTauGrid(std::unique_ptr<DeviceTauGridField> field, Index dim, int n_tau)
      : field_(std::move(field)), dim_(dim), n_tau_(n_tau) {}
  ~CudaTauGrid() override {
    if (plan_) cufftDestroy(plan_);
  }

  void nonlinear(const Complex* y, Complex* out) override {
    if (field_->evaluate_coefficients(y, out, Real(1) / n_tau_)) return;  // the field fused the transforms
    if (!plan_) {  // made on first use: a field that fuses them needs none (nor its work area)
      // Length n_tau along the rows of the dim x n_tau layout: stride dim, one transform per row.
      long long n[1] = {n_tau_}, embed[1] = {n_tau_};
      size_t work = 0;
      TSI_CUDA(cufftCreate(&plan_));
      TSI_CUDA(cufftMakePlanMany64(plan_, 1, n, embed, dim_, 1, embed, dim_, 1, CUFFT_Z2Z, dim_, &work));
      TSI_CUDA(cufftSetStream(plan_, cudaStreamPerThread));
    }
    auto* in = reinterpret_cast<cufftDoubleComplex*>(const_cast<Complex*>(y));
    auto* o = reinterpret_cast<cufftDoubleComplex*>(out);
    TSI_CUDA(cufftExecZ2Z(plan_, in, o, CUFFT_INVERSE));  // coefficients -> values on the tau grid
    field_->evaluate(out, Real(1) / n_tau_);               // f there, with the forward transform's 1/n
    TSI_CUDA(cufftExecZ2Z(plan_, o, o, CUFFT_FORWARD));
  }

 private:
  std::unique_ptr<DeviceTauGridField> field_;
  Index dim_;
  int n_tau_;
  cufftHandle plan_ = 0;
};

}  // namespace

std::unique_ptr<DeviceTauGrid> make_device_tau_grid(const Model& model, const RealVector& taus, Index dim, int n_tau) {
  const auto* kernels = dynamic_cast<const DeviceKernels*>(&model);
  if (!kernels)
    throw Error("--device cuda: the model has no device kernels (tsi::DeviceKernels); the models that run on the "
                "device: nls, vlasov-poisson-2d");
  return std::make_unique<CudaTauGrid>(kernels->bind_device_tau_grid(taus), dim, n_tau);
}

}  // namespace tsi
