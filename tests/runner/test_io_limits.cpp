// Limits before a run starts (--max-steps), outputs that cannot be written (a full disk,
// simulated with RLIMIT_FSIZE: exit code 3, the file named, what is on disk valid), and the
// memory of a long run with output every step (constant in its length).
#include <doctest/doctest.h>

#include <chrono>
#include <cstdlib>
#include <thread>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace t = tsi::test;

namespace {

// Henon-Heiles, SE1, `steps` steps of h = 0.01 with a row of invariants.csv at every step.
t::Json long_hh_config(long steps, int n_tau = 16) {
  return {{"model", {{"name", "henon-heiles"}, {"eps", 0.01}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", n_tau}}},
          {"scheme", {{"name", "se1"}}},
          {"time", {{"h", 0.01}, {"t_end", 0.01 * static_cast<double>(steps)}}},
          {"output", {{"every", 1}}}};
}

// A CSV whose every line is whole: the header's number of fields, each row's fields numbers.
// Returns the number of data rows.
long check_valid_csv(const t::fs::path& file) {
  const std::string text = t::read_text(file);
  INFO(file.string());
  REQUIRE_FALSE(text.empty());
  CHECK(text.back() == '\n');
  const std::vector<std::string> lines = t::lines_of(text);
  REQUIRE(!lines.empty());
  const size_t fields = t::csv_fields(lines[0]).size();
  CHECK(t::contains(lines[0], "t,H,I,m,err_H"));
  for (size_t k = 1; k < lines.size(); ++k) {
    const std::vector<std::string> row = t::csv_fields(lines[k]);
    INFO("line " << k + 1 << ": " << lines[k]);
    REQUIRE(row.size() == fields);
    for (const auto& f : row) {
      char* end = nullptr;
      std::strtod(f.c_str(), &end);
      CHECK((!f.empty() && end == f.c_str() + f.size()));
    }
  }
  return static_cast<long>(lines.size()) - 1;
}

// No temporary file of an atomic write is left in `dir` (or below it).
void check_no_temporaries(const t::fs::path& dir) {
  for (const auto& entry : t::fs::recursive_directory_iterator(dir)) {
    INFO(entry.path().string());
    CHECK_FALSE(t::contains(entry.path().filename().string(), ".tmp."));
  }
}

}  // namespace

TEST_CASE("max-steps: a run beyond --max-steps is refused before anything is computed") {
  t::TempDir dir;
  const std::string config = t::write_config(dir, t::small_config());  // 4 steps
  const t::CommandResult refused = t::run_tsi({"run", config, "--out", dir / "out", "--max-steps", "3"});
  INFO(refused.describe());
  CHECK(refused.exit_code == 2);
  CHECK(t::contains(refused.err, "tsi: error: time.h: got 0.25: the run would take 4 steps"));
  CHECK(t::contains(refused.err, "more than --max-steps = 3"));
  CHECK(t::contains(refused.err, "raise the limit with --max-steps N"));
  CHECK_FALSE(t::fs::exists(dir.path() / "out"));  // refused before --out is touched

  const t::CommandResult allowed = t::run_tsi({"run", config, "--out", dir / "out", "--max-steps", "4"});
  INFO(allowed.describe());
  CHECK(allowed.exit_code == 0);

  // The default: 1e9. The estimate is computed in double, so 1e10 steps are named as such.
  t::Json huge = t::small_config();
  huge["time"] = {{"h", 1.0}, {"t_end", 1e10}};
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, huge, "huge.json"), "--out", dir / "huge"});
  INFO(r.describe());
  CHECK(r.exit_code == 2);
  CHECK(t::contains(r.err, "tsi: error: time.h: got 1: the run would take 1e+10 steps"));
  CHECK(t::contains(r.err, "--max-steps = 1e+09"));
  CHECK_FALSE(t::fs::exists(dir.path() / "huge"));

  for (const std::string bad : {"0", "-5", "1e13", "nan"}) {
    const t::CommandResult b = t::run_tsi({"run", config, "--out", dir / "bad", "--max-steps", bad});
    INFO(b.describe());
    CHECK(b.exit_code == 2);
    CHECK(t::contains(b.err, "--max-steps"));
  }
}

TEST_CASE("max-steps: an adaptive reference is estimated from eps and the fastest frequency") {
  // rk78 on the filtered problem at eps = 1e-6: 8 steps per period 2 pi eps over t_end = 1,
  // about 1.27e6 steps.
  t::TempDir dir;
  t::Json config = t::small_config();
  config["model"]["eps"] = 1e-6;
  config["reference"] = t::Json::object();
  const std::string file = t::write_config(dir, config);
  const t::CommandResult r = t::run_tsi({"run", file, "--out", dir / "out", "--max-steps", "1e6"});
  INFO(r.describe());
  CHECK(r.exit_code == 2);
  CHECK(t::contains(r.err, "tsi: error: reference: rk78 on the filtered problem would take at least 1.27e+06 steps"));
  CHECK(t::contains(r.err, "more than --max-steps = 1e+06"));
  CHECK(t::contains(r.err, "--max-steps N"));
  CHECK_FALSE(t::fs::exists(dir.path() / "out" / "result.json"));
}

