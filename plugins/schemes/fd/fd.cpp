// FD-TSI (eq. FD scheme), the explicit finite-difference two-scale integrator of
// Chartier-Crouseilles-Lemou-Mehats:
//   (U^{n+1/2} - U^n)/(h/2) - L U^{n+1/2}       = N(U^n)
//   (U^{n+1}   - U^n)/h     - L (U^{n+1} + U^n)/2 = N(U^{n+1/2})
// L diagonal, so both stages are explicit. Uniform order 2 needs prepared data of order 3.
#include <limits>
#include <memory>

#include "tsi/diagonal.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::Vector;

class Fd final : public tsi::Stepper {
 public:
  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    if (h != h_ || problem.size() != inverse_.size()) {
      tsi::diagonal_function(problem.linear_multipliers(), 0.5 * h,
                             [](Complex z) { return 1.0 / (1.0 - z); }, inverse_);
      tsi::diagonal_function(problem.linear_multipliers(), 0.5 * h,
                             [](Complex z) { return 1.0 + z; }, forward_);
      h_ = h;
    }
    problem.nonlinear(t, y, n_);
    half_ = inverse_.cwiseProduct(y + (0.5 * h) * n_);
    problem.nonlinear(t + 0.5 * h, half_, n_);
    y = inverse_.cwiseProduct(forward_.cwiseProduct(y) + h * n_);
  }

 private:
  double h_ = std::numeric_limits<double>::quiet_NaN();
  Vector inverse_, forward_, half_, n_;  // (1 - hL/2)^{-1}, (1 + hL/2)
};

void register_fd(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "fd";
  entry.info.aliases = {"fd-tsi"};
  entry.info.summary = "FD-TSI: explicit finite-difference two-scale scheme (eq. FD scheme)";
  entry.traits.order = 2;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 3;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params&) { return std::make_unique<Fd>(); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("fd", register_fd)
