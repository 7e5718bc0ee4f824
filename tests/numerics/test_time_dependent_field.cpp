// A C++ model with a time-dependent f (the TimeDependentField capability), carried by the core
// with t as one more variable: HOODESolver.jl's linear test f(t, u) = B u + t a + b written as a
// Model gives the numbers of the matrix model with its "linear" field, and SE1 and eab reach
// their orders against the exact solution, computed here independently (the exponential of an
// augmented matrix in long double), as rk78 does on the filtered and direct problems. The model
// the registry creates is one more entry long, and its u0, u_final and derivative are those of
// the model's own variables.
#include <doctest/doctest.h>

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>
#include <vector>
#include <unsupported/Eigen/MatrixFunctions>

#include "tsi/assembly.hpp"
#include "tsi/driver.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"
#include "tsi/time_as_variable.hpp"

namespace {

using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::Json;
using tsi::MatrixRef;
using tsi::RealVector;
using tsi::Vector;

// u' = (1/eps) A u + B u + t a + b, A turning (u1, u3) at frequency 1 (HOODESolver.jl's linear
// test, SPEC.md section 7), as a plugin author writes it: the five functions of the general
// class but with f(t, u) in nonlinear_field_at.
class LinearTestModel : public tsi::Model, public tsi::TimeDependentField {
 public:
  explicit LinearTestModel(double eps) : Model(eps), B_(4, 4), a_(4), b_(4) {
    B_ << 0.12, -0.78, 0.91, 0.34, -0.45, 0.56, 0.03, 0.54, -0.67, 0.09, 0.18, 0.89, -0.91, -0.56, 0.11, -0.56;
    a_ << 0.12, -0.98, 0.45, 0.26;
    b_ << -0.04, 0.48, 0.23, -0.87;
  }
  Index dim() const override { return 4; }
  bool is_complex() const override { return false; }
  void linear_flow(const RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const double c = std::cos(taus(j)), s = std::sin(taus(j));
      const auto u1 = u(0, j), u3 = u(2, j);
      u(0, j) = c * u1 + s * u3;
      u(2, j) = -s * u1 + c * u3;
    }
  }
  void apply_A(const Vector& u, Vector& out) const override {
    out = Vector::Zero(4);
    out(0) = u(2);
    out(2) = -u(0);
  }
  Vector initial_value() const override {
    Vector u(4);
    u << -0.34, 0.78, 0.67, -5.6;
    return u;
  }

  const tsi::TimeDependentField* time_dependent_field() const override { return this; }
  void nonlinear_field_at(const RealVector& t, ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) out.col(j) = B_ * u.col(j) + t(j) * a_ + b_;
  }
  void nonlinear_field_derivative_at(const RealVector&, ConstMatrixRef, ConstMatrixRef z,
                                     MatrixRef out) const override {
    out = B_ * z;
  }

  tsi::Matrix B_;
  Vector a_, b_;
};

// The same model declaring an energy as well, which takes no t: refused.
class WithHamiltonian final : public LinearTestModel, public tsi::HamiltonianStructure {
 public:
  using LinearTestModel::LinearTestModel;
  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  void apply_M(const Vector& u, Vector& out) const override { out = u; }
  void apply_J(const Vector& u, Vector& out) const override { out = u; }
  tsi::Real H1(const Vector&) const override { return 0.0; }
};

// The core's entries, the shipped plugins and the model above as "cpp-linear".
const tsi::Registry& registry() {
  static tsi::Registry r;
  static tsi::PluginLoader loader(r);
  static const bool ready = [] {
    tsi::register_core(r);
    loader.load_directory(TSI_TEST_PLUGIN_DIR);
    tsi::ModelEntry entry;
    entry.info.name = "cpp-linear";
    entry.info.summary = "HOODESolver.jl's linear test as a C++ model with a time-dependent f (test)";
    entry.default_n_tau = 16;
    entry.nonlinearity_degree = 1;  // affine in (u, t)
    entry.create = [](const tsi::Params& p) { return std::make_unique<LinearTestModel>(p.number("eps")); };
    r.add_model(std::move(entry));
    return true;
  }();
  (void)ready;
  return r;
}

