#pragma once
// The derivative-free micro-macro scheme of order n (Chartier, Lemou, Mehats, Zhao, IMA J.
// Numer. Anal. 2022; the recursion as HOODESolver.jl builds it, tests/data/rivals/micro-macro.md,
// section 4): standard averaging of order n, phi_n = Phi^[n] - id with <phi_n> = 0,
//     phi_1(u)     = eps A[ f_.(u) ],
//     phi_{k+1}(u) = eps A[ f_.(u + phi_k(u)) - (D phi_k(u)(G_k(u) + L u) - L phi_k(u)) ],
//     G_k(u)       = < f_.(u + phi_k(u)) >,
// only f is evaluated: the derivative of phi_k along G_k + L u is the central difference of
// fourth order with step eps^(k/4), as the two-scale preparation takes it (HOODESolver's
// one-sided quotient of step eps^k needs extended precision). The filtered solution is split as
// y = ub + phi_n(ub)(t/eps) + w with
//     ub' = G_n(ub) + L ub,
//     w'  = L w + f_{t/eps}(ub + phi_n(ub) + w) - G_n - (1/eps) d_tau phi_n(ub) - D phi_n(ub)(G_n + L ub) + L phi_n(ub),
// w = O(eps^{n+1}), and (ub, w) advanced by an explicit Runge-Kutta method of order q <= n in
// the frame e^{-L s} of the step's start (Lawson): uniformly of order q. The micro field's
// derivative of phi_n must be consistent with phi_n (it decides whether y = ub + phi_n(ub) + w
// holds): its step is at most difference_step. The base point solves
// y(t) = ub + phi_n(ub)(t/eps) by n sweeps (one more power of eps each); w takes the rest.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "filtered_grid.hpp"
#include "tsi/stepper.hpp"

namespace tsi_micro_macro {

struct DerivativeFreeSettings {
  int order = 2;     // n, of the change of variables
  int rk_order = 2;  // q <= n, of the Runge-Kutta method
  int n_tau = 32;
  Real difference_step = 1e-3;  // the largest step of the micro field's difference along G_n + L u
};

/// An explicit Runge-Kutta method of order 1 to 4: Euler, the explicit midpoint, Kutta's third
/// order, the classical fourth order.
struct RungeKutta {
  int stages;
  std::array<std::array<Real, 4>, 4> a;
  std::array<Real, 4> b, c;
  static RungeKutta of_order(int q) {
    switch (q) {
      case 1: return {1, {{{0, 0, 0, 0}}}, {1, 0, 0, 0}, {0, 0, 0, 0}};
      case 2: return {2, {{{0, 0, 0, 0}, {0.5, 0, 0, 0}}}, {0, 1, 0, 0}, {0, 0.5, 0, 0}};
      case 3: return {3, {{{0, 0, 0, 0}, {0.5, 0, 0, 0}, {-1, 2, 0, 0}}}, {Real(1) / 6, Real(2) / 3, Real(1) / 6, 0}, {0, 0.5, 1, 0}};
      default:
        return {4, {{{0, 0, 0, 0}, {0.5, 0, 0, 0}, {0, 0.5, 0, 0}, {0, 0, 1, 0}}},
                {Real(1) / 6, Real(1) / 3, Real(1) / 3, Real(1) / 6}, {0, 0.5, 0.5, 1}};
    }
  }
};

class DerivativeFree final : public tsi::Stepper {
 public:
  DerivativeFree(tsi::Problem& problem, Real h, const DerivativeFreeSettings& settings)
      : Stepper(problem, h),
        settings_(settings),
        grid_(problem, settings.n_tau, "micro-macro"),
        series_(problem.size(), settings.n_tau),
        rk_(RungeKutta::of_order(settings.rk_order)),
        whole_(grid_.remainder_flow(h)) {
    for (int i = 0; i < rk_.stages; ++i) {
      to_stage_.push_back(grid_.remainder_flow(rk_.c[static_cast<size_t>(i)] * h));
      from_stage_.push_back(grid_.remainder_flow(-rk_.c[static_cast<size_t>(i)] * h));
    }
    levels_.resize(static_cast<size_t>(settings.order) + 2);
    k_ub_.resize(static_cast<size_t>(rk_.stages));
    k_w_.resize(static_cast<size_t>(rk_.stages));
  }

