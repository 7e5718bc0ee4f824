#pragma once
// The micro-macro scheme of Chartier, Crouseilles, Lemou and Mehats (Numer. Math. 129, 2015),
// as MicroMacro.jl implements it (tests/data/rivals/micro-macro.md, section 3): the filtered
// solution split as
//     y(t) = C1(ub(t))(t/eps) + w(t),   C1(ub)(tau) = ub + eps (A f_.(ub))(tau)
// (standard averaging of order 1, <C1(ub)> = ub), the macro part ub' = F(ub) = <f_.(C1(ub))> + L ub
// smooth and the micro part w = O(eps^2) with
//     w' = L w + g(t/eps),  g(tau) = f_tau(C1(ub)(tau) + w) - (I - Pi) f_tau(ub) + eps L (A f_.(ub))(tau)
//                                      - F - eps A( Df_.(ub)(F + L ub) - L f_.(ub) )(tau),
// F + eps A(...) being d/dt C1(ub(t)) (the last term the slow time the remainder brings).
// One step is the explicit midpoint on (ub, w) in the frame e^{-L s} of the step's start, with
// the micro part's fast phase integrated exactly for the field frozen at the stage:
//     int_a^b g(s/eps) ds = (b - a) <g> + eps [(A g)(b/eps) - (A g)(a/eps)].
// Uniformly of order 2 in eps (f and Df only). The state is y; (ub, w) are carried between the
// steps of one trajectory and formed again from y (ub = y - eps (A f_.(y))(t/eps),
// w = y - C1(ub)(t/eps) = O(eps^2)) when a step finds another state than the one it left.
#include "filtered_grid.hpp"
#include "tsi/stepper.hpp"

namespace tsi_micro_macro {

struct CclmSettings {
  int n_tau = 32;
};

class Cclm final : public tsi::Stepper {
 public:
  Cclm(tsi::Problem& problem, Real h, const CclmSettings& settings)
      : Stepper(problem, h),
        grid_(problem, settings.n_tau, "micro-macro"),
        f_series_(problem.size(), settings.n_tau),
        d_series_(problem.size(), settings.n_tau),
        g_series_(problem.size(), settings.n_tau),
        half_(grid_.remainder_flow(h / 2)),
        whole_(grid_.remainder_flow(h)) {}

  void reset() override { started_ = false; }

  void step(Real t, Vector& y) override {
    const Real eps = grid_.eps();
    if (!started_ || t != next_t_ || y != output_) start(t, y);
    const Real theta0 = tsi::fast_phase(t, eps), theta_half = tsi::fast_phase(t + h_ / 2, eps),
               theta1 = tsi::fast_phase(t + h_, eps);

    // Stage at the step's start (the field of ub is the output's).
    fields(ub_, w_, true, macro_);
    micro_increment(h_ / 2, theta0, theta_half, micro_);
    stage_ub_ = ub_ + (h_ / 2) * macro_;
    stage_w_ = w_ + micro_;
    // Stage at the middle, in the middle's own frame (e^{L h/2} of the start's).
    turn(half_, stage_ub_);
    turn(half_, stage_w_);
    fields(stage_ub_, stage_w_, false, macro_);
    micro_increment(h_, theta0, theta1, micro_);
    // z_{n+1} = z_n + h e^{-L h/2} (F, micro) in the start's frame, turned by e^{L h} into the end's.
    turn(half_, macro_);
    turn(half_, micro_);
    turn(whole_, ub_);
    turn(whole_, w_);
    ub_ += h_ * macro_;
    w_ += micro_;
    output(t + h_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {grid_.n_tau()}); }
  // Grids of n_tau vectors: f_tau(ub), its antiderivative, C1, f_tau(C1), the derivative term and
  // its antiderivative, the micro field, three series (coefficients and work space each); and
  // ub, w, the output, two stages, the macro and micro increments, the grid's two.
  static double state_vectors_for(const tsi::ProblemLayout&, const CclmSettings& s) {
    return 13.0 * s.n_tau + 9.0;
  }

 private:
  // The macro field F = <f_.(C1(ub))> (L ub is the frame's) at (ub, w), and g's series;
  // `f_ready`: f_ and f_series_ already hold ub's field.
  void fields(const Vector& ub, const Vector& w, bool f_ready, Vector& macro) {
    const Real eps = grid_.eps();
    if (!f_ready) {
      grid_.field(ub, f_);
      f_series_.analyse(f_);
    }
    f_series_.mean(mean_f_);
    f_series_.antiderivative_grid(c1_, eps);
    c1_.colwise() += ub;  // C1(ub) on the grid
    grid_.field(c1_, fc1_);
    macro = fc1_.rowwise().mean();
    // d/dt C1 = F + eps A( Df(ub)(F + L ub) - L f(ub) ).
    grid_.apply_remainder(ub, direction_);
    direction_ += macro;
    grid_.derivative(ub, direction_, d_);
    if (grid_.has_remainder()) d_ -= grid_.remainder().asDiagonal() * f_;
    d_series_.analyse(d_);
    d_series_.antiderivative_grid(ad_, eps);
    // g = f(C1 + w) - f(ub) + <f(ub)> - F - eps A(...)  (eps L A f(ub) is inside the last term).
    c1_.colwise() += w;
    grid_.field(c1_, fc1_);
    fc1_ -= f_;
    fc1_ -= ad_;
    fc1_.colwise() += mean_f_ - macro;
    g_series_.analyse(fc1_);
  }
  // int over [t_a, t_b] of the frozen micro field g(s/eps): (t_b - t_a) <g> + eps [A g(theta_b) - A g(theta_a)].
  void micro_increment(Real length, Real theta_a, Real theta_b, Vector& out) {
    g_series_.mean(out);
    out *= length;
    g_series_.antiderivative_at(theta_b, point_);
    out += grid_.eps() * point_;
    g_series_.antiderivative_at(theta_a, point_);
    out -= grid_.eps() * point_;
  }
  // y = C1(ub)(theta) + w at time t, leaving ub's field in f_series_ for the next step.
  void output(Real t, Vector& y) {
    grid_.field(ub_, f_);
    f_series_.analyse(f_);
    f_series_.antiderivative_at(tsi::fast_phase(t, grid_.eps()), point_);
    y = ub_ + grid_.eps() * point_ + w_;
    output_ = y;
    next_t_ = t;
    started_ = true;
  }
  void start(Real t, const Vector& y) {
    const Real theta = tsi::fast_phase(t, grid_.eps());
    grid_.field(y, f_);
    f_series_.analyse(f_);
    f_series_.antiderivative_at(theta, point_);
    ub_ = y - grid_.eps() * point_;
    grid_.field(ub_, f_);
    f_series_.analyse(f_);
    f_series_.antiderivative_at(theta, point_);
    w_ = y - ub_ - grid_.eps() * point_;
  }

  FilteredGrid grid_;
  TauSeries f_series_, d_series_, g_series_;
  Vector half_, whole_;  // e^{L h/2}, e^{L h} (empty without a remainder)
  bool started_ = false;
  Real next_t_ = 0;
  Vector ub_, w_, output_, stage_ub_, stage_w_, macro_, micro_, mean_f_, direction_, point_;
  Matrix f_, c1_, fc1_, d_, ad_;
};

}  // namespace tsi_micro_macro
