#pragma once
#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <limits>

#include "tsi/precision.hpp"

namespace tsi {

/// The real type of states, times, step sizes and scheme coefficients: double, or long double
/// or quad (Boost's float128) in a build configured with TSI_PRECISION=long-double or quad
/// (precision.hpp). Counters, timings and memory figures stay double in every build.
using Real = TSI_REAL_TYPE;
using Complex = std::complex<Real>;
/// A state: complex throughout (real models keep zero imaginary parts).
using Vector = Eigen::Matrix<Complex, Eigen::Dynamic, 1>;
using RealVector = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
/// A batch of states, one per column (column j is the state at the j-th tau point).
using Matrix = Eigen::Matrix<Complex, Eigen::Dynamic, Eigen::Dynamic>;
using MatrixRef = Eigen::Ref<Matrix>;
using ConstMatrixRef = Eigen::Ref<const Matrix>;
/// A batch of real states (a real model's tau grid), one per column.
using RealMatrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using RealMatrixRef = Eigen::Ref<RealMatrix>;
using Index = Eigen::Index;

/// Real inner product <u, v> = Re sum conj(u_i) v_i.
inline Real inner(const Vector& u, const Vector& v) { return u.dot(v).real(); }

/// Largest modulus of the entries (0 for an empty vector). Squared moduli are compared,
/// so there is one square root, not one hypot per entry.
inline Real max_norm(const Vector& v) { return v.size() ? std::sqrt(v.cwiseAbs2().maxCoeff()) : Real(0); }

/// The smallest relative tolerance an adaptive reference solver takes: 1e-16 in a double
/// build, 1e-20 in a long-double one, 1e-34 in quad (each just below its unit roundoff).
inline constexpr double smallest_tolerance =
    std::numeric_limits<Real>::digits > 64 ? 1e-34 : std::numeric_limits<Real>::digits > 53 ? 1e-20 : 1e-16;

/// The real part of a real or complex value: a kernel templated on real and complex tau grids
/// reads either (std::real takes no class type such as quad's Real).
inline Real real_part(const Real& x) { return x; }
inline Real real_part(const Complex& z) { return z.real(); }

/// A Real as a double: the figures a run records (errors, invariants, norms) are written
/// as doubles, whose range holds every error an extended build reaches.
inline double to_double(Real x) { return static_cast<double>(x); }

}  // namespace tsi
