#include "check_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>

#include "tsi/convergence.hpp"
#include "tsi/driver.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"

namespace tsi::app {
namespace {

constexpr double t_end = 1.0;
constexpr long step_counts[] = {4, 8, 16, 32};  // h = 1/4 .. 1/32
// When the order over h = 1/4 .. 1/32 misses, the steps are still pre-asymptotic for this
// model if the order over h = 1/16 .. 1/128 settles: that fit counts then.
constexpr long finer_step_counts[] = {16, 32, 64, 128};
constexpr double reference_tol = 1e-12;
constexpr double order_margin = 0.2;
constexpr double symmetry_step = 0.25, symmetry_limit = 1e-10;
// Errors below this measure the reference and the tau resolution (n_tau), not the scheme:
// they are left out of the order fit (a round-off plateau filter).
constexpr double error_floor = 1e-7;

bool two_scale(const SchemeEntry& e) {
  const auto& r = e.traits.reformulations;
  return std::find(r.begin(), r.end(), "two-scale") != r.end();
}

/// A state of the model's kind away from any special point: u0 plus a fixed perturbation.
Vector sample_state(const Model& model, const Vector& u0, double phase) {
  const double scale = std::max(max_norm(u0), 0.1);
  Vector w = u0;
  for (Index i = 0; i < w.size(); ++i) {
    const double a = std::sin(1.7 * static_cast<double>(i) + phase),
                 b = std::cos(0.9 * static_cast<double>(i) + 2 * phase);
    w(i) += 0.1 * scale * (model.is_complex() ? Complex(a, b) : Complex(a, 0.0));
  }
  return w;
}

/// The steps h = 1/4 .. 1/32 that lie close to a whole number of half fast periods (pi eps),
/// within 0.06 of one, as "h = 1/16, h = 1/32 are" (empty when none).
std::string resonant_steps(double eps) {
  std::string out;
  int count = 0;
  for (const long n : step_counts) {
    const double half_periods = 1.0 / (static_cast<double>(n) * 0.5 * two_pi * eps);
    const double nearest = std::round(half_periods);
    if (nearest >= 1.0 && std::abs(half_periods - nearest) <= 0.06) {
      out += fmt::format("{}h = 1/{}", out.empty() ? "" : ", ", n);
      ++count;
    }
  }
  return out.empty() ? out : out + (count > 1 ? " are" : " is");
}

double relative(const Vector& a, const Vector& b, double scale) {
  return max_norm(a - b) / std::max(scale, 1e-300);
}

/// The checks of one model, printed as they run; failures are collected for the summary.
class ModelChecks {
 public:
  ModelChecks(const Registry& registry, const ModelEntry& entry) : registry_(registry), entry_(entry) {}

  void interface(double eps);
  void convergence(const std::vector<const SchemeEntry*>& schemes, const std::vector<double>& epsilons);

  /// A failure outside any single check (the model could not even be built).
  void fail(const std::string& why) {
    fmt::print("    {:<5} {}\n", "FAIL", why);
    failures_.push_back(why);
  }
  const std::vector<std::string>& failures() const { return failures_; }
  int count() const { return count_; }

 private:
  void report(bool ok, const std::string& line, const std::string& failure, const std::string& hint) {
    ++count_;
    fmt::print("    {:<5} {}\n", ok ? "ok" : "FAIL", line);
    if (!ok) failures_.push_back(failure + (hint.empty() ? "" : "\n      " + hint));
  }
  void check(const std::string& what, double value, double limit, const std::string& hint) {
    const bool ok = std::isfinite(value) && value <= limit;
    report(ok, fmt::format("{:<52} {:>9.2e} {:>9.0e}", what, value, limit),
           fmt::format("{}: {:.2e} exceeds {:.0e}", what, value, limit), hint);
  }

