// The trigonometric (Gautschi-type) integrators on FPUT (SPEC.md section 8): every filter against
// the reference data of tests/data/rivals/ (the public package resting-dove/gautschiIntegrators
// for the garcia-archilla and hairer-lubich rows, an independent numpy implementation of SPEC's
// one-step form for all five, both run outside the project), second order against rk78, and the
// long-time energies away from and at the step-size resonances h omega = pi, 2 pi.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "harness.hpp"
#include "tsi/convergence.hpp"
#include "tsi/error.hpp"

namespace {

using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

const Json& reference_data() {
  static const Json data = [] {
    std::ifstream in(std::string(TSI_TEST_SOURCE_DIR) + "/tests/data/rivals/gautschi-fput-reference.json");
    REQUIRE(in);
    return Json::parse(in);
  }();
  return data;
}

Json fput_trig(const std::string& filter) {
  return {{"model", {{"name", "fput"}, {"eps", 1.0 / 50}}},
          {"reformulation", {{"name", "direct"}}},
          {"scheme", {{"name", "trigonometric"}, {"filter", filter}}}};
}

// (x, x') of SPEC's variables after n steps of h from SPEC's data, and H, I along the way.
struct Run {
  Vector state;  // physical: x_1..x_6, y_1..y_6
  double max_dH = 0, max_dI = 0, max_dH_first_half = 0;
  long evaluations = 0;
};

Run trig_run(const std::string& filter, double h, long n, bool energies = false) {
  tsi::Assembly a = Harness::instance().assemble(fput_trig(filter));
  Vector y = a.reformulation->prepare(a.u0);
  const double H0 = a.model->energy(a.u0), I0 = a.model->oscillatory_energy(a.u0);
  Run r;
  tsi::StepObserver observer;
  if (energies)
    observer = [&](long k, tsi::Real t, const Vector& state) {
      const Vector u = a.reformulation->read_back(state, t);
      const double dH = std::abs(a.model->energy(u) - H0), dI = std::abs(a.model->oscillatory_energy(u) - I0);
      r.max_dH = std::max(r.max_dH, dH);
      r.max_dI = std::max(r.max_dI, dI);
      if (2 * k <= n) r.max_dH_first_half = std::max(r.max_dH_first_half, dH);
      return true;
    };
  const long before = a.reformulation->evaluations();
  tsi::integrate(a.bind(h), y, n, observer);
  r.evaluations = a.reformulation->evaluations() - before;
  r.state = a.model->to_physical(a.reformulation->read_back(y, tsi::step_time(n, h)));
  return r;
}

double max_difference(const Vector& state, const Json& expected) {
  double d = 0;
  for (int i = 0; i < 6; ++i) {
    d = std::max(d, std::abs(state(i).real() - expected["x"][i].get<double>()));
    d = std::max(d, std::abs(state(6 + i).real() - expected["v"][i].get<double>()));
  }
  return d;
}

}  // namespace

