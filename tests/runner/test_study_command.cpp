// `tsi study` end to end: the files and their schema, shared references, and a failing run
// that is recorded without stopping the others.
#include <doctest/doctest.h>

#include <cmath>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "run_command.hpp"

using namespace tsi::test;

namespace {

Json small_study() {
  return {{"kind", "convergence"},
          {"base", {{"model", {{"name", "henon-heiles"}, {"eps", 0.01}}}, {"time", {{"t_end", 1.0}}}, {"reference", Json::object()}}},
          {"vary", {{"scheme.name", {"se1", "fd"}}, {"model.eps", {1.0, 1.0 / 4096}}, {"time.h", {0.25, 0.125, 0.0625}}}}};
}

}  // namespace

TEST_CASE("study: table.csv, study.json and one result per run, with orders and uniform errors") {
  TempDir dir;
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"study", write_config(dir, small_study(), "study.json"), "--out", out, "--jobs", "2", "--no-plots"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(contains(r.out, "se1 on henon-heiles"));
  CHECK(contains(r.out, "LS order"));
  const auto lines = lines_of(read_text(fs::path(out) / "table.csv"));
  REQUIRE(lines.size() == 13);  // header and 12 runs
  const std::vector<std::string> header = csv_fields(lines[0]);
  for (const char* column : {"model", "scheme", "reformulation", "eps", "h", "t_end", "n_tau", "error", "order", "err_H",
                             "err_I", "err_m", "sweeps_mean", "rhs_evals", "wall_seconds", "status"})
    CHECK(std::find(header.begin(), header.end(), column) != header.end());
  const Json study = read_json(fs::path(out) / "study.json");
  for (const char* key : {"tsi_version", "study", "machine", "table", "convergence", "wall_seconds"})
    CHECK(study.contains(key));
  REQUIRE(study["table"].size() == 12);
  for (const auto& row : study["table"]) {
    CHECK(row["status"] == "completed");
    CHECK(fs::is_regular_file(fs::path(out) / "runs" / row["id"].get<std::string>() / "result.json"));
    if (row["h"].get<double>() < 0.25) CHECK(std::abs(row["order"].get<double>() - 2.0) <= 0.15);
  }
  CHECK(study["convergence"]["series"].size() == 4);
  CHECK(study["convergence"]["uniform"].size() == 2);
  // One reference per eps, shared: every run at the same eps reports the same reference state.
  std::map<double, std::set<std::string>> references;
  for (const auto& row : study["table"]) {
    const Json result = read_json(fs::path(out) / "runs" / row["id"].get<std::string>() / "result.json");
    references[row["eps"].get<double>()].insert(result["error"]["reference"]["u_final"].dump());
  }
  REQUIRE(references.size() == 2);
  for (const auto& [eps, states] : references) CHECK(states.size() == 1);
}

TEST_CASE("study: a failing run is recorded with its message and the others complete") {
  TempDir dir;
  Json spec = small_study();
  spec["vary"] = {{"time.h", {0.25, 0.125}}};
  spec["cases"] = {{{"label", "ok"}},
                   {{"label", "stops"}, {"set", {{"scheme.max_iter", 1}, {"scheme.on_failure", "stop"}}}}};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"study", write_config(dir, spec, "study.json"), "--out", out, "--no-plots"});
  INFO(r.describe());
  CHECK(r.exit_code == 1);
  const Json study = read_json(fs::path(out) / "study.json");
  REQUIRE(study["table"].size() == 4);
  int completed = 0, failed = 0;
  for (const auto& row : study["table"]) {
    if (row["status"] == "completed") ++completed;
    if (row["status"] == "failed") {
      ++failed;
      CHECK(row["label"] == "stops");
      CHECK(contains(row["message"].get<std::string>(), "max_iter = 1"));
    }
  }
  CHECK(completed == 2);
  CHECK(failed == 2);
}

TEST_CASE("study: a completed run's warnings are listed, and kept in study.json") {
  // NLS at eps = 0.5 with SE1 loses its coherence in tau by t = 40 (see test_run_command.cpp);
  // at eps = 0.01 it does not.
  TempDir dir;
  const Json spec = {{"kind", "conservation"},
                     {"base", {{"model", {{"name", "nls"}}},
                               {"scheme", {{"name", "se1"}}},
                               {"time", {{"t_end", 40.0}, {"h", 0.05}}},
                               {"output", {{"every", 20}}}}},
                     {"vary", {{"model.eps", {0.5, 0.01}}}}};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"study", write_config(dir, spec, "study.json"), "--out", out, "--no-plots"});
  INFO(r.describe());
  CHECK(r.exit_code == 0);
  CHECK(contains(r.out, "warning r0001 (se1, eps = 0.5, h = 0.05): the tau profile of U lost its coherence at t = "));
  CHECK_FALSE(contains(r.out, "warning r0002"));
  const Json study = read_json(fs::path(out) / "study.json");
  REQUIRE(study["table"].size() == 2);
  // The coherence warning comes first; the roughness one follows a little later.
  REQUIRE(study["table"][0]["warnings"].size() >= 1);
  CHECK(contains(study["table"][0]["warnings"][0].get<std::string>(), "lost its coherence"));
  CHECK(study["table"][1]["warnings"].empty());
}

