// ME-TSI (eq. EI scheme), the two-step exponential two-scale integrator:
//   U^{n+1} = e^z U^n + h phi1(z) N(U^n) + h phi2(z) [N(U^n) - N(U^{n-1})],   n >= 1,
// started by  U^* = e^z U^0 + h phi1(z) N(U^0),  U^1 = U^* + h phi2(z) [N(U^*) - N(U^0)].
#include <cmath>
#include <memory>
#include <variant>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/phi.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace algebra = tsi::algebra;
using tsi::Real;
using tsi::Complex;
using tsi::Vector;

class Me final : public tsi::Stepper {
 public:
  Me(tsi::Problem& problem, Real h, std::monostate)
      : Stepper(problem, h), n_(problem.new_state()), previous_(problem.new_state()) {
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(z); }, e_);
    tsi::diagonal_function(lambda, h, [h](Complex z) { return h * tsi::phi1(z); }, p1_);
    tsi::diagonal_function(lambda, h, [h](Complex z) { return h * tsi::phi2(z); }, p2_);
    p12_ = lambda.like(p1_.values() + p2_.values());
    minus_p2_ = lambda.like(-p2_.values());
  }

  void reset() override { has_previous_ = false; }

  void step(Real t, Vector& y) override {
    problem_.nonlinear(t, y, n_);
    if (has_previous_) {
      algebra::diagonal_combination(e_, y, p12_, n_, minus_p2_, previous_, y);
    } else {  // the start-up step, in the history's slot (empty until now) and in y
      Vector& star = previous_;
      algebra::diagonal_combination(e_, y, p1_, n_, star);
      problem_.nonlinear(t + h_, star, y);  // N(U^*)
      algebra::axpby(1.0, y, -1.0, n_, y);
      algebra::diagonal_multiply_add(star, p2_, y, y);
    }
    previous_.swap(n_);
    has_previous_ = true;
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {}); }
  // Five coefficients, N and the previous N (the start-up works in these and y).
  static double state_vectors_for(const tsi::ProblemLayout& layout, std::monostate) {
    return 5.0 * layout.diagonal_fraction() + 2.0;
  }

 private:
  bool has_previous_ = false;
  tsi::Diagonal e_, p1_, p2_, p12_, minus_p2_;  // the coefficients of step size h; p12 = p1 + p2
  Vector n_, previous_;
};

void register_me(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "me";
  entry.info.aliases = {"me-tsi"};
  entry.info.summary = "ME-TSI: two-step exponential two-scale scheme (eq. EI scheme)";
  entry.traits.order = 2;
  entry.traits.multistep = true;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params&) { return tsi::make_scheme<Me>(std::monostate{}); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("me", register_me)
