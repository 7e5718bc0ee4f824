#include "run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <limits>

#include <sys/resource.h>

#include "config.hpp"
#include "dense_output.hpp"
#include "field_snapshots.hpp"
#include "interrupt.hpp"
#include "run_recorder.hpp"
#include "split_state_file.hpp"
#include "tsi/assembly.hpp"
#include "tsi/collective.hpp"
#include "tsi/device.hpp"
#include "tsi/device_kernels.hpp"
#include "tsi/phase.hpp"
#include "tsi/driver.hpp"
#include "tsi/error.hpp"
#include "tsi/stop_request.hpp"
#include "tsi/npy.hpp"
#include "tsi/output.hpp"
#include "tsi/version.hpp"

namespace tsi::app {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The reference's scheme section: its tolerance scaled by `tol_factor`, its substeps per fast
// period by `substep_factor`.
Json reference_scheme_section(const Json& ref, const SchemeEntry& scheme, double tol_factor, double substep_factor) {
  Json scheme_section = {{"name", scheme.info.name}};
  for (const auto& spec : scheme.info.params) {
    if (spec.name == "tol") scheme_section["tol"] = std::max(smallest_tolerance, ref["tol"].get<double>() * tol_factor);
    if (spec.name == "substeps_per_period")
      scheme_section["substeps_per_period"] = spec.default_value.get<double>() * substep_factor;
  }
  return scheme_section;
}

}  // namespace

namespace {

// The reference's objects, through the same assembler as the run's (a two-scale reference gets
// the model's own tau resolution and the data its scheme needs).
Assembly reference_assembly(const Json& config, const Registry& registry, const Json& scheme_section,
                            const RunSettings& settings) {
  AssemblyOptions options;
  options.context = settings.context;
  Json reformulation = {{"name", config["reference"]["reformulation"]}};
  if (config["reference"].value("n_tau", Json()).is_number()) reformulation["n_tau"] = config["reference"]["n_tau"];
  try {
    return assemble_config({{"model", config["model"]}, {"reformulation", reformulation}, {"scheme", scheme_section}},
                           registry, options);
  } catch (const ConfigError& e) {
    // The reference's reformulation is the reference section's: reformulation.n_tau here is
    // reference.n_tau (or the default it took), reformulation.name reference.reformulation.
    const std::string& field = e.field();
    if (field.rfind("reformulation.", 0) != 0) throw;
    const std::string key = field.substr(std::string("reformulation.").size());
    const std::string message = std::string(e.what()).substr(field.size() + 2);
    throw ConfigError("reference." + (key == "name" ? std::string("reformulation") : key),
                      message + (config["reference"].contains(key) ? "" : " (the reference's default)"));
  }
}

// The steps a reference will take, before it starts: an adaptive solver at least
// substeps_per_period per fastest period of the problem (NaN for a solver without that setting
// or a problem without a fast period), a fixed step t_end / reference.h (NaN without one).
struct ReferenceSteps {
  double adaptive = std::numeric_limits<double>::quiet_NaN();
  double fixed = std::numeric_limits<double>::quiet_NaN();
};

ReferenceSteps reference_steps(const Json& config, const Assembly& a, const Json& scheme_section) {
  ReferenceSteps steps;
  const Json& ref = config["reference"];
  const double t_end = config["time"]["t_end"];
  const double period = to_double(a.reformulation->fast_period());
  if (scheme_section.contains("substeps_per_period") && period > 0.0)  // in double: 1e300 with eps = 1e-300
    steps.adaptive = t_end / period * scheme_section["substeps_per_period"].get<double>();
  if (!ref["h"].is_null()) steps.fixed = t_end / ref["h"].get<double>();
  return steps;
}

// What the reference will cost, refused before it starts when it would exceed --max-steps.
void check_reference_cost(const Json& config, const Assembly& a, const Json& scheme_section, double limit) {
  const Json& ref = config["reference"];
  const double t_end = config["time"]["t_end"];
  const ReferenceSteps steps = reference_steps(config, a, scheme_section);
  if (!std::isnan(steps.adaptive) && !(steps.adaptive <= limit))
    throw ConfigError("reference", fmt::format("{} on the {} problem would take at least {:.3g} steps ({} per fast "
                                               "period 2 pi eps / {:g}), more than --max-steps = {:.3g}; use a "
                                               "two-scale reference, e.g. {{\"scheme\": \"se2\", \"reformulation\": "
                                               "\"two-scale\", \"h\": {}}}, or raise the limit with --max-steps N",
                                               a.scheme_entry->info.name, ref["reformulation"].get<std::string>(),
                                               steps.adaptive, scheme_section["substeps_per_period"].get<double>(),
                                               a.model->max_linear_frequency(), limit, t_end / 4096));
  if (!std::isnan(steps.fixed) && !(steps.fixed <= limit))
    throw ConfigError("reference.h", fmt::format("got {}: {:.3g} steps over t_end = {}; at most {:.3g} "
                                                 "(--max-steps; raise the limit with --max-steps N)",
                                                 ref["h"].get<double>(), steps.fixed, t_end, limit));
}

}  // namespace

RunSettings RunSettings::from_flags(int tau_grid_threads, int fft_threads, double max_steps) {
  if (!(max_steps >= 1.0 && max_steps <= 1e12))
    throw ConfigError("--max-steps", fmt::format("got {}, expected a number of steps from 1 to 1e12 (beyond "
                                                 "1e12, t_end / h is refused whatever the limit)",
                                                 max_steps));
  return {Context::with_threads(tau_grid_threads, fft_threads), max_steps};
}

void check_run_steps(const Json& config, double max_steps) {
  const double h = config["time"]["h"], t_end = config["time"]["t_end"];
  const double estimate = t_end / h;  // in double: t_end / h may be 1e300, far beyond a long
  if (!(estimate <= max_steps))
    throw ConfigError("time.h", fmt::format("got {}: the run would take {:.3g} steps (t_end = {} / h), more than "
                                            "--max-steps = {:.3g}; choose a larger time.h or a smaller time.t_end, "
                                            "or raise the limit with --max-steps N",
                                            h, estimate, t_end, max_steps));
  if (config.contains("output") && config["output"].value("error_estimate", std::string("none")) == "richardson" &&
      !(2.0 * estimate <= max_steps))
    throw ConfigError("output.error_estimate",
                      fmt::format("\"richardson\" reruns the run at h / 2: {:.3g} steps, more than --max-steps = "
                                  "{:.3g}; raise the limit with --max-steps N",
                                  2.0 * estimate, max_steps));
}

void check_work_estimate(const Json& config, const Registry& registry, const RunSettings& settings) {
  check_run_steps(config, settings.max_steps);
  if (config.contains("reference")) check_reference_cost(config, registry, settings);
}

