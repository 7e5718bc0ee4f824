// `tsi check`: the conformance checks of a model plugin pass on a good model and fail, with
// a message that says what is wrong, on a model with a wrong linear flow.
#include <doctest/doctest.h>

#include <string>

#include "run_command.hpp"

namespace {

namespace t = tsi::test;


}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("check: a shipped model passes with a shipped scheme") {
  const t::CommandResult r = t::run_tsi({"check", "henon-heiles", "--scheme", "se1"});
  INFO(r.describe());
  CHECK(r.exit_code == 0);
  for (const char* part : {"henon-heiles (provided by", "linear_flow(2 pi) u = u", "batched calls",
                           "real states stay real", "energy H conserved at eps = 0.001", "se1", "symmetry",
                           "henon-heiles: all"})
    CHECK_MESSAGE(t::contains(r.out, part), "missing: " << part);
  CHECK_FALSE(t::contains(r.out, "FAIL"));
}

TEST_CASE("check: a model with a wrong linear flow fails and says why") {
  const std::string plugin = t::fixture_plugin("broken_flow");
  const t::CommandResult r = t::run_tsi({"check", "--plugin", plugin, "--scheme", "se1"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 1);
  CHECK(t::contains(r.out, "fixture-broken-flow (provided by"));
  CHECK(t::contains(r.out, "tsi_fixture_broken_flow.so"));
  CHECK(t::contains(r.out, "checks FAILED"));
  CHECK(t::contains(r.out, "linear_flow(2 pi) u = u: "));
  CHECK(t::contains(r.out, "2 pi periodic"));
  CHECK(t::contains(r.out, "d/dtau linear_flow(tau) u at 0 = J M u: "));
  CHECK(t::contains(r.out, "energy H conserved at eps = 1: "));
  CHECK_FALSE(t::contains(r.out, "henon-heiles"));  // only the plugin's model is checked
}

TEST_CASE("check: a model whose fused filtered_field disagrees with flow, field and flow back fails") {
  const t::CommandResult r = t::run_tsi({"check", "--plugin", t::fixture_plugin("broken_fused"), "--scheme", "se1"});
  INFO(r.describe());
  CHECK(r.exit_code == 1);
  CHECK(t::contains(r.out, "filtered_field = flow, field, flow back: "));
  CHECK(t::contains(r.out, "ok    linear_flow(2 pi) u = u"));  // the flow itself is right
}

TEST_CASE("check: the runner's --plugin selects the plugin's model too") {
  const t::CommandResult r =
      t::run_tsi({"--plugin", t::fixture_plugin("broken_flow"), "check", "--scheme", "se1", "--eps", "0.5"});
  INFO(r.describe());
  CHECK(r.exit_code == 1);
  CHECK(t::contains(r.out, "fixture-broken-flow"));
  CHECK(t::contains(r.out, "eps = 0.5"));
}

TEST_CASE("check: bad input is exit code 2 with a message") {
  SUBCASE("unknown model") {
    const t::CommandResult r = t::run_tsi({"check", "no-such-model"});
    INFO(r.describe());
    CHECK(r.exit_code == 2);
    CHECK(t::contains(r.err, "\"no-such-model\""));
    CHECK(t::contains(r.err, "henon-heiles"));  // the valid names
  }
  SUBCASE("eps out of range") {
    const t::CommandResult r = t::run_tsi({"check", "henon-heiles", "--eps", "2"});
    INFO(r.describe());
    CHECK(r.exit_code == 2);
    CHECK(t::contains(r.err, "check --eps: got 2, expected a number in (0, 1]"));
  }
  SUBCASE("a scheme that does not integrate the two-scale problem") {
    const t::CommandResult r = t::run_tsi({"check", "henon-heiles", "--scheme", "rk78"});
    INFO(r.describe());
    CHECK(r.exit_code == 2);
    CHECK(t::contains(r.err, "does not integrate the two-scale problem"));
  }
}

}  // TEST_SUITE
