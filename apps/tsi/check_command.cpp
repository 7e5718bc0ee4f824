#include "check_command.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <set>

#include "tsi/error.hpp"
#include "tsi/model_checks.hpp"

namespace tsi::app {
namespace {
bool two_scale(const SchemeEntry& e) {
  const auto& r = e.traits.reformulations;
  return std::find(r.begin(), r.end(), "two-scale") != r.end();
}

std::string canonical(const std::string& path) {
  std::error_code ec;
  const auto c = std::filesystem::canonical(path, ec);
  return ec ? path : c.string();
}


}  // namespace

int check_command(PluginLoader& loader, const Registry& registry, CheckOptions options,
                  const std::vector<std::string>& runner_plugins) {
  std::set<std::string> providers;
  for (const auto& file : options.plugins) {
    loader.load(file);
    providers.insert(canonical(file));
  }
  for (const auto& file : runner_plugins) providers.insert(canonical(file));
  std::vector<const ModelEntry*> models;
  std::vector<const SchemeEntry*> schemes;
  if (!options.model.empty()) {
    models.push_back(&registry.model(options.model, "check"));
  } else {
    for (const auto* e : registry.models())
      if (providers.contains(e->info.provider)) models.push_back(e);
  }
  if (!options.schemes.empty()) {
    for (const auto& name : options.schemes) {
      const SchemeEntry& e = registry.scheme(name, "check --scheme");
      if (!two_scale(e))
        throw ConfigError("check --scheme",
                          "\"" + e.info.name + "\" does not integrate the two-scale problem");
      schemes.push_back(&e);
    }
  } else {
    for (const auto* e : registry.schemes())
      if (two_scale(*e) && providers.contains(e->info.provider)) schemes.push_back(e);
  }
  if (!providers.empty() && models.empty() && schemes.empty() && options.model.empty())
    throw ConfigError("check",
                      "the plugins named provide no model and no two-scale scheme: nothing to check");
  if (models.empty()) models = registry.models();
  if (schemes.empty() && options.schemes.empty())
    for (const auto* e : registry.schemes())
      if (two_scale(*e)) schemes.push_back(e);

  if (!options.epsilons.empty() || !options.steps.empty())
    check_regime(options.epsilons.empty() ? std::vector<double>{1.0} : options.epsilons,
                 options.steps.empty() ? std::vector<long>{4, 8, 16} : options.steps);
  if (!options.model_params.is_object()) options.model_params = Json::object();
  for (const char* key : {"name", "eps", "u0"})
    if (options.model_params.contains(key))
      throw ConfigError(std::string("check --set model.") + key,
                        "is chosen by the check itself (the model is the one checked, eps by --eps)");
  if (!options.model_params.empty() && models.size() > 1)
    throw ConfigError("check --set", "model parameters need one model to check: name it (tsi check MODEL --set ...)");
  if (!options.model_params.empty()) {  // bad parameters are bad input, refused before any check runs
    Json params = options.model_params;
    params["eps"] = 1.0;
    resolve_params(models.front()->info.params, params, "model");
  }
  // The checks integrate the two-scale problem: its parameters are checked against it, and
  // each scheme key must be a parameter of some scheme checked (each scheme takes those it has).
  if (!options.reformulation_params.is_object()) options.reformulation_params = Json::object();
  if (!options.scheme_params.is_object()) options.scheme_params = Json::object();
  if (options.reformulation_params.contains("name"))
    throw ConfigError("check --set reformulation.name", "is chosen by the check itself (the two-scale problem)");
  if (options.scheme_params.contains("name"))
    throw ConfigError("check --set scheme.name", "is chosen by --scheme (repeatable)");
  if (!options.reformulation_params.empty())
    resolve_params(registry.reformulation("two-scale").info.params, options.reformulation_params, "reformulation");
  for (const auto& [key, value] : options.scheme_params.items()) {
    std::vector<std::string> names;
    bool taken = false;
    for (const auto* s : schemes) {
      names.push_back(s->info.name);
      for (const auto& p : s->info.params)
        if (p.name == key) {  // its value checked by each scheme that takes it
          taken = true;
          resolve_params(s->info.params, Json{{key, value}}, "scheme");
        }
    }
    if (!taken)
      throw ConfigError("check --set scheme." + key, fmt::format("is a parameter of none of the schemes checked ({})",
                                                                 fmt::join(names, ", ")));
  }

  int failed_models = 0;
  for (const auto* entry : models)
    if (!check_model(registry, *entry, schemes, options, stdout).failures.empty()) ++failed_models;
  if (models.size() > 1)
    fmt::print("{} of {} models passed every check\n", models.size() - static_cast<size_t>(failed_models),
               models.size());
  return failed_models == 0 ? 0 : 1;
}

}  // namespace tsi::app
