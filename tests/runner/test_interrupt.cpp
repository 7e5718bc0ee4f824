// SIGINT and SIGTERM during a run or a study: the computation stops at its next step, what was
// computed is written (status "interrupted"), and the exit code is 128 + the signal.
#include <doctest/doctest.h>

#include <algorithm>
#include <csignal>
#include <string>

#include "run_command.hpp"

namespace t = tsi::test;

TEST_CASE("interrupt: a run stopped by SIGINT or SIGTERM keeps every step it made") {
  for (const int signal : {SIGINT, SIGTERM}) {
    t::TempDir dir;
    // About 100 s of work: long enough that the signal always lands mid-run.
    const t::Json config = {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 64}}},
                              {"scheme", {{"name", "se1"}}},
                              {"time", {{"h", 0.01}, {"t_end", 1000.0}}}};
    t::CommandEnv env;
    env.send_signal = signal;
    env.signal_after_seconds = 1.0;
    const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"}, env);
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 128 + signal);
    const t::Json result = t::read_json(dir.path() / "out" / "result.json");
    CHECK(result.at("status") == "interrupted");
    const long steps = result.at("steps").get<long>();
    CHECK(steps > 0);
    CHECK(steps < 100000);
    CHECK(t::contains(result.at("message").get<std::string>(), "interrupted by signal " + std::to_string(signal)));
    // invariants.csv: the header, t = 0 and every step made (output.every = 1).
    const std::string csv = t::read_text(dir.path() / "out" / "invariants.csv");
    CHECK(static_cast<long>(std::count(csv.begin(), csv.end(), '\n')) == steps + 2);
  }
}

TEST_CASE("interrupt: a study stopped by SIGINT writes its table with every run's status") {
  t::TempDir dir;
  const t::Json spec = {{"kind", "conservation"},
                          {"base", {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 64}}},
                                    {"time", {{"h", 0.01}, {"t_end", 1000.0}}}}},
                          {"vary", {{"scheme.name", {"se1", "se2", "fd", "me"}}}}};
  t::CommandEnv env;
  env.send_signal = SIGINT;
  env.signal_after_seconds = 1.0;
  const t::CommandResult r =
      t::run_tsi({"study", t::write_config(dir, spec, "study.json"), "--out", dir / "out", "--no-plots", "--jobs", "1"},
                 env);
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 128 + SIGINT);
  const std::string table = t::read_text(dir.path() / "out" / "table.csv");
  CHECK(t::contains(table, "interrupted"));
  const t::Json first = t::read_json(dir.path() / "out" / "runs" / "r0001" / "result.json");
  CHECK(first.at("status") == "interrupted");
  CHECK(first.at("steps").get<long>() > 0);
}

TEST_CASE("interrupt: even SIGKILL leaves the rows computed more than a second before on disk") {
  t::TempDir dir;
  const t::Json config = {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 64}}},
                          {"scheme", {{"name", "se1"}}},
                          {"time", {{"h", 0.01}, {"t_end", 1000.0}}}};
  t::CommandEnv env;
  env.send_signal = SIGKILL;
  env.signal_after_seconds = 2.5;
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"}, env);
  INFO(r.describe());
  CHECK(r.signal == SIGKILL);
  const std::string csv = t::read_text(dir.path() / "out" / "invariants.csv.partial");
  CHECK(std::count(csv.begin(), csv.end(), '\n') > 10);  // streamed, flushed at least once a second
  CHECK(t::contains(csv, "t,H,I,m,err_H"));
}
