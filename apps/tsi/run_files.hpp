#pragma once
#include <string>

#include "run.hpp"

namespace tsi::app {

/// Makes sure DIR exists and can be written, before anything is computed: a run whose
/// results could not be written is refused at the start (a ConfigError naming --out), not
/// lost at the end.
void prepare_output_dir(const std::string& dir);

/// Writes DIR/result.json and DIR/invariants.csv atomically (creating DIR), whether the
/// run completed or failed part-way.
void write_run_files(const std::string& dir, const RunOutcome& outcome);

}  // namespace tsi::app
