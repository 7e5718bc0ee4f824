#pragma once
// The filtered problem y' = L y + N(t, y), N(t, y) = f_{t/eps}(y), seen on a tau grid: since N
// has period 2 pi eps in t (Problem::oscillation_period), f_{tau_j}(y) = N(eps tau_j, y). L is
// the model's remainder (diagonal i omega, bounded in eps; empty without one), which the
// schemes here integrate exactly by working in the frame e^{-L s} of the step's start.
#include <string>
#include <vector>

#include "tau_series.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"
#include "tsi/problem.hpp"

namespace tsi_micro_macro {

class FilteredGrid {
 public:
  FilteredGrid(tsi::Problem& problem, int n_tau, const std::string& scheme)
      : problem_(problem), n_tau_(n_tau), column_(problem.new_state()), result_(problem.new_state()) {
    const Real period = problem.oscillation_period();
    if (!(period > 0))
      throw tsi::ConfigError("reformulation", "got a problem without a 2 pi eps-periodic fast phase for \"" + scheme +
                                                  "\"; expected the filtered reformulation (its N(t, y) = f_{t/eps}(y))");
    eps_ = period / tsi::two_pi;
    times_.resize(n_tau);
    for (int j = 0; j < n_tau; ++j) times_[static_cast<size_t>(j)] = period * static_cast<Real>(j) / static_cast<Real>(n_tau);
    remainder_ = problem.remainder_multipliers();
  }

  Real eps() const { return eps_; }
  int n_tau() const { return n_tau_; }
  Index rows() const { return problem_.size(); }
  bool has_remainder() const { return remainder_.size() > 0; }
  /// L's diagonal (empty without a remainder).
  const Vector& remainder() const { return remainder_; }

  /// out.col(j) = f_{tau_j}(y).
  void field(const Vector& y, Matrix& out) {
    out.resize(rows(), n_tau_);
    for (int j = 0; j < n_tau_; ++j) {
      problem_.nonlinear(times_[static_cast<size_t>(j)], y, result_);
      out.col(j) = result_;
    }
  }
  /// out.col(j) = f_{tau_j}(ys.col(j)).
  void field(const Matrix& ys, Matrix& out) {
    out.resize(rows(), n_tau_);
    for (int j = 0; j < n_tau_; ++j) {
      column_ = ys.col(j);
      problem_.nonlinear(times_[static_cast<size_t>(j)], column_, result_);
      out.col(j) = result_;
    }
  }
  /// out.col(j) = Df_{tau_j}(y) z.
  void derivative(const Vector& y, const Vector& z, Matrix& out) {
    out.resize(rows(), n_tau_);
    for (int j = 0; j < n_tau_; ++j) {
      problem_.nonlinear_derivative(times_[static_cast<size_t>(j)], y, z, result_);
      out.col(j) = result_;
    }
  }
  /// f_theta(y) at the time t itself (theta = t / eps).
  void field_at(Real t, const Vector& y, Vector& out) {
    out.resize(rows());
    problem_.nonlinear(t, y, out);
  }
  /// L y (0 without a remainder).
  void apply_remainder(const Vector& y, Vector& out) const {
    if (has_remainder())
      out = remainder_.cwiseProduct(y);
    else
      out.setZero(y.size());
  }
  /// e^{L s}'s diagonal (empty without a remainder).
  Vector remainder_flow(Real s) const {
    if (!has_remainder()) return {};
    return (remainder_ * s).array().exp().matrix();
  }

 private:
  tsi::Problem& problem_;
  int n_tau_;
  Real eps_ = 0;
  std::vector<Real> times_;
  Vector remainder_, column_, result_;
};

/// y <- e^{L s} y for a diagonal factor from FilteredGrid::remainder_flow (empty: identity).
inline void turn(const Vector& factor, Vector& y) {
  if (factor.size() > 0) y.array() *= factor.array();
}

}  // namespace tsi_micro_macro
