// `mpirun -np P tsi run CONFIG --split`: one particle run split over MPI ranks gives the
// particles, invariants and error of the run on one process to rounding (the density is summed
// in another order), and whatever a split run cannot do is refused on every rank alike. Built
// only when tsi was built with MPI (TSI_WITH_MPI).
#include <doctest/doctest.h>

#ifdef TSI_TEST_MPIEXEC
#include <cmath>
#include <csignal>
#include <string>
#include <vector>
#include <fstream>
#include <sstream>

#include "run_command.hpp"
#include "split_run.hpp"
#include "tsi/npy.hpp"

namespace t = tsi::test;

namespace {

constexpr double pi_over_16 = 0.19634954084936207;  // the peer's step

// A plasma of 2048 of the peer's particles (tests/data/uapic) on its 128 x 64 grid, 8 steps.
t::Json particle_config(const std::string& scheme) {
  return {{"model",
           {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}, {"particles", tsi::test::path_text({TSI_TEST_SOURCE_DIR, "/tests/data/uapic/n2048_init.bin"})},
            {"n_x", 128}, {"n_y", 64}, {"k_x", 0.5}, {"k_y", 1.0}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}}},
          {"scheme", {{"name", scheme}}},
          {"time", {{"h", pi_over_16}, {"t_end", 8 * pi_over_16}}},
          {"output", {{"every", 1}, {"state_every", 4}}}};
}

}  // namespace

TEST_CASE("split run: 1 process and mpirun -np 2 and 3 --split give the same particles, invariants and error") {
  struct Case {
    std::string label;
    t::Json config;
  };
  t::Json peer = particle_config("etd2rk");  // the UA-PIC set-up: the diagonal field, re-prepared every step
  peer["model"]["tau_field"] = "diagonal";
  peer["reformulation"].update({{"initial_data_order", 2}, {"reprepare", 1}, {"nyquist", "average"}});
  peer["reference"] = {{"scheme", "etd2rk"}, {"reformulation", "two-scale"}, {"h", pi_over_16 / 2},
                       {"estimate_accuracy", false}};
  t::Json implicit = particle_config("se1");  // fixed-point stages and data of order 4, iterated
  implicit["reformulation"]["initial_data_order"] = 4;
  implicit["reformulation"]["reprepare"] = "auto";
  implicit["scheme"]["solver"] = "anderson";
  t::Json eab = particle_config("eab");  // its default data of order 6
  for (const Case& c : {Case{"peer", peer}, Case{"se1", implicit}, Case{"eab", eab}}) {
    CAPTURE(c.label);
    t::TempDir dir("tsi-split");
    const std::string config = t::write_config(dir, c.config, "run.json");
    const t::CommandResult one = t::run_tsi({"run", config, "--out", dir / "one"});
    REQUIRE_MESSAGE(one.exit_code == 0, one.describe());
    const t::Json one_record = t::read_json(dir.path() / "one/result.json");
    for (const int ranks : c.label == "peer" ? std::vector<int>{2, 3} : std::vector<int>{2}) {
      CAPTURE(ranks);
      const std::string out = dir / ("split" + std::to_string(ranks));
      const t::CommandResult split = t::split_run(ranks, {config, "--out", out});
      REQUIRE_MESSAGE(split.exit_code == 0, split.describe());
      const t::Json record = t::read_json(t::fs::path(out) / "result.json");
      CHECK(record["split"]["processes"] == ranks);
      CHECK(t::relative_difference(dir.path() / "one/u_final.npy", t::fs::path(out) / "u_final.npy") < 1e-13);
      CHECK(t::relative_difference(dir.path() / "one/state.npy", t::fs::path(out) / "state.npy") < 1e-13);
      // Every recorded W, P, Q and W_E (the sums over the ranks), and the tau monitors.
      const auto rows = t::csv_rows(dir.path() / "one/invariants.csv"), split_rows = t::csv_rows(t::fs::path(out) / "invariants.csv");
      REQUIRE(rows.size() == split_rows.size());
      REQUIRE(rows.size() == 9);
      // (The change columns of P and Q are rounding, 1e-16 .. 1e-14: compared absolutely.)
      for (std::size_t i = 0; i < rows.size(); ++i)
        for (std::size_t j = 0; j < rows[i].size(); ++j)
          CHECK(std::abs(split_rows[i][j] - rows[i][j]) <= 1e-12 * std::abs(rows[i][j]) + 1e-13);
      // The same decisions: fixed-point sweeps, re-preparations, the data's order.
      CHECK(record["solver"] == one_record["solver"]);
      CHECK(record["repreparations"] == one_record["repreparations"]);
      CHECK(record.value("initial_data_order_reached", 0) == one_record.value("initial_data_order_reached", 0));
      if (one_record.contains("error"))
        CHECK(record["error"]["relative"].get<double>() ==
              doctest::Approx(one_record["error"]["relative"].get<double>()).epsilon(1e-10));
    }
  }
}

