#pragma once
#include "tsi/export.hpp"
#include "tsi/function_ref.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Calls body(i) once for each i = 0 .. count - 1, spread over `threads` threads (OpenMP, in the
/// core: a plugin needs no OpenMP of its own), in no set order; on the calling thread with
/// threads <= 1 or count <= 1. A body must not throw. For work split into pieces that do not
/// depend on the thread count, so that its numbers do not either (a run's threads come from
/// its Context: tsi sets nothing process wide).
TSI_API void parallel_for(int threads, Index count, FunctionRef<void(Index)> body);

}  // namespace tsi
