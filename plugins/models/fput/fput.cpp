// The Fermi-Pasta-Ulam-Tsingou chain with stiff springs (Hairer, Lubich & Wanner, Geometric
// Numerical Integration, sec. I.5.1 and XIII.2.1; SPEC.md section 8).
//
// 2m unit masses on a line with fixed ends, joined alternately by soft nonlinear springs
// (potential z^4) and stiff linear springs of frequency omega = 1/eps. In SPEC's variables
// x = (x_1..x_m, x_{m+1}..x_{2m}) (centres and elongations of the stiff springs, scaled by
// 1/sqrt 2) and their momenta y:
//
//   H = 1/2 |y|^2 + omega^2/2 sum_j x_{m+j}^2 + U(x),
//   U = 1/4 [ (x_1 - x_{m+1})^4 + sum_{i=1}^{m-1} (x_{i+1} - x_{m+i+1} - x_i - x_{m+i})^4
//             + (x_m + x_{2m})^4 ].
//
// The stiff part becomes (1/(2 eps)) (|xi|^2 + |eta|^2) under the symplectic scaling
// xi_j = x_{m+j} / sqrt(eps), eta_j = sqrt(eps) y_{m+j}, so that the model's state
//
//   u = (x_1..m, xi_1..m, y_1..m, eta_1..m),   J = [[0, I], [-I, 0]],
//   M = diag(0, I, 0, I),                      H1(u) = 1/2 sum_{i<=m} y_i^2 + U(x),
//
// gives u' = J [ (1/eps) M u + grad H1(u) ], SPEC's system exactly: e^{JM tau} turns each
// stiff pair (xi_j, eta_j) by the angle tau, and I = <Mu, u> / (2 eps) = sum_j I_j with
// I_j = 1/2 (y_{m+j}^2 + omega^2 x_{m+j}^2), SPEC's oscillatory energies. Physical variables
// (model.u0, u_final, errors) are SPEC's (x_1..x_2m, y_1..y_2m). Default data as SPEC's for
// m = 3, for any m: x_1 = 1, y_1 = 1, x_{m+1} = 1/omega, y_{m+1} = 1, all others 0.
//
// The mathematics is that of the plugin example examples/plugins/fput (registered there as
// "fput-example"), with the stiff energies I_j declared as recorded quantities.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tsi/model.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Real;
using tsi::Vector;

constexpr long max_stiff_springs = 1000;  // dim 4000: far beyond any chain the literature runs

