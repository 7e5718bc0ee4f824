#pragma once
#include <optional>
#include <string>
#include <vector>

#include "tau_grid.hpp"

namespace tsi {

struct SigmaNodes;

/// How prepared data of order 2 and above is computed (docs/explanation/high-order.md, "Prepared data of
/// any order").
enum class DataMethod {
  automatic,  ///< SPEC.md's closed formulas for orders 1-3, the recursion along a trajectory above
  recursion,  ///< the recursion along an averaged trajectory at every order
  central,    ///< the recursion with central difference quotients at every order (5^(k-2) evaluations)
};

/// Prepared initial data of a two-scale problem (eq. 2nd data; SPEC.md sections 2 and 6): the
/// U(0, tau) whose solution's t-derivatives stay bounded as eps -> 0, of order p, centred at a
/// phase s (U(s) = v exactly; s = 0 for the initial data, the current phase when a run
/// re-prepares). Computed on the problem's tau grid, whose field evaluations it counts.
class PreparedData {
 public:
  /// The largest order.
  static constexpr int max_order = 8;

  /// `remainder`: the model's i omega per coordinate (empty without one). The order must be
  /// from 1 to max_order (a ConfigError naming reformulation.initial_data_order otherwise).
  PreparedData(TauGrid& grid, Real eps, Vector remainder, int order, DataMethod method);

  /// The data centred at the phase s, as a state of the grid's layout.
  Vector at(const Vector& v, Real s);
  /// The same in `out` (its storage reused where it has the state's size: a run re-prepared
  /// every step allocates no state-sized buffer per step).
  void at(const Vector& v, Real s, Vector& out);
  /// The order the last preparation reached (the asymptotic recursion may stop early).
  int order_reached() const { return order_reached_; }
  /// The vectors of the state's size the preparation of this order and method holds at its
  /// peak (its temporaries), known before anything is built.
  static double work_vectors(const Model& model, int order, const std::string& method);

 private:
  /// r1(w) = A f_.(w), as coefficients.
  Matrix r1(const Vector& w);
  /// r2(w) = A[Df(w) A f(w)] - A^2[Df(w) (Pi f(w) + JR w)] + JR A^2 f(w), as coefficients
  /// (SPEC.md's r2; the JR terms come from the remainder in the averaged flow).
  Matrix r2(const Vector& w);
  /// Orders 1 and 2 of the closed formulas in the real layout, directly as a state: the
  /// field on the real tau grid, no all-mode temporaries (a particle-in-cell state re-prepared
  /// every step is 10^8 coefficients).
  void low_order_data(const Vector& v, Real s, Vector& out);
  /// The closed formulas of SPEC.md (orders 1-3), as coefficients.
  Matrix closed_data(const Vector& v, Real s);
  /// The derivative-free recursion (SPEC.md, "Higher order") to `order` with central
  /// difference quotients, as coefficients.
  Matrix central_data(const Vector& v, Real s, int order);
  /// Phi^k(u): the mean-free tau dependence of data of order k at base point u, coefficients:
  ///   Phi^1 = 0,  Phi^k(u) = eps A [ f(u + Phi^{k-1}(u)) + JR Phi^{k-1}(u) - D Phi^{k-1}(u) G ],
  ///   G = Pi f(u + Phi^{k-1}(u)) + JR u,
  /// with D Phi^{k-1}(u) G a fourth-order central difference (see the definition).
  Matrix central_phi(const Vector& u, int k);
  /// The same recursion evaluated along one trajectory of the averaged flow, on which
  /// D Phi^{k-1} G is d/dsigma (docs/explanation/high-order.md), as coefficients.
  Matrix trajectory_data(const Vector& v, Real s);
  /// The averaged trajectory for trajectory_data: the points c_i = c(h x_i) of the trajectory
  /// through the base point u = v - Phi(u)(s), found with the data themselves (one order of
  /// Phi and one Picard step per sweep) from the line through v along `drift`, the averaged
  /// field at v. Returns the points (u is points[nodes.center]), none where the sweeps diverge.
  std::optional<std::vector<Vector>> averaged_trajectory(const Vector& v, Real s, const SigmaNodes& nodes,
                                                         Real h, const Vector& drift);
  /// One level of the recursion at every point c_i of a trajectory (or at `only` alone):
  ///   next_i = eps A [ f(c_i + previous_i) + JR previous_i - (d/dsigma previous)(sigma_i) ],
  /// with drift_i = Pi f(c_i + previous_i) + JR c_i, the averaged field there.
  void trajectory_level(const std::vector<Vector>& points, const std::vector<Vector>& previous,
                        const SigmaNodes& nodes, Real h, std::vector<Vector>& next,
                        std::vector<Vector>& drift, int only = -1);
  /// The points u + int_0^{sigma_i} drift of the trajectory through u, by the interpolant of
  /// the drift at the points (a Picard step).
  std::vector<Vector> picard_step(const Vector& u, const std::vector<Vector>& drift, const SigmaNodes& nodes,
                                  Real h) const;

  TauGrid& grid_;
  Index dim_;
  int n_tau_;
  int columns_;
  Real eps_;
  Vector at_s_;  // low_order_data: its correction at tau = s, kept between re-preparations
  Vector remainder_;  // i omega per model coordinate (empty without a remainder)
  int order_;
  DataMethod method_;
  int order_reached_ = 0;
  Real phase_ = 0.0;  // the centre of the data being prepared: the diagonal of its evaluations
};

}  // namespace tsi
