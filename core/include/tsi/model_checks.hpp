#pragma once
#include <cstdio>
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/params.hpp"
#include "tsi/registry.hpp"

namespace tsi {

/// Where and how to check a model (`tsi check`'s --eps, --steps, --set).
struct TSI_API ModelCheckOptions {
  std::vector<double> epsilons;        ///< eps of the order checks (empty: the model's declared regime)
  std::vector<long> steps;             ///< numbers of steps over T = 1 (empty: the model's declared regime)
  Json model_params = Json::object();  ///< model parameters besides eps
  /// Parameters of the two-scale reformulation of every run (n_tau, initial_data_order, ...).
  Json reformulation_params = Json::object();
  /// Scheme parameters, given to each checked scheme that takes them (tol, order, ...).
  Json scheme_params = Json::object();
  /// Judge the uniform order on the maximum over a dense sample of the eps range (32
  /// log-spaced, the given ones, the step-size resonances inside); false: over the given eps
  /// only (cheaper: each eps costs an rk78 reference, 1/eps substeps).
  bool dense_eps_sample = true;
};

/// What the checks of one model found.
struct TSI_API ModelCheckReport {
  int count = 0;                      ///< checks run
  std::vector<std::string> failures;  ///< one line each, with the measured cause where one stands out
  /// Checks that could not decide (too few errors above the references' accuracy), with why:
  /// neither passed nor failed.
  std::vector<std::string> undecidable;
  double seconds = 0.0;
};

/// Refuses eps outside (0, 1], fewer than three step counts, or step counts that do not
/// increase from 1 to 1000000 (a ConfigError naming --eps or --steps).
TSI_API void check_regime(const std::vector<double>& epsilons, const std::vector<long>& steps);

/// The conformance checks of one model (docs/explanation/model-interface.md; `tsi check` is this over the
/// models selected): its interface against model-independent expectations, the observed order
/// of every given two-scale scheme at every eps (tsi::fit_order, the runs built by the core's
/// assembler), with the measured cause of a miss, and the symmetry of the symmetric schemes.
/// Prints its table to `out` as it runs.
TSI_API ModelCheckReport check_model(const Registry& registry, const ModelEntry& entry,
                                     const std::vector<const SchemeEntry*>& schemes,
                                     const ModelCheckOptions& options, std::FILE* out);

}  // namespace tsi
