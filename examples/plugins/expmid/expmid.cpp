// The explicit exponential midpoint rule as a tsi scheme plugin: SE1-TSI's two formulas with
// the implicit stage replaced by one explicit exponential Euler half step,
//   U^*     = e^{z/2} U^n + (h/2) phi1(z/2) N(U^n)
//   U^{n+1} = e^{z}   U^n +  h    phi1(z)   N(U^*),     z = h L (a diagonal multiplier).
// Explicit, second order, not symmetric; on the two-scale problem it needs prepared data of
// order 2 for an error uniform in eps.
#include <cmath>
#include <memory>
#include <variant>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/phi.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::Real;
using tsi::Vector;

class ExpMidpoint final : public tsi::Stepper {
 public:
  // Bound to one problem and step size h: e^{z/2}, (h/2) phi1(z/2), e^z, h phi1(z) for every
  // entry of L's diagonal, computed here once, and the work vectors from the problem's prototype.
  ExpMidpoint(tsi::Problem& problem, Real h, std::monostate)
      : Stepper(problem, h), n_(problem.new_state()), stage_(problem.new_state()) {
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    tsi::diagonal_function(lambda, 0.5 * h, [](Complex z) { return std::exp(z); }, e_half_);
    tsi::diagonal_function(lambda, 0.5 * h, [h](Complex z) { return Real(0.5) * h * tsi::phi1(z); }, b_half_);
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(z); }, e_full_);
    tsi::diagonal_function(lambda, h, [h](Complex z) { return h * tsi::phi1(z); }, b_full_);
  }

  void step(Real t, Vector& y) override {
    problem_.nonlinear(t, y, n_);
    tsi::algebra::diagonal_combination(e_half_, y, b_half_, n_, stage_);
    problem_.nonlinear(t + 0.5 * h_, stage_, n_);
    tsi::algebra::diagonal_combination(e_full_, y, b_full_, n_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {}); }
  // Four coefficients (one value per tau mode on the two-scale problem without a remainder),
  // N and the stage: what the footprint check of a run counts before the problem is built.
  static double state_vectors_for(const tsi::ProblemLayout& layout, std::monostate) {
    return 4.0 * layout.diagonal_fraction() + 2.0;
  }

 private:
  tsi::Diagonal e_half_, b_half_, e_full_, b_full_;
  Vector n_, stage_;
};

void register_expmid(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "exp-midpoint";
  entry.info.aliases = {"emp"};
  entry.info.summary = "explicit exponential midpoint: SE1's formulas with an explicit stage";
  entry.traits.order = 2;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  // Like SE1, it loses an order at step-size resonances h = k pi eps (tsi check measures the
  // maximum of its error over eps falling at 1.5 on Henon-Heiles between eps = 1e-6 and 1).
  entry.traits.resonant_order = 1;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params&) { return tsi::make_scheme<ExpMidpoint>(std::monostate{}); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("exp-midpoint", register_expmid)
