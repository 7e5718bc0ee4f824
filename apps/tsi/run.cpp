#include "run.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "config.hpp"
#include "tsi/driver.hpp"
#include "tsi/error.hpp"
#include "tsi/version.hpp"

namespace tsi::app {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// |X - X0| / |X0| (absolute when X0 = 0).
double relative_change(double value, double initial) {
  return std::abs(value - initial) / (initial != 0.0 ? std::abs(initial) : 1.0);
}

Vector initial_value(const Model& model, const Json& model_config) {
  if (!model_config.contains("u0") || model_config["u0"].is_null()) return model.initial_value();
  const Json& u0 = model_config["u0"];
  if (static_cast<Index>(u0.size()) != model.dim())
    throw ConfigError("model.u0", fmt::format("got {} entries, expected {} (the model's dimension)",
                                              u0.size(), model.dim()));
  Vector x(model.dim());
  for (Index i = 0; i < model.dim(); ++i) {
    const Json& v = u0[static_cast<size_t>(i)];
    if (v.is_number())
      x(i) = v.get<double>();
    else if (v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number())
      x(i) = Complex(v[0].get<double>(), v[1].get<double>());
    else
      throw ConfigError(fmt::format("model.u0[{}]", i), "got " + v.dump() + ", expected a number or [re, im]");
  }
  return model.from_physical(x);
}

struct InvariantTrack {
  double initial = 0.0, final = 0.0, max_rel_error = 0.0;
  Json to_json() const { return {{"initial", initial}, {"final", final}, {"max_rel_error", max_rel_error}}; }
};

// The reference solution at t_end, computed by another scheme on another reformulation.
Vector reference_solution(const Json& config, const Json& ref, const Registry& registry,
                          std::shared_ptr<const Model> model, const Vector& u0) {
  const SchemeEntry& scheme = registry.scheme(ref["scheme"], "reference.scheme");
  const ReformulationEntry& reform = registry.reformulation(ref["reformulation"], "reference.reformulation");
  Json scheme_params = Json::object();
  for (const auto& spec : scheme.info.params)
    if (spec.name == "tol") scheme_params["tol"] = ref["tol"];
  auto reformulation = reform.create(model, Params(resolve_params(reform.info.params, Json::object(), "reference")));
  auto stepper = scheme.create(Params(resolve_params(scheme.info.params, scheme_params, "reference")));
  const double t_end = config["time"]["t_end"];
  Vector y = reformulation->prepare(u0);
  if (t_end > 0.0) {
    const double h = ref["h"].is_null() ? t_end : ref["h"].get<double>();
    const long steps = std::max(1L, std::lround(t_end / h));
    integrate(*reformulation, *stepper, y, t_end / static_cast<double>(steps), steps, {});
  }
  return reformulation->read_back(y, t_end);
}

}  // namespace

Json state_to_json(const Vector& x, bool complex_state) {
  Json out = Json::array();
  for (Index i = 0; i < x.size(); ++i) {
    if (complex_state)
      out.push_back({x(i).real(), x(i).imag()});
    else
      out.push_back(x(i).real());
  }
  return out;
}

