// Exponential Adams-Bashforth of order r on y' = L y + N(t, y), L diagonal: the scheme
// HOODESolver.jl applies to the two-scale problem (Chartier, Crouseilles, Lemou, Méhats, Zhao).
//   y_{n+1} = e^{hL} y_n + h sum_{j<r} beta_j(hL) N_{n-j},
//   beta_j(z) = int_0^1 e^{(1-s) z} l_j(s) ds   (tsi::InterpolatoryWeights),
// l_j the Lagrange polynomials on the nodes 0, -1, ..., -(r-1) (in units of h). Start-up (HOODESolver computes its history backwards too): the
// values at t - h, ..., t - (r-1) h from the same interpolatory formula towards the past,
// y(t - k h) = e^{-khL} y + h sum_j beta_j^{(-k)}(hL) N_{-j}, iterated r times from N_{-j} = N_0
// (each pass gains one order in h), so the history is accurate to O(h^{r+1}).
// Or HOODESolver.jl's start-up (startup = "hoodesolver"), stage by stage for q = 2 .. r: the
// values u_{-1} .. u_{-(q-1)} backward with the formula of order q - 1 on the values after
// them, then u_1 .. u_{q-1} forward with the formula of order q, N evaluated at each new value;
// the run goes on from u_{r-1} (u_1 .. u_{r-1} are its first steps), the backward values
// discarded. The same interpolatory weights, on the nodes 0, 1, .. (backward, kappa = -1).
#include <array>
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/error.hpp"
#include "tsi/exponential_weights.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::Real;
using tsi::Vector;

constexpr int max_order = 6;

enum class Startup { interpolatory, hoodesolver };

struct Settings {
  int order = 4;
  Startup startup = Startup::interpolatory;
};

class Eab final : public tsi::Stepper {
 public:
  Eab(tsi::Problem& problem, Real h, const Settings& settings)
      : Stepper(problem, h), r_(settings.order), startup_(settings.startup) {
    // The weights of N_{-j} for the value at kappa h: kappa = 1 the step, -k the start-up,
    // with the factor h folded in (one value per tau mode on the two-scale problem without a
    // remainder: tsi::Diagonal).
    const tsi::InterpolatoryWeights weights_of(past_nodes(r_));
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    weights_.assign(r_, {});
    exponentials_.assign(r_, tsi::Diagonal());
    for (int k = 0; k < r_; ++k) {
      const Real kappa = k == 0 ? 1.0 : -static_cast<Real>(k);
      tsi::diagonal_function(lambda, h, [kappa](Complex z) { return std::exp(kappa * z); }, exponentials_[k]);
      scaled_weights(lambda, h, weights_of, kappa, weights_[k]);
    }
    history_.assign(r_, problem.new_state());
    if (startup_ == Startup::hoodesolver && r_ > 1)
      prepare_stages(lambda, h);
    else
      past_.assign(r_ - 1, problem.new_state());  // the interpolatory start-up's values only
  }

  void reset() override {
    started_ = false;
    next_level_ = 0;
  }

