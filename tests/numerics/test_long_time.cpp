// Near conservation over long times (SPEC.md section 5.3): Henon-Heiles, eps = 0.01,
// h = 1/5, T = 200. The symmetric schemes keep err_H below 1e-3 with no drift (the
// least-squares slope of err_H over [20, 200], times the window, within the residual
// noise); the others drift, and their max err_H is at least 10 times larger.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "harness.hpp"
#include "tsi/convergence.hpp"

namespace {

using tsi::Vector;
using tsi::test::Harness;

struct EnergyRecord {
  std::vector<double> t, err_H;
};

EnergyRecord energy_error(const tsi::SchemeEntry& scheme) {
  auto& h = Harness::instance();
  auto model = h.model("henon-heiles", 0.01);
  auto two_scale = h.reformulation("two-scale", model,
                                   {{"n_tau", 64}, {"initial_data_order", std::max(1, tsi::default_traits(scheme).initial_data_order)}});
  auto stepper = h.scheme(scheme.info.name, tsi::Json::object(), "henon-heiles");
  REQUIRE(stepper);
  const Vector u0 = model->initial_value();
  const double H0 = model->energy(u0);
  Vector y = two_scale->prepare(u0);
  EnergyRecord record;
  tsi::integrate(*stepper->bind(*two_scale, 0.2), y, 1000, [&](long, double t, const Vector& state) {
    record.t.push_back(t);
    record.err_H.push_back(std::abs(model->energy(two_scale->read_back(state, t)) - H0) / std::abs(H0));
    return true;
  });
  return record;
}

struct Drift {
  double over_window;  // least-squares slope times the window length
  double noise;        // standard deviation of the residual about the line
};

Drift drift(const EnergyRecord& r, double from) {
  const tsi::DriftFit fit = tsi::drift_fit(r.t, r.err_H, from);
  return {fit.slope * (r.t.back() - from), fit.residual_rms};
}

}  // namespace

TEST_CASE("long time: symmetric schemes conserve energy without drift, the others drift") {
  double symmetric_max = 0.0;
  std::vector<std::pair<std::string, double>> others;
  // Every two-scale scheme with its defaults: the paper's four, the symmetric compositions and
  // collocation, and exponential Adams-Bashforth (which drifts). The 10x margin compares the
  // second-order schemes only.
  for (const auto* scheme : tsi::test::two_scale_schemes()) {
    const tsi::StepperTraits traits = tsi::default_traits(*scheme);
    const bool second_order = traits.order == 2 && traits.classical_order <= 2;
    const EnergyRecord record = energy_error(*scheme);
    const double max_err = *std::max_element(record.err_H.begin(), record.err_H.end());
    const Drift d = drift(record, 20.0);
    CAPTURE(scheme->info.name);
    CAPTURE(max_err);
    CAPTURE(d.over_window);
    CAPTURE(d.noise);
    REQUIRE(record.t.size() == 1001);
    if (tsi::default_traits(*scheme).symmetric) {
      CHECK(max_err < 1e-3);
      CHECK(std::abs(d.over_window) < d.noise);  // no drift beyond the oscillation
      if (second_order) symmetric_max = std::max(symmetric_max, max_err);
    } else {
      CHECK(d.over_window > 10.0 * d.noise);  // a drift well above the oscillation
      if (second_order) others.emplace_back(scheme->info.name, max_err);
    }
  }
  REQUIRE(symmetric_max > 0.0);
  REQUIRE_FALSE(others.empty());
  for (const auto& [name, max_err] : others) {
    CAPTURE(name);
    CHECK(max_err >= 10.0 * symmetric_max);
  }
}
