#pragma once
#include <memory>

#include "tsi/export.hpp"
#include "tsi/params.hpp"
#include "tsi/registry.hpp"

namespace tsi {

/// Resolves the model, reformulation and scheme sections of a config (one assembler for the
/// runner, `tsi check`, the benchmarks and the tests): names and aliases to canonical names,
/// parameters checked against each entry's schema with defaults filled, then completed by each
/// entry from the selection (the reformulation's n_tau and data order, SE2's quadrature nodes),
/// and the scheme/reformulation pair checked. The reformulation defaults to "two-scale" when
/// the scheme integrates it, else to the scheme's first. Bad input is a ConfigError naming the
/// field. Returns {"model": {...}, "reformulation": {...}, "scheme": {...}}, each with "name".
TSI_API Json resolve_selection(const Json& config, const Registry& registry);

/// The objects of a run, built from a resolved selection.
struct TSI_API Assembly {
  const ModelEntry* model_entry = nullptr;
  const ReformulationEntry* reformulation_entry = nullptr;
  const SchemeEntry* scheme_entry = nullptr;
  StepperTraits traits;  ///< the scheme's traits with its resolved parameters (scheme_traits)
  std::shared_ptr<const Model> model;
  std::unique_ptr<Reformulation> reformulation;
  std::unique_ptr<Scheme> scheme;
  /// The scheme bound to the reformulation: by assemble when the config has time.h, else by bind.
  std::unique_ptr<Stepper> stepper;
  Vector u0;  ///< the initial value in model variables (model.u0 in physical variables, or the model's own)

  /// Binds the scheme to the reformulation and step size h (replacing any earlier binding).
  Stepper& bind(double h);
};

/// Builds model, reformulation and scheme from a resolved selection (resolve_selection) and
/// enforces the declared capabilities before anything runs: a scheme that needs a diagonal
/// linear part or exact flows on a problem without them is a ConfigError naming scheme,
/// model and reformulation.
TSI_API Assembly assemble(const Json& resolved, const Registry& registry);

/// resolve_selection then assemble.
TSI_API Assembly assemble_config(const Json& config, const Registry& registry);

/// The initial value a model section asks for, in model variables: its "u0" (physical
/// variables: numbers, or [re, im] pairs for a complex model; or the name of a .npy file of
/// float64 or complex128 values, as many as the model's dimension in any shape, finite, and
/// real for a real model) or the model's default. resolve_selection makes a file name absolute
/// (relative to the working directory) and checks its header; the values are read here.
TSI_API Vector initial_value(const Model& model, const Json& model_section);

}  // namespace tsi
