#pragma once
// Every CUDA and cuFFT call is checked: a failure is a tsi::Error naming the call and the
// runtime's reason (an exit code of 0 proves nothing on a device).
#include <cuda_runtime.h>
#include <cufft.h>

#include <string>

#include "tsi/error.hpp"

namespace tsi::cuda {

inline void check(cudaError_t status, const char* call, const char* file, int line) {
  if (status != cudaSuccess)
    throw Error(std::string("CUDA: ") + call + " failed (" + file + ":" + std::to_string(line) +
                "): " + cudaGetErrorString(status));
}

inline void check(cufftResult status, const char* call, const char* file, int line) {
  if (status != CUFFT_SUCCESS)
    throw Error(std::string("cuFFT: ") + call + " failed (" + file + ":" + std::to_string(line) + "): error " +
                std::to_string(static_cast<int>(status)));
}

}  // namespace tsi::cuda

#define TSI_CUDA(call) ::tsi::cuda::check((call), #call, __FILE__, __LINE__)
/// After a kernel launch: the launch's own error (bad configuration), not the kernel's outcome.
#define TSI_CUDA_LAUNCHED() ::tsi::cuda::check(cudaGetLastError(), "kernel launch", __FILE__, __LINE__)
