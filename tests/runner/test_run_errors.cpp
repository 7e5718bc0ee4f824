// Bad input to `tsi run`: exit code 2, no signal, no files written, and a message on stderr
// "tsi: error: FIELD: ..." that names the field, the offending value and what was expected.
#include <doctest/doctest.h>

#include <fstream>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace {

using namespace tsi::test;


/// Checks a bad-input outcome: exit code 2, the "tsi: error: FIELD:" prefix, every fragment.
void check_bad_input(const CommandResult& r, const std::string& field, const std::vector<std::string>& fragments) {
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "tsi: error: " + field + ":"));
  for (const auto& f : fragments) {
    INFO("expected on stderr: " << f);
    CHECK(contains(r.err, f));
  }
}

/// Runs the example config with `--set` overrides into a fresh directory; checks that bad
/// input writes nothing and returns the outcome.
CommandResult run_example_with(const std::vector<std::string>& assignments) {
  TempDir dir;
  const std::string out = dir / "out";
  std::vector<std::string> args = {"run", example_config(), "--out", out};
  for (const auto& a : assignments) {
    args.push_back("--set");
    args.push_back(a);
  }
  CommandResult r = run_tsi(args);
  if (r.exit_code == 2) {
    INFO(r.describe());
    CHECK_FALSE(fs::exists(fs::path(out) / "result.json"));
  }
  return r;
}

/// Runs a config given as JSON text into a fresh directory.
CommandResult run_config_text(const std::string& text, const std::vector<std::string>& extra = {}) {
  TempDir dir;
  const std::string config = dir / "config.json";
  write_text(config, text);
  const std::string out = dir / "out";
  std::vector<std::string> args = {"run", config, "--out", out};
  args.insert(args.end(), extra.begin(), extra.end());
  CommandResult r = run_tsi(args);
  if (r.exit_code == 2) {
    INFO(r.describe());
    CHECK_FALSE(fs::exists(fs::path(out) / "result.json"));
  }
  return r;
}

CommandResult run_config(const Json& config, const std::vector<std::string>& extra = {}) {
  return run_config_text(config.dump(2), extra);
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("run errors: --device cuda is refused before anything runs where the device cannot take the run") {
  // A build without CUDA, or a machine without a device, names --device; a CUDA build on a GPU
  // names what the device does not run (here: the filtered problem).
  const Json nls = {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 16}}},
                    {"reformulation", {{"name", "filtered"}}},
                    {"scheme", {{"name", "se1"}}},
                    {"time", {{"h", 0.1}, {"t_end", 0.2}}}};
  const CommandResult r = run_config(nls, {"--device", "cuda"});
  INFO(r.describe());
  CHECK(r.exit_code == 2);
  CHECK((contains(r.err, "tsi: error: --device: got \"cuda\", but ") ||
         contains(r.err, "tsi: error: reformulation.name: got \"filtered\" with --device cuda")));
  const CommandResult unknown = run_config(nls, {"--device", "gpu"});
  CHECK(unknown.exit_code == 2);
  CHECK(contains(unknown.err, "--device: gpu not in {cpu,cuda}"));
  const CommandResult cpu = run_config(nls, {"--device", "cpu"});  // the default, named
  CHECK(cpu.exit_code == 0);
}

TEST_CASE("run errors: an unknown model lists the valid models") {
  check_bad_input(run_example_with({"model.name=no-such-model"}), "model.name",
                  {"unknown model", "\"no-such-model\"", "henon-heiles", "hh", "from a plugin needs the plugin loaded: --plugin FILE"});
}

TEST_CASE("run errors: an unknown scheme lists the valid schemes") {
  check_bad_input(run_example_with({"scheme.name=no-such-scheme"}), "scheme.name",
                  {"unknown scheme", "\"no-such-scheme\"", "se1", "rk78", "--plugin FILE"});
}

TEST_CASE("run errors: an unknown reformulation lists the valid reformulations") {
  check_bad_input(run_example_with({"reformulation.name=no-such-reformulation"}), "reformulation.name",
                  {"unknown reformulation", "\"no-such-reformulation\"", "two-scale", "filtered", "direct"});
}

TEST_CASE("run errors: eps outside 0 to 1") {
  SUBCASE("eps = 2") {
    check_bad_input(run_example_with({"model.eps=2"}), "model.eps", {"got 2", "expected", "(0, 1]"});
  }
  SUBCASE("eps = 0") {
    check_bad_input(run_example_with({"model.eps=0"}), "model.eps", {"got 0", "expected", "(0, 1]"});
  }
  SUBCASE("eps = -1") {
    check_bad_input(run_example_with({"model.eps=-1"}), "model.eps", {"got -1", "expected", "(0, 1]"});
  }
}

