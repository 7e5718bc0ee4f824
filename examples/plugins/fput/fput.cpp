// The Fermi-Pasta-Ulam-Tsingou chain with stiff springs (Hairer, Lubich & Wanner, Geometric
// Numerical Integration, sec. I.5 and ch. XIII) as a tsi model plugin.
//
// 2m unit masses on a line with fixed ends, joined alternately by soft nonlinear springs
// (potential z^4/4) and stiff linear springs of frequency omega = 1/eps. In GNI's variables
// (eq. I.5.2) x0_i, x1_i (1 <= i <= m) are the centre and the half elongation of the i-th
// stiff spring, scaled by sqrt(2), and y0, y1 their momenta:
//
//   H = 1/2 |y0|^2 + 1/2 |y1|^2 + omega^2/2 |x1|^2 + U(x0, x1),
//   U = 1/4 [ (x0_1 - x1_1)^4 + sum_{i=1}^{m-1} (x0_{i+1} - x1_{i+1} - x0_i - x1_i)^4
//             + (x0_m + x1_m)^4 ].
//
// The stiff part 1/2 |y1|^2 + omega^2/2 |x1|^2 becomes (1/(2 eps)) (|xi|^2 + |eta|^2) under
// the symplectic scaling xi = x1 / sqrt(eps), eta = sqrt(eps) y1. The model's state is
//
//   u = (x0_1..m, xi_1..m, y0_1..m, eta_1..m),   J = [[0, I], [-I, 0]],
//   M = diag(0, I, 0, I),                        H1(u) = 1/2 |y0|^2 + U(x0, sqrt(eps) xi),
//
// so that u' = J [ (1/eps) M u + grad H1(u) ] is GNI's system exactly, e^{JM tau} rotates each
// pair (xi_j, eta_j) by the angle tau (period 2 pi), and the oscillatory energy
// I = <Mu, u> / (2 eps) = 1/2 |y1|^2 + omega^2/2 |x1|^2 is GNI's. Physical variables (u0 in a
// config, u_final, errors) are GNI's (x0, x1, y0, y1). Default initial value as in GNI
// (m = 3): x0_1 = 1, y0_1 = 1, x1_1 = 1/omega = eps, y1_1 = 1, all others 0.
//
// tsi ships the same model as "fput" (plugins/models/fput); this example registers as
// "fput-example", so that both load in one process (a name or alias is taken only once).
#include <cmath>
#include <memory>

#include "tsi/model.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Real;
using tsi::Vector;

// Hamiltonian (energies are reported), with its own physical variables.
class Fput final : public tsi::Model, public tsi::HamiltonianStructure, public tsi::PhysicalVariables {
 public:
  Fput(Real eps, Index m) : Model(eps), m_(m), root_eps_(std::sqrt(eps)) {}

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }

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

  // J grad H1 = (dH1/dy0, dH1/deta, -dH1/dx0, -dH1/dxi) = (y0, 0, -dU/dx0, -sqrt(eps) dU/dx1).
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

  // J Hess H1(u) z: the soft spring k contributes 3 d_k^2 (a_k . z) a_k to Hess U z.
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
    for (Index k = 0; k <= m_; ++k) soft += std::pow(spring(u, k).real(), 4);
    return 0.5 * u.segment(2 * m_, m_).real().squaredNorm() + 0.25 * soft;
  }

  Vector initial_value() const override {
    Vector x = Vector::Zero(dim());
    x(0) = 1.0;       // x0_1
    x(m_) = eps();    // x1_1 = 1/omega
    x(2 * m_) = 1.0;  // y0_1
    x(3 * m_) = 1.0;  // y1_1
    return from_physical(x);
  }

  Index physical_dim() const override { return dim(); }

  // (x0, x1, y0, y1) <-> (x0, xi, y0, eta) = (x0, x1 / sqrt(eps), y0, sqrt(eps) y1).
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
  // Elongation d_k of the soft spring k = 0..m (k = 0 and k = m hold the walls), in GNI's
  // variables with x1 = sqrt(eps) xi: d_0 = x0_1 - x1_1, d_k = x0_{k+1} - x1_{k+1} - x0_k - x1_k,
  // d_m = -(x0_m + x1_m) (1-based as in GNI; the sign of d_m does not change U). Linear in u,
  // so it also gives the directional derivative a_k . z when applied to z.
  template <class Column>
  Complex spring(const Column& u, Index k) const {
    Complex d(0);
    if (k < m_) d += u(k) - root_eps_ * u(m_ + k);
    if (k > 0) d -= u(k - 1) + root_eps_ * u(m_ + k - 1);
    return d;
  }

  // The force of spring k with weight g on the momentum rows: out(y0, eta) -= g * grad d_k,
  // where the gradient is taken in (x0, xi) (so the xi part carries sqrt(eps)).
  template <class Column>
  void add_spring_force(Index k, Complex g, Column&& out) const {
    if (k < m_) {
      out(2 * m_ + k) -= g;              // d_k contains +x0_{k+1}
      out(3 * m_ + k) += root_eps_ * g;  // and -sqrt(eps) xi_{k+1}
    }
    if (k > 0) {
      out(2 * m_ + k - 1) += g;              // -x0_k
      out(3 * m_ + k - 1) += root_eps_ * g;  // -sqrt(eps) xi_k
    }
  }

  Index m_;
  Real root_eps_;
};

void register_fput(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "fput-example";
  entry.info.summary =
      "Fermi-Pasta-Ulam-Tsingou chain, m stiff springs of frequency 1/eps (GNI I.5, XIII), dim 4m";
  entry.info.params = {
      tsi::integer_param("m", 3, "number of stiff springs (2m masses)")
          .check([](const tsi::Json& v) { return v.get<long>() >= 1; }, "a positive integer")};
  entry.default_n_tau = 64;
  entry.nonlinearity_degree = 3;  // J grad H1 is cubic in u
  entry.create = [](const tsi::Params& p) { return std::make_unique<Fput>(p.number("eps"), p.integer("m")); };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("fput-example", register_fput)