TEST_CASE("trigonometric on fput: every filter gives the reference data's states after 1 and 1000 steps") {
  const Json& data = reference_data();
  REQUIRE(std::abs(data["_meta"]["H0"].get<double>() - 2.00120008) < 1e-15);
  // The package's methods and the independent implementation of each row (SPEC.md's filters).
  struct Row {
    const char* filter;
    const char* key;
  };
  const std::vector<Row> rows = {{"hairer-lubich", "OneStepF"},        {"garcia-archilla", "OneStepGS99"},
                                 {"gautschi", "A_gautschi1961"},       {"deuflhard", "B_deuflhard1979"},
                                 {"garcia-archilla", "C_gss1999"},     {"hochbruck-lubich", "D_hochbrucklubich1999"},
                                 {"hairer-lubich", "E_hairerlubich2000"}};
  // The FPUT trajectory is chaotic: a change of 1e-15 at t = 0 is 3e-14 at t = 30 and about 1e-10 at
  // t = 100 (tests/data/rivals/gautschi.md, section 4). The bounds: rounding after one step, that
  // growth with a margin of 30 after 1000 (t = 30, 63, 100, 126).
  const std::vector<std::pair<std::string, double>> steps_1000 = {
      {"0.03", 1e-12}, {"pi/omega", 1e-10}, {"0.1", 3e-9}, {"2pi/omega", 3e-8}};
  for (const Row& row : rows)
    for (const auto& [h_name, bound] : steps_1000) {
      const double h = std::stod(data["_meta"]["h"][h_name].get<std::string>());
      const Json& expected = data[row.key][h_name];
      CAPTURE(row.key);
      CAPTURE(h_name);
      if (expected["1"]["H"].is_null() || expected["1"]["H"].get<double>() > 1e10) {
        // Gautschi and Hochbruck-Lubich at h omega = pi: psi_1 = tan(xi/2)/(xi/2) is infinite,
        // the reference's state is 1e26 or NaN; tsi refuses the step size.
        CHECK_THROWS_WITH_AS(trig_run(row.filter, h, 1), doctest::Contains("time.h: got h = 0.06283185307179587, where h omega = 3.1415926535897936 is an odd multiple of pi (omega = 50)"),
                             tsi::ConfigError);
        continue;
      }
      const double one = max_difference(trig_run(row.filter, h, 1).state, expected["1"]);
      CHECK(one <= 1e-14);
      if (expected["1000"]["H"].get<double>() > 10) continue;  // an unstable row (below): the growth itself
      const Run r = trig_run(row.filter, h, 1000);
      const double thousand = max_difference(r.state, expected["1000"]);
      MESSAGE(fmt::format("{} h = {}: {:.1e} after 1 step, {:.1e} after 1000", row.key, h_name, one, thousand));
      CHECK(thousand <= bound);
      CHECK(r.evaluations == 1001);  // one force a step, and the first step's own
    }
}

TEST_CASE("trigonometric on fput: second order for every filter at omega = 50, against rk78") {
  const double t_end = 1.0;
  auto model = Harness::instance().model_with("fput", 1.0 / 50, Json::object());
  auto direct = Harness::instance().reformulation("direct", model);
  auto rk78 = Harness::instance().scheme("rk78", {{"tol", 1e-14}});
  const Vector reference = tsi::test::solve(*model, *direct, *rk78, t_end, 1);
  for (const std::string filter : {"gautschi", "deuflhard", "garcia-archilla", "hochbruck-lubich", "hairer-lubich"}) {
    std::vector<double> hs, errors;
    // h omega = 0.31 .. 0.04, where the errors are in their asymptotic regime (from h omega = 1.25
    // down the slopes of the five filters ranged from 1.89 to 2.52)
    for (const long n : {160, 320, 640, 1280}) {
      const Run r = trig_run(filter, t_end / static_cast<double>(n), n);
      hs.push_back(t_end / static_cast<double>(n));
      errors.push_back((r.state - reference).norm() / reference.norm());
    }
    const tsi::OrderFit fit = tsi::fit_order(hs, errors, 1e-12);
    REQUIRE(fit.measurable);
    const double order = fit.order;
    MESSAGE(fmt::format("{}: errors {:.2e} .. {:.2e}, order {:.2f}", filter, errors.front(), errors.back(), order));
    CHECK(order > 1.9);
    CHECK(order < 2.1);
  }
}

