#pragma once
#include <string>

#include "tsi/registry.hpp"

namespace tsi::app {

/// What `tsi list [models|reformulations|schemes]` shows; `what` empty lists all three.
/// An unknown `what` is a ConfigError listing the valid words.
Json list_json(const Registry& registry, const std::string& what);
std::string list_text(const Registry& registry, const std::string& what);

}  // namespace tsi::app
