#pragma once
// Builds models, reformulations and schemes from the shipped plugins, as the runner does,
// for tests that drive the numerics directly.
#include <memory>
#include <string>

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

  std::shared_ptr<const Model> model(const std::string& name, double eps) const {
    const auto& e = registry_.model(name);
    return e.create(Params(resolve_params(e.info.params, {{"eps", eps}}, "model")));
  }

  std::unique_ptr<Reformulation> reformulation(const std::string& name, std::shared_ptr<const Model> m,
                                               const Json& params = Json::object()) const {
    const auto& e = registry_.reformulation(name);
    return e.create(std::move(m), Params(resolve_params(e.info.params, params, "reformulation")));
  }

  std::unique_ptr<Stepper> scheme(const std::string& name, const Json& params = Json::object()) const {
    const auto& e = registry_.scheme(name);
    return e.create(Params(resolve_params(e.info.params, params, "scheme")));
  }

  const Registry& registry() const { return registry_; }

 private:
  Harness() : loader_(registry_) {
    register_core(registry_);
    loader_.load_directory(TSI_TEST_PLUGIN_DIR);
  }
  Registry registry_;
  PluginLoader loader_;
};

/// u(t_end) in physical variables: n steps of size t_end / n from the model's u0.
inline Vector solve(const Model& model, Reformulation& reformulation, Stepper& stepper, double t_end, long n) {
  Vector y = reformulation.prepare(model.initial_value());
  const double h = t_end / static_cast<double>(n);
  integrate(reformulation, stepper, y, h, n, {});
  return model.to_physical(reformulation.read_back(y, step_time(n, h)));
}

}  // namespace tsi::test
