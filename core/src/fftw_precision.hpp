#pragma once
#include <fftw3.h>

#include "tsi/precision.hpp"

/// FFTW's interface of the build's precision: TSI_FFTW(plan_many_dft) is fftw_plan_many_dft in
/// a double build and fftwl_plan_many_dft in a long-double one (libfftw3l).
#if defined(TSI_PRECISION_LONG_DOUBLE)
#define TSI_FFTW(name) fftwl_##name
#else
#define TSI_FFTW(name) fftw_##name
#endif
