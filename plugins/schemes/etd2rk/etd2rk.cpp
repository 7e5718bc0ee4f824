// ETD2RK (Cox and Matthews 2002), the two-stage exponential Runge-Kutta scheme the UA-PIC codes
// apply to the two-scale problem (Chartier, Crouseilles, Lemou, Mehats, Zhao):
//   U^* = e^z U^n + h phi1(z) N(t_n, U^n),
//   U^{n+1} = U^* + h phi2(z) [N(t_n + h, U^*) - N(t_n, U^n)],        z = h L,
// the linear part exactly, the forcing interpolated linearly over the step. One step: it
// needs no history, so a re-prepared state goes on at once. Second order; re-prepared every step
// with data of order 2 (the peer's "first-order corrected" data), on vlasov-poisson-2d's
// diagonal field and with the Nyquist mode averaged, it is UAPIC.jl's fortran/bupdate.F90 on a
// uniform field.
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

class Etd2rk final : public tsi::Stepper {
 public:
  Etd2rk(tsi::Problem& problem, Real h, std::monostate)
      : Stepper(problem, h), n0_(problem.new_state()), star_(problem.new_state()), n1_(problem.new_state()) {
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(z); }, e_);
    tsi::diagonal_function(lambda, h, [h](Complex z) { return h * tsi::phi1(z); }, p1_);
    tsi::diagonal_function(lambda, h, [h](Complex z) { return h * tsi::phi2(z); }, p2_);
    p1_minus_p2_ = lambda.like(p1_.values() - p2_.values());
  }

  void step(Real t, Vector& y) override {
    problem_.nonlinear(t, y, n0_);
    algebra::diagonal_combination(e_, y, p1_, n0_, star_);
    problem_.nonlinear(t + h_, star_, n1_);
    // U^{n+1} = e^z U^n + h (phi1 - phi2) N_0 + h phi2 N_1: U^* is not needed again.
    algebra::diagonal_combination(e_, y, p1_minus_p2_, n0_, p2_, n1_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {}); }
  // Four coefficients; N_0, U^* and N_1.
  static double state_vectors_for(const tsi::ProblemLayout& layout, std::monostate) {
    return 4.0 * layout.diagonal_fraction() + 3.0;
  }

 private:
  tsi::Diagonal e_, p1_, p2_, p1_minus_p2_;  // the coefficients of step size h
  Vector n0_, star_, n1_;
};

void register_etd2rk(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "etd2rk";
  entry.info.aliases = {"etdrk2", "cox-matthews"};
  entry.info.summary = "ETD2RK (Cox-Matthews): two-stage exponential Runge-Kutta, the UA-PIC codes' scheme";
  entry.traits.order = 2;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params&) { return tsi::make_scheme<Etd2rk>(std::monostate{}); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("etd2rk", register_etd2rk)
