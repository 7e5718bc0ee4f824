#pragma once
#include <Eigen/Dense>
#include <cmath>
#include <complex>

namespace tsi {

using Complex = std::complex<double>;
/// A state: complex throughout (real models keep zero imaginary parts).
using Vector = Eigen::VectorXcd;
using RealVector = Eigen::VectorXd;
/// A batch of states, one per column (column j is the state at the j-th tau point).
using Matrix = Eigen::MatrixXcd;
using MatrixRef = Eigen::Ref<Matrix>;
using ConstMatrixRef = Eigen::Ref<const Matrix>;
/// A batch of real states (a real model's tau grid), one per column.
using RealMatrix = Eigen::MatrixXd;
using RealMatrixRef = Eigen::Ref<RealMatrix>;
using Index = Eigen::Index;

/// Real inner product <u, v> = Re sum conj(u_i) v_i.
inline double inner(const Vector& u, const Vector& v) { return u.dot(v).real(); }

/// Largest modulus of the entries (0 for an empty vector). Squared moduli are compared,
/// so there is one square root, not one hypot per entry.
inline double max_norm(const Vector& v) { return v.size() ? std::sqrt(v.cwiseAbs2().maxCoeff()) : 0.0; }

}  // namespace tsi
