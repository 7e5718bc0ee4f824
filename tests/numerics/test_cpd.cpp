// The charged-particle model (SPEC.md section 4, eq. CPD, eq. model CPD F): canonical
// variables inside and physical (x, v) outside, its linear flow e^{JM tau}, the reference
// against an independent integration of the physical equations, second order of the
// two-scale schemes at eps = 1 and errors that shrink with eps (SPEC.md section 5.1), and
// bounded energy error for SE1 over long times while ME blows up (section 5.3).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>

#include "harness.hpp"
#include "runner/run_command.hpp"
#include "tsi/convergence.hpp"

namespace {

using tsi::Vector;
using tsi::test::Harness;

// The physical right-hand side: x' = v, v' = (1/eps) B v - grad U(x), U = 1/|x|, B v = (v2, -v1).
Vector physical_rhs(const Vector& s, double eps) {
  const double x1 = s(0).real(), x2 = s(1).real(), v1 = s(2).real(), v2 = s(3).real();
  const double r3 = std::pow(x1 * x1 + x2 * x2, 1.5);
  Vector out(4);
  out << v1, v2, v2 / eps + x1 / r3, -v1 / eps + x2 / r3;
  return out;
}

// Classical RK4 on the physical equations (independent of the model and its variables).
Vector physical_rk4(double eps, double t_end, long n) {
  Vector s(4);
  s << 0.8, 0.9, 0.5, 0.6;
  const double h = t_end / static_cast<double>(n);
  for (long k = 0; k < n; ++k) {
    const Vector k1 = physical_rhs(s, eps), k2 = physical_rhs(s + 0.5 * h * k1, eps),
                 k3 = physical_rhs(s + 0.5 * h * k2, eps), k4 = physical_rhs(s + h * k3, eps);
    s += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return s;
}

// The physical equations in the frame turning with the gyration, w = e^{-B t/eps} v:
// x' = e^{B t/eps} w, w' = e^{-B t/eps} x / |x|^3, in long double (64-bit mantissa),
// with Odeint's rk78 over windows of an eighth of the fast period. Nothing here shares code
// or variables with the model: the check of the reference at small eps.
Vector rotating_frame_long_double(double eps_in, double t_end) {
  using Real = long double;
  using State = std::array<Real, 4>;
  namespace odeint = boost::numeric::odeint;
  const Real eps = eps_in, two_pi = 6.283185307179586476925286766559L;
  const auto rhs = [&](const State& s, State& d, Real t) {
    const Real c = std::cos(t / eps), sn = std::sin(t / eps);  // e^{B theta} = [[c, s], [-s, c]]
    const Real r2 = s[0] * s[0] + s[1] * s[1], k = 1 / (r2 * std::sqrt(r2));
    d[0] = c * s[2] + sn * s[3];
    d[1] = -sn * s[2] + c * s[3];
    d[2] = k * (c * s[0] - sn * s[1]);
    d[3] = k * (sn * s[0] + c * s[1]);
  };
  State s{0.8L, 0.9L, 0.5L, 0.6L};
  const long windows = static_cast<long>(std::ceil(t_end / (two_pi * eps / 8)));
  const Real dt = t_end / static_cast<Real>(windows);
  odeint::runge_kutta_fehlberg78<State, Real> stepper;
  for (long i = 0; i < windows; ++i)
    odeint::integrate_adaptive(odeint::make_controlled<decltype(stepper)>(1e-18L, 1e-18L), rhs, s,
                               static_cast<Real>(i) * dt, static_cast<Real>(i + 1) * dt, dt);
  const Real c = std::cos(t_end / eps), sn = std::sin(t_end / eps);
  Vector x(4);
  x << static_cast<double>(s[0]), static_cast<double>(s[1]), static_cast<double>(c * s[2] + sn * s[3]),
      static_cast<double>(-sn * s[2] + c * s[3]);
  return x;
}

double relative(const Vector& x, const Vector& ref) { return (x - ref).norm() / ref.norm(); }

// FD's third-order data is rougher in tau: N_tau = 128 for it (SPEC.md section 4).
int n_tau_for(const tsi::SchemeEntry& scheme) { return tsi::default_traits(scheme).initial_data_order >= 3 ? 128 : 64; }

double cpd_error(const tsi::SchemeEntry& scheme, double eps, long steps) {
  auto& h = Harness::instance();
  auto model = h.model("cpd", eps);
  auto two_scale = h.reformulation(
      "two-scale", model,
      {{"n_tau", n_tau_for(scheme)}, {"initial_data_order", std::max(1, tsi::default_traits(scheme).initial_data_order)}});
  tsi::Json params = tsi::Json::object();
  for (const auto& p : scheme.info.params)
    if (p.name == "tol") params["tol"] = 1e-12;
  auto stepper = h.scheme(scheme.info.name, params, "cpd");
  return relative(tsi::test::solve(*model, *two_scale, *stepper, 1.0, steps),
                  tsi::test::reference_solution("cpd", eps, 1.0));
}

}  // namespace

TEST_CASE("cpd: canonical variables inside, physical (x, v) outside, SPEC's invariants") {
  auto& h = Harness::instance();
  for (double eps : {1.0, 0.1, 1e-3}) {
    auto model = h.model("cpd", eps);
    CAPTURE(eps);
    REQUIRE(model->dim() == 4);
    CHECK_FALSE(model->is_complex());
    Vector x0(4);
    x0 << 0.8, 0.9, 0.5, 0.6;
    const Vector u0 = model->initial_value();
    // q = x, p = 2 eps v - B x.
    CHECK(std::abs(u0(0) - 0.8) < 1e-15);
    CHECK(std::abs(u0(1) - 0.9) < 1e-15);
    CHECK(std::abs(u0(2) - (2.0 * eps * 0.5 - 0.9)) < 1e-15);
    CHECK(std::abs(u0(3) - (2.0 * eps * 0.6 + 0.8)) < 1e-15);
    // v = (p + B q) / (2 eps) cancels: the round trip loses a factor 1/eps.
    CHECK(relative(model->to_physical(u0), x0) < 1e-15 / eps);
    CHECK(relative(model->from_physical(x0), u0) < 1e-15);

    // H = I + 2 eps U(q) with I = eps |v|^2: H = 2 eps E, E = |v|^2/2 + U(x) the physical energy.
    // I sums O(1) terms to 4 eps^2 |v|^2: its rounding is relative 1e-16 / eps^2.
    const double tol = 1e-14 / (eps * eps);
    const double q1 = u0(0).real(), q2 = u0(1).real(), p1 = u0(2).real(), p2 = u0(3).real();
    const double I = (q1 * q1 + q2 * q2 + p1 * p1 + p2 * p2 + 2.0 * (p1 * q2 - p2 * q1)) / (4.0 * eps);
    const double energy = 0.5 * (0.5 * 0.5 + 0.6 * 0.6) + 1.0 / std::hypot(0.8, 0.9);
    CHECK(model->oscillatory_energy(u0) == doctest::Approx(I).epsilon(tol).scale(0.0));
    CHECK(model->oscillatory_energy(u0) ==
          doctest::Approx(eps * (0.5 * 0.5 + 0.6 * 0.6)).epsilon(tol).scale(0.0));
    CHECK(model->energy(u0) == doctest::Approx(2.0 * eps * energy).epsilon(tol).scale(0.0));
    CHECK(model->mass(u0) ==
          doctest::Approx(q1 * q1 + q2 * q2 + p1 * p1 + p2 * p2).epsilon(1e-15).scale(0.0));

    // The direct problem's right-hand side, read in physical variables, is the CPD system.
    auto direct = h.reformulation("direct", model);
    Vector rhs;
    direct->rhs(0.0, direct->prepare(u0), rhs);
    const Vector expected = physical_rhs(x0, eps);
    CHECK(relative(model->to_physical(direct->read_back(rhs, 0.0)), expected) < 1e-13);
  }
}

TEST_CASE("cpd: e^{JM tau} solves d/dtau = JM, is 2 pi periodic and keeps <Mu, u>") {
  auto& h = Harness::instance();
  auto model = h.model("cpd", 0.3);
  Vector u(4), mu(4), jmu(4);
  u << 0.8, -0.9, 1.3, 0.2;
  model->hamiltonian()->apply_M(u, mu);
  const double mu_u = tsi::inner(mu, u);
  for (double tau : {0.0, 0.4, 1.0, 2.5, 4.0, 6.0}) {
    CAPTURE(tau);
    const Vector flowed = model->linear_flow(tau, u);
    // Derivative: a fourth-order central difference against JM applied to the flowed state.
    const double d = 1e-3;
    const Vector derivative = (8.0 * (model->linear_flow(tau + d, u) - model->linear_flow(tau - d, u)) -
                               (model->linear_flow(tau + 2 * d, u) - model->linear_flow(tau - 2 * d, u))) /
                              (12.0 * d);
    model->hamiltonian()->apply_M(flowed, mu);
    model->hamiltonian()->apply_J(mu, jmu);
    CHECK(relative(derivative, jmu) < 1e-11);
    // Period 2 pi, a group, and <Mu, u> is kept (JM is skew with respect to M).
    CHECK(relative(model->linear_flow(tau + tsi::two_pi, u), flowed) < 1e-15);
    CHECK(relative(model->linear_flow(0.7, flowed), model->linear_flow(tau + 0.7, u)) < 1e-15);
    model->hamiltonian()->apply_M(flowed, mu);
    CHECK(tsi::inner(mu, flowed) == doctest::Approx(mu_u).epsilon(1e-14).scale(0.0));
  }
  // 2 pi is the period, not a multiple of a shorter one: JM has eigenvalues +-i.
  CHECK(relative(model->linear_flow(tsi::two_pi, u), u) < 1e-15);
  CHECK(relative(model->linear_flow(0.5 * tsi::two_pi, u), u) > 0.1);
}

TEST_CASE("cpd: field derivative and exact nonlinear flow") {
  auto& h = Harness::instance();
  auto model = h.model("cpd", 0.2);
  const Vector u0 = model->initial_value();
  Vector z(4);
  z << 0.3, -0.7, 0.1, 0.4;
  const double d = 1e-6;
  tsi::Matrix out(4, 1);
  model->nonlinear_field_derivative(tsi::Matrix(u0), tsi::Matrix(z), out);
  const Vector fd =
      (model->nonlinear_field(Vector(u0 + d * z)) - model->nonlinear_field(Vector(u0 - d * z))) / (2.0 * d);
  CHECK(relative(out.col(0), fd) < 1e-8);
  // J grad H1 = (0, -2 eps grad U(q)) = (0, 2 eps q / |q|^3).
  const Vector f = model->nonlinear_field(u0);
  const double r3 = std::pow(0.8 * 0.8 + 0.9 * 0.9, 1.5);
  CHECK(std::abs(f(0)) == 0.0);
  CHECK(std::abs(f(1)) == 0.0);
  CHECK(std::abs(f(2) - 2.0 * 0.2 * 0.8 / r3) < 1e-15);
  CHECK(std::abs(f(3) - 2.0 * 0.2 * 0.9 / r3) < 1e-15);
  // Exact flow: q fixed, p moves along the field.
  REQUIRE(model->has_exact_nonlinear_flow());
  Vector u = u0;
  model->nonlinear_flow(0.5, u);
  CHECK(relative(u, Vector(u0 + 0.5 * f)) < 1e-15);
}

TEST_CASE("cpd: the rk78 reference agrees with RK4 on the physical equations") {
  for (double eps : {1.0, 1.0 / 16}) {
    const Vector& ref = tsi::test::reference_solution("cpd", eps, 1.0);
    CAPTURE(eps);
    CHECK(relative(physical_rk4(eps, 1.0, 20000), ref) < 1e-10);
  }
}

TEST_CASE("cpd: at eps = 1e-5 the reference agrees with a long-double integration in the turning frame") {
  // v = (p + B q) / (2 eps) turns each rounding of p into 1/eps of it in v: the reference's
  // 1.3e5 substeps must not round at ulp(p) each (before rk78 integrated deviations from
  // a compensated state, it was off by 8.1e-8 here and 2.2e-7 at eps = 1e-6).
  const double eps = 1e-5;
  const Vector& ref = tsi::test::reference_solution("cpd", eps, 1.0);
  const double error = relative(ref, rotating_frame_long_double(eps, 1.0));
  CAPTURE(error);
  CHECK(error < 1e-9);
  // The two-scale answer, from 8 steps, agrees too.
  auto& h = Harness::instance();
  auto model = h.model("cpd", eps);
  auto two_scale = h.reformulation("two-scale", model);
  auto se1 = h.scheme("se1", {{"tol", 1e-14}});
  const double se1_error = relative(tsi::test::solve(*model, *two_scale, *se1, 1.0, 8), rotating_frame_long_double(eps, 1.0));
  CAPTURE(se1_error);
  CHECK(se1_error < 1e-9);
}

TEST_CASE("cpd: second order at eps = 1 for every two-scale scheme") {
  std::vector<std::string> names;
  for (const auto* scheme : tsi::test::second_order_schemes()) {
    names.push_back(scheme->info.name);
    // The asymptotic range h = 1/16 .. 1/128. (From h = 1/4, FD and ME are still
    // pre-asymptotic at eps = 1: their successive orders rise 1.5, 1.8, 2.0 and
    // 1.2, 1.7, 1.8, 1.9; SE1 and SE2 have 2.00 from h = 1/4.)
    const std::vector<long> steps = {16, 32, 64, 128};
    std::vector<double> hs, errors;
    for (long n : steps) {
      hs.push_back(1.0 / static_cast<double>(n));
      errors.push_back(cpd_error(*scheme, 1.0, n));
    }
    const double order = tsi::least_squares_order(hs, errors);
    CAPTURE(scheme->info.name);
    CAPTURE(order);
    CHECK(std::abs(order - 2.0) <= 0.15);
  }
  for (const char* expected : {"fd", "me", "se1", "se2"})
    CHECK(std::find(names.begin(), names.end(), expected) != names.end());
}

TEST_CASE("cpd: at every h the error of every two-scale scheme falls as eps falls") {
  // The dynamics become trivial at leading order as eps -> 0 (SPEC.md section 5.1).
  for (const auto* scheme : tsi::test::second_order_schemes()) {
    for (long n : {4, 8, 16, 32}) {
      const double e1 = cpd_error(*scheme, 1.0, n), e16 = cpd_error(*scheme, 1.0 / 16, n),
                   e256 = cpd_error(*scheme, 1.0 / 256, n);
      CAPTURE(scheme->info.name);
      CAPTURE(n);
      CAPTURE(e1);
      CAPTURE(e16);
      CAPTURE(e256);
      CHECK(e16 < 0.5 * e1);
      CHECK(e256 < 0.5 * e16);
    }
  }
}

TEST_CASE("cpd: over T = 200 at eps = 0.5, SE1 keeps the energy error small while ME blows up") {
  // h = 1/5, N_tau = 64, the paper's long-time experiment (SPEC.md section 5.3).
  auto& h = Harness::instance();
  auto model = h.model("cpd", 0.5);
  const Vector u0 = model->initial_value();
  const double H0 = model->energy(u0);
  auto max_energy_error = [&](const std::string& name) {
    const auto& entry = h.registry().scheme(name);
    auto two_scale = h.reformulation(
        "two-scale", model, {{"n_tau", 64}, {"initial_data_order", tsi::default_traits(entry).initial_data_order}});
    auto stepper = h.scheme(name, tsi::Json::object(), "cpd");
    Vector y = two_scale->prepare(u0);
    double err_H = 0.0;
    tsi::integrate(*stepper->bind(*two_scale, 0.2), y, 1000, [&](long, double t, const Vector& state) {
      const double e = std::abs(model->energy(two_scale->read_back(state, t)) - H0) / std::abs(H0);
      err_H = std::isfinite(e) ? std::max(err_H, e) : HUGE_VAL;
      return std::isfinite(e);
    });
    return err_H;
  };
  const double se1 = max_energy_error("se1"), se2 = max_energy_error("se2"), me = max_energy_error("me");
  CAPTURE(se1);
  CAPTURE(se2);
  CAPTURE(me);
  CHECK(se1 < 2e-2);
  CHECK(se2 < 2e-2);
  CHECK(me > 1.0);
}

namespace {

// The magnetic moment from physical variables: the field strength is 1/eps, the gyration
// velocity w = v - v_E is measured from the E x B drift v_E = eps B g(x) (the v with
// (1/eps) B v + g = 0), g = -grad U, B a = (a2, -a1): mu = eps |w|^2 / 2.
double magnetic_moment(const Vector& x, double eps, bool coulomb) {
  const double x1 = x(0).real(), x2 = x(1).real(), v1 = x(2).real(), v2 = x(3).real();
  const double k = coulomb ? 1.0 / std::pow(x1 * x1 + x2 * x2, 1.5) : -1.0;  // g = k x
  const double w1 = v1 - eps * k * x2, w2 = v2 + eps * k * x1;
  return 0.5 * eps * (w1 * w1 + w2 * w2);
}

}  // namespace

TEST_CASE("cpd: the declared magnetic moment mu, adiabatic: O(eps^2) relative change over long SE1 runs") {
  auto& h = Harness::instance();
  for (const char* potential : {"coulomb", "harmonic"})
    for (double eps : {1.0, 0.1, 1e-3}) {
      auto model = h.model_with("cpd", eps, {{"potential", potential}});
      const auto invariants = model->invariants();
      REQUIRE(invariants.size() == 1);
      CHECK(invariants[0].name == "mu");
      CHECK(tsi::test::contains(invariants[0].description, "adiabatic"));
      Vector u = model->initial_value();
      u(2) += 0.3;  // away from the default data too
      CAPTURE(potential);
      CAPTURE(eps);
      // Both go through p + B q = 2 eps v: rounding of 1e-16 / eps relative.
      for (const Vector& state : {model->initial_value(), u})
        CHECK(invariants[0].value(state) ==
              doctest::Approx(magnetic_moment(model->to_physical(state), eps, potential == std::string("coulomb")))
                  .epsilon(1e-14 / eps));
    }

  // SE1 on the two-scale problem (N_tau = 64, h = 1/5) over T = 2000, the Coulomb field.
  // Measured: mu changes by 2.0e-4 at eps = 0.01 and 2.0e-6 at eps = 0.001 (2.0 eps^2, a
  // ratio of 101), without drift; the exact solution (rk78) changes it by 1.7 eps^2 over
  // t = 10. eps |v|^2 / 2 = I / 2, the moment without the drift, changes by 1.8 eps.
  struct Changes {
    double mu = 0.0, mu_first_half = 0.0, I = 0.0;
  };
  const auto se1_changes = [&](double eps) {
    auto model = h.model("cpd", eps);
    auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}, {"initial_data_order", 2}});
    auto se1 = h.scheme("se1");
    const auto mu = model->invariants()[0].value;
    const Vector u0 = model->initial_value();
    const double mu0 = mu(u0), I0 = model->oscillatory_energy(u0);
    Changes c;
    Vector y = two_scale->prepare(u0);
    tsi::integrate(*se1->bind(*two_scale, 0.2), y, 10000, [&](long n, double t, const Vector& state) {
      const Vector u = two_scale->read_back(state, t);
      c.mu = std::max(c.mu, std::abs(mu(u) - mu0) / mu0);
      c.I = std::max(c.I, std::abs(model->oscillatory_energy(u) - I0) / I0);
      if (n == 5000) c.mu_first_half = c.mu;
      return true;
    });
    return c;
  };
  const Changes coarse = se1_changes(0.01), fine = se1_changes(0.001);
  const double ratio = coarse.mu / fine.mu;
  CAPTURE(coarse.mu);
  CAPTURE(fine.mu);
  CAPTURE(ratio);
  CAPTURE(coarse.I);
  CAPTURE(fine.I);
  CHECK(coarse.mu < 3.0 * 0.01 * 0.01);  // C eps^2 with C = 3 (measured 2.0)
  CHECK(fine.mu < 3.0 * 0.001 * 0.001);
  CHECK(ratio > 50.0);  // eps ten times smaller: the change about a hundred times (101)
  CHECK(ratio < 200.0);
  CHECK(coarse.mu < 1.5 * coarse.mu_first_half);  // no drift over the second half
  CHECK(fine.mu < 1.5 * fine.mu_first_half);
  // The moment without the drift correction oscillates by O(eps): mu is the better invariant.
  CHECK(coarse.I > 1.0 * 0.01);
  CHECK(coarse.I < 3.0 * 0.01);
  CHECK(coarse.I > 30.0 * coarse.mu);
}

TEST_CASE("cpd: the example cpd-se1.json runs and meets its reference") {
  const tsi::test::TempDir dir("tsi-cpd-example");
  const auto r = tsi::test::run_tsi({"run", tsi::test::example_config("cpd-se1.json"), "--out", dir / "out"});
  REQUIRE_MESSAGE(r.exit_code == 0, r.describe());
  const auto result = tsi::test::read_json(dir.path() / "out" / "result.json");
  CHECK(result.at("status") == "completed");
  CHECK(result.at("config").at("model").at("name") == "cpd");
  CHECK(result.at("u_final").size() == 4);
  const double error = result.at("error").at("relative");
  CHECK(error > 1e-6);  // a real error of a second-order scheme at h = 1/8 ...
  CHECK(error < 1e-3);  // ... and a small one
}