namespace {

// The model of a config whose reference is "exact", refused (ConfigError naming
// reference.scheme) when it declares no exact solution.
std::shared_ptr<const Model> model_with_exact_solution(const Json& config, const Registry& registry,
                                                       const RunSettings& settings) {
  std::shared_ptr<const Model> model =
      registry.model(config["model"]["name"]).create(Params(without_name(config["model"]), settings.context));
  if (!model->exact_solution())
    throw ConfigError("reference.scheme",
                      fmt::format("got \"{}\", but the model \"{}\" declares no exact solution for these parameters "
                                  "(the matrix model has one with an affine field such as \"linear\", nls with "
                                  "initial \"plane-wave\", klein-gordon with it and lambda 0); choose a reference "
                                  "solver, e.g. \"rk78\"",
                                  exact_reference, config["model"]["name"].get<std::string>()));
  return model;
}

// A model's exact solution starts from its own data (nls and klein-gordon: the plane wave of
// model.initial): a run from another model.u0 has none, refused before the run, not after it.
void check_exact_start(const Json& config, const Model& model) {
  const Json& section = config["model"];
  if (!section.contains("u0") || section["u0"].is_null()) return;
  const Vector x0 = model.to_physical(initial_value(model, without_name(section)));
  try {
    (void)model.exact_solution()->at(x0, 0.0);
  } catch (const ConfigError&) {
    throw;
  } catch (const Error& e) {
    const Json& u0 = section["u0"];
    throw ConfigError("model.u0",
                      fmt::format("got {}, but reference.scheme is \"{}\": {}; leave model.u0 out (the model's own "
                                  "data, e.g. model.initial \"plane-wave\", are then the initial value), or choose a "
                                  "reference solver, e.g. \"rk78\"",
                                  u0.is_string() ? "the file " + u0.dump() : fmt::format("{} values", u0.size()),
                                  exact_reference, e.what()));
  }
}

}  // namespace

void check_reference_cost(const Json& config, const Registry& registry, const RunSettings& settings) {
  const Json& ref = config["reference"];
  if (ref["scheme"] == exact_reference) {
    check_exact_start(config, *model_with_exact_solution(config, registry, settings));
    return;
  }
  const Json scheme_section =
      reference_scheme_section(ref, registry.scheme(ref["scheme"], "reference.scheme"), 1.0, 1.0);
  check_reference_cost(config, reference_assembly(config, registry, scheme_section, settings), scheme_section,
                       settings.max_steps);
}

ReferenceEstimate estimate_reference(const Json& config, const Registry& registry, const RunSettings& settings) {
  ReferenceEstimate estimate;
  const Json& ref = config["reference"];
  if (ref["scheme"] == exact_reference) {
    estimate.exact = true;
    return estimate;
  }
  const Json scheme_section =
      reference_scheme_section(ref, registry.scheme(ref["scheme"], "reference.scheme"), 1.0, 1.0);
  const ReferenceSteps steps =
      reference_steps(config, reference_assembly(config, registry, scheme_section, settings), scheme_section);
  estimate.at_least = !std::isnan(steps.adaptive);
  estimate.steps = std::isnan(steps.adaptive) ? steps.fixed : std::isnan(steps.fixed) ? steps.adaptive
                                                                                      : std::max(steps.adaptive, steps.fixed);
  estimate.accuracy_check = ref.value("estimate_accuracy", true);
  return estimate;
}

namespace {

// u(t_end) in model variables from an assembly's initial value in `steps` equal steps, with
// progress under the name `what`. An interrupt, or a state that stops being finite, is an
// error (a run's own integration records these instead; this serves the side runs: the
// reference and the error estimate's).
Vector final_model_state(Assembly& a, double t_end, long steps, const ProgressFn& progress, const char* what) {
  Vector y = a.reformulation->prepare(a.u0);
  SteppedClock progress_clock;  // the progress function is called when it is read: every few steps
  integrate(a.bind(Real(t_end) / static_cast<Real>(steps)), y, steps, [&](long n, Real t, const Vector& state) {
    if (!state.allFinite()) throw Error(fmt::format("{}: the state is not finite at t = {:.6g} (step {})", what, to_double(t), n));
    if (interrupted()) throw Error(fmt::format("interrupted by signal {} at t = {:.6g}", interrupt_signal(), to_double(t)));
    if (progress && progress_clock.tick()) progress({what, n, steps, to_double(t), t_end});
    return true;
  }, a.reformulation->repreparation());
  return a.reformulation->read_back(y, t_end);
}

// The reference's final state in model variables, with its scheme's tolerance scaled by
// `tol_factor` and its substeps per fast period by `substep_factor`.
Vector reference_model_state(const Json& config, const Registry& registry, const RunSettings& settings,
                             double tol_factor, double substep_factor, const ProgressFn& progress, const char* what) {
  const Json& ref = config["reference"];
  const SchemeEntry& scheme = registry.scheme(ref["scheme"], "reference.scheme");
  const Json scheme_section = reference_scheme_section(ref, scheme, tol_factor, substep_factor);
  Assembly a = reference_assembly(config, registry, scheme_section, settings);
  if (tol_factor == 1.0 && substep_factor == 1.0) check_reference_cost(config, a, scheme_section, settings.max_steps);
  const double t_end = config["time"]["t_end"];
  if (t_end <= 0.0) return a.reformulation->read_back(a.reformulation->prepare(a.u0), t_end);
  // An adaptive reference goes in chunks of t_end / 256 (it chooses its substeps inside
  // each): an interrupt stops it within one chunk, and a long one shows its progress.
  constexpr long adaptive_chunks = 256;
  const double h = ref["h"].is_null() ? t_end / adaptive_chunks : ref["h"].get<double>() / substep_factor;
  return final_model_state(a, t_end, std::max(1L, std::lround(t_end / h)), progress, what);
}

}  // namespace

ReferenceSolution compute_reference(const Json& config, const Registry& registry, const RunSettings& settings,
                                    const ProgressFn& progress) {
  ReferenceSolution out;
  out.settings = config["reference"];
  const auto start = Clock::now();
  if (out.settings["scheme"] == exact_reference) {
    const std::shared_ptr<const Model> model = model_with_exact_solution(config, registry, settings);
    const Vector x0 = model->to_physical(initial_value(*model, without_name(config["model"])));
    const ExactSolution::Value exact = model->exact_solution()->at(x0, config["time"]["t_end"].get<double>());
    out.x = exact.x;
    out.accuracy = to_double(exact.accuracy);
    out.wall_seconds = seconds_since(start);
    return out;
  }
  const Vector u = reference_model_state(config, registry, settings, 1.0, 1.0, progress, "reference");  // its cost checked first
  std::shared_ptr<const Model> model =
      registry.model(config["model"]["name"]).create(Params(without_name(config["model"]), settings.context));
  out.x = model->to_physical(u);
  out.wall_seconds = seconds_since(start);
  out.accuracy = std::numeric_limits<double>::quiet_NaN();
  if (out.settings.value("estimate_accuracy", true)) {
    const Vector tighter = model->to_physical(reference_model_state(config, registry, settings, 0.1, 2.0, progress, "reference check"));
    out.accuracy = to_double(std::max(model->error_norm(out.x - tighter) / model->error_norm(tighter),
                                      model->rounding_floor(u)));
  }
  return out;
}

