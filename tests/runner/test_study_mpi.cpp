// `mpirun -np 2 tsi study`: the same table.csv and study.json as `--jobs 1`, failed runs
// included. Built only when tsi was built with MPI (TSI_WITH_MPI); mpirun runs as root here
// (CI containers), on one machine, without network.
#include <doctest/doctest.h>

#ifdef TSI_TEST_MPIEXEC
#include "run_command.hpp"
#include "study_compare.hpp"

using namespace tsi::test;

TEST_CASE("study under mpirun -np 2: the table of --jobs 1, each run's files written") {
  TempDir dir;
  const Json spec = {
      {"kind", "convergence"},
      {"title", "mpi"},
      {"base", {{"model", {{"name", "henon-heiles"}}}, {"time", {{"t_end", 1.0}}}, {"reference", Json::object()}}},
      {"vary", {{"model.eps", {1.0, 1.0 / 64, 1.0 / 4096}}, {"time.h", {0.25, 0.125, 0.0625}}}},
      {"cases", {{{"label", "se1"}, {"set", {{"scheme.name", "se1"}}}},
                 {{"label", "stops"}, {"set", {{"scheme.name", "se2"}, {"scheme.max_iter", 1}, {"scheme.on_failure", "stop"}}}}}}};
  const std::string study = write_config(dir, spec, "study.json");
  const auto serial = run_tsi({"study", study, "--out", dir / "serial", "--jobs", "1", "--no-plots"});
  REQUIRE_MESSAGE(serial.exit_code == 1, serial.describe());  // the "stops" runs fail

  CommandEnv env = mpirun_env();
  env.send_signal = SIGTERM;  // a guard: the study takes about a second; a hung mpirun is stopped
  env.signal_after_seconds = 300.0;
  const auto mpi = run_command(TSI_TEST_MPIEXEC, {"-np", "2", "--oversubscribe", "--allow-run-as-root", TSI_TEST_RUNNER,
                                                  "study", study, "--out", dir / "mpi", "--no-plots"},
                               env);
  INFO(mpi.describe());
  CHECK(mpi.exit_code == 1);
  CHECK(contains(mpi.out, "on 2 MPI ranks"));
  CHECK(table_without_timings(fs::path(dir / "mpi")) == table_without_timings(fs::path(dir / "serial")));
  CHECK(study_without_timings(fs::path(dir / "mpi")) == study_without_timings(fs::path(dir / "serial")));
  CHECK(read_json(fs::path(dir / "mpi") / "study.json")["mpi_ranks"] == 2);
  const Json mpi_study = read_json(fs::path(dir / "mpi") / "study.json");  // kept: the loop refers into it
  for (const auto& row : mpi_study["table"]) {
    CHECK(fs::is_regular_file(fs::path(dir / "mpi") / "runs" / row["id"].get<std::string>() / "result.json"));
    if (row["label"] == "stops") CHECK(row["status"] == "failed");
  }
}
#endif

#ifdef TSI_TEST_MPIEXEC
TEST_CASE("study under mpirun: a rank that cannot start is reported and the other ranks run its share") {
  TempDir dir;
  const Json spec = {{"kind", "convergence"},
                     {"title", "mpi-rank-fails"},
                     {"base", {{"model", {{"name", "henon-heiles"}}}, {"time", {{"t_end", 1.0}}}, {"reference", Json::object()}}},
                     {"vary", {{"model.eps", {1.0, 1.0 / 64, 1.0 / 4096}}, {"time.h", {0.25, 0.125}}}}};
  const std::string study = write_config(dir, spec, "study.json");
  const auto serial = run_tsi({"study", study, "--out", dir / "serial", "--jobs", "1", "--no-plots"});
  REQUIRE_MESSAGE(serial.exit_code == 0, serial.describe());

  // Two application contexts (MPMD): ranks 0 and 1 read the study, rank 2 is given a file that
  // does not exist, as a node without the study's files would be.
  CommandEnv env = mpirun_env();
  env.send_signal = SIGTERM;
  env.signal_after_seconds = 300.0;
  const std::string missing = (fs::path(dir.path()) / "missing.json").string();
  const auto mpi = run_command(TSI_TEST_MPIEXEC, {"--oversubscribe", "--allow-run-as-root", "-np", "2", TSI_TEST_RUNNER,
                                                  "study", study, "--out", dir / "mpi", "--no-plots", ":", "-np", "1",
                                                  TSI_TEST_RUNNER, "study", missing, "--out", dir / "mpi", "--no-plots"},
                               env);
  INFO(mpi.describe());
  CHECK(contains(mpi.err, "rank 2 stopped"));
  CHECK(contains(mpi.err, "missing.json"));
  CHECK(mpi.exit_code == 2);  // mpirun passes on the failed rank's code: bad input
  CHECK(table_without_timings(fs::path(dir / "mpi")) == table_without_timings(fs::path(dir / "serial")));
  const Json mpi_study = read_json(fs::path(dir / "mpi") / "study.json");
  for (const auto& row : mpi_study["table"]) CHECK(row["status"] == "completed");
}
#endif