TEST_CASE("split run: what cannot be split is refused on every rank, said once, exit code 2") {
  t::TempDir dir("tsi-split-refused");
  const std::string config = t::write_config(dir, particle_config("etd2rk"), "run.json");
  const t::Json hh = {{"model", {{"name", "henon-heiles"}, {"eps", 0.1}}}, {"scheme", {{"name", "se1"}}},
                      {"time", {{"h", 0.1}, {"t_end", 1.0}}}};
  struct Case {
    std::vector<std::string> args;
    const char* says;
  };
  const std::string hh_config = t::write_config(dir, hh, "hh.json");
  for (const Case& c : {Case{{hh_config, "--out", dir / "hh"}, "--split: the model \"henon-heiles\" does not split"},
                        Case{{config, "--out", dir / "rk78", "--set", "reformulation={\"name\": \"direct\"}", "--set",
                              "scheme.name=rk78"},
                             "scheme: \"rk78\" chooses its steps from the state"},
                        Case{{config, "--out", dir / "few", "--set", "model.particles=2"},
                             "model.particles: 2 particles cannot be split over 3 processes"},
                        Case{{config, "--out", dir / "times", "--set", "output.times=[0.5]"},
                             "output.times: dense output is not available under --split"}}) {
    CAPTURE(c.says);
    const t::CommandResult r = t::split_run(3, c.args);
    CHECK_MESSAGE(r.exit_code == 2, r.describe());
    const std::size_t first = r.err.find(c.says);
    REQUIRE_MESSAGE(first != std::string::npos, r.describe());
    CHECK(r.err.find(c.says, first + 1) == std::string::npos);  // once, by rank 0
    CHECK_FALSE(t::fs::exists(dir.path() / "few" / "result.json"));
  }
  // Launched on 2 ranks without --split, a run would be made twice into one directory.
  t::CommandEnv env = t::mpirun_env();
  env.send_signal = SIGTERM;
  env.signal_after_seconds = 300.0;
  const t::CommandResult twice = t::run_command(
      TSI_TEST_MPIEXEC,
      {"-np", "2", "--oversubscribe", "--allow-run-as-root", TSI_TEST_RUNNER, "run", config, "--out", dir / "twice"}, env);
  CHECK(twice.exit_code == 2);
  CHECK(t::contains(twice.err, "started on 2 MPI processes without --split"));
  CHECK_FALSE(t::fs::exists(dir.path() / "twice"));
}
#endif

#ifdef TSI_TEST_MPIEXEC
TEST_CASE("split run: SIGINT to mpirun stops every rank at one step, and rank 0 keeps the run up to it") {
  t::TempDir dir("tsi-split-interrupt");
  t::Json config = particle_config("etd2rk");
  config["time"]["t_end"] = 4000 * pi_over_16;  // minutes: the signal comes first
  config["output"] = {{"every", 1}};
  t::CommandEnv env = t::mpirun_env();
  env.send_signal = SIGINT;
  env.signal_after_seconds = 2.0;
  env.timeout_seconds = 300.0;  // a hung mpirun is killed, and the test fails
  const t::CommandResult r = t::run_command(
      TSI_TEST_MPIEXEC,
      {"-np", "2", "--oversubscribe", "--allow-run-as-root", TSI_TEST_RUNNER, "run",
       t::write_config(dir, config, "run.json"), "--out", dir / "out", "--split"},
      env);
  INFO(r.describe());
  CHECK_FALSE(r.timed_out);
  CHECK(r.exit_code != 0);
  const t::Json record = t::read_json(dir.path() / "out/result.json");
  CHECK(record["status"] == "interrupted");
  const long steps = record["steps"].get<long>();
  CHECK(steps > 0);
  CHECK(steps < 4000);
  CHECK(t::csv_rows(dir.path() / "out/invariants.csv").size() == static_cast<std::size_t>(steps + 1));
  CHECK(tsi::read_npy_header(dir / "out/u_final.npy").shape == std::vector<std::uint64_t>{2048, 4});
}
#endif
