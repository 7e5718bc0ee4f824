// The recorder on a model whose answers are known: the harmonic oscillator u(t) = (cos(t/eps),
// -sin(t/eps)) with invariants of its own, one starting at 0 (absolute change), one not
// (relative change), and names it must refuse.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "fixtures/fixture_model.hpp"
#include "run_recorder.hpp"
#include "tsi/error.hpp"
#include "tsi/registry.hpp"

namespace {

using tsi::Json;
using tsi::ModelInvariant;
using tsi::Vector;

class DeclaringModel final : public tsi::fixture::HarmonicModel {
 public:
  DeclaringModel(double eps, std::vector<ModelInvariant> invariants)
      : HarmonicModel(eps), invariants_(std::move(invariants)) {}
  std::vector<ModelInvariant> invariants() const override { return invariants_; }

 private:
  std::vector<ModelInvariant> invariants_;
};

// u(t) = (cos t, -sin t) at eps = 1: "Q" = u_1^2 + 1 starts at 2 and changes by cos^2 t - 1;
// "z" = u_2 starts at 0 and changes by |sin t|.
std::vector<ModelInvariant> sample_invariants() {
  return {{"Q", "u_1^2 + 1", [](const Vector& u) { return std::norm(u(0)) + 1.0; }},
          {"z", "u_2", [](const Vector& u) { return u(1).real(); }}};
}

Json config(double h, double t_end) {
  return {{"output", {{"every", 1}}},
          {"monitor", {{"max_err_H", 1e10}, {"tau_roughness_warn", 1.0}, {"tau_spread_growth_warn", 1e10}}},
          {"time", {{"h", h}, {"t_end", t_end}}}};
}

struct Setup {
  std::shared_ptr<const tsi::Model> model;
  std::unique_ptr<tsi::Reformulation> direct;
  explicit Setup(std::vector<ModelInvariant> invariants)
      : model(std::make_shared<DeclaringModel>(1.0, std::move(invariants))) {
    tsi::Registry registry;
    tsi::register_core(registry);
    const auto& entry = registry.reformulation("direct");
    direct = entry.create(model, tsi::Params(tsi::resolve_params(entry.info.params, Json::object(), "r")));
  }
};

Vector exact(double t) {
  Vector u(2);
  u << std::cos(t), -std::sin(t);
  return u;
}

// The recorder's verdict after steps 0 .. 4 of h = 0.25 with an invariant that is 2 while
// |u_2| < 0.3 (t < 0.305) and `beyond` after: a declared invariant that stops being a number
// while the state stays finite (a particle energy sum w |v|^2 / 2 that overflows).
struct Outcome {
  long stopped_at = -1;
  std::string status, message;
  Json invariant;
};

Outcome record(double beyond) {
  Setup s({{"W", "2, then beyond", [beyond](const Vector& u) { return std::abs(u(1).real()) < 0.3 ? 2.0 : beyond; }}});
  tsi::app::RunRecorder recorder(*s.model, *s.direct, exact(0.0), config(0.25, 1.0));
  Outcome out;
  for (long n = 0; n <= 4 && out.stopped_at < 0; ++n)
    if (!recorder.observe(n, 0.25 * static_cast<double>(n), s.direct->prepare(exact(0.25 * static_cast<double>(n)))))
      out.stopped_at = n;
  out.status = recorder.status();
  out.message = recorder.message();
  out.invariant = recorder.invariants_json()["W"];
  return out;
}

}  // namespace

TEST_CASE("recorder: a declared invariant gets a value and a change column, relative or absolute") {
  Setup s(sample_invariants());
  tsi::app::RunRecorder recorder(*s.model, *s.direct, exact(0.0), config(0.5, 1.0));
  for (long n = 0; n <= 2; ++n) {
    const double t = 0.5 * static_cast<double>(n);
    REQUIRE(recorder.observe(n, t, s.direct->prepare(exact(t))));
  }
  const std::string csv = recorder.csv();
  CHECK(csv.substr(0, csv.find('\n')) == "t,H,I,m,err_H,err_I,err_m,tau_roughness,tau_spread,Q,err_Q,z,abs_err_z");

  const Json inv = recorder.invariants_json();
  CHECK(inv["Q"]["change"] == "relative");
  CHECK(inv["Q"]["column"] == "err_Q");
  CHECK(inv["Q"]["description"] == "u_1^2 + 1");
  CHECK(inv["Q"]["initial"].get<double>() == 2.0);
  CHECK(inv["Q"]["final"].get<double>() == doctest::Approx(std::pow(std::cos(1.0), 2) + 1.0).epsilon(1e-15));
  CHECK(inv["Q"]["max_change"].get<double>() == doctest::Approx(std::pow(std::sin(1.0), 2) / 2.0).epsilon(1e-14));
  CHECK(inv["z"]["change"] == "absolute");
  CHECK(inv["z"]["column"] == "abs_err_z");
  CHECK(inv["z"]["initial"].get<double>() == 0.0);
  CHECK(inv["z"]["max_change"].get<double>() == doctest::Approx(std::sin(1.0)).epsilon(1e-15));
  // H, I, m keep their entries.
  for (const char* name : {"H", "I", "m"}) CHECK(inv[name].contains("max_rel_error"));

  // The last row: t = 1, the values and their changes at the end of the columns.
  const std::string last = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
  std::vector<double> fields;
  for (size_t pos = 0; pos < last.size();) {
    const size_t comma = last.find(',', pos);
    fields.push_back(std::stod(last.substr(pos, comma - pos)));
    pos = comma == std::string::npos ? last.size() : comma + 1;
  }
  REQUIRE(fields.size() == 13);
  CHECK(fields[0] == 1.0);
  CHECK(fields[9] == doctest::Approx(std::pow(std::cos(1.0), 2) + 1.0).epsilon(1e-15));
  CHECK(fields[10] == doctest::Approx(std::pow(std::sin(1.0), 2) / 2.0).epsilon(1e-6));
  CHECK(fields[11] == doctest::Approx(-std::sin(1.0)).epsilon(1e-15));
  CHECK(fields[12] == doctest::Approx(std::sin(1.0)).epsilon(1e-6));
}

