#pragma once
#include <string>

#include "tsi/export.hpp"

namespace tsi {

/// The memory this process may still allocate, in bytes: the least of the machine's available
/// memory (MemAvailable), the address-space limit (ulimit -v) less what the process maps now,
/// and its cgroup's memory.max less memory.current. Infinity when none of them is known.
TSI_API double allocatable_bytes();

/// Refuses, before anything of that size is allocated, `bytes` that `what` needs ("the model's
/// grid of 1024 x 1024 x 1024 points"): a ConfigError on `field` naming both sizes. `limit`
/// (bytes, 0: allocatable_bytes()) is a caller's own budget.
TSI_API void check_allocation(const std::string& field, double bytes, const std::string& what, double limit = 0.0);

}  // namespace tsi
