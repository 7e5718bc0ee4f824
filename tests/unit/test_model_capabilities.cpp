// The narrow Model: a model with only the required core gets the defaults the capabilities
// replace (f_tau in three passes, its own variables, no energy), and a declared capability
// is what tsi then uses.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "tsi/error.hpp"
#include "tsi/model.hpp"

namespace {

using tsi::Complex;
using tsi::Index;
using tsi::Matrix;
using tsi::RealVector;
using tsi::Vector;

// u1 turns with u2 at frequency 1 (e^{A tau} a rotation), f(u) = (u2^2, u1): not a gradient
// field of any H1, and the required core only.
class CoreOnly : public tsi::Model {
 public:
  CoreOnly() : Model(0.1) {}
  Index dim() const override { return 2; }
  bool is_complex() const override { return false; }
  void linear_flow(const RealVector& taus, tsi::MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const double c = std::cos(taus(j)), s = std::sin(taus(j));
      const Complex a = u(0, j), b = u(1, j);
      u(0, j) = c * a + s * b;
      u(1, j) = -s * a + c * b;
    }
  }
  void nonlinear_field(tsi::ConstMatrixRef u, tsi::MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out(0, j) = u(1, j) * u(1, j);
      out(1, j) = u(0, j);
    }
  }
  Vector initial_value() const override { return Vector::Constant(2, 0.5); }
};

// The same with a fused f_tau that is deliberately different (twice the field), and physical
// variables x = 2 u: each capability, once declared, is the one used.
class Declaring final : public CoreOnly, public tsi::FusedTauGrid, public tsi::PhysicalVariables {
 public:
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }
  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const RealVector& taus) const override {
    // (Not through this model's own filtered_field, which comes back here: a plain copy.)
    class Twice final : public tsi::TauGridField {
     public:
      explicit Twice(RealVector taus) : taus_(std::move(taus)) {}
      void evaluate(tsi::MatrixRef u, tsi::MatrixRef out) override {
        plain_.filtered_field(taus_, u, out);
        out *= 2.0;
      }

     private:
      CoreOnly plain_;
      RealVector taus_;
    };
    return std::make_unique<Twice>(taus);
  }
  Index physical_dim() const override { return 2; }
  Vector from_physical(const Vector& x) const override { return x / 2.0; }
  Vector to_physical(const Vector& u) const override { return 2.0 * u; }
};

Matrix filtered(const tsi::Model& m, const RealVector& taus, const Matrix& u) {
  Matrix states = u, out(u.rows(), u.cols());
  m.filtered_field(taus, states, out);
  return out;
}

Matrix bound(const tsi::Model& m, const RealVector& taus, const Matrix& u) {
  Matrix states = u, out(u.rows(), u.cols());
  m.bind_tau_grid(taus)->evaluate(states, out);
  return out;
}

}  // namespace

TEST_CASE("model: the required core alone gives f_tau = e^{-A tau} f(e^{A tau} u), its own variables and no energy") {
  const CoreOnly m;
  CHECK_FALSE(m.has_hamiltonian_structure());
  CHECK_FALSE(m.has_exact_nonlinear_flow());
  CHECK(m.exact_solution() == nullptr);
  CHECK_FALSE(m.independent_tau_grid_bindings());

  // f_tau by hand. Column 0, tau = pi/2: e^{A pi/2} (a, b) = (b, -a) = (-0.7, -0.3),
  // f = (0.09, -0.7), e^{-A pi/2} (x, y) = (-y, x) = (0.7, 0.09). Column 1, tau = 0: f(u).
  RealVector taus(2);
  taus << M_PI / 2, 0.0;
  Matrix u(2, 2);
  u << 0.3, 0.3, -0.7, -0.7;
  Matrix expected(2, 2);
  expected << 0.7, 0.49, 0.09, 0.3;
  CHECK((filtered(m, taus, u) - expected).norm() < 1e-15);
  CHECK((bound(m, taus, u) - expected).norm() < 1e-15);

  const Vector x = m.initial_value();
  CHECK(m.physical_dim() == 2);
  CHECK(m.to_physical(x) == x);
  CHECK(m.from_physical(x) == x);
  CHECK(m.error_norm(x) == doctest::Approx(x.norm()));
  CHECK(m.mass(x) == doctest::Approx(0.5));

  // What needs a capability the model lacks says which one.
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const tsi::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(message([&] { (void)m.energy(x); }).find("no Hamiltonian structure") != std::string::npos);
  CHECK(message([&] { (void)m.oscillatory_energy(x); }).find("no Hamiltonian structure") != std::string::npos);
  Vector out;
  CHECK(message([&] { m.apply_A(x, out); }).find("overrides apply_A") != std::string::npos);
  Vector y = x;
  CHECK(message([&] { m.nonlinear_flow(0.1, y); }).find("no exact nonlinear flow") != std::string::npos);
}

TEST_CASE("model: a declared capability is the one used (fused f_tau, physical variables)") {
  const Declaring m;
  RealVector taus(2);
  taus << 0.4, -1.1;
  Matrix u(2, 2);
  u << 0.3, -0.2, -0.7, 0.5;
  const CoreOnly plain;
  const Matrix three_passes = filtered(plain, taus, u);
  // The fused binding doubles the field: the model's route goes through it, and the
  // capability's default filtered_field binds and evaluates once.
  CHECK((bound(m, taus, u) - 2.0 * three_passes).norm() < 1e-15);
  CHECK((filtered(m, taus, u) - 2.0 * three_passes).norm() < 1e-15);

  const Vector x = m.initial_value();
  CHECK(m.to_physical(x) == 2.0 * x);
  CHECK(m.from_physical(2.0 * x) == x);
  CHECK(m.rounding_floor(x) == doctest::Approx(std::numeric_limits<double>::epsilon()).epsilon(1e-6));
}
