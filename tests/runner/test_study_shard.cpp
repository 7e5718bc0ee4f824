// `tsi study --shard i/N` and `tsi study --merge`: the shards of a study, merged, give the
// table and study.json of the whole study run at once; bad splits and merges are refused.
#include <doctest/doctest.h>

#include <sstream>

#include "run_command.hpp"
#include "study_compare.hpp"

using namespace tsi::test;

namespace {

// Text from parts (GCC 12 warns, falsely, on "literal" + std::string under -O3: -Wrestrict).
template <class... Parts>
std::string cat(const Parts&... parts) {
  std::ostringstream s;
  (s << ... << parts);
  return s.str();
}

// 12 runs sharing 2 references, with a case that fails (an unconverged stage that stops).
Json shard_study() {
  return {{"kind", "convergence"},
          {"title", "shards"},
          {"base", {{"model", {{"name", "henon-heiles"}}}, {"time", {{"t_end", 1.0}}}, {"reference", Json::object()}}},
          {"vary", {{"model.eps", {1.0, 1.0 / 4096}}, {"time.h", {0.25, 0.125, 0.0625}}}},
          {"cases", {{{"label", "se1"}, {"set", {{"scheme.name", "se1"}}}},
                     {{"label", "stops"}, {"set", {{"scheme.name", "se2"}, {"scheme.max_iter", 1}, {"scheme.on_failure", "stop"}}}}}}};
}

}  // namespace

TEST_CASE("study --shard i/N, then --merge: the same table and study.json as the whole study") {
  TempDir dir;
  const std::string study = write_config(dir, shard_study(), "study.json");
  const auto whole = run_tsi({"study", study, "--out", dir / "whole", "--jobs", "1", "--no-plots"});
  REQUIRE_MESSAGE(whole.exit_code == 1, whole.describe());  // the "stops" case fails
  std::vector<std::string> merge = {"study", "--merge"};
  size_t runs = 0;
  for (int i = 1; i <= 3; ++i) {
    const std::string out = dir / cat("shard", i);
    const auto r = run_tsi({"study", study, "--shard", cat(i, "/3"), "--out", out, "--jobs", "1", "--no-plots"});
    INFO(r.describe());
    CHECK((r.exit_code == 0 || r.exit_code == 1));
    CHECK(contains(r.out, cat("shard ", i, "/3")));
    const Json record = read_json(fs::path(out) / "shard.json");
    CHECK(record["shard"]["index"] == i);
    CHECK(record["total_runs"] == 12);
    runs += record["runs"].size();
    CHECK_FALSE(fs::exists(fs::path(out) / "table.csv"));
    merge.push_back(out);
  }
  CHECK(runs == 12);
  std::reverse(merge.begin() + 2, merge.end());  // any order
  merge.insert(merge.end(), {"--out", dir / "merged", "--no-plots"});
  const auto merged = run_tsi(merge);
  INFO(merged.describe());
  CHECK(merged.exit_code == 1);
  CHECK(contains(merged.out, "se1 on henon-heiles"));
  CHECK(table_without_timings(fs::path(dir / "merged")) == table_without_timings(fs::path(dir / "whole")));
  CHECK(study_without_timings(fs::path(dir / "merged")) == study_without_timings(fs::path(dir / "whole")));
  CHECK(read_json(fs::path(dir / "merged") / "study.json")["shards"] == 3);
  for (int i = 1; i <= 12; ++i) {
    const std::string id = cat(i < 10 ? "r000" : "r00", i);
    CHECK(fs::is_regular_file(fs::path(dir / "merged") / "runs" / id / "result.json"));
    CHECK(fs::is_regular_file(fs::path(dir / "merged") / "runs" / id / "invariants.csv"));
  }
}

TEST_CASE("study --merge refuses missing, duplicated and foreign shards, naming them") {
  TempDir dir;
  Json spec = shard_study();
  spec["cases"] = Json::array({spec["cases"][0]});
  spec.erase("vary");
  spec["vary"] = {{"time.h", {0.25, 0.125}}};
  const std::string study = write_config(dir, spec, "study.json");
  for (int i = 1; i <= 2; ++i) {
    const auto r = run_tsi({"study", study, "--shard", cat(i, "/2"), "--out", dir / cat("s", i),
                            "--no-plots"});
    REQUIRE_MESSAGE(r.exit_code == 0, r.describe());
  }
  spec["title"] = "another";
  const auto other = run_tsi({"study", write_config(dir, spec, "other.json"), "--shard", "2/2", "--out", dir / "o2", "--no-plots"});
  REQUIRE_MESSAGE(other.exit_code == 0, other.describe());

  const auto missing = run_tsi({"study", "--merge", dir / "s1", "--out", dir / "m"});
  CHECK(missing.exit_code == 2);
  CHECK(contains(missing.err, "--merge: shard 2/2 is missing"));
  const auto twice = run_tsi({"study", "--merge", dir / "s1", dir / "s2", dir / "s1", "--out", dir / "m"});
  CHECK(twice.exit_code == 2);
  CHECK(contains(twice.err, "shard 1/2 is given twice"));
  const auto foreign = run_tsi({"study", "--merge", dir / "s1", dir / "o2", "--out", dir / "m"});
  CHECK(foreign.exit_code == 2);
  CHECK(contains(foreign.err, "is a shard of another study"));
  const auto not_shard = run_tsi({"study", "--merge", dir / "s1", dir.path().string(), "--out", dir / "m"});
  CHECK(not_shard.exit_code == 2);
  CHECK(contains(not_shard.err, "holds no shard.json"));
  const auto no_out = run_tsi({"study", "--merge", dir / "s1", dir / "s2"});
  CHECK(no_out.exit_code == 2);
  CHECK(contains(no_out.err, "--out: required with --merge"));
  CHECK_FALSE(fs::exists(fs::path(dir / "m") / "table.csv"));
  const auto ok = run_tsi({"study", "--merge", dir / "s2", dir / "s1", "--out", dir / "m", "--no-plots"});
  CHECK_MESSAGE(ok.exit_code == 0, ok.describe());
}

TEST_CASE("study --shard: i and N are checked, shards are numbered from 1") {
  TempDir dir;
  const std::string study = write_config(dir, shard_study(), "study.json");
  for (const char* bad : {"0/3", "4/3", "1/0", "a/b", "3", "1/2/3"}) {
    const auto r = run_tsi({"study", study, "--shard", bad, "--out", dir / "out", "--no-plots"});
    INFO(bad << "\n" << r.describe());
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, cat("--shard: got \"", bad, "\"")));
  }
  CHECK_FALSE(fs::exists(fs::path(dir / "out") / "shard.json"));
}