TEST_CASE("study: the invariants a model declares get a column of their largest change") {
  TempDir dir;
  const Json spec = {{"kind", "conservation"},
                     {"base", {{"model", {{"eps", 0.1}}}, {"time", {{"t_end", 1.0}, {"h", 0.25}}}}},
                     {"vary", {{"model.name", {"nls", "henon-heiles"}}}}};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"study", write_config(dir, spec, "study.json"), "--out", out, "--no-plots"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(contains(r.out, "max err_P"));
  const auto lines = lines_of(read_text(fs::path(out) / "table.csv"));
  REQUIRE(lines.size() == 3);
  const auto header = csv_fields(lines[0]);
  // After the fixed columns (which keep their places), before the message.
  const auto at = [&header](const std::string& c) {
    return std::find(header.begin(), header.end(), c) - header.begin();
  };
  REQUIRE(at("err_P") < static_cast<long>(header.size()));
  CHECK(at("err_P") == at("status") + 1);
  CHECK(header.back() == "message");
  const Json study = read_json(fs::path(out) / "study.json");
  REQUIRE(study["table"].size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    const Json& row = study["table"][i];
    const auto fields = csv_fields(lines[i + 1]);
    REQUIRE(fields.size() == header.size());
    const std::string cell = fields[static_cast<size_t>(at("err_P"))];
    if (row["model"] == "nls") {
      const Json result = read_json(fs::path(out) / "runs" / row["id"].get<std::string>() / "result.json");
      const double max_change = result["invariants"]["P"]["max_change"];
      CHECK(max_change > 0.0);
      CHECK(row["err_P"].get<double>() == max_change);
      CHECK(std::stod(cell) == doctest::Approx(max_change).epsilon(1e-9));
    } else {
      CHECK_FALSE(row.contains("err_P"));
      CHECK(cell.empty());
    }
  }
}

TEST_CASE("study: a bad path is rejected before any run, naming the run and the path") {
  TempDir dir;
  Json spec = small_study();
  spec["vary"]["model.epz"] = {1.0};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"study", write_config(dir, spec, "study.json"), "--out", out});
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "model.epz: unknown parameter"));
  CHECK(contains(r.err, "run r0001"));
  CHECK_FALSE(fs::exists(fs::path(out) / "table.csv"));
}

TEST_CASE("study: one --out holds one study: another is refused, the same one replaces its runs") {
  TempDir dir;
  const Json first = {{"kind", "convergence"},
                      {"base", {{"model", {{"name", "hh"}}}, {"time", {{"t_end", 0.5}}}}},
                      {"vary", {{"time.h", {0.25, 0.125}}}}};
  Json second = first;
  second["vary"]["time.h"] = {0.5};
  const std::string out = dir / "out";
  const auto a = run_tsi({"study", write_config(dir, first, "first.json"), "--out", out, "--no-plots"});
  REQUIRE_MESSAGE(a.exit_code == 0, a.describe());
  fs::create_directories(fs::path(out) / "runs" / "r9999");  // a stale run
  const auto again = run_tsi({"study", write_config(dir, first, "first.json"), "--out", out, "--no-plots"});
  INFO(again.describe());
  CHECK(again.exit_code == 0);
  CHECK_FALSE(fs::exists(fs::path(out) / "runs" / "r9999"));
  CHECK(fs::exists(fs::path(out) / "runs" / "r0002" / "result.json"));
  const auto other = run_tsi({"study", write_config(dir, second, "second.json"), "--out", out, "--no-plots"});
  INFO(other.describe());
  CHECK(other.exit_code == 2);
  CHECK(contains(other.err, "holds the results of another study"));
  CHECK(fs::exists(fs::path(out) / "runs" / "r0002" / "result.json"));  // untouched
}

TEST_CASE("study: --force replaces another study's results, --resume keeps the finished runs of the same one") {
  TempDir dir;
  const Json first = {{"kind", "convergence"},
                      {"base", {{"model", {{"name", "hh"}}}, {"time", {{"t_end", 0.5}}}}},
                      {"vary", {{"time.h", {0.25, 0.125}}}}};
  Json second = first;
  second["vary"]["time.h"] = {0.5};
  const std::string out = dir / "out";
  const std::string first_path = write_config(dir, first, "first.json");
  REQUIRE(run_tsi({"study", first_path, "--out", out, "--no-plots"}).exit_code == 0);

  // --resume: r0001 is kept as it is on disk (a marker in its result.json survives, and reaches
  // the table), r0002, whose files are gone, runs again.
  const fs::path kept = fs::path(out) / "runs" / "r0001" / "result.json";
  Json marked = Json::parse(read_text(kept.string()));
  marked["wall_seconds"] = 12345.0;
  std::ofstream(kept) << marked.dump(2) << "\n";
  fs::remove_all(fs::path(out) / "runs" / "r0002");
  const auto resumed = run_tsi({"study", first_path, "--out", out, "--no-plots", "--resume"});
  INFO(resumed.describe());
  REQUIRE(resumed.exit_code == 0);
  CHECK(contains(resumed.out, "resumed: 1 of 2 runs finished earlier are kept, 1 to run"));
  CHECK(Json::parse(read_text(kept.string()))["wall_seconds"] == 12345.0);
  CHECK(fs::exists(fs::path(out) / "runs" / "r0002" / "invariants.csv"));
  CHECK(contains(read_text(out + "/table.csv"), "12345"));

  // Another study: refused with --resume, replaced with --force.
  const std::string second_path = write_config(dir, second, "second.json");
  const auto refused = run_tsi({"study", second_path, "--out", out, "--no-plots", "--resume"});
  CHECK(refused.exit_code == 2);
  CHECK(contains(refused.err, "--resume: "));
  const auto forced = run_tsi({"study", second_path, "--out", out, "--no-plots", "--force"});
  INFO(forced.describe());
  REQUIRE(forced.exit_code == 0);
  CHECK_FALSE(fs::exists(fs::path(out) / "runs" / "r0002"));
  CHECK(Json::parse(read_text(out + "/study.json"))["study"] == second);
  const auto both = run_tsi({"study", second_path, "--out", out, "--resume", "--force"});
  CHECK(both.exit_code == 2);
  CHECK(contains(both.err, "--resume: cannot be combined with --force"));
}
