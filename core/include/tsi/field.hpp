#pragma once
#include <functional>
#include <memory>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// f(t, u) = B u + t a + b: what a field that is affine in u and t declares (Field::affine_terms),
/// so that its model has an exact solution (SPEC.md section 7: HOODESolver.jl's linear test).
struct TSI_API AffineTerms {
  Matrix B;  ///< n x n
  Vector a;  ///< the coefficient of t (zero for an autonomous field)
  Vector b;
};

/// The field f(t, u) of a model of the general class u' = (1/eps) A u + f(t, u) given without
/// C++ for its A (the core's "matrix" model: A a matrix in the run's JSON, SPEC.md section 7).
/// A plugin registers one with Registry::add_field, Python with tsi.register_field; a run
/// names it in model.f.
class TSI_API Field {
 public:
  virtual ~Field() = default;
  /// out.col(j) = f(t(j), states.col(j)) for every column: one state per column, with its own
  /// time (the two-scale problem evaluates a whole tau grid in one call). `out` has the shape
  /// of `states`, is not zeroed and never aliases it. An autonomous field ignores t.
  virtual void evaluate(const RealVector& t, ConstMatrixRef states, MatrixRef out) const = 0;
  /// True when derivative() is given in closed form.
  virtual bool has_derivative() const { return false; }
  /// out.col(j) = D_u f(t(j), u_j) z_j, the derivative in u along z_j (the default throws).
  virtual void derivative(const RealVector& t, ConstMatrixRef states, ConstMatrixRef directions,
                          MatrixRef out) const;
  /// B, a and b when f(t, u) = B u + t a + b (then the matrix model offers an exact solution);
  /// null for any other field (the default).
  virtual const AffineTerms* affine_terms() const { return nullptr; }
};

}  // namespace tsi
