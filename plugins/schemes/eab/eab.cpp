// Exponential Adams-Bashforth of order r on y' = L y + N(t, y), L diagonal: the scheme
// HOODESolver.jl applies to the two-scale problem (Chartier, Crouseilles, Lemou, Méhats, Zhao).
//   y_{n+1} = e^{hL} y_n + h sum_{j<r} beta_j(hL) N_{n-j},
//   beta_j(z) = int_0^1 e^{(1-s) z} l_j(s) ds   (tsi::InterpolatoryWeights),
// l_j the Lagrange polynomials on the nodes 0, -1, ..., -(r-1) (in units of h). Start-up (HOODESolver computes its history backwards too): the
// values at t - h, ..., t - (r-1) h from the same interpolatory formula towards the past,
// y(t - k h) = e^{-khL} y + h sum_j beta_j^{(-k)}(hL) N_{-j}, iterated r times from N_{-j} = N_0
// (each pass gains one order in h), so the history is accurate to O(h^{r+1}).
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <vector>

#include "tsi/algebra.hpp"
#include "tsi/error.hpp"
#include "tsi/exponential_weights.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::Vector;

constexpr int max_order = 6;

class Eab final : public tsi::Stepper {
 public:
  explicit Eab(int order) : r_(order), weights_of_(past_nodes(order)) {}

  void reset() override { history_.clear(); }

  void step(tsi::Problem& problem, double t, double h, Vector& y) override {
    if (h != h_ || problem.size() != y.size() || e_.size() != y.size()) prepare(problem, h);
    if (history_.empty()) start(problem, t, h, y);
    next_ = e_.cwiseProduct(y);
    for (int j = 0; j < r_; ++j) next_ += h * weights_[0][j].cwiseProduct(history_[j]);
    y.swap(next_);
    history_.pop_back();
    history_.emplace_front(y.size());
    problem.nonlinear(t + h, y, history_.front());
  }

 private:
  // The weights of N_{-j} for the value at kappa h: kappa = 1 the step, -k the start-up.
  void prepare(const tsi::Problem& problem, double h) {
    const Vector& lambda = problem.linear_multipliers();
    const auto n = lambda.size();
    weights_.assign(r_, std::vector<Vector>(r_, Vector(n)));
    exponentials_.assign(r_, Vector(n));
    for (int k = 0; k < r_; ++k) {
      const double kappa = k == 0 ? 1.0 : -static_cast<double>(k);
      for (tsi::Index i = 0; i < n; ++i) {
        const Complex z = h * lambda(i);
        exponentials_[k](i) = std::exp(kappa * z);
        const std::vector<Complex> w = weights_of_(kappa, z);
        for (int j = 0; j < r_; ++j) weights_[k][j](i) = w[j];
      }
    }
    e_ = exponentials_[0];
    h_ = h;
    history_.clear();
  }

  // N at t, t - h, ..., t - (r-1) h, the past values from r passes of the interpolatory formula.
  void start(tsi::Problem& problem, double t, double h, const Vector& y) {
    history_.assign(r_, Vector(y.size()));
    problem.nonlinear(t, y, history_[0]);
    for (int j = 1; j < r_; ++j) history_[j] = history_[0];
    std::vector<Vector> past(r_, Vector(y.size()));
    for (int pass = 0; pass < r_; ++pass) {
      for (int k = 1; k < r_; ++k) {
        past[k] = exponentials_[k].cwiseProduct(y);
        for (int j = 0; j < r_; ++j) past[k] += h * weights_[k][j].cwiseProduct(history_[j]);
      }
      for (int k = 1; k < r_; ++k) problem.nonlinear(t - k * h, past[k], history_[k]);
    }
  }

  static std::vector<double> past_nodes(int r) {
    std::vector<double> nodes(r);
    for (int j = 0; j < r; ++j) nodes[j] = -j;
    return nodes;
  }

  int r_;
  tsi::InterpolatoryWeights weights_of_;
  double h_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<Vector>> weights_;  // [k][j]: k = 0 the step, k >= 1 the value at -k h
  std::vector<Vector> exponentials_;          // [k]: e^{kappa_k h L}
  Vector e_, next_;
  std::deque<Vector> history_;  // N_n, N_{n-1}, ..., N_{n-r+1}
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
    return std::make_unique<Eab>(p.has("order") ? static_cast<int>(p.integer("order")) : 4);
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("eab", register_eab)
