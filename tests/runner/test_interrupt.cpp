// SIGINT and SIGTERM during a run or a study: the computation stops at its next step, what was
// computed is written (status "interrupted"), and the exit code is 128 + the signal.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

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

TEST_CASE("interrupt: even SIGKILL leaves the rows computed more than a second before on disk, and a checkpoint") {
  t::TempDir dir;
  const t::Json config = {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 64}}},
                          {"scheme", {{"name", "se1"}}},
                          {"time", {{"h", 0.01}, {"t_end", 1000.0}}},
                          {"output", {{"checkpoint_seconds", 0.5}}}};
  t::CommandEnv env;
  env.send_signal = SIGKILL;
  env.signal_after_seconds = 2.5;
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"}, env);
  INFO(r.describe());
  CHECK(r.signal == SIGKILL);
  const std::string csv = t::read_text(dir.path() / "out" / "invariants.csv.partial");
  CHECK(std::count(csv.begin(), csv.end(), '\n') > 10);  // streamed, flushed at least once a second
  CHECK(t::contains(csv, "t,H,I,m,err_H"));
  // result.json from the last checkpoint (every 0.5 s): how far the run got, within the rows.
  const t::Json checkpoint = t::read_json(dir.path() / "out" / "result.json");
  CHECK(checkpoint.at("status") == "running");
  CHECK(checkpoint.at("config").at("model").at("name") == "nls");
  const long done = checkpoint.at("steps_done").get<long>();
  CHECK(done > 0);
  CHECK(checkpoint.at("t_reached").get<double>() > 0.0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') >= done + 2);  // header and t = 0, then the rows reach the checkpoint (flushed before it)
}

namespace {

// Interrupt trials at random moments: TSI_INTERRUPT_TRIALS of them (default `fallback`; the
// README's numbers are from 20), each moment uniform in [0.05 s, `longest` s].
std::vector<double> random_moments(int fallback, double longest, unsigned& seed) {
  int trials = fallback;
  if (const char* n = std::getenv("TSI_INTERRUPT_TRIALS")) trials = std::max(1, std::atoi(n));
  seed = std::random_device{}();
  if (const char* s = std::getenv("TSI_INTERRUPT_SEED")) seed = static_cast<unsigned>(std::strtoul(s, nullptr, 10));
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> moment(0.05, longest);
  std::vector<double> out;
  for (int k = 0; k < trials; ++k) out.push_back(moment(random));
  return out;
}

// The rows of a streamed invariants.csv: whole lines, as many fields as the header.
long csv_rows(const t::fs::path& file) {
  const std::vector<std::string> lines = t::lines_of(t::read_text(file));
  REQUIRE(!lines.empty());
  const size_t fields = t::csv_fields(lines[0]).size();
  const long whole = std::count_if(lines.begin(), lines.end(),
                                   [&](const std::string& line) { return t::csv_fields(line).size() == fields; });
  CHECK(whole == static_cast<long>(lines.size()));
  return static_cast<long>(lines.size()) - 1;
}

// A run of about 3 s: Henon-Heiles, SE1, 120000 steps (1.6 s), then its rk78 reference and the
// reference's check (1.7 s).
t::Json three_second_run() {
  return {{"model", {{"name", "henon-heiles"}, {"eps", 0.01}}},
          {"scheme", {{"name", "se1"}}},
          {"time", {{"h", 0.025}, {"t_end", 3000.0}}},
          {"reference", t::Json::object()}};
}

}  // namespace

