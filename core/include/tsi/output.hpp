#pragma once
#include <string>

#include "tsi/export.hpp"

namespace tsi {

/// Writes `contents` to `path` atomically: a temporary file in the same directory, flushed,
/// then renamed over the target, so no half-written file survives a failure.
TSI_API void write_file_atomically(const std::string& path, const std::string& contents);

}  // namespace tsi
