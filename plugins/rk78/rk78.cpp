// rk78: the classical adaptive Runge-Kutta-Fehlberg 7(8) pair of Boost.Odeint, for the
// filtered or direct problem. The default reference solver, and the baseline a user would
// otherwise pick (its cost grows like 1/eps).
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tsi/error.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace odeint = boost::numeric::odeint;
using tsi::Complex;
using tsi::Vector;
using State = std::vector<double>;  // (re, im) pairs of the complex state

class Rk78 final : public tsi::Stepper {
 public:
  Rk78(double tol, double substeps_per_period) : tol_(tol), substeps_per_period_(substeps_per_period) {}

  void reset() override { dt_ = 0.0; }

  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    const auto n = y.size();
    state_.resize(2 * static_cast<size_t>(n));
    in_.resize(n), out_.resize(n);
    Eigen::Map<Vector>(reinterpret_cast<Complex*>(state_.data()), n) = y;
    auto system = [&](const State& x, State& dxdt, double time) {
      in_ = Eigen::Map<const Vector>(reinterpret_cast<const Complex*>(x.data()), n);
      problem.rhs(time, in_, out_);
      dxdt.resize(x.size());
      Eigen::Map<Vector>(reinterpret_cast<Complex*>(dxdt.data()), n) = out_;
    };
    auto stepper = odeint::make_controlled(tol_, tol_, odeint::runge_kutta_fehlberg78<State>());
    if (dt_ == 0.0 || dt_ * h < 0.0) dt_ = initial_substep(problem, t, h, y);

    // Elapsed time as an unevaluated sum hi + lo (Kahan): odeint's own t += dt would add a
    // rounding per substep, a phase error of steps * ulp / eps in the fast variable.
    const double t_end = t + h;
    const double max_dt = problem.fast_period() / substeps_per_period_;
    double t_hi = t, t_lo = 0.0;
    for (;;) {
      const double remaining = (t_end - t_hi) - t_lo;
      if (remaining == 0.0 || remaining * h < 0.0) break;
      if (max_dt > 0.0 && std::abs(dt_) > max_dt) dt_ = std::copysign(max_dt, h);
      const bool last = std::abs(dt_) >= std::abs(remaining);
      double dt = last ? remaining : dt_;
      double t_try = t_hi + t_lo;
      const double dt_taken = dt;
      backup_ = state_;
      bool accepted = stepper.try_step(system, state_, t_try, dt) == odeint::success;
      if (accepted && !all_finite(state_)) {
        // A NaN error estimate passes odeint's "err > 1" test: refuse the step ourselves.
        state_ = backup_;
        dt = 0.1 * dt_taken;
        accepted = false;
      }
      if (accepted) {
        const double sum = t_hi + dt_taken;  // two-sum: the rounding of t_hi + dt_taken
        const double b = sum - t_hi;
        t_lo += (t_hi - (sum - b)) + (dt_taken - b);
        t_hi = sum;
        if (last) break;
      } else if (std::abs(dt) < 1e-14 * std::max(std::abs(t_hi), std::abs(h))) {
        throw tsi::Error("rk78: step size underflow at t = " + std::to_string(t_hi) + " (tol " +
                         std::to_string(tol_) + " cannot be met)");
      }
      dt_ = dt;
    }
    y = Eigen::Map<const Vector>(reinterpret_cast<const Complex*>(state_.data()), n);
  }

 private:
  static bool all_finite(const State& x) {
    for (double v : x)
      if (!std::isfinite(v)) return false;
    return true;
  }

  // Hairer-Norsett-Wanner's first guess: a step over which y changes by a small fraction.
  double initial_substep(tsi::Problem& problem, double t, double h, const Vector& y) {
    problem.rhs(t, y, out_);
    const double scale = tol_ + tol_ * tsi::max_norm(y), rate = tsi::max_norm(out_);
    double dt = rate > 0.0 ? 0.01 * std::max(scale, tsi::max_norm(y)) / rate : std::abs(h);
    dt = std::min(dt, std::abs(h));
    return h < 0.0 ? -dt : dt;
  }

  double tol_;
  double substeps_per_period_;
  double dt_ = 0.0;  // the controller's last substep, carried across calls
  State state_, backup_;
  Vector in_, out_;
};

void register_rk78(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "rk78";
  entry.info.aliases = {"rkf78"};
  entry.info.summary = "classical adaptive Runge-Kutta-Fehlberg 7(8) (Boost.Odeint)";
  entry.info.params = {tsi::number_param("tol", 1e-10, "absolute and relative tolerance per substep")
                           .range(1e-16, 1e-1),
                       tsi::number_param("substeps_per_period", 8.0,
                                         "fewest substeps per period of an explicit fast time "
                                         "dependence (filtered problem): larger steps alias")
                           .range(1.0, 1e6)};
  entry.traits.order = 7;
  entry.traits.adaptive = true;
  entry.traits.reformulations = {"direct", "filtered"};
  entry.create = [](const tsi::Params& p) { return std::make_unique<Rk78>(p.number("tol"), p.number("substeps_per_period")); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("rk78", register_rk78)
