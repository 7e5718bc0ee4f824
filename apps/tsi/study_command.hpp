#pragma once
#include <string>
#include <vector>

#include "progress.hpp"
#include "study_runner.hpp"
#include "tsi/plugin_loader.hpp"

namespace tsi::app {

/// `tsi study STUDY.json [--out DIR] [--jobs N] [--set ...] [--no-plots]`: expands, runs in
/// parallel, writes table.csv, study.json, runs/ and plots, and prints the tables.
/// Returns the exit code (study_exit_code: 3 an output not written, 1 a run failed, else 0).
/// `resume`: the runs of this same study already finished in out_dir (result.json with status
/// completed or blow-up, and invariants.csv) are kept and not run again. `force`: results of
/// another study in out_dir are replaced instead of refused.
/// `quiet`: no progress line (--quiet).
int study_command(PluginLoader& loader, Registry& registry, const std::string& study_path,
                  std::string out_dir, int jobs, const std::vector<std::string>& overrides, bool plots,
                  const RunSettings& settings, bool resume = false, bool force = false, bool quiet = false);

/// A study's progress on `line` (units done of all, the current run, time left), throttled
/// by the line.
StudyProgressFn study_progress(ProgressLine& line);

/// The plotting script (python3 + matplotlib) next to the sources or the installed runner.
std::string plot_script_path();

/// Runs the plotting script on a study's output directory when `plots`, or says how to.
void call_plots(const std::string& out_dir, bool plots);

/// "ID: message" of every run whose files could not be written (outcomes[i] is runs[i]'s).
std::vector<std::string> io_errors_of(const std::vector<StudyRun>& runs, const std::vector<RunOutcome>& outcomes);

/// A study's exit code, the same for threads, shards, merges and MPI: 3 when an output could
/// not be written (each reported, the first 8), else 1 when a run failed (a blow-up is a
/// measured outcome; an error is not), else 0.
int study_exit_code(const Json& rows, const std::vector<std::string>& io_errors);

}  // namespace tsi::app