std::string reference_key(const Json& config) {
  return Json{config["model"], config["time"]["t_end"], config.value("reference", Json())}.dump();
}

Json state_to_json(const Vector& x, bool complex_state) {
  Json out = Json::array();
  for (Index i = 0; i < x.size(); ++i) {
    if (complex_state)
      out.push_back({to_double(x(i).real()), to_double(x(i).imag())});
    else
      out.push_back(to_double(x(i).real()));
  }
  return out;
}

Json state_entry(const Vector& x, bool complex_state, const std::vector<std::uint64_t>& shape, const std::string& file) {
  if (x.size() <= max_inline_state) return state_to_json(x, complex_state);
  return state_file_entry(complex_state, shape, file);
}

Json state_file_entry(bool complex_state, const std::vector<std::uint64_t>& shape, const std::string& file) {
  return {{"file", file}, {"dtype", complex_state ? "complex128" : "float64"}, {"shape", shape}};
}

namespace {

// The shape of the state files: model.u0's file's when the run started from one (an N x 4
// particle array stays one), else the model's physical shape (a grid's (n_x, n_y, n_z)), else
// (dim,).
std::vector<std::uint64_t> state_shape(const Json& config, const Model& model, Index dim) {
  std::vector<std::uint64_t> flat = {static_cast<std::uint64_t>(dim)};
  std::vector<std::uint64_t> declared;
  std::uint64_t count = 1;
  for (const Index n : model.physical_shape()) {
    declared.push_back(static_cast<std::uint64_t>(n));
    count *= static_cast<std::uint64_t>(n);
  }
  if (count == flat.front()) flat = declared;
  const Json& u0 = config["model"].value("u0", Json());
  if (!u0.is_string()) return flat;
  try {
    const NpyHeader header = read_npy_header(u0.get<std::string>());
    return header.count == static_cast<std::uint64_t>(dim) ? header.shape : flat;
  } catch (const Error&) {  // gone since the run read it: the plain shape
    return flat;
  }
}

// result.json's dense_output: the times, the interpolation's degree, and u at each time (null
// where the run did not reach it) inline up to max_inline_state values in all, else where
// u_times.npy holds them (NaN where not reached).
Json dense_output_entry(const DenseOutput& dense, const RunOutcome& outcome) {
  // How many were evaluated: the others (past where the run stopped, or left by an interrupt)
  // are null here and NaN in u_times.npy.
  const auto evaluated = std::count_if(dense.values().begin(), dense.values().end(),
                                       [](const Vector& u) { return u.size() > 0; });
  Json entry = {{"times", dense.times()}, {"degree", dense.degree()}, {"evaluated", evaluated}};
  std::uint64_t per_time = 1;
  for (const std::uint64_t d : outcome.state_shape) per_time *= d;
  if (per_time * dense.times().size() > static_cast<std::uint64_t>(max_inline_state)) {
    std::vector<std::uint64_t> shape = {dense.times().size()};
    shape.insert(shape.end(), outcome.state_shape.begin(), outcome.state_shape.end());
    entry["u"] = {{"file", u_times_file}, {"dtype", outcome.complex_state ? "complex128" : "float64"}, {"shape", shape}};
    return entry;
  }
  entry["u"] = Json::array();
  for (const Vector& u : dense.values())
    entry["u"].push_back(u.size() ? state_to_json(u, outcome.complex_state) : Json());
  return entry;
}

// u(t_end) in physical variables from the run's own configuration at `steps` steps (the same
// model, data, scheme and re-preparation; the Richardson estimate's coarser runs). A state
// that stops being finite, or an interrupt, is an error.
Vector final_state_with_steps(const Json& config, const Registry& registry, const RunSettings& settings, long steps,
                              const ProgressFn& progress, const char* what) {
  AssemblyOptions options;  // bound at the steps' size by final_model_state
  options.context = settings.context;
  Assembly a = assemble(resolved_selection(config), registry, options);
  return a.model->to_physical(final_model_state(a, config["time"]["t_end"], steps, progress, what));
}

// The Richardson estimate of the error of x = u_h(t_end) from u_{h/2} and u_{2h}: with
// d = |u_h - u_{h/2}| and D = |u_2h - u_h| (relative to |x|), the observed order p = log2(D / d)
// and the error d 2^p / (2^p - 1). The finer run measures the error at h itself (a step-size
// resonance at h shows in it, which coarser runs would miss); the coarser one checks the
// order: the run is in its asymptotic range where p lies between the scheme's uniform order
// and its order at fixed eps (0.5 to spare each side); elsewhere the record says so, and p is
// taken as the nearer of the two. A run that fails is recorded, not hidden.
Json richardson_estimate(const Json& config, const Registry& registry, const RunSettings& settings,
                         const StepperTraits& traits, const Model& model, const Vector& x, long steps,
                         const ProgressFn& progress) {
  const auto start = Clock::now();
  const double h = config["time"]["h"];
  Json out = {{"method", "richardson"}, {"h", {h / 2.0, h, 2.0 * h}}};
  Vector fine, coarse;
  try {  // whatever happens here, the run's own results are kept
    fine = final_state_with_steps(config, registry, settings, 2 * steps, progress, "error estimate (h / 2)");
    coarse = final_state_with_steps(config, registry, settings, steps / 2, progress, "error estimate (2 h)");
  } catch (const std::exception& e) {
    out["status"] = interrupted() ? "interrupted" : "failed";
    out["message"] = fmt::format("a run at another step failed: {}", e.what());
    out["relative"] = nullptr;
    out["wall_seconds"] = seconds_since(start);
    return out;
  }
  const Real scale = model.error_norm(x);
  const double d = to_double(model.error_norm(x - fine) / scale), D = to_double(model.error_norm(coarse - x) / scale);
  const int low = std::max(1, traits.order), high = std::max(low, traits.classical_order);
  const double observed = d > 0.0 && D > 0.0 ? std::log2(D / d) : std::numeric_limits<double>::quiet_NaN();
  const bool asymptotic = std::isfinite(observed) && observed >= low - 0.5 && observed <= high + 0.5;
  const double used = std::isfinite(observed) ? std::clamp(observed, static_cast<double>(low), static_cast<double>(high))
                                              : static_cast<double>(low);
  out["status"] = "completed";
  out["differences"] = {d, D};
  out["observed_order"] = std::isfinite(observed) ? Json(observed) : Json();
  out["declared_orders"] = {low, high};
  out["order_used"] = used;
  out["relative"] = d * std::pow(2.0, used) / (std::pow(2.0, used) - 1.0);
  out["asymptotic"] = asymptotic;
  if (!asymptotic)
    out["note"] = std::isfinite(observed)
                      ? fmt::format("observed order {:.2f} from 2 h, h and h / 2, outside [{}, {}] (0.5 to spare): "
                                    "not in the asymptotic range, the estimate is not reliable",
                                    observed, low, high)
                      : std::string("the runs at 2 h, h and h / 2 agree to the last digit: no order can be observed");
  out["wall_seconds"] = seconds_since(start);
  return out;
}

}  // namespace

