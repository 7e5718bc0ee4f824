// The study expander: cartesian products, cases, paths, and bad paths rejected up front.
#include <doctest/doctest.h>

#include "study_spec.hpp"
#include "tsi/error.hpp"
#include "tsi/plugin_loader.hpp"

namespace {

tsi::Registry& registry() {
  static tsi::Registry r;
  static bool loaded = [] {
    tsi::register_core(r);
    tsi::PluginLoader(r).load_directory(TSI_TEST_PLUGIN_DIR);
    return true;
  }();
  (void)loaded;
  return r;
}

tsi::Json base() { return {{"model", {{"name", "hh"}}}, {"time", {{"t_end", 1.0}}}}; }

}  // namespace

TEST_CASE("study: vary expands to the cartesian product, paths in sorted order, the last fastest") {
  const tsi::Json spec = {{"kind", "convergence"},
                          {"base", base()},
                          {"vary", {{"model.eps", {1.0, 0.1}}, {"time.h", {0.5, 0.25, 0.125}}}}};
  const auto study = tsi::app::expand_study(spec, registry(), {});
  REQUIRE(study.runs.size() == 6);
  CHECK(study.runs[0].id == "r0001");
  CHECK(study.runs[0].config["model"]["eps"] == 1.0);
  CHECK(study.runs[0].config["time"]["h"] == 0.5);
  CHECK(study.runs[1].config["time"]["h"] == 0.25);
  CHECK(study.runs[3].config["model"]["eps"] == 0.1);
  CHECK(study.runs[5].config["time"]["h"] == 0.125);
  // Every run is fully resolved: canonical names and defaults.
  CHECK(study.runs[0].config["model"]["name"] == "henon-heiles");
  CHECK(study.runs[0].config["reformulation"]["n_tau"] == 64);
  CHECK(study.varied == std::vector<std::string>{"model.eps", "time.h"});
}

TEST_CASE("study: cases set their own paths and vary more") {
  const tsi::Json spec = {
      {"kind", "work-precision"},
      {"base", base()},
      {"vary", {{"model.eps", {0.01}}}},
      {"cases",
       {{{"label", "SE1"}, {"vary", {{"time.h", {0.5, 0.25}}}}},
        {{"label", "rk78"},
         {"set", {{"scheme", {{"name", "rk78"}}}, {"reformulation.name", "direct"}, {"time.h", 1.0}}},
         {"vary", {{"scheme.tol", {1e-6, 1e-8, 1e-10}}}}}}}};
  const auto study = tsi::app::expand_study(spec, registry(), {"time.t_end=2"});
  REQUIRE(study.runs.size() == 5);
  CHECK(study.runs[0].label == "SE1");
  CHECK(study.runs[0].config["scheme"]["name"] == "se1");
  CHECK(study.runs[0].config["time"]["t_end"] == 2.0);  // --set applies to the base
  CHECK(study.runs[4].label == "rk78");
  CHECK(study.runs[4].config["reformulation"]["name"] == "direct");
  CHECK(study.runs[4].config["scheme"]["tol"] == 1e-10);
  CHECK(study.runs[4].assignments["scheme.tol"] == 1e-10);
}

TEST_CASE("study: bad kinds, lists and paths are rejected before anything runs") {
  auto rejects = [](const tsi::Json& spec, const std::string& words) {
    CAPTURE(spec.dump());
    CHECK_THROWS_WITH_AS(tsi::app::expand_study(spec, registry(), {}), doctest::Contains(words.c_str()), tsi::ConfigError);
  };
  rejects({{"kind", "speed"}, {"base", base()}}, "expected one of: convergence, conservation, work-precision");
  rejects({{"kind", "convergence"}}, "base: missing");
  rejects({{"base", base()}, {"vary", {{"time.h", tsi::Json::array()}}}}, "vary.time.h: got [], expected a non-empty list");
  rejects({{"base", base()}, {"vary", {{"model.epz", {1.0}}}}}, "model.epz: unknown parameter");
  rejects({{"base", base()}, {"vary", {{"nosuch.x", {1.0}}}}}, "unknown section \"nosuch\"");
  rejects({{"base", base()}, {"vary", {{"model.eps", {0.5, 2.0}}}}}, "got 2.0, expected a number in (0, 1], at least 1e-300 (1/eps must be a finite double) (run r0002: model.eps=2.0)");
  rejects({{"base", base()}, {"bogus", 1}}, "unknown study key");
}

TEST_CASE("study: a vary that expands to 1e10 runs is refused with the count, before anything is allocated") {
  tsi::Json values = tsi::Json::array();
  for (int i = 0; i < 100; ++i) values.push_back(0.5);
  const tsi::Json spec = {{"base", {{"model", {{"name", "hh"}}}, {"time", {{"t_end", 1.0}}}}},
                          {"vary", {{"model.eps", values}, {"time.h", values}, {"scheme.tol", values},
                                    {"monitor.max_err_H", values}, {"output.every", values}}}};
  CHECK_THROWS_WITH_AS(tsi::app::expand_study(spec, registry(), {}),
                       doctest::Contains("the study expands to 1e+10 runs; at most 100000"), tsi::ConfigError);
}
