// Every run config in examples/ runs to completion and meets its reference; every study (in
// examples/paper/, examples/long-time/ and examples/general/, and a file with a "kind" in examples/ or examples/pic/) expands (all its runs resolve) without
// running. New examples are picked up by the glob, so an example cannot rot unnoticed.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "run_command.hpp"

using namespace tsi::test;

namespace {

std::vector<fs::path> json_files(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".json") out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

// A study names its kind; a run config does not.
bool is_study(const fs::path& file) { return read_json(file).contains("kind"); }

}  // namespace

TEST_CASE("examples: every run config completes and meets its reference") {
  const auto files = json_files(fs::path(TSI_TEST_SOURCE_DIR) / "examples");
  REQUIRE(files.size() >= 4);
  for (const auto& file : files) {
    if (is_study(file)) continue;  // expanded below
    TempDir dir;
    const CommandResult r = run_tsi({"run", file.string(), "--out", dir / "out"});
    CAPTURE(file.filename().string());
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const Json result = read_json(fs::path(dir / "out") / "result.json");
    CHECK(result.at("status") == "completed");
    if (result.contains("error")) {
      const double error = result.at("error").at("relative");
      CHECK(error > 0.0);
      CHECK(error < 1e-2);  // second order at the examples' steps
    }
  }
}

TEST_CASE("examples: every study expands, and a bad path in one is caught") {
  // --set time.t_end=0 makes each run a zero-step run: this checks the files, not the numbers
  // (the numbers are the studies' own business and the numerics tests').
  auto files = json_files(fs::path(TSI_TEST_SOURCE_DIR) / "examples" / "paper");
  REQUIRE(files.size() >= 7);
  for (const auto& file : json_files(fs::path(TSI_TEST_SOURCE_DIR) / "examples"))
    if (is_study(file)) files.push_back(file);
  for (const auto& file : json_files(fs::path(TSI_TEST_SOURCE_DIR) / "examples" / "long-time")) files.push_back(file);
  for (const auto& file : json_files(fs::path(TSI_TEST_SOURCE_DIR) / "examples" / "general")) files.push_back(file);
  for (const auto& file : json_files(fs::path(TSI_TEST_SOURCE_DIR) / "examples" / "pic"))
    if (is_study(file)) files.push_back(file);
  for (const auto& file : files) {
    TempDir dir;
    // A case that sets its own t_end (a slow reference run to a shorter time) loses it in a copy
    // of the study, so that --set gives it 0 as the others (--set refuses a path a case sets).
    std::string study = file.string();
    Json spec = read_json(file);
    bool rewritten = false;
    for (Json& c : spec["cases"])
      if (c.contains("set") && c["set"].contains("time.t_end")) c["set"].erase("time.t_end"), rewritten = true;
    if (rewritten) study = write_config(dir, spec, file.filename().string());
    const CommandResult r = run_tsi({"study", study, "--out", dir / "out", "--no-plots", "--jobs", "2",
                                     "--set", "time.t_end=0", "--set", "reference=null"});
    CAPTURE(file.filename().string());
    INFO(r.describe());
    CHECK(r.exit_code == 0);
    CHECK(fs::is_regular_file(fs::path(dir / "out") / "table.csv"));
  }
}