  void step(Real t, Vector& y) override {
    if (startup_ == Startup::hoodesolver && r_ > 1) {
      // The start-up's forward values are the first steps.
      if (!started_) {
        start_by_stages(t, y);
        next_level_ = 1;
      }
      if (next_level_ < r_) {
        y.swap(forward_u_[static_cast<size_t>(next_level_ - 1)]);
        ++next_level_;
        return;
      }
    }
    if (!started_) start(t, y);
    combine(0, y, y);  // in place: the combination reads each entry before it writes it
    // The history moves back one place (swaps, no copies) and N_{n+1} takes the front.
    for (int j = r_ - 1; j > 0; --j) history_[j].swap(history_[j - 1]);
    problem_.nonlinear(t + h_, y, history_.front());
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {r_, startup_}); }
  // (r + 1) r coefficients (the weights and exponentials of the step and of the values at
  // -k h); the history of r values of N, and the interpolatory start-up's r - 1 past values or
  // HOODESolver's 3 (r - 1) (its backward values, their N, its forward values) with its stages'
  // coefficients: e^{-hL}, q - 1 backward weights for q = 2 .. r and q forward ones for
  // q = 2 .. r - 1, r (r - 1) in all.
  static double state_vectors_for(const tsi::ProblemLayout& layout, const Settings& settings) {
    const int r = settings.order;
    double vectors = (r + 1.0) * r * layout.diagonal_fraction() + 2.0 * r - 1.0;
    if (settings.startup == Startup::hoodesolver && r > 1)
      vectors += 2.0 * (r - 1) + static_cast<double>(r) * (r - 1) * layout.diagonal_fraction();
    return vectors;
  }

 private:
  // out = e^{kappa_k hL} y + sum_j h w_j(kappa_k) N_{-j}, in one pass (out may be y).
  void combine(int k, const Vector& y, Vector& out) const {
    std::array<const tsi::Diagonal*, max_order + 1> d{};
    std::array<const Vector*, max_order + 1> x{};
    d[0] = &exponentials_[k], x[0] = &y;
    for (int j = 0; j < r_; ++j) d[j + 1] = &weights_[k][j], x[j + 1] = &history_[j];
    tsi::algebra::diagonal_linear_combination(nullptr, std::span<const tsi::Diagonal* const>(d.data(), r_ + 1),
                                              std::span<const Vector* const>(x.data(), r_ + 1), out);
  }

  // N at t, t - h, ..., t - (r-1) h, the past values from r passes of the interpolatory formula.
  void start(Real t, const Vector& y) {
    problem_.nonlinear(t, y, history_[0]);
    for (int j = 1; j < r_; ++j) tsi::algebra::copy(history_[0], history_[j]);
    for (int pass = 0; pass < r_; ++pass) {
      for (int k = 1; k < r_; ++k) combine(k, y, past_[k - 1]);
      for (int k = 1; k < r_; ++k) problem_.nonlinear(t - k * h_, past_[k - 1], history_[k]);
    }
    started_ = true;
  }

  static std::vector<Real> past_nodes(int r) {
    std::vector<Real> nodes(r);
    for (int j = 0; j < r; ++j) nodes[j] = -j;
    return nodes;
  }
  // h w_j(kappa, hL) for every node of weights_of, one Diagonal each (the factor h folded in).
  static void scaled_weights(const tsi::Diagonal& lambda, Real h, const tsi::InterpolatoryWeights& weights_of,
                             Real kappa, std::vector<tsi::Diagonal>& out) {
    const int m = static_cast<int>(weights_of.nodes().size());
    out.assign(m, tsi::Diagonal());
    std::array<tsi::Diagonal*, max_order> outs{};
    for (int j = 0; j < m; ++j) outs[j] = &out[j];
    tsi::diagonal_functions(
        lambda, h,
        [&](Complex z) {
          std::vector<Complex> w = weights_of(kappa, z);
          for (Complex& x : w) x *= h;
          return w;
        },
        std::span<tsi::Diagonal* const>(outs.data(), m));
  }
  static std::vector<Real> future_nodes(int r) {
    std::vector<Real> nodes(r);
    for (int j = 0; j < r; ++j) nodes[j] = j;
    return nodes;
  }

  // HOODESolver's stages: for q = 2 .. r, the backward formula of order q - 1 (nodes 0 .. q - 2
  // after the base, kappa = -1) and the forward one of order q (nodes 0 .. -(q - 1), kappa = 1).
  void prepare_stages(const tsi::Diagonal& lambda, Real h) {
    tsi::diagonal_function(lambda, h, [](Complex z) { return std::exp(-z); }, backward_exponential_);
    backward_.assign(r_ + 1, {});
    forward_.assign(r_ + 1, {});
    for (int q = 2; q <= r_; ++q) {
      scaled_weights(lambda, h, tsi::InterpolatoryWeights(future_nodes(q - 1)), -1.0, backward_[q]);
      if (q < r_)  // order r: the step's own weights
        scaled_weights(lambda, h, tsi::InterpolatoryWeights(past_nodes(q)), 1.0, forward_[q]);
    }
    backward_u_.assign(r_ - 1, problem_.new_state());
    backward_n_.assign(r_ - 1, problem_.new_state());
    forward_u_.assign(r_ - 1, problem_.new_state());
  }

  // u at level m (y is level 0) and N there (levels 0 .. r - 1 in the history, newest first at
  // the end: history_[r - 1 - m]).
  Vector& level_u(int m, Vector& y) {
    return m == 0 ? y : m < 0 ? backward_u_[static_cast<size_t>(-m - 1)] : forward_u_[static_cast<size_t>(m - 1)];
  }
  Vector& level_n(int m) {
    return m < 0 ? backward_n_[static_cast<size_t>(-m - 1)] : history_[static_cast<size_t>(r_ - 1 - m)];
  }

  void start_by_stages(Real t, Vector& y) {
    problem_.nonlinear(t, y, level_n(0));
    std::array<const tsi::Diagonal*, max_order + 1> d{};
    std::array<const Vector*, max_order + 1> x{};
    for (int q = 2; q <= r_; ++q) {
      // Backward, order q - 1: u_{-k} from u_{-k+1} and N at -k+1 .. -k+q-1.
      for (int k = 1; k <= q - 1; ++k) {
        const int base = -k + 1;
        d[0] = &backward_exponential_, x[0] = &level_u(base, y);
        for (int j = 0; j < q - 1; ++j) d[j + 1] = &backward_[q][j], x[j + 1] = &level_n(base + j);
        tsi::algebra::diagonal_linear_combination(nullptr, std::span<const tsi::Diagonal* const>(d.data(), q),
                                                  std::span<const Vector* const>(x.data(), q), level_u(-k, y));
        problem_.nonlinear(t - k * h_, level_u(-k, y), level_n(-k));
      }
      // Forward, order q: u_k from u_{k-1} and N at k-1 .. k-q.
      const std::vector<tsi::Diagonal>& w = q < r_ ? forward_[q] : weights_[0];
      for (int k = 1; k <= q - 1; ++k) {
        const int base = k - 1;
        d[0] = &exponentials_[0], x[0] = &level_u(base, y);
        for (int j = 0; j < q; ++j) d[j + 1] = &w[j], x[j + 1] = &level_n(base - j);
        tsi::algebra::diagonal_linear_combination(nullptr, std::span<const tsi::Diagonal* const>(d.data(), q + 1),
                                                  std::span<const Vector* const>(x.data(), q + 1), level_u(k, y));
        problem_.nonlinear(t + k * h_, level_u(k, y), level_n(k));
      }
    }
    started_ = true;
  }

  int r_;
  Startup startup_;
  int next_level_ = 0;  // HOODESolver's start-up: the next forward value a step returns
  tsi::Diagonal backward_exponential_;                                 // e^{-hL}
  std::vector<std::vector<tsi::Diagonal>> backward_, forward_;         // [q][j], see prepare_stages
  std::vector<Vector> backward_u_, backward_n_, forward_u_;            // levels -1 .., and 1 .. r - 1
  bool started_ = false;
  std::vector<std::vector<tsi::Diagonal>> weights_;  // [k][j]: k = 0 the step, k >= 1 the value at -k h
  std::vector<tsi::Diagonal> exponentials_;          // [k]: e^{kappa_k h L}
  std::vector<Vector> history_;  // N_n, N_{n-1}, ..., N_{n-r+1}
  std::vector<Vector> past_;     // the start-up's values at t - k h, k = 1 .. r - 1
};

