#pragma once
// `tsi run --dry-run` and `tsi study --dry-run`: the config resolved and every run's objects
// built and checked as a real run builds and checks them (the same errors and exit codes), then
// a summary of what would run and what it would cost; nothing is run or written.
#include <optional>
#include <string>
#include <vector>

#include "run.hpp"
#include "study_spec.hpp"

namespace tsi::app {

/// What a run would cost, known before it starts.
struct RunEstimate {
  long steps = 0;                  ///< t_end / h
  double error_estimate_steps = 0.0;  ///< the Richardson estimate's runs at h / 2 and 2 h (0: none)
  double state_bytes = 0.0;        ///< the run's state (its unknowns, complex)
  double peak_vectors = 0.0;       ///< vectors of the state's size held at the peak, the state included
  std::string peak_breakdown;      ///< what they are ("scheme 6, problem 2, ...")
  std::optional<ReferenceEstimate> reference;  ///< with a reference section
  std::vector<std::string> warnings;           ///< result.json's warnings known before the run
  double peak_bytes() const { return peak_vectors * state_bytes; }
};

/// Builds and checks a resolved config's run (plan_run, and its recorder of invariants) and
/// estimates its cost; `check_reference` as plan_run's. ConfigError on bad input.
RunEstimate estimate_run(const Json& resolved, const Registry& registry, const RunSettings& settings,
                         bool check_reference = true);

/// "16 KiB", "1.5 GiB".
std::string bytes_text(double bytes);

/// A section's parameters, resolved, as "eps = 0.01, n_tau = 64" (long arrays as their size).
std::string parameters_text(const Json& section);

/// The summary of `tsi run --dry-run` for a resolved config.
std::string run_dry_text(const std::string& config_path, const Json& resolved, const RunEstimate& estimate,
                         const std::string& out_dir);

/// `tsi run --dry-run`, once the config is resolved and its steps checked as a run's: the run
/// built and checked as it would be (a split run's ranks agree as they would to start), its
/// summary printed on stdout (by rank 0). Returns 0; bad input throws as it would for the run.
int run_dry_run(const std::string& config_path, const Json& resolved, const Registry& registry,
                const RunSettings& settings, const std::string& out_dir);

/// `tsi study --dry-run`: every run of the study estimated (estimate_run; each distinct reference
/// checked once, as run_study does), a line per run and the totals written to `text`. A run
/// that would be refused when it starts is listed as failing, with its message, as a real study
/// records it. Returns the exit code the study would have for that (1 when a run would fail,
/// else 0).
int study_dry_run(const std::string& study_path, const Study& study, const Registry& registry, int jobs,
                  std::string& text);

}  // namespace tsi::app
