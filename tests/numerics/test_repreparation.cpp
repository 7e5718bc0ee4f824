// Re-preparation of two-scale data (SPEC.md section 6): it leaves the solution unchanged, keeps
// uniform second order at T = 1, and restores near conservation where the tau
// characteristics come apart over long times.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "harness.hpp"
#include "tsi/convergence.hpp"

namespace {

using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

Json config(const std::string& model, const std::string& scheme, double eps, const Json& reprepare) {
  Json c = {{"model", {{"name", model}, {"eps", eps}}},
            {"reformulation", {{"name", "two-scale"}, {"reprepare", reprepare}}},
            {"scheme", {{"name", scheme}}}};
  for (const auto& p : Harness::instance().registry().scheme(scheme).info.params)
    if (p.name == "tol") c["scheme"]["tol"] = 1e-13;
  return c;
}

// Relative error at T = 1 against the rk78 reference.
double error_at_one(const std::string& model, const std::string& scheme, double eps, long steps,
                    const Json& reprepare) {
  auto a = Harness::instance().assemble(config(model, scheme, eps, reprepare));
  Vector y = a.reformulation->prepare(a.u0);
  const double h = 1.0 / static_cast<double>(steps);
  tsi::integrate(a.bind(h), y, steps, {}, a.reformulation->repreparation());
  const Vector x = a.model->to_physical(a.reformulation->read_back(y, tsi::step_time(steps, h)));
  const Vector& ref = tsi::test::reference_solution(model, eps, 1.0);
  return a.model->error_norm(x - ref) / a.model->error_norm(ref);
}

}  // namespace

TEST_CASE("re-preparation: U(t_n, s_n) = v_n exactly, so the solution read back does not change") {
  for (const char* model : {"henon-heiles", "nls", "cpd"})
    for (int order : {1, 2, 3}) {
      Json c = config(model, "se1", 0.05, 1);
      c["reformulation"]["initial_data_order"] = order;
      auto a = Harness::instance().assemble(c);
      Vector y = a.reformulation->prepare(a.u0);
      const double h = 0.3;
      a.bind(h).step(0.0, y);
      const Vector before = a.reformulation->read_back(y, h), stepped = y;
      CHECK(a.reformulation->repreparation()->after_step(1, h, y));
      const Vector after = a.reformulation->read_back(y, h);
      CAPTURE(model);
      CAPTURE(order);
      CHECK((after - before).norm() <= 1e-13 * before.norm());
      CHECK((y - stepped).norm() > 1e-12 * stepped.norm());  // U itself was rebuilt
      CHECK(a.reformulation->two_scale_diagnostics()->repreparation_times() == std::vector<double>{h});
    }
}

TEST_CASE("re-preparation: uniform second order at T = 1 is kept, every step and auto") {
  // Henon-Heiles, every two-scale scheme: the order over h = 1/4 .. 1/32 stays 2 and the
  // error stays within 5% of the plain run's (SPEC.md section 6).
  const std::vector<long> steps = {4, 8, 16, 32};
  std::vector<double> hs;
  for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
  for (const auto* scheme : tsi::test::second_order_schemes())
    for (double eps : {1.0, 1.0 / 256, 1.0 / 4096})
      for (const Json& rule : {Json(1), Json("auto")}) {
        std::vector<double> plain, reprepared;
        for (long n : steps) {
          plain.push_back(error_at_one("henon-heiles", scheme->info.name, eps, n, "never"));
          reprepared.push_back(error_at_one("henon-heiles", scheme->info.name, eps, n, rule));
        }
        const double order = tsi::least_squares_order(hs, reprepared);
        double worst = 0.0;
        for (size_t i = 0; i < steps.size(); ++i) worst = std::max(worst, reprepared[i] / plain[i]);
        CAPTURE(scheme->info.name);
        CAPTURE(eps);
        CAPTURE(rule.dump());
        CAPTURE(order);
        CAPTURE(worst);
        CHECK(std::abs(order - 2.0) <= 0.15);
        CHECK(worst <= 1.05);
      }
}

TEST_CASE("re-preparation: NLS at eps = 0.1 keeps its mass over T = 200 where the plain run loses it") {
  // h = 1/8, SE1 (SPEC.md section 6; an independent implementation: never 1.0, every 80 steps 1.4e-4).
  auto max_mass_error = [](const Json& rule) {
    auto a = Harness::instance().assemble(config("nls", "se1", 0.1, rule));
    Vector y = a.reformulation->prepare(a.u0);
    const double m0 = a.model->mass(a.u0);
    double worst = 0.0;
    tsi::integrate(a.bind(0.125), y, 1600, [&](long, double t, const Vector& state) {
      worst = std::max(worst, std::abs(a.model->mass(a.reformulation->read_back(state, t)) - m0) / m0);
      return true;
    }, a.reformulation->repreparation());
    return worst;
  };
  const double never = max_mass_error("never"), every = max_mass_error(80), automatic = max_mass_error("auto");
  CAPTURE(never);
  CAPTURE(every);
  CAPTURE(automatic);
  CHECK(never > 0.5);       // measured 0.79 (tol 1e-13)
  CHECK(every < 1e-3);      // measured 1.8e-4
  CHECK(automatic < 1e-3);  // measured 1.9e-4
}

