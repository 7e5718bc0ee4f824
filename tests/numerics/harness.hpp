#pragma once
// Builds models, reformulations and schemes from the shipped plugins through the core's
// assembler (tsi::assemble_config, as `tsi run`, `tsi check` and the benchmarks do), for tests
// that drive the numerics directly.
#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <tuple>

#include "tsi/assembly.hpp"
#include "tsi/driver.hpp"
#include "tsi/phase.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"

namespace tsi::test {

class Harness {
 public:
  static Harness& instance() {
    static Harness harness;
    return harness;
  }

  /// A run's objects from a config's model, reformulation and scheme sections, every default
  /// completed by the selected entries (the model's n_tau, the scheme's data order, SE2's nodes).
  Assembly assemble(const Json& config) const { return assemble_config(config, registry_); }

  std::shared_ptr<const Model> model(const std::string& name, double eps) const {
    return model_with(name, eps, Json::object());
  }
  /// The model with parameters besides eps (NLS's n_x).
  std::shared_ptr<const Model> model_with(const std::string& name, double eps, Json params) const {
    const auto& e = registry_.model(name);
    params["eps"] = eps;
    return e.create(Params(resolve_params(e.info.params, params, "model"), context));
  }

  std::unique_ptr<Reformulation> reformulation(const std::string& name, std::shared_ptr<const Model> m,
                                               const Json& params = Json::object()) const {
    const auto& e = registry_.reformulation(name);
    return e.create(std::move(m), Params(resolve_params(e.info.params, params, "reformulation"), context));
  }

  /// A scheme, its parameters completed for `model` on the two-scale reformulation (SE2's
  /// nodes depend on the model: without a model it refuses to guess).
  std::unique_ptr<Scheme> scheme(const std::string& name, const Json& params = Json::object(),
                                  const std::string& model = "") const {
    const auto& e = registry_.scheme(name);
    Json resolved = resolve_params(e.info.params, params, "scheme");
    if (e.complete && !model.empty())
      e.complete(resolved, Selection{registry_.model(model), registry_.reformulation("two-scale"), e});
    return e.create(Params(resolved));
  }

  const Registry& registry() const { return registry_; }

  /// The context the models and reformulations made here get (threads; ContextSetting below
  /// sets it for one test case).
  Context context;

 private:
  Harness() : loader_(registry_) {
    register_core(registry_);
    loader_.load_directory(TSI_TEST_PLUGIN_DIR);
  }
  Registry registry_;
  PluginLoader loader_;
};

/// Sets the harness's context for a scope and restores the default however it ends.
struct ContextSetting {
  explicit ContextSetting(const Context& c) { Harness::instance().context = c; }
  ~ContextSetting() { Harness::instance().context = Context{}; }
  /// Threads on the tau grid for grids of at least min_values.
  static Context tau_grid(int threads, long min_values) {
    Context c;
    c.tau_grid = {threads, min_values};
    return c;
  }
  /// FFTW's threads for batches of at least min_values.
  static Context fft(int threads, long min_values) {
    Context c;
    c.fft = {threads, min_values};
    return c;
  }
};

/// Every registered scheme that integrates the two-scale problem, by name.
inline std::vector<const SchemeEntry*> two_scale_schemes() {
  std::vector<const SchemeEntry*> out;
  for (const auto* e : Harness::instance().registry().schemes()) {
    const auto& r = e->traits.reformulations;
    if (std::find(r.begin(), r.end(), "two-scale") != r.end()) out.push_back(e);
  }
  return out;
}

/// The two-scale schemes of the paper's kind: uniformly second order at every eps, with
/// classical order 2 (the model tests assert what they measure of such schemes).
inline std::vector<const SchemeEntry*> second_order_schemes() {
  std::vector<const SchemeEntry*> out;
  for (const auto* e : two_scale_schemes()) {
    const StepperTraits t = default_traits(*e);
    if (t.order == 2 && t.classical_order <= 2) out.push_back(e);
  }
  return out;
}

/// u(t_end) in physical variables: n steps of size t_end / n from the model's u0.
inline Vector solve(const Model& model, Reformulation& reformulation, const Scheme& scheme, double t_end, long n) {
  Vector y = reformulation.prepare(model.initial_value());
  const double h = t_end / static_cast<double>(n);
  integrate(*scheme.bind(reformulation, h), y, n, {}, reformulation.repreparation());
  return model.to_physical(reformulation.read_back(y, step_time(n, h)));
}

/// The reference u(t_end) for the model's u0: rk78 (tol 1e-14) on the filtered problem,
/// another reformulation and another scheme than the two-scale ones under test. Cached.
inline const Vector& reference_solution(const std::string& model_name, double eps, double t_end) {
  static std::map<std::tuple<std::string, double, double>, Vector> cache;
  const auto key = std::make_tuple(model_name, eps, t_end);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  auto& h = Harness::instance();
  auto model = h.model(model_name, eps);
  auto filtered = h.reformulation("filtered", model);
  auto rk78 = h.scheme("rk78", {{"tol", 1e-14}});  // below the order-4 errors at h = 1/128
  return cache[key] = solve(*model, *filtered, *rk78, t_end, 1);
}

}  // namespace tsi::test