  std::shared_ptr<const Model> model(double eps) const {
    return entry_.create(Params(resolve_params(entry_.info.params, Json{{"eps", eps}}, "model")));
  }
  std::unique_ptr<Reformulation> reformulation(const std::string& name, std::shared_ptr<const Model> m,
                                               const Json& params) const {
    const ReformulationEntry& e = registry_.reformulation(name);
    return e.create(std::move(m), Params(resolve_params(e.info.params, params, "reformulation")));
  }
  std::unique_ptr<Stepper> stepper(const SchemeEntry& e, double tol, int max_iter) const {
    Json params = Json::object();
    for (const auto& p : e.info.params) {
      if (p.name == "tol") params["tol"] = tol;
      if (p.name == "max_iter") params["max_iter"] = max_iter;
    }
    params = resolve_params(e.info.params, params, "scheme");
    if (params.contains("quadrature_nodes") && params["quadrature_nodes"].is_null())
      params["quadrature_nodes"] = default_quadrature_nodes(entry_);
    return e.create(Params(params));
  }
  std::unique_ptr<Reformulation> two_scale_problem(const SchemeEntry& scheme,
                                                   std::shared_ptr<const Model> m) const {
    return reformulation("two-scale", std::move(m),
                         {{"n_tau", entry_.default_n_tau},
                          {"initial_data_order", std::max(1, scheme.traits.initial_data_order)}});
  }
  Vector reference(std::shared_ptr<const Model> m, const Vector& u0) const;
  /// The relative errors at T for the given numbers of steps.
  std::vector<double> errors(const SchemeEntry& scheme, double eps, const Vector& x_ref,
                             const long (&steps)[4]) const;
  void orders(const SchemeEntry& scheme, double eps, const Vector& x_ref);
  void symmetry(const SchemeEntry& scheme, double eps);

