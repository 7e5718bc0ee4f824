// SE1-TSI (eq. S1), the symmetric one-stage exponential two-scale integrator:
//   U^{n+1/2} = e^{z/2} U^n + (h/2) phi1(z/2) N(U^{n+1/2})     (implicit: fixed point)
//   U^{n+1}   = e^{z}   U^n +  h    phi1(z)   N(U^{n+1/2}),     z = h L.
#include <cmath>
#include <limits>
#include <memory>

#include "tsi/algebra.hpp"
#include "tsi/fixed_point.hpp"
#include "tsi/phi.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace algebra = tsi::algebra;
using tsi::Vector;

class Se1 final : public tsi::Stepper {
 public:
  explicit Se1(const tsi::FixedPointOptions& options)
      : solver_(tsi::make_fixed_point_solver(options)), guess_previous_(options.guess == "previous") {}

  void reset() override { have_previous_ = false; }

  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    if (h != h_ || problem.size() != y_half_.size()) prepare(problem, h);
    algebra::diagonal_multiply(e_half_, y, base_half_);
    // Starting guess: the stage with the previous step's N(U^{n-1/2}), an O(h^2) predictor.
    if (guess_previous_ && have_previous_)
      algebra::diagonal_multiply_add(base_half_, b_half_, n_half_, y_half_);
    else
      algebra::copy(base_half_, y_half_);
    const double t_half = t + 0.5 * h;
    solver_->solve(y_half_, [&](const Vector& x, Vector& out) {
      problem.nonlinear(t_half, x, n_half_);
      algebra::diagonal_multiply_add(base_half_, b_half_, n_half_, out);
    });
    // n_half_ = N at the last-but-one iterate, within tol of N(U^{n+1/2}).
    algebra::diagonal_combination(e_full_, y, b_full_, n_half_, y);
    have_previous_ = true;
  }

  tsi::SolverStats stats() const override { return solver_->stats(); }

 private:
  // The diagonal coefficients for step size h, computed once per h.
  void prepare(const tsi::Problem& problem, double h) {
    const Vector& lambda = problem.linear_multipliers();
    const auto n = lambda.size();
    e_half_.resize(n), b_half_.resize(n), e_full_.resize(n), b_full_.resize(n);
    y_half_.resize(n), base_half_.resize(n), n_half_.resize(n);
    for (tsi::Index i = 0; i < n; ++i) {
      const tsi::Complex z = h * lambda(i);
      e_half_(i) = std::exp(0.5 * z);
      b_half_(i) = 0.5 * h * tsi::phi1(0.5 * z);
      e_full_(i) = std::exp(z);
      b_full_(i) = h * tsi::phi1(z);
    }
    h_ = h;
    have_previous_ = false;
  }

  std::unique_ptr<tsi::FixedPointSolver> solver_;
  bool guess_previous_;
  bool have_previous_ = false;
  double h_ = std::numeric_limits<double>::quiet_NaN();
  Vector e_half_, b_half_, e_full_, b_full_;
  Vector y_half_, base_half_, n_half_;
};

void register_se1(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "se1";
  entry.info.aliases = {"se1-tsi"};
  entry.info.summary = "SE1-TSI: symmetric exponential, implicit midpoint stage (eq. S1)";
  entry.info.params = tsi::fixed_point_params();
  entry.traits.order = 2;
  entry.traits.symmetric = true;
  entry.traits.implicit = true;
  entry.traits.needs_diagonal_linear_part = true;
  entry.traits.initial_data_order = 2;
  entry.traits.reformulations = {"filtered", "two-scale"};
  entry.create = [](const tsi::Params& p) {
    return std::make_unique<Se1>(tsi::fixed_point_options(p));
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("se1", register_se1)
