#pragma once
#include <chrono>
#include <string>
#include <vector>

#include "study_runner.hpp"
#include "tsi/plugin_loader.hpp"

namespace tsi::app {

/// `tsi study STUDY.json [--out DIR] [--jobs N] [--set ...] [--no-plots]`: expands, runs in
/// parallel, writes table.csv, study.json, runs/ and plots, and prints the tables.
/// Returns the exit code: 1 when a run failed with an error, 0 otherwise (blow-ups included).
/// `resume`: the runs of this same study already finished in out_dir (result.json with status
/// completed or blow-up, and invariants.csv) are kept and not run again. `force`: results of
/// another study in out_dir are replaced instead of refused.
int study_command(PluginLoader& loader, Registry& registry, const std::string& study_path,
                  std::string out_dir, int jobs, const std::vector<std::string>& overrides, bool plots,
                  bool resume = false, bool force = false);

/// A study's progress line on stderr (done/total, elapsed, time to go), silent when not `tty`.
StudyProgressFn terminal_progress(bool tty, std::chrono::steady_clock::time_point start);

/// The plotting script (python3 + matplotlib) next to the sources or the installed runner.
std::string plot_script_path();

}  // namespace tsi::app
