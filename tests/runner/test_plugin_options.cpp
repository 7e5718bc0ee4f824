// Plugins given to the runner: --plugin (an error when it fails), TSI_PLUGIN_PATH (a
// warning when one fails) and the "plugins" list of a config file.
#include <doctest/doctest.h>

#include <string>

#include "run_command.hpp"

namespace {

using namespace tsi::test;


Json entry_named(const Json& entries, const std::string& name) {
  for (const auto& e : entries)
    if (e.at("name") == name) return e;
  return nullptr;
}

/// A refused --plugin: exit code 2 (not a signal), an error line naming the file.
void check_refused(const CommandResult& r, const std::string& file, const std::string& reason) {
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "tsi: error:"));
  CHECK(contains(r.err, fs::path(file).filename().string()));
  CHECK(contains(r.err, reason));
  CHECK(r.out.empty());
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("plugins: --plugin adds the fixture model and scheme under the plugin's path") {
  const std::string good = fixture_plugin("good");
  const CommandResult r = run_tsi({"--plugin", good, "list", "--json"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json all = Json::parse(r.out);
  const Json model = entry_named(all.at("models"), "fixture-model");
  REQUIRE(model.is_object());
  CHECK(contains(model.at("provider").get<std::string>(), "tsi_fixture_good.so"));
  CHECK(model.at("aliases") == Json::array({"fm"}));
  const Json scheme = entry_named(all.at("schemes"), "fixture-scheme");
  REQUIRE(scheme.is_object());
  CHECK(contains(scheme.at("provider").get<std::string>(), "tsi_fixture_good.so"));
  // the shipped plugins are still there
  CHECK(entry_named(all.at("models"), "henon-heiles").is_object());
}

TEST_CASE("plugins: --plugin before list models --json") {
  const CommandResult r = run_tsi({"--plugin", fixture_plugin("good"), "list", "models", "--json"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json models = Json::parse(r.out).at("models");
  const Json model = entry_named(models, "fixture-model");
  REQUIRE(model.is_object());
  CHECK(contains(model.at("provider").get<std::string>(), "tsi_fixture_good.so"));
}

TEST_CASE("plugins: --plugin for another ABI is refused cleanly") {
  const std::string file = fixture_plugin("wrong_abi");
  check_refused(run_tsi({"--plugin", file, "list", "models", "--json"}), file, "ABI");
  const CommandResult r = run_tsi({"--plugin", file, "list"});
  CHECK(contains(r.err, "999"));
}

TEST_CASE("plugins: --plugin for another tsi major version is refused cleanly") {
  const std::string file = fixture_plugin("wrong_major");
  check_refused(run_tsi({"--plugin", file, "list"}), file, "major");
}

TEST_CASE("plugins: --plugin without the entry point is refused cleanly") {
  const std::string file = fixture_plugin("no_entry");
  check_refused(run_tsi({"--plugin", file, "list"}), file, "not a tsi plugin");
}

TEST_CASE("plugins: --plugin whose registration throws is refused cleanly") {
  const std::string file = fixture_plugin("throws");
  const CommandResult r = run_tsi({"--plugin", file, "list"});
  check_refused(r, file, "registration failed");
  CHECK(contains(r.err, "boom"));
}

TEST_CASE("plugins: --plugin that registers a taken name is refused and names both providers") {
  const std::string good = fixture_plugin("good"), duplicate = fixture_plugin("duplicate");
  const CommandResult r = run_tsi({"--plugin", good, "--plugin", duplicate, "list"});
  check_refused(r, duplicate, "already registered");
  CHECK(contains(r.err, "\"fixture-model\""));
  CHECK(contains(r.err, "tsi_fixture_good.so"));
}

TEST_CASE("plugins: --plugin of a file that does not exist is a usage error") {
  TempDir dir;
  const CommandResult r = run_tsi({"--plugin", dir / "no-such-plugin.so", "list"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "no-such-plugin.so"));
}

TEST_CASE("plugins: a refused --plugin stops a run before it writes anything") {
  TempDir dir;
  const std::string file = fixture_plugin("wrong_abi");
  const CommandResult r =
      run_tsi({"--plugin", file, "run", write_config(dir, small_config()), "--out", dir / "out"});
  check_refused(r, file, "ABI");
  CHECK_FALSE(fs::exists(dir.path() / "out"));
}

TEST_CASE("plugins: TSI_PLUGIN_PATH with broken plugins only warns") {
  CommandEnv env;
  env.set["TSI_PLUGIN_PATH"] = TSI_TEST_FIXTURE_DIR;

  SUBCASE("list shows fixture-model") {
    const CommandResult r = run_tsi({"list", "--json"}, env);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const Json all = Json::parse(r.out);
    const Json model = entry_named(all.at("models"), "fixture-model");
    REQUIRE(model.is_object());
    CHECK(contains(model.at("provider").get<std::string>(), TSI_TEST_FIXTURE_DIR));
    CHECK(entry_named(all.at("models"), "henon-heiles").is_object());
    // the broken fixtures are reported, not fatal
    CHECK(contains(r.err, "warn"));
    CHECK(contains(r.err, "tsi_fixture_wrong_abi.so"));
    CHECK(contains(r.err, "ABI"));
    CHECK(contains(r.err, "tsi_fixture_no_entry.so"));
    CHECK(contains(r.err, "tsi_fixture_throws.so"));
    CHECK_FALSE(contains(r.err, "tsi: error:"));
  }

  SUBCASE("a run still works") {
    TempDir dir;
    const std::string out = dir / "out";
    const CommandResult r = run_tsi({"run", write_config(dir, small_config()), "--out", out}, env);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const Json result = read_json(fs::path(out) / "result.json");
    CHECK(result.at("status") == "completed");
    CHECK(result.at("steps") == 4);
  }

  SUBCASE("the text list shows fixture-model") {
    const CommandResult r = run_tsi({"list", "models"}, env);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.out, "fixture-model"));
  }
}

TEST_CASE("plugins: TSI_PLUGIN_PATH naming a single good file and a missing entry") {
  TempDir dir;
  CommandEnv env;
  env.set["TSI_PLUGIN_PATH"] = fixture_plugin("good") + ":" + (dir / "nothing-here.so");
  const CommandResult r = run_tsi({"list", "models", "--json"}, env);
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json model = entry_named(Json::parse(r.out).at("models"), "fixture-model");
  REQUIRE(model.is_object());
  CHECK(contains(model.at("provider").get<std::string>(), "tsi_fixture_good.so"));
  CHECK(contains(r.err, "nothing-here.so"));
}

TEST_CASE("plugins: a config file's plugins list loads an absolute path") {
  TempDir dir;
  const std::string good = fs::canonical(fixture_plugin("good")).string();
  Json config = small_config();
  config["plugins"] = {good};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"run", write_config(dir, config), "--out", out});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json result = read_json(fs::path(out) / "result.json");
  CHECK(result.at("config").at("plugins") == Json::array({good}));
}

