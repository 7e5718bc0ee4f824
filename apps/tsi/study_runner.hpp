#pragma once
#include <functional>
#include <vector>

#include "progress.hpp"
#include "run.hpp"
#include "study_spec.hpp"

namespace tsi::app {

/// Called when a unit of work (a reference or a run) starts or finishes, and now and then (at
/// most every quarter second per unit) while it runs, with where the study is; calls are
/// serialised.
using StudyProgressFn = std::function<void(const StudyProgress&)>;

/// Runs every run of a study on `jobs` worker threads. References are computed first, once
/// per distinct reference_key, and shared. A run that fails, or whose reference fails, is
/// recorded as failed with its message and does not stop the others. Outcomes are in the
/// order of study.runs.
/// With `out_dir`, each run streams its invariants.csv rows into out_dir/runs/<id>/ as it goes.
std::vector<RunOutcome> run_study(const Study& study, const Registry& registry, int jobs,
                                  const StudyProgressFn& progress = {}, const std::string& out_dir = "",
                                  const std::vector<bool>& skip = {});

/// One --out, one study: refuses (ConfigError naming --out, or --resume) an output directory
/// that holds another study's results, unless `force`, which removes that study's files.
/// Removes runs/ (a smaller expansion would leave stale ones) unless `resume` and the same
/// study is there; returns whether its runs/ was kept for resuming.
bool claim_study_dir(const std::string& out_dir, const Study& study, bool resume = false, bool force = false);

/// A run that did not run (or threw): status failed, with the message.
RunOutcome failed_run_outcome(const StudyRun& run, const std::string& message);

}  // namespace tsi::app
