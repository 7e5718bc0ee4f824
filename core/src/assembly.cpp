#include "tsi/assembly.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "tsi/error.hpp"
#include "tsi/fft.hpp"
#include "tsi/matrix_model.hpp"
#include "tsi/memory.hpp"
#include "tsi/npy.hpp"
#include "reformulations/two_scale.hpp"

namespace tsi {
namespace {

const Json& section_object(const Json& config, const std::string& key) {
  static const Json empty = Json::object();
  if (!config.contains(key) || config.at(key).is_null()) return empty;
  const Json& s = config.at(key);
  if (!s.is_object()) throw ConfigError(key, "got " + s.dump() + ", expected an object");
  return s;
}

std::string name_of(const Json& section, const std::string& key, const std::string& fallback) {
  if (!section.contains("name")) {
    if (fallback.empty()) throw ConfigError(key + ".name", "missing; it names the " + key + " to use");
    return fallback;
  }
  const Json& n = section.at("name");
  if (!n.is_string()) throw ConfigError(key + ".name", "got " + n.dump() + ", expected a string");
  return n.get<std::string>();
}

Json without_name(const Json& section) {
  Json out = section;
  out.erase("name");
  return out;
}

bool supports(const SchemeEntry& scheme, const std::string& reformulation) {
  const auto& r = scheme.traits.reformulations;
  return std::find(r.begin(), r.end(), reformulation) != r.end();
}

}  // namespace

Footprint two_scale_footprint(const Model& model, const Params& reformulation, const Scheme& scheme,
                              const std::string& scheme_name, bool bound_before_preparation,
                              const Context& context) {
  Footprint f;
  if (!reformulation.has("n_tau")) return f;  // not the two-scale reformulation
  f.dim = static_cast<double>(model.dim());
  f.n_tau = static_cast<double>(reformulation.integer("n_tau"));
  // A real model's state holds tau modes 0 .. n_tau/2 (the real layout).
  const bool real = TwoScale::real_layout_for(model) &&
                    !(reformulation.has("real_layout") && !reformulation.boolean("real_layout"));
  const double modes = real ? f.n_tau / 2 + 1 : f.n_tau;
  f.state_bytes = 16.0 * f.dim * modes;
  f.scheme = scheme_name;
  // The layout the problem will have, from the sizes alone (nothing of them allocated yet).
  const double size = f.dim * modes;
  const bool per_tau_mode = TwoScale::diagonal_run(model) > 1;
  ProblemLayout layout;
  layout.size = static_cast<Index>(std::min(size, 9e18));
  layout.diagonal_values = per_tau_mode ? static_cast<Index>(modes) : layout.size;
  f.scheme_vectors = scheme.state_vectors(layout);
  const int order =
      reformulation.has("initial_data_order") ? static_cast<int>(reformulation.integer("initial_data_order")) : 1;
  const std::string method =
      reformulation.has("initial_data_method") ? reformulation.string("initial_data_method") : std::string("auto");
  double preparation = 0.0;
  const double work = TwoScale::work_vectors(model, order, method, &preparation);
  f.problem_vectors = work - preparation;
  f.preparation_vectors = preparation;
  if (real) {
    // The preparation's grids hold all n_tau modes (n_tau / modes states each); the problem
    // holds the real grid and, where its binding does not evaluate in place, the real field.
    f.preparation_vectors *= f.n_tau / modes;
    f.problem_vectors = 2.0;
  } else {
    // The complex layout's tau transforms: a batch that is not buffered (fewer than 32 tau
    // points or unknowns, or split by FFTW's threads) holds a whole grid, one state more.
    const Index values = static_cast<Index>(std::min(f.dim * f.n_tau, 9e18));
    const bool split = context.fft.for_size(values) > 1;
    if (f.dim < 2147483647.0 && !FftBatch::buffers(static_cast<int>(f.n_tau), static_cast<int>(f.dim), split))
      f.problem_vectors += 1.0;
  }
  // A run prepares its data before it binds the scheme (the preparation's grids are freed by
  // then); bound first, both are held at once.
  f.vectors = 1.0 + f.problem_vectors +
              (bound_before_preparation ? f.scheme_vectors + f.preparation_vectors
                                        : std::max(f.scheme_vectors, f.preparation_vectors));
  return f;
}

namespace {

// Refused before anything of the state's size is allocated when the run cannot fit, with what
// the caller keeps besides (`kept` bytes, named by `kept_field`).
void check_footprint(const Footprint& f, double limit, double kept_states, double physical_dim,
                     const std::string& kept_field) {
  const double kept = 16.0 * kept_states * physical_dim;
  const bool machine = !(limit > 0.0);
  const double available = machine ? allocatable_bytes() : limit;
  const std::string who = machine ? std::string("this process") : std::string("the memory limit");
  if (f.state_bytes > 0.0 && f.bytes() > available)
    throw ConfigError(
        "reformulation.n_tau",
        fmt::format("got {:.0f}: with the model's {:.0f} unknowns a run needs about {:.3g} GB: {:.3g} vectors of "
                    "{:.0f} x {:.0f} complex values ({:.3g} GB each; tau modes 0 .. n_tau/2 for a real model): the "
                    "state, {:.3g} of scheme \"{}\", {:.3g} of the two-scale problem and {:.3g} of its prepared data; "
                    "{} has {:.3g} GB available",
                    f.n_tau, f.dim, f.bytes() / 1e9, f.vectors, f.dim, f.state_bytes / (16.0 * f.dim),
                    f.state_bytes / 1e9, f.scheme_vectors, f.scheme, f.problem_vectors, f.preparation_vectors, who,
                    available / 1e9));
  if (kept > 0.0 && f.bytes() + kept > available)
    throw ConfigError(kept_field, fmt::format("got {:.0f} times: their states ({:.0f} x {:.0f} complex values) take "
                                              "{:.3g} GB while the run goes{}; {} has {:.3g} GB available: ask for "
                                              "fewer times, or save states to files as the run goes "
                                              "(output.state_every)",
                                              kept_states, kept_states, physical_dim, kept / 1e9,
                                              f.bytes() > 0.0 ? fmt::format(", besides the run's {:.3g} GB", f.bytes() / 1e9)
                                                              : std::string(),
                                              who, available / 1e9));
}

// Whether a model's "u0" is the common parameter (an array, or the name of a .npy file); a
// model that declares a "u0" of its own keeps its own meaning.
bool u0_may_name_a_file(const ModelEntry& entry) {
  const auto& params = entry.info.params;
  const auto it = std::find_if(params.begin(), params.end(), [](const ParamSpec& p) { return p.name == "u0"; });
  return it != params.end() && it->type == ParamType::Array;
}

// model.u0 naming a .npy file: made absolute (a relative name is relative to the working
// directory here; the runner resolves it against the config file's directory first), and its
// header read and checked now, before anything is computed or written.
std::string checked_u0_file(const Json& value) {
  const std::string name = value.get<std::string>();
  if (name.empty())
    throw ConfigError("model.u0", "got \"\", expected an array of values or the name of a .npy file");
  std::error_code ec;
  std::filesystem::path file = std::filesystem::absolute(name, ec);
  if (ec) throw ConfigError("model.u0", "cannot resolve the file name \"" + name + "\": " + ec.message());
  file = file.lexically_normal();
  try {
    (void)read_npy_header(file.string());
  } catch (const Error& e) {
    throw ConfigError("model.u0", std::string(e.what()) + " (model.u0 as a string names a .npy file of the initial "
                                                          "value in physical variables)");
  }
  return file.string();
}

}  // namespace

Json ResolvedEntry::section() const {
  Json out = {{"name", name}};
  out.update(params);
  return out;
}

Json ResolvedSelection::sections() const {
  return {{"model", model.section()}, {"reformulation", reformulation.section()}, {"scheme", scheme.section()}};
}

ResolvedSelection resolve_selection(const Json& config, const Registry& registry) {
  if (!config.is_object()) throw ConfigError("config", "got " + config.dump() + ", expected a JSON object");
  const Json& model = section_object(config, "model");
  const Json& scheme = section_object(config, "scheme");
  const Json& reformulation = section_object(config, "reformulation");

  const ModelEntry& model_entry = registry.model(name_of(model, "model", ""));
  const SchemeEntry& scheme_entry = registry.scheme(name_of(scheme, "scheme", "se1"));
  const auto& supported = scheme_entry.traits.reformulations;
  const std::string default_reformulation =
      supports(scheme_entry, "two-scale") || supported.empty() ? "two-scale" : supported.front();
  const ReformulationEntry& reformulation_entry =
      registry.reformulation(name_of(reformulation, "reformulation", default_reformulation));
  registry.check_compatible(scheme_entry, reformulation_entry);

  Selection selection{model_entry, reformulation_entry, scheme_entry};
  Json model_given = without_name(model);
  std::string u0_file;  // model.u0 as the name of a .npy file
  if (model_given.contains("u0") && model_given["u0"].is_string() && u0_may_name_a_file(model_entry)) {
    u0_file = checked_u0_file(model_given["u0"]);
    model_given.erase("u0");
  }
  Json model_params = resolve_params(model_entry.info.params, model_given, "model");
  if (!u0_file.empty()) model_params["u0"] = u0_file;
  Json scheme_params = resolve_params(scheme_entry.info.params, without_name(scheme), "scheme");
  Json reformulation_params =
      resolve_params(reformulation_entry.info.params, without_name(reformulation), "reformulation");
  if (scheme_entry.complete) scheme_entry.complete(scheme_params, selection);
  selection.scheme_params = &scheme_params;
  if (reformulation_entry.complete) reformulation_entry.complete(reformulation_params, selection);
  return {{model_entry.info.name, std::move(model_params)},
          {reformulation_entry.info.name, std::move(reformulation_params)},
          {scheme_entry.info.name, std::move(scheme_params)}};
}

namespace {

// "entry 5", with its index in a shape of several dimensions: "entry 5 (index (1, 1) of shape (2, 4))".
std::string entry_name(std::uint64_t flat, const std::vector<std::uint64_t>& shape) {
  if (shape.size() < 2) return fmt::format("entry {}", flat);
  std::vector<std::uint64_t> index(shape.size());
  std::uint64_t rest = flat;
  for (std::size_t k = shape.size(); k-- > 0;) {
    index[k] = shape[k] ? rest % shape[k] : 0;
    rest = shape[k] ? rest / shape[k] : 0;
  }
  return fmt::format("entry {} (index {} of shape {})", flat, npy_shape_text(index), npy_shape_text(shape));
}

// A shape without its axes of length 1: a file of shape (8, 6, 1) holds an (8, 6) grid.
std::vector<std::uint64_t> without_unit_axes(std::vector<std::uint64_t> shape) {
  shape.erase(std::remove(shape.begin(), shape.end(), std::uint64_t{1}), shape.end());
  return shape;
}

// A model whose physical state has several axes (a 2-D or 3-D grid) reads model.u0's file in
// that shape, in C order; a file of another shape holds the same count of values in another
// order (a transposed grid, a flat array that does not say its order) and is refused, naming
// both shapes. A model of one axis takes any shape (its values in C order).
void check_u0_shape(const std::vector<std::uint64_t>& expected, const NpyHeader& header, const std::string& file) {
  const std::vector<std::uint64_t> want = without_unit_axes(expected), got = without_unit_axes(header.shape);
  if (want.size() < 2 || got == want) return;
  std::string hint;
  std::vector<std::uint64_t> sorted_want = want, sorted_got = got;
  std::sort(sorted_want.begin(), sorted_want.end());
  std::sort(sorted_got.begin(), sorted_got.end());
  if (got.size() == 1)
    hint = fmt::format("a flat array does not say in which order its values go: save a.reshape{} if they go in C "
                       "order (the last axis fastest)",
                       npy_shape_text(want));
  else if (std::equal(got.begin(), got.end(), want.rbegin(), want.rend()))
    hint = "its axes are reversed (a transposed array?): save np.ascontiguousarray(a.T)";
  else if (sorted_got == sorted_want)
    hint = "its axes are in another order: save np.ascontiguousarray(a.transpose(...)) with them in the model's order";
  else
    hint = "the same count of values in another shape would be read in the wrong order";
  throw ConfigError("model.u0",
                    fmt::format("{}: an array of shape {}, expected shape {} (the model's state in physical variables, "
                                "in C order: the last axis fastest); {}",
                                file, npy_shape_text(header.shape), npy_shape_text(expected), hint));
}

// model.u0 from a .npy file: as many values as the model's dimension, in the model's shape
// where it has several axes (check_u0_shape), else in any shape; finite; real for a real model
// (a complex file whose imaginary parts are all zero is taken).
Vector initial_value_from_file(const Model& model, const std::string& file) {
  const auto refuse = [&](const std::string& what) {
    return ConfigError("model.u0", fmt::format("{}: {}", file, what));
  };
  NpyHeader header;
  try {
    header = read_npy_header(file);
  } catch (const Error& e) {
    throw ConfigError("model.u0", e.what());
  }
  const std::string kind = model.is_complex() ? "complex" : "real";
  std::vector<std::uint64_t> expected;
  std::uint64_t product = 1;
  for (const Index n : model.physical_shape()) {
    expected.push_back(static_cast<std::uint64_t>(n));
    product *= static_cast<std::uint64_t>(n);
  }
  // A declared shape that does not hold the model's dimension (a split run's share) says nothing.
  const bool one_axis =
      without_unit_axes(expected).size() < 2 || product != static_cast<std::uint64_t>(model.physical_dim());
  if (header.count != static_cast<std::uint64_t>(model.physical_dim()))
    throw refuse(fmt::format("{} values (shape {}), expected {} (the model's dimension: {} values in physical "
                             "variables, {})",
                             header.count, npy_shape_text(header.shape), model.physical_dim(), kind,
                             one_axis ? std::string("in any shape") : "of shape " + npy_shape_text(expected)));
  if (!one_axis) check_u0_shape(expected, header, file);
  NpyArray array;
  try {
    array = read_npy(file);
  } catch (const Error& e) {
    throw ConfigError("model.u0", e.what());
  }
  const Vector& x = array.values;
  if (array.header.count != header.count)  // the file was replaced between the two reads
    throw refuse(fmt::format("{} values, expected {}", array.header.count, model.physical_dim()));
  for (Index i = 0; i < x.size(); ++i) {
    const auto flat = static_cast<std::uint64_t>(i);
    if (!std::isfinite(x(i).real()) || !std::isfinite(x(i).imag()))
      throw refuse(fmt::format("{} is {}{}; expected finite values", entry_name(flat, array.header.shape),
                               x(i).real(), array.header.is_complex ? fmt::format("{:+}j", x(i).imag()) : ""));
    if (!model.is_complex() && x(i).imag() != 0.0)
      throw refuse(fmt::format("{} is {}{:+}j: a complex value ('{}'), expected real values (this model's state is "
                               "real; a complex file is taken only when every imaginary part is 0)",
                               entry_name(flat, array.header.shape), x(i).real(), x(i).imag(), array.header.descr));
  }
  return model.from_physical(x);
}

}  // namespace

Vector initial_value(const Model& model, const Json& model_params) {
  if (!model_params.contains("u0") || model_params["u0"].is_null()) return model.initial_value();
  const Json& u0 = model_params["u0"];
  if (u0.is_string()) return initial_value_from_file(model, u0.get<std::string>());
  if (!u0.is_array() || static_cast<Index>(u0.size()) != model.physical_dim())
    throw ConfigError("model.u0", fmt::format("got {} entries, expected {} (the model's dimension)",
                                              u0.is_array() ? u0.size() : 1, model.physical_dim()));
  Vector x(model.physical_dim());
  for (Index i = 0; i < model.physical_dim(); ++i) {
    const Json& v = u0[static_cast<size_t>(i)];
    if (v.is_number())
      x(i) = v.get<double>();
    else if (v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number()) {
      if (!model.is_complex() && v[1].get<double>() != 0.0)
        throw ConfigError(fmt::format("model.u0[{}]", i),
                          "got " + v.dump() + ", expected a real number (this model's state is real)");
      x(i) = Complex(v[0].get<double>(), v[1].get<double>());
    } else
      throw ConfigError(fmt::format("model.u0[{}]", i), "got " + v.dump() + ", expected a number or [re, im]");
  }
  return model.from_physical(x);
}

Assembly assemble(const ResolvedSelection& resolved, const Registry& registry, const AssemblyOptions& options) {
  Assembly a;
  a.model_entry = &registry.model(resolved.model.name);
  a.reformulation_entry = &registry.reformulation(resolved.reformulation.name);
  a.scheme_entry = &registry.scheme(resolved.scheme.name);
  a.model = a.model_entry->create(Params(resolved.model.params, options.context));
  a.u0 = initial_value(*a.model, resolved.model.params);
  // A matrix model refuses a tau grid that aliases its frequencies (matrix_model.hpp).
  if (const Json n_tau = resolved.reformulation.params.value("n_tau", Json()); n_tau.is_number_integer())
    check_matrix_model_n_tau(*a.model_entry, *a.model, n_tau.get<long>());
  a.traits = scheme_traits(*a.scheme_entry, resolved.scheme.params);
  // The scheme first (its parameters only): its vector count for the problem's layout sizes the
  // footprint, checked before the reformulation allocates anything of the state's size.
  a.scheme = a.scheme_entry->create(Params(resolved.scheme.params, options.context));
  const Params reformulation_params(resolved.reformulation.params, options.context);
  const bool binds = options.h > 0.0;
  a.footprint = two_scale_footprint(*a.model, reformulation_params, *a.scheme, a.scheme_entry->info.name, binds,
                                    options.context);
  check_footprint(a.footprint, options.memory_bytes, options.kept_states,
                  static_cast<double>(a.model->physical_dim()), options.kept_states_field);
  a.reformulation = a.reformulation_entry->create(a.model, reformulation_params);
  const StepperTraits& traits = a.traits;
  const std::string pair = fmt::format("model \"{}\" on the \"{}\" reformulation", a.model_entry->info.name,
                                       a.reformulation_entry->info.name);
  if (traits.needs_diagonal_linear_part && !a.reformulation->has_diagonal_linear_part())
    throw ConfigError("scheme.name",
                      fmt::format("scheme \"{}\" needs a linear part diagonal in the problem's coordinates, which {} "
                                  "does not have; use a reformulation it supports ({})",
                                  a.scheme_entry->info.name, pair, fmt::join(traits.reformulations, ", ")));
  // A capability the scheme uses and the problem lacks: named, with why it is missing.
  const auto refuse = [&](const std::string& needs, const char* why) {
    throw ConfigError("scheme.name", fmt::format("scheme \"{}\" needs {}, which {} does not provide{}",
                                                 a.scheme_entry->info.name, needs, pair, why));
  };
  if (traits.needs_exact_flows && !a.reformulation->has_exact_flows())
    refuse("the exact linear and nonlinear flows", a.model->has_exact_nonlinear_flow()
                                                       ? " (only \"direct\" in model variables does)"
                                                       : " (the model has no exact nonlinear flow)");
  if (traits.needs_second_order_form && !a.reformulation->second_order())
    refuse("the second-order form x'' = -Omega^2 x + g(x)",
           a.model->has_second_order_form()
               ? " (only \"direct\" does)"
               : " (the model does not declare it; models that do: fput, henon-heiles, klein-gordon, "
                 "klein-gordon-complex)");
  if (traits.needs_charged_particle_form && !a.reformulation->charged_particle())
    refuse("the Lorentz-force form x' = v, v' = v x B(x) + E(x)",
           a.model->has_charged_particle_form()
               ? " (only \"direct\" does)"
               : " (the model does not declare it; models that do: cpd, charged-particle-3d)");
  if (binds) a.bind(options.h);
  return a;
}

Stepper& Assembly::bind(Real h) {
  stepper = scheme->bind(*reformulation, h);
  return *stepper;
}

Assembly assemble_config(const Json& config, const Registry& registry, const AssemblyOptions& options) {
  return assemble(resolve_selection(config, registry), registry, options);
}

}  // namespace tsi
