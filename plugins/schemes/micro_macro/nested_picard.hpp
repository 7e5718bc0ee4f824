#pragma once
// Nested Picard integrators on the whole class, of order m = 1 .. 4 (after Cai and Zhou's NPI for
// Klein-Gordon; tests/data/rivals/micro-macro.md, sections 5.4 and 9). Duhamel's formula in the
// frame of the step's start,
//     z(sigma) = y_n + int_0^sigma g(s, z(s)) ds,   g(s, z) = e^{-L s} f_{theta(s)}(e^{L s} z),
//     theta(s) = (t_n + s)/eps,
// is iterated m times by Picard, each iterate held as a two-scale function of the slow s and the
// fast tau (whose diagonal tau = theta(s) is the iterate):
//     Delta_k(s, tau) = sum_q s^q C_q(tau) + D,   Delta_0 = 0,
//     Delta_k(sigma, .) = int_0^sigma P_k(s, theta(s)) ds,
// where P_k(s, tau) is the polynomial of degree k - 1 in s through the k nodes s_i of [0, h]
// (0; 0, h; 0, h/2, h; ...) of F_k(s_i, tau_j) = g_{tau_j}(s_i, y_n + Delta_{k-1}(s_i, tau_j)),
// one batch of n_tau evaluations per node. Each term s^p G(theta(s)) is integrated exactly, by
// parts, mode by mode (a = i k / eps):
//     int_0^sigma s^p G(theta(s)) ds = <G> sigma^(p+1)/(p+1)
//         + sum_{j=0..p} (-1)^j p!/(p-j)! eps^(j+1) sigma^(p-j) (A^(j+1) G)(theta(sigma))
//         - (-1)^p p! eps^(p+1) (A^(p+1) G)(theta_n),
// so the fast phase is never expanded and the frame e^{+-L s} is evaluated, not Taylor-expanded.
// Iterate k is accurate to O(h^(k+1)) whatever eps (the interpolation is in the slow variable
// only): y_{n+1} = e^{L h} (y_n + Delta_m(h, theta(h))) is uniformly of order m, with
// m (m + 1)/2 batches of f and no derivative. Order 1 is Cai and Zhou's first order (the field
// frozen at y_n; MicroMacro.jl's "schema 0"). Exact only where the tau grid resolves the phases
// of what is evaluated (for NLS, |k1^2 - k2^2 + k3^2 - m^2| up to about n_x^2/2).
#include <vector>

#include "filtered_grid.hpp"
#include "tsi/stepper.hpp"

namespace tsi_micro_macro {

struct NestedPicardSettings {
  int n_tau = 32;
  int order = 1;
};

class NestedPicard final : public tsi::Stepper {
 public:
  NestedPicard(tsi::Problem& problem, Real h, const NestedPicardSettings& settings)
      : Stepper(problem, h),
        order_(settings.order),
        grid_(problem, settings.n_tau, "npi"),
        series_(problem.size(), settings.n_tau),
        whole_(grid_.remainder_flow(h)) {
    // Per iterate k: its nodes, their frames e^{+-L s_i}, and the inverse of the Vandermonde
    // matrix in x = s/h (P_k = sum_p x^p Ghat_p, Ghat = V^{-1} F).
    for (int k = 1; k <= order_; ++k) {
      Iterate it;
      tsi::RealMatrix v(k, k);
      for (int i = 0; i < k; ++i) {
        const Real x = k == 1 ? Real(0) : static_cast<Real>(i) / static_cast<Real>(k - 1);
        it.nodes.push_back(x * h);
        it.to_node.push_back(grid_.remainder_flow(x * h));
        it.from_node.push_back(grid_.remainder_flow(-x * h));
        for (int p = 0; p < k; ++p) v(i, p) = std::pow(x, p);
      }
      it.inverse = v.inverse();
      iterates_.push_back(std::move(it));
    }
    coefficients_.resize(static_cast<size_t>(order_) + 1);
    fields_.resize(static_cast<size_t>(order_));
  }

