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
#include <limits>
#include <memory>
#include <vector>

#include "tsi/exponential_weights.hpp"
#include "tsi/fixed_point.hpp"
#include "tsi/plugin.hpp"
#include "tsi/quadrature.hpp"

namespace {

using tsi::Complex;
using tsi::Vector;

class Collocation final : public tsi::Stepper {
 public:
  Collocation(int stages, const tsi::FixedPointOptions& options)
      : s_(stages),
        weights_of_(tsi::gauss_legendre(stages).nodes),
        solver_(tsi::make_fixed_point_solver(options)),
        guess_previous_(options.guess == "previous") {}

  void reset() override { have_previous_ = false; }

  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    if (h != h_ || problem.size() * s_ != stages_.size()) prepare(problem, h);
    const tsi::Index n = y.size();
    for (int i = 0; i < s_; ++i) base_.segment(i * n, n) = e_stage_[i].cwiseProduct(y);
    // Starting guess: the stages with the previous step's N, else the linear flow alone.
    stages_ = base_;
    if (guess_previous_ && have_previous_) stage_map(h, n, stages_);
    const auto& nodes = weights_of_.nodes();
    solver_->solve(stages_, [&](const Vector& x, Vector& out) {
      for (int j = 0; j < s_; ++j) {
        Vector stage = x.segment(j * n, n);
        problem.nonlinear(t + nodes[j] * h, stage, n_stage_[j]);
      }
      out = base_;
      stage_map(h, n, out);
    });
    y = e_full_.cwiseProduct(y);
    for (int j = 0; j < s_; ++j) y += h * b_[j].cwiseProduct(n_stage_[j]);
    have_previous_ = true;
  }

  tsi::SolverStats stats() const override { return solver_->stats(); }

 private:
  // out_i += h sum_j a_ij N_j for the stored stage values N_j.
  void stage_map(double h, tsi::Index n, Vector& out) const {
    for (int i = 0; i < s_; ++i)
      for (int j = 0; j < s_; ++j) out.segment(i * n, n) += h * a_[i][j].cwiseProduct(n_stage_[j]);
  }

  void prepare(const tsi::Problem& problem, double h) {
    const Vector& lambda = problem.linear_multipliers();
    const auto n = lambda.size();
    const auto& nodes = weights_of_.nodes();
    a_.assign(s_, std::vector<Vector>(s_, Vector(n)));
    b_.assign(s_, Vector(n));
    e_stage_.assign(s_, Vector(n));
    n_stage_.assign(s_, Vector::Zero(n));
    e_full_.resize(n);
    for (tsi::Index k = 0; k < n; ++k) {
      const Complex z = h * lambda(k);
      e_full_(k) = std::exp(z);
      const std::vector<Complex> b = weights_of_(1.0, z);
      for (int j = 0; j < s_; ++j) b_[j](k) = b[j];
      for (int i = 0; i < s_; ++i) {
        e_stage_[i](k) = std::exp(nodes[i] * z);
        const std::vector<Complex> a = weights_of_(nodes[i], z);
        for (int j = 0; j < s_; ++j) a_[i][j](k) = a[j];
      }
    }
    stages_.resize(s_ * n);
    base_.resize(s_ * n);
    h_ = h;
    have_previous_ = false;
  }

  int s_;
  tsi::InterpolatoryWeights weights_of_;
  std::unique_ptr<tsi::FixedPointSolver> solver_;
  bool guess_previous_;
  bool have_previous_ = false;
  double h_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<Vector>> a_;
  std::vector<Vector> b_, e_stage_, n_stage_;
  Vector e_full_, stages_, base_;
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
    return std::make_unique<Collocation>(p.has("stages") ? static_cast<int>(p.integer("stages")) : 3,
                                         tsi::fixed_point_options(p));
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("collocation", register_collocation)
