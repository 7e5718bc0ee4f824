#pragma once
// Nested Picard integrators on the whole class, of order 1 and 2 (after Cai and Zhou's NPI for
// Klein-Gordon; tests/data/rivals/micro-macro.md, sections 5.4 and 9): Duhamel's formula in the
// frame of the step's start, z' = g(s, z) = e^{-L s} f_{theta(s)}(e^{L s} z), theta(s) =
// (t_n + s)/eps, iterated by Picard with the slow dependence expanded in s and the fast phase
// integrated exactly on the tau grid (TauSeries::integral and moment):
//   order 1   z(h) = y_n + int_0^h f_theta(y_n) ds
//             = y_n + h <f> + eps [(A f)(theta_1) - (A f)(theta_0)]  (MicroMacro.jl's "schema 0").
//   order 2   the second Picard iterate, linearised about y_n:
//             z(h) = y_n + int f_theta(y_n) + int s K1(theta) + eps int K2(theta),
//             K1(tau) = Df_tau(y_n)(<f> + L y_n) - L f_tau(y_n)   (the slow drift of z and of the frame),
//             K2(tau) = Df_tau(y_n)((A f)(tau) - (A f)(theta_0))  (the fast part of the first iterate).
// Then y_{n+1} = e^{L h} z(h). Every neglected term is O(h^3) whatever eps (the fast phase is
// never expanded): uniformly of order 1 and 2, with 1 and 3 batches of n_tau evaluations a step.
// Exact only where the tau grid resolves the phases of f_tau (for NLS, |k1^2 - k2^2 + k3^2 - m^2|
// up to about n_x^2/2).
#include "filtered_grid.hpp"
#include "tsi/stepper.hpp"

namespace tsi_micro_macro {

struct NestedPicardSettings {
  int n_tau = 32;
  int order = 1;
};

class NestedPicard final : public tsi::Stepper {
 public:
  NestedPicard(tsi::Problem& problem, Real h, const NestedPicardSettings& settings)
      : Stepper(problem, h),
        order_(settings.order),
        grid_(problem, settings.n_tau, "npi"),
        series_(problem.size(), settings.n_tau),
        whole_(grid_.remainder_flow(h)) {}

  void step(Real t, Vector& y) override {
    const Real eps = grid_.eps(), theta0 = tsi::fast_phase(t, eps), theta1 = tsi::fast_phase(t + h_, eps);
    grid_.field(y, field_);
    series_.analyse(field_);
    series_.integral(h_, eps, theta0, theta1, increment_, point_);
    if (order_ >= 2) {
      // K1 = Df(y)(<f> + L y) - L f: its s-moment.
      series_.mean(direction_);
      grid_.apply_remainder(y, point_);
      direction_ += point_;
      // K2's directions, (A f)(tau_j) - (A f)(theta_0), before the series is reused.
      series_.antiderivative_grid(directions_);
      series_.antiderivative_at(theta0, point_);
      directions_.colwise() -= point_;
      grid_.derivative(y, direction_, derivative_);
      if (grid_.has_remainder()) derivative_ -= grid_.remainder().asDiagonal() * field_;
      series_.analyse(derivative_);
      series_.moment(h_, eps, theta0, theta1, term_, point_);
      increment_ += term_;
      grid_.derivative(y, directions_, derivative_);
      series_.analyse(derivative_);
      series_.integral(h_, eps, theta0, theta1, term_, point_);
      increment_ += eps * term_;
    }
    y += increment_;
    turn(whole_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {grid_.n_tau(), order_}); }
  // The field's grid and the series (coefficients, work space): 3 n_tau, and order 2 two grids
  // more (the directions, the derivatives); the increment, a term, a point, a direction,
  // e^{L h} and the grid's two.
  static double state_vectors_for(const tsi::ProblemLayout&, const NestedPicardSettings& s) {
    return (s.order >= 2 ? 5.0 : 3.0) * s.n_tau + 7.0;
  }

 private:
  int order_;
  FilteredGrid grid_;
  TauSeries series_;
  Vector whole_, increment_, point_, term_, direction_;
  Matrix field_, directions_, derivative_;
};

}  // namespace tsi_micro_macro
