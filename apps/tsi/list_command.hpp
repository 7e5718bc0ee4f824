#pragma once
#include <string>
#include <vector>

#include "tsi/registry.hpp"

namespace tsi::app {

/// What `tsi list [models|reformulations|schemes|fields|config]` shows; `what` empty lists the
/// four kinds of the registry; "config" lists the run config's sections and their keys instead.
/// An unknown `what` is a ConfigError listing the valid words. `given_plugins`: the files of
/// --plugin; the entries they registered are marked ("from_plugin_option": true in JSON, a
/// trailing "[from FILE]" in text), so that a plugin's author sees what it added.
Json list_json(const Registry& registry, const std::string& what, const std::vector<std::string>& given_plugins = {});
std::string list_text(const Registry& registry, const std::string& what,
                      const std::vector<std::string>& given_plugins = {});

}  // namespace tsi::app