class Fput final : public tsi::Model,
                   public tsi::HamiltonianStructure,
                   public tsi::PhysicalVariables,
                   public tsi::SecondOrderForm {
 public:
  Fput(Real eps, Index m) : Model(eps), m_(m), root_eps_(std::sqrt(eps)) {}

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }
  const tsi::SecondOrderForm* second_order_form() const override { return this; }

  // x'' = -Omega^2 x - grad U(x) in SPEC's x = (x_1..x_2m): Omega = diag(0 (m), omega = 1/eps (m)).
  Index positions() const override { return 2 * m_; }
  tsi::RealVector frequencies() const override {
    tsi::RealVector omega = tsi::RealVector::Zero(2 * m_);
    omega.tail(m_).setConstant(1 / eps());
    return omega;
  }
  void to_second_order(const Vector& u, tsi::RealVector& x, tsi::RealVector& v) const override {
    x.resize(2 * m_);
    v.resize(2 * m_);
    for (Index i = 0; i < m_; ++i) {
      x(i) = u(i).real();
      x(m_ + i) = root_eps_ * u(m_ + i).real();
      v(i) = u(2 * m_ + i).real();
      v(m_ + i) = u(3 * m_ + i).real() / root_eps_;
    }
  }
  void from_second_order(const tsi::RealVector& x, const tsi::RealVector& v, Vector& u) const override {
    u.resize(dim());
    for (Index i = 0; i < m_; ++i) {
      u(i) = x(i);
      u(m_ + i) = x(m_ + i) / root_eps_;
      u(2 * m_ + i) = v(i);
      u(3 * m_ + i) = root_eps_ * v(m_ + i);
    }
  }
  // g = -grad U = -sum_k d_k^3 grad d_k, with the springs d_k of spring() in x.
  void force(const tsi::RealVector& x, tsi::RealVector& g) const override {
    g.setZero(2 * m_);
    for (Index k = 0; k <= m_; ++k) {
      Real d = 0;
      if (k < m_) d += x(k) - x(m_ + k);
      if (k > 0) d -= x(k - 1) + x(m_ + k - 1);
      const Real d3 = d * d * d;
      if (k < m_) {
        g(k) -= d3;
        g(m_ + k) += d3;
      }
      if (k > 0) {
        g(k - 1) += d3;
        g(m_ + k - 1) += d3;
      }
    }
  }

  Index dim() const override { return 4 * m_; }
  bool is_complex() const override { return false; }

  // e^{JM tau}: xi' = eta, eta' = -xi in tau, a rotation of every stiff pair.
  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const Real c = std::cos(taus(j)), s = std::sin(taus(j));
      for (Index i = 0; i < m_; ++i) {
        const Complex xi = u(m_ + i, j), eta = u(3 * m_ + i, j);
        u(m_ + i, j) = c * xi + s * eta;
        u(3 * m_ + i, j) = -s * xi + c * eta;
      }
    }
  }

  // J grad H1 = (dH1/dy, dH1/deta, -dH1/dx, -dH1/dxi) = (y, 0, -dU/dx_i, -sqrt(eps) dU/dx_{m+i}).
  void nonlinear_field(ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out.col(j).setZero();
      for (Index k = 0; k <= m_; ++k) {
        const Complex d = spring(u.col(j), k);
        add_spring_force(k, d * d * d, out.col(j));
      }
      out.col(j).segment(0, m_) = u.col(j).segment(2 * m_, m_);
    }
  }

  // J Hess H1(u) z: the soft spring k adds 3 d_k^2 (a_k . z) a_k to Hess U z.
  void nonlinear_field_derivative(ConstMatrixRef u, ConstMatrixRef z, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out.col(j).setZero();
      for (Index k = 0; k <= m_; ++k) {
        const Complex d = spring(u.col(j), k), dz = spring(z.col(j), k);
        add_spring_force(k, Real(3) * d * d * dz, out.col(j));
      }
      out.col(j).segment(0, m_) = z.col(j).segment(2 * m_, m_);
    }
  }

  void apply_M(const Vector& u, Vector& out) const override {
    out = u;
    out.segment(0, m_).setZero();
    out.segment(2 * m_, m_).setZero();
  }

  void apply_J(const Vector& u, Vector& out) const override {
    out.resize(dim());
    out.head(2 * m_) = u.tail(2 * m_);
    out.tail(2 * m_) = -u.head(2 * m_);
  }

  Real H1(const Vector& u) const override {
    Real soft = 0;
    for (Index k = 0; k <= m_; ++k) {
      const Real d = spring(u, k).real();
      soft += d * d * d * d;
    }
    return 0.5 * u.segment(2 * m_, m_).real().squaredNorm() + 0.25 * soft;
  }

  // I_j of the stiff spring j (1-based in the name), 1/2 (y_{m+j}^2 + omega^2 x_{m+j}^2) =
  // (xi_j^2 + eta_j^2) / (2 eps). Not conserved: the exact flow passes the energy from spring
  // to spring on the time scale omega (GNI I.5.1), while their sum I stays within O(eps).
  std::vector<tsi::ModelInvariant> invariants() const override {
    std::vector<tsi::ModelInvariant> all;
    for (Index j = 0; j < m_; ++j) {
      const std::string n = std::to_string(j + 1);
      all.push_back({"I_" + n,
                     "oscillatory energy of the stiff spring " + n + ", (y_{m+" + n + "}^2 + omega^2 x_{m+" + n +
                         "}^2) / 2: exchanged between the springs on the time scale omega = 1/eps, their sum is I",
                     [this, j](const Vector& u) { return stiff_energy(u, j); }, false});
    }
    return all;
  }

  Vector initial_value() const override {
    Vector x = Vector::Zero(dim());
    x(0) = 1.0;       // x_1
    x(m_) = eps();    // x_{m+1} = 1/omega
    x(2 * m_) = 1.0;  // y_1
    x(3 * m_) = 1.0;  // y_{m+1}
    return from_physical(x);
  }

  Index physical_dim() const override { return dim(); }

  // (x, y) <-> u = (x_1..m, x_{m+1..2m} / sqrt(eps), y_1..m, sqrt(eps) y_{m+1..2m}).
  Vector from_physical(const Vector& x) const override {
    Vector u = x;
    u.segment(m_, m_) /= root_eps_;
    u.segment(3 * m_, m_) *= root_eps_;
    return u;
  }
  Vector to_physical(const Vector& u) const override {
    Vector x = u;
    x.segment(m_, m_) *= root_eps_;
    x.segment(3 * m_, m_) /= root_eps_;
    return x;
  }

 private:
  Real stiff_energy(const Vector& u, Index j) const {
    return (std::norm(u(m_ + j)) + std::norm(u(3 * m_ + j))) / (2 * eps());
  }

  // Elongation d_k of the soft spring k = 0..m (k = 0 and k = m hold the walls), with
  // x_{m+i} = sqrt(eps) xi_i: d_0 = x_1 - x_{m+1}, d_k = x_{k+1} - x_{m+k+1} - x_k - x_{m+k},
  // d_m = -(x_m + x_{2m}) (the sign of d_m does not change U). Linear in u, so applied to z
  // it gives the directional derivative a_k . z.
  template <class Column>
  Complex spring(const Column& u, Index k) const {
    Complex d(0);
    if (k < m_) d += u(k) - root_eps_ * u(m_ + k);
    if (k > 0) d -= u(k - 1) + root_eps_ * u(m_ + k - 1);
    return d;
  }

  // The force of spring k with weight g on the momentum rows: out(y, eta) -= g grad d_k, the
  // gradient taken in (x, xi) (its xi part carries sqrt(eps)).
  template <class Column>
  void add_spring_force(Index k, Complex g, Column&& out) const {
    if (k < m_) {
      out(2 * m_ + k) -= g;              // d_k contains +x_{k+1}
      out(3 * m_ + k) += root_eps_ * g;  // and -sqrt(eps) xi_{k+1}
    }
    if (k > 0) {
      out(2 * m_ + k - 1) += g;              // -x_k
      out(3 * m_ + k - 1) += root_eps_ * g;  // -sqrt(eps) xi_k
    }
  }

  Index m_;
  Real root_eps_;
};

