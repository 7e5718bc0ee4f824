#pragma once

/// The build's floating-point precision (CMake: TSI_PRECISION=double, long-double or quad), as
/// PETSc's --with-precision: one build, one real type, the same schemes and models. The
/// plugin ABI stamp records it, so a plugin of another precision is refused at load.
#if defined(TSI_PRECISION_QUAD)
// IEEE quadruple precision (113-bit significand) through Boost.Multiprecision's float128, a
// class wrapping GCC's __float128 (libquadmath): Eigen takes it (eigen.hpp), std::complex of it
// works through argument-dependent lookup, and FFTW's libfftw3q transforms its arrays.
#include <boost/multiprecision/eigen.hpp>
#include <boost/multiprecision/float128.hpp>
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#define TSI_REAL_TYPE boost::multiprecision::float128
#define TSI_PRECISION_NAME "quad"
#define TSI_REAL_CONSTEXPR const  // float128 is no literal type
// The std:: names tsi's numerics call, for float128 too: Boost's overloads join the standard
// ones, so that one source serves every precision. (Declarations in std are the standard's
// to make; this is the one place tsi adds any, for this build only.)
namespace std {
using boost::multiprecision::abs;
using boost::multiprecision::acos;
using boost::multiprecision::cbrt;
using boost::multiprecision::ceil;
using boost::multiprecision::copysign;
using boost::multiprecision::cos;
using boost::multiprecision::exp;
using boost::multiprecision::expm1;
using boost::multiprecision::fabs;
using boost::multiprecision::floor;
using boost::multiprecision::fma;
using boost::multiprecision::hypot;
using boost::multiprecision::isfinite;
using boost::multiprecision::isinf;
using boost::multiprecision::isnan;
using boost::multiprecision::ldexp;
using boost::multiprecision::log;
using boost::multiprecision::log2;
using boost::multiprecision::lround;
using boost::multiprecision::pow;
using boost::multiprecision::round;
using boost::multiprecision::sin;
using boost::multiprecision::sqrt;
namespace numbers {
template <>
inline const boost::multiprecision::float128 pi_v<boost::multiprecision::float128> =
    boost::multiprecision::float128("3.14159265358979323846264338327950288419716939937510582097494");
}  // namespace numbers
}  // namespace std
// Messages show a float128 as the double nearest to it.
template <>
struct fmt::formatter<boost::multiprecision::float128> : fmt::formatter<double> {
  auto format(const boost::multiprecision::float128& x, fmt::format_context& ctx) const {
    return fmt::formatter<double>::format(static_cast<double>(x), ctx);
  }
};
#elif defined(TSI_PRECISION_LONG_DOUBLE)
#define TSI_REAL_TYPE long double
#define TSI_PRECISION_NAME "long-double"
#define TSI_REAL_CONSTEXPR constexpr
#else
#define TSI_REAL_TYPE double
#define TSI_PRECISION_NAME "double"
#define TSI_REAL_CONSTEXPR constexpr
#endif
