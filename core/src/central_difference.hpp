#pragma once
// The derivative of a batched field by a central difference, the default of every field
// derivative a model does not give in closed form (Model's, TimeDependentField's).
#include <algorithm>
#include <cmath>
#include <limits>

#include "tsi/types.hpp"

namespace tsi {

/// out.col(j) = Dg(u_j) z_j for u_j = states.col(j), z_j = directions.col(j), where
/// field(values, out) evaluates g on every column, by a central difference with a step
/// balancing truncation (delta^2) and rounding (1/delta), relative to |u_j| (at least 1).
template <class Field>
void central_difference(const Field& field, ConstMatrixRef states, ConstMatrixRef directions, MatrixRef out) {
  const Real delta = std::cbrt(std::numeric_limits<Real>::epsilon());
  Matrix plus(states.rows(), states.cols()), minus(states.rows(), states.cols());
  for (Index j = 0; j < states.cols(); ++j) {
    const Real scale = std::max<Real>(1, states.col(j).norm()) / std::max<Real>(directions.col(j).norm(), 1e-300);
    plus.col(j) = states.col(j) + delta * scale * directions.col(j);
    minus.col(j) = states.col(j) - delta * scale * directions.col(j);
  }
  Matrix f_plus(states.rows(), states.cols()), f_minus(states.rows(), states.cols());
  field(plus, f_plus);
  field(minus, f_minus);
  for (Index j = 0; j < states.cols(); ++j) {
    const Real dn = directions.col(j).norm();
    if (dn == 0.0) {
      out.col(j).setZero();
      continue;
    }
    const Real scale = std::max<Real>(1, states.col(j).norm()) / dn;
    out.col(j) = (f_plus.col(j) - f_minus.col(j)) / (2.0 * delta * scale);
  }
}

}  // namespace tsi