  const Registry& registry_;
  const ModelEntry& entry_;
  std::vector<std::string> failures_;
  int count_ = 0;
};

void ModelChecks::interface(double eps) {
  fmt::print("  {:<60} {:>9} {:>9}\n", fmt::format("interface at eps = {:g}", eps), "value", "limit");
  const auto m = model(eps);
  const Model& mod = *m;
  const Vector u0 = mod.initial_value();
  const Index n = mod.dim();
  const bool sized = u0.size() == n && n > 0;
  report(sized, fmt::format("initial_value() has dim() = {} entries", n),
         fmt::format("initial_value() has {} entries, dim() is {}", u0.size(), n),
         "dim() is the number of entries of u; initial_value() returns u0 in model variables");
  if (!sized) return;
  const Vector w = sample_state(mod, u0, 0.3), z = sample_state(mod, Vector::Zero(n), 1.1);
  const double w_norm = max_norm(w);

  check("linear_flow(2 pi) u = u", relative(mod.linear_flow(two_pi, w), w, w_norm), 1e-10,
        "linear_flow(tau) must be e^{JM tau}, 2 pi periodic: JM has eigenvalues i k with integer k "
        "(the fast frequency is 1/eps; scale M so that it is)");
  check("linear_flow(a) linear_flow(b) = linear_flow(a + b)",
        relative(mod.linear_flow(0.7, mod.linear_flow(1.9, w)), mod.linear_flow(2.6, w), w_norm), 1e-10,
        "linear_flow must be the exact flow of a linear equation (a one-parameter group)");

  Vector mw(n), jmw(n);
  mod.apply_M(w, mw);
  mod.apply_J(mw, jmw);
  const double omega = mod.max_linear_frequency(), delta = 1e-5 / omega;
  const Vector derivative = (mod.linear_flow(delta, w) - mod.linear_flow(-delta, w)) / (2 * delta);
  check("d/dtau linear_flow(tau) u at 0 = J M u",
        relative(derivative, jmw, std::max(max_norm(jmw), omega * w_norm)), 1e-6,
        "the flow must be generated by apply_J(apply_M(u)): the flow, M and J disagree (a sign or a factor)");

  // Batched calls: one state per column, each column on its own.
  Matrix states(n, 3), dirs(n, 3);
  states << w, u0, mod.linear_flow(1.3, w);
  dirs << z, w, u0;
  RealVector taus(3);
  taus << 0.3, 2.0, 5.5;
  Matrix flowed = states, field(n, 3), dfield(n, 3);
  mod.linear_flow(taus, flowed);
  mod.nonlinear_field(states, field);
  mod.nonlinear_field_derivative(states, dirs, dfield);
  double batch = 0.0;
  for (Index j = 0; j < 3; ++j) {
    Matrix f1(n, 1), d1(n, 1);
    mod.nonlinear_field(states.col(j), f1);
    mod.nonlinear_field_derivative(states.col(j), dirs.col(j), d1);
    const double scale = max_norm(states.col(j));
    batch = std::max({batch, relative(flowed.col(j), mod.linear_flow(taus(j), states.col(j)), scale),
                      relative(field.col(j), f1.col(0), std::max(max_norm(f1.col(0)), scale)),
                      relative(dfield.col(j), d1.col(0), std::max(max_norm(d1.col(0)), scale))});
  }
  // filtered_field against its definition (a model may fuse the three steps).
  Matrix scratch = states, fused(n, 3), composed = states, field_back(n, 3);
  const RealVector minus_taus = -taus;
  mod.filtered_field(taus, scratch, fused);
  mod.linear_flow(taus, composed);
  mod.nonlinear_field(composed, field_back);
  mod.linear_flow(minus_taus, field_back);
  Matrix bound_scratch = states, bound(n, 3);
  mod.bind_tau_grid(taus)->evaluate(bound_scratch, bound);
  double fused_error = 0.0;
  for (Index j = 0; j < 3; ++j) {
    const double scale = std::max(max_norm(field_back.col(j)), 1e-300);
    fused_error = std::max({fused_error, relative(fused.col(j), field_back.col(j), scale),
                            relative(bound.col(j), field_back.col(j), scale)});
  }
  check("filtered_field = flow, field, flow back", fused_error, 1e-12,
        "filtered_field(taus, u) and bind_tau_grid(taus)->evaluate(u) must equal linear_flow(-tau) of nonlinear_field of linear_flow(tau) u, "
        "column by column");

  check("batched calls = one column at a time", batch, 1e-12,
        "batched calls take one state per column (column j: the state at the j-th tau point); "
        "every column must be treated, independently of the others");

  if (!mod.is_complex()) {
    const Vector rw = w.real().cast<Complex>(), rz = z.real().cast<Complex>();
    Matrix f(n, 1), d(n, 1);
    mod.nonlinear_field(rw, f);
    mod.nonlinear_field_derivative(rw, rz, d);
    const Vector fl = mod.linear_flow(1.3, rw);
    const double imag = std::max({fl.imag().cwiseAbs().maxCoeff() / max_norm(rw),
                                  f.imag().cwiseAbs().maxCoeff() / std::max(max_norm(f.col(0)), 1e-300),
                                  d.imag().cwiseAbs().maxCoeff() / std::max(max_norm(d.col(0)), 1e-300)});
    check("real states stay real (is_complex() is false)", imag, 1e-14,
          "a real model keeps zero imaginary parts in linear_flow and nonlinear_field");
  }

  const double h = 1e-6 * std::max(1.0, w_norm);
  Matrix plus(n, 1), minus(n, 1), analytic(n, 1);
  mod.nonlinear_field(w + h * z, plus);
  mod.nonlinear_field(w - h * z, minus);
  mod.nonlinear_field_derivative(w, z, analytic);
  const Vector quotient = (plus - minus).col(0) / (2 * h);
  check("nonlinear_field_derivative = difference quotient",
        relative(analytic.col(0), quotient,
                 std::max({max_norm(quotient), max_norm(plus.col(0)) / w_norm, 1e-12})),
        1e-6, "nonlinear_field_derivative(u, z) must be J Hess H1(u) z, the derivative of nonlinear_field");
}

Vector ModelChecks::reference(std::shared_ptr<const Model> m, const Vector& u0) const {
  auto filtered = reformulation("filtered", m, Json::object());
  const SchemeEntry& rk78 = registry_.scheme("rk78", "reference.scheme");
  auto ref = stepper(rk78, reference_tol, 200);
  Vector y = filtered->prepare(u0);
  integrate(*filtered, *ref, y, t_end, 1, {});
  return filtered->read_back(y, t_end);
}

std::vector<double> ModelChecks::errors(const SchemeEntry& scheme, double eps, const Vector& x_ref,
                                        const long (&steps)[4]) const {
  std::vector<double> out;
  for (const long n : steps) {
    const auto m = model(eps);
    auto problem = two_scale_problem(scheme, m);
    auto s = stepper(scheme, 1e-12, 200);
    const double h = t_end / static_cast<double>(n);
    Vector y = problem->prepare(m->initial_value());
    integrate(*problem, *s, y, h, n, {});
    const Vector x = m->to_physical(problem->read_back(y, step_time(n, h)));
    out.push_back(m->error_norm(x - x_ref) / m->error_norm(x_ref));
  }
  return out;
}

namespace {

/// The observed order over the errors above the floor (at least three of them), if any.
struct Fit {
  bool finite = false, measurable = false;
  double order = 0.0;
  size_t used = 0;
};

Fit fit_order(const long (&steps)[4], const std::vector<double>& errors) {
  Fit f;
  f.finite = std::all_of(errors.begin(), errors.end(), [](double e) { return std::isfinite(e); });
  std::vector<double> hs, es;
  for (size_t i = 0; i < errors.size(); ++i)
    if (errors[i] >= error_floor)
      hs.push_back(t_end / static_cast<double>(steps[i])), es.push_back(errors[i]);
  f.used = es.size();
  f.measurable = f.finite && es.size() >= 3;
  if (f.measurable) f.order = least_squares_order(hs, es);
  return f;
}

}  // namespace

void ModelChecks::orders(const SchemeEntry& scheme, double eps, const Vector& x_ref) {
  const auto within = [&](const Fit& f) {
    return f.measurable && std::abs(f.order - scheme.traits.order) <= order_margin;
  };
  const std::vector<double> errs = errors(scheme, eps, x_ref, step_counts);
  const Fit fit = fit_order(step_counts, errs);
  std::string row;
  for (const double e : errs) row += fmt::format(" {:>9.2e}", e);
  std::string note;
  bool ok = within(fit) || (fit.finite && !fit.measurable);
  if (!fit.finite)
    note = "  (not finite: blow-up)";
  else if (!fit.measurable)
    note = fmt::format("  (errors below {:.0e}: no order to observe)", error_floor);
  else if (fit.used < errs.size())
    note = fmt::format("  (over the {} errors above {:.0e})", fit.used, error_floor);
  Fit finer;
  if (!ok && fit.finite) {
    const std::vector<double> finer_errs = errors(scheme, eps, x_ref, finer_step_counts);
    finer = fit_order(finer_step_counts, finer_errs);
    ok = within(finer);
    note = finer.measurable ? fmt::format("  ({:.2f} over h = 1/16 .. 1/128)", finer.order) : "";
  }
  const std::string observed = fit.measurable ? fmt::format("{:.2f}", fit.order) : "-";
  report(ok,
         fmt::format("{:<12} {:<8g}{} {:>6}  {} +- {:g}{}", scheme.info.name, eps, row, observed,
                     scheme.traits.order, order_margin, note),
         fmt::format("{} at eps = {:g}: observed order {}{}, expected {} +- {:g}", scheme.info.name, eps,
                     observed,
                     finer.measurable ? fmt::format(" ({:.2f} over h = 1/16 .. 1/128)", finer.order) : "",
                     scheme.traits.order, order_margin),
         fit.finite
             ? "the two-scale schemes reach their order only on a model of the problem class: see the "
               "interface lines above; n_tau (default_n_tau) must resolve the tau dependence"
             : "the run blew up or its implicit stages diverged: if the model is strongly nonlinear at this "
               "eps, h = 1/4 .. 1/32 does not resolve it; check the eps of its regime with --eps");
}

void ModelChecks::symmetry(const SchemeEntry& scheme, double eps) {
  const auto m = model(eps);
  auto problem = two_scale_problem(scheme, m);
  auto s = stepper(scheme, 1e-14, 1000);
  const Vector start = problem->prepare(m->initial_value());
  Vector y = start;
  s->step(*problem, 0.0, symmetry_step, y);
  s->step(*problem, symmetry_step, -symmetry_step, y);
  const double back = max_norm(y - start) / max_norm(start);
  check(fmt::format("{:<8} eps = {:g}: returns to", scheme.info.name, eps), back, symmetry_limit,
        "a symmetric scheme's step h then -h returns the state; if the model is smooth this points at "
        "the scheme");
}

void ModelChecks::convergence(const std::vector<const SchemeEntry*>& schemes,
                              const std::vector<double>& epsilons) {
  std::vector<Vector> references;
  fmt::print("\n  reference: rk78 on the filtered problem, tol {:g}, T = {:g}\n", reference_tol, t_end);
  for (const double eps : epsilons) {
    const auto m = model(eps);
    const Vector u0 = m->initial_value();
    const Vector u = reference(m, u0);
    references.push_back(m->to_physical(u));
    const double h0 = m->energy(u0);
    check(fmt::format("energy H conserved at eps = {:g}", eps),
          std::abs(m->energy(u) - h0) / std::max(std::abs(h0), 1e-300), 1e-6,
          "the exact flow conserves H = <Mu, u>/(2 eps) + H1(u): nonlinear_field must be J grad H1 of the "
          "model's H1, with the M and J of linear_flow");
  }
  for (const double eps : epsilons) {
    const std::string resonant = resonant_steps(eps);
    if (!resonant.empty())
      fmt::print(
          "    note: at eps = {:g}, {} close to a whole number of half fast periods (pi eps):\n"
          "          a step-size resonance can bend the observed order there\n",
          eps, resonant);
  }
  if (schemes.empty()) {
    fmt::print("\n  no scheme integrates the two-scale problem: no orders to check\n");
    return;
  }
  fmt::print("\n  order at T = {:g}, h = 1/4 .. 1/32, relative error against the reference\n", t_end);
  fmt::print("    {:<5} {:<12} {:<8}", "", "scheme", "eps");
  for (const long steps : step_counts)
    fmt::print(" {:>9}", fmt::format("{}1/{}", steps == step_counts[0] ? "h = " : "", steps));
  fmt::print(" {:>6}  {}\n", "order", "expected");
  for (const auto* scheme : schemes) {
    for (size_t k = 0; k < epsilons.size(); ++k) {
      try {
        orders(*scheme, epsilons[k], references[k]);
      } catch (const std::exception& e) {
        report(false, fmt::format("{:<12} {:<8g} {}", scheme->info.name, epsilons[k], e.what()),
               fmt::format("{} at eps = {:g}: {}", scheme->info.name, epsilons[k], e.what()), "");
      }
    }
  }
  bool any_symmetric = false;
  for (const auto* scheme : schemes) {
    if (!scheme->traits.symmetric) continue;
    if (!any_symmetric)
      fmt::print("\n  {:<60} {:>9} {:>9}\n",
                 fmt::format("symmetry: a step h = {:g}, then -h (symmetric schemes)", symmetry_step),
                 "value", "limit");
    any_symmetric = true;
    for (const double eps : epsilons) {
      try {
        symmetry(*scheme, eps);
      } catch (const std::exception& e) {
        report(false, fmt::format("{:<8} eps = {:g}: {}", scheme->info.name, eps, e.what()),
               fmt::format("{} symmetry at eps = {:g}: {}", scheme->info.name, eps, e.what()), "");
      }
    }
  }
}

std::string canonical(const std::string& path) {
  std::error_code ec;
  const auto c = std::filesystem::canonical(path, ec);
  return ec ? path : c.string();
}

}  // namespace

int check_command(PluginLoader& loader, const Registry& registry, CheckOptions options,
                  const std::vector<std::string>& runner_plugins) {
  std::set<std::string> providers;
  for (const auto& file : options.plugins) {
    loader.load(file);
    providers.insert(canonical(file));
  }
  for (const auto& file : runner_plugins) providers.insert(canonical(file));
  if (options.epsilons.empty()) options.epsilons = {1.0, 1e-3};
  for (const double eps : options.epsilons)
    if (!(eps > 0.0 && eps <= 1.0))
      throw ConfigError("check --eps", fmt::format("got {:g}, expected a number in (0, 1]", eps));

  std::vector<const ModelEntry*> models;
  std::vector<const SchemeEntry*> schemes;
  if (!options.model.empty()) {
    models.push_back(&registry.model(options.model, "check"));
  } else {
    for (const auto* e : registry.models())
      if (providers.contains(e->info.provider)) models.push_back(e);
  }
  if (!options.schemes.empty()) {
    for (const auto& name : options.schemes) {
      const SchemeEntry& e = registry.scheme(name, "check --scheme");
      if (!two_scale(e))
        throw ConfigError("check --scheme",
                          "\"" + e.info.name + "\" does not integrate the two-scale problem");
      schemes.push_back(&e);
    }
  } else {
    for (const auto* e : registry.schemes())
      if (two_scale(*e) && providers.contains(e->info.provider)) schemes.push_back(e);
  }
  if (!providers.empty() && models.empty() && schemes.empty() && options.model.empty())
    throw ConfigError("check",
                      "the plugins named provide no model and no two-scale scheme: nothing to check");
  if (models.empty()) models = registry.models();
  if (schemes.empty() && options.schemes.empty())
    for (const auto* e : registry.schemes())
      if (two_scale(*e)) schemes.push_back(e);

  int failed_models = 0;
  for (const auto* entry : models) {
    const auto start = std::chrono::steady_clock::now();
    fmt::print("{} (provided by {})\n", entry->info.name, entry->info.provider);
    ModelChecks checks(registry, *entry);
    try {
      const auto m = entry->create(
          Params(resolve_params(entry->info.params, Json{{"eps", options.epsilons.front()}}, "model")));
      fmt::print("  dim {}, {}, default n_tau {}, nonlinearity degree {}\n\n", m->dim(),
                 m->is_complex() ? "complex" : "real", entry->default_n_tau, entry->nonlinearity_degree);
      checks.interface(options.epsilons.front());
      checks.convergence(schemes, options.epsilons);
    } catch (const std::exception& e) {
      checks.fail(e.what());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (checks.failures().empty()) {
      fmt::print("\n{}: all {} checks passed ({:.2g} s)\n\n", entry->info.name, checks.count(), seconds);
    } else {
      ++failed_models;
      fmt::print("\n{}: {} of {} checks FAILED ({:.2g} s):\n", entry->info.name, checks.failures().size(),
                 std::max(checks.count(), static_cast<int>(checks.failures().size())), seconds);
      for (const auto& f : checks.failures()) fmt::print("  - {}\n", f);
      fmt::print("\n");
    }
  }
  if (models.size() > 1)
    fmt::print("{} of {} models passed every check\n", models.size() - static_cast<size_t>(failed_models),
               models.size());
  return failed_models == 0 ? 0 : 1;
}

}  // namespace tsi::app
