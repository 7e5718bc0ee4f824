#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "tsi/collective.hpp"
#include "tsi/types.hpp"

namespace tsi::app {

/// A split run's state of more than max_inline_state values written as one .npy file by every
/// process at once, none gathering it: rank 0 writes np.save's header and sizes a temporary file
/// in the same directory, each process writes its share of each of the state's `parts` fields
/// at its place (pwrite), and rank 0 renames the file over `path`. The whole state is each
/// field's shares in rank order (the layout a gather on rank 0 builds). Every process calls it
/// alike, with `path` the same; a failure on any (a full disk) is a tsi::IoError naming `path` on
/// every one, and leaves no file behind.
void write_split_state(const Collective& split, const std::string& path, const Vector& local, Index parts,
                       bool complex_values, const std::vector<std::uint64_t>& shape);

}  // namespace tsi::app