namespace {

// Refuses (ConfigError naming the field) what a run split over processes cannot do: each
// process must make the same reductions in the same order, so nothing may decide from its own
// share alone (an adaptive step size: the norms of the fixed-point tests, the prepared data and
// the re-preparation are the whole state's), and the states the runner interpolates are not
// split.
void check_split_run(const Json& config, const Assembly& assembly, const Registry& registry) {
  const Model& model = *assembly.model;
  if (!model.split_across_processes())
    throw ConfigError("--split", fmt::format("the model \"{}\" does not split its state over processes; expected "
                                             "a model that does (vlasov-poisson-2d: its particles; nls, "
                                             "klein-gordon and klein-gordon-complex on a 2-D or 3-D grid: slabs of it)",
                                             config["model"]["name"].get<std::string>()));
  if (assembly.traits.adaptive)
    throw ConfigError("scheme", fmt::format("\"{}\" chooses its steps from the state, which a split run holds in "
                                            "shares; expected a scheme with fixed steps under --split",
                                            assembly.scheme_entry->info.name));
  if (config.contains("output") && config["output"].contains("times") && !config["output"]["times"].empty())
    throw ConfigError("output.times", "dense output is not available under --split; expected no output.times");
  if (config.contains("reference") && config["reference"]["scheme"] != exact_reference &&
      registry.scheme(config["reference"]["scheme"], "reference.scheme").traits.adaptive)
    throw ConfigError("reference.scheme", fmt::format("\"{}\" chooses its steps from the state, which a split run "
                                                      "holds in shares; expected a reference with a fixed step "
                                                      "(reference.h) under --split",
                                                      config["reference"]["scheme"].get<std::string>()));
}

// A failure on one process of a split run: the others wait in a reduction and would never
// learn of it. Rank 0 keeps what it has (the streamed rows, result.json saying "failed"), then
// every process is stopped.
[[noreturn]] void stop_split_run(const Collective& split, const std::string& stream_dir, const Json& result,
                                 RunRecorder& recorder, const std::string& message, int code) {
  fmt::print(stderr, "tsi: error: rank {} of {}: {}\n", split.rank(), split.size(), message);
  if (!stream_dir.empty()) {
    try {
      recorder.flush_csv();
      Json failed = result;
      failed["status"] = "failed";
      failed["message"] = fmt::format("rank {} of {}: {}; every rank was stopped; invariants.csv.partial holds the "
                                      "rows up to step {}",
                                      split.rank(), split.size(), message, recorder.steps());
      failed["t_reached"] = recorder.t_reached();
      failed["steps_done"] = recorder.steps();
      write_file_atomically(stream_dir + "/result.json", failed.dump(2) + "\n");
    } catch (const std::exception& e) {
      fmt::print(stderr, "tsi: error: {}\n", e.what());
    }
  }
  split.abort(code);
  std::abort();  // abort() does not return; a virtual call is not known to the compiler as noreturn
}

}  // namespace

void agree_to_start(const Collective& split, const Json& config, const Registry& registry,
                    const RunSettings& settings, const std::function<void()>& before) {
  std::exception_ptr failure;
  try {
    before();
    AssemblyOptions options;
    options.context = settings.context;
    const Assembly assembly = assemble(resolved_selection(config), registry, options);
    check_split_run(config, assembly, registry);
  } catch (...) {
    failure = std::current_exception();
  }
  Real refused[2] = {failure ? Real(1) : Real(0), failure && split.rank() == 0 ? Real(1) : Real(0)};  // anywhere, on rank 0
  split.max(refused, 2);
  if (refused[0] == 0.0) return;
  if (failure && split.rank() != 0 && refused[1] != 0.0) {
    try {
      std::rethrow_exception(failure);
    } catch (const std::exception& e) {
      throw ReportedElsewhere(e.what());
    }
  }
  if (failure) std::rethrow_exception(failure);
  throw Error(fmt::format("rank {} of {}: another rank refused the run (its error is above)", split.rank(),
                          split.size()));
}

namespace {

// Where a run's initial value comes from, for a refusal of it: the field the user gave it by
// (model.u0; else the model's data parameter given: a particle file, z0 and eps_z_t0, a plane
// wave's amplitude; else the model's own data), "got VALUE: " where the value is short, what it
// gives ("from model.z0 and model.eps_z_t0") and what to change.
struct InitialValueSource {
  std::string field = "model.name", got, gives = "(the model's own data)", remedy;
};

InitialValueSource initial_value_source(const Json& model) {
  const auto given = [&](const char* key) { return model.contains(key) && !model[key].is_null(); };
  InitialValueSource source;
  std::vector<std::string> fields;
  if (given("u0")) fields.push_back("u0");
  if (given("particles") && model["particles"].is_string()) fields.push_back("particles");
  for (const char* key : {"z0", "eps_z_t0", "amplitude"})
    if (given(key)) fields.push_back(key);
  if (fields.empty()) return source;
  const Json& first = model[fields.front()];
  source.field = "model." + fields.front();
  if (first.is_number() || first.is_string()) source.got = "got " + first.dump() + ": ";
  for (std::string& f : fields) f = "model." + f;
  source.gives = fmt::format("from {}", fmt::join(fields, " and "));
  source.remedy = fields.front() == "model.amplitude" ? " (a smaller model.amplitude)" : " (smaller values)";
  return source;
}

// output.times, checked: each in [0, t_end], and not with a re-prepared run.
std::vector<double> checked_output_times(const Json& config) {
  std::vector<double> times;
  if (!config.contains("output") || !config["output"].contains("times") || !config["output"]["times"].is_array())
    return times;
  const double t_end = config["time"]["t_end"];
  for (const Json& t : config["output"]["times"]) {
    if (!(t.get<double>() <= t_end))
      throw ConfigError(fmt::format("output.times[{}]", times.size()),
                        fmt::format("got {}, expected a time in [0, t_end = {}]", t.get<double>(), t_end));
    times.push_back(t.get<double>());
  }
  const Json& rconf = config["reformulation"];
  if (!times.empty() && rconf.contains("reprepare") && rconf["reprepare"] != "never")
    throw ConfigError("output.times", "cannot be combined with reformulation.reprepare: a re-prepared U is not "
                                      "smooth in t across its re-preparations, so it is not interpolated there");
  return times;
}

}  // namespace

