#include "list_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "config.hpp"
#include "tsi/error.hpp"

namespace tsi::app {
namespace {

Json params_json(const ParamSchema& schema) {
  Json out = Json::array();
  for (const auto& p : schema)
    out.push_back({{"name", p.name},
                   {"type", describe(p.type)},
                   {"default", p.default_value},
                   {"description", p.description},
                   {"expected", p.expected}});
  return out;
}

/// The providers the given plugin files stand for: the loader stamps an entry with its file's
/// canonical path, whatever path --plugin named it by.
std::vector<std::string> canonical_providers(const std::vector<std::string>& files) {
  std::vector<std::string> out;
  for (const auto& file : files) {
    std::error_code ec;
    const auto canonical = std::filesystem::canonical(file, ec);
    out.push_back(ec ? file : canonical.string());
  }
  return out;
}

Json info_json(const EntryInfo& info, const std::vector<std::string>& marked) {
  return {{"name", info.name},
          {"aliases", info.aliases},
          {"summary", info.summary},
          {"provider", info.provider},
          {"from_plugin_option", std::find(marked.begin(), marked.end(), info.provider) != marked.end()},
          {"params", params_json(info.params)}};
}

void check_what(const std::string& what) {
  if (!what.empty() && what != "models" && what != "reformulations" && what != "schemes" && what != "fields" &&
      what != "config")
    throw ConfigError("list", "got \"" + what +
                                  "\", expected models, reformulations, schemes or fields (or config: the run "
                                  "config's sections and keys)");
}

/// The run config's sections (`tsi list config`): not part of the default listing, which is
/// what the registry holds.
Json config_json() {
  Json out = Json::array();
  for (const auto& section : runner_sections()) {
    Json j = {{"name", section.name}, {"summary", section.summary}};
    if (section.params) j["params"] = params_json(*section.params);
    if (!section.chosen_from.empty()) j["chosen_from"] = section.chosen_from;
    out.push_back(j);
  }
  return out;
}

}  // namespace

Json list_json(const Registry& registry, const std::string& what, const std::vector<std::string>& given_plugins) {
  check_what(what);
  if (what == "config") return {{"config", config_json()}};
  const std::vector<std::string> marked = canonical_providers(given_plugins);
  Json out = Json::object();
  if (what.empty() || what == "models") {
    out["models"] = Json::array();
    for (const auto* e : registry.models()) {
      Json j = info_json(e->info, marked);
      j["default_n_tau"] = e->default_n_tau;
      j["linear_remainder"] = e->linear_remainder;
      out["models"].push_back(j);
    }
  }
  if (what.empty() || what == "reformulations") {
    out["reformulations"] = Json::array();
    for (const auto* e : registry.reformulations()) out["reformulations"].push_back(info_json(e->info, marked));
  }
  if (what.empty() || what == "schemes") {
    out["schemes"] = Json::array();
    for (const auto* e : registry.schemes()) {
      Json j = info_json(e->info, marked);
      const StepperTraits t = default_traits(*e);  // with its default parameters
      j["traits"] = {{"order", t.order},         {"classical_order", std::max(t.order, t.classical_order)},
                     {"resonant_order", t.order_with_resonances()},
                     {"symmetric", t.symmetric},
                     {"implicit", t.implicit},   {"multistep", t.multistep},
                     {"adaptive", t.adaptive},   {"initial_data_order", t.initial_data_order},
                     {"remainder_data_order", t.data_order_for(true)},
                     {"reformulations", t.reformulations}};
      out["schemes"].push_back(j);
    }
  }
  if (what.empty() || what == "fields") {
    out["fields"] = Json::array();
    for (const auto* e : registry.fields()) {
      Json j = info_json(e->info, marked);
      j["dim"] = e->dim;
      j["time_dependent"] = e->time_dependent;
      j["is_complex"] = e->is_complex;
      out["fields"].push_back(j);
    }
  }
  return out;
}

std::string list_text(const Registry& registry, const std::string& what, const std::vector<std::string>& given_plugins) {
  const Json all = list_json(registry, what, given_plugins);
  std::string s;
  if (all.contains("config")) {
    s += "config:\n";
    for (const auto& section : all["config"]) {
      s += fmt::format("  {}  {}{}\n", section["name"].get<std::string>(), section["summary"].get<std::string>(),
                       section.contains("chosen_from")
                           ? " (tsi list " + section["chosen_from"].get<std::string>() + ")"
                           : "");
      for (const auto& p : section.value("params", Json::array()))
        s += fmt::format("      {:<24} {:<10} default {:<8} {}{}\n", p["name"].get<std::string>(),
                         p["type"].get<std::string>(), p["default"].is_null() ? "-" : p["default"].dump(),
                         p["description"].get<std::string>(),
                         p["expected"].get<std::string>().empty() ? "" : " [" + p["expected"].get<std::string>() + "]");
    }
    return s;
  }
  for (const char* kind : {"models", "reformulations", "schemes", "fields"}) {
    if (!all.contains(kind)) continue;
    s += fmt::format("{}{}:\n", s.empty() ? "" : "\n", kind);
    for (const auto& e : all[kind]) {
      std::string aliases;
      for (const auto& a : e["aliases"]) aliases += (aliases.empty() ? "" : ", ") + a.get<std::string>();
      const std::string mark =
          e["from_plugin_option"].get<bool>()
              ? "  [from " + std::filesystem::path(e["provider"].get<std::string>()).filename().string() + "]"
              : "";
      s += fmt::format("  {}{}  {}{}\n", e["name"].get<std::string>(),
                       aliases.empty() ? "" : " (" + aliases + ")", e["summary"].get<std::string>(), mark);
      if (e.contains("traits")) {
        const auto& t = e["traits"];
        std::string reforms;
        for (const auto& r : t["reformulations"]) reforms += (reforms.empty() ? "" : ", ") + r.get<std::string>();
        const int classical = t["classical_order"].get<int>();
        const int resonant = t["resonant_order"].get<int>();
        const int data = t["initial_data_order"].get<int>(), with_remainder = t["remainder_data_order"].get<int>();
        s += fmt::format("      order {}{}{}, {}, {}, data order {}{}, on: {}\n", t["order"].get<int>(),
                         classical > t["order"].get<int>() ? fmt::format(" uniformly ({} at fixed eps)", classical) : "",
                         resonant < t["order"].get<int>()
                             ? (resonant > 0 ? fmt::format(", {} at step-size resonances h ~ k pi eps", resonant)
                                             : std::string(", bounded only at step-size resonances h ~ k pi eps"))
                             : "",
                         t["symmetric"].get<bool>() ? "symmetric" : "not symmetric",
                         t["implicit"].get<bool>() ? "implicit" : "explicit",
                         data, with_remainder > data ? fmt::format(" ({} on a model with a remainder)", with_remainder) : "",
                         reforms);
      }
      if (e.contains("default_n_tau"))
        s += fmt::format("      default n_tau {}{}\n", e["default_n_tau"].get<int>(),
                         e["linear_remainder"].get<bool>() ? ", a linear remainder R (integrated exactly)" : "");
      if (e.contains("time_dependent"))
        s += fmt::format("      {} entries, {}, {}\n", e["dim"].get<long>() == 0 ? std::string("any number of") : std::to_string(e["dim"].get<long>()),
                         e["time_dependent"].get<bool>() ? "time-dependent" : "autonomous",
                         e["is_complex"].get<bool>() ? "complex" : "real");
      for (const auto& p : e["params"]) {
        const std::string def = p["default"].is_null() ? "-" : p["default"].dump();
        s += fmt::format("      {:<20} {:<10} default {:<8} {}{}\n", p["name"].get<std::string>(),
                         p["type"].get<std::string>(), def, p["description"].get<std::string>(),
                         p["expected"].get<std::string>().empty() ? ""
                                                                  : " [" + p["expected"].get<std::string>() + "]");
      }
      s += fmt::format("      provided by {}\n", e["provider"].get<std::string>());
    }
  }
  return s;
}

}  // namespace tsi::app