TEST_CASE("max-steps: a study is refused before any run when one of its runs exceeds --max-steps") {
  t::TempDir dir;
  const t::Json spec = {{"kind", "conservation"},
                        {"base", t::small_config()},
                        {"vary", {{"time.h", {0.25, 0.0625}}}}};
  const std::string file = t::write_config(dir, spec, "study.json");
  const t::CommandResult r =
      t::run_tsi({"study", file, "--out", dir / "out", "--no-plots", "--max-steps", "10"});
  INFO(r.describe());
  CHECK(r.exit_code == 2);
  CHECK(t::contains(r.err, "tsi: error: time.h: got 0.0625: the run would take 16 steps"));
  CHECK(t::contains(r.err, "(run r0002: time.h=0.0625)"));
  CHECK_FALSE(t::fs::exists(dir.path() / "out"));
  const t::CommandResult ok = t::run_tsi({"study", file, "--out", dir / "out", "--no-plots", "--max-steps", "16"});
  INFO(ok.describe());
  CHECK(ok.exit_code == 0);
}

TEST_CASE("full disk: a run whose invariants.csv cannot grow stops with exit code 3 and valid files") {
  t::TempDir dir;
  // 10000 rows of about 170 bytes: far more than the 200 kB a file may have here.
  const std::string config = t::write_config(dir, long_hh_config(10000));
  t::CommandEnv env;
  env.file_size_limit = 200000;
  const t::CommandResult r = t::run_tsi({"run", config, "--out", dir / "out"}, env);
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "tsi: error: cannot write " + (dir / "out") + "/invariants.csv.partial: File too large"));
  CHECK(t::contains(r.err, "invariants.csv keeps the rows up to t = "));

  const t::Json result = t::read_json(dir.path() / "out" / "result.json");
  CHECK(result.at("status") == "failed");
  CHECK(t::contains(result.at("message").get<std::string>(), "cannot write"));
  const long steps = result.at("steps").get<long>();
  CHECK(steps > 100);
  CHECK(steps < 10000);
  CHECK(result.at("u_final").size() == 4);
  const long rows = check_valid_csv(dir.path() / "out" / "invariants.csv");
  CHECK(rows > 100);
  CHECK(rows <= steps + 1);
  CHECK(t::fs::file_size(dir.path() / "out" / "invariants.csv") <= 200000);
  check_no_temporaries(dir.path() / "out");
}

TEST_CASE("full disk: when result.json itself cannot be written, no partial file is left, only a short record") {
  t::TempDir dir;
  t::CommandEnv env;
  env.file_size_limit = 1500;  // invariants.csv of 4 steps fits, result.json (about 3 kB) does not
  const t::CommandResult r =
      t::run_tsi({"run", t::write_config(dir, t::small_config()), "--out", dir / "out"}, env);
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "tsi: error: cannot write " + (dir / "out") + "/result.json: File too large"));
  // In its place, a short record of the failure (it fits where the whole one did not).
  const t::Json result = t::read_json(dir.path() / "out" / "result.json");
  CHECK(result.at("status") == "failed");
  CHECK(t::contains(result.at("message").get<std::string>(), "result.json: File too large"));
  CHECK(t::contains(result.at("message").get<std::string>(), "the run's own status: completed"));
  CHECK(check_valid_csv(dir.path() / "out" / "invariants.csv") == 5);
  check_no_temporaries(dir.path() / "out");
}

TEST_CASE("unwritable output: --out removed mid-run gives exit code 3 naming the file, and result.json") {
  t::TempDir dir;
  const std::string out = dir / "out";
  const std::string config = t::write_config(dir, long_hh_config(300000));  // about 1.5 s
  std::thread remover([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    std::error_code ec;
    t::fs::remove_all(out, ec);
  });
  const t::CommandResult r = t::run_tsi({"run", config, "--out", out});
  remover.join();
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "tsi: error: cannot rename " + out + "/invariants.csv.partial to " + out +
                               "/invariants.csv: No such file or directory"));
  CHECK(t::read_json(t::fs::path(out) / "result.json").at("steps") == 300000);
}

