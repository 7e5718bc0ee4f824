// The recorder on a declared invariant that stops being a number while the state stays finite
// (a particle energy sum w |v|^2 / 2 that overflows): the run stops as a blow-up naming it, and
// its max_change is NaN or inf, never the 0 that std::max(0, NaN) would leave.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "fixtures/fixture_model.hpp"
#include "run_recorder.hpp"
#include "tsi/registry.hpp"

namespace {

using tsi::Json;
using tsi::ModelInvariant;
using tsi::Vector;

class DeclaringModel final : public tsi::fixture::HarmonicModel {
 public:
  explicit DeclaringModel(ModelInvariant invariant) : HarmonicModel(1.0), invariant_(std::move(invariant)) {}
  std::vector<ModelInvariant> invariants() const override { return {invariant_}; }

 private:
  ModelInvariant invariant_;
};

// u(t) = (cos t, -sin t) at eps = 1, on the direct reformulation.
Vector exact(double t) {
  Vector u(2);
  u << std::cos(t), -std::sin(t);
  return u;
}

Json config() {
  return {{"output", {{"every", 1}}},
          {"monitor", {{"max_err_H", 1e10}, {"tau_roughness_warn", 1.0}, {"tau_spread_growth_warn", 1e10}}},
          {"time", {{"h", 0.25}, {"t_end", 1.0}}}};
}

// The recorder's verdict after steps 0 .. 4 of h = 0.25 with an invariant that is 2 while
// |u_2| < 0.3 (t < 0.305) and `beyond` after.
struct Outcome {
  long stopped_at = -1;
  std::string status, message;
  Json invariant;
};

Outcome record(double beyond) {
  const auto model = std::make_shared<DeclaringModel>(ModelInvariant{
      "W", "2, then beyond", [beyond](const Vector& u) { return std::abs(u(1).real()) < 0.3 ? 2.0 : beyond; }});
  tsi::Registry registry;
  tsi::register_core(registry);
  const auto& entry = registry.reformulation("direct");
  const auto direct = entry.create(model, tsi::Params(tsi::resolve_params(entry.info.params, Json::object(), "r")));
  tsi::app::RunRecorder recorder(*model, *direct, exact(0.0), config());
  Outcome out;
  for (long n = 0; n <= 4 && out.stopped_at < 0; ++n)
    if (!recorder.observe(n, 0.25 * static_cast<double>(n), direct->prepare(exact(0.25 * static_cast<double>(n)))))
      out.stopped_at = n;
  out.status = recorder.status();
  out.message = recorder.message();
  out.invariant = recorder.invariants_json()["W"];
  return out;
}

}  // namespace

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