TEST_CASE("interrupt: SIGINT at random moments of a run keeps a valid result.json with every step made") {
  unsigned seed = 0;
  const std::vector<double> moments = random_moments(3, 3.5, seed);
  MESSAGE("seed " << seed << " (TSI_INTERRUPT_SEED repeats it)");
  int interrupted = 0, completed = 0, in_reference = 0;
  for (const double moment : moments) {
    t::TempDir dir;
    t::CommandEnv env;
    env.send_signal = SIGINT;
    env.signal_after_seconds = moment;
    const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, three_second_run()), "--out", dir / "out"}, env);
    INFO("SIGINT after " << moment << " s; " << r.describe());
    REQUIRE(r.signal == 0);
    const t::Json result = t::read_json(dir.path() / "out" / "result.json");
    const std::string status = result.at("status");
    REQUIRE((status == "interrupted" || status == "completed"));
    // 130 once the signal is sent; 0 only when the run ended before its moment came.
    CHECK((r.exit_code == 128 + SIGINT || (status == "completed" && r.exit_code == 0)));
    const long steps = result.at("steps").get<long>();
    CHECK(csv_rows(dir.path() / "out" / "invariants.csv") == steps + 1);  // t = 0 and every step
    CHECK_FALSE(t::fs::exists(dir.path() / "out" / "invariants.csv.partial"));
    CHECK(result.at("u_final").size() == 4);
    if (status == "completed") {
      ++completed;
      CHECK(steps == 120000);
      CHECK(result.at("error").at("relative").is_number());
    } else {
      ++interrupted;
      CHECK(t::contains(result.at("message").get<std::string>(), "interrupted"));
      if (steps == 120000) {  // the run was done, its reference was not
        ++in_reference;
        CHECK(t::contains(result.at("message").get<std::string>(), "while computing the reference"));
        CHECK_FALSE(result.contains("error"));
      }
    }
  }
  MESSAGE(moments.size() << " interrupts: " << interrupted << " interrupted (" << in_reference
                         << " in the reference), " << completed << " completed before the signal");
}

namespace {

// Six runs of under a second to a few seconds (Henon-Heiles over T = 800, SE1 and SE2, three h)
// and their reference:
// a study to interrupt at random moments.
t::Json six_run_study() {
  return {{"kind", "convergence"},
          {"base", {{"model", {{"name", "henon-heiles"}, {"eps", 0.01}}},
                    {"time", {{"t_end", 800.0}}},
                    {"reference", t::Json::object()}}},
          {"vary", {{"scheme.name", {"se1", "se2"}}, {"time.h", {0.05, 0.025, 0.0125}}}}};
}

// An interrupted (or finished) six_run_study in `out`: study.json and table.csv list every run;
// a completed run's files are whole, an interrupted run's files (when it has them: a run that
// never started on an MPI rank has none) hold what it made. Returns whether all completed.
bool check_study_kept(const t::fs::path& out, bool every_run_has_files, long& finished, long& stopped) {
  const t::Json study = t::read_json(out / "study.json");
  REQUIRE(study.at("table").size() == 6);
  CHECK(t::lines_of(t::read_text(out / "table.csv")).size() == 7);
  bool all_completed = true;
  for (const auto& row : study.at("table")) {
    const std::string id = row.at("id"), status = row.at("status");
    INFO(id << ": " << row.dump());
    REQUIRE((status == "completed" || status == "interrupted"));
    all_completed = all_completed && status == "completed";
    const t::fs::path run = out / "runs" / id;
    if (status == "completed") ++finished;
    else ++stopped;
    if (status != "completed" && !every_run_has_files && !t::fs::exists(run / "result.json")) continue;
    const t::Json result = t::read_json(run / "result.json");
    CHECK(result.at("status") == status);
    if (status == "completed") CHECK(result.at("error").at("relative").is_number());
    if (status == "completed" || result.value("steps", 0L) > 0)
      CHECK(csv_rows(run / "invariants.csv") == result.at("steps").get<long>() + 1);
  }
  return all_completed;
}

}  // namespace

TEST_CASE("interrupt: SIGINT at random moments of a study keeps study.json and every finished run") {
  unsigned seed = 0;
  const std::vector<double> moments = random_moments(3, 3.5, seed);
  MESSAGE("seed " << seed << " (TSI_INTERRUPT_SEED repeats it)");
  long finished_runs = 0, stopped_runs = 0;
  for (const double moment : moments) {
    t::TempDir dir;
    t::CommandEnv env;
    env.send_signal = SIGINT;
    env.signal_after_seconds = moment;
    const t::CommandResult r = t::run_tsi({"study", t::write_config(dir, six_run_study(), "study.json"), "--out",
                                           dir / "out", "--no-plots", "--jobs", "2"},
                                          env);
    INFO("SIGINT after " << moment << " s; " << r.describe());
    REQUIRE(r.signal == 0);
    CHECK((r.exit_code == 128 + SIGINT || r.exit_code == 0));  // 0: the study ended before its moment
    const bool all_completed = check_study_kept(dir.path() / "out", true, finished_runs, stopped_runs);
    if (r.exit_code == 0) CHECK(all_completed);
  }
  MESSAGE(moments.size() << " interrupts: " << finished_runs << " runs completed and kept, " << stopped_runs
                         << " interrupted or not started");
}

