// `tsi list`: what the runner knows, as text and as JSON, and its usage errors.
#include <doctest/doctest.h>

#include <set>
#include <sstream>
#include <string>

#include "run_command.hpp"

namespace {

using namespace tsi::test;


bool ends_with(const std::string& text, const std::string& tail) { return text.ends_with(tail); }

/// The entry called `name` in a list of entries, or null.
Json entry_named(const Json& entries, const std::string& name) {
  for (const auto& e : entries)
    if (e.at("name") == name) return e;
  return nullptr;
}

/// The parameter called `name` in an entry's params, or null.
Json param_named(const Json& entry, const std::string& name) { return entry_named(entry.at("params"), name); }

bool has_string(const Json& list, const std::string& s) {
  for (const auto& x : list)
    if (x == s) return true;
  return false;
}

Json list_json(const std::vector<std::string>& extra = {}, const CommandEnv& env = {}) {
  std::vector<std::string> args = {"list"};
  args.insert(args.end(), extra.begin(), extra.end());
  args.push_back("--json");
  const CommandResult r = run_tsi(args, env);
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  return Json::parse(r.out);
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("list --json: models and reformulations and schemes") {
  const Json all = list_json();
  INFO(all.dump(2));
  REQUIRE(all.at("models").is_array());
  REQUIRE(all.at("reformulations").is_array());
  REQUIRE(all.at("schemes").is_array());

  SUBCASE("henon-heiles comes from its plugin with eps and u0 parameters") {
    const Json hh = entry_named(all.at("models"), "henon-heiles");
    REQUIRE(hh.is_object());
    CHECK(ends_with(hh.at("provider").get<std::string>(), "tsi_henon_heiles.so"));
    CHECK(has_string(hh.at("aliases"), "hh"));
    CHECK(hh.at("default_n_tau") == 64);
    CHECK_FALSE(hh.at("summary").get<std::string>().empty());
    const Json eps = param_named(hh, "eps");
    REQUIRE(eps.is_object());
    CHECK(eps.at("default").get<double>() == 0.01);
    CHECK(eps.at("type") == "a number");
    CHECK(contains(eps.at("expected").get<std::string>(), "(0, 1]"));
    const Json u0 = param_named(hh, "u0");
    REQUIRE(u0.is_object());
    CHECK(u0.at("default").is_null());
  }

  SUBCASE("se1 and rk78 with their parameters and traits") {
    const Json se1 = entry_named(all.at("schemes"), "se1");
    REQUIRE(se1.is_object());
    CHECK(ends_with(se1.at("provider").get<std::string>(), "tsi_se1.so"));
    CHECK(has_string(se1.at("aliases"), "se1-tsi"));
    REQUIRE(param_named(se1, "tol").is_object());
    CHECK(param_named(se1, "tol").at("default").get<double>() == 1e-10);
    REQUIRE(param_named(se1, "max_iter").is_object());
    CHECK(param_named(se1, "max_iter").at("default") == 200);
    CHECK(param_named(se1, "max_iter").at("type") == "an integer");
    const Json& t = se1.at("traits");
    CHECK(t.at("order") == 2);
    CHECK(t.at("symmetric") == true);
    CHECK(t.at("implicit") == true);
    CHECK(t.at("initial_data_order") == 2);
    CHECK(has_string(t.at("reformulations"), "two-scale"));
    CHECK(has_string(t.at("reformulations"), "filtered"));

    const Json rk78 = entry_named(all.at("schemes"), "rk78");
    REQUIRE(rk78.is_object());
    CHECK(ends_with(rk78.at("provider").get<std::string>(), "tsi_rk78.so"));
    REQUIRE(param_named(rk78, "tol").is_object());
    CHECK(param_named(rk78, "tol").at("default").get<double>() == 1e-10);
    CHECK(rk78.at("traits").at("adaptive") == true);
    CHECK(has_string(rk78.at("traits").at("reformulations"), "direct"));
    CHECK(has_string(rk78.at("traits").at("reformulations"), "filtered"));
    CHECK_FALSE(has_string(rk78.at("traits").at("reformulations"), "two-scale"));
  }

  SUBCASE("the core reformulations") {
    for (const char* name : {"two-scale", "filtered", "direct"}) {
      INFO("reformulation " << name);
      const Json r = entry_named(all.at("reformulations"), name);
      REQUIRE(r.is_object());
      CHECK(r.at("provider") == "core");
      CHECK(r.at("params").is_array());
    }
    const Json two_scale = entry_named(all.at("reformulations"), "two-scale");
    const Json n_tau = param_named(two_scale, "n_tau");
    REQUIRE(n_tau.is_object());
    CHECK(n_tau.at("default").is_null());  // the model's own
    CHECK(n_tau.at("type") == "an integer");
    CHECK(contains(n_tau.at("expected").get<std::string>(), "even"));
    REQUIRE(param_named(two_scale, "initial_data_order").is_object());
  }

  SUBCASE("entries are sorted by name") {
    for (const char* kind : {"models", "reformulations", "schemes"}) {
      INFO(kind);
      const Json& entries = all.at(kind);
      for (std::size_t i = 1; i < entries.size(); ++i)
        CHECK(entries[i - 1].at("name").get<std::string>() < entries[i].at("name").get<std::string>());
    }
  }
}

TEST_CASE("list --json: one kind at a time") {
  SUBCASE("models") {
    const Json j = list_json({"models"});
    CHECK(j.contains("models"));
    CHECK_FALSE(j.contains("reformulations"));
    CHECK_FALSE(j.contains("schemes"));
  }
  SUBCASE("reformulations") {
    const Json j = list_json({"reformulations"});
    CHECK(j.contains("reformulations"));
    CHECK_FALSE(j.contains("models"));
    CHECK_FALSE(j.contains("schemes"));
  }
  SUBCASE("schemes") {
    const Json j = list_json({"schemes"});
    CHECK(j.contains("schemes"));
    CHECK_FALSE(j.contains("models"));
    CHECK_FALSE(j.contains("reformulations"));
  }
}

// `tsi list config` documents the run config (the docs' reference is generated from it): its
// sections must be the ones a config may have, and the runner's own keys the ones a run
// resolves, with the defaults a run records.
TEST_CASE("list config: the run config's sections and the defaults a run records") {
  const Json listed = list_json({"config"});
  INFO(listed.dump(2));
  REQUIRE(listed.size() == 1);
  const Json& sections = listed.at("config");
  std::vector<std::string> names;
  for (const auto& s : sections) names.push_back(s.at("name"));
  CHECK(names == std::vector<std::string>{"model", "reformulation", "scheme", "time", "reference", "output", "monitor",
                                          "plugins"});
  CHECK(entry_named(sections, "model").at("chosen_from") == "models");
  CHECK(entry_named(sections, "scheme").at("chosen_from") == "schemes");

  // an unknown section is refused with the list of valid ones: the same as listed
  TempDir dir;
  Json bad = small_config();
  bad["bogus"] = Json::object();
  const CommandResult refused = run_tsi({"run", write_config(dir, bad, "bad.json"), "--dry-run"});
  INFO(refused.describe());
  CHECK(refused.exit_code == 2);
  std::string valid;
  for (const auto& n : names) valid += (valid.empty() ? "" : ", ") + n;
  CHECK(contains(refused.err, "valid sections are: " + valid));

  // a run (with the default reference) records every listed key of the runner's sections,
  // and the listed default where the config gives none
  Json config = small_config();
  config["reference"] = Json::object();
  const CommandResult run = run_tsi({"run", write_config(dir, config), "--out", dir / "out", "--quiet"});
  INFO(run.describe());
  REQUIRE(run.exit_code == 0);
  const Json resolved = read_json(dir.path() / "out" / "result.json").at("config");
  int checked = 0;
  for (const char* name : {"time", "reference", "output", "monitor"}) {
    const Json section = entry_named(sections, name);
    REQUIRE(section.contains("params"));
    for (const auto& p : section.at("params")) {
      const std::string key = p.at("name");
      INFO(name << "." << key);
      if (config.contains(name) && config[name].contains(key)) continue;
      if (p.at("default").is_null()) continue;  // decided by the run (reference.h: t_end)
      REQUIRE(resolved.at(name).contains(key));
      CHECK(resolved.at(name).at(key) == p.at("default"));
      ++checked;
    }
    for (const auto& [key, value] : resolved.at(name).items()) {
      INFO("resolved " << name << "." << key);
      CHECK(param_named(section, key).is_object());
    }
  }
  CHECK(checked >= 10);
}

TEST_CASE("list config: the text form") {
  const CommandResult r = run_tsi({"list", "config"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  for (const char* part : {"config:", "  time  ", "t_end", "checkpoint_seconds", "max_err_H", "(tsi list schemes)"})
    CHECK_MESSAGE(contains(r.out, part), "missing: " << part);
  CHECK_FALSE(contains(r.out, "henon-heiles"));
}

TEST_CASE("list: the text form names every entry and its provider") {
  const CommandResult r = run_tsi({"list"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  for (const char* part : {"models:", "reformulations:", "schemes:", "henon-heiles (hh)", "se1 (se1-tsi)", "rk78",
                           "two-scale", "filtered", "direct", "provided by", "tsi_henon_heiles.so", "max_iter"})
    CHECK_MESSAGE(contains(r.out, part), "missing: " << part);
}

TEST_CASE("list: the text form of one kind") {
  const CommandResult r = run_tsi({"list", "schemes"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(contains(r.out, "schemes:"));
  CHECK(contains(r.out, "se1"));
  CHECK_FALSE(contains(r.out, "models:"));
  CHECK_FALSE(contains(r.out, "henon-heiles"));
}

TEST_CASE("list: an unknown kind is bad input") {
  for (const bool json : {false, true}) {
    INFO("--json " << json);
    std::vector<std::string> args = {"list", "bogus"};
    if (json) args.push_back("--json");
    const CommandResult r = run_tsi(args);
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "tsi: error: list:"));
    CHECK(contains(r.err, "\"bogus\""));
    CHECK(contains(r.err, "models, reformulations, schemes or fields"));
    CHECK(r.out.empty());
  }
}

// `tsi --plugin FILE list` marks exactly what FILE registered: the fixture "general" adds the
// model fixture-quickstart and the fields fixture-quickstart-f, fixture-linear and fixture-zero-f. The fixture
// "good", loaded beside it through TSI_PLUGIN_PATH, and the shipped plugins stay unmarked.
TEST_CASE("list --plugin FILE: exactly the entries FILE registered are marked") {
  // (paths built with fs::path: g++ 12 -O3 warns falsely on fixture_plugin's string sums here)
  const fs::path fixtures(TSI_TEST_FIXTURE_DIR);
  const std::string general = (fixtures / "tsi_fixture_general.so").string();
  const std::string good = (fixtures / "tsi_fixture_good.so").string();
  CommandEnv env;
  env.set["TSI_PLUGIN_PATH"] = good;
  const std::set<std::string> expected = {"models/fixture-quickstart", "fields/fixture-quickstart-f",
                                          "fields/fixture-linear", "fields/fixture-zero-f"};

  SUBCASE("json: from_plugin_option on FILE's entries alone, named by a relative path") {
    // the loader records the file's canonical path; the marks must follow it
    const fs::path file(general);
    const CommandResult r = run_tsi({"--plugin", file.filename().string(), "list", "--json"}, env,
                                    file.parent_path().string());
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const Json all = Json::parse(r.out);
    std::set<std::string> marked, from_general;
    std::size_t entries = 0;
    for (const char* kind : {"models", "reformulations", "schemes", "fields"})
      for (const auto& e : all.at(kind)) {
        ++entries;
        const std::string id = std::string(kind) + "/" + e.at("name").get<std::string>();
        if (e.at("from_plugin_option").get<bool>()) marked.insert(id);
        if (ends_with(e.at("provider").get<std::string>(), "/tsi_fixture_general.so")) from_general.insert(id);
      }
    CHECK(marked == expected);
    CHECK(from_general == expected);
    // the neighbours really are there, unmarked: the plugin path's fixture and a shipped model
    CHECK(entry_named(all.at("models"), "fixture-model").at("from_plugin_option") == false);
    CHECK(entry_named(all.at("schemes"), "fixture-scheme").at("from_plugin_option") == false);
    CHECK(entry_named(all.at("models"), "henon-heiles").at("from_plugin_option") == false);
    CHECK(entries > expected.size() + 10);
  }

  SUBCASE("text: a trailing [from FILE] on FILE's entries alone") {
    const CommandResult r = run_tsi({"--plugin", general, "list"}, env);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    std::set<std::string> marked;
    std::string kind;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
      if (!line.empty() && line.back() == ':' && line[0] != ' ') kind = line.substr(0, line.size() - 1);
      if (line.find("[from") == std::string::npos) continue;
      CHECK(ends_with(line, "  [from tsi_fixture_general.so]"));
      const std::size_t start = line.find_first_not_of(' ');
      marked.insert(kind + "/" + line.substr(start, line.find(' ', start) - start));
    }
    CHECK(marked == expected);
  }

  SUBCASE("without --plugin nothing is marked") {
    const Json all = list_json({}, env);
    for (const char* kind : {"models", "reformulations", "schemes", "fields"})
      for (const auto& e : all.at(kind)) CHECK(e.at("from_plugin_option") == false);
    CHECK(entry_named(all.at("models"), "fixture-model").is_object());  // loaded, yet unmarked
    const CommandResult r = run_tsi({"list"}, env);
    CHECK(r.exit_code == 0);
    CHECK_FALSE(contains(r.out, "[from"));
  }
}

TEST_CASE("cli: no command is a usage error and --version and --help succeed") {
  SUBCASE("no command") {
    const CommandResult r = run_tsi({});
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 2);
  }
  SUBCASE("unknown command") {
    const CommandResult r = run_tsi({"frobnicate"});
    INFO(r.describe());
    CHECK(r.signal == 0);
    CHECK(r.exit_code == 2);
  }
  SUBCASE("--version") {
    const CommandResult r = run_tsi({"--version"});
    INFO(r.describe());
    CHECK(r.exit_code == 0);
    CHECK_FALSE(r.out.empty());
    // the same version that a run records in result.json
    TempDir dir;
    const CommandResult run = run_tsi({"run", write_config(dir, small_config()), "--out", dir / "out"});
    INFO(run.describe());
    REQUIRE(run.exit_code == 0);
    const std::string version = read_json(dir.path() / "out" / "result.json").at("tsi_version");
    CHECK(contains(r.out, version));
  }
  SUBCASE("--help") {
    const CommandResult r = run_tsi({"--help"});
    INFO(r.describe());
    CHECK(r.exit_code == 0);
    CHECK(contains(r.out, "list"));
    CHECK(contains(r.out, "run"));
  }
}

}  // TEST_SUITE
