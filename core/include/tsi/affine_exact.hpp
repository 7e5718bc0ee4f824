#pragma once
#include "tsi/export.hpp"
#include "tsi/field.hpp"
#include "tsi/model.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// The largest n for which affine_exact_solution is offered: its arithmetic is quadruple
/// precision in software, O(n^3) per squaring.
inline constexpr Index max_affine_exact_dim = 32;

/// The exact solution of u' = C u + t a + b, u(0) = u0, with C = A / eps + B (SPEC.md section 7):
/// u(t) is the first n entries of e^{t Z} (u0, 0, 1) for the augmented matrix
/// Z = [[C, a, b], [0, 0, 1], [0, 0, 0]]. e^{t Z} is computed in quadruple precision (__float128)
/// by scaling and squaring a Taylor polynomial, since |t C| reaches 1e7 at eps = 1e-7 and double
/// (or x87 long double, all Eigen's matrix exponential takes) would leave 1e-9 (1e-12) of it.
/// The inputs are the double numbers the schemes integrate. `accuracy` is the relative
/// difference to a second evaluation with 8 times the scaling, or the rounding of u(t) to
/// double where that is larger, or quad's rounding of the phases, 2^-112 |t Z|_1 (common to both
/// evaluations). Refuses (tsi::Error) n > max_affine_exact_dim, t < 0 and sizes that do not
/// match, and (ConfigError on reference.scheme) a |t Z|_1 beyond 5e30, whose phases quad no
/// longer resolves to 1e-3 (eps = 1e-300 gave NaN with an accuracy of 1e-16 before), and a
/// solution that is not finite in quad.
TSI_API ExactSolution::Value affine_exact_solution(const Matrix& A, Real eps, const AffineTerms& f,
                                                   const Vector& u0, Real t);

}  // namespace tsi
