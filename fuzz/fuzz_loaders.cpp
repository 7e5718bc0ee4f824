// libFuzzer harness on the config and study loaders: the bytes are parsed as `tsi run` and
// `tsi study` parse a file (parse_json), then resolved as a run config (resolve_run_config)
// and expanded as a study (expand_study), without running anything. Lines of the form
// `//set key.path=value` (comments to the parser) are applied as --set overrides first.
// A tsi::Error is the expected answer to bad input; any other exception escapes and is a
// finding, as are crashes and sanitizer reports.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "config.hpp"
#include "plugin_setup.hpp"
#include "study_spec.hpp"
#include "tsi/error.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"

namespace {

tsi::Registry& registry() {
  static tsi::Registry& r = [] () -> tsi::Registry& {
    static tsi::Registry registry;
    static tsi::PluginLoader loader(registry);
    tsi::app::load_plugins(loader, registry, {});
    return registry;
  }();
  return r;
}

std::vector<std::string> overrides_in(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("//set ", 0) == 0) out.push_back(line.substr(6));
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  tsi::Registry& reg = registry();
  const std::string text(reinterpret_cast<const char*>(data), size);
  tsi::Json raw;
  try {
    std::istringstream in(text);
    raw = tsi::app::parse_json(in, "fuzz.json");
  } catch (const tsi::Error&) {
    return 0;
  }
  const std::vector<std::string> overrides = overrides_in(text);
  try {  // as `tsi run` reads it
    tsi::Json config = raw;
    for (const auto& assignment : overrides) tsi::app::apply_override(config, assignment);
    const tsi::Json resolved = tsi::app::resolve_run_config(config, reg);
    (void)tsi::app::step_count(resolved);
  } catch (const tsi::Error&) {
  }
  try {  // as `tsi study` reads it
    (void)tsi::app::expand_study(raw, reg, overrides, {}, {}, false);  // the loaders only: no model is built
  } catch (const tsi::Error&) {
  }
  return 0;
}
