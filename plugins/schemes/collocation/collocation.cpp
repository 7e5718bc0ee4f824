// Exponential Gauss collocation with s stages on y' = L y + N(t, y), L diagonal: N along the
// step replaced by its interpolation polynomial at the Gauss nodes c_1 .. c_s of [0, 1],
//   Y_i     = e^{c_i z} y_n + h sum_j a_ij(z) N(Y_j)     (implicit: fixed point on all stages)
//   y_{n+1} = e^{z} y_n     + h sum_j b_j(z)  N(Y_j),     z = h L,
// a_ij(z) = int_0^{c_i} e^{(c_i - s) z} l_j(s) ds, b_j(z) = int_0^1 e^{(1 - s) z} l_j(s) ds.
// s = 1 is SE1. The nodes are symmetric about 1/2, so the method is symmetric. At a fixed eps
// it has Gauss collocation's order 2 s; uniformly in eps it is declared of order 2 only: the
// maximum of its errors over eps falls at order 4 for s = 3 on Henon-Heiles (16 eps from 1 to
// 1e-6), NLS, the charged particle and Klein-Gordon, but at 3.2 on the FPUT example near a
// step-size resonance (docs/high-order.md).
#include <cmath>
#include <memory>
#include <vector>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/exponential_weights.hpp"
#include "tsi/fixed_point.hpp"
#include "tsi/plugin.hpp"
#include "tsi/quadrature.hpp"

namespace {

using tsi::Complex;
using tsi::Vector;

class Collocation final : public tsi::Stepper {
 public:
  struct Settings {
    int stages;
    tsi::FixedPointOptions options;
  };

  Collocation(tsi::Problem& problem, double h, const Settings& settings)
      : Stepper(problem, h),
        s_(settings.stages),
        nodes_(tsi::gauss_legendre(settings.stages).nodes),
        solver_(tsi::make_fixed_point_solver(settings.options)),
        guess_(settings.options),
        stage_(problem.new_state()) {
    // The coefficients of step size h, with the factor h folded into a and b.
    const tsi::InterpolatoryWeights weights_of(nodes_);
    const Vector& lambda = problem.linear_multipliers();
    const auto scaled = [&](double kappa) {
      return [&, kappa](Complex z) {
        std::vector<Complex> w = weights_of(kappa, z);
        for (Complex& x : w) x *= h;
        return w;
      };
    };
    a_.assign(s_, std::vector<Vector>(s_));
    b_.assign(s_, Vector());
    e_stage_.assign(s_, Vector());
    n_stage_.assign(s_, problem.new_state());
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(z); }, e_full_);
    tsi::diagonal_functions(lambda, h, scaled(1.0), pointers(b_));
    for (int i = 0; i < s_; ++i) {
      const double c = nodes_[i];
      tsi::diagonal_function(lambda, h, [c](Complex z) { return std::exp(c * z); }, e_stage_[i]);
      tsi::diagonal_functions(lambda, h, scaled(c), pointers(a_[i]));
    }
    stages_ = Vector::Zero(s_ * problem.size());
    base_ = stages_;
    a_terms_.resize(s_), n_terms_.resize(s_), b_terms_.resize(s_ + 1), y_terms_.resize(s_ + 1);
    for (int j = 0; j < s_; ++j) n_terms_[j] = &n_stage_[j];
  }

  void reset() override { guess_.reset(); }

  void step(double t, Vector& y) override {
    const tsi::Index n = y.size();
    for (int i = 0; i < s_; ++i) base_.segment(i * n, n) = e_stage_[i].cwiseProduct(y);
    // Starting guess: the stages with the previous step's N, else the linear flow alone.
    tsi::algebra::copy(base_, stages_);
    if (guess_.from_previous()) stage_map(n, base_, stages_);
    solver_->solve(stages_, [&](const Vector& x, Vector& out) {
      for (int j = 0; j < s_; ++j) {
        stage_ = x.segment(j * n, n);  // preallocated: a copy, no allocation
        problem_.nonlinear(t + nodes_[j] * h_, stage_, n_stage_[j]);
      }
      stage_map(n, base_, out);
    });
    // y_{n+1} = e^{z} y_n + sum_j h b_j N_j, in one pass.
    b_terms_[0] = &e_full_, y_terms_[0] = &y;
    for (int j = 0; j < s_; ++j) b_terms_[j + 1] = &b_[j], y_terms_[j + 1] = &n_stage_[j];
    tsi::algebra::diagonal_linear_combination(nullptr, b_terms_, y_terms_, y);
    guess_.stored();
  }

  tsi::SolverStats stats() const override { return solver_->stats(); }
  // a (s^2), b, e_stage, N (s each) and e_full, one stage; stages and base are s each.
  double state_vectors() const override {
    const double s = s_;
    return s * s + 3.0 * s + 2.0 + 2.0 * s + s * solver_->state_vectors();
  }

 private:
  static std::vector<Vector*> pointers(std::vector<Vector>& v) {
    std::vector<Vector*> p;
    for (Vector& x : v) p.push_back(&x);
    return p;
  }

  // out_i = base_i + sum_j h a_ij N_j for the stored stage values N_j (out may be base).
  void stage_map(tsi::Index n, const Vector& base, Vector& out) {
    for (int i = 0; i < s_; ++i) {
      for (int j = 0; j < s_; ++j) a_terms_[j] = &a_[i][j];
      // The segments as vectors of their own would be copies: one stage at a time through stage_.
      stage_ = base.segment(i * n, n);
      tsi::algebra::diagonal_linear_combination(&stage_, a_terms_, n_terms_, stage_);
      out.segment(i * n, n) = stage_;
    }
  }

  int s_;
  std::vector<double> nodes_;
  std::unique_ptr<tsi::FixedPointSolver> solver_;
  tsi::StageGuess guess_;
  std::vector<std::vector<Vector>> a_;
  std::vector<Vector> b_, e_stage_, n_stage_;
  Vector e_full_, stages_, base_, stage_;
  std::vector<const Vector*> a_terms_, n_terms_, b_terms_, y_terms_;  // operand lists, allocated once
};

