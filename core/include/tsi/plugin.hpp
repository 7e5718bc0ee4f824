#pragma once
#include <cstdint>
#include <limits>
#include <string>

#include "tsi/export.hpp"
#include "tsi/params.hpp"
#include "tsi/registry.hpp"
#include "tsi/types.hpp"
#include "tsi/version.hpp"

/// The plugin ABI (LLVM pass-plugin style, with gz-plugin's size handshake): a plugin exports
/// one C function, tsi_plugin_entry, returning a TsiPluginInfo. The loader checks, in this
/// order, the ABI version, the size of TsiPluginInfo, the tsi major version and the layout of
/// every structure the plugin exchanges with tsi, before it calls register_fn.
/// What is stable and what bumps the version: docs/reference/plugin-abi.md.
inline constexpr std::uint32_t TSI_PLUGIN_ABI_VERSION = 25;

extern "C" {

/// sizeof and alignof of one type, as a translation unit saw it.
struct TsiTypeLayout {
  std::uint32_t size;
  std::uint32_t align;
};

/// The layout of the structures a plugin and tsi exchange, as the plugin was compiled.
/// A difference means the two were built from different headers or with incompatible
/// settings (another standard library ABI, another Eigen alignment), and the plugin is refused.
struct TsiPluginLayout {
  TsiTypeLayout entry_info;           ///< tsi::EntryInfo
  TsiTypeLayout param_spec;           ///< tsi::ParamSpec
  TsiTypeLayout model_entry;          ///< tsi::ModelEntry
  TsiTypeLayout reformulation_entry;  ///< tsi::ReformulationEntry
  TsiTypeLayout scheme_entry;         ///< tsi::SchemeEntry
  TsiTypeLayout stepper_traits;       ///< tsi::StepperTraits
  TsiTypeLayout model;                ///< tsi::Model
  TsiTypeLayout stepper;              ///< tsi::Stepper
  TsiTypeLayout scheme;               ///< tsi::Scheme
  TsiTypeLayout params;               ///< tsi::Params
  TsiTypeLayout vector;               ///< tsi::Vector (Eigen::VectorXcd)
  TsiTypeLayout json;                 ///< tsi::Json (nlohmann::json)
  TsiTypeLayout string;               ///< std::string
  TsiTypeLayout field_entry;          ///< tsi::FieldEntry
  /// EIGEN_MAX_ALIGN_BYTES: vectors resized by the plugin are freed by tsi and the other way
  /// round, so both must allocate with the same alignment.
  std::uint32_t eigen_max_align_bytes;
  /// 1 when compiled with AddressSanitizer: Eigen then allocates through another allocator, and
  /// memory one side allocates the other frees, so both must agree.
  std::uint32_t address_sanitizer;
  /// tsi::Real, the build's precision (TSI_PRECISION): a double plugin's states and step sizes
  /// are not a quad tsi's. Its size and alignment, and its significand's bits (53, 64 or 113:
  /// long double and quad are both 16 bytes).
  TsiTypeLayout real;
  std::uint32_t real_digits;
};

struct TsiPluginInfo {
  std::uint32_t abi_version;  ///< TSI_PLUGIN_ABI_VERSION the plugin was built with
  std::uint32_t info_size;    ///< sizeof(TsiPluginInfo) the plugin was built with
  int tsi_version_major;      ///< tsi::version_major the plugin was built with
  const char* tsi_version;    ///< tsi::version_string the plugin was built with
  const char* name;           ///< the plugin's own name
  void (*register_fn)(tsi::Registry&);  ///< adds the plugin's models and schemes
  TsiPluginLayout layout;     ///< tsi_plugin_layout() as the plugin was compiled
};
}

namespace tsi::detail {
template <class T>
constexpr TsiTypeLayout layout_of() {
  return {static_cast<std::uint32_t>(sizeof(T)), static_cast<std::uint32_t>(alignof(T))};
}
}  // namespace tsi::detail

/// The layout of the exchanged structures in the calling translation unit: the plugin's
/// entry point records its own, the loader compares it with tsi's.
constexpr TsiPluginLayout tsi_plugin_layout() {
  using tsi::detail::layout_of;
  return {layout_of<tsi::EntryInfo>(),
          layout_of<tsi::ParamSpec>(),
          layout_of<tsi::ModelEntry>(),
          layout_of<tsi::ReformulationEntry>(),
          layout_of<tsi::SchemeEntry>(),
          layout_of<tsi::StepperTraits>(),
          layout_of<tsi::Model>(),
          layout_of<tsi::Stepper>(),
          layout_of<tsi::Scheme>(),
          layout_of<tsi::Params>(),
          layout_of<tsi::Vector>(),
          layout_of<tsi::Json>(),
          layout_of<std::string>(),
          layout_of<tsi::FieldEntry>(),
          static_cast<std::uint32_t>(EIGEN_MAX_ALIGN_BYTES),
#if defined(__SANITIZE_ADDRESS__)
          1u,
#else
          0u,
#endif
          layout_of<tsi::Real>(),
          static_cast<std::uint32_t>(std::numeric_limits<tsi::Real>::digits)};
}

/// Name of the entry point the loader looks up.
#define TSI_PLUGIN_ENTRY_NAME "tsi_plugin_entry"

/// Defines the entry point of a plugin: TSI_PLUGIN("my-plugin", my_register_function).
/// `my_register_function` is a void(tsi::Registry&) that adds the plugin's entries.
#define TSI_PLUGIN(NAME, REGISTER_FN)                                                   \
  extern "C" TSI_API const TsiPluginInfo* tsi_plugin_entry() {                          \
    static const TsiPluginInfo info{TSI_PLUGIN_ABI_VERSION, sizeof(TsiPluginInfo),      \
                                    tsi::version_major,     tsi::version_string,        \
                                    NAME,                   REGISTER_FN,                \
                                    tsi_plugin_layout()};                               \
    return &info;                                                                       \
  }
