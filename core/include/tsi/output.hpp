#pragma once
#include <cstdio>
#include <functional>
#include <string>

#include "tsi/export.hpp"

namespace tsi {

/// Writes `contents` to `path` atomically: a temporary file in the same directory, flushed,
/// then renamed over the target, so no half-written file survives a failure.
TSI_API void write_file_atomically(const std::string& path, const std::string& contents);

/// The same with the contents put into the open file by `write`, which returns false when a
/// write failed (a large file written in pieces, never held whole in memory).
TSI_API void write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write);

}  // namespace tsi
