// SE1-TSI (eq. S1), the symmetric one-stage exponential two-scale integrator:
//   U^{n+1/2} = e^{z/2} U^n + (h/2) phi1(z/2) N(U^{n+1/2})     (implicit: fixed point)
//   U^{n+1}   = e^{z}   U^n +  h    phi1(z)   N(U^{n+1/2}),     z = h L.
#include <cmath>
#include <memory>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/fixed_point.hpp"
#include "tsi/phi.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace algebra = tsi::algebra;
using tsi::Real;
using tsi::Complex;
using tsi::Vector;

// The diagonal coefficients of step size h: the binding's cache (one value per tau mode on the
// two-scale problem without a remainder: tsi::Diagonal).
struct Coefficients {
  tsi::Diagonal e_half, b_half, e_full, b_full;
  Coefficients(const tsi::Problem& problem, Real h) {
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    tsi::diagonal_function(lambda, 0.5 * h, [](Complex z) { return std::exp(z); }, e_half);
    tsi::diagonal_function(lambda, 0.5 * h, [h](Complex z) { return 0.5 * h * tsi::phi1(z); }, b_half);
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(z); }, e_full);
    tsi::diagonal_function(lambda, h, [h](Complex z) { return h * tsi::phi1(z); }, b_full);
  }
};

class Se1 final : public tsi::Stepper {
 public:
  Se1(tsi::Problem& problem, Real h, const tsi::FixedPointOptions& options)
      : Stepper(problem, h),
        c_(problem, h),
        solver_(tsi::make_fixed_point_solver(options)),
        guess_(options),
        y_half_(problem.new_state()),
        n_half_(problem.new_state()),
        base_(problem.layout().stores_stage_bases() ? problem.new_state() : Vector()) {}

  void reset() override { guess_.reset(); }

  // The stage's base e^{z/2} U^n is stored for small states only (ProblemLayout::
  // stores_stage_bases); otherwise each sweep forms it again in the same pass (the same
  // products, rounded the same way), one vector less.
  void step(Real t, Vector& y) override {
    // Starting guess: the stage with the previous step's N(U^{n-1/2}), an O(h^2) predictor.
    if (guess_.from_previous())
      algebra::diagonal_combination(c_.e_half, y, c_.b_half, n_half_, y_half_);
    else
      algebra::diagonal_multiply(c_.e_half, y, y_half_);
    const Real t_half = t + 0.5 * h_;
    if (base_.size()) algebra::diagonal_multiply(c_.e_half, y, base_);
    solver_->solve(y_half_, [&](const Vector& x, Vector& out) {
      problem_.nonlinear(t_half, x, n_half_);
      if (base_.size())
        algebra::diagonal_multiply_add(base_, c_.b_half, n_half_, out);
      else
        algebra::diagonal_combination(c_.e_half, y, c_.b_half, n_half_, out);
    });
    // n_half_ = N at the last-but-one iterate, within tol of N(U^{n+1/2}).
    algebra::diagonal_combination(c_.e_full, y, c_.b_full, n_half_, y);
    guess_.stored();
  }

  tsi::SolverStats stats() const override { return solver_->stats(); }
  double state_vectors() const override { return state_vectors_for(problem_.layout(), options_); }
  // Four coefficients, the stage and its N (and its base, small states), and the solver's work space.
  static double state_vectors_for(const tsi::ProblemLayout& layout, const tsi::FixedPointOptions& options) {
    return 4.0 * layout.diagonal_fraction() + (layout.stores_stage_bases() ? 3.0 : 2.0) +
           tsi::fixed_point_state_vectors(options);
  }

 private:
  Coefficients c_;
  std::unique_ptr<tsi::FixedPointSolver> solver_;
  tsi::StageGuess guess_;
  tsi::FixedPointOptions options_ = solver_->options();
  Vector y_half_, n_half_;
  Vector base_;  // e^{z/2} U^n where the state is small (empty otherwise)
};

void register_se1(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "se1";
  entry.info.aliases = {"se1-tsi"};
  entry.info.summary = "SE1-TSI: symmetric exponential, implicit midpoint stage (eq. S1)";
  entry.info.params = tsi::fixed_point_params();
  entry.traits.order = 2;
  entry.traits.symmetric = true;
  // At step-size resonances h = k pi eps the error falls at order 1 only (Henon-Heiles, k = 1:
  // 4.0e-4, 2.0e-4, 1.0e-4, 4.6e-5 at h = 1/16 .. 1/128; docs/benchmarks/high-order.md).
  entry.traits.resonant_order = 1;
  entry.traits.implicit = true;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params& p) { return tsi::make_scheme<Se1>(tsi::fixed_point_options(p)); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("se1", register_se1)
