#pragma once

/// The build's floating-point precision (CMake: TSI_PRECISION=double or long-double), as
/// PETSc's --with-precision: one build, one real type, the same schemes and models. The
/// plugin ABI stamp records it, so a plugin of another precision is refused at load.
#if defined(TSI_PRECISION_LONG_DOUBLE)
#define TSI_REAL_TYPE long double
#define TSI_PRECISION_NAME "long-double"
#else
#define TSI_REAL_TYPE double
#define TSI_PRECISION_NAME "double"
#endif