RunOutcome execute_run(const Json& config, const Registry& registry, const ProgressFn& progress) {
  RunOutcome outcome;
  Json& result = outcome.result;
  result["tsi_version"] = version_string;
  result["config"] = config;
  result["warnings"] = Json::array();
  std::string& csv = outcome.csv;
  csv = "t,H,I,m,err_H,err_I,err_m,tau_roughness\n";
  const auto start = Clock::now();
  long steps_done = 0;
  // Construction: bad input (a model's own checks, u0 of the wrong shape) is a ConfigError
  // that propagates before anything runs.
  const ModelEntry& model_entry = registry.model(config["model"]["name"]);
  const SchemeEntry& scheme_entry = registry.scheme(config["scheme"]["name"]);
  const ReformulationEntry& reform_entry = registry.reformulation(config["reformulation"]["name"]);
  std::shared_ptr<const Model> model = model_entry.create(Params(without_name(config["model"])));
  const Vector u0 = initial_value(*model, config["model"]);
  auto reformulation = reform_entry.create(model, Params(without_name(config["reformulation"])));
  auto stepper = scheme_entry.create(Params(without_name(config["scheme"])));

  const auto& rconf = config["reformulation"];
  if (rconf.contains("initial_data_order") &&
      rconf["initial_data_order"].get<int>() < scheme_entry.traits.initial_data_order) {
    result["warnings"].push_back(fmt::format(
        "scheme \"{}\" needs prepared data of order {} for uniform accuracy; running with order {}",
        scheme_entry.info.name, scheme_entry.traits.initial_data_order,
        rconf["initial_data_order"].get<int>()));
  }

  try {
    const double h = config["time"]["h"], t_end = config["time"]["t_end"];
    const long n_steps = step_count(config);
    const long every = config["output"]["every"];

    InvariantTrack H{model->energy(u0)}, I{model->oscillatory_energy(u0)}, m{model->mass(u0)};
    double roughness_max = 0.0;
    Vector y = reformulation->prepare(u0);
    Vector u = u0;
    auto last_progress = Clock::now();

    integrate(*reformulation, *stepper, y, h, n_steps, [&](long n, double t, const Vector& state) {
      steps_done = n;
      u = reformulation->read_back(state, t);
      const double values[3] = {model->energy(u), model->oscillatory_energy(u), model->mass(u)};
      InvariantTrack* tracks[3] = {&H, &I, &m};
      double errors[3];
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(values[k]))
          throw Error(fmt::format("the solution became non-finite at t = {} (step {})", t, n));
        errors[k] = relative_change(values[k], tracks[k]->initial);
        tracks[k]->final = values[k];
        tracks[k]->max_rel_error = std::max(tracks[k]->max_rel_error, errors[k]);
      }
      const double roughness = reformulation->tau_roughness(state);
      roughness_max = std::max(roughness_max, roughness);
      if (n % every == 0 || n == n_steps)
        csv += fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.6e},{:.6e},{:.6e},{:.6e}\n", t, values[0],
                           values[1], values[2], errors[0], errors[1], errors[2], roughness);
      if (progress && seconds_since(last_progress) > 0.5) {
        progress(static_cast<double>(n) / static_cast<double>(std::max(1L, n_steps)));
        last_progress = Clock::now();
      }
      return true;
    });
    const double wall = seconds_since(start);

    const Vector x = model->to_physical(u);
    result["status"] = "completed";
    result["steps"] = n_steps;
    result["t_end"] = t_end;
    result["u_final"] = state_to_json(x, model->is_complex());
    result["invariants"] = {{"H", H.to_json()}, {"I", I.to_json()}, {"m", m.to_json()}};
    const SolverStats stats = stepper->stats();
    result["solver"] = {{"iterations_mean", stats.iterations_mean()},
                        {"iterations_max", stats.iterations_max},
                        {"not_converged", stats.not_converged},
                        {"stages", stats.solves}};
    if (stats.not_converged > 0)
      result["warnings"].push_back(fmt::format("{} implicit stages did not converge to tol within max_iter",
                                               stats.not_converged));
    result["rhs_evaluations"] = reformulation->evaluations();
    result["tau_roughness_max"] = roughness_max;
    result["wall_seconds"] = wall;

    if (config.contains("reference")) {
      const auto ref_start = Clock::now();
      const Vector ref = model->to_physical(reference_solution(config, config["reference"], registry, model, u0));
      Json error = {{"relative", model->error_norm(x - ref) / model->error_norm(ref)},
                    {"absolute", model->error_norm(x - ref)},
                    {"reference", config["reference"]}};
      error["reference"]["wall_seconds"] = seconds_since(ref_start);
      error["reference"]["u_final"] = state_to_json(ref, model->is_complex());
      result["error"] = error;
    }
  } catch (const std::exception& e) {
    outcome.ok = false;
    outcome.message = e.what();
    result["status"] = "failed";
    result["message"] = e.what();
    result["steps"] = steps_done;
    result["wall_seconds"] = seconds_since(start);
  }
  return outcome;
}

}  // namespace tsi::app
