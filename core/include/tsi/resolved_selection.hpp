#pragma once
#include <string>

#include "tsi/export.hpp"
#include "tsi/params.hpp"

namespace tsi {

/// One entry of a resolved selection: its canonical name and its parameters, checked against
/// the entry's schema, every default filled and completed from the selection. The parameters
/// are the entry's own (a plugin declares them at run time), read through tsi::Params' typed
/// getters by the entry that declared them.
struct TSI_API ResolvedEntry {
  std::string name;
  Json params = Json::object();  ///< without "name"
  /// The section as a config writes it: {"name": name, ...params}.
  Json section() const;
};

/// A config's model, reformulation and scheme, resolved once (tsi::resolve_selection): what
/// tsi::assemble builds a run from. Nothing below it reads a config.
struct TSI_API ResolvedSelection {
  ResolvedEntry model, reformulation, scheme;
  /// {"model": ..., "reformulation": ..., "scheme": ...}: the sections as a config writes them
  /// (result.json's config, a study's rows).
  Json sections() const;
};

}  // namespace tsi
