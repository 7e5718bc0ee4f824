#pragma once
#include <string>
#include <vector>

#include "tsi/plugin_loader.hpp"

namespace tsi::app {

/// `tsi study STUDY.json [--out DIR] [--jobs N] [--set ...] [--no-plots]`: expands, runs in
/// parallel, writes table.csv, study.json, runs/ and plots, and prints the tables.
/// Returns the exit code: 1 when a run failed with an error, 0 otherwise (blow-ups included).
int study_command(PluginLoader& loader, Registry& registry, const std::string& study_path,
                  std::string out_dir, int jobs, const std::vector<std::string>& overrides, bool plots);

/// The plotting script (python3 + matplotlib) next to the sources or the installed runner.
std::string plot_script_path();

}  // namespace tsi::app