// u(t_end) in physical variables: t_end / h steps of the scheme on the two-scale problem
// (n_tau = 16: F_tau has tau modes up to 2) or another reformulation.
Vector solve(const Json& model, const Json& scheme, double h, double t_end = 1.0,
             const Json& reformulation = {{"name", "two-scale"}, {"n_tau", 16}}) {
  const Json config = {{"model", model}, {"reformulation", reformulation}, {"scheme", scheme}};
  tsi::Assembly a = tsi::assemble_config(config, registry());
  const long n = std::lround(t_end / h);
  Vector y = a.reformulation->prepare(a.u0);
  tsi::integrate(a.bind(h), y, n, {}, a.reformulation->repreparation());
  return a.model->to_physical(a.reformulation->read_back(y, tsi::step_time(n, h)));
}

// The exact solution at t_end: z = (u, t, 1) solves z' = [[A/eps + B, a, b], [0, 0, 1], [0, 0, 0]] z.
Vector linear_exact(double eps, double t_end) {
  using M6 = Eigen::Matrix<long double, 6, 6>;
  M6 Z = M6::Zero();
  const long double B[4][4] = {{0.12L, -0.78L, 0.91L, 0.34L},
                               {-0.45L, 0.56L, 0.03L, 0.54L},
                               {-0.67L, 0.09L, 0.18L, 0.89L},
                               {-0.91L, -0.56L, 0.11L, -0.56L}};
  const long double a[4] = {0.12L, -0.98L, 0.45L, 0.26L}, b[4] = {-0.04L, 0.48L, 0.23L, -0.87L};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) Z(i, j) = B[i][j];
    Z(i, 4) = a[i];
    Z(i, 5) = b[i];
  }
  const long double e = static_cast<long double>(eps);
  Z(0, 2) += 1.0L / e;
  Z(2, 0) -= 1.0L / e;
  Z(4, 5) = 1.0L;
  const M6 E = (static_cast<long double>(t_end) * Z).exp();
  Eigen::Matrix<long double, 6, 1> z0;
  z0 << -0.34L, 0.78L, 0.67L, -5.6L, 0.0L, 1.0L;
  const Eigen::Matrix<long double, 6, 1> z = E * z0;
  Vector u(4);
  for (Index i = 0; i < 4; ++i) u(i) = static_cast<double>(z(i));
  return u;
}