#ifdef TSI_TEST_MPIEXEC
TEST_CASE("interrupt: SIGINT to mpirun at random moments of an MPI study keeps study.json and every finished run") {
  // Open MPI turns mpirun's SIGINT into SIGTERM for every rank; rank 0 then writes the table.
  // From 1.5 s on: before that, mpirun may still be starting the ranks (0.4 s measured), and a
  // rank that has not yet installed its handlers dies of the SIGTERM with nothing to write.
  unsigned seed = 0;
  const std::vector<double> moments = random_moments(3, 3.5, seed);
  MESSAGE("seed " << seed << " (TSI_INTERRUPT_SEED repeats it)");
  long finished_runs = 0, stopped_runs = 0;
  for (const double moment : moments) {
    t::TempDir dir;
    t::CommandEnv env = t::mpirun_env();
    env.send_signal = SIGINT;
    env.signal_after_seconds = 1.5 + moment;
    env.timeout_seconds = 300.0;  // a guard: a hung mpirun is killed, and the checks below fail
    const t::CommandResult r = t::run_command(
        TSI_TEST_MPIEXEC, {"-np", "2", "--oversubscribe", "--allow-run-as-root", TSI_TEST_RUNNER, "study",
                           t::write_config(dir, six_run_study(), "study.json"), "--out", dir / "out", "--no-plots"},
        env);
    INFO("SIGINT after " << 1.5 + moment << " s; " << r.describe());
    REQUIRE(r.signal == 0);
    const bool all_completed = check_study_kept(dir.path() / "out", false, finished_runs, stopped_runs);
    // mpirun's own code (1 here): not 0 when a run was cut short. A signal that lands after the
    // study was written, while mpirun ends, may still give a non-zero code with every run done.
    if (!all_completed) CHECK(r.exit_code != 0);
  }
  MESSAGE(moments.size() << " interrupts: " << finished_runs << " runs completed and kept, " << stopped_runs
                         << " interrupted or not started");
}
#endif

TEST_CASE("interrupt: SIGINT during dense output's evaluations stops them within a second") {
  // 20,000 output times within the first step, each an evaluation of U (1024 tau points of a
  // 32 x 32 grid) at about 5 ms: 100 s of evaluations at one step, interrupted after 2 s.
  t::TempDir dir;
  t::Json times = t::Json::array();
  for (int k = 0; k < 20000; ++k) times.push_back(0.25 * k / 20000.0);
  const t::Json config = {{"model", {{"name", "nls"}, {"eps", 0.01}, {"dims", 2}, {"n_x", 32}}},
                          {"reformulation", {{"name", "two-scale"}, {"n_tau", 1024}}},
                          {"scheme", {{"name", "se1"}}},
                          {"time", {{"h", 0.25}, {"t_end", 0.5}}},
                          {"output", {{"times", times}}}};
  t::CommandEnv env;
  env.send_signal = SIGINT;
  env.signal_after_seconds = 2.0;
  const auto start = std::chrono::steady_clock::now();
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"}, env);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  INFO(r.describe());
  CHECK(r.exit_code == 128 + SIGINT);
  // The signal at 2 s; the 320 MB of u_times.npy written after it take well under a second
  // more. Without the poll, the evaluations ran on for about 100 s.
  CHECK(seconds < 10.0);
  const t::Json result = t::read_json(dir.path() / "out" / "result.json");
  CHECK(result.at("status") == "interrupted");
  const long evaluated = result.at("dense_output").at("evaluated").get<long>();
  CHECK(evaluated < 20000);
  CHECK(std::filesystem::exists(dir.path() / "out" / "u_times.npy"));
}
