#pragma once
#include <functional>
#include <vector>

#include "run.hpp"
#include "study_spec.hpp"

namespace tsi::app {

/// Called after each unit of work (a reference or a run) with the units done and in all.
using StudyProgressFn = std::function<void(size_t done, size_t total)>;

/// Runs every run of a study on `jobs` worker threads. References are computed first, once
/// per distinct reference_key, and shared. A run that fails, or whose reference fails, is
/// recorded as failed with its message and does not stop the others. Outcomes are in the
/// order of study.runs.
/// With `out_dir`, each run streams its invariants.csv rows into out_dir/runs/<id>/ as it goes.
std::vector<RunOutcome> run_study(const Study& study, const Registry& registry, int jobs,
                                  const StudyProgressFn& progress = {}, const std::string& out_dir = "",
                                  const std::vector<bool>& skip = {});

}  // namespace tsi::app
