// Klein-Gordon with complex z (SPEC.md section 8): against the reference solutions that the
// authors of MicroMacro.jl publish with it (CosSin, N = 128, T = 0.25, eps = 1 .. 1e-6;
// tests/data/rivals/micromacro-cos-sin/, which an integrating-factor solve of our own,
// tests/data/rivals/kg_complex_if_solve.py, meets to 1.7e-14 .. 3.0e-14 at eps = 1, 0.1, 0.01),
// the real model as its special case z real, and the conservation of the energy and the charge.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "micromacro_reference.hpp"
#include "tsi/convergence.hpp"

namespace {

using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

}  // namespace

TEST_CASE("klein-gordon-complex: CosSin at T = 0.25 is MicroMacro.jl's reference solution for eps = 1 .. 1e-6") {
  // eab of order 4 on the two-scale problem at h = 1/256: uniformly accurate, so one step size serves
  // every eps; rk78 on the filtered problem (tol 1e-13) as a second route where its cost allows.
  const auto& cases = tsi::test::micromacro_cases();
  auto& harness = Harness::instance();
  for (const auto& c : cases) {
    const double eps = c.first;
    auto model = harness.model_with("klein-gordon-complex", eps, {{"n_x", 128}});
    const Vector reference = tsi::test::micromacro_reference(c.second);
    const double norm = model->error_norm(reference);
    auto two_scale = harness.reformulation("two-scale", model, {{"n_tau", 32}, {"initial_data_order", 6}});
    const Vector eab = tsi::test::solve(*model, *two_scale, *harness.scheme("eab", {{"order", 4}}), 0.25, 64);
    const double eab_error = model->error_norm(eab - reference) / norm;
    double rk78_error = -1;
    if (eps >= 1e-2) {
      auto filtered = harness.reformulation("filtered", model);
      const Vector rk78 = tsi::test::solve(*model, *filtered, *harness.scheme("rk78", {{"tol", 1e-13}}), 0.25, 1);
      rk78_error = model->error_norm(rk78 - reference) / norm;
      CHECK(rk78_error < 1e-11);  // measured 1.4e-14 .. 2.5e-12
    }
    MESSAGE(fmt::format("eps = {:g}: eab 4 at h = 1/256: {:.2e}; rk78: {}", eps, eab_error,
                        rk78_error < 0 ? std::string("not run") : fmt::format("{:.2e}", rk78_error)));
    CHECK(eab_error < 1e-8);  // measured 5.0e-10 .. 4.3e-9
  }
}

