// Plugins the `tsi` runner must refuse, each with a clear message naming the file and a
// non-zero exit, never a crash: a name already taken by a shipped plugin, structures of
// another size, and the other handshake failures.
#include <doctest/doctest.h>

#include <string>

#include "runner/run_command.hpp"
#include "tsi/plugin.hpp"

namespace {

namespace t = tsi::test;
namespace fs = std::filesystem;

bool mentions(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// `tsi --plugin FILE list`, which must fail with exit code 2 and an error naming FILE and `reason`.
t::CommandResult refused(const std::string& name, const std::string& reason) {
  const std::string file = t::fixture_plugin(name);
  const t::CommandResult r = t::run_tsi({"--plugin", file, "list"});
  INFO(r.describe());
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 2);
  CHECK(mentions(r.err, "tsi: error:"));
  CHECK(mentions(r.err, fs::path(file).filename().string()));
  CHECK(mentions(r.err, reason));
  CHECK(r.out.empty());
  return r;
}

}  // namespace

TEST_CASE("runner: a plugin registering a shipped model's name is refused, naming both files") {
  const t::CommandResult r = refused("shipped_duplicate", "model \"henon-heiles\" is already registered by");
  INFO(r.describe());
  CHECK(mentions(r.err, "tsi_henon_heiles.so"));
  CHECK(mentions(r.err, "tsi_fixture_shipped_duplicate.so"));
}

TEST_CASE("runner: a plugin whose structures differ in size is refused, naming the structure") {
  const t::CommandResult r = refused("wrong_layout", "tsi::ModelEntry is ");
  INFO(r.describe());
  CHECK(mentions(r.err, std::to_string(tsi_plugin_layout().model_entry.size) + " bytes"));
  CHECK(mentions(r.err, "rebuild the plugin"));
}

TEST_CASE("runner: every broken fixture is refused without a crash") {
  refused("wrong_abi",
          "built for plugin ABI 999, this tsi speaks ABI " + std::to_string(TSI_PLUGIN_ABI_VERSION));
  refused("wrong_major", "built for tsi 99.0.0");
  refused("no_entry", "not a tsi plugin");
  refused("throws", "registration failed: boom");
}

TEST_CASE("runner: a refused plugin on TSI_PLUGIN_PATH is a warning, the shipped model stays") {
  t::CommandEnv env;
  env.set["TSI_PLUGIN_PATH"] =
      t::fixture_plugin("shipped_duplicate") + ":" + t::fixture_plugin("wrong_layout");
  const t::CommandResult r = t::run_tsi({"list", "models", "--json"}, env);
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(mentions(r.err, "already registered"));
  CHECK(mentions(r.err, "tsi::ModelEntry"));
  const t::Json listed = t::Json::parse(r.out);  // named: a range-for over .at() of a temporary dangles
  for (const auto& m : listed.at("models"))
    if (m.at("name") == "henon-heiles")
      CHECK(mentions(m.at("provider").get<std::string>(), "tsi_henon_heiles.so"));
}

TEST_CASE("runner: --plugin may also follow the subcommand") {
  const t::CommandResult ok = t::run_tsi({"list", "models", "--json", "--plugin", t::fixture_plugin("good")});
  INFO(ok.describe());
  REQUIRE(ok.exit_code == 0);
  CHECK(mentions(ok.out, "\"fixture-model\""));

  t::TempDir dir;
  const t::CommandResult bad = t::run_tsi({"run", t::write_config(dir, t::small_config()), "--plugin",
                                           t::fixture_plugin("wrong_layout"), "--out", dir / "out"});
  INFO(bad.describe());
  CHECK(bad.exit_code == 2);
  CHECK(mentions(bad.err, "tsi::ModelEntry"));
  CHECK_FALSE(fs::exists(dir.path() / "out"));
}
