#pragma once
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/registry.hpp"

namespace tsi {

/// The outcome of one attempt to load a plugin file.
struct TSI_API PluginLoadReport {
  std::string path;
  std::string name;   ///< the plugin's own name (empty if it never got that far)
  bool ok = false;
  std::string error;  ///< why it failed
};

/// Loads plugins into a registry (dlopen, never dlclose: handles live as long as the
/// process, so factories and vtables stay valid). Failures never crash the process: each
/// is a PluginError (load) or a collected report (load_directory), as in OpenMM.
class TSI_API PluginLoader {
 public:
  explicit PluginLoader(Registry& registry) : registry_(registry) {}

  /// Loads one file; throws PluginError with the reason on any failure. Loading the same
  /// file twice is a no-op.
  void load(const std::string& path);
  /// Loads every tsi_*.so in `dir` (sorted); failures are collected, not thrown.
  std::vector<PluginLoadReport> load_directory(const std::string& dir);
  /// Loads every entry of a colon-separated list of files and directories (TSI_PLUGIN_PATH).
  std::vector<PluginLoadReport> load_path_list(const std::string& list);

  /// Everything attempted so far, in order.
  const std::vector<PluginLoadReport>& reports() const { return reports_; }

  /// The shipped plugins' directory: the build tree's, or <prefix>/lib/tsi/plugins next to
  /// an installed runner.
  static std::string default_directory();

 private:
  PluginLoadReport try_load(const std::string& path);
  Registry& registry_;
  std::vector<PluginLoadReport> reports_;
};

}  // namespace tsi