TEST_CASE("recorder: an initial value at the threshold is changed absolutely, above it relatively") {
  const double threshold = tsi::app::RunRecorder::relative_change_threshold;
  for (const auto& [initial, kind] : {std::pair{threshold, "absolute"}, std::pair{2.0 * threshold, "relative"},
                                      std::pair{-2.0 * threshold, "relative"}}) {
    Setup s({{"c", "a constant", [v = initial](const Vector&) { return v; }}});
    tsi::app::RunRecorder recorder(*s.model, *s.direct, exact(0.0), config(1.0, 1.0));
    CAPTURE(initial);
    CHECK(recorder.invariants_json()["c"]["change"] == kind);
  }
}

TEST_CASE("recorder: invariant names that are no column names, or whose columns are taken, are refused") {
  for (const std::string name : {"", "a b", "x,y", "H", "m", "t", "err_H", "tau_roughness"}) {
    CAPTURE(name);
    Setup s({{name, "", [](const Vector&) { return 1.0; }}});
    CHECK_THROWS_AS(tsi::app::RunRecorder(*s.model, *s.direct, exact(0.0), config(1.0, 1.0)), tsi::Error);
  }
  // Two invariants with the same name, or one named as another's change column.
  Setup twice({{"P", "", [](const Vector&) { return 1.0; }}, {"P", "", [](const Vector&) { return 2.0; }}});
  CHECK_THROWS_AS(tsi::app::RunRecorder(*twice.model, *twice.direct, exact(0.0), config(1.0, 1.0)), tsi::Error);
  Setup column({{"P", "", [](const Vector&) { return 1.0; }}, {"err_P", "", [](const Vector&) { return 2.0; }}});
  CHECK_THROWS_AS(tsi::app::RunRecorder(*column.model, *column.direct, exact(0.0), config(1.0, 1.0)), tsi::Error);
  Setup missing(std::vector<ModelInvariant>{{"P", "", nullptr}});
  CHECK_THROWS_WITH_AS(tsi::app::RunRecorder(*missing.model, *missing.direct, exact(0.0), config(1.0, 1.0)),
                       doctest::Contains("without a value function"), tsi::Error);
}

TEST_CASE("recorder: invariants and monitors run every output.every steps, a finiteness check at every step") {
  // A declared invariant that counts its evaluations: one at the start, then one per recorded step.
  auto calls = std::make_shared<long>(0);
  Setup s({{"c", "counted", [calls](const Vector& u) { return ++*calls, u(0).real(); }}});
  Json cfg = config(0.1, 2.0);  // 20 steps
  cfg["output"]["every"] = 7;
  tsi::app::RunRecorder recorder(*s.model, *s.direct, exact(0.0), cfg);
  const long at_start = *calls;
  const auto time = [](long n) { return 0.1 * static_cast<double>(n); };
  for (long n = 0; n <= 20; ++n) REQUIRE(recorder.observe(n, time(n), s.direct->prepare(exact(time(n)))));
  CHECK(*calls - at_start == 4);  // steps 0, 7, 14 and the last, 20
  CHECK(recorder.steps() == 20);
  // The rows are those steps; the maximum of err_H is over them.
  const std::string csv = recorder.csv();
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 1 + 4);

  // A non-finite state between two recorded steps stops the run there, naming both steps.
  tsi::app::RunRecorder watched(*s.model, *s.direct, exact(0.0), cfg);
  for (long n = 0; n <= 8; ++n) REQUIRE(watched.observe(n, time(n), s.direct->prepare(exact(time(n)))));
  Vector bad = s.direct->prepare(exact(time(9)));  // the problem's state (a real model's: packed)
  bad(0) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(watched.observe(9, time(9), bad));
  CHECK(watched.status() == "blow-up");
  CHECK(watched.message().find("non-finite at t = 0.9 (step 9)") != std::string::npos);
  CHECK(watched.message().find("last recorded state is from t = 0.7 (step 7") != std::string::npos);
  CHECK(watched.steps() == 7);
  CHECK(watched.u_last() == exact(time(7)));
}

TEST_CASE("recorder: a declared invariant that turns NaN stops the run, and its max_change is NaN, not 0") {
  const Outcome o = record(std::numeric_limits<double>::quiet_NaN());
  CHECK(o.stopped_at == 2);  // t = 0.5: |sin 0.5| = 0.48
  CHECK(o.status == "blow-up");
  CHECK(o.message.find("the invariant W = nan at t = 0.5 (step 2) is not a finite number") != std::string::npos);
  CHECK(std::isnan(o.invariant["max_change"].get<double>()));
}

TEST_CASE("recorder: a declared invariant that overflows to inf stops the run, naming it") {
  const Outcome o = record(std::numeric_limits<double>::infinity());
  CHECK(o.stopped_at == 2);
  CHECK(o.status == "blow-up");
  CHECK(o.message.find("the invariant W = inf at t = 0.5 (step 2)") != std::string::npos);
  CHECK(std::isinf(o.invariant["max_change"].get<double>()));
}

TEST_CASE("recorder: a finite declared invariant runs to the end with its largest change") {
  const Outcome o = record(3.0);
  CHECK(o.stopped_at == -1);
  CHECK(o.status == "running");
  CHECK(o.invariant["max_change"].get<double>() == 0.5);  // |3 - 2| / 2
}
