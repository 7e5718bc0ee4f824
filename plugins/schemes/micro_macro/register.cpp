// The uniformly accurate rivals of the two-scale schemes on the filtered problem (SPEC.md
// section 8): the micro-macro schemes (`micro-macro`) and the first-order nested Picard
// integrator (`npi`). Formulas, sources and what could not be confirmed:
// tests/data/rivals/micro-macro.md.
#include <string>

#include "cclm.hpp"
#include "derivative_free.hpp"
#include "nested_picard.hpp"
#include "tsi/error.hpp"
#include "tsi/plugin.hpp"

namespace {

using namespace tsi_micro_macro;

tsi::ParamSpec n_tau_param(const std::string& what) {
  return tsi::integer_param("n_tau", 32, "points of the scheme's own tau grid (" + what + ")")
      .check([](const tsi::Json& v) { return v.is_number_integer() && v.get<long>() >= 4 && v.get<long>() <= 4096 && v.get<long>() % 2 == 0; },
             "an even integer in [4, 4096]");
}

// The order n and Runge-Kutta order q of the derivative-free variant, checked; the cclm variant takes neither.
struct Orders {
  int n = 2, q = 2;
};
Orders orders(const tsi::Json& params) {
  const std::string variant = params.value("variant", std::string("cclm"));
  const bool has_order = params.contains("order") && !params["order"].is_null();
  const bool has_rk = params.contains("rk_order") && !params["rk_order"].is_null();
  if (variant == "cclm") {
    if (has_order)
      throw tsi::ConfigError("scheme.order", "got " + params["order"].dump() +
                                                 " with variant \"cclm\" (its change of variables is of order 1, its "
                                                 "midpoint uniformly of order 2); expected it only with variant "
                                                 "\"derivative-free\"");
    if (has_rk)
      throw tsi::ConfigError("scheme.rk_order", "got " + params["rk_order"].dump() +
                                                    " with variant \"cclm\"; expected it only with variant "
                                                    "\"derivative-free\"");
    return {1, 2};
  }
  Orders o;
  o.n = has_order ? params["order"].get<int>() : 2;
  o.q = has_rk ? params["rk_order"].get<int>() : o.n;
  if (o.q > o.n)
    throw tsi::ConfigError("scheme.rk_order",
                           "got " + std::to_string(o.q) + " with order " + std::to_string(o.n) +
                               "; expected at most the order of the change of variables: w = O(eps^(n+1)) has "
                               "derivatives of size eps^(n+1-k), so a Runge-Kutta method of order q > n is not "
                               "uniformly accurate (it stalls where h ~ eps)");
  return o;
}

void register_micro_macro(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "micro-macro";
  entry.info.aliases = {"micmac"};
  entry.info.summary =
      "micro-macro on the filtered problem: cclm (Chartier-Crouseilles-Lemou-Mehats 2015, MicroMacro.jl's "
      "scheme, uniform order 2) or derivative-free of order n with Runge-Kutta of order q (Chartier-Lemou-"
      "Mehats-Zhao 2022)";
  entry.info.params = {
      tsi::string_param("variant", "cclm",
                        "cclm (standard averaging of order 1, explicit midpoint with the fast phase integrated "
                        "exactly: f and Df) or derivative-free (order n, only f)")
          .choices({"cclm", "derivative-free"}),
      tsi::integer_param("order", nullptr, "derivative-free: the order n of the change of variables (default 2)")
          .range(1, 4),
      tsi::integer_param("rk_order", nullptr,
                         "derivative-free: the order q <= n of the Runge-Kutta method on (ub, w) (1 Euler, 2 "
                         "midpoint, 3 Kutta, 4 classical; default n)")
          .range(1, 4),
      n_tau_param("it must resolve the tau spectrum of f_tau composed with the change of variables"),
      tsi::number_param("difference_step", 1e-3,
                        "derivative-free: the largest step of the micro field's central difference along G_n + L ub (the recursion's levels take eps^(k/4))")
          .range(1e-12, 1e-1),
  };
  entry.traits.order = 2;
  entry.traits.reformulations = {"filtered"};
  entry.traits_for = [base = entry.traits](const tsi::Json& params) {
    tsi::StepperTraits traits = base;
    traits.order = orders(params).q;
    return traits;
  };
  entry.create = [](const tsi::Params& p) -> std::unique_ptr<tsi::Scheme> {
    const Orders o = orders(p.raw());
    const int n_tau = static_cast<int>(p.integer("n_tau"));
    if (p.string("variant") == "cclm") return tsi::make_scheme<Cclm>(CclmSettings{n_tau});
    return tsi::make_scheme<DerivativeFree>(
        DerivativeFreeSettings{o.n, o.q, n_tau, static_cast<Real>(p.number("difference_step"))});
  };
  registry.add_scheme(std::move(entry));

  tsi::SchemeEntry npi;
  npi.info.name = "npi";
  npi.info.aliases = {"nested-picard"};
  npi.info.summary =
      "nested Picard (after Cai-Zhou) on the filtered problem: m Picard iterates of Duhamel's formula, "
      "polynomial in the slow time, the fast phase integrated exactly; uniform order m = 1 .. 4, only f";
  npi.info.params = {
      tsi::integer_param("order", 1,
                         "m, the Picard iterates (uniform order m; m (m + 1)/2 batches of n_tau evaluations of f "
                         "a step; 1: the field frozen at y_n)")
          .range(1, 4),
      n_tau_param("it must resolve the tau spectrum of f_tau"),
  };
  npi.traits.order = 1;
  npi.traits.reformulations = {"filtered"};
  npi.traits_for = [base = npi.traits](const tsi::Json& params) {
    tsi::StepperTraits traits = base;
    traits.order = params.value("order", 1);
    return traits;
  };
  npi.create = [](const tsi::Params& p) {
    return tsi::make_scheme<NestedPicard>(
        NestedPicardSettings{static_cast<int>(p.integer("n_tau")), static_cast<int>(p.integer("order"))});
  };
  registry.add_scheme(std::move(npi));
}

}  // namespace

TSI_PLUGIN("micro-macro", register_micro_macro)