namespace {

// --device cuda: what runs on the device, refused before anything runs otherwise.
void check_device_run(const Json& config, const Assembly& assembly, const RunSettings& settings) {
  if (!device::available())
    throw ConfigError("--device", "got \"cuda\", but this build of tsi has no CUDA backend; configure with "
                                  "-DTSI_WITH_CUDA=ON on a machine with the CUDA toolkit (docs/how-to/gpu.md)");
  if (device::device_count() == 0)
    throw ConfigError("--device", fmt::format("got \"cuda\", but {}", device::describe()));
  if (settings.context.collective)
    throw ConfigError("--device", "got \"cuda\" with --split; a split run's shares stay on the CPU");
  const std::string& reformulation = assembly.reformulation_entry->info.name;
  if (reformulation != "two-scale")
    throw ConfigError("reformulation.name", fmt::format("got \"{}\" with --device cuda; expected \"two-scale\" (the "
                                                        "device runs the two-scale problem)", reformulation));
  if (!dynamic_cast<const DeviceKernels*>(assembly.model.get()))
    throw ConfigError("model.name", fmt::format("got \"{}\" with --device cuda; expected a model with device kernels: "
                                                "nls, vlasov-poisson-2d", assembly.model_entry->info.name));
  const Json& mconf = config["model"];
  if (mconf.contains("tau_field") && mconf["tau_field"] != "per-tau")
    throw ConfigError("model.tau_field", fmt::format("got {} with --device cuda; expected \"per-tau\"",
                                                     mconf["tau_field"].dump()));
  // The device's tau grid is the complex layout's; a real model keeps it only when asked.
  if (!assembly.model->is_complex() && config["reformulation"].value("real_layout", true))
    throw ConfigError("reformulation.real_layout", "got true (the default for a real model) with --device cuda; "
                                                   "expected false: the device's tau grid is the complex layout");
  // The schemes whose steps were checked against the CPU on a device (docs/how-to/gpu.md): a
  // scheme that read a state's entries on the host would read a stale copy there.
  const std::string& scheme = assembly.scheme_entry->info.name;
  if (scheme != "se1" && scheme != "eab")
    throw ConfigError("scheme.name", fmt::format("got \"{}\" with --device cuda; expected one of the schemes checked "
                                                 "on the device: se1, eab", scheme));
  const Json& sconf = config["scheme"];
  if (sconf.contains("solver") && sconf["solver"] != "picard")
    throw ConfigError("scheme.solver", fmt::format("got {} with --device cuda; expected \"picard\"",
                                                   sconf["solver"].dump()));
  const Json& rconf = config["reformulation"];
  if (rconf.contains("reprepare") && rconf["reprepare"] != "never")
    throw ConfigError("reformulation.reprepare", fmt::format("got {} with --device cuda; expected \"never\"",
                                                             rconf["reprepare"].dump()));
  if (!checked_output_times(config).empty())
    throw ConfigError("output.times", "dense output is not available with --device cuda; expected none");
}

}  // namespace

RunPlan plan_run(const Json& config, const Registry& registry, const RunSettings& settings, bool check_reference) {
  RunPlan plan;
  // Construction: bad input (a model's own checks, u0 of the wrong shape, a run that cannot fit
  // in memory) is a ConfigError that propagates before anything runs. The scheme is bound after
  // the data are prepared: the preparation's temporaries are gone by then.
  AssemblyOptions assembly_options;  // bound after the preparation (assembly.bind in execute_run)
  assembly_options.context = settings.context;
  // Dense output keeps u at every output time until the run's end: counted before it starts.
  assembly_options.kept_states = static_cast<double>(checked_output_times(config).size());
  assembly_options.kept_states_field = "output.times";
  plan.assembly = assemble(resolved_selection(config), registry, assembly_options);
  Assembly& assembly = plan.assembly;
  // A reference that could not finish is refused now, not after the run.
  check_run_steps(config, settings.max_steps);
  if (config.contains("reference") && check_reference) check_reference_cost(config, registry, settings);
  const SchemeEntry& scheme_entry = *assembly.scheme_entry;
  const Model& model = *assembly.model;
  const Vector& u0 = assembly.u0;
  {  // an initial value whose invariants overflow (entries of 1e300) would only "blow up" at t = 0
    const InitialValueSource source = initial_value_source(config["model"]);
    if (!u0.allFinite())
      throw ConfigError(source.field, fmt::format("{}the initial value {} has non-finite entries; expected finite "
                                                  "numbers",
                                                  source.got, source.gives));
    const bool hamiltonian = model.has_hamiltonian_structure();
    const Real H0 = hamiltonian ? model.energy(u0) : 0, I0 = hamiltonian ? model.oscillatory_energy(u0) : 0,
               m0 = hamiltonian ? model.mass(u0) : 0;
    if (!std::isfinite(H0) || !std::isfinite(I0) || !std::isfinite(m0))
      throw ConfigError(source.field, fmt::format("{}H = {}, I = {}, m = {} at the initial value {}; expected an "
                                                  "initial value whose invariants are finite numbers{}",
                                                  source.got, H0, I0, m0, source.gives, source.remedy));
    // The model's own conserved invariants too (a particle energy sum w |v|^2 / 2 that overflows):
    // else their monitors are NaN from the first step. Not in a split run, whose invariants are
    // collective (its model checked its share's data when it was made).
    if (!settings.context.collective)
      for (const ModelInvariant& invariant : model.invariants()) {
        const Real value = invariant.conserved ? invariant.value(u0) : Real(0);
        if (!std::isfinite(value))
          throw ConfigError(source.field, fmt::format("{}{} = {} at the initial value {} ({}); expected an initial "
                                                      "value whose invariants are finite numbers{}",
                                                      source.got, invariant.name, value, source.gives,
                                                      invariant.description, source.remedy));
      }
  }

  const auto& rconf = config["reformulation"];
  if (settings.context.collective) check_split_run(config, assembly, registry);  // tsi run --split
  if (const long every = config.contains("output") ? config["output"].value("fields_every", 0L) : 0L; every > 0) {
    if (model.grid_fields().names.empty())
      throw ConfigError("output.fields_every",
                        fmt::format("got {}, but the model \"{}\" has no fields on a grid to write; expected 0, or a "
                                    "grid model (nls, klein-gordon, klein-gordon-complex)",
                                    every, assembly.model_entry->info.name));
    if (!FieldSnapshots::available())
      throw ConfigError("output.fields_every", fmt::format("got {}, but this tsi cannot write HDF5 ({}); build it "
                                                           "with libhdf5-dev installed (cmake finds it by itself)",
                                                           every, FieldSnapshots::unavailable_reason()));
  }
  const int data_needed = assembly.traits.data_order_for(assembly.model_entry->linear_remainder);
  if (rconf.contains("initial_data_order") && rconf["initial_data_order"].get<int>() < data_needed) {
    plan.warnings.push_back(fmt::format(
        "scheme \"{}\" needs prepared data of order {} for uniform accuracy; running with order {}",
        scheme_entry.info.name, data_needed, rconf["initial_data_order"].get<int>()));
  }

  // f_tau of a nonlinearity of degree d has tau harmonics up to |k| = d + 1 (e^{-i tau} times d
  // factors e^{i tau}); a grid that cannot hold them (n_tau/2 - 1 < d + 1: the Nyquist mode is
  // dropped) aliases them silently, and the tau monitors see nothing (HH at n_tau = 2: 26% in H).
  const int degree = assembly.model_entry->nonlinearity_degree;
  if (rconf.contains("n_tau") && rconf["n_tau"].is_number() && degree > 0 &&
      rconf["n_tau"].get<long>() / 2 - 1 < degree + 1)
    plan.warnings.push_back(fmt::format(
        "reformulation.n_tau = {} cannot hold the tau harmonics of this model's degree-{} nonlinearity "
        "(up to |k| = {}: n_tau >= {} needed); the result aliases them",
        rconf["n_tau"].get<long>(), degree, degree + 1, 2 * (degree + 2)));
  if (settings.device == "cuda") check_device_run(config, assembly, settings);
  plan.steps = step_count(config);
  checked_output_times(config);
  return plan;
}