  void reset() override { started_ = false; }

  void step(Real t, Vector& y) override {
    if (!started_ || t != next_t_ || y != output_) start(t, y);
    for (int i = 0; i < rk_.stages; ++i) {
      const auto si = static_cast<size_t>(i);
      stage_ub_ = ub_;
      stage_w_ = w_;
      for (int j = 0; j < i; ++j) {
        const Real a = h_ * rk_.a[si][static_cast<size_t>(j)];
        if (a == 0) continue;
        stage_ub_ += a * k_ub_[static_cast<size_t>(j)];
        stage_w_ += a * k_w_[static_cast<size_t>(j)];
      }
      turn(to_stage_[si], stage_ub_);
      turn(to_stage_[si], stage_w_);
      stage_field(t + rk_.c[si] * h_, stage_ub_, stage_w_, k_ub_[si], k_w_[si]);
      turn(from_stage_[si], k_ub_[si]);
      turn(from_stage_[si], k_w_[si]);
    }
    for (int i = 0; i < rk_.stages; ++i) {
      const Real b = h_ * rk_.b[static_cast<size_t>(i)];
      if (b == 0) continue;
      ub_ += b * k_ub_[static_cast<size_t>(i)];
      w_ += b * k_w_[static_cast<size_t>(i)];
    }
    turn(whole_, ub_);
    turn(whole_, w_);
    next_t_ = t + h_;
    phi_at(order_, ub_, tsi::fast_phase(next_t_, grid_.eps()), point_);
    y = ub_ + point_ + w_;
    output_ = y;
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), settings_); }
  // Each level of the recursion holds four grids of n_tau vectors (phi, its integrand, the
  // shifted point's field, the derivative), the stage two more and the series two; ub, w, the
  // output, the stages and 2 q stage slopes.
  static double state_vectors_for(const tsi::ProblemLayout&, const DerivativeFreeSettings& s) {
    return (4.0 * s.order + 4.0) * s.n_tau + 8.0 + 2.0 * s.rk_order;
  }

 private:
  // What one level of the recursion works in, kept between calls (no allocation per call).
  struct Level {
    Matrix previous, previous_integrand, shifted, derivative, plus, minus, scratch;
  };

  // phi_k(u) on the grid and the integrand H_k with phi_k = eps A H_k.
  void phi(int k, const Vector& u, Matrix& values, Matrix& integrand) {
    if (k == 1) {
      grid_.field(u, integrand);
    } else {
      Level& level = levels_[static_cast<size_t>(k)];
      phi(k - 1, u, level.previous, level.previous_integrand);
      level.shifted = level.previous;
      level.shifted.colwise() += u;
      grid_.field(level.shifted, integrand);  // f_.(u + phi_{k-1}(u))
      const Vector average = integrand.rowwise().mean();
      derivative_along(k - 1, u, average, level.previous, recursion_step(k - 1), level, level.derivative);
      integrand -= level.derivative;
    }
    series_.analyse(integrand);
    series_.antiderivative_grid(values, grid_.eps());
  }
  // out = D phi_k(u)(G + L u) - L phi_k(u), the first term by the central difference of fourth
  // order with step d along g = G + L u (in `level`'s work space, a level above k's).
  void derivative_along(int k, const Vector& u, const Vector& average, const Matrix& phi_u, Real d, Level& level,
                        Matrix& out) {
    grid_.apply_remainder(u, direction_);
    direction_ += average;
    const Vector g = direction_;
    phi(k, u + d * g, level.plus, level.scratch);
    phi(k, u - d * g, level.minus, level.scratch);
    out = Real(8) * (level.plus - level.minus);
    phi(k, u + 2 * d * g, level.plus, level.scratch);
    phi(k, u - 2 * d * g, level.minus, level.scratch);
    out -= level.plus - level.minus;
    out /= 12 * d;
    if (grid_.has_remainder()) out -= grid_.remainder().asDiagonal() * phi_u;
  }
  // The step of level k's differences inside the recursion: eps^(k/4), as the two-scale
  // preparation takes it (its error d^4 O(eps) is O(eps^(k+1)), and the steps stay coarse, so
  // the rounding of one level is not amplified by the next).
  Real recursion_step(int k) const { return std::pow(grid_.eps(), Real(0.25) * static_cast<Real>(k)); }
  // The step of the micro field's derivative of phi_n, which must be consistent with phi_n
  // itself (y = ub + phi_n(ub) + w): the recursion's step, at most difference_step.
  Real micro_step(int n) const { return std::min(recursion_step(n), settings_.difference_step); }
  // phi_k(u)(theta).
  void phi_at(int k, const Vector& u, Real theta, Vector& out) {
    phi(k, u, values_, integrand_);
    series_.analyse(integrand_);
    series_.antiderivative_at(theta, out);
    out *= grid_.eps();
  }
  // The slopes of ub and w (y frame, without L ub and L w: the frame's) at time t.
  void stage_field(Real t, const Vector& ub, const Vector& w, Vector& slope_ub, Vector& slope_w) {
    const int n = order_;
    const Real theta = tsi::fast_phase(t, grid_.eps());
    phi(n, ub, values_, integrand_);
    shifted_ = values_;
    shifted_.colwise() += ub;
    grid_.field(shifted_, field_);
    slope_ub = field_.rowwise().mean();  // G_n(ub)
    derivative_along(n, ub, slope_ub, values_, micro_step(n), levels_[static_cast<size_t>(n) + 1], derivative_);
    // phi_n(theta), H_n(theta) - <H_n> = (1/eps) d_tau phi_n(theta), and the derivative at theta.
    series_.analyse(integrand_);
    series_.antiderivative_at(theta, point_);
    point_ *= grid_.eps();
    series_.value_at(theta, slope_w);
    slope_w -= integrand_.rowwise().mean();
    series_.analyse(derivative_);
    series_.value_at(theta, term_);
    slope_w += term_;
    point_ += ub + w;
    grid_.field_at(t, point_, term_);
    slope_w = term_ - slope_ub - slope_w;
  }
  // The base point and w from y, and the order of the change of variables: the expansion is
  // asymptotic, so where its corrections at y stop decreasing (eps near 1) it is truncated at
  // its smallest one, as the two-scale preparation is (Klein-Gordon at eps = 1: order 4 diverges).
  void start(Real t, const Vector& y) {
    const Real theta = tsi::fast_phase(t, grid_.eps());
    order_ = 1;
    Matrix previous;
    phi(1, y, previous, integrand_);
    Real last = std::numeric_limits<Real>::infinity();
    for (int k = 2; k <= settings_.order; ++k) {
      phi(k, y, values_, integrand_);
      const Real correction = (values_ - previous).cwiseAbs().maxCoeff();
      const Real size = values_.cwiseAbs().maxCoeff() + y.cwiseAbs().maxCoeff();
      if (!std::isfinite(correction) || (k > 2 && correction > std::max(last, 64 * std::numeric_limits<Real>::epsilon() * size)))
        break;
      last = correction;
      previous.swap(values_);
      order_ = k;
    }
    ub_ = y;
    for (int k = 1; k <= order_; ++k) {
      phi_at(k, ub_, theta, point_);
      ub_ = y - point_;
    }
    phi_at(order_, ub_, theta, point_);
    w_ = y - ub_ - point_;
    next_t_ = t;
    started_ = true;
  }

  DerivativeFreeSettings settings_;
  FilteredGrid grid_;
  TauSeries series_;
  RungeKutta rk_;
  Vector whole_;
  std::vector<Vector> to_stage_, from_stage_, k_ub_, k_w_;
  bool started_ = false;
  int order_ = 1;  // of the change of variables in use (settings_.order, or less near eps = 1)
  Real next_t_ = 0;
  Vector ub_, w_, output_, stage_ub_, stage_w_, point_, term_;
  std::vector<Level> levels_;  // index k: phi_k's work space
  Vector direction_;
  Matrix values_, integrand_, shifted_, field_, derivative_;
};

}  // namespace tsi_micro_macro
