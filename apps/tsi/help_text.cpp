#include "help_text.hpp"

namespace tsi::app {
namespace {

constexpr const char* exit_codes =
    "Exit codes: 0 success; 1 a run failed (its files are still written); 2 bad input (the message\n"
    "names the field); 3 an output could not be written (what could be is kept valid); 128 + N\n"
    "interrupted by signal N (what was computed is written).\n";

constexpr const char* progress =
    "Progress: on a terminal one line (step, t, simulated time per second, time left) rewritten at\n"
    "most once a second; otherwise (a log) a plain line at most every 30 s; --quiet for none.\n";

}  // namespace

std::string long_help(const std::string& command) {
  if (command.empty())
    return std::string(exit_codes) + "\n" + progress +
           "\nExamples:\n"
           "  tsi list schemes                             the schemes and their parameters\n"
           "  tsi run examples/hh-se1.json --dry-run       check a config: its steps, memory, reference\n"
           "  tsi run examples/hh-se1.json --out out/hh    run it: out/hh/result.json, invariants.csv\n"
           "  tsi study examples/kg-convergence.json -j 2  a study: table.csv, study.json, runs/, plots\n"
           "  tsi check henon-heiles                       the conformance checks of a model\n"
           "\nPlugins: --plugin FILE, the directories in TSI_PLUGIN_PATH, or a config's \"plugins\" list.\n"
           "Documentation: README.md and docs/ in the source tree.\n";
  if (command == "run")
    return std::string(
               "A config is a JSON object with the sections model, reformulation, scheme and time (h,\n"
               "t_end), and optionally reference, output and monitor; `tsi list` shows every entry and its\n"
               "parameters with their defaults.\n"
               "--dry-run resolves and checks the config as a run does (the same errors and exit codes),\n"
               "prints the resolved sections, the number of steps, the memory and the reference's work,\n"
               "and writes nothing.\n"
               "Written to --out: result.json (the resolved config, status, invariants, errors),\n"
               "invariants.csv (a row per output step), and .npy files for large states.\n\n") +
           exit_codes + "\n" + progress +
           "\nExamples:\n"
           "  tsi run examples/hh-se1.json --dry-run\n"
           "  tsi run examples/hh-se1.json --out out/hh --set time.h=0.25 --set model.eps=0.001\n";
  if (command == "study")
    return std::string(
               "A study file is {\"kind\": \"convergence\" | \"conservation\" | \"work-precision\", \"title\",\n"
               "\"base\": a run config, \"vary\": {\"path\": [values]}, \"cases\": [...]}: the runs are the\n"
               "product of the lists, on --jobs threads, or over the ranks of mpirun.\n"
               "--dry-run expands and checks every run as it would run, prints each run's steps, memory\n"
               "and reference and the totals, and writes nothing.\n"
               "Written to --out: table.csv, study.json, runs/<id>/ (each run's files) and plots.\n\n") +
           exit_codes + "\n" +
           "Progress: on a terminal one line (runs done of all, the current run, time left) rewritten\n"
           "at most once a second; otherwise a plain line at most every 30 s; --quiet for none.\n"
           "\nExamples:\n"
           "  tsi study examples/kg-convergence.json --dry-run\n"
           "  tsi study examples/kg-convergence.json --out out/kg -j 2\n";
  return "";
}

}  // namespace tsi::app