tsi::StepperTraits traits_of_order(int r) {
  tsi::StepperTraits t;
  t.order = r;
  t.symmetric = false;
  t.implicit = false;
  t.multistep = true;
  t.needs_diagonal_linear_part = true;
  // HOODESolver.jl's default, data of order r + 2 (its prepared data are of order r + 1 at
  // least); tsi's recursion goes to 8.
  t.initial_data_order = std::min(r + 2, 8);
  t.reformulations = {"filtered", "two-scale"};
  return t;
}

void register_eab(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "eab";
  entry.info.aliases = {"exponential-adams-bashforth"};
  entry.info.summary = "exponential Adams-Bashforth of order r (HOODESolver.jl's scheme), explicit, multistep";
  entry.info.params = {tsi::integer_param("order", 4, "the order r: r steps of history, one evaluation of N per step")
                           .check([](const tsi::Json& v) { return v.get<long>() >= 1 && v.get<long>() <= max_order; },
                                  "an integer from 1 to 6"),
                       tsi::string_param("startup", "tsi",
                                         "the history's start-up: tsi (r passes of the interpolatory formula "
                                         "backward from the initial value, r (r - 1) + 1 evaluations) or hoodesolver "
                                         "(HOODESolver.jl's: stage by stage, backward then forward values, "
                                         "(r - 1) r + 1 evaluations, the forward ones the first steps)")
                           .choices({"tsi", "hoodesolver"})};
  entry.traits = traits_of_order(4);
  entry.traits_for = [](const tsi::Json& p) {
    return traits_of_order(p.contains("order") && p["order"].is_number_integer() ? p["order"].get<int>() : 4);
  };
  entry.create = [](const tsi::Params& p) {
    Settings settings;
    if (p.has("order")) settings.order = static_cast<int>(p.integer("order"));
    if (p.has("startup") && p.string("startup") == "hoodesolver") settings.startup = Startup::hoodesolver;
    return tsi::make_scheme<Eab>(settings);
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("eab", register_eab)
