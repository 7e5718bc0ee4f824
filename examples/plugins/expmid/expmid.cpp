// The explicit exponential midpoint rule as a tsi scheme plugin: SE1-TSI's two formulas with
// the implicit stage replaced by one explicit exponential Euler half step,
//   U^*     = e^{z/2} U^n + (h/2) phi1(z/2) N(U^n)
//   U^{n+1} = e^{z}   U^n +  h    phi1(z)   N(U^*),     z = h L (a diagonal multiplier).
// Explicit, second order, not symmetric; on the two-scale problem it needs prepared data of
// order 2 for an error uniform in eps.
#include <cmath>
#include <limits>
#include <memory>

#include "tsi/algebra.hpp"
#include "tsi/phi.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::Vector;

class ExpMidpoint final : public tsi::Stepper {
 public:
  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    if (h != h_ || problem.size() != e_full_.size()) prepare(problem, h);
    problem.nonlinear(t, y, n_);
    tsi::algebra::diagonal_combination(e_half_, y, b_half_, n_, stage_);
    problem.nonlinear(t + 0.5 * h, stage_, n_);
    tsi::algebra::diagonal_combination(e_full_, y, b_full_, n_, y);
  }

 private:
  // e^{z/2}, (h/2) phi1(z/2), e^z, h phi1(z) for every entry of L's diagonal, once per h.
  void prepare(const tsi::Problem& problem, double h) {
    const Vector& lambda = problem.linear_multipliers();
    const tsi::Index n = lambda.size();
    e_half_.resize(n), b_half_.resize(n), e_full_.resize(n), b_full_.resize(n);
    for (tsi::Index i = 0; i < n; ++i) {
      const Complex z = h * lambda(i);
      e_half_(i) = std::exp(0.5 * z);
      b_half_(i) = 0.5 * h * tsi::phi1(0.5 * z);
      e_full_(i) = std::exp(z);
      b_full_(i) = h * tsi::phi1(z);
    }
    h_ = h;
  }

  double h_ = std::numeric_limits<double>::quiet_NaN();
  Vector e_half_, b_half_, e_full_, b_full_, n_, stage_;
};

void register_expmid(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "exp-midpoint";
  entry.info.aliases = {"emp"};
  entry.info.summary = "explicit exponential midpoint: SE1's formulas with an explicit stage";
  entry.traits.order = 2;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params&) { return std::make_unique<ExpMidpoint>(); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("exp-midpoint", register_expmid)