TEST_CASE("trigonometric on fput over T = 1000: H near-conserved without drift away from resonances, the stiff "
          "energies frozen at h omega = 2 pi, Deuflhard's filter unstable there") {
  // h omega = 1.5: every filter keeps |H - H(0)| at a few 1e-2 (the reference: 2.9e-3 .. 3.5e-2),
  // no larger over [500, 1000] than twice its largest over [0, 500]; I moves by the exact flow's
  // own O(1/omega) oscillation (6.5e-2 .. 8.6e-2 for the exact flow).
  for (const std::string filter : {"gautschi", "deuflhard", "garcia-archilla", "hochbruck-lubich", "hairer-lubich"}) {
    const Run r = trig_run(filter, 0.03, 33333, true);
    MESSAGE(fmt::format("{} at h = 0.03: max |H - H0| = {:.2e}, max |I - I0| = {:.2e}", filter, r.max_dH, r.max_dI));
    CHECK(r.max_dH < 0.1);
    CHECK(r.max_dH <= 2 * r.max_dH_first_half);
    CHECK(r.max_dI < 0.15);
  }
  // h omega = 2 pi: cos = 1 and psi vanishes on the stiff block, which stands still: each I_j
  // (and I) is kept to rounding and the exchange I_1 -> I_2 -> I_3 is lost; Deuflhard's psi_1 = 1
  // feeds the stiff block and I grows without bound (the resonance instability of GNI XIII).
  const double h = 2 * M_PI / 50;
  for (const std::string filter : {"gautschi", "garcia-archilla", "hochbruck-lubich", "hairer-lubich"}) {
    const Run r = trig_run(filter, h, 7958, true);
    CHECK(r.max_dI < 1e-10);
    CHECK(r.max_dH < 0.1);
  }
  const Run deuflhard = trig_run("deuflhard", h, 7958, true);
  MESSAGE(fmt::format("deuflhard at h omega = 2 pi: max |I - I0| = {:.2e}", deuflhard.max_dI));
  CHECK(deuflhard.max_dI > 10);
}

TEST_CASE("trigonometric on henon-heiles: second order at eps = 1, not uniformly accurate as eps -> 0") {
  // The second-order form of the paper's Henon-Heiles has the fast velocity p1/eps: the energy of
  // x'' = -Omega^2 x + g(x) is unbounded as eps -> 0, outside the trigonometric integrators'
  // bounded-energy theory. Their error at a fixed h then grows as eps falls; a two-scale scheme's
  // does not (the finding the side-by-side studies show).
  const double t_end = 1.0;
  std::vector<double> errors_at_h64;
  for (const double eps : {1.0, 1.0 / 16, 1.0 / 256}) {
    auto model = Harness::instance().model("henon-heiles", eps);
    auto direct = Harness::instance().reformulation("direct", model);
    auto rk78 = Harness::instance().scheme("rk78", {{"tol", 1e-14}});
    const Vector reference = tsi::test::solve(*model, *direct, *rk78, t_end, 1);
    auto trig = Harness::instance().scheme("trigonometric", {{"filter", "hairer-lubich"}});
    std::vector<double> hs, errors;
    for (const long n : {32, 64, 128, 256}) {
      const Vector u = tsi::test::solve(*model, *direct, *trig, t_end, n);
      hs.push_back(t_end / static_cast<double>(n));
      errors.push_back((u - reference).norm() / reference.norm());
      if (n == 64) errors_at_h64.push_back(errors.back());
    }
    const tsi::OrderFit fit = tsi::fit_order(hs, errors, 1e-12);
    MESSAGE(fmt::format("eps = {}: errors {:.2e} .. {:.2e}, order {:.2f}", eps, errors.front(), errors.back(),
                        fit.order));
    if (eps == 1.0) {
      REQUIRE(fit.measurable);
      CHECK(fit.order > 1.9);
      CHECK(fit.order < 2.1);
    }
  }
  MESSAGE(fmt::format("h = 1/64: errors {:.2e}, {:.2e}, {:.2e} at eps = 1, 1/16, 1/256", errors_at_h64[0],
                      errors_at_h64[1], errors_at_h64[2]));
  CHECK(errors_at_h64[1] > 2 * errors_at_h64[0]);
  CHECK(errors_at_h64[2] > 2 * errors_at_h64[1]);
}

