#include <algorithm>
#include <memory>

#include "reformulations/direct.hpp"
#include "reformulations/filtered.hpp"
#include "tsi/matrix_model.hpp"
#include "tsi/registry.hpp"
#include "reformulations/two_scale.hpp"

namespace tsi {

int default_quadrature_nodes(const ModelEntry& model) {
  return model.nonlinearity_degree > 0 ? (model.nonlinearity_degree + 2) / 2 : 6;
}

namespace {

// The filtered and direct problems' real_layout.
ParamSpec real_state_param() {
  return bool_param("real_layout", true,
                    "a real model's state holds its real values two to a complex entry (half the memory; "
                    "the same numbers); false: one value per entry, as for a complex model");
}

}  // namespace

void register_core(Registry& registry) {
  const auto previous = registry.provider();
  registry.set_provider("core");

  ReformulationEntry two_scale;
  two_scale.info = {
      "two-scale",
      {"2scale", "tsi"},
      "U(t, tau) with dU/dt + (1/eps) dU/dtau = f_tau(U), Fourier in tau (eq. 2scale eq)",
      {integer_param("n_tau", nullptr, "Fourier points in tau; default: the model's own")
           .check([](const Json& v) { return v.get<long>() > 0 && v.get<long>() <= (1L << 20) && v.get<long>() % 2 == 0; },
                  "an even integer from 2 to 1048576"),
       integer_param("initial_data_order", nullptr,
                     "order of the prepared initial data (1 to 8); default: what the scheme "
                     "needs for its uniform order")
           .check([](const Json& v) { return v.get<long>() >= 1 && v.get<long>() <= TwoScale::max_data_order; },
                  "an integer from 1 to 8"),
       string_param("initial_data_method", "auto",
                    "auto: SPEC.md's closed formulas for orders 1-3, the derivative-free recursion along "
                    "an averaged trajectory above; recursion: that recursion at every order; central: "
                    "the recursion with central difference quotients at every order (5^(order-2) "
                    "evaluations, for comparison)")
           .choices({"auto", "recursion", "central"}),
       integer_or_string_param("reprepare", "never",
                               "re-prepare U from the solution (SPEC.md section 6): never (the paper's "
                               "schemes), every K steps (an integer), or auto (when tau_spread grows)")
           .check(
               [](const Json& v) {
                 if (v.is_string()) return v == "never" || v == "auto";
                 return v.get<double>() >= 1 && v.get<double>() <= 1e12;
               },
               "\"never\", \"auto\" or a number of steps from 1"),
       number_param("reprepare_defect", 0.1,
                    "auto: re-prepare when U is farther than this fraction of its prepared tau variation "
                    "from the data prepared at its own diagonal value")
           .range(0.0, 1e300, true, false),
       number_param("reprepare_defect_floor", 1e-4,
                    "auto: defects below this fraction of |U| (the scheme's own error) never trigger a "
                    "re-preparation")
           .range(0.0, 1.0, false, true),
       integer_param("reprepare_min_gap", 10, "auto: test (one evaluation of r1) every this many steps")
           .check([](const Json& v) { return v.get<long>() >= 1 && v.get<long>() <= 1000000000; },
                  "an integer from 1 to 1e9"),
       bool_param("real_layout", true,
                  "a real model keeps U(tau) real: the state holds tau modes 0 .. n_tau/2 and the "
                  "transforms are real-to-complex (half the memory); false: all n_tau modes, as for a "
                  "complex model (the same numbers to rounding)"),
       string_param("nyquist", "zero",
                    "the tau Nyquist mode: zero (its multiplier is 0, as the Fourier differentiation matrix "
                    "has it: SPEC.md) or average (the functions of L there averaged over +-i n_tau/(2 eps), as "
                    "a naive real-to-complex code takes it: the UA-PIC peer's; the exponential schemes read it, "
                    "fd does not; breaks exact time symmetry)")
           .choices({"zero", "average"})},
      ""};
  two_scale.complete = [](Json& p, const Selection& s) {
    if (p["n_tau"].is_null()) p["n_tau"] = s.model.default_n_tau;
    if (p["initial_data_order"].is_null()) {
      const StepperTraits traits =
          s.scheme_params ? scheme_traits(s.scheme, *s.scheme_params) : s.scheme.traits;
      // Re-prepared data is rebuilt many times from the solution: its own error (O(eps^p) off
      // the invariant manifold) is what the tau characteristics then carry, so it gets order 4
      // at least (charged particle, eps = 1, T = 200, auto: err_H 7.9e-3 with order 2, 6.4e-4
      // with order 4).
      const bool reprepared = p.contains("reprepare") && p["reprepare"] != "never";
      p["initial_data_order"] =
          std::max({1, traits.data_order_for(s.model.linear_remainder), reprepared ? 4 : 1});
    }
  };
  two_scale.create = [](std::shared_ptr<const Model> model, const Params& p) {
    const int n_tau = p.has("n_tau") ? static_cast<int>(p.integer("n_tau")) : 64;
    const int order = p.has("initial_data_order") ? static_cast<int>(p.integer("initial_data_order")) : 2;
    Repreparation repreparation;
    if (p.has("reprepare")) {
      const Json& rule = p.raw().at("reprepare");
      if (rule == "auto") repreparation.mode = Repreparation::Mode::Auto;
      if (rule.is_number()) {
        repreparation.mode = Repreparation::Mode::Every;
        repreparation.every = static_cast<long>(rule.get<double>());
      }
    }
    if (p.has("reprepare_defect")) repreparation.defect = p.number("reprepare_defect");
    if (p.has("reprepare_min_gap")) repreparation.min_gap = p.integer("reprepare_min_gap");
    if (p.has("reprepare_defect_floor")) repreparation.defect_floor = p.number("reprepare_defect_floor");
    const std::string method = p.has("initial_data_method") ? p.string("initial_data_method") : "auto";
    const TwoScale::DataMethod data_method = method == "recursion" ? TwoScale::DataMethod::recursion
                                             : method == "central" ? TwoScale::DataMethod::central
                                                                   : TwoScale::DataMethod::automatic;
    const bool real_layout = !p.has("real_layout") || p.boolean("real_layout");
    auto made = std::make_unique<TwoScale>(std::move(model), n_tau, order, repreparation, data_method, real_layout,
                                           p.context());
    if (p.has("nyquist") && p.string("nyquist") == "average") made->average_nyquist();
    return made;
  };
  registry.add_reformulation(std::move(two_scale));

  ReformulationEntry filtered;
  filtered.info = {"filtered", {"filter"},
                   "v = e^{-JM t/eps} u, v' = f_{t/eps}(v): no stiff part, period 2 pi eps in t",
                   {real_state_param()}, ""};
  filtered.create = [](std::shared_ptr<const Model> model, const Params& p) {
    return std::make_unique<Filtered>(std::move(model), !p.has("real_layout") || p.boolean("real_layout"));
  };
  registry.add_reformulation(std::move(filtered));

  ReformulationEntry direct;
  direct.info = {"direct", {}, "u' = J[(1/eps) M u + grad H1(u)] as it stands (classical solvers)",
                 {string_param("variables", "model",
                               "the variables integrated: u (model), or those errors are measured in (physical)")
                      .choices({"model", "physical"}),
                  real_state_param()},
                 ""};
  direct.create = [](std::shared_ptr<const Model> model, const Params& p) {
    const bool physical = p.has("variables") && p.string("variables") == "physical";
    return std::make_unique<Direct>(std::move(model), physical ? Direct::Variables::physical : Direct::Variables::model,
                                    !p.has("real_layout") || p.boolean("real_layout"));
  };
  registry.add_reformulation(std::move(direct));

  register_matrix_model(registry);

  registry.set_provider(previous);
}

}  // namespace tsi
