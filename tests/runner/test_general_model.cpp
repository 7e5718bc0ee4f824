// A model of the general class without Hamiltonian structure (HOODESolver.jl's quickstart
// problem, tests/fixtures/fixture_general.cpp): runs report no energy, their error against an
// rk78 reference on the filtered problem is that of a second-order scheme, and `tsi check`
// skips the Hamiltonian checks and says why.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "run_command.hpp"

namespace {

namespace t = tsi::test;
using t::Json;

Json quickstart(const std::string& scheme, double h) {
  return {{"model", {{"name", "fixture-quickstart"}, {"eps", 1e-4}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", 32}}},
          {"scheme", {{"name", scheme}}},
          {"time", {{"h", h}, {"t_end", 3.0}}},
          {"reference", {{"tol", 1e-13}}}};
}

// The relative error at t = 3 of a run, after checking it reported no energy.
double error_of(const t::TempDir& dir, const std::string& plugin, const std::string& scheme, double h) {
  const std::string out = dir / (scheme + std::to_string(h));
  const t::CommandResult r =
      t::run_tsi({"run", t::write_config(dir, quickstart(scheme, h)), "--plugin", plugin, "--out", out});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json result = t::read_json(t::fs::path(out) / "result.json");
  CHECK(result["status"] == "completed");
  for (const char* name : {"H", "I", "m"}) CHECK_FALSE(result["invariants"].contains(name));
  const auto lines = t::lines_of(t::read_text(t::fs::path(out) / "invariants.csv"));
  CHECK(lines.front() == "t,tau_roughness,tau_spread");
  CHECK_FALSE(t::contains(r.out, "max rel. change of H"));
  return result["error"]["relative"].get<double>();
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("general model: no energy reported, SE1 and eab converge to an rk78 reference at their orders") {
  t::TempDir dir;
  const std::string plugin = t::fixture_plugin("general");
  // SE1 at h = 0.2, 0.1 and 0.05: order 2 (an independent reference: rk78 on the filtered problem).
  const double e1 = error_of(dir, plugin, "se1", 0.2), e2 = error_of(dir, plugin, "se1", 0.1),
               e3 = error_of(dir, plugin, "se1", 0.05);
  MESSAGE("se1 errors " << e1 << " " << e2 << " " << e3);
  CHECK(std::log2(e1 / e2) == doctest::Approx(2.0).epsilon(0.15));
  CHECK(std::log2(e2 / e3) == doctest::Approx(2.0).epsilon(0.15));
  // eab of order 4 (data of order 6) from h = 0.1 (HOODESolver's quickstart step) down: order 4
  // (measured 4.58 and 3.96; at h = 0.1 its error, 4.6e-4, is the start-up's).
  const double a1 = error_of(dir, plugin, "eab", 0.1), a2 = error_of(dir, plugin, "eab", 0.05),
               a3 = error_of(dir, plugin, "eab", 0.025);
  MESSAGE("eab errors " << a1 << " " << a2 << " " << a3);
  CHECK(std::log2(a1 / a2) > 3.6);
  CHECK(std::log2(a2 / a3) == doctest::Approx(4.0).epsilon(0.1));
}

TEST_CASE("general model: the direct problem (A u from apply_A) and the filtered one give the same reference") {
  t::TempDir dir;
  const std::string plugin = t::fixture_plugin("general");
  Json finals[2];
  int k = 0;
  for (const char* reformulation : {"direct", "filtered"}) {
    Json config = quickstart("se1", 0.1);
    config["model"]["eps"] = 1e-2;
    config["reference"] = {{"reformulation", reformulation}, {"tol", 1e-12}};
    const std::string out = dir / reformulation;
    const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--plugin", plugin, "--out", out});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    finals[k++] = t::read_json(t::fs::path(out) / "result.json")["error"]["reference"]["u_final"];
  }
  for (size_t i = 0; i < 4; ++i)
    CHECK(finals[0][i].get<double>() == doctest::Approx(finals[1][i].get<double>()).epsilon(1e-9));
}

TEST_CASE("general model: tsi check skips the Hamiltonian checks and says why") {
  const t::CommandResult r = t::run_tsi({"check", "--plugin", t::fixture_plugin("general"), "--scheme", "se1"});
  INFO(r.describe());
  CHECK(r.exit_code == 0);
  CHECK(t::contains(r.out, "declares no Hamiltonian structure"));
  CHECK(t::contains(r.out, "d/dtau linear_flow(tau) u at 0 = A u"));
  CHECK_FALSE(t::contains(r.out, "energy H conserved"));
  CHECK_FALSE(t::contains(r.out, "FAIL"));
}

}  // TEST_SUITE
