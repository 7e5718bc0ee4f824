// Exponential Gauss collocation with s stages on y' = L y + N(t, y), L diagonal: N along the
// step replaced by its interpolation polynomial at the Gauss nodes c_1 .. c_s of [0, 1],
//   Y_i     = e^{c_i z} y_n + h sum_j a_ij(z) N(Y_j)     (implicit: fixed point on all stages)
//   y_{n+1} = e^{z} y_n     + h sum_j b_j(z)  N(Y_j),     z = h L,
// a_ij(z) = int_0^{c_i} e^{(c_i - s) z} l_j(s) ds, b_j(z) = int_0^1 e^{(1 - s) z} l_j(s) ds.
// s = 1 is SE1. The nodes are symmetric about 1/2, so the method is symmetric. At a fixed eps
// it has Gauss collocation's order 2 s; uniformly in eps it is declared of order 2 only: the
// maximum of its errors over eps falls at order 4 for s = 3 on Henon-Heiles (16 eps from 1 to
// 1e-6), NLS, the charged particle and Klein-Gordon, but at 3.2 on the FPUT example near a
// step-size resonance (docs/explanation/high-order.md).
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
using tsi::Real;
using tsi::Vector;

class Collocation final : public tsi::Stepper {
 public:
  struct Settings {
    int stages;
    tsi::FixedPointOptions options;
  };

  Collocation(tsi::Problem& problem, Real h, const Settings& settings)
      : Stepper(problem, h),
        s_(settings.stages),
        nodes_(tsi::gauss_legendre(settings.stages).nodes),
        solver_(tsi::make_fixed_point_solver(settings.options)),
        guess_(settings.options),
        options_(settings.options),
        stage_(problem.new_state()) {
    // The coefficients of step size h, with the factor h folded into a and b (one value per tau
    // mode on the two-scale problem without a remainder: tsi::Diagonal).
    const tsi::InterpolatoryWeights weights_of(nodes_);
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    const auto scaled = [&](Real kappa) {
      return [&, kappa](Complex z) {
        std::vector<Complex> w = weights_of(kappa, z);
        for (Complex& x : w) x *= h;
        return w;
      };
    };
    a_.assign(s_, std::vector<tsi::Diagonal>(s_));
    b_.assign(s_, tsi::Diagonal());
    e_stage_.assign(s_, tsi::Diagonal());
    n_stage_.assign(s_, problem.new_state());
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(z); }, e_full_);
    tsi::diagonal_functions(lambda, h, scaled(1.0), pointers(b_));
    for (int i = 0; i < s_; ++i) {
      const Real c = nodes_[i];
      tsi::diagonal_function(lambda, h, [c](Complex z) { return std::exp(c * z); }, e_stage_[i]);
      tsi::diagonal_functions(lambda, h, scaled(c), pointers(a_[i]));
    }
    stages_ = Vector::Zero(s_ * problem.size());
    a_terms_.resize(s_ + 1), n_terms_.resize(s_ + 1), b_terms_.resize(s_ + 1), y_terms_.resize(s_ + 1);
    for (int j = 0; j < s_; ++j) n_terms_[j + 1] = &n_stage_[j];
  }

  void reset() override { guess_.reset(); }

  // The stages' bases e^{c_i z} y_n are not stored: every sweep forms them again in the pass
  // that adds the a_ij N_j (the same products in the same order), s vectors less.
  void step(Real t, Vector& y) override {
    const tsi::Index n = y.size();
    // Starting guess: the stages with the previous step's N, else the linear flow alone.
    if (guess_.from_previous())
      stage_map(n, y, stages_);
    else
      for (int i = 0; i < s_; ++i) {
        tsi::algebra::diagonal_multiply(e_stage_[i], y, stage_);
        stages_.segment(i * n, n) = stage_;
      }
    solver_->solve(stages_, [&](const Vector& x, Vector& out) {
      for (int j = 0; j < s_; ++j) {
        stage_ = x.segment(j * n, n);  // preallocated: a copy, no allocation
        problem_.nonlinear(t + nodes_[j] * h_, stage_, n_stage_[j]);
      }
      stage_map(n, y, out);
    });
    // y_{n+1} = e^{z} y_n + sum_j h b_j N_j, in one pass.
    b_terms_[0] = &e_full_, y_terms_[0] = &y;
    for (int j = 0; j < s_; ++j) b_terms_[j + 1] = &b_[j], y_terms_[j + 1] = &n_stage_[j];
    tsi::algebra::diagonal_linear_combination(nullptr, b_terms_, y_terms_, y);
    guess_.stored();
  }

  tsi::SolverStats stats() const override { return solver_->stats(); }
  double state_vectors() const override { return state_vectors_for(problem_.layout(), {s_, options_}); }
  // a (s^2), b, e_stage (s each) and e_full; the s values of N, one stage, and the s stages
  // with the solver's work space on them.
  static double state_vectors_for(const tsi::ProblemLayout& layout, const Settings& settings) {
    const double s = settings.stages;
    return (s * s + 2.0 * s + 1.0) * layout.diagonal_fraction() + s + 1.0 + s +
           s * tsi::fixed_point_state_vectors(settings.options);
  }

 private:
  template <class T>
  static std::vector<T*> pointers(std::vector<T>& v) {
    std::vector<T*> p;
    for (T& x : v) p.push_back(&x);
    return p;
  }

  // out_i = e^{c_i z} y + sum_j h a_ij N_j for the stored stage values N_j, one stage at a time
  // through stage_ (the segments as vectors of their own would be copies).
  void stage_map(tsi::Index n, const Vector& y, Vector& out) {
    a_terms_[0] = nullptr, n_terms_[0] = &y;
    for (int i = 0; i < s_; ++i) {
      a_terms_[0] = &e_stage_[i];
      for (int j = 0; j < s_; ++j) a_terms_[j + 1] = &a_[i][j];
      tsi::algebra::diagonal_linear_combination(nullptr, a_terms_, n_terms_, stage_);
      out.segment(i * n, n) = stage_;
    }
  }

  int s_;
  std::vector<Real> nodes_;
  std::unique_ptr<tsi::FixedPointSolver> solver_;
  tsi::StageGuess guess_;
  tsi::FixedPointOptions options_;
  std::vector<std::vector<tsi::Diagonal>> a_;
  std::vector<tsi::Diagonal> b_, e_stage_;
  tsi::Diagonal e_full_;
  std::vector<Vector> n_stage_;
  Vector stages_, stage_;
  std::vector<const tsi::Diagonal*> a_terms_, b_terms_;  // operand lists, allocated once
  std::vector<const Vector*> n_terms_, y_terms_;
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