  void step(Real t, Vector& y) override {
    const Real eps = grid_.eps(), theta0 = tsi::fast_phase(t, eps);
    const Index rows = grid_.rows();
    for (auto& c : coefficients_) c.setZero(rows, grid_.n_tau());
    constant_.setZero(rows);
    for (int k = 1; k <= order_; ++k) {
      const Iterate& it = iterates_[static_cast<size_t>(k - 1)];
      // F_k at the nodes, from Delta_{k-1} (held in coefficients_ and constant_).
      for (int i = 0; i < k; ++i) {
        const Real s = it.nodes[static_cast<size_t>(i)];
        states_ = coefficients_[0];
        Real power = 1;
        for (int q = 1; q <= order_; ++q) {
          power *= s;
          if (k > 1) states_ += power * coefficients_[static_cast<size_t>(q)];
        }
        states_.colwise() += y + constant_;
        turn_columns(it.to_node[static_cast<size_t>(i)], states_);
        grid_.field(states_, fields_[static_cast<size_t>(i)]);
        turn_columns(it.from_node[static_cast<size_t>(i)], fields_[static_cast<size_t>(i)]);
      }
      // Delta_k from scratch: the integral of P_k.
      for (auto& c : coefficients_) c.setZero(rows, grid_.n_tau());
      constant_.setZero(rows);
      for (int p = 0; p < k; ++p) {
        polynomial_ = Real(it.inverse(p, 0)) * fields_[0];
        for (int i = 1; i < k; ++i) polynomial_ += Real(it.inverse(p, i)) * fields_[static_cast<size_t>(i)];
        polynomial_ /= std::pow(h_, p);  // the coefficient of s^p
        integrate_term(p, theta0);
      }
    }
    // z(h) = y + Delta_m(h, theta(h)).
    const Real theta1 = tsi::fast_phase(t + h_, eps);
    increment_ = constant_;
    Real power = 1;
    for (int q = 0; q <= order_; ++q) {
      series_.analyse(coefficients_[static_cast<size_t>(q)]);
      series_.value_at(theta1, point_);
      increment_ += power * point_;
      power *= h_;
    }
    y += increment_;
    turn(whole_, y);
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {grid_.n_tau(), order_}); }
  // Grids of n_tau vectors: the m + 1 coefficients C_q, m node fields, the states, the
  // polynomial, a term and the series (coefficients, work space); the constant, the increment,
  // a point, e^{L h}, the node frames and the grid's two.
  static double state_vectors_for(const tsi::ProblemLayout&, const NestedPicardSettings& s) {
    return (2.0 * s.order + 6.0) * s.n_tau + 6.0 + s.order * (s.order + 1);
  }

 private:
  struct Iterate {
    std::vector<Real> nodes;
    std::vector<Vector> to_node, from_node;
    tsi::RealMatrix inverse;
  };

  // Adds int_0^sigma s^p G(theta(s)) ds, G = polynomial_, to Delta (see the header).
  void integrate_term(int p, Real theta0) {
    const Real eps = grid_.eps();
    series_.analyse(polynomial_);
    series_.mean(point_);
    coefficients_[static_cast<size_t>(p) + 1].colwise() += point_ / static_cast<Real>(p + 1);
    Real falling = 1;  // p! / (p - j)!
    Real eps_power = eps;
    for (int j = 0; j <= p; ++j) {
      series_.antiderivative_power_grid(j + 1, term_, (j % 2 == 0 ? 1 : -1) * falling * eps_power);
      coefficients_[static_cast<size_t>(p - j)] += term_;
      if (j == p) {
        series_.antiderivative_power_at(p + 1, theta0, point_);
        constant_ -= ((p % 2 == 0 ? 1 : -1) * falling * eps_power) * point_;
      }
      falling *= static_cast<Real>(p - j);
      eps_power *= eps;
    }
  }
  // Every column of m turned by the diagonal factor (empty: identity).
  static void turn_columns(const Vector& factor, Matrix& m) {
    if (factor.size() > 0) m = factor.asDiagonal() * m;
  }

  int order_;
  FilteredGrid grid_;
  TauSeries series_;
  Vector whole_, constant_, increment_, point_;
  std::vector<Iterate> iterates_;
  std::vector<Matrix> coefficients_, fields_;
  Matrix states_, polynomial_, term_;
};

}  // namespace tsi_micro_macro
