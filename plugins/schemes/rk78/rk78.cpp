// rk78: the classical adaptive Runge-Kutta-Fehlberg 7(8) pair of Boost.Odeint, for the
// filtered or direct problem. The default reference solver, and the baseline a user would
// otherwise pick (its cost grows like 1/eps).
#include <boost/numeric/odeint.hpp>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tsi/error.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace odeint = boost::numeric::odeint;
using tsi::Real;
using tsi::Complex;
using tsi::Vector;
using State = std::vector<Real>;  // (re, im) pairs of the complex state

// Odeint's error test with the tolerance relative to the full state anchor + z, while the
// stepper itself sees only the deviation z (see Rk78::step).
struct AnchoredErrorChecker {
  using value_type = Real;
  using algebra_type = odeint::range_algebra;
  using operations_type = odeint::default_operations;

  Real tol = 1e-10;
  const State* anchor = nullptr;

  template <class S, class D, class E, class T>
  Real error(algebra_type& /*algebra*/, const S& z, const D& dzdt, E& err, T dt) const {
    Real worst = 0.0;
    for (size_t i = 0; i < z.size(); ++i) {
      const Real scale = tol + tol * (std::abs((*anchor)[i] + z[i]) + std::abs(dt) * std::abs(dzdt[i]));
      worst = std::max(worst, std::abs(err[i]) / scale);
    }
    return worst;
  }
};

using Controlled = odeint::controlled_runge_kutta<odeint::runge_kutta_fehlberg78<State, Real, State, Real>, AnchoredErrorChecker,
                                                  odeint::default_step_adjuster<Real, Real>,
                                                  odeint::initially_resizer, odeint::explicit_error_stepper_tag>;

class Rk78 final : public tsi::Stepper {
 public:
  struct Settings {
    Real tol, substeps_per_period;
  };

  Rk78(tsi::Problem& problem, Real h, const Settings& settings)
      : Stepper(problem, h),
        tol_(settings.tol),
        substeps_per_period_(settings.substeps_per_period),
        hi_(2 * static_cast<size_t>(problem.size())),
        lo_(hi_.size()),
        z_(hi_.size()),
        in_(problem.new_state()),
        out_(problem.new_state()),
        controlled_(AnchoredErrorChecker{settings.tol, &hi_}) {}

  void reset() override { dt_ = 0.0; }

  // Each substep integrates the deviation z from the state y = hi + lo (an unevaluated sum
  // per component) and folds it in with an exact two-sum. Adding an increment to y directly
  // rounds at ulp(y) per substep; over the 10^6 .. 10^8 substeps of a small-eps run that
  // accumulates (charged particle, eps = 1e-6: 4e-13 in p = 2 eps v - B x, 2e-7 in v, and
  // systematic when the substeps divide the fast period), while z rounds at ulp(z).
  void step(Real t, Vector& y) override {
    const Real h = h_;
    const auto n = y.size();
    const size_t m = 2 * static_cast<size_t>(n);
    std::fill(lo_.begin(), lo_.end(), 0.0);
    Eigen::Map<Vector>(reinterpret_cast<Complex*>(hi_.data()), n) = y;
    auto system = [&](const State& z, State& dzdt, Real time) {
      Real* in = reinterpret_cast<Real*>(in_.data());
      for (size_t i = 0; i < m; ++i) in[i] = hi_[i] + (lo_[i] + z[i]);
      problem_.rhs(time, in_, out_);
      dzdt.resize(m);
      Eigen::Map<Vector>(reinterpret_cast<Complex*>(dzdt.data()), n) = out_;
    };
    if (dt_ == 0.0 || dt_ * h < 0.0) dt_ = initial_substep(problem_, t, h, y);

    // Elapsed time as an unevaluated sum too: odeint's own t += dt would add a rounding per
    // substep, a phase error of steps * ulp / eps in the fast variable.
    const Real t_end = t + h;
    const Real max_dt = problem_.fast_period() / substeps_per_period_;
    Real t_hi = t, t_lo = 0.0;
    for (;;) {
      const Real remaining = (t_end - t_hi) - t_lo;
      if (remaining == 0.0 || remaining * h < 0.0) break;
      if (max_dt > 0.0 && std::abs(dt_) > max_dt) dt_ = std::copysign(max_dt, h);
      const bool last = std::abs(dt_) >= std::abs(remaining);
      Real dt = last ? remaining : dt_;
      Real t_try = t_hi + t_lo;
      const Real dt_taken = dt;
      std::fill(z_.begin(), z_.end(), 0.0);
      bool accepted = controlled_.try_step(system, z_, t_try, dt) == odeint::success;
      if (accepted && !all_finite(z_)) {
        // A NaN error estimate passes odeint's "err > 1" test: refuse the step ourselves.
        dt = 0.1 * dt_taken;
        accepted = false;
      }
      if (accepted) {
        for (size_t i = 0; i < m; ++i) two_sum(hi_[i], lo_[i], z_[i]);
        two_sum(t_hi, t_lo, dt_taken);
        if (last) break;
      } else if (std::abs(dt) < 1e-14 * std::max(std::abs(t_hi), std::abs(h))) {
        throw tsi::Error("rk78: step size underflow at t = " + std::to_string(tsi::to_double(t_hi)) + " (tol " +
                         std::to_string(tsi::to_double(tol_)) + " cannot be met)");
      }
      dt_ = dt;
    }
    for (size_t i = 0; i < m; ++i) hi_[i] += lo_[i];
    y = Eigen::Map<const Vector>(reinterpret_cast<const Complex*>(hi_.data()), n);
  }