TEST_CASE("plugins: a model from a config file's plugin can be run") {
  TempDir dir;
  const Json config = {{"plugins", {fixture_plugin("good")}},
                       {"model", {{"name", "fm"}, {"eps", 0.5}}},
                       {"scheme", {{"name", "rk78"}}},
                       {"reformulation", {{"name", "filtered"}}},
                       {"time", {{"h", 0.25}, {"t_end", 1.0}}}};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"run", write_config(dir, config), "--out", out});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json result = read_json(fs::path(out) / "result.json");
  CHECK(result.at("config").at("model").at("name") == "fixture-model");
  CHECK(result.at("steps") == 4);
}

TEST_CASE("plugins: a relative path in a config file is relative to the config file") {
  TempDir dir;
  fs::create_directories(dir.path() / "configs" / "lib");
  fs::copy_file(fixture_plugin("good"), dir.path() / "configs" / "lib" / "tsi_fixture_good.so");
  const Json config = {{"plugins", {"lib/tsi_fixture_good.so"}},
                       {"model", {{"name", "fixture-model"}, {"eps", 0.5}}},
                       {"scheme", {{"name", "rk78"}}},
                       {"reformulation", {{"name", "filtered"}}},
                       {"time", {{"h", 0.5}, {"t_end", 1.0}}}};
  const std::string file = (dir.path() / "configs" / "run.json").string();
  write_text(file, config.dump(2));
  // run from another directory so that only the config's directory can explain the find
  const CommandResult r = run_tsi({"run", file, "--out", dir / "out"}, {}, fs::temp_directory_path().string());
  INFO(r.describe());
  CHECK(r.exit_code == 0);
}

TEST_CASE("plugins: a broken plugin in a config file is bad input naming the plugins field") {
  TempDir dir;
  Json config = small_config();
  config["plugins"] = {fixture_plugin("wrong_abi")};
  const std::string out = dir / "out";
  const CommandResult r = run_tsi({"run", write_config(dir, config), "--out", out});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(contains(r.err, "tsi: error: plugins:"));
  CHECK(contains(r.err, "tsi_fixture_wrong_abi.so"));
  CHECK(contains(r.err, "ABI"));
  CHECK_FALSE(fs::exists(fs::path(out) / "result.json"));
}

}  // TEST_SUITE