TEST_CASE("run errors: eps of the wrong type") {
  check_bad_input(run_example_with({"model.eps=\"abc\""}), "model.eps", {"got \"abc\"", "expected a number"});
}

TEST_CASE("run errors: a bare word where a number is expected") {
  check_bad_input(run_example_with({"time.h=fast"}), "time.h", {"got \"fast\"", "expected a number"});
}

TEST_CASE("run errors: a non-positive time step") {
  SUBCASE("h = 0") {
    check_bad_input(run_example_with({"time.h=0"}), "time.h", {"got 0", "expected", "(0, inf)"});
  }
  SUBCASE("h = -0.1") {
    check_bad_input(run_example_with({"time.h=-0.1"}), "time.h", {"got -0.1", "expected", "(0, inf)"});
  }
}

TEST_CASE("run errors: a negative final time") {
  check_bad_input(run_example_with({"time.t_end=-1"}), "time.t_end", {"got -1", "expected", "[0, inf)"});
}

TEST_CASE("run errors: t_end that is not a whole number of steps") {
  check_bad_input(run_example_with({"time.h=0.3"}), "time.h", {"t_end = 1", "h = 0.3", "whole number of steps"});
}

TEST_CASE("run errors: n_tau must be a positive even integer") {
  SUBCASE("odd") {
    check_bad_input(run_example_with({"reformulation.n_tau=63"}), "reformulation.n_tau",
                    {"got 63", "even integer from 2 to 1048576"});
  }
  SUBCASE("zero") {
    check_bad_input(run_example_with({"reformulation.n_tau=0"}), "reformulation.n_tau",
                    {"got 0", "even integer from 2 to 1048576"});
  }
  SUBCASE("not an integer") {
    check_bad_input(run_example_with({"reformulation.n_tau=2.5"}), "reformulation.n_tau",
                    {"got 2.5", "integer"});
  }
  SUBCASE("negative") {
    check_bad_input(run_example_with({"reformulation.n_tau=-4"}), "reformulation.n_tau",
                    {"got -4", "even integer from 2 to 1048576"});
  }
  SUBCASE("beyond 32 bits: checked before it is narrowed, never run as 64") {
    check_bad_input(run_example_with({"reformulation.n_tau=4294967360"}), "reformulation.n_tau",
                    {"got 4294967360", "even integer from 2 to 1048576"});
  }
}

TEST_CASE("run errors: time.h larger than t_end, and a reference step that does not divide t_end") {
  check_bad_input(run_example_with({"time.h=1e10"}), "time.h", {"got 10000000000", "at most t_end"});
  check_bad_input(run_example_with({"time.h=1e308"}), "time.h", {"at most t_end"});
  check_bad_input(run_example_with({"reference={\"scheme\": \"se1\", \"reformulation\": \"two-scale\", \"h\": 0.3}"}),
                  "reference.h", {"got 0.3", "whole number"});
}

TEST_CASE("run errors: eps too small for 1/eps to be a double") {
  check_bad_input(run_example_with({"model.eps=5e-324"}), "model.eps", {"at least 1e-300"});
}

TEST_CASE("run errors: initial_data_order must be from 1 to 8") {
  check_bad_input(run_example_with({"reformulation.initial_data_order=9"}), "reformulation.initial_data_order",
                  {"got 9", "from 1 to 8"});
}

TEST_CASE("run errors: scheme parameters are checked") {
  SUBCASE("se1 tol = 0") {
    check_bad_input(run_example_with({"scheme.tol=0"}), "scheme.tol", {"got 0", "expected", "(0, 1)"});
  }
  SUBCASE("se1 max_iter = 0") {
    check_bad_input(run_example_with({"scheme.max_iter=0"}), "scheme.max_iter",
                    {"got 0", "integer from 1 to 1000000"});
  }
  SUBCASE("se1 max_iter = 2^32: never narrowed to zero sweeps") {
    check_bad_input(run_example_with({"scheme.max_iter=4294967296"}), "scheme.max_iter",
                    {"got 4294967296", "integer from 1 to 1000000"});
  }
}

TEST_CASE("run errors: output.every must be a positive integer") {
  check_bad_input(run_example_with({"output.every=0"}), "output.every", {"got 0", "positive integer"});
}

