#include "plugin_setup.hpp"

#include <cstdlib>
#include <filesystem>

#include "tsi/error.hpp"

namespace tsi::app {

std::vector<std::string> load_plugins(PluginLoader& loader, Registry& registry,
                                      const std::vector<std::string>& explicit_files) {
  register_core(registry);
  std::vector<std::string> warnings;
  auto collect = [&](const std::vector<PluginLoadReport>& reports) {
    for (const auto& r : reports)
      if (!r.ok) warnings.push_back(r.error);
  };
  collect(loader.load_directory(PluginLoader::default_directory()));
  if (const char* path = std::getenv("TSI_PLUGIN_PATH"); path && *path) collect(loader.load_path_list(path));
  for (const auto& file : explicit_files) loader.load(file);
  return warnings;
}

void load_config_plugins(PluginLoader& loader, const Json& plugins, const std::string& config_path) {
  if (!plugins.is_array()) throw ConfigError("plugins", "got " + plugins.dump() + ", expected a list of file names");
  const auto base = std::filesystem::path(config_path).parent_path();
  for (const auto& p : plugins) {
    if (!p.is_string()) throw ConfigError("plugins", "got " + p.dump() + ", expected a file name");
    std::filesystem::path file = p.get<std::string>();
    if (file.is_relative()) file = base / file;
    try {
      loader.load(file.string());
    } catch (const PluginError& e) {
      throw ConfigError("plugins", e.what());
    }
  }
}

}  // namespace tsi::app
