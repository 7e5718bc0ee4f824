#pragma once
// The first-order nested Picard integrator on the whole class (Cai and Zhou's NPI of order 1,
// written through the tau grid: tests/data/rivals/micro-macro.md, section 5.4): the filtered
// field frozen at y_n, its fast phase integrated exactly,
//     y_{n+1} = e^{L h} [ y_n + h <f_.(y_n)> + eps ((A f_.(y_n))(t_{n+1}/eps) - (A f_.(y_n))(t_n/eps)) ].
// Uniformly of order 1 (MicroMacro.jl's "schema 0"). Exact only where the tau grid resolves the
// phases of f_tau (for NLS, |k1^2 - k2^2 + k3^2 - m^2| up to about n_x^2/2).
#include "filtered_grid.hpp"
#include "tsi/stepper.hpp"

namespace tsi_micro_macro {

struct NestedPicardSettings {
  int n_tau = 32;
};

class NestedPicard final : public tsi::Stepper {
 public:
  NestedPicard(tsi::Problem& problem, Real h, const NestedPicardSettings& settings)
      : Stepper(problem, h),
        grid_(problem, settings.n_tau, "npi"),
        series_(problem.size(), settings.n_tau),
        whole_(grid_.remainder_flow(h)) {}

  void step(Real t, Vector& y) override {
    const Real eps = grid_.eps();
    grid_.field(y, field_);
    series_.analyse(field_);
    series_.mean(increment_);
    increment_ *= h_;
    series_.antiderivative_at(tsi::fast_phase(t + h_, eps), point_);
    increment_ += eps * point_;
    series_.antiderivative_at(tsi::fast_phase(t, eps), point_);
    increment_ -= eps * point_;
    y += increment_;
    turn(whole_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {grid_.n_tau()}); }
  // The field's grid and the series (coefficients, work space): 3 n_tau; the increment, a point,
  // e^{L h} and the grid's two.
  static double state_vectors_for(const tsi::ProblemLayout&, const NestedPicardSettings& s) { return 3.0 * s.n_tau + 5.0; }

 private:
  FilteredGrid grid_;
  TauSeries series_;
  Vector whole_, increment_, point_;
  Matrix field_;
};

}  // namespace tsi_micro_macro
