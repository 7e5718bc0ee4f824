#include "tsi/plugin_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "tsi/error.hpp"
#include "tsi/plugin.hpp"

#ifndef TSI_BUILD_PLUGIN_DIR
#define TSI_BUILD_PLUGIN_DIR ""
#endif

namespace tsi {

namespace fs = std::filesystem;

namespace {

using EntryFn = const TsiPluginInfo* (*)();

/// Every handle ever opened: never closed, so factories and vtables stay valid.
void keep_handle(void* handle) {
  static std::mutex mutex;
  static std::vector<void*> handles;
  std::lock_guard lock(mutex);
  if (std::find(handles.begin(), handles.end(), handle) == handles.end()) handles.push_back(handle);
}

/// True when `registry` already holds something registered from `provider`.
bool provides(const Registry& registry, const std::string& provider) {
  const auto from = [&provider](const auto* e) { return e->info.provider == provider; };
  const auto any = [&from](const auto& entries) {
    return std::any_of(entries.begin(), entries.end(), from);
  };
  return any(registry.models()) || any(registry.reformulations()) || any(registry.schemes());
}

/// The plugin's info block, after the ABI, size and version checks; throws the reason.
const TsiPluginInfo& open_plugin(const std::string& path) {
  dlerror();
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = dlerror();
    throw PluginError(path + ": cannot load: " + (why ? why : "unknown dlopen error"));
  }
  keep_handle(handle);
  void* symbol = dlsym(handle, TSI_PLUGIN_ENTRY_NAME);
  if (!symbol)
    throw PluginError(path + ": not a tsi plugin (no entry point " TSI_PLUGIN_ENTRY_NAME ")");
  EntryFn entry = nullptr;
  std::memcpy(&entry, &symbol, sizeof entry);
  const TsiPluginInfo* info = entry();
  if (!info) throw PluginError(path + ": " TSI_PLUGIN_ENTRY_NAME " returned no plugin info");
  if (info->abi_version != TSI_PLUGIN_ABI_VERSION) {
    throw PluginError(path + ": built for plugin ABI " + std::to_string(info->abi_version) +
                      ", this tsi speaks ABI " + std::to_string(TSI_PLUGIN_ABI_VERSION));
  }
  if (info->info_size != sizeof(TsiPluginInfo)) {
    throw PluginError(path + ": plugin info is " + std::to_string(info->info_size) +
                      " bytes, this tsi expects " + std::to_string(sizeof(TsiPluginInfo)));
  }
  if (info->tsi_version_major != version_major) {
    const std::string theirs =
        info->tsi_version ? info->tsi_version : std::to_string(info->tsi_version_major);
    throw PluginError(path + ": built for tsi " + theirs + ", this is tsi " + version_string +
                      " (major versions differ)");
  }
  if (!info->register_fn) throw PluginError(path + ": plugin has no register function");
  return *info;
}

/// Runs the plugin's registration under its own provider name; on failure removes whatever
/// it registered half-way and rethrows the reason.
void register_plugin(Registry& registry, const TsiPluginInfo& info, const std::string& path) {
  const std::string previous = registry.provider();
  registry.set_provider(path);
  std::string why;
  try {
    info.register_fn(registry);
  } catch (const std::exception& e) {
    why = e.what();
  } catch (...) {
    why = "unknown exception";
  }
  if (!why.empty()) registry.remove_provider(path);
  registry.set_provider(previous);
  if (!why.empty()) throw PluginError(path + ": registration failed: " + why);
}

}  // namespace

PluginLoadReport PluginLoader::try_load(const std::string& path) {
  PluginLoadReport report;
  report.path = path;
  try {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw PluginError(path + ": no such file");
    const std::string canonical = fs::canonical(path).string();
    report.path = canonical;
    const TsiPluginInfo& info = open_plugin(canonical);
    report.name = info.name ? info.name : "";
    if (!provides(registry_, canonical)) register_plugin(registry_, info, canonical);
    report.ok = true;
  } catch (const std::exception& e) {
    report.error = e.what();
  }
  reports_.push_back(report);
  return report;
}

void PluginLoader::load(const std::string& path) {
  const PluginLoadReport report = try_load(path);
  if (!report.ok) throw PluginError(report.error);
}

std::vector<PluginLoadReport> PluginLoader::load_directory(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool match = name.starts_with("tsi_") && name.ends_with(".so");
    std::error_code type_ec;
    if (match && it->is_regular_file(type_ec)) files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  std::vector<PluginLoadReport> out;
  for (const auto& file : files) out.push_back(try_load(file));
  return out;
}

std::vector<PluginLoadReport> PluginLoader::load_path_list(const std::string& list) {
  std::vector<PluginLoadReport> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t colon = std::min(list.find(':', start), list.size());
    const std::string entry = list.substr(start, colon - start);
    start = colon + 1;
    if (entry.empty()) continue;
    std::error_code ec;
    if (fs::is_directory(entry, ec)) {
      auto reports = load_directory(entry);
      out.insert(out.end(), reports.begin(), reports.end());
    } else {
      out.push_back(try_load(entry));
    }
  }
  return out;
}

std::string PluginLoader::default_directory() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path() / ".." / "lib" / "tsi" / "plugins";
    if (fs::is_directory(installed, ec)) {
      const fs::path clean = fs::weakly_canonical(installed, ec);
      return ec ? installed.string() : clean.string();
    }
  }
  return TSI_BUILD_PLUGIN_DIR;
}

}  // namespace tsi