  // The state, its rounding and the deviation (real pairs), the field's argument and value;
  // odeint's pair holds 13 stages and 3 temporaries more, allocated on its first step.
  double state_vectors() const override { return state_vectors_for(problem_.layout(), {}); }
  // Its own work vectors and odeint's stages, whatever the layout.
  static double state_vectors_for(const tsi::ProblemLayout&, const Settings&) { return 5.0 + 16.0; }

 private:
  // hi + lo += x, with the rounding of hi + x carried in lo (Knuth's two-sum).
  static void two_sum(Real& hi, Real& lo, Real x) {
    const Real sum = hi + x, b = sum - hi;
    lo += (hi - (sum - b)) + (x - b);
    hi = sum;
  }

  static bool all_finite(const State& x) {
    for (Real v : x)
      if (!std::isfinite(v)) return false;
    return true;
  }

  // The largest of the doubles of x, as the error test measures them (a real state held two
  // values to an entry gets the same substeps as held one to an entry).
  static Real max_double(const Vector& x) {
    return Eigen::Map<const tsi::RealVector>(reinterpret_cast<const Real*>(x.data()), 2 * x.size())
        .cwiseAbs()
        .maxCoeff();
  }

  // Hairer-Norsett-Wanner's first guess: a step over which y changes by a small fraction.
  Real initial_substep(tsi::Problem& problem, Real t, Real h, const Vector& y) {
    problem.rhs(t, y, out_);
    const Real size = max_double(y), scale = tol_ + tol_ * size, rate = max_double(out_);
    Real dt = rate > 0.0 ? 0.01 * std::max(scale, size) / rate : std::abs(h);
    dt = std::min(dt, std::abs(h));
    return h < 0.0 ? -dt : dt;
  }

  Real tol_;
  Real substeps_per_period_;
  Real dt_ = 0.0;  // the controller's last substep, carried across calls
  State hi_, lo_, z_;
  Vector in_, out_;
  Controlled controlled_;  // after hi_: its error checker points at it
};

void register_rk78(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "rk78";
  entry.info.aliases = {"rkf78"};
  entry.info.summary = "classical adaptive Runge-Kutta-Fehlberg 7(8) (Boost.Odeint)";
  entry.info.params = {tsi::number_param("tol", 1e-10, "absolute and relative tolerance per substep")
                           .range(tsi::smallest_tolerance, 1e-1),
                       tsi::number_param("substeps_per_period", 8.0,
                                         "fewest substeps per period of an explicit fast time "
                                         "dependence (filtered problem): larger steps alias")
                           .range(1.0, 1e6)};
  entry.traits.order = 7;
  entry.traits.adaptive = true;
  entry.traits.reformulations = {"direct", "filtered"};
  entry.create = [](const tsi::Params& p) {
    return tsi::make_scheme<Rk78>(Rk78::Settings{p.number("tol"), p.number("substeps_per_period")});
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("rk78", register_rk78)
