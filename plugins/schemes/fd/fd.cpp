// FD-TSI (eq. FD scheme), the explicit finite-difference two-scale integrator of
// Chartier-Crouseilles-Lemou-Mehats:
//   (U^{n+1/2} - U^n)/(h/2) - L U^{n+1/2}       = N(U^n)
//   (U^{n+1}   - U^n)/h     - L (U^{n+1} + U^n)/2 = N(U^{n+1/2})
// L diagonal, so both stages are explicit. Uniform order 2 needs prepared data of order 3 (4 on
// a model with a remainder: traits.remainder_data_order).
// A model's remainder R (Problem::remainder_multipliers, L = L_tau + R) is integrated exactly
// rather than by the Crank-Nicolson fraction: the scheme above is applied to V = e^{-(t - t_n) R} U
// (a Lawson transformation), which, all operators being diagonal, only changes the coefficients:
//   U^{n+1/2} = e^{hR/2} (1 - h L_tau/2)^{-1} [U^n + (h/2) N(U^n)]
//   U^{n+1}   = e^{hR} (1 - h L_tau/2)^{-1} (1 + h L_tau/2) U^n + h e^{hR/2} (1 - h L_tau/2)^{-1} N(U^{n+1/2}).
// Without a remainder this is the scheme as published. (Crank-Nicolson on R turns mode j by a
// phase wrong by (h omega_j)^3/12 per step: on Klein-Gordon it was all of FD's error.)
#include <cmath>
#include <memory>
#include <utility>
#include <variant>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace algebra = tsi::algebra;
using tsi::Real;
using tsi::Complex;
using tsi::Vector;

class Fd final : public tsi::Stepper {
 public:
  Fd(tsi::Problem& problem, Real h, std::monostate)
      : Stepper(problem, h), half_(problem.new_state()), n_(problem.new_state()) {
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    const Vector& remainder = problem.remainder_multipliers();
    // One value per stored value of L (per tau mode on the two-scale problem without a
    // remainder); a remainder varies along every run, so with one L is taken entry by entry.
    const tsi::Index run = remainder.size() ? 1 : lambda.run();
    const Vector values = run == lambda.run() ? lambda.values() : lambda.expanded();
    const tsi::Index n = values.size();
    Vector inverse(n), half_inverse(n), cayley(n), full_inverse(n);
    for (tsi::Index i = 0; i < n; ++i) {
      const Complex r = remainder.size() ? remainder(i) : Complex(0);
      const Complex z = Real(0.5) * h * (values(i) - r);  // h L_tau / 2
      const Complex half_turn = std::exp(Real(0.5) * h * r), inv = Real(1) / (Real(1) - z);
      inverse(i) = half_turn * inv;
      half_inverse(i) = Real(0.5) * h * half_turn * inv;
      cayley(i) = half_turn * half_turn * (Real(1) + z) * inv;
      full_inverse(i) = h * half_turn * inv;
    }
    inverse_ = tsi::Diagonal(std::move(inverse), run).with_threads(lambda.threads());
    half_inverse_ = tsi::Diagonal(std::move(half_inverse), run).with_threads(lambda.threads());
    cayley_ = tsi::Diagonal(std::move(cayley), run).with_threads(lambda.threads());
    full_inverse_ = tsi::Diagonal(std::move(full_inverse), run).with_threads(lambda.threads());
  }

  void step(Real t, Vector& y) override {
    problem_.nonlinear(t, y, n_);
    algebra::diagonal_combination(inverse_, y, half_inverse_, n_, half_);
    problem_.nonlinear(t + 0.5 * h_, half_, n_);
    algebra::diagonal_combination(cayley_, y, full_inverse_, n_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {}); }
  // Four coefficients (per unknown with a remainder), the half step and N.
  static double state_vectors_for(const tsi::ProblemLayout& layout, std::monostate) {
    return 4.0 * layout.diagonal_fraction() + 2.0;
  }

 private:
  // With E = e^{hR/2} and C = (1 - h L_tau/2)^{-1}: E C, (h/2) E C, E^2 C (1 + h L_tau/2), h E C
  tsi::Diagonal inverse_, half_inverse_, cayley_, full_inverse_;
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
  // With a remainder the data's O(eps^3) defect grows with eps |R| (Klein-Gordon, n_x = 16:
  // eps max A_k = 0.28 at eps = 1e-2, 0.71 at 3e-2), and the Crank-Nicolson fraction turns
  // it by a wrong phase while h k / eps ~ 1: with order 3 the maximum over eps in [1e-2, 1] falls at 1.4 to
  // 1.6 from h = 1/16 to 1/512, with order 4 at 1.83 to 1.97 (docs/benchmarks/high-order.md).
  entry.traits.remainder_data_order = 4;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params&) { return tsi::make_scheme<Fd>(std::monostate{}); };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("fd", register_fd)
