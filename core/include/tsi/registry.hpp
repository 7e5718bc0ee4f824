#pragma once
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/field.hpp"
#include "tsi/model.hpp"
#include "tsi/params.hpp"
#include "tsi/reformulation.hpp"
#include "tsi/stepper.hpp"

namespace tsi {

/// What every registered object tells about itself.
struct TSI_API EntryInfo {
  std::string name;
  std::vector<std::string> aliases;
  std::string summary;   ///< one line
  ParamSchema params;    ///< the parameters its config section accepts
  std::string provider;  ///< "core" or the plugin file that registered it (set by the registry)
};

using ModelFactory = std::function<std::unique_ptr<Model>(const Params&)>;
using ReformulationFactory =
    std::function<std::unique_ptr<Reformulation>(std::shared_ptr<const Model>, const Params&)>;
/// A scheme from its resolved parameters; it is bound to a problem and step size later.
using SchemeFactory = std::function<std::unique_ptr<Scheme>(const Params&)>;

struct ModelEntry;
struct ReformulationEntry;
struct SchemeEntry;

/// What a config selects: the three registered entries a run is assembled from.
struct TSI_API Selection {
  const ModelEntry& model;
  const ReformulationEntry& reformulation;
  const SchemeEntry& scheme;
  /// The scheme's resolved and completed parameters, set when the reformulation is completed
  /// (a two-scale data order follows the scheme's traits, which may depend on them).
  const Json* scheme_params = nullptr;
};

/// Completes an entry's resolved parameters from the selection: sets the ones its schema left
/// null (optional, no fixed default) to what this model and scheme need. Runs after the
/// schema check, before anything is built.
using CompleteFn = std::function<void(Json& params, const Selection& selection)>;

/// The traits of a scheme whose order or needs follow from its parameters (a composition's
/// method and base, an Adams-Bashforth order), from its resolved parameters.
using TraitsFn = std::function<StepperTraits(const Json& params)>;

/// Where a model's order is observable at T = 1 from its default u0: `tsi check`'s defaults
/// and the regime of the conformance suite, which runs every scheme there.
struct TSI_API VerificationRegime {
  std::vector<double> epsilons = {1.0, 1e-3};  ///< in (0, 1]
  std::vector<long> steps = {4, 8, 16, 32};    ///< numbers of steps over T = 1, increasing
  /// Model parameters of the regime besides eps (a particle model's small plasma), under what
  /// the caller sets (tsi check --set model.KEY=VALUE).
  Json params = Json::object();
};

struct TSI_API ModelEntry {
  EntryInfo info;
  VerificationRegime verification;
  int default_n_tau = 64;  ///< tau resolution for the two-scale reformulation (SPEC.md sec. 4)
  /// Degree of J grad H1 as a polynomial in u (Henon-Heiles 2, NLS 3), 0 if not polynomial:
  /// sets the Gauss-Legendre nodes of average-vector-field schemes (quadrature_nodes).
  int nonlinearity_degree = 0;
  /// The model has a linear remainder R (Model::linear_remainder() not empty, Klein-Gordon),
  /// for some of its parameters at least: some schemes then need prepared data of a higher
  /// order (StepperTraits::remainder_data_order). `tsi check` fails a model that has one
  /// without declaring it.
  bool linear_remainder = false;
  ModelFactory create;
};

/// A registered field f(t, u) (tsi/field.hpp): what a run names in model.f of the core's
/// "matrix" model, whose A is a matrix in the run's JSON.
struct TSI_API FieldEntry {
  EntryInfo info;  ///< info.params is unused: a field has no parameters of its own
  Index dim = 0;   ///< the number of entries of u it takes; 0: any (A's size decides)
  bool time_dependent = false;  ///< f depends on t (the model then carries t as one more variable)
  bool is_complex = false;      ///< f takes and gives complex states
  /// The default u0 of a run with this field, in physical variables; empty: the run must
  /// give model.u0.
  Vector initial_value;
  /// The field for states of `dim` entries (dim already checked against FieldEntry::dim).
  std::function<std::shared_ptr<const Field>(Index dim)> create;
};

struct TSI_API ReformulationEntry {
  EntryInfo info;
  ReformulationFactory create;
  CompleteFn complete;  ///< optional (two-scale: n_tau from the model, data order from the scheme)
};

struct TSI_API SchemeEntry {
  EntryInfo info;
  StepperTraits traits;
  SchemeFactory create;
  CompleteFn complete;  ///< optional (SE2: quadrature nodes from the model's nonlinearity)
  TraitsFn traits_for;  ///< optional: traits that depend on the parameters (else `traits`)
};

/// What a scheme is with these resolved parameters: traits_for(params) when the scheme has
/// one, else its declared traits.
TSI_API StepperTraits scheme_traits(const SchemeEntry& scheme, const Json& params);
/// The same for the scheme's default parameters (what `tsi list` and `tsi check` show).
TSI_API StepperTraits default_traits(const SchemeEntry& scheme);

/// The runtime registry of models, reformulations and schemes (PETSc TSRegister / OpenFOAM
/// runtime selection). Look-ups accept names and aliases; a miss lists the valid names.
class TSI_API Registry {
 public:
  /// A run's registry is its caller's (the runner's, a Python session's): nothing is process wide.
  Registry();
  ~Registry();
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  /// Registration. A name or alias already taken (within its kind) is a PluginError that
  /// names who provided it first. Every model gets the common parameters "eps" and "u0".
  void add_model(ModelEntry entry);
  void add_reformulation(ReformulationEntry entry);
  void add_scheme(SchemeEntry entry);
  /// A field f(t, u) for the core's "matrix" model (model.f names it).
  void add_field(FieldEntry entry);

  /// Look-ups by name or alias; `field` is the config path reported on a miss.
  const ModelEntry& model(const std::string& name, const std::string& field = "model.name") const;
  const ReformulationEntry& reformulation(const std::string& name,
                                          const std::string& field = "reformulation.name") const;
  const SchemeEntry& scheme(const std::string& name, const std::string& field = "scheme.name") const;
  const FieldEntry& field(const std::string& name, const std::string& path = "model.f") const;

  /// Entries sorted by name.
  std::vector<const ModelEntry*> models() const;
  std::vector<const ReformulationEntry*> reformulations() const;
  std::vector<const SchemeEntry*> schemes() const;
  std::vector<const FieldEntry*> fields() const;

  /// Refuses a scheme/reformulation pair the scheme does not support, naming the compatible
  /// reformulations.
  void check_compatible(const SchemeEntry& scheme, const ReformulationEntry& reformulation) const;

  /// The provider stamped on entries added from now on ("core" by default).
  void set_provider(std::string provider);
  const std::string& provider() const;
  /// Removes everything a provider added (a plugin whose registration failed half-way).
  void remove_provider(const std::string& provider);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Gauss-Legendre nodes that integrate the model's nonlinearity along a segment exactly
/// (degree d needs (d + 2) / 2 nodes); 6 for a non-polynomial one.
TSI_API int default_quadrature_nodes(const ModelEntry& model);

/// Registers the core's entries: the three reformulations (two-scale, filtered, direct), the
/// "matrix" model (A from the run's JSON, f a registered field) and its built-in field
/// "quickstart".
TSI_API void register_core(Registry& registry);

}  // namespace tsi
