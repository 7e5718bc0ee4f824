#pragma once
#include <string>

#include "run.hpp"

namespace tsi::app {

/// Makes sure DIR exists and can be written, before anything is computed: a run whose
/// results could not be written is refused at the start (a ConfigError naming --out), not
/// lost at the end.
void prepare_output_dir(const std::string& dir);

/// Writes DIR/result.json, DIR/invariants.csv and the states, DIR/u_final.npy (and
/// DIR/reference_u_final.npy with a reference), atomically (creating DIR), whether the run
/// completed or failed part-way. A file that cannot be written is an IoError (exit code 3),
/// thrown after everything else that could be written is; a state file that could not be
/// written marks result.json failed, naming it.
void write_run_files(const std::string& dir, const RunOutcome& outcome);

}  // namespace tsi::app
