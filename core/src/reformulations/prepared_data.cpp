#include "prepared_data.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "remainder.hpp"
#include "sigma_nodes.hpp"
#include "tsi/error.hpp"
#include "tsi/stop_request.hpp"

namespace tsi {
namespace {


/// The asymptotic recursion's stopping rule: order k (> 2) is kept while its correction to
/// order k - 1 does not grow. Growth at the rounding level of the data is noise, not
/// divergence: those corrections are kept.
bool keeps_decreasing(int k, Real correction, Real last_correction, Real data_norm) {
  const Real rounding = 64.0 * std::numeric_limits<Real>::epsilon() * data_norm;
  return k <= 2 || correction <= std::max(last_correction, rounding);
}

/// The trajectory's points for data of order p: data of order p differentiate p - 2 times
/// along it (level k differentiates level k - 1), so its polynomial needs degree p - 2 (with 5
/// points, order 7 lost its eps^6 term: 1.7e-12 off at eps = 1/32, 1e-15 with 7). A remainder
/// turns the high modes fast along it: 7 points resolve them (Klein-Gordon, eps = 1e-4: 2e-15
/// off with 5, 5e-19 with 7).
int trajectory_point_count(int order, bool remainder) { return remainder || order > 6 ? 7 : 5; }

/// The trajectory's half length with m points, in units of the time in which the averaged flow
/// at the data moves by their own size: shorter loses digits to the differentiation (eps D / h
/// per level, D's largest row (m - 1)^2), longer to the interpolation ((h speed)^(m-1)). A
/// higher degree allows a longer one (NLS, order 7 at eps = 1/16: 1.9e-12 off at 0.01, 7e-14 at
/// 0.03), the fast rotations of a remainder do not (Klein-Gordon, order 7 at eps = 1/256:
/// 1.7e-14 at 0.01, 1.5e-12 at 0.03). Measured on Henon-Heiles, NLS, the charged particle and
/// Klein-Gordon at eps = 1e-4 .. 1 (docs/benchmarks/high-order.md).
Real trajectory_length(int m, bool remainder) { return m > 5 && !remainder ? 0.03 : 0.01; }
// The order of the central quotients' data where the trajectory's sweeps diverge.
constexpr int central_fallback_order = 4;

}  // namespace

PreparedData::PreparedData(TauGrid& grid, Real eps, Vector remainder, int order, DataMethod method)
    : grid_(grid),
      dim_(grid.dim()),
      n_tau_(grid.n_tau()),
      columns_(grid.columns()),
      eps_(eps),
      remainder_(std::move(remainder)),
      order_(order),
      method_(method) {
  if (order < 1 || order > max_order)
    throw ConfigError("reformulation.initial_data_order",
                      "got " + std::to_string(order) + ", expected an integer from 1 to " + std::to_string(max_order));
}

double PreparedData::work_vectors(const Model& model, int order, const std::string& method) {
  // The closed formulas (orders 2, 3) hold at most 4 grids at once (r2), the central quotients
  // a grid per level of their recursion and its quotient's four, the recursion along a
  // trajectory the previous and the next level at its m points (trajectory_data).
  const bool remainder = model_remainder(model).size() > 0;
  if (order < 2) return 2.0;
  if (method == "central") return 3.0 + 2.0 * order;
  if (method == "recursion" || order > 3) return 2.0 * trajectory_point_count(order, remainder) + 3.0;
  return order == 3 ? 5.0 : 2.0;
}

Matrix PreparedData::r1(const Vector& w) { return grid_.apply_A(grid_.f_coefficients(w.replicate(1, n_tau_))); }

Matrix PreparedData::r2(const Vector& w) {
  // At most four grids at once: the constant grid of w is made again for each use.
  Matrix f = grid_.f_coefficients(w.replicate(1, n_tau_));
  Vector drift = f.col(0);  // the averaged field at w, Pi f(w) + JR w: constant in tau
  if (remainder_.size()) drift += remainder_.cwiseProduct(w);
  Matrix remainder_term;
  if (remainder_.size()) remainder_term = remainder_.asDiagonal() * grid_.apply_A(grid_.apply_A(f));
  Matrix af_grid = grid_.to_grid(grid_.apply_A(std::move(f)));
  Matrix r = grid_.apply_A(grid_.df_coefficients(w.replicate(1, n_tau_), std::move(af_grid)));
  r -= grid_.apply_A(grid_.apply_A(grid_.df_coefficients(w.replicate(1, n_tau_), drift.replicate(1, n_tau_))));
  if (remainder_.size()) r += remainder_term;
  return r;
}

Vector PreparedData::at(const Vector& v, Real s) {
  Vector out;
  at(v, s, out);
  return out;
}

void PreparedData::at(const Vector& v, Real s, Vector& out) {
  order_reached_ = order_;  // the recursions lower it where they stop early
  phase_ = s;
  if (method_ == DataMethod::automatic && order_ <= 2 && grid_.real_layout()) return low_order_data(v, s, out);
  Matrix c;
  if (method_ == DataMethod::central)
    c = central_data(v, s, order_);
  else if (method_ == DataMethod::recursion || order_ > 3)
    c = trajectory_data(v, s);
  else
    c = closed_data(v, s);
  out = Eigen::Map<const Vector>(c.data(), grid_.size());
}

void PreparedData::low_order_data(const Vector& v, Real s, Vector& out) {
  // Order 2: U = v + eps (r1(v) - r1(v)(s)), r1 = A f_.(v), with f_tau of the constant grid v
  // evaluated as the state's nonlinearity at the zero state shifted by v; order 1: U = v.
  // The columns scaled by eps A and their value at s come in the same pass (ColumnFinish).
  if (order_ >= 2) {
    TauGrid::ColumnFinish finish;
    for (int j = 0; j < columns_; ++j) {
      const Complex a = grid_.antiderivative(j);
      finish.factors.push_back(a == Complex(0) ? Complex(0) : eps_ * a);
    }
    finish.phase = s;
    finish.at_phase = &at_s_;
    grid_.nonlinear_of_constant(v, out, s, &finish);
  } else {
    out.setZero(grid_.size());
  }
  Eigen::Map<Matrix> c(out.data(), dim_, columns_);
  if (order_ >= 2) c.col(0) -= at_s_;
  c.col(0) += v;
}

Matrix PreparedData::closed_data(const Vector& v, Real s) {
  Matrix c;
  if (order_ < 2) c = Matrix::Zero(dim_, n_tau_);
  if (order_ >= 2) {
    // eq. (2nd data) centred at s; order 3 evaluates r1 at vbar = v - eps r1(v)(s) and adds
    // eps^2 r2(v). s = 0 is the initial data.
    Matrix r = r1(v);
    if (order_ == 3) {
      const Vector vbar = v - eps_ * grid_.evaluate(r, s);
      r.resize(0, 0);  // r2's grids next, without it
      r = eps_ * r2(v);
      r = r1(vbar) + r;
    }
    r *= eps_;
    c = std::move(r);
    c.col(0) -= grid_.evaluate(c, s);  // U(s) = v exactly: subtract the value at tau = s
  }
  c.col(0) += v;
  return c;
}

Matrix PreparedData::central_data(const Vector& v, Real s, int order) {
  // The base point from the fixed point u = v - Phi(u)(s), one iteration per order (each gains
  // a factor eps), as HOODESolver.jl does: U = u + Phi^k(u_prev), exact at s by construction.
  // The expansion is asymptotic: at eps near 1 its corrections stop decreasing (Henon-Heiles at
  // eps = 1: 2.3e-3 at order 5, 2.6e-3 at 6, 4.0 at 8), so it is truncated where they grow,
  // at its smallest term, and the order reached is recorded.
  Matrix data = Matrix::Zero(dim_, n_tau_), c = data;
  data.col(0) = v;
  Vector u = v;
  Real last_correction = std::numeric_limits<Real>::infinity();
  order_reached_ = 1;
  for (int k = 2; k <= order; ++k) {
    throw_if_stop_requested("preparing the two-scale initial data");  // an order can take seconds
    Matrix next = central_phi(u, k);
    const Vector next_u = v - grid_.evaluate(next, s);
    Matrix candidate = next;
    candidate.col(0) += next_u;
    const Real correction = grid_.norm_from_squares((candidate - data).squaredNorm());
    if (!keeps_decreasing(k, correction, last_correction, grid_.norm_from_squares(data.squaredNorm()))) break;
    last_correction = correction;
    data.swap(candidate);
    u = next_u;
    order_reached_ = k;
  }
  return data;
}

Matrix PreparedData::central_phi(const Vector& u, int k) {
  if (k <= 1) return Matrix::Zero(dim_, n_tau_);
  const Matrix previous = central_phi(u, k - 1);
  const Matrix f = grid_.f_coefficients(u.replicate(1, n_tau_) + grid_.to_grid(previous));
  Matrix rhs = f;
  if (remainder_.size()) rhs += remainder_.asDiagonal() * previous;
  if (k >= 3) {
    // D Phi^{k-1}(u) G by the central difference of fourth order with step d = eps^((k-2)/4):
    // its error, d^4 times the fifth derivative of Phi^{k-1} (O(eps)), is O(eps^(k-1)) and
    // eps^k after the factor eps A, as the recursion needs. HOODESolver's forward quotient
    // with step eps^(k-2) divides rounding errors by eps^(k-2) at every level (about
    // (k-1)(k-2)/2 log10(1/eps) digits lost at order k); this step loses none up to order 6
    // (docs/benchmarks/high-order.md has the measurement).
    Vector g = f.col(0);
    if (remainder_.size()) g += remainder_.cwiseProduct(u);
    const Real d = std::pow(eps_, 0.25 * (k - 2));
    const auto at = [&](Real shift) { return central_phi(u + shift * d * g, k - 1); };
    const Matrix derivative = (Real(8) * (at(1) - at(-1)) - (at(2) - at(-2))) / (12 * d);
    rhs -= derivative;
  }
  return eps_ * grid_.apply_A(rhs);
}

Matrix PreparedData::trajectory_data(const Vector& v, Real s) {
  // The recursion of central_data, with D Phi^{k-1}(u) G taken as d/dsigma along one trajectory
  // sigma -> c(sigma) of the averaged flow c' = G(c) through the base point: on it every level
  // closes on the points c_i = c(h x_i) themselves, Phi^k(c_i) = eps A [ f(c_i + Phi^{k-1}(c_i))
  // + JR Phi^{k-1}(c_i) - (d/dsigma Phi^{k-1})(c_i) ], one evaluation per point and level. One
  // trajectory serves every level: a G off by dG costs eps^2 dG (eps A, and D Phi = O(eps)), so
  // the trajectory of the most accurate averaged field serves all orders below it.
  order_reached_ = 1;
  if (order_ < 2) {
    Matrix data = Matrix::Zero(dim_, n_tau_);
    data.col(0) = v;
    return data;
  }
  Matrix f = grid_.f_coefficients(v.replicate(1, n_tau_));
  if (order_ == 2) {  // Phi^2 = eps A f needs no trajectory
    Matrix phi = grid_.apply_A(std::move(f));
    phi *= eps_;
    phi.col(0) += v - grid_.evaluate(phi, s);
    order_reached_ = 2;
    return phi;
  }
  // The trajectory's half length h: a fixed fraction of the time in which the averaged flow
  // at v moves by |v|. Shorter loses digits to the differentiation (eps D/h per level), longer
  // to the interpolation of the trajectory (measured: docs/benchmarks/high-order.md).
  const bool remainder = remainder_.size() > 0;
  const SigmaNodes nodes(trajectory_point_count(order_, remainder));
  Vector drift = f.col(0);
  f.resize(0, 0);
  if (remainder) drift += remainder_.cwiseProduct(v);
  const Real speed = grid_.norm_from_squares(drift.squaredNorm()) / grid_.norm_from_squares(v.squaredNorm());
  const Real length = trajectory_length(static_cast<int>(nodes.x.size()), remainder);
  const Real h = speed > 0.0 && std::isfinite(speed) ? length / speed : length;
  const int m = static_cast<int>(nodes.x.size()), c = nodes.center;
  const std::optional<std::vector<Vector>> trajectory = averaged_trajectory(v, s, nodes, h, drift);
  // No trajectory where the expansion diverges from its first orders on (eps near 1): there the
  // central quotients' coarse steps (d = 1 at eps = 1) give the better data (the charged
  // particle at eps = 1, re-prepared: err_H 6.4e-4 against 1.3e-3 by the trajectory), up to
  // order 4 (38 evaluations: orders beyond it gain nothing there).
  if (!trajectory) return central_data(v, s, std::min(order_, central_fallback_order));
  const std::vector<Vector>& points = *trajectory;
  Matrix data = Matrix::Zero(dim_, n_tau_);
  data.col(0) = v;
  std::vector<Vector> previous(m, Vector::Zero(grid_.size())), next(m, Vector(grid_.size())), drifts(m);
  Real last_correction = std::numeric_limits<Real>::infinity();
  for (int k = 2; k <= order_; ++k) {
    throw_if_stop_requested("preparing the two-scale initial data");  // an order can take seconds
    trajectory_level(points, previous, nodes, h, next, drifts, k == order_ ? c : -1);
    Matrix candidate = grid_.all_modes(Eigen::Map<const Matrix>(next[c].data(), dim_, columns_));
    candidate.col(0) += v - grid_.evaluate(candidate, s);  // U(s) = v exactly
    const Real correction = grid_.norm_from_squares((candidate - data).squaredNorm());
    if (!keeps_decreasing(k, correction, last_correction, grid_.norm_from_squares(data.squaredNorm()))) break;
    last_correction = correction;
    data.swap(candidate);
    order_reached_ = k;
    previous.swap(next);
  }
  return data;
}

std::optional<std::vector<Vector>> PreparedData::averaged_trajectory(const Vector& v, Real s, const SigmaNodes& nodes,
                                                                 Real h, const Vector& drift) {
  // Sweeps of the whole system at once: Phi at the points gains an order, the base point
  // u = v - Phi(u)(s) follows it, and the trajectory takes a Picard step with the averaged field
  // they give. The data of order p then lose eps |du| to the base point and eps^2 |dc| to the
  // trajectory (measured); the sweeps stop when these fall below the data's own error.
  const int m = static_cast<int>(nodes.x.size()), c = nodes.center;
  std::vector<Vector> points = picard_step(v, std::vector<Vector>(m, drift), nodes, h);
  std::vector<Vector> phi(m, Vector::Zero(grid_.size())), next(m, Vector(grid_.size())), drifts(m);
  const Real target =
      std::max(64.0 * std::numeric_limits<Real>::epsilon(), 1e-3 * std::pow(eps_, order_)) *
      grid_.norm_from_squares(v.squaredNorm());
  // The sweeps gain about a factor eps each; where they gain less (Klein-Gordon at eps = 1e-2:
  // 5-10x) the data's own truncation is as slow, and a few sweeps more suffice.
  const int max_sweeps = order_ + 4;
  Vector u = v;
  Real last_change = std::numeric_limits<Real>::infinity();
  for (int sweep = 1; sweep <= max_sweeps; ++sweep) {
    throw_if_stop_requested("preparing the two-scale initial data");  // an order can take seconds
    trajectory_level(points, phi, nodes, h, next, drifts);
    const Vector next_u = v - grid_.evaluate(Eigen::Map<const Matrix>(next[c].data(), dim_, columns_), s);
    std::vector<Vector> next_points = picard_step(next_u, drifts, nodes, h);
    Real change = 0.0, moved = 0.0;
    for (int i = 0; i < m; ++i) {
      change = std::max(change, grid_.coefficient_norm(next[i] - phi[i]));
      moved = std::max(moved, grid_.norm_from_squares((next_points[i] - points[i]).squaredNorm()));
    }
    // Near eps = 1 the sweeps can diverge with the asymptotic series: no trajectory then.
    if (sweep > 2 && !(change < 2.0 * last_change)) return std::nullopt;
    last_change = change;
    const Real error = eps_ * grid_.norm_from_squares((next_u - u).squaredNorm()) + eps_ * eps_ * moved;
    phi.swap(next);
    points.swap(next_points);
    u = next_u;
    if (error <= target) break;
  }
  return points;
}

void PreparedData::trajectory_level(const std::vector<Vector>& points, const std::vector<Vector>& previous,
                                const SigmaNodes& nodes, Real h, std::vector<Vector>& next,
                                std::vector<Vector>& drift, int only) {
  const int m = static_cast<int>(points.size());
  const auto phi = [&](int j) { return Eigen::Map<const Matrix>(previous[j].data(), dim_, columns_); };
  for (int i = 0; i < m; ++i) {
    if (only >= 0 && i != only) continue;
    throw_if_stop_requested("preparing the two-scale initial data");
    grid_.nonlinear(previous[i], &points[i], next[i], phase_);  // f at c_i + previous_i(tau)
    Eigen::Map<Matrix> rhs(next[i].data(), dim_, columns_);
    drift[i] = rhs.col(0);
    if (remainder_.size()) drift[i] += remainder_.cwiseProduct(points[i]);
    // One pass per tau mode over the m points' data (each mode a few hundred kB at most).
    for (int col = 0; col < columns_; ++col) {
      auto mode = rhs.col(col);
      const Complex factor = eps_ * grid_.antiderivative(col);
      if (factor == Complex(0)) {
        mode.setZero();
        continue;
      }
      if (remainder_.size()) mode += remainder_.cwiseProduct(phi(i).col(col));
      for (int j = 0; j < m; ++j)
        if (nodes.differentiate(i, j) != 0.0) mode -= (nodes.differentiate(i, j) / h) * phi(j).col(col);
      mode *= factor;
    }
  }
}

std::vector<Vector> PreparedData::picard_step(const Vector& u, const std::vector<Vector>& drift, const SigmaNodes& nodes,
                                          Real h) const {
  const int m = static_cast<int>(drift.size());
  std::vector<Vector> points(m, u);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) points[i] += (h * nodes.integrate(i, j)) * drift[j];
  return points;
}


}  // namespace tsi