tsi::StepperTraits traits_of(int stages) {
  tsi::StepperTraits t;
  t.order = 2;                    // uniform in eps: what every model shows (see above)
  t.classical_order = 2 * stages;  // Gauss collocation at a fixed eps
  t.symmetric = true;
  t.implicit = true;
  t.needs_diagonal_linear_part = true;
  // Henon-Heiles, eps = 1/256, s = 3: a plateau at 1.2e-7 with data of order 2, none with 4.
  t.initial_data_order = stages > 1 ? 4 : 2;
  t.reformulations = {"filtered", "two-scale"};
  return t;
}

void register_collocation(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "collocation";
  entry.info.aliases = {"exponential-gauss"};
  entry.info.summary = "exponential Gauss collocation, s stages: symmetric, order 2 s at fixed eps (s = 1: SE1)";
  entry.info.params = {tsi::integer_param("stages", 3, "Gauss nodes s: 1 (SE1), 2, 3, ... (order 2 s at a fixed eps)")
                           .check([](const tsi::Json& v) { return v.get<long>() >= 1 && v.get<long>() <= 8; },
                                  "an integer from 1 to 8")};
  for (auto& p : tsi::fixed_point_params()) entry.info.params.push_back(std::move(p));
  entry.traits = traits_of(3);
  entry.traits_for = [](const tsi::Json& p) {
    return traits_of(p.contains("stages") && p["stages"].is_number_integer() ? p["stages"].get<int>() : 3);
  };
  entry.create = [](const tsi::Params& p) {
    return tsi::make_scheme<Collocation>(
        Collocation::Settings{p.has("stages") ? static_cast<int>(p.integer("stages")) : 3, tsi::fixed_point_options(p)});
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("collocation", register_collocation)
