// FD-TSI (eq. FD scheme), the explicit finite-difference two-scale integrator of
// Chartier-Crouseilles-Lemou-Mehats:
//   (U^{n+1/2} - U^n)/(h/2) - L U^{n+1/2}       = N(U^n)
//   (U^{n+1}   - U^n)/h     - L (U^{n+1} + U^n)/2 = N(U^{n+1/2})
// L diagonal, so both stages are explicit. Uniform order 2 needs prepared data of order 3.
#include <limits>
#include <memory>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace algebra = tsi::algebra;
using tsi::Complex;
using tsi::Vector;

class Fd final : public tsi::Stepper {
 public:
  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    if (h != h_ || problem.size() != inverse_.size()) {
      const Vector& lambda = problem.linear_multipliers();
      tsi::diagonal_function(lambda, 0.5 * h, [](Complex z) { return 1.0 / (1.0 - z); }, inverse_);
      tsi::diagonal_function(lambda, 0.5 * h, [h](Complex z) { return 0.5 * h / (1.0 - z); }, half_inverse_);
      tsi::diagonal_function(lambda, 0.5 * h, [](Complex z) { return (1.0 + z) / (1.0 - z); }, cayley_);
      tsi::diagonal_function(lambda, 0.5 * h, [h](Complex z) { return h / (1.0 - z); }, full_inverse_);
      h_ = h;
    }
    problem.nonlinear(t, y, n_);
    algebra::diagonal_combination(inverse_, y, half_inverse_, n_, half_);
    problem.nonlinear(t + 0.5 * h, half_, n_);
    algebra::diagonal_combination(cayley_, y, full_inverse_, n_, y);
  }

 private:
  double h_ = std::numeric_limits<double>::quiet_NaN();
  // (1 - hL/2)^{-1}, (h/2) (1 - hL/2)^{-1}, (1 + hL/2) (1 - hL/2)^{-1}, h (1 - hL/2)^{-1}
  Vector inverse_, half_inverse_, cayley_, full_inverse_;
  Vector half_, n_;
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