void register_fput(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "fput";
  entry.info.aliases = {"fpu", "fermi-pasta-ulam"};
  entry.info.summary =
      "Fermi-Pasta-Ulam-Tsingou chain, m stiff springs of frequency 1/eps (GNI I.5.1, XIII), dim 4m";
  entry.info.params = {tsi::integer_param("m", 3, "number of stiff springs (2m masses)")
                           .check(
                               [](const tsi::Json& v) {
                                 const long m = v.get<long>();
                                 return m >= 1 && m <= max_stiff_springs;
                               },
                               "an integer from 1 to " + std::to_string(max_stiff_springs))};
  entry.default_n_tau = 64;
  entry.nonlinearity_degree = 3;  // J grad H1 is cubic in u
  // GNI's data stretch the chain so far that at eps = 1 the prepared data need steps far below
  // h = 1/32: the order is observed in the regime the model is for, omega = 1/eps large, at
  // SPEC's omega = 50 and at eps where h = 1/4 .. 1/32 stay clear of h = k pi eps (at eps = 1e-3,
  // h = 1/32 is 10 pi eps: SE1's order there 1.77).
  entry.verification = {{1.0 / 50, 1.0 / 500, 1e-4}, {4, 8, 16, 32}};
  entry.create = [](const tsi::Params& p) { return std::make_unique<Fput>(p.number("eps"), p.integer("m")); };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("fput", register_fput)