TEST_CASE("run errors: a scheme that cannot integrate the reformulation names the compatible ones") {
  const Json config = Json::parse(R"({
    "model": {"name": "henon-heiles", "eps": 0.1},
    "reformulation": {"name": "two-scale"},
    "scheme": {"name": "rk78"},
    "time": {"h": 0.25, "t_end": 1.0}
  })");
  check_bad_input(run_config(config), "reformulation.name",
                  {"\"rk78\"", "\"two-scale\"", "compatible reformulations: direct, filtered"});
}

TEST_CASE("run errors: the reference pair is checked for compatibility too") {
  const Json config = Json::parse(R"({
    "model": {"name": "henon-heiles", "eps": 0.1},
    "scheme": {"name": "se1"},
    "time": {"h": 0.25, "t_end": 1.0},
    "reference": {"scheme": "se1", "reformulation": "direct", "h": 0.25}
  })");
  check_bad_input(run_config(config), "reference.reformulation",
                  {"\"se1\"", "\"direct\"", "filtered, two-scale"});
}

TEST_CASE("run errors: an unknown reference scheme names reference.scheme") {
  const Json config = Json::parse(R"({
    "model": {"name": "henon-heiles", "eps": 0.1},
    "time": {"h": 0.25, "t_end": 1.0},
    "reference": {"scheme": "no-such-scheme"}
  })");
  check_bad_input(run_config(config), "reference.scheme", {"unknown scheme", "\"no-such-scheme\"", "rk78"});
}

TEST_CASE("run errors: a non-adaptive reference scheme needs a step") {
  const Json config = Json::parse(R"({
    "model": {"name": "henon-heiles", "eps": 0.1},
    "time": {"h": 0.25, "t_end": 1.0},
    "reference": {"scheme": "se1", "reformulation": "two-scale"}
  })");
  check_bad_input(run_config(config), "reference.h", {"\"se1\"", "not adaptive"});
}

TEST_CASE("run errors: a missing config file") {
  TempDir dir;
  const std::string missing = dir / "no-such-config.json";
  const CommandResult r = run_tsi({"run", missing, "--out", dir / "out"});
  check_bad_input(r, missing, {"cannot open"});
  CHECK_FALSE(fs::exists(dir.path() / "out"));
}

TEST_CASE("run errors: a malformed JSON file") {
  TempDir dir;
  const std::string config = dir / "broken.json";
  write_text(config, "{\"model\": {\"name\": \"henon-heiles\",\n");
  const CommandResult r = run_tsi({"run", config, "--out", dir / "out"});
  check_bad_input(r, config, {"malformed JSON", "line"});
  CHECK_FALSE(fs::exists(dir.path() / "out"));
}

TEST_CASE("run errors: a config that is not a JSON object") {
  check_bad_input(run_config_text("[1, 2, 3]"), "config", {"got [1,2,3]", "expected a JSON object"});
}

TEST_CASE("run errors: an unknown top-level section in a config file") {
  Json config = small_config();
  config["bogus_section"] = {{"x", 1}};
  check_bad_input(run_config(config), "bogus_section",
                  {"unknown section", "valid sections are", "model", "reformulation", "scheme", "time", "reference"});
}

TEST_CASE("run errors: a section that is not an object") {
  Json config = small_config();
  config["time"] = 5;
  check_bad_input(run_config(config), "time", {"got 5", "expected an object"});
}

TEST_CASE("run errors: a config without a model name") {
  const Json config = Json::parse(R"({"model": {"eps": 0.1}, "time": {"h": 0.25}})");
  check_bad_input(run_config(config), "model.name", {"missing"});
}

TEST_CASE("run errors: an unknown parameter in a config file lists the valid ones") {
  Json config = small_config();
  config["scheme"]["tolerance"] = 1e-8;
  check_bad_input(run_config(config), "scheme.tolerance",
                  {"unknown parameter", "valid parameters are", "max_iter", "tol"});
}

TEST_CASE("run errors: --set of a parameter that does not exist") {
  check_bad_input(run_example_with({"model.foo=1"}), "model.foo",
                  {"unknown parameter", "valid parameters are", "eps", "u0"});
}

TEST_CASE("run errors: --set in a section that does not exist") {
  const CommandResult r = run_example_with({"nosuch.x=1"});
  check_bad_input(r, "--set nosuch.x", {"unknown section", "\"nosuch\"", "valid sections are", "model", "time"});
}

TEST_CASE("run errors: --set without a value") {
  check_bad_input(run_example_with({"model.eps"}), "--set", {"\"model.eps\"", "expected key.path=value"});
}