namespace {

// Two runs whose invariants.csv outgrow full_disk()'s 200 kB, as a study.
t::Json two_long_runs() {
  return {{"kind", "conservation"}, {"base", long_hh_config(10000)}, {"vary", {{"scheme.name", {"se1", "se2"}}}}};
}

// A disk that fills at 200 kB per file: RLIMIT_FSIZE, writes beyond it fail with EFBIG.
t::CommandEnv full_disk() {
  t::CommandEnv env;
  env.file_size_limit = 200000;
  return env;
}

// The two runs of a study stopped by a full disk: failed, with what they made kept whole.
void check_full_disk_runs(const t::fs::path& out) {
  for (const std::string id : {"r0001", "r0002"}) {
    const t::fs::path run = out / "runs" / id;
    const t::Json result = t::read_json(run / "result.json");
    CHECK(result.at("status") == "failed");
    CHECK(result.at("steps").get<long>() > 100);
    CHECK(check_valid_csv(run / "invariants.csv") > 100);
  }
  check_no_temporaries(out);
}

}  // namespace

TEST_CASE("full disk: a study keeps every run's result.json and its table, and exits with 3") {
  t::TempDir dir;
  const t::Json spec = two_long_runs();
  const t::CommandEnv env = full_disk();
  const t::CommandResult r = t::run_tsi(
      {"study", t::write_config(dir, spec, "study.json"), "--out", dir / "out", "--no-plots", "--jobs", "1"}, env);
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "tsi: error: r0001: cannot write " + (dir / "out") +
                               "/runs/r0001/invariants.csv.partial: File too large"));
  CHECK(t::contains(r.err, "r0002: cannot write"));

  const t::Json study = t::read_json(dir.path() / "out" / "study.json");
  REQUIRE(study.at("table").size() == 2);
  for (const auto& row : study.at("table")) CHECK(row.at("status") == "failed");
  const std::vector<std::string> table = t::lines_of(t::read_text(dir.path() / "out" / "table.csv"));
  CHECK(table.size() == 3);
  check_full_disk_runs(dir.path() / "out");
}

TEST_CASE("full disk: a shard keeps every run's result.json and its shard.json, and exits with 3") {
  t::TempDir dir;
  const t::Json spec = two_long_runs();
  const t::CommandEnv env = full_disk();
  const t::CommandResult r = t::run_tsi({"study", t::write_config(dir, spec, "study.json"), "--out", dir / "out",
                                         "--no-plots", "--jobs", "1", "--shard", "1/1"},
                                        env);
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "tsi: error: r0001: cannot write " + (dir / "out") +
                               "/runs/r0001/invariants.csv.partial: File too large"));
  const t::Json shard = t::read_json(dir.path() / "out" / "shard.json");
  REQUIRE(shard.at("runs").size() == 2);
  check_full_disk_runs(dir.path() / "out");
}

#ifdef TSI_TEST_MPIEXEC
TEST_CASE("unwritable output: an MPI study whose runs/ cannot be written reports each run and exits with 3") {
  // A file size limit stops Open MPI itself (its shared-memory files), so the runs' directory
  // is made unwritable instead: runs/ becomes a file while the study computes its reference.
  t::TempDir dir;
  const t::Json spec = {{"kind", "convergence"},
                        {"base", {{"model", {{"name", "henon-heiles"}, {"eps", 0.01}}},
                                  {"time", {{"t_end", 100.0}}},
                                  {"reference", t::Json::object()}}},
                        {"vary", {{"time.h", {0.05, 0.025}}}}};
  const std::string out = dir / "out";
  std::thread blocker([&] {
    const auto start = std::chrono::steady_clock::now();
    while (!t::fs::exists(t::fs::path(out) / "runs") && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    // A rank may make runs/ID again between the removal and the write: then try again. Nothing
    // may throw here (a thread); if runs/ never becomes a file, the checks below fail.
    for (int attempt = 0; attempt < 1000; ++attempt) {
      std::error_code ec;
      t::fs::remove_all(t::fs::path(out) / "runs", ec);
      try {
        t::write_text(t::fs::path(out) / "runs", "not a directory\n");
        if (t::fs::is_regular_file(t::fs::path(out) / "runs", ec)) return;
      } catch (const std::exception&) {
      }
    }
  });
  t::CommandEnv env = t::mpirun_env();
  env.timeout_seconds = 300.0;
  const t::CommandResult r = t::run_command(TSI_TEST_MPIEXEC,
                                            {"-np", "2", "--oversubscribe", "--allow-run-as-root", TSI_TEST_RUNNER,
                                             "study", t::write_config(dir, spec, "study.json"), "--out", out, "--no-plots"},
                                            env);
  blocker.join();
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);  // rank 0's code, passed on by mpirun
  CHECK(t::contains(r.err, "r0001: "));
  CHECK(t::contains(r.err, "r0002: "));
  const t::Json study = t::read_json(t::fs::path(out) / "study.json");
  REQUIRE(study.at("table").size() == 2);
  for (const auto& row : study.at("table")) CHECK(row.at("status") == "failed");
}
#endif

