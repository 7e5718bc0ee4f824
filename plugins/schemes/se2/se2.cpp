// SE2-TSI (eq. S2), the symmetric average-vector-field exponential two-scale integrator:
//   U^{n+1} = e^{z} U^n + h phi1(z) int_0^1 N((1 - rho) U^n + rho U^{n+1}) d rho,  z = h L,
// the rho-integral by Gauss-Legendre quadrature, U^{n+1} by fixed-point iteration.
#include <cmath>
#include <memory>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/error.hpp"
#include "tsi/fixed_point.hpp"
#include "tsi/phi.hpp"
#include "tsi/plugin.hpp"
#include "tsi/quadrature.hpp"

namespace {

namespace algebra = tsi::algebra;
using tsi::Real;
using tsi::Complex;
using tsi::Vector;

class Se2 final : public tsi::Stepper {
 public:
  struct Settings {
    tsi::FixedPointOptions options;
    int nodes;
  };

  Se2(tsi::Problem& problem, Real h, const Settings& settings)
      : Stepper(problem, h),
        solver_(tsi::make_fixed_point_solver(settings.options)),
        guess_(settings.options),
        rule_(tsi::gauss_legendre(settings.nodes)),
        options_(settings.options),
        next_(problem.new_state()),
        n_(problem.new_state()),
        average_(problem.new_state()) {
    tsi::diagonal_function(problem.linear_multipliers(), h, [](Complex z) { return std::exp(z); }, e_);
    tsi::diagonal_function(problem.linear_multipliers(), h, [h](Complex z) { return h * tsi::phi1(z); }, b_);
  }

  void reset() override { guess_.reset(); }

  // The base e^z U^n is not stored: each sweep forms it again in its last pass (the same
  // products, rounded the same way), one vector less.
  void step(Real t, Vector& y) override {
    // Starting guess: the previous step's averaged N, an O(h^2) predictor.
    if (guess_.from_previous())
      algebra::diagonal_combination(e_, y, b_, average_, next_);
    else
      algebra::diagonal_multiply(e_, y, next_);
    // A quadrature point's state goes in `out` (free until the map's result is written there).
    solver_->solve(next_, [&](const Vector& x, Vector& out) {
      algebra::set_zero(y.size(), average_);
      for (size_t i = 0; i < rule_.nodes.size(); ++i) {
        const Real rho = rule_.nodes[i];
        algebra::axpby(1.0 - rho, y, rho, x, out);
        problem_.nonlinear(t + rho * h_, out, n_);
        algebra::axpy(rule_.weights[i], n_, average_);
      }
      algebra::diagonal_combination(e_, y, b_, average_, out);
    });
    algebra::copy(next_, y);
    guess_.stored();
  }

  tsi::SolverStats stats() const override { return solver_->stats(); }
  double state_vectors() const override { return state_vectors_for(problem_.layout(), {options_, 0}); }
  // Two coefficients, the iterate, N at a quadrature point, the average, the solver's.
  static double state_vectors_for(const tsi::ProblemLayout& layout, const Settings& settings) {
    return 2.0 * layout.diagonal_fraction() + 3.0 + tsi::fixed_point_state_vectors(settings.options);
  }

 private:
  std::unique_ptr<tsi::FixedPointSolver> solver_;
  tsi::StageGuess guess_;
  tsi::QuadratureRule rule_;
  tsi::FixedPointOptions options_;
  tsi::Diagonal e_, b_;  // the coefficients of step size h
  Vector next_, n_, average_;
};

void register_se2(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "se2";
  entry.info.aliases = {"se2-tsi"};
  entry.info.summary = "SE2-TSI: symmetric exponential average-vector-field scheme (eq. S2)";
  entry.info.params = tsi::fixed_point_params();
  entry.info.params.push_back(
      tsi::integer_param("quadrature_nodes", nullptr,
                         "Gauss-Legendre nodes for the rho-integral; default: exact for the model's "
                         "polynomial nonlinearity (2 for quadratic and cubic), 6 otherwise")
          .check([](const tsi::Json& v) { return v.get<long>() >= 1 && v.get<long>() <= 64; },
                 "an integer from 1 to 64"));
  entry.traits.order = 2;
  entry.traits.symmetric = true;
  // At step-size resonances h = k pi eps the error falls at order 1 only (Henon-Heiles, k = 1:
  // 4.0e-4, 2.0e-4, 1.0e-4, 4.6e-5 at h = 1/16 .. 1/128; docs/benchmarks/high-order.md).
  entry.traits.resonant_order = 1;
  entry.traits.implicit = true;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.complete = [](tsi::Json& p, const tsi::Selection& s) {
    if (p["quadrature_nodes"].is_null()) p["quadrature_nodes"] = tsi::default_quadrature_nodes(s.model);
  };
  entry.create = [](const tsi::Params& p) {
    // No silent default here: the node count depends on the model, which complete() knows.
    if (!p.has("quadrature_nodes"))
      throw tsi::ConfigError("scheme.quadrature_nodes",
                             "not set: build the scheme through tsi::assemble, which completes it from the model");
    const int nodes = static_cast<int>(p.integer("quadrature_nodes"));
    return tsi::make_scheme<Se2>(Se2::Settings{tsi::fixed_point_options(p), nodes});
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("se2", register_se2)