TEST_CASE("run errors: --set with an empty key component") {
  check_bad_input(run_example_with({"model..eps=0.1"}), "--set model..eps", {"empty component"});
}

TEST_CASE("run errors: --set through a value that is not an object") {
  check_bad_input(run_example_with({"model.eps.x=1"}), "--set model.eps.x", {"not an object"});
}

TEST_CASE("run errors: model.u0 of the wrong length is bad input") {
  // Validated when the run starts; bad input all the same: exit code 2.
  check_bad_input(run_example_with({"model.u0=[0.1, 0.2, 0.3]"}), "model.u0", {"got 3 entries", "expected 4"});
}

TEST_CASE("run errors: a model.u0 entry that is not a number is bad input") {
  check_bad_input(run_example_with({"model.u0=[0.1, 0.2, 0.3, \"x\"]"}), "model.u0[3]",
                  {"got \"x\"", "expected a number"});
}

TEST_CASE("run errors: a missing plugin in the config names the plugins field and the file") {
  TempDir dir;
  Json config = small_config();
  config["plugins"] = {"no-such-plugin.so"};
  const std::string file = write_config(dir, config);
  const CommandResult r = run_tsi({"run", file, "--out", dir / "out"});
  check_bad_input(r, "plugins", {"no-such-plugin.so", "no such file"});
}

TEST_CASE("run errors: plugins that is not a list") {
  Json config = small_config();
  config["plugins"] = "tsi_fixture_good.so";
  check_bad_input(run_config(config), "plugins", {"got \"tsi_fixture_good.so\"", "expected a list"});
}

TEST_CASE("run errors: a missing CONFIG argument is a usage error") {
  const CommandResult r = run_tsi({"run"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "config"));
}

TEST_CASE("run errors: an unknown command-line option is a usage error") {
  const CommandResult r = run_tsi({"run", example_config(), "--no-such-option"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "--no-such-option"));
}

}  // TEST_SUITE

TEST_CASE("run errors: a complex u0 for a real model is bad input, never silently dropped") {
  TempDir dir;
  const CommandResult r = run_tsi({"run", example_config(), "--out", dir / "out", "--set",
                                   "model.u0=[0.1, [0.1, 0.2], 0.1, 0.1]"});
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "model.u0[1]: got [0.1,0.2], expected a real number"));
}

TEST_CASE("run errors: a config's JSON is read strictly, every problem named and none a crash") {
  TempDir dir;
  const auto run_text = [&](const std::string& text) {
    const std::string path = dir / "config.json";
    std::ofstream(path) << text;
    return run_tsi({"run", path, "--out", dir / "out"});
  };
  SUBCASE("a duplicated key, which a parser would silently resolve to its last value") {
    check_bad_input(run_text(R"({"model": {"name": "hh", "eps": 0.1, "eps": 0.5}})"), dir / "config.json: model",
                    {"duplicate key \"eps\""});
  }
  SUBCASE("a number beyond a double names its field") {
    check_bad_input(run_text(R"({"model": {"name": "hh", "eps": 1e400}})"), dir / "config.json: model.eps",
                    {"out of the range of a double"});
  }
  SUBCASE("nesting 60000 deep is refused, not a stack overflow") {
    check_bad_input(run_text(std::string(60000, '[') + std::string(60000, ']')), dir / "config.json",
                    {"nested deeper than 64 levels"});
  }
  SUBCASE("a directory is not a config") {
    const CommandResult r = run_tsi({"run", dir.path().string(), "--out", dir / "out"});
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "is a directory"));
  }
  SUBCASE("--set: a value nested 60000 deep, and a key path of 60000 components") {
    check_bad_input(run_example_with({"model.u0=" + std::string(60000, '[') + std::string(60000, ']')}),
                    "--set model.u0", {"nested deeper than 64 levels"});
    std::string path = "model";
    for (int i = 0; i < 60000; ++i) path += ".a";
    const CommandResult r = run_example_with({path + "=1"});
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "a key path of 60001 components"));
  }
}

TEST_CASE("run errors: an --out that cannot hold the results is refused before anything is computed") {
  TempDir dir;
  const std::string file = dir / "taken";
  std::ofstream(file) << "not a directory\n";
  for (const std::string& out : {file, file + "/sub"}) {
    const CommandResult r = run_tsi({"run", example_config(), "--out", out, "--set", "time.t_end=1000"});
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "tsi: error: --out:"));
    CHECK_FALSE(contains(r.out, "running"));
  }
  const CommandResult study = run_tsi({"study", (fs::path(TSI_TEST_SOURCE_DIR) / "examples/paper/hh-convergence.json").string(),
                                       "--out", file, "--no-plots"});
  INFO(study.describe());
  CHECK(study.exit_code == 2);
  CHECK(contains(study.err, "tsi: error: --out:"));
}