TEST_CASE("klein-gordon-complex: with z real it is the real model, and it keeps its energy and charge") {
  auto& harness = Harness::instance();
  const double eps = 0.1;
  // The real model's default data as (u, v) = (v_real, v_real): z = Re v_real, the same z_t.
  auto real = harness.model_with("klein-gordon", eps, {{"n_x", 16}});
  auto complex = harness.model_with("klein-gordon-complex", eps, {{"n_x", 16}});
  const Vector v_real = real->to_physical(real->initial_value());
  Vector uv(32);
  uv << v_real, v_real;
  auto real_filtered = harness.reformulation("filtered", real);
  auto complex_filtered = harness.reformulation("filtered", complex);
  const auto rk78 = harness.scheme("rk78", {{"tol", 1e-13}});
  // Both from their own u0 through the same reformulation and solver: compare at T = 1.
  Vector y_real = real_filtered->prepare(real->initial_value());
  tsi::integrate(*rk78->bind(*real_filtered, 1.0), y_real, 1, {});
  const Vector z_real = real->to_physical(real_filtered->read_back(y_real, 1.0));
  Vector y_complex = complex_filtered->prepare(complex->from_physical(uv));
  tsi::integrate(*rk78->bind(*complex_filtered, 1.0), y_complex, 1, {});
  const Vector c1 = complex_filtered->read_back(y_complex, 1.0);
  const Vector uv1 = complex->to_physical(c1);
  CHECK((uv1.head(16) - z_real).norm() <= 1e-11 * z_real.norm());
  CHECK((uv1.tail(16) - z_real).norm() <= 1e-11 * z_real.norm());
  // The CosSin data over T = 1: H (the physical energy, through the Hamiltonian structure). H is
  // int eps |z_t|^2 + |z_x|^2 + |z|^2 / eps + lambda |z|^4 / 2 of z(0) = (1+i) cos x,
  // eps z_t(0) = (1-i) sin x: 2 pi / eps + 2 pi + 2 pi / eps + 3 pi / 2 (|z|^2 = 2 cos^2 x).
  auto cos_sin = harness.model_with("klein-gordon-complex", eps, {{"n_x", 32}});
  auto filtered = harness.reformulation("filtered", cos_sin);
  const Vector c0 = cos_sin->initial_value();
  const double H0 = cos_sin->energy(c0), expected = 4 * M_PI / eps + 2 * M_PI + 1.5 * M_PI;
  CHECK(std::abs(H0 - expected) <= 1e-12 * expected);
  Vector y = filtered->prepare(c0);
  tsi::integrate(*rk78->bind(*filtered, 1.0), y, 1, {});
  CHECK(std::abs(cos_sin->energy(filtered->read_back(y, 1.0)) - H0) <= 1e-10 * H0);
  // CosSin and Faou-Schratz carry no charge (conj(z) eps z_t integrates to a real number): the
  // charge is checked on u = 0.8 e^{ix} + 0.3, v = 0.5 e^{2ix}, which carries some.
  Vector charged(64);
  for (int j = 0; j < 32; ++j) {
    const double x = 2 * M_PI * j / 32;
    charged(j) = 0.8 * std::polar(1.0, x) + 0.3;
    charged(32 + j) = 0.5 * std::polar(1.0, 2 * x);
  }
  const Vector q0 = cos_sin->from_physical(charged);
  const auto charge = cos_sin->invariants().at(0).value;
  const double Q0 = charge(q0), E0 = cos_sin->energy(q0);
  Vector yq = filtered->prepare(q0);
  tsi::integrate(*rk78->bind(*filtered, 1.0), yq, 1, {});
  const Vector q1 = filtered->read_back(yq, 1.0);
  MESSAGE(fmt::format("charged data, eps = 0.1: H = {:.12g} -> {:.12g}, Q = {:.12g} -> {:.12g}", E0,
                      cos_sin->energy(q1), Q0, charge(q1)));
  CHECK(std::abs(Q0) > 0.1);
  CHECK(std::abs(charge(q1) - Q0) <= 1e-10 * std::abs(Q0));
  CHECK(std::abs(cos_sin->energy(q1) - E0) <= 1e-10 * E0);
}

TEST_CASE("klein-gordon-complex: Bao and Dong's data on a box of length 16 are our integrating-factor solve's") {
  // z = sech(x^2) centred in [0, 16), eps z_t = 0, lambda = 4 (MicroMacro.jl's data set 1), N = 128,
  // T = 0.25: rk78 on the filtered problem against tests/data/rivals/kg_complex_if_solve.py
  // --bao-dong (numpy, DOP853 at 1e-12; its own tol-1e-10 run differs by 5.7e-12 and 1.5e-11).
  // The box enters through the wave numbers 2 pi k / 16 and the volume 16 in every integral.
  auto& harness = Harness::instance();
  for (const auto& [eps, name] : std::vector<std::pair<double, std::string>>{{1.0, "1"}, {0.1, "0_1"}}) {
    auto model = harness.model_with("klein-gordon-complex", eps,
                                    {{"n_x", 128}, {"data", "bao-dong"}, {"length", 16.0}, {"lambda", 4.0}});
    const Vector reference = tsi::test::read_uv_file("kg-complex-bao-dong/eps_" + name + ".txt");
    auto filtered = harness.reformulation("filtered", model);
    const Vector u = tsi::test::solve(*model, *filtered, *harness.scheme("rk78", {{"tol", 1e-13}}), 0.25, 1);
    const double error = model->error_norm(u - reference) / model->error_norm(reference);
    MESSAGE(fmt::format("eps = {:g}: rk78 against the integrating-factor solve {:.2e}", eps, error));
    CHECK(error < 1e-10);  // measured 1.2e-12 at eps = 0.1
    // The energy is kept (the box's volume in H): rk78 at tol 1e-13.
    const double h0 = model->energy(model->initial_value());
    CHECK(std::abs(model->energy(model->from_physical(u)) - h0) < 1e-9 * std::abs(h0));
  }
}
