#pragma once
// Functions of the fast phase tau held on a uniform grid tau_j = 2 pi j / n_tau (column j of a
// rows x n_tau matrix) and by their Fourier coefficients: the tau-mean <g>, the mean-free
// antiderivative A g = (d/dtau)^{-1} (I - Pi) g (SPEC.md section 2; the Nyquist mode set to
// zero, as there) and the trigonometric interpolant between grid points. The micro-macro and
// nested Picard schemes integrate the fast phase exactly through these.
#include <cmath>

#include "tsi/fft.hpp"
#include "tsi/types.hpp"

namespace tsi_micro_macro {

using tsi::Complex;
using tsi::Index;
using tsi::Matrix;
using tsi::Real;
using tsi::Vector;

class TauSeries {
 public:
  TauSeries(Index rows, int n_tau)
      : fft_(n_tau, static_cast<int>(rows)), n_tau_(n_tau), coefficients_(rows, n_tau), work_(rows, n_tau) {}

  int n_tau() const { return n_tau_; }
  /// The wave number of coefficient column j (FFT order), 0 for the Nyquist column (dropped).
  int wave_number(int j) const { return j < n_tau_ / 2 ? j : (j == n_tau_ / 2 ? 0 : j - n_tau_); }

  /// (i k)^power, by products (exact for the integers here).
  static Complex ik_power(int k, int power) {
    Complex z(1, 0);
    for (int i = 0; i < power; ++i) z *= Complex(0, static_cast<Real>(k));
    return z;
  }

  /// Takes g's values on the grid (rows x n_tau).
  void analyse(const Matrix& values) {
    fft_.transform(values.data(), coefficients_.data(), 0, Real(1) / static_cast<Real>(n_tau_));
    coefficients_.col(n_tau_ / 2).setZero();
  }
  /// <g>, the mean over tau.
  void mean(Vector& out) const { out = coefficients_.col(0); }
  /// (A^power g)(tau_j) at every grid point, scaled by `scale` (mode k divided by (ik)^power).
  void antiderivative_power_grid(int power, Matrix& out, Real scale = 1) {
    work_.col(0).setZero();
    for (int j = 1; j < n_tau_; ++j) {
      const int k = wave_number(j);
      if (k == 0)
        work_.col(j).setZero();
      else
        work_.col(j) = coefficients_.col(j) * (scale / ik_power(k, power));
    }
    out.resize(coefficients_.rows(), n_tau_);
    fft_.transform(work_.data(), out.data(), 1);
  }
  /// (A^power g)(theta) at any phase.
  void antiderivative_power_at(int power, Real theta, Vector& out) const {
    out.setZero(coefficients_.rows());
    for (int j = 1; j < n_tau_; ++j) {
      const int k = wave_number(j);
      if (k == 0) continue;
      const Real phase = static_cast<Real>(k) * theta;
      out += coefficients_.col(j) * (Complex(std::cos(phase), std::sin(phase)) / ik_power(k, power));
    }
  }
  /// (A g)(tau_j) at every grid point, scaled by `scale`.
  void antiderivative_grid(Matrix& out, Real scale = 1) { antiderivative_power_grid(1, out, scale); }
  /// (A g)(theta) at any phase.
  void antiderivative_at(Real theta, Vector& out) const { antiderivative_power_at(1, theta, out); }
  /// g(theta), the trigonometric interpolant of the grid values.
  void value_at(Real theta, Vector& out) const {
    out = coefficients_.col(0);
    for (int j = 1; j < n_tau_; ++j) {
      const int k = wave_number(j);
      if (k == 0) continue;
      const Real phase = static_cast<Real>(k) * theta;
      out += coefficients_.col(j) * Complex(std::cos(phase), std::sin(phase));
    }
  }

 private:
  tsi::FftBatch fft_;
  int n_tau_;
  Matrix coefficients_, work_;
};

}  // namespace tsi_micro_macro