TEST_CASE("run errors: --fft-threads beyond 1024 is refused, not a run that never plans") {
  const CommandResult r = run_tsi({"--fft-threads", "100000", "list", "models"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "--fft-threads"));
}

TEST_CASE("run errors: a reference that could not finish is refused before the run, with its cost") {
  // rk78 on the filtered problem at eps = 1e-300 needs 8 steps per period 2 pi eps: ~1e300.
  check_bad_input(run_example_with({"model.eps=1e-300", "reference={}"}), "reference",
                  {"would take at least", "use a two-scale reference"});
  check_bad_input(run_example_with({"reference={\"scheme\": \"se1\", \"reformulation\": \"two-scale\", \"h\": 1e-10}"}),
                  "reference.h", {"got 1e-10", "1e+10 steps", "at most 1e+09", "--max-steps N"});
}

TEST_CASE("run errors: a run that cannot fit in memory is refused before anything is allocated") {
  // NLS at the largest n_x with n_tau = 1024: about 86 GB (5 vectors of 17 GB for SE1), far beyond a
  // test machine.
  TempDir dir;
  const CommandResult r = run_tsi({"run", (fs::path(TSI_TEST_SOURCE_DIR) / "examples/nls-se1.json").string(), "--out",
                                   dir / "out", "--set", "model.n_x=1048576", "--set", "reformulation.n_tau=1024"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "tsi: error: reformulation.n_tau: got 1024: with the model's 1048576 unknowns a run needs"));
  CHECK(contains(r.err, "GB available"));
}

TEST_CASE("run errors: under an address-space limit a grid or a state that does not fit is refused, not bad_alloc") {
  // ulimit -v 2 GB: a 3-D grid of 512^3 points (the model's own grids alone 4.3 GB), and a 1-D
  // run whose two-scale state (n_tau 1024, 65536 unknowns: 1 GB a vector) does not fit either.
  TempDir dir;
  CommandEnv env;
  env.address_space_limit = 2LL << 30;
  const CommandResult grid = run_tsi({"run", (fs::path(TSI_TEST_SOURCE_DIR) / "examples/nls-se1.json").string(), "--out",
                                      dir / "grid", "--set", "model.dims=3", "--set", "model.n_x=512"},
                                     env);
  INFO(grid.describe());
  CHECK(grid.signal == 0);
  CHECK(grid.exit_code == 2);
  CHECK(contains(grid.err, "tsi: error: model.n_x: a grid of 512 x 512 x 512 = 134217728 points"));
  CHECK(contains(grid.err, "this process can allocate"));
  CHECK_FALSE(contains(grid.err, "bad_alloc"));
  const CommandResult state = run_tsi({"run", (fs::path(TSI_TEST_SOURCE_DIR) / "examples/nls-se1.json").string(), "--out",
                                       dir / "state", "--set", "model.n_x=65536", "--set", "reformulation.n_tau=1024"},
                                      env);
  INFO(state.describe());
  CHECK(state.exit_code == 2);
  CHECK(contains(state.err, "tsi: error: reformulation.n_tau: got 1024"));
  CHECK(contains(state.err, "this process has"));
  CHECK_FALSE(contains(state.err, "bad_alloc"));
}

TEST_CASE("run errors: dense output that cannot be kept in memory is refused before the run, naming output.times") {
  // 100,000 times of a 1024 x 1024 grid: 1.7 TB of states.
  TempDir dir;
  Json config = read_json(fs::path(TSI_TEST_SOURCE_DIR) / "examples/nls-se1.json");
  config["model"]["dims"] = 2;
  config["model"]["n_x"] = 1024;
  Json times = Json::array();
  for (int k = 0; k < 100000; ++k) times.push_back(config["time"]["t_end"].get<double>() * k / 100000.0);
  config["output"]["times"] = times;
  const CommandResult r = run_tsi({"run", write_config(dir, config), "--out", dir / "out"});
  INFO(r.err);
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "tsi: error: output.times: got 100000 times: their states (100000 x 1048576 complex values) take"));
  CHECK(contains(r.err, "output.state_every"));
  CHECK_FALSE(fs::exists(dir.path() / "out" / "result.json"));
}