// The least-squares slope of log(error) against log(h).
double slope(const std::vector<double>& hs, const std::vector<double>& errors) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const auto n = static_cast<double>(hs.size());
  for (std::size_t i = 0; i < hs.size(); ++i) {
    const double x = std::log(hs[i]), y = std::log(errors[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

TEST_CASE("time-dependent f: the registry's model carries t, its physical variables and derivative are the model's") {
  const auto& entry = registry().model("cpp-linear");
  const tsi::Params params(tsi::resolve_params(entry.info.params, {{"eps", 0.1}}, "model"));
  const std::unique_ptr<tsi::Model> model = entry.create(params);
  CHECK(model->dim() == 5);
  CHECK(model->physical_dim() == 4);
  CHECK_FALSE(model->has_time_dependent_field());  // the core's model is autonomous
  const LinearTestModel own(0.1);
  const Vector u0 = model->initial_value();
  CHECK(u0(4) == 0.0);  // runs start at t = 0
  CHECK(model->to_physical(u0) == own.initial_value());
  CHECK(model->from_physical(own.initial_value()) == u0);
  // f of (u, s) = (B u + s a + b, 1), and e^{A tau} leaves s alone.
  Vector w(5);
  w << 0.3, -0.2, 0.5, 0.1, 0.75;
  const Vector f = model->nonlinear_field(w);
  CHECK((f.head(4) - (own.B_ * w.head(4) + 0.75 * own.a_ + own.b_)).norm() < 1e-15);
  CHECK(f(4) == 1.0);
  const Vector turned = model->linear_flow(1.3, w);
  CHECK(turned(4) == w(4));
  const tsi::Model& own_model = own;  // Model's one-state overloads (hidden in the subclass)
  CHECK((turned.head(4) - own_model.linear_flow(1.3, Vector(w.head(4)))).norm() < 1e-15);
  // D(f, 1)(u, s)(z, z_s) = (B z + z_s a, 0): the model's own derivative in u, tsi's in t.
  Vector z(5);
  z << 0.7, 0.4, -0.9, 0.2, -1.5;
  tsi::Matrix dfield(5, 1);
  model->nonlinear_field_derivative(tsi::Matrix(w), tsi::Matrix(z), dfield);
  const Vector expected = own.B_ * z.head(4) - 1.5 * own.a_;
  const double error = (dfield.col(0).head(4) - expected).norm() / expected.norm();
  MESSAGE("derivative with a t component: relative error " << error);
  CHECK(error < 1e-9);
  CHECK(dfield(4, 0) == 0.0);
  // Evaluated as an autonomous field, the model refuses: its f needs t.
  CHECK_THROWS_WITH_AS(own_model.nonlinear_field(Vector(w.head(4))), doctest::Contains("time_dependent_field()"),
                       tsi::Error);
}

TEST_CASE("time-dependent f: a capability that takes no t beside it is refused, naming it") {
  CHECK_THROWS_WITH_AS(tsi::with_time_as_variable(std::make_unique<WithHamiltonian>(0.1)),
                       doctest::Contains("declares hamiltonian() too, which takes no t"), tsi::Error);
}

TEST_CASE("time-dependent f: a C++ model gives the matrix model's numbers with its \"linear\" field") {
  const Json se1 = {{"name", "se1"}}, eab = {{"name", "eab"}, {"order", 4}};
  for (const double eps : {0.015, 1.5e-4}) {
    for (const Json& scheme : {se1, eab}) {
      const Vector cpp = solve({{"name", "cpp-linear"}, {"eps", eps}}, scheme, 1.0 / 16);
      const Vector matrix = solve({{"name", "matrix"}, {"eps", eps}, {"f", "linear"}}, scheme, 1.0 / 16);
      const double difference = (cpp - matrix).norm() / matrix.norm();
      MESSAGE(scheme.dump() << " eps = " << eps << ": C++ model vs matrix model " << difference);
      CHECK(difference < 1e-14);
    }
  }
}

TEST_CASE("time-dependent f: SE1 and eab reach their orders against the exact solution at two eps") {
  // SE1 is fitted where it is in its asymptotic range (as the matrix model's test does): at
  // eps = 0.015 its error is nearly flat from h = 1/4 to 1/16, at eps = 1.5e-4 it settles from
  // h = 1/8 and levels off below 1e-6 after h = 1/64.
  struct Case {
    double eps;
    Json scheme;
    double order, tolerance;
    std::vector<double> steps;
  };
  const Json se1 = {{"name", "se1"}}, eab = {{"name", "eab"}, {"order", 4}};
  const std::vector<double> coarse = {1.0 / 4, 1.0 / 8, 1.0 / 16, 1.0 / 32};
  const Case cases[] = {{0.015, se1, 2.0, 0.15, {1.0 / 32, 1.0 / 64, 1.0 / 128, 1.0 / 256}},
                        {0.015, eab, 4.0, 0.3, coarse},
                        {1.5e-4, se1, 2.0, 0.15, {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64}},
                        {1.5e-4, eab, 4.0, 0.3, coarse}};
  for (const Case& c : cases) {
    const Vector exact = linear_exact(c.eps, 1.0);
    std::vector<double> errors;
    for (const double h : c.steps)
      errors.push_back((solve({{"name", "cpp-linear"}, {"eps", c.eps}}, c.scheme, h) - exact).norm() / exact.norm());
    const double order = slope(c.steps, errors);
    std::string shown;
    for (const double e : errors) shown += fmt::format(" {:.3e}", e);
    MESSAGE(c.scheme.dump() << " eps = " << c.eps << ": errors" << shown << ", order " << order);
    CHECK(std::fabs(order - c.order) <= c.tolerance);
  }
}

TEST_CASE("time-dependent f: the filtered and direct problems carry t too (rk78 against the exact solution)") {
  // The direct problem is stiff at 1/eps: rk78 resolves the fast period there, at eps = 0.015 only.
  const Json rk78 = {{"name", "rk78"}, {"tol", 1e-13}};
  struct Case {
    const char* reformulation;
    double eps;
  };
  for (const Case c : {Case{"filtered", 0.015}, Case{"filtered", 1.5e-4}, Case{"direct", 0.015}}) {
    const Vector exact = linear_exact(c.eps, 1.0);
    const Vector u = solve({{"name", "cpp-linear"}, {"eps", c.eps}}, rk78, 1.0, 1.0, {{"name", c.reformulation}});
    const double error = (u - exact).norm() / exact.norm();
    MESSAGE("rk78 on the " << std::string(c.reformulation) << " problem, eps = " << c.eps << ": error " << error);
    CHECK(error < 1e-9);
  }
}