TEST_CASE("memory: the peak memory of a run with output every step does not grow with its length") {
  // invariants.csv is streamed (at most 64 KiB held), so 10 times the steps and rows take
  // the same memory. Measured with the README's 0.16M and 1.6M steps too.
  t::TempDir dir;
  long rss[2] = {0, 0};
  const long steps[2] = {20000, 200000};
  const std::string names[2] = {"short", "long"};
  for (int k = 0; k < 2; ++k) {
    const std::string out = dir / names[k];
    const std::string config = t::write_config(dir, long_hh_config(steps[k]), names[k] + ".json");
    t::CommandEnv env;
#if defined(__SANITIZE_ADDRESS__)
    // ASan holds freed memory in a quarantine (256 MB) that grows with the run's allocations:
    // without it the allocator reuses memory as the normal one does, and the check stands.
    const char* asan = std::getenv("ASAN_OPTIONS");
    env.set["ASAN_OPTIONS"] = std::string(asan ? asan : "") + ":quarantine_size_mb=0";
#endif
    const t::CommandResult r = t::run_tsi({"run", config, "--out", out}, env);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    CHECK(t::read_json(t::fs::path(out) / "result.json").at("steps") == steps[k]);
    CHECK(t::fs::file_size(t::fs::path(out) / "invariants.csv") > static_cast<std::uintmax_t>(100 * steps[k]));
    rss[k] = r.max_rss_kb;
  }
  INFO("peak RSS: " << rss[0] << " KiB for " << steps[0] << " steps, " << rss[1] << " KiB for " << steps[1]);
  CHECK(rss[0] > 0);
  CHECK(static_cast<double>(rss[1]) < 1.2 * static_cast<double>(rss[0]));
}

#if !defined(__SANITIZE_ADDRESS__)
TEST_CASE("memory: SE1, SE2, FD and ME peak at most 8 states of resident memory at NLS n_x = 8192, n_tau = 64") {
  // The state (8.4 MB) dominates there: the process's own memory (libraries, plans; about 12 MB,
  // 1.4 states) included, a run holds the state, its scheme's vectors, a slice of the model's
  // grid, and before the steps its prepared data. Measured: SE1 6.1, SE2 7.1, FD 7.2, ME 5.1.
  // (AddressSanitizer's shadow memory and quarantine would be counted too: not there.)
  t::TempDir dir;
  for (const char* scheme : {"se1", "se2", "fd", "me"}) {
    CAPTURE(scheme);
    const t::Json config = {{"model", {{"name", "nls"}, {"eps", 0.01}, {"n_x", 8192}}},
                            {"reformulation", {{"name", "two-scale"}, {"n_tau", 64}}},
                            {"scheme", {{"name", scheme}}},
                            {"time", {{"h", 0.001}, {"t_end", 0.002}}},
                            {"output", {{"every", 1000}}}};
    const std::string out = dir / scheme;
    const t::CommandResult r =
        t::run_tsi({"--threads", "1", "run", t::write_config(dir, config, std::string(scheme) + ".json"), "--out", out});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const t::Json memory = t::read_json(t::fs::path(out) / "result.json").at("memory");
    const double state = memory.at("state_bytes").get<double>();
    CHECK(state == 16.0 * 8192 * 64);
    const double peak = memory.at("process_peak_rss_bytes").get<double>() / state;
    INFO("peak RSS / state: " << peak);
    CHECK(peak <= 8.0);
    // The footprint the run was checked against bounds what it took (the process's own memory
    // apart).
    CHECK(peak - 2.0 <= memory.at("footprint_vectors").get<double>());
  }
}
#endif

TEST_CASE("io limits: a final result.json that cannot be written leaves no checkpoint saying \"running\"") {
  // Checkpoints at every clock tick write a result.json of about 16 KB; the final one, with
  // the dense output's 4,000 values inline, is about 160 KB: past a 100 KB file size limit.
  t::TempDir dir;
  t::Json config = long_hh_config(2000);
  t::Json times = t::Json::array();
  for (int k = 0; k < 1000; ++k) times.push_back(20.0 * k / 1000.0);
  config["output"] = {{"every", 100000}, {"checkpoint_seconds", 1e-9}, {"times", times}};
  t::CommandEnv env;
  env.file_size_limit = 100 * 1024;
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"}, env);
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "result.json"));
  // The short record of the failure fits where the whole one did not.
  const t::Json result = t::read_json(dir.path() / "out" / "result.json");
  CHECK(result.at("status") == "failed");
  CHECK(t::contains(result.at("message").get<std::string>(), "the run's own status: completed"));
  CHECK(result.at("steps") == 2000);
  check_no_temporaries(dir.path());
}
