#pragma once
// The long help (`--help`) of the runner and its commands: what `-h` lists (the options), then
// what a first user needs beyond them: what a config holds, what is written, exit codes, examples.
#include <string>

namespace tsi::app {

/// The text after the options in `tsi [COMMAND] --help`: "" for the runner itself, "run",
/// "study"; empty for a command with nothing to add.
std::string long_help(const std::string& command);

}  // namespace tsi::app
