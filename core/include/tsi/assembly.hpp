#pragma once
#include <memory>
#include <string>

#include "tsi/export.hpp"
#include "tsi/params.hpp"
#include "tsi/registry.hpp"
#include "tsi/resolved_selection.hpp"

namespace tsi {

/// Resolves the model, reformulation and scheme sections of a config (one assembler for the
/// runner, `tsi check`, the benchmarks and the tests): names and aliases to canonical names,
/// parameters checked against each entry's schema with defaults filled, then completed by each
/// entry from the selection (the reformulation's n_tau and data order, SE2's quadrature nodes),
/// and the scheme/reformulation pair checked. The reformulation defaults to "two-scale" when
/// the scheme integrates it, else to the scheme's first. Bad input is a ConfigError naming the
/// field. Other sections of the config are not read.
TSI_API ResolvedSelection resolve_selection(const Json& config, const Registry& registry);

/// The memory a two-scale run of a selection holds at its peak, in vectors of the state's size
/// (dim x n_tau complex values), known before anything of that size is allocated: the state, the
/// bound scheme's vectors (Scheme::state_vectors for the problem's layout), the two-scale
/// problem's work space and its prepared data's temporaries (TwoScale::work_vectors). All zero
/// for the other reformulations.
struct TSI_API Footprint {
  double dim = 0.0, n_tau = 0.0;
  double state_bytes = 0.0;          ///< 16 dim n_tau
  std::string scheme;                ///< the scheme's name
  double scheme_vectors = 0.0;       ///< the bound scheme's
  double problem_vectors = 0.0;      ///< the two-scale problem's work space (an allowance for the model's grid)
  double preparation_vectors = 0.0;  ///< the prepared data's temporaries (freed before the steps)
  double vectors = 0.0;              ///< at the peak, the state included
  double bytes() const { return vectors * state_bytes; }
};

/// How assemble builds a run.
struct TSI_API AssemblyOptions {
  /// Bind the scheme to this step size (0: not bound; Assembly::bind later). A run binds after
  /// it has prepared its data (0 here, then Assembly::bind): the preparation's temporaries are
  /// freed by then.
  Real h = 0;
  /// The memory a two-scale run may take, in bytes (0: what the machine has available now);
  /// a run whose footprint exceeds it is refused, naming its sizes, before it is built.
  double memory_bytes = 0.0;
  /// States of the model's physical size that the caller keeps while the run goes (the dense
  /// output's values at output.times), counted in the memory check before anything of the
  /// state's size is allocated; a refusal they cause names kept_states_field.
  double kept_states = 0.0;
  std::string kept_states_field;
  /// What the run may use of the process (its threads), given to every entry's create().
  Context context;
};

/// The footprint of a two-scale run of `model` with these resolved reformulation parameters
/// and this scheme (bound before or after the preparation of the data), in this context (FFTW's
/// threads decide whether the tau transforms hold a whole grid of their own).
TSI_API Footprint two_scale_footprint(const Model& model, const Params& reformulation, const Scheme& scheme,
                                      const std::string& scheme_name, bool bound_before_preparation,
                                      const Context& context = {});

/// The objects of a run, built from a resolved selection.
struct TSI_API Assembly {
  const ModelEntry* model_entry = nullptr;
  const ReformulationEntry* reformulation_entry = nullptr;
  const SchemeEntry* scheme_entry = nullptr;
  StepperTraits traits;  ///< the scheme's traits with its resolved parameters (scheme_traits)
  std::shared_ptr<const Model> model;
  std::unique_ptr<Reformulation> reformulation;
  std::unique_ptr<Scheme> scheme;
  /// The scheme bound to the reformulation: by assemble with AssemblyOptions::h, else by bind.
  std::unique_ptr<Stepper> stepper;
  Vector u0;  ///< the initial value in model variables (model.u0 in physical variables, or the model's own)
  Footprint footprint;  ///< what the run will hold at its peak (checked before the reformulation was built)

  /// Binds the scheme to the reformulation and step size h (replacing any earlier binding).
  Stepper& bind(Real h);
};

/// Builds model, scheme and reformulation from a resolved selection (resolve_selection) and
/// enforces the declared capabilities before anything runs: a scheme that needs a diagonal
/// linear part or exact flows on a problem without them is a ConfigError naming scheme,
/// model and reformulation; a two-scale run whose footprint exceeds the memory available
/// (options.memory_bytes) is a ConfigError on reformulation.n_tau naming its sizes, raised before
/// the reformulation is built.
TSI_API Assembly assemble(const ResolvedSelection& resolved, const Registry& registry,
                          const AssemblyOptions& options = {});

/// resolve_selection then assemble.
TSI_API Assembly assemble_config(const Json& config, const Registry& registry, const AssemblyOptions& options = {});

/// The initial value a model section asks for, in model variables: its "u0" (physical
/// variables: numbers, or [re, im] pairs for a complex model; or the name of a .npy file of
/// float64 or complex128 values, as many as the model's dimension in any shape, finite, and
/// real for a real model) or the model's default. resolve_selection makes a file name absolute
/// (relative to the working directory) and checks its header; the values are read here.
/// `model_params`: the resolved model's parameters (ResolvedEntry::params).
TSI_API Vector initial_value(const Model& model, const Json& model_params);

}  // namespace tsi
