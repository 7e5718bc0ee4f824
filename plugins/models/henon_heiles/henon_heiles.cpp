// The Henon-Heiles model in the form of the paper (eq. HH model; SPEC.md section 4):
// u = (q1, q2, p1, p2), M = diag(1, 0, 1, 0), J = [[0, I2], [-I2, 0]],
// H1 = q2^2/2 + p2^2/2 + q1^2 q2 - q2^3/3.
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

class HenonHeiles final : public tsi::Model,
                          public tsi::HamiltonianStructure,
                          public tsi::FusedTauGrid,
                          public tsi::SecondOrderForm {
 public:
  explicit HenonHeiles(Real eps) : Model(eps) {}

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  const tsi::SecondOrderForm* second_order_form() const override { return this; }

  // x = (q1, q2), x' = (p1/eps, p2): q1'' = -q1/eps^2 - (2/eps) q1 q2, q2'' = -q2 - q1^2 + q2^2,
  // so Omega = diag(1/eps, 1) and g = (-(2/eps) q1 q2, -q1^2 + q2^2). The fast velocity is
  // O(1/eps) for the paper's data: the energy of the second-order system is unbounded as
  // eps -> 0, outside the bounded-energy regime of the trigonometric integrators' theory.
  Index positions() const override { return 2; }
  tsi::RealVector frequencies() const override {
    tsi::RealVector omega(2);
    omega << Real(1) / eps(), Real(1);
    return omega;
  }
  void to_second_order(const Vector& u, tsi::RealVector& x, tsi::RealVector& v) const override {
    x.resize(2);
    v.resize(2);
    x << u(0).real(), u(1).real();
    v << u(2).real() / eps(), u(3).real();
  }
  void from_second_order(const tsi::RealVector& x, const tsi::RealVector& v, Vector& u) const override {
    u.resize(4);
    u << Complex(x(0)), Complex(x(1)), Complex(eps() * v(0)), Complex(v(1));
  }
  void force(const tsi::RealVector& x, tsi::RealVector& g) const override {
    g.resize(2);
    g << Real(-2) * x(0) * x(1) / eps(), -x(0) * x(0) + x(1) * x(1);
  }

  Index dim() const override { return 4; }
  bool is_complex() const override { return false; }

  // JM couples (q1, p1) only: q1' = p1, p1' = -q1 in tau, a rotation of period 2*pi.
  // The model is real (is_complex() is false): the batched functions compute with real
  // parts, which halves their cost against complex arithmetic.
  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const Real c = std::cos(taus(j)), s = std::sin(taus(j));
      const Real q1 = u(0, j).real(), p1 = u(2, j).real();
      u(0, j) = c * q1 + s * p1;
      u(2, j) = -s * q1 + c * p1;
    }
  }

  // J grad H1 = (dH1/dp, -dH1/dq).
  void nonlinear_field(ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const Real q1 = u(0, j).real(), q2 = u(1, j).real(), p2 = u(3, j).real();
      out(0, j) = 0.0;
      out(1, j) = p2;
      out(2, j) = -2.0 * q1 * q2;
      out(3, j) = -q2 - q1 * q1 + q2 * q2;
    }
  }

  void filtered_field(const tsi::RealVector& taus, MatrixRef u, MatrixRef out) const override {
    const tsi::RealVector c = taus.array().cos(), s = taus.array().sin();
    fused_field(c, s, u, out);
  }

  // A run's tau grid: cos and sin computed once.
  class GridField final : public tsi::TauGridField {
   public:
    explicit GridField(const tsi::RealVector& taus) : cos_(taus.array().cos()), sin_(taus.array().sin()) {}
    void evaluate(MatrixRef u, MatrixRef out) override { fused_field(cos_, sin_, u, out); }
    bool evaluates_real() const override { return true; }
    bool in_place() const override { return true; }  // each column read before it is written
    void evaluate_real(tsi::RealMatrixRef u, tsi::RealMatrixRef out) override { fused_field(cos_, sin_, u, out); }

   private:
    tsi::RealVector cos_, sin_;
  };

  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(taus);
  }
  // Each binding owns its tables and transforms: bindings may run on different threads.
  bool independent_tau_grid_bindings() const override { return true; }

  // The three steps of f_tau in one pass: the flow turns (q1, p1) only, so the field needs
  // the turned q1, and its (q1, p1) part, (0, -2 q1 q2), turns back by -tau. On complex or
  // real grids (a real model's two-scale problem keeps its tau grid real).
  template <class Grid>
  static void fused_field(const tsi::RealVector& cos, const tsi::RealVector& sin, Grid& u, Grid& out) {
    for (Index j = 0; j < u.cols(); ++j) {
      const Real c = cos(j), s = sin(j);
      const Real q1 = c * tsi::real_part(u(0, j)) + s * tsi::real_part(u(2, j)), q2 = tsi::real_part(u(1, j)),
                   p2 = tsi::real_part(u(3, j));
      const Real g = -2.0 * q1 * q2;
      out(0, j) = -s * g;
      out(1, j) = p2;
      out(2, j) = c * g;
      out(3, j) = -q2 - q1 * q1 + q2 * q2;
    }
  }

  void nonlinear_field_derivative(ConstMatrixRef u, ConstMatrixRef z, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const Complex q1 = u(0, j), q2 = u(1, j);
      const Complex a = z(0, j), b = z(1, j), d = z(3, j);
      out(0, j) = 0.0;
      out(1, j) = d;
      out(2, j) = Real(-2) * (a * q2 + q1 * b);
      out(3, j) = -b - Real(2) * q1 * a + Real(2) * q2 * b;
    }
  }

  void apply_M(const Vector& u, Vector& out) const override {
    out.resize(4);
    out << u(0), Complex(0), u(2), Complex(0);
  }

  void apply_J(const Vector& u, Vector& out) const override {
    out.resize(4);
    out << u(2), u(3), -u(0), -u(1);
  }

  Real H1(const Vector& u) const override {
    const Real q1 = u(0).real(), q2 = u(1).real(), p2 = u(3).real();
    return 0.5 * q2 * q2 + 0.5 * p2 * p2 + q1 * q1 * q2 - q2 * q2 * q2 / 3.0;
  }

  Vector initial_value() const override { return Vector::Constant(4, Complex(0.12)); }
};

void register_henon_heiles(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "henon-heiles";
  entry.info.aliases = {"hh"};
  entry.info.summary = "Henon-Heiles with a fast (q1, p1) oscillator (eq. HH model), dim 4";
  entry.default_n_tau = 64;
  entry.nonlinearity_degree = 2;
  entry.verification = {{1.0, 1.0 / 16, 1.0 / 256, 1.0 / 4096, 1e-6}, {4, 8, 16, 32, 64}};
  entry.create = [](const tsi::Params& p) { return std::make_unique<HenonHeiles>(p.number("eps")); };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("henon-heiles", register_henon_heiles)
