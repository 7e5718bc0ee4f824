// Exponential Adams-Bashforth of order r on y' = L y + N(t, y), L diagonal: the scheme
// HOODESolver.jl applies to the two-scale problem (Chartier, Crouseilles, Lemou, Méhats, Zhao).
//   y_{n+1} = e^{hL} y_n + h sum_{j<r} beta_j(hL) N_{n-j},
//   beta_j(z) = int_0^1 e^{(1-s) z} l_j(s) ds   (tsi::InterpolatoryWeights),
// l_j the Lagrange polynomials on the nodes 0, -1, ..., -(r-1) (in units of h). Start-up (HOODESolver computes its history backwards too): the
// values at t - h, ..., t - (r-1) h from the same interpolatory formula towards the past,
// y(t - k h) = e^{-khL} y + h sum_j beta_j^{(-k)}(hL) N_{-j}, iterated r times from N_{-j} = N_0
// (each pass gains one order in h), so the history is accurate to O(h^{r+1}).
#include <array>
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "tsi/algebra.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/error.hpp"
#include "tsi/exponential_weights.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::Vector;

constexpr int max_order = 6;

class Eab final : public tsi::Stepper {
 public:
  Eab(tsi::Problem& problem, double h, int order) : Stepper(problem, h), r_(order) {
    // The weights of N_{-j} for the value at kappa h: kappa = 1 the step, -k the start-up,
    // with the factor h folded in (one value per tau mode on the two-scale problem without a
    // remainder: tsi::Diagonal).
    const tsi::InterpolatoryWeights weights_of(past_nodes(r_));
    const tsi::Diagonal& lambda = problem.linear_multipliers();
    weights_.assign(r_, std::vector<tsi::Diagonal>(r_));
    exponentials_.assign(r_, tsi::Diagonal());
    for (int k = 0; k < r_; ++k) {
      const double kappa = k == 0 ? 1.0 : -static_cast<double>(k);
      tsi::diagonal_function(lambda, h, [kappa](Complex z) { return std::exp(kappa * z); }, exponentials_[k]);
      std::array<tsi::Diagonal*, max_order> outs{};
      for (int j = 0; j < r_; ++j) outs[j] = &weights_[k][j];
      tsi::diagonal_functions(
          lambda, h,
          [&](Complex z) {
            std::vector<Complex> w = weights_of(kappa, z);
            for (Complex& x : w) x *= h;
            return w;
          },
          std::span<tsi::Diagonal* const>(outs.data(), r_));
    }
    history_.assign(r_, problem.new_state());
    past_.assign(r_ - 1, problem.new_state());
  }

  void reset() override { started_ = false; }

  void step(double t, Vector& y) override {
    if (!started_) start(t, y);
    combine(0, y, y);  // in place: the combination reads each entry before it writes it
    // The history moves back one place (swaps, no copies) and N_{n+1} takes the front.
    for (int j = r_ - 1; j > 0; --j) history_[j].swap(history_[j - 1]);
    problem_.nonlinear(t + h_, y, history_.front());
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), r_); }
  // (r + 1) r coefficients; the history of r values of N and the start-up's r - 1 past values.
  static double state_vectors_for(const tsi::ProblemLayout& layout, int r) {
    return (r + 1.0) * r * layout.diagonal_fraction() + 2.0 * r - 1.0;
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
  void start(double t, const Vector& y) {
    problem_.nonlinear(t, y, history_[0]);
    for (int j = 1; j < r_; ++j) tsi::algebra::copy(history_[0], history_[j]);
    for (int pass = 0; pass < r_; ++pass) {
      for (int k = 1; k < r_; ++k) combine(k, y, past_[k - 1]);
      for (int k = 1; k < r_; ++k) problem_.nonlinear(t - k * h_, past_[k - 1], history_[k]);
    }
    started_ = true;
  }

  static std::vector<double> past_nodes(int r) {
    std::vector<double> nodes(r);
    for (int j = 0; j < r; ++j) nodes[j] = -j;
    return nodes;
  }

  int r_;
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
                                  "an integer from 1 to 6")};
  entry.traits = traits_of_order(4);
  entry.traits_for = [](const tsi::Json& p) {
    return traits_of_order(p.contains("order") && p["order"].is_number_integer() ? p["order"].get<int>() : 4);
  };
  entry.create = [](const tsi::Params& p) {
    return tsi::make_scheme<Eab>(p.has("order") ? static_cast<int>(p.integer("order")) : 4);
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("eab", register_eab)
