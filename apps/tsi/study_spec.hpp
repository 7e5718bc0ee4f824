#pragma once
#include <string>
#include <vector>

#include "run.hpp"
#include "tsi/params.hpp"
#include "tsi/registry.hpp"

namespace tsi::app {

/// One run of a study: the values it varies and its fully resolved config.
struct StudyRun {
  std::string id;      ///< r0001, r0002, ... in expansion order
  std::string label;   ///< the case's label ("" without cases)
  Json assignments;    ///< path -> value: what this run sets beyond the base
  Json config;         ///< resolved, as `tsi run` would use it
};

/// A study: a base run config, lists of values for config paths run as their cartesian
/// product, optionally per case (a case sets paths of its own and may vary more):
///   {"kind": "convergence" | "conservation" | "work-precision", "title": "...",
///    "base": {run config}, "vary": {"path": [values]},
///    "cases": [{"label": "...", "set": {"path": value}, "vary": {...}}]}
struct Study {
  std::string kind;
  std::string title;
  Json spec;  ///< the study file as given (after --set on its base)
  std::vector<StudyRun> runs;
  std::vector<std::string> varied;  ///< every varied path (and every path a case sets), in first-seen order
  /// Base settings that only some runs take (a parameter of some schemes or models only): path
  /// -> the ids of the runs that do not take it. The others run with it.
  Json not_used = Json::object();
  RunSettings settings;  ///< what every run may use (threads) and take (--max-steps)
};

/// The most runs a study may expand to (counted before expanding): far beyond any real study,
/// and a bound on the memory the expansion takes.
inline constexpr long max_study_runs = 100000;

/// Validates and expands a study; every run is resolved before any runs, so a bad path or
/// value is reported (naming the run and the path) before work starts. `overrides` are
/// --set assignments applied to the base. Files the runs name (model.u0 as a .npy file) are
/// relative to the directory of `study_path` (empty: the working directory). With
/// `build_runs`, every run's objects are also built once (plan_run: the model's own checks,
/// its data, the memory check) and dropped, so that no run fails on its input after others
/// have computed; runs that differ only in time.h are built once.
Study expand_study(const Json& spec, const Registry& registry, const std::vector<std::string>& overrides,
                   const std::string& study_path = {}, const RunSettings& settings = {}, bool build_runs = true);

}  // namespace tsi::app
