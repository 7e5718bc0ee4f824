#pragma once
#include <string>
#include <vector>

#include "tsi/plugin_loader.hpp"

namespace tsi::app {

/// Registers the core and loads plugins in the order: the shipped plugin directory,
/// TSI_PLUGIN_PATH, then `explicit_files` (--plugin). Failures in the shipped directory
/// and TSI_PLUGIN_PATH are returned as warnings; an explicit file that fails throws.
std::vector<std::string> load_plugins(PluginLoader& loader, Registry& registry,
                                      const std::vector<std::string>& explicit_files);

/// Loads a config's "plugins" list, relative paths taken from the config's directory.
void load_config_plugins(PluginLoader& loader, const Json& plugins, const std::string& config_path);

}  // namespace tsi::app
