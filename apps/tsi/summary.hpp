#pragma once
#include <string>

#include "run.hpp"

namespace tsi::app {

/// The one-screen summary of a run printed on the terminal.
std::string run_summary(const RunOutcome& outcome, const std::string& out_dir);

}  // namespace tsi::app
