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
#ifndef TSI_PLUGIN_DIR_FROM_BIN
#define TSI_PLUGIN_DIR_FROM_BIN "../lib/tsi/plugins"
#endif
#ifndef TSI_PLUGIN_DIR_FROM_LIB
#define TSI_PLUGIN_DIR_FROM_LIB "tsi/plugins"
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

/// Describes one layout as "N bytes, alignment A".
std::string describe(const TsiTypeLayout& l) {
  return std::to_string(l.size) + " bytes, alignment " + std::to_string(l.align);
}

/// Refuses a plugin whose exchanged structures differ from this tsi's, naming the first one.
void check_layout(const std::string& path, const TsiPluginLayout& theirs) {
  static constexpr TsiPluginLayout ours = tsi_plugin_layout();
  struct Field {
    const char* type;
    TsiTypeLayout TsiPluginLayout::*member;
  };
  static constexpr Field fields[] = {
      {"tsi::EntryInfo", &TsiPluginLayout::entry_info},
      {"tsi::ParamSpec", &TsiPluginLayout::param_spec},
      {"tsi::ModelEntry", &TsiPluginLayout::model_entry},
      {"tsi::ReformulationEntry", &TsiPluginLayout::reformulation_entry},
      {"tsi::SchemeEntry", &TsiPluginLayout::scheme_entry},
      {"tsi::StepperTraits", &TsiPluginLayout::stepper_traits},
      {"tsi::Model", &TsiPluginLayout::model},
      {"tsi::Stepper", &TsiPluginLayout::stepper},
      {"tsi::Scheme", &TsiPluginLayout::scheme},
      {"tsi::Params", &TsiPluginLayout::params},
      {"tsi::Vector", &TsiPluginLayout::vector},
      {"tsi::Json", &TsiPluginLayout::json},
      {"std::string", &TsiPluginLayout::string},
      {"tsi::FieldEntry", &TsiPluginLayout::field_entry}};
  for (const auto& f : fields) {
    const TsiTypeLayout& a = theirs.*f.member;
    const TsiTypeLayout& b = ours.*f.member;
    if (a.size != b.size || a.align != b.align)
      throw PluginError(path + ": " + f.type + " is " + describe(a) + " in the plugin, " + describe(b) +
                        " in this tsi (built against other tsi headers or an incompatible "
                        "toolchain: rebuild the plugin against this tsi)");
  }
  if (theirs.eigen_max_align_bytes != ours.eigen_max_align_bytes)
    throw PluginError(path + ": built with EIGEN_MAX_ALIGN_BYTES " +
                      std::to_string(theirs.eigen_max_align_bytes) + ", this tsi uses " +
                      std::to_string(ours.eigen_max_align_bytes) +
                      " (vectors cross the plugin boundary: build both with the same flags)");
  if (theirs.address_sanitizer != ours.address_sanitizer)
    throw PluginError(path + ": built " + (theirs.address_sanitizer ? "with" : "without") +
                      " AddressSanitizer, this tsi " + (ours.address_sanitizer ? "with" : "without") +
                      " it (Eigen allocates through another allocator under ASan, and vectors cross the "
                      "plugin boundary: build both the same way)");
  if (theirs.real.size != ours.real.size || theirs.real.align != ours.real.align ||
      theirs.real_digits != ours.real_digits)
    throw PluginError(path + ": its real type (tsi::Real) is " + describe(theirs.real) + " with a " +
                      std::to_string(theirs.real_digits) + "-bit significand, this tsi's is " + describe(ours.real) +
                      " with " + std::to_string(ours.real_digits) + " bits (" TSI_PRECISION_NAME
                      "): built for another TSI_PRECISION; rebuild the plugin against this tsi");
}

/// The plugin's info block, after the ABI, size, version and layout checks; throws the reason.
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
  check_layout(path, info->layout);
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
  // Next to the running executable (an installed runner: <prefix>/bin/../lib/tsi/plugins),
  // then next to this library (any program linked against an installed libtsi_core), then
  // the build tree's.
  std::vector<fs::path> candidates;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / TSI_PLUGIN_DIR_FROM_BIN);
  static const char anchor = 0;  // an address inside libtsi_core
  Dl_info self{};
  if (dladdr(&anchor, &self) != 0 && self.dli_fname)
    candidates.push_back(fs::path(self.dli_fname).parent_path() / TSI_PLUGIN_DIR_FROM_LIB);
  for (const auto& dir : candidates) {
    if (fs::is_directory(dir, ec)) {
      const fs::path clean = fs::weakly_canonical(dir, ec);
      return ec ? dir.string() : clean.string();
    }
  }
  return TSI_BUILD_PLUGIN_DIR;
}

}  // namespace tsi