RunOutcome execute_run(const Json& config, const Registry& registry, const RunSettings& settings,
                       const ProgressFn& progress, const ReferenceSolution* shared_reference,
                       const std::string& stream_dir) {
  RunOutcome outcome;
  Json& result = outcome.result;
  result["tsi_version"] = version_string;
  result["config"] = config;
  result["warnings"] = Json::array();
  const auto start = Clock::now();
  RunPlan plan = plan_run(config, registry, settings, !shared_reference);
  Assembly& assembly = plan.assembly;
  for (auto& warning : plan.warnings) result["warnings"].push_back(std::move(warning));
  std::shared_ptr<const Model> model = assembly.model;
  const Vector u0 = assembly.u0;
  Reformulation* reformulation = assembly.reformulation.get();
  Stepper* stepper = nullptr;  // bound once the data are prepared

  const auto& rconf = config["reformulation"];
  const Collective* split = settings.context.collective;  // tsi run --split: this process's share
  // Split over processes, the run stops where all agree (at a step's end), never one mid-step.
  std::optional<StopPollsPaused> collective_stops;
  if (split) collective_stops.emplace();
  const double h = config["time"]["h"], t_end = config["time"]["t_end"];
  const long n_steps = plan.steps;
  if (!stream_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(stream_dir, ec);
    if (ec) throw IoError("cannot create " + stream_dir + ": " + ec.message());
    outcome.csv_file = stream_dir + "/invariants.csv.partial";
  }
  RunRecorder recorder(*model, *reformulation, u0, config, outcome.csv_file);
  recorder.split_over(split);
  // A state of the whole run: a split run's shares gathered on rank 0 (empty elsewhere).
  // A grid model's fields (u, then v) are each split in slabs: rank r's share is its slab of
  // every field, and the whole state each field's slabs in rank order.
  const Index grid_parts = static_cast<Index>(model->grid_fields().names.size());
  const auto whole = [split, complex = model->is_complex(), parts = std::max<Index>(1, grid_parts)](
                         const Vector& local) -> Vector {
    if (!split) return local;
    Vector all = split->gather(local.real()).cast<Complex>();
    if (complex) all.imag() = split->gather(local.imag());
    if (parts == 1 || all.size() == 0) return all;
    const Index share = local.size() / parts, processes = split->size();  // equal slabs (tsi::grid_slab)
    Vector ordered(all.size());
    for (Index r = 0; r < processes; ++r)
      for (Index f = 0; f < parts; ++f)
        ordered.segment((f * processes + r) * share, share) = all.segment((r * parts + f) * share, share);
    return ordered;
  };
  // A grid model's state files above max_inline_state values in a split run: every process
  // writes its share (write_split_state), none gathers the state. Smaller ones (result.json
  // holds them), and a particle run's, are gathered on rank 0. Decided alike on every process.
  const auto written_in_shares = [&](const Vector& local) {
    return split && grid_parts > 0 && !settings.split_dir.empty() &&
           split->sum(static_cast<Real>(local.size())) > static_cast<Real>(max_inline_state);
  };
  const auto whole_count = [&](const Vector& local) {
    return static_cast<Index>(std::llround(to_double(split->sum(static_cast<Real>(local.size())))));
  };
  // output.fields_every: the fields as HDF5 + XDMF (rank 0 of a split run writes what all gather).
  const long fields_every = config.contains("output") ? config["output"].value("fields_every", 0L) : 0L;
  // Every process of a split run holds one (the others write their rows of large snapshots).
  std::optional<FieldSnapshots> snapshots;
  if (fields_every > 0 && !stream_dir.empty())
    snapshots.emplace(stream_dir, model->grid_fields(), model->is_complex());
  else if (fields_every > 0 && split && !settings.split_dir.empty())
    snapshots.emplace(settings.split_dir, model->grid_fields(), model->is_complex(), /*lists=*/false);
  // u between the steps (output.times), from the scheme's states interpolated in t.
  std::unique_ptr<DenseOutput> dense;
  if (std::vector<double> times = checked_output_times(config); !times.empty())
    dense = std::make_unique<DenseOutput>(std::move(times), std::min(assembly.traits.order, 8), h, n_steps, *model,
                                          *reformulation);
  std::string status = "completed";
  auto last_checkpoint = Clock::now();
  // Clocks read every few steps only: a cheap step pays no clock read.
  SteppedClock checkpoint_clock, progress_clock;
  const double checkpoint_seconds = config.contains("output") ? config["output"].value("checkpoint_seconds", 30.0) : 30.0;
  const long state_every = config.contains("output") ? config["output"].value("state_every", 0L) : 0L;
  // A checkpoint: result.json says how far the run got, so that a kill -9 or a power cut
  // leaves, besides the streamed rows, a record of the run (replaced by the full one at the end).
  const auto checkpoint = [&](long n, double t) {
    recorder.flush_csv();  // the rows first: a checkpoint never claims more than the file holds
    Json partial = result;
    partial["status"] = "running";
    partial["message"] = fmt::format("a checkpoint at t = {:.6g} (step {} of {}); invariants.csv.partial holds the "
                                     "rows up to here", t, n, n_steps);
    partial["t_reached"] = t;
    partial["steps_done"] = n;
    partial["wall_seconds"] = seconds_since(start);
    write_file_atomically(stream_dir + "/result.json", partial.dump(2) + "\n");  // IoError: an I/O failure
    last_checkpoint = Clock::now();
  };
  const TwoScaleDiagnostics* diagnostics = reformulation->two_scale_diagnostics();
  result["threads"] = diagnostics ? diagnostics->threads() : 1;  // on the tau grid (tsi --threads)
  result["device"] = settings.device == "cuda" ? "cuda: " + device::describe() : "cpu";  // where the steps ran
  try {
    Vector y = reformulation->prepare(u0);
    const int data_order = diagnostics ? diagnostics->data_order_reached() : 0;
    if (data_order > 0) {
      result["initial_data_order_reached"] = data_order;
      if (rconf.contains("initial_data_order") && data_order < rconf["initial_data_order"].get<int>())
        result["warnings"].push_back(fmt::format(
            "prepared data reached order {} of the {} asked: eps = {:g} is too large for their asymptotic "
            "expansion beyond that order",
            data_order, rconf["initial_data_order"].get<int>(), model->eps()));
    }
    stepper = &assembly.bind(config["time"]["h"].get<double>());
    // --device cuda: the steps on the device, y back on the host when the scope closes.
    std::optional<device::Scope> on_device;
    if (settings.device == "cuda") on_device.emplace(y);
    integrate(*stepper, y, n_steps, [&](long n, Real t, const Vector& state) {
      const bool go_on = recorder.observe(n, t, state);
      if (go_on && dense) dense->observe(n, state);  // a finite state only
      // A split run stops where any of its processes saw the signal, all at the same step.
      if (go_on && (split ? !split->all(!interrupted()) : interrupted())) {  // kept up to this step, as "interrupted"
        status = "interrupted";
        outcome.message = fmt::format("interrupted by signal {} at t = {:.6g} (step {} of {})",
                                      interrupted() ? interrupt_signal() : 0, t, n, n_steps);
        return false;
      }
      if (progress && progress_clock.tick()) progress({"run", n, n_steps, to_double(t), t_end});
      if (go_on && fields_every > 0 && snapshots && (n % fields_every == 0 || n == n_steps)) {
        const device::HostView host(state);
        const Vector local = model->to_physical(reformulation->read_back(state, t));
        if (written_in_shares(local)) {
          snapshots->write_shares(*split, n, to_double(t), local);
        } else {
          const Vector x = whole(local);
          if (!stream_dir.empty()) snapshots->write(n, to_double(t), x);
        }
      }
      if (go_on && state_every > 0 && (split || !stream_dir.empty()) && (n % state_every == 0 || n == n_steps)) {
        // The state as a file a run can start from (written to a temporary file, then renamed),
        // and result.json's checkpoint says at which time it is.
        const device::HostView host(state);
        const Vector local = model->to_physical(reformulation->read_back(state, t));
        std::vector<std::uint64_t> shape;
        for (const Index d : model->physical_shape()) shape.push_back(static_cast<std::uint64_t>(d));
        if (written_in_shares(local)) {
          write_split_state(*split, settings.split_dir + "/state.npy", local, grid_parts, model->is_complex(), shape);
        } else {
          Vector x = whole(local);
          if (!stream_dir.empty()) {
            model->canonicalize_physical(x);
            write_npy(stream_dir + "/state.npy", x, model->is_complex(), shape);
          }
        }
        if (!stream_dir.empty()) {
          result["state"] = {{"file", "state.npy"}, {"t", to_double(t)}, {"step", n}};
          checkpoint(n, to_double(t));
        }
      }
      if (go_on && !stream_dir.empty())
        if (const auto now = checkpoint_clock.tick();
            now && std::chrono::duration<double>(*now - last_checkpoint).count() > checkpoint_seconds)
          checkpoint(n, to_double(t));
      return go_on;
    }, reformulation->repreparation());
    if (status == "completed" && recorder.status() != "running") {
      status = recorder.status();
      outcome.message = recorder.message();
    }
  } catch (const Interrupted& e) {  // within a step or the preparation: the steps made are kept
    status = "interrupted";
    outcome.message = fmt::format("interrupted by signal {} at t = {:.6g} (step {} of {}) {}", e.signal(),
                                  step_time(recorder.steps(), h), recorder.steps(), n_steps,
                                  recorder.steps() > 0 ? "during the next step" : "before the first step");
    if (split) stop_split_run(*split, stream_dir, result, recorder, outcome.message, 1);
  } catch (const IoError& e) {  // the output failed (a full disk), not the computation
    status = "failed";
    outcome.io_error = e.what();
    if (split) stop_split_run(*split, stream_dir, result, recorder, e.what(), 3);
  } catch (const std::exception& e) {
    status = "failed";
    outcome.message = fmt::format("at t = {:.6g} (step {}): {}", step_time(recorder.steps(), h),
                                  recorder.steps() + 1, e.what());
    if (split) stop_split_run(*split, stream_dir, result, recorder, outcome.message, 1);
  }
  if (outcome.io_error.empty()) {
    try {
      recorder.finish_csv();
    } catch (const IoError& e) {
      status = "failed";
      outcome.io_error = e.what();
    }
  }
  if (!outcome.io_error.empty()) {
    const double kept = recorder.csv_written_to();
    outcome.message = fmt::format("{}: the run stopped at t = {:.6g} (step {}); invariants.csv keeps {}",
                                  outcome.io_error, recorder.t_reached(), recorder.steps(),
                                  std::isnan(kept) ? std::string("its header only")
                                                   : fmt::format("the rows up to t = {:.6g}", kept));
  }
  const double wall = seconds_since(start);

  // Everything up to where the run stopped is kept, whatever the status.
  outcome.ok = status == "completed";
  outcome.csv = recorder.csv();
  result["status"] = status;
  if (!outcome.ok) result["message"] = outcome.message;
  // The final state: this process's share (errors are norms over every process) and the whole
  // run's for the files (gathered on rank 0 of a split run, or written in shares when large).
  const Vector x_here = model->to_physical(recorder.u_last());
  const bool final_in_shares = written_in_shares(x_here);
  const Vector x = final_in_shares ? Vector() : whole(x_here);
  if (split) result["split"] = {{"processes", split->size()}, {"memory", "rank 0's"}};
  if (snapshots)
    result["fields"] = {{"file", "fields.h5"}, {"xdmf", "fields.xmf"}, {"every", fields_every},
                        {"snapshots", snapshots->count()}};
  if (dense) {
    dense->finish();
    outcome.output_times = dense->times();
    outcome.u_times = dense->values();
  }
  result["steps"] = recorder.steps();
  result["t_end"] = t_end;
  result["t_reached"] = recorder.t_reached();
  outcome.complex_state = model->is_complex();
  outcome.u_final_written = final_in_shares ? whole_count(x_here) : 0;
  outcome.state_shape = state_shape(config, *model, final_in_shares ? outcome.u_final_written : x.size());
  if (final_in_shares) {
    write_split_state(*split, settings.split_dir + "/" + u_final_file, x_here, grid_parts, outcome.complex_state,
                      outcome.state_shape);
    outcome.u_final_head = x_here.head(std::min<Index>(4, x_here.size()));  // rank 0's share comes first
    result["u_final"] = state_file_entry(outcome.complex_state, outcome.state_shape, u_final_file);
  } else {
    outcome.u_final = x;
    result["u_final"] = state_entry(x, outcome.complex_state, outcome.state_shape, u_final_file);
  }
  if (dense) result["dense_output"] = dense_output_entry(*dense, outcome);
  result["invariants"] = recorder.invariants_json();
  {
    const char* names[3] = {"H", "I", "m"};
    for (int k = 0; model->has_hamiltonian_structure() && k < 3; ++k) {
      const double d = recorder.drift(k);
      result["invariants"][names[k]]["drift"] = std::isnan(d) ? Json() : Json(d);
    }
  }
  const SolverStats stats = stepper ? stepper->stats() : SolverStats{};
  Json histogram = Json::object();
  for (size_t k = 0; k < stats.sweeps_histogram.size(); ++k)
    if (stats.sweeps_histogram[k] > 0) histogram[std::to_string(k)] = stats.sweeps_histogram[k];
  result["solver"] = {{"iterations_mean", stats.iterations_mean()},
                      {"iterations_max", stats.iterations_max},
                      {"not_converged", stats.not_converged},
                      {"stages", stats.solves},
                      {"sweeps_histogram", histogram}};
  for (const auto& w : recorder.warnings()) result["warnings"].push_back(w);
  if (stats.not_converged > 0)
    result["warnings"].push_back(fmt::format("{} implicit stages did not converge to tol within max_iter",
                                             stats.not_converged));
  result["rhs_evaluations"] = reformulation->evaluations();
  result["tau_roughness_max"] = recorder.roughness_max();
  result["tau_spread_max"] = recorder.spread_max();
  const std::vector<double> reprepared = diagnostics ? diagnostics->repreparation_times() : std::vector<double>{};
  result["repreparations"] = {{"count", reprepared.size()}, {"times", reprepared}};
  result["wall_seconds"] = wall;
  {
    // The memory the run's state takes, and the bound stepper's vectors of that size; the
    // process's peak resident memory (in a study with --jobs, shared by its runs).
    const double state_bytes = static_cast<double>(reformulation->size()) * static_cast<double>(sizeof(Complex));
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    result["memory"] = {{"state_bytes", state_bytes},
                        {"stepper_state_vectors", stepper ? stepper->state_vectors() : assembly.footprint.scheme_vectors},
                        {"process_peak_rss_bytes", static_cast<double>(usage.ru_maxrss) * 1024.0}};
    // The footprint the run was checked against before it was built (two-scale runs).
    if (assembly.footprint.vectors > 0.0) result["memory"]["footprint_vectors"] = assembly.footprint.vectors;
  }

  if (outcome.ok && config.contains("reference")) {
    ReferenceSolution ref;
    try {
      ref = shared_reference ? *shared_reference : compute_reference(config, registry, settings, progress);
    } catch (const ConfigError&) {
      throw;
    } catch (const std::exception& e) {
      // The run's own results are kept: an interrupt (or a failure) of its reference only
      // leaves the error out.
      outcome.ok = false;
      result["status"] = interrupted() ? "interrupted" : "failed";
      outcome.message = fmt::format("{} the reference solution: {} (the run itself completed: its results are kept)",
                                    interrupted() ? "interrupted while computing" : "failed computing", e.what());
      result["message"] = outcome.message;
      return outcome;
    }
    Json error = {{"relative", to_double(model->error_norm(x_here - ref.x) / model->error_norm(ref.x))},
                  {"absolute", to_double(model->error_norm(x_here - ref.x))},
                  {"reference", ref.settings}};
    error["reference"]["wall_seconds"] = ref.wall_seconds;
    error["reference"]["estimated_relative_accuracy"] =
        std::isfinite(ref.accuracy) ? Json(ref.accuracy) : Json(nullptr);
    if (written_in_shares(ref.x)) {
      write_split_state(*split, settings.split_dir + "/" + reference_u_final_file, ref.x, grid_parts,
                        outcome.complex_state, outcome.state_shape);
      outcome.reference_written = whole_count(ref.x);
      error["reference"]["u_final"] =
          state_file_entry(outcome.complex_state, outcome.state_shape, reference_u_final_file);
    } else {
      outcome.reference_u_final = whole(ref.x);
      error["reference"]["u_final"] =
          state_entry(ref.x, outcome.complex_state, outcome.state_shape, reference_u_final_file);
    }
    result["error"] = error;
  }
  if (outcome.ok && config.contains("output") &&
      config["output"].value("error_estimate", std::string("none")) == "richardson") {
    result["error_estimate"] =
        richardson_estimate(config, registry, settings, assembly.traits, *model, x_here, n_steps, progress);
    if (result["error_estimate"]["status"] == "interrupted") {  // the run's results are kept, as for a reference
      outcome.ok = false;
      result["status"] = "interrupted";
      outcome.message = fmt::format("interrupted while estimating the error: {} (the run itself completed: its "
                                    "results are kept)",
                                    result["error_estimate"]["message"].get<std::string>());
      result["message"] = outcome.message;
      return outcome;
    }
    if (result.contains("error") && result["error_estimate"]["relative"].is_number() &&
        result["error"]["relative"].get<double>() > 0.0)
      result["error_estimate"]["ratio_to_error"] =
          result["error_estimate"]["relative"].get<double>() / result["error"]["relative"].get<double>();
  }
  return outcome;
}

}  // namespace tsi::app