TEST_CASE("klein-gordon's second-order form in 1-D to 3-D, real and complex z: the model's own equation, read as "
          "q'' = -Omega^2 q + g") {
  // The form's x, x' and x'' against central differences of the direct problem's flow
  // (its rhs, independent of the form): x' = v and v' = -Omega^2 x + g(x) along u' = F(u).
  const std::vector<std::pair<std::string, Json>> cases = {
      {"klein-gordon", {{"n_x", 16}}},
      {"klein-gordon", {{"dims", 2}, {"n_x", 8}}},
      {"klein-gordon", {{"dims", 3}, {"n_x", 4}}},
      {"klein-gordon-complex", {{"n_x", 16}}},
      {"klein-gordon-complex", {{"dims", 2}, {"n_x", 8}}}};
  for (const auto& c : cases) {
    const Json& params = c.second;
    auto model = Harness::instance().model_with(c.first, 0.25, params);
    const tsi::SecondOrderForm* form = model->second_order_form();
    REQUIRE(form);
    auto direct = Harness::instance().reformulation("direct", model);
    const Vector u = model->initial_value();
    Vector f(u.size());
    direct->rhs(0, u, f);
    tsi::RealVector x, v, x_plus, v_plus, x_minus, v_minus, g;
    form->to_second_order(u, x, v);
    const double delta = 1e-5;
    form->to_second_order(u + delta * f, x_plus, v_plus);
    form->to_second_order(u - delta * f, x_minus, v_minus);
    form->force(x, g);
    const tsi::RealVector omega = form->frequencies();
    const tsi::RealVector dx = (x_plus - x_minus) / (2 * delta), dv = (v_plus - v_minus) / (2 * delta);
    const tsi::RealVector acceleration = -omega.array().square().matrix().cwiseProduct(x) + g;
    CAPTURE(c.first);
    CAPTURE(params.dump());
    CHECK((dx - v).norm() <= 1e-8 * v.norm());
    CHECK((dv - acceleration).norm() <= 1e-8 * acceleration.norm());
    Vector back;
    form->from_second_order(x, v, back);
    CHECK((back - u).norm() <= 1e-14 * u.norm());
  }
}

TEST_CASE("trigonometric on klein-gordon: second order at eps = 1 and 1/16, not uniformly accurate as eps falls") {
  // Bao and Dong's exponential wave integrators are this family on Klein-Gordon; in the
  // non-relativistic limit they need h = O(eps): at a fixed h the error grows like 1/eps^2.
  auto error_at = [](double eps, long n) {
    auto model = Harness::instance().model_with("klein-gordon", eps, {{"n_x", 16}});
    auto direct = Harness::instance().reformulation("direct", model);
    const Vector x = tsi::test::solve(*model, *direct, *Harness::instance().scheme("trigonometric", Json::object()), 1.0, n);
    const Vector& reference = tsi::test::reference_solution("klein-gordon", eps, 1.0);
    return (x - reference).norm() / reference.norm();
  };
  for (const double eps : {1.0, 1.0 / 16}) {
    std::vector<double> hs, errors;
    for (const long n : {64, 128, 256}) {
      hs.push_back(1.0 / static_cast<double>(n));
      errors.push_back(error_at(eps, n));
    }
    const tsi::OrderFit fit = tsi::fit_order(hs, errors, 1e-12);
    REQUIRE(fit.measurable);
    MESSAGE(fmt::format("klein-gordon eps = {}: {:.2e} .. {:.2e}, order {:.2f}", eps, errors.front(), errors.back(),
                        fit.order));
    CHECK(fit.order > 1.95);
    CHECK(fit.order < 2.05);
  }
  const double e1 = error_at(1.0, 64), e16 = error_at(1.0 / 16, 64), e256 = error_at(1.0 / 256, 64);
  MESSAGE(fmt::format("klein-gordon at h = 1/64: {:.2e}, {:.2e}, {:.2e} at eps = 1, 1/16, 1/256", e1, e16, e256));
  CHECK(e16 > 30 * e1);
  CHECK(e256 > 30 * e16);
}
