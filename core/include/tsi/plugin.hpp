#pragma once
#include <cstdint>

#include "tsi/export.hpp"
#include "tsi/registry.hpp"
#include "tsi/version.hpp"

/// The plugin ABI (LLVM pass-plugin style): a plugin exports one C function,
/// tsi_plugin_entry, returning a TsiPluginInfo. The loader checks the ABI version, the
/// size of the structure and the tsi major version before calling register_fn.
inline constexpr std::uint32_t TSI_PLUGIN_ABI_VERSION = 1;

extern "C" {
struct TsiPluginInfo {
  std::uint32_t abi_version;  ///< TSI_PLUGIN_ABI_VERSION the plugin was built with
  std::uint32_t info_size;    ///< sizeof(TsiPluginInfo) the plugin was built with
  int tsi_version_major;      ///< tsi::version_major the plugin was built with
  const char* tsi_version;    ///< tsi::version_string the plugin was built with
  const char* name;           ///< the plugin's own name
  void (*register_fn)(tsi::Registry&);  ///< adds the plugin's models and schemes
};
}

/// Name of the entry point the loader looks up.
#define TSI_PLUGIN_ENTRY_NAME "tsi_plugin_entry"

/// Defines the entry point of a plugin: TSI_PLUGIN("my-plugin", my_register_function).
#define TSI_PLUGIN(NAME, REGISTER_FN)                                                       \
  extern "C" TSI_API const TsiPluginInfo* tsi_plugin_entry() {                             \
    static const TsiPluginInfo info{TSI_PLUGIN_ABI_VERSION, sizeof(TsiPluginInfo),          \
                                    tsi::version_major, tsi::version_string, NAME,          \
                                    REGISTER_FN};                                            \
    return &info;                                                                            \
  }