TEST_CASE("re-preparation: auto brings the charged particle at eps = 1 below 1e-3 and leaves NLS at eps = 0.01 alone") {
  // The largest relative change of H over T = 200, plain and auto (with auto's default data of
  // order 4), through the same assembler as tsi run.
  auto max_energy_error = [](const std::string& model, const std::string& scheme, double eps, double h,
                             const Json& rule, long* repreparations) {
    auto a = Harness::instance().assemble(config(model, scheme, eps, rule));
    Vector y = a.reformulation->prepare(a.u0);
    const double e0 = a.model->energy(a.u0);
    double worst = 0.0;
    const long steps = std::lround(200.0 / h);
    tsi::integrate(a.bind(h), y, steps, [&](long, double t, const Vector& state) {
      worst = std::max(worst, std::abs(a.model->energy(a.reformulation->read_back(state, t)) - e0) / std::abs(e0));
      return std::isfinite(worst) && worst < 10.0;
    }, a.reformulation->repreparation());
    *repreparations = static_cast<long>(a.reformulation->two_scale_diagnostics()->repreparation_times().size());
    return worst;
  };
  long count = 0;
  for (const char* scheme : {"se1", "se2"}) {
    CAPTURE(std::string(scheme));
    const double never = max_energy_error("cpd", scheme, 1.0, 0.2, "never", &count);
    const double automatic = max_energy_error("cpd", scheme, 1.0, 0.2, "auto", &count);
    CAPTURE(never);
    CAPTURE(automatic);
    CHECK(never > 0.1);        // measured 0.42 (SE1), SE2 blows up at t = 128
    CHECK(automatic < 1e-3);   // measured 6.4e-4, 7.7e-4
    CHECK(count > 10);         // measured 94, 95
  }
  // NLS at eps = 0.01: U's distance from its prepared data is the scheme's own O(h^2) error;
  // the floor keeps auto from acting on it (without: 9x the plain err_H).
  const double never = max_energy_error("nls", "se1", 0.01, 0.125, "never", &count);
  const double automatic = max_energy_error("nls", "se1", 0.01, 0.125, "auto", &count);
  CAPTURE(never);
  CAPTURE(automatic);
  CHECK(count == 0);
  CHECK(automatic <= 1.5 * never);
}

TEST_CASE("re-preparation: every model keeps its order at T = 1 in its declared regime, every step and auto") {
  // Second order is kept everywhere. The error may grow by a bounded factor: each re-preparation
  // restarts the scheme (ME then takes its start-up step every step: 1.85 times the plain error
  // on NLS at eps = 1, the largest measured) and leaves the O(eps^p) defect of the prepared data.
  for (const std::string model : {"nls", "cpd", "klein-gordon"}) {
    const auto& regime = Harness::instance().registry().model(model).verification;
    std::vector<double> hs;
    for (long n : regime.steps) hs.push_back(1.0 / static_cast<double>(n));
    for (const auto* scheme : tsi::test::second_order_schemes())
      for (const double eps : regime.epsilons)
        for (const Json& rule : {Json(1), Json("auto")}) {
          std::vector<double> plain, reprepared;
          for (long n : regime.steps) {
            plain.push_back(error_at_one(model, scheme->info.name, eps, n, "never"));
            reprepared.push_back(error_at_one(model, scheme->info.name, eps, n, rule));
          }
          const tsi::OrderFit fit = tsi::fit_order(hs, reprepared, 1e-7);
          double worst = 0.0;
          for (size_t i = 0; i < hs.size(); ++i) worst = std::max(worst, reprepared[i] / plain[i]);
          CAPTURE(model);
          CAPTURE(scheme->info.name);
          CAPTURE(eps);
          CAPTURE(rule.dump());
          CAPTURE(fit.order);
          CAPTURE(worst);
          CHECK(fit.finite);
          // At least second order: `auto` decides per run, so at some h it re-prepares and at
          // others not, and the errors need not lie on one power law (FD at eps = 1 on the charged
          // particle and Klein-Gordon: fitted orders 2.5 and 2.6, errors 0.6 to 0.7 times the plain;
          // the lowest measured: 1.81, Klein-Gordon SE1 at eps = 1).
          if (fit.measurable) CHECK(fit.order >= 1.8);
          CHECK(worst <= 2.0);
        }
  }
}
