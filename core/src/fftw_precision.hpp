#pragma once
#include <fftw3.h>

#include "tsi/precision.hpp"

/// FFTW's interface of the build's precision: TSI_FFTW(plan_many_dft) is fftw_plan_many_dft in
/// a double build and fftwl_plan_many_dft in a long-double one (libfftw3l).
#if defined(TSI_PRECISION_QUAD)
#define TSI_FFTW(name) fftwq_##name
#elif defined(TSI_PRECISION_LONG_DOUBLE)
#define TSI_FFTW(name) fftwl_##name
#else
#define TSI_FFTW(name) fftw_##name
#endif

#include "tsi/types.hpp"

namespace tsi::detail {
/// The real type FFTW's interface of this precision takes: Real itself, or the __float128
/// that quad's Real (Boost's float128) holds, with the same bits.
#if defined(TSI_PRECISION_QUAD)
__extension__ typedef __float128 FftwReal;
#else
using FftwReal = Real;
#endif
static_assert(sizeof(FftwReal) == sizeof(Real));
inline FftwReal* fftw_real(Real* p) { return reinterpret_cast<FftwReal*>(p); }
inline FftwReal* fftw_real(const Real* p) { return reinterpret_cast<FftwReal*>(const_cast<Real*>(p)); }
inline Real* tsi_real(FftwReal* p) { return reinterpret_cast<Real*>(p); }
}  // namespace tsi::detail
