#include <doctest/doctest.h>

#include <algorithm>

#include "tsi/error.hpp"
#include "tsi/registry.hpp"

namespace {

tsi::ModelEntry model(std::string name, std::vector<std::string> aliases = {}) {
  tsi::ModelEntry e;
  e.info.name = std::move(name);
  e.info.aliases = std::move(aliases);
  return e;
}

tsi::ReformulationEntry reformulation(std::string name) {
  tsi::ReformulationEntry e;
  e.info.name = std::move(name);
  return e;
}

tsi::SchemeEntry scheme(std::string name, std::vector<std::string> reformulations) {
  tsi::SchemeEntry e;
  e.info.name = std::move(name);
  e.traits.reformulations = std::move(reformulations);
  return e;
}

bool has_param(const tsi::ParamSchema& schema, const std::string& name) {
  return std::any_of(schema.begin(), schema.end(),
                     [&](const tsi::ParamSpec& s) { return s.name == name; });
}

}  // namespace

TEST_CASE("registry: look-up by name and by alias") {
  tsi::Registry r;
  r.add_model(model("henon-heiles", {"hh"}));
  r.add_model(model("cpd", {"charged-particle"}));
  CHECK(&r.model("hh") == &r.model("henon-heiles"));
  CHECK(r.model("charged-particle").info.name == "cpd");
  CHECK(r.model("cpd").info.provider == "core");
  const auto all = r.models();
  REQUIRE(all.size() == 2);
  CHECK(all[0]->info.name == "cpd");
  CHECK(all[1]->info.name == "henon-heiles");
}

TEST_CASE("registry: a miss lists the valid names, sorted, with their aliases") {
  tsi::Registry r;
  r.add_model(model("henon-heiles", {"hh"}));
  r.add_model(model("cpd", {"charged-particle"}));
  CHECK_THROWS_WITH_AS(
      r.model("foo"),
      "model.name: unknown model \"foo\"; valid models are: cpd (alias: charged-particle), "
      "henon-heiles (alias: hh); a model from a plugin needs the plugin loaded: --plugin FILE, TSI_PLUGIN_PATH, "
      "the config's \"plugins\" list, or tsi.load_plugin(FILE) in Python",
      tsi::ConfigError);
  try {
    r.scheme("x", "run.scheme");
  } catch (const tsi::ConfigError& e) {
    CHECK(e.field() == "run.scheme");
  }
}

TEST_CASE("registry: names and aliases are unique within a kind") {
  tsi::Registry r;
  r.set_provider("/p/tsi_a.so");
  r.add_scheme(scheme("se1", {"two-scale"}));
  r.add_model(model("henon-heiles", {"hh"}));
  r.set_provider("/p/other.so");
  CHECK_THROWS_WITH_AS(
      r.add_scheme(scheme("se1", {})),
      "scheme \"se1\" is already registered by /p/tsi_a.so (while registering from /p/other.so)",
      tsi::PluginError);
  CHECK_THROWS_WITH_AS(r.add_model(model("hh")), doctest::Contains("alias of \"henon-heiles\""),
                       tsi::PluginError);
  CHECK_THROWS_AS(r.add_model(model("new", {"henon-heiles"})), tsi::PluginError);
  CHECK(r.models().size() == 1);
  r.add_model(model("se1"));  // another kind: no clash
  CHECK(r.models().size() == 2);
}

TEST_CASE("registry: every model gets eps and u0") {
  tsi::Registry r;
  tsi::ModelEntry e = model("m");
  e.info.params.push_back(tsi::number_param("eps", 0.5, "own eps"));
  r.add_model(std::move(e));
  const auto& params = r.model("m").info.params;
  CHECK(has_param(params, "u0"));
  CHECK(std::count_if(params.begin(), params.end(),
                      [](const auto& s) { return s.name == "eps"; }) == 1);
  CHECK(params[0].default_value == 0.5);

  r.add_model(model("plain"));
  const auto resolved =
      tsi::resolve_params(r.model("plain").info.params, tsi::Json::object(), "model");
  CHECK(resolved["eps"] == 0.01);
  CHECK(resolved["u0"].is_null());
  CHECK_THROWS_WITH_AS(
      tsi::resolve_params(r.model("plain").info.params, tsi::Json{{"eps", 2}}, "model"),
      "model.eps: got 2, expected a number in (0, 1], at least 1e-300 (1/eps must be a finite double)", tsi::ConfigError);
}

TEST_CASE("registry: check_compatible names the compatible reformulations") {
  tsi::Registry r;
  r.add_reformulation(reformulation("two-scale"));
  r.add_reformulation(reformulation("direct"));
  r.add_scheme(scheme("rk78", {"filtered", "direct"}));
  CHECK_NOTHROW(r.check_compatible(r.scheme("rk78"), r.reformulation("direct")));
  CHECK_THROWS_WITH_AS(
      r.check_compatible(r.scheme("rk78"), r.reformulation("two-scale")),
      "reformulation.name: scheme \"rk78\" cannot integrate the \"two-scale\" reformulation; "
      "compatible reformulations: direct, filtered",
      tsi::ConfigError);
}

TEST_CASE("registry: remove_provider removes exactly that provider's entries") {
  tsi::Registry r;
  r.add_model(model("core-model"));
  r.set_provider("/p/tsi_x.so");
  r.add_model(model("x-model", {"xm"}));
  r.add_scheme(scheme("x-scheme", {}));
  CHECK(r.provider() == "/p/tsi_x.so");
  r.set_provider("core");
  r.remove_provider("/p/tsi_x.so");
  CHECK(r.models().size() == 1);
  CHECK(r.schemes().empty());
  CHECK_THROWS_AS(r.model("xm"), tsi::ConfigError);
  r.add_model(model("x-model", {"xm"}));  // the names are free again
  CHECK(r.model("xm").info.provider == "core");
}
