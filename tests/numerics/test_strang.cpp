// Strang splitting with the exact flows (the paper's reference for NLS): second order
// against the rk78 reference, exact time symmetry, and a clear refusal where the problem has
// no exact flows.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>

#include "harness.hpp"
#include "runner/run_command.hpp"
#include "tsi/convergence.hpp"
#include "tsi/error.hpp"

namespace {

using tsi::Vector;
using tsi::test::Harness;

std::vector<double> strang_errors(const std::string& model_name, double eps, const std::vector<long>& steps) {
  auto& h = Harness::instance();
  auto model = h.model(model_name, eps);
  const Vector& ref = tsi::test::reference_solution(model_name, eps, 1.0);
  std::vector<double> errors;
  for (long n : steps) {
    auto direct = h.reformulation("direct", model);
    auto strang = h.scheme("strang");
    const Vector u = tsi::test::solve(*model, *direct, *strang, 1.0, n);
    errors.push_back(model->error_norm(u - ref) / model->error_norm(ref));
  }
  return errors;
}

std::vector<double> step_sizes(const std::vector<long>& steps) {
  std::vector<double> hs;
  for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
  return hs;
}

}  // namespace

TEST_CASE("strang: registered as a symmetric second-order scheme for the direct problem") {
  const auto& e = Harness::instance().registry().scheme("strang");
  CHECK(e.traits.order == 2);
  CHECK(e.traits.symmetric);
  CHECK_FALSE(e.traits.implicit);
  REQUIRE(e.traits.reformulations.size() == 1);
  CHECK(e.traits.reformulations[0] == "direct");
}

TEST_CASE("strang: second order on NLS at eps = 1") {
  // At eps = 1 the fastest mode turns by h (N_x/2)^2 = 64 h per step: from h = 1/4 to 1/16
  // the error is pre-asymptotic (1.2e-2, 8.1e-3, 1.9e-3); from h = 1/32 on, order 2.
  const std::vector<long> steps = {32, 64, 128, 256};
  const auto errors = strang_errors("nls", 1.0, steps);
  const double order = tsi::least_squares_order(step_sizes(steps), errors);
  CAPTURE(errors[0]);
  CAPTURE(errors[3]);
  CAPTURE(order);
  CHECK(std::abs(order - 2.0) <= 0.15);
  CHECK(errors[3] < 5e-6);  // measured 2.7e-6 at h = 1/256
}

TEST_CASE("strang: second order on the charged particle at eps = 1") {
  const std::vector<long> steps = {4, 8, 16, 32};
  const auto errors = strang_errors("cpd", 1.0, steps);
  const double order = tsi::least_squares_order(step_sizes(steps), errors);
  CAPTURE(order);
  CHECK(std::abs(order - 2.0) <= 0.15);
}

TEST_CASE("strang: a step with h then -h returns the state") {
  auto& h = Harness::instance();
  for (const std::string name : {"nls", "cpd"}) {
    for (double eps : {1.0, 0.01, 1e-6}) {
      auto model = h.model(name, eps);
      auto direct = h.reformulation("direct", model);
      auto strang = h.scheme("strang");
      const Vector start = direct->prepare(model->initial_value());
      Vector y = start;
      strang->bind(*direct, 0.1)->step(0.0, y);
      const double moved = tsi::max_norm(y - start) / tsi::max_norm(start);
      strang->bind(*direct, -0.1)->step(0.1, y);
      const double back = tsi::max_norm(y - start) / tsi::max_norm(start);
      CAPTURE(name);
      CAPTURE(eps);
      CAPTURE(moved);
      CAPTURE(back);
      CHECK(moved > 1e-7);  // (the charged particle barely moves at eps = 1e-6: 1.4e-6)
      CHECK(back < 1e-13);
    }
  }
}

TEST_CASE("strang: refuses a problem without exact flows before anything runs") {
  auto& h = Harness::instance();
  // Henon-Heiles has no exact nonlinear flow: the assembler refuses the pairing, naming both.
  const tsi::Json selection = {{"model", {{"name", "henon-heiles"}, {"eps", 0.1}}},
                               {"reformulation", {{"name", "direct"}}},
                               {"scheme", {{"name", "strang"}}}};
  CHECK_THROWS_WITH_AS(h.assemble(selection),
                       doctest::Contains("scheme \"strang\" needs the exact linear and nonlinear flows, which "
                                         "model \"henon-heiles\" on the \"direct\" reformulation"),
                       tsi::ConfigError);
  // NLS has one: the same selection assembles.
  tsi::Json nls = selection;
  nls["model"] = {{"name", "nls"}, {"eps", 0.1}};
  CHECK(h.assemble(nls).scheme != nullptr);
  // The other reformulations are refused by the registry's compatibility check.
  const auto& registry = h.registry();
  CHECK_THROWS_AS(registry.check_compatible(registry.scheme("strang"), registry.reformulation("two-scale")),
                  tsi::ConfigError);
  CHECK_THROWS_AS(registry.check_compatible(registry.scheme("strang"), registry.reformulation("filtered")),
                  tsi::ConfigError);

  // From the runner both are bad input (exit 2, the field named), and nothing is computed.
  const tsi::test::TempDir dir("tsi-strang");
  tsi::Json config = tsi::test::small_config();
  config["scheme"] = {{"name", "strang"}};
  config["reformulation"] = {{"name", "direct"}};
  const auto hh = tsi::test::run_tsi({"run", tsi::test::write_config(dir, config), "--out", dir / "hh"});
  CHECK(hh.exit_code == 2);
  CHECK(tsi::test::contains(hh.err, "scheme.name"));
  CHECK(tsi::test::contains(hh.err, "henon-heiles"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "hh" / "result.json"));
  config["model"] = {{"name", "nls"}, {"eps", 0.1}};
  config["reformulation"] = {{"name", "two-scale"}};
  const auto two_scale =
      tsi::test::run_tsi({"run", tsi::test::write_config(dir, config), "--out", dir / "ts"});
  CHECK(two_scale.exit_code == 2);
  CHECK(tsi::test::contains(two_scale.err, "reformulation.name"));
}
