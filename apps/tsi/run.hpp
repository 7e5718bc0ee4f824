#pragma once
#include <functional>
#include <string>

#include "tsi/params.hpp"
#include "tsi/registry.hpp"

namespace tsi::app {

/// Everything a run produced, kept even when it failed part-way.
struct RunOutcome {
  Json result;       ///< the content of result.json
  std::string csv;   ///< the content of invariants.csv
  bool ok = true;
  std::string message;  ///< why the run failed (empty when ok)
};

/// Called now and then with the fraction done, for a progress line.
using ProgressFn = std::function<void(double fraction)>;

/// Runs a resolved config (resolve_run_config): builds model, reformulation and scheme from
/// the registry, integrates, records the invariants, and compares with the reference when
/// one is requested. Errors during the run are caught and reported in the outcome.
RunOutcome execute_run(const Json& resolved, const Registry& registry, const ProgressFn& progress = {});

/// The physical state as JSON: real numbers, or [re, im] pairs for a complex model.
Json state_to_json(const Vector& x, bool complex_state);

}  // namespace tsi::app
