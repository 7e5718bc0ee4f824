#pragma once
#include <string>

#include "run.hpp"

namespace tsi::app {

/// Writes DIR/result.json and DIR/invariants.csv atomically (creating DIR), whether the
/// run completed or failed part-way.
void write_run_files(const std::string& dir, const RunOutcome& outcome);

}  // namespace tsi::app
