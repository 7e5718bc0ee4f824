#include "tsi/model_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <limits>

#include "tsi/assembly.hpp"
#include "tsi/convergence.hpp"
#include "tsi/driver.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"

namespace tsi {
namespace {

constexpr double t_end = 1.0;

constexpr double reference_tol = 1e-14;
constexpr double order_margin = 0.2, high_order_margin = 0.5;
constexpr double symmetry_step = 0.25, symmetry_limit = 1e-10;
// Errors below this measure the reference and the tau resolution (n_tau), not the scheme:
// they are left out of the order fit (a round-off plateau filter).
constexpr double error_floor = 1e-7;
// Orders above 2 fall below 1e-7 within the steps checked: their errors are fitted down to
// this, still well above the reference's accuracy at reference_tol.
constexpr double high_order_floor = 1e-9, envelope_floor = 1e-10;
// A model's default n_tau resolves tau to the errors of order 2; the higher orders reach the
// tau grid's own error (NLS at eps = 1, n_tau = 256: 2.2e-8), so they run on twice the grid.
constexpr int high_order_tau_factor = 2;

double floor_for(const StepperTraits& traits) { return traits.order > 2 ? high_order_floor : error_floor; }


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

/// The steps that lie close to a whole number of half fast periods (pi eps), within 0.06 of
/// one, as "h = 1/16, h = 1/32 are" (empty when none).
std::string resonant_steps(const std::vector<long>& steps, double eps) {
  std::string out;
  int count = 0;
  for (const long n : steps) {
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
  ModelChecks(const Registry& registry, const ModelEntry& entry, const ModelCheckOptions& options, std::FILE* out)
      : registry_(registry), entry_(entry), options_(options), out_(out) {
    // When the order over the given steps misses, they may still be pre-asymptotic for this
    // model: if the order over steps four times finer settles, that fit counts.
    for (const long n : options_.steps) finer_steps_.push_back(4 * n);
  }

  void interface(double eps);
  void convergence(const std::vector<const SchemeEntry*>& schemes, const std::vector<double>& epsilons);

  /// A failure outside any single check (the model could not even be built).
  void fail(const std::string& why) {
    fmt::print(out_, "    {:<5} {}\n", "FAIL", why);
    failures_.push_back(why);
  }
  const std::vector<std::string>& failures() const { return failures_; }
  /// The model section of the checks' configs: the user's --set model parameters and eps.
  Json model_section(double eps) const {
    Json m = options_.model_params;
    m["name"] = entry_.info.name;
    m["eps"] = eps;
    return m;
  }
  /// The scheme's traits with the user's --set scheme parameters (eab's order, ...).
  StepperTraits traits_of(const SchemeEntry& scheme) const {
    Json params = Json::object();
    for (const auto& p : scheme.info.params)
      if (options_.scheme_params.contains(p.name)) params[p.name] = options_.scheme_params[p.name];
    return scheme_traits(scheme, resolve_params(scheme.info.params, params, "scheme"));
  }
  /// The reformulation section of the checks' configs: the user's --set reformulation
  /// parameters on the two-scale one.
  Json reformulation_section(const std::string& name) const {
    Json r = name == "two-scale" ? options_.reformulation_params : Json::object();
    r["name"] = name;
    return r;
  }
  std::shared_ptr<const Model> model(double eps) const {
    Json params = model_section(eps);
    params.erase("name");
    return entry_.create(Params(resolve_params(entry_.info.params, params, "model")));
  }

  int count() const { return count_; }

 private:
  void report(bool ok, const std::string& line, const std::string& failure, const std::string& hint) {
    ++count_;
    fmt::print(out_, "    {:<5} {}\n", ok ? "ok" : "FAIL", line);
    if (!ok) failures_.push_back(failure + (hint.empty() ? "" : "\n      " + hint));
  }
  void check(const std::string& what, double value, double limit, const std::string& hint) {
    const bool ok = std::isfinite(value) && value <= limit;
    report(ok, fmt::format("{:<52} {:>9.2e} {:>9.0e}", what, value, limit),
           fmt::format("{}: {:.2e} exceeds {:.0e}", what, value, limit), hint);
  }

  /// A run's objects through the core's assembler (as `tsi run` builds them): the scheme's tol
  /// and max_iter where it takes them, every other default completed by the entries.
  Assembly assembly(const SchemeEntry& scheme, const std::string& reformulation, double eps, double tol,
                    int max_iter) const {
    Json scheme_section = {{"name", scheme.info.name}};
    for (const auto& p : scheme.info.params) {
      if (p.name == "tol") scheme_section["tol"] = tol;
      if (p.name == "max_iter") scheme_section["max_iter"] = max_iter;
      if (options_.scheme_params.contains(p.name)) scheme_section[p.name] = options_.scheme_params[p.name];
    }
    return assemble_config({{"model", model_section(eps)},
                            {"reformulation", reformulation_section(reformulation)},
                            {"scheme", scheme_section}},
                           registry_);
  }
  /// What limits h for this model whatever eps: the size of J Hess H1 at u0 (a power
  /// iteration on nonlinear_field_derivative). An explicit treatment of H1 needs h L <~ 2.
  double field_stiffness(double eps) const;
  /// The measured cause of a missed order, as advice (empty when nothing stands out).
  std::string diagnose(const SchemeEntry& scheme, double eps, const Vector& x_ref) const;
  Vector reference(std::shared_ptr<const Model> m, const Vector& u0, double tol = reference_tol) const;
  /// Below this an error measures the reference: twice its change from tol to 10 tol (which is
  /// about 6x its error at tol; Klein-Gordon at eps = 1e-4: 2.5e-9 at tol 1e-14), at least `floor`.
  double reference_floor(double eps, double floor) const {
    const auto it = reference_accuracy_.find(eps);
    return std::max(floor, it == reference_accuracy_.end() ? 0.0 : 2.0 * it->second);
  }
  std::map<double, double> reference_accuracy_;
  /// The relative errors at T for the given numbers of steps.
  std::vector<double> errors(const SchemeEntry& scheme, double eps, const Vector& x_ref,
                             const std::vector<long>& steps, int n_tau_factor = 1) const;
  void orders(const SchemeEntry& scheme, double eps, const Vector& x_ref);
  /// The order of the maximum error over eps (schemes whose classical order exceeds their
  /// uniform order).
  void envelope(const SchemeEntry& scheme, const std::vector<double>& epsilons, const std::vector<Vector>& references);
  void symmetry(const SchemeEntry& scheme, double eps);

  const Registry& registry_;
  const ModelEntry& entry_;
  const ModelCheckOptions& options_;
  std::FILE* out_;
  std::vector<long> finer_steps_;
  std::vector<std::string> failures_;
  int count_ = 0;
};

void ModelChecks::interface(double eps) {
  fmt::print(out_, "  {:<60} {:>9} {:>9}\n", fmt::format("interface at eps = {:g}", eps), "value", "limit");
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

  const bool hamiltonian = mod.has_hamiltonian_structure();
  if (!hamiltonian)
    fmt::print(out_, "    {:<5} {}\n", "note",
               "the model declares no Hamiltonian structure: the checks of J, M, H1 and of energy conservation are "
               "skipped (its f is not a Hamiltonian field)");
  Vector au(n);
  if (hamiltonian) {
    Vector mw(n);
    mod.apply_M(w, mw);
    mod.apply_J(mw, au);
  } else {
    mod.apply_A(w, au);
  }
  const double omega = mod.max_linear_frequency(), delta = 1e-5 / omega;
  const Vector derivative = (mod.linear_flow(delta, w) - mod.linear_flow(-delta, w)) / (2 * delta);
  check(hamiltonian ? "d/dtau linear_flow(tau) u at 0 = J M u" : "d/dtau linear_flow(tau) u at 0 = A u",
        relative(derivative, au, std::max(max_norm(au), omega * w_norm)), 1e-6,
        hamiltonian ? "the flow must be generated by apply_J(apply_M(u)): the flow, M and J disagree (a sign or a factor)"
                    : "the flow must be generated by apply_A(u): the flow and A disagree (a sign or a factor)");

  if (mod.has_linear_remainder()) {
    // J R must commute with J M: the two-scale multipliers -i k/eps + i omega_j assume that
    // e^{JR t} acts on every tau mode alike.
    Vector rl = mod.linear_flow(0.9, w), lr = w;
    mod.remainder_flow(0.37, rl);
    mod.remainder_flow(0.37, lr);
    lr = mod.linear_flow(0.9, lr);
    check("remainder_flow commutes with linear_flow", relative(rl, lr, w_norm), 1e-12,
          "linear_remainder() gives the frequencies of J R in the model's coordinates, and J R must commute "
          "with J M (both diagonal in the model's coordinates)");
  }

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

Vector ModelChecks::reference(std::shared_ptr<const Model> m, const Vector& u0, double tol) const {
  Assembly a = assembly(registry_.scheme("rk78", "reference.scheme"), "filtered", m->eps(), tol, 200);
  Vector y = a.reformulation->prepare(u0);
  integrate(a.bind(t_end), y, 1, {});
  return a.reformulation->read_back(y, t_end);
}

std::vector<double> ModelChecks::errors(const SchemeEntry& scheme, double eps, const Vector& x_ref,
                                        const std::vector<long>& steps, int n_tau_factor) const {
  std::vector<double> out;
  for (const long n : steps) {
    Assembly a = assembly(scheme, "two-scale", eps, 1e-14, 1000);
    if (n_tau_factor != 1) {  // the same run on a finer tau grid (diagnose)
      Json config = {{"model", model_section(eps)}, {"reformulation", reformulation_section("two-scale")},
                     {"scheme", {{"name", scheme.info.name}}}};
      for (const auto& p : scheme.info.params)
        if (options_.scheme_params.contains(p.name)) config["scheme"][p.name] = options_.scheme_params[p.name];
      const Json resolved = resolve_selection(config, registry_);
      config["reformulation"]["n_tau"] = n_tau_factor * resolved["reformulation"]["n_tau"].get<long>();
      for (const auto& p : scheme.info.params)
        if (p.name == "tol") config["scheme"]["tol"] = 1e-14;
      a = assemble_config(config, registry_);
    }
    const double h = t_end / static_cast<double>(n);
    Vector y = a.reformulation->prepare(a.u0);
    double error = std::numeric_limits<double>::quiet_NaN();
    try {
      integrate(a.bind(h), y, n, {});
      const Vector x = a.model->to_physical(a.reformulation->read_back(y, step_time(n, h)));
      error = a.model->error_norm(x - x_ref) / a.model->error_norm(x_ref);
    } catch (const Error&) {
      // a diverged stage or a non-finite state: a failed run, reported as not finite
    }
    out.push_back(error);
  }
  return out;
}

namespace {

std::vector<double> step_sizes(const std::vector<long>& steps) {
  std::vector<double> h;
  for (const long n : steps) h.push_back(t_end / static_cast<double>(n));
  return h;
}

std::string step_range(const std::vector<long>& steps) {
  return fmt::format("h = 1/{} .. 1/{}", steps.front(), steps.back());
}

}  // namespace

double ModelChecks::field_stiffness(double eps) const {
  const auto m = model(eps);
  const Vector u0 = m->initial_value();
  Vector z = sample_state(*m, Vector::Zero(m->dim()), 0.7);
  double rate = 0.0;
  Matrix out(m->dim(), 1);
  for (int k = 0; k < 30; ++k) {  // the growth of z under J Hess H1(u0): its largest eigenvalue's modulus
    const double norm = z.norm();
    if (!(norm > 0.0)) return 0.0;
    z /= norm;
    m->nonlinear_field_derivative(u0, z, out);
    rate = out.col(0).norm();
    z = out.col(0);
  }
  return rate;
}

std::string ModelChecks::diagnose(const SchemeEntry& scheme, double eps, const Vector& x_ref) const {
  std::vector<std::string> causes;
  const double coarsest = t_end / static_cast<double>(options_.steps.front());
  const double stiffness = field_stiffness(eps);
  if (coarsest * stiffness > 1.0)
    causes.push_back(fmt::format(
        "measured: J Hess H1 at u0 has size {:.3g}, so h = {:g} times it is {:.2g}: the nonlinear part is "
        "stiff and limits h to about 2 / {:.3g} = {:.2g} whatever eps. If a large linear part sits in H1, "
        "hand it over as Model::linear_remainder (docs/writing-a-model.md) so that it is integrated exactly",
        stiffness, coarsest, coarsest * stiffness, stiffness, 2.0 / stiffness));
  const std::vector<long> finest = {options_.steps.back()};
  const double plain = errors(scheme, eps, x_ref, finest).front();
  const double doubled = errors(scheme, eps, x_ref, finest, 2).front();
  if (std::isfinite(plain) && std::isfinite(doubled) && std::abs(plain - doubled) > 0.25 * std::abs(doubled))
    causes.push_back(fmt::format(
        "measured: doubling n_tau moves the error at h = 1/{} from {:.2e} to {:.2e}: the tau grid does not "
        "resolve the tau dependence; raise the model's default_n_tau (or reformulation.n_tau)",
        finest.front(), plain, doubled));
  std::string out;
  for (const auto& c : causes) out += (out.empty() ? "" : "\n      ") + c;
  return out;
}

void ModelChecks::orders(const SchemeEntry& scheme, double eps, const Vector& x_ref) {
  // Orders above 2 settle later and reach the reference's accuracy sooner: within 0.5.
  const int order = traits_of(scheme).order;
  const double margin = order > 2 ? high_order_margin : order_margin;
  const auto within = [&](const OrderFit& f) { return f.measurable && std::abs(f.order - order) <= margin; };
  const std::vector<long>& steps = options_.steps;
  const std::vector<double> errs = errors(scheme, eps, x_ref, steps, order > 2 ? high_order_tau_factor : 1);
  const double floor = reference_floor(eps, floor_for(traits_of(scheme)));
  const OrderFit fit = fit_order(step_sizes(steps), errs, floor);
  std::string row;
  for (const double e : errs) row += fmt::format(" {:>9.2e}", e);
  std::string note;
  bool ok = within(fit) || (fit.finite && !fit.measurable && fit.used == 0);
  if (!fit.finite)
    note = "  (not finite: blow-up or a failed run)";
  else if (!fit.measurable)
    note = fmt::format("  (errors below {:.0e}: no order to observe)", floor);
  else if (fit.used < errs.size())
    note = fmt::format("  (over the {} errors above {:.0e})", fit.used, floor);
  OrderFit finer;
  if (!ok && fit.finite) {
    const std::vector<double> finer_errs = errors(scheme, eps, x_ref, finer_steps_, order > 2 ? high_order_tau_factor : 1);
    finer = fit_order(step_sizes(finer_steps_), finer_errs, floor);
    ok = within(finer);
    note = finer.measurable ? fmt::format("  ({:.2f} over {})", finer.order, step_range(finer_steps_)) : "";
  }
  const std::string observed = fit.measurable ? fmt::format("{:.2f}", fit.order) : "-";
  std::string hint;
  if (!ok) {
    hint = diagnose(scheme, eps, x_ref);
    if (hint.empty())
      hint = fit.finite ? "nothing measured stands out (the field is not stiff at u0 and n_tau resolves tau): the "
                          "two-scale schemes reach their order only on a model of the problem class; see the "
                          "interface lines above"
                        : "the run blew up or its implicit stages diverged, and the field is not stiff at u0: if "
                          "the model is strongly nonlinear at this eps, the steps do not resolve it; try --steps "
                          "with more steps, or the eps of its regime with --eps";
  }
  report(ok,
         fmt::format("{:<12} {:<10.4g}{} {:>6}  {} +- {:g}{}", scheme.info.name, eps, row, observed,
                     order, margin, note),
         fmt::format("{} at eps = {:g}: observed order {}{}, expected {} +- {:g}", scheme.info.name, eps,
                     fit.finite ? observed : "- (not finite)",
                     finer.measurable ? fmt::format(" ({:.2f} over {})", finer.order, step_range(finer_steps_)) : "",
                     order, margin),
         hint);
}

void ModelChecks::envelope(const SchemeEntry& scheme, const std::vector<double>& epsilons,
                           const std::vector<Vector>& references) {
  // Uniform order p: max over eps of the error <= C h^p. At a given eps such a scheme's error
  // may dip below that bound (step-size resonances), so the order is fitted on the maximum.
  const StepperTraits traits = traits_of(scheme);
  const std::vector<long>& steps = options_.steps;
  std::vector<double> worst(steps.size(), 0.0);
  try {
    for (size_t k = 0; k < epsilons.size(); ++k) {
      const std::vector<double> errs = errors(scheme, epsilons[k], references[k], steps, high_order_tau_factor);
      // An error below its own reference's accuracy measures that reference: left out.
      const double floor = reference_floor(epsilons[k], envelope_floor);
      for (size_t i = 0; i < steps.size(); ++i)
        worst[i] = !std::isfinite(errs[i]) ? std::numeric_limits<double>::infinity()
                                           : std::max(worst[i], errs[i] > floor ? errs[i] : 0.0);
    }
  } catch (const std::exception& e) {
    report(false, fmt::format("{:<12} {:<10} {}", scheme.info.name, "max", e.what()),
           fmt::format("{}: {}", scheme.info.name, e.what()), "");
    return;
  }
  const OrderFit fit = fit_order(step_sizes(steps), worst, envelope_floor);
  std::string row;
  for (const double e : worst) row += e > 0.0 ? fmt::format(" {:>9.2e}", e) : fmt::format(" {:>9}", "(ref)");
  // Too few errors above the reference's accuracy to fit: nothing to observe, as in orders().
  const bool ok = fit.finite && (fit.measurable ? fit.order >= traits.order - order_margin : true);
  const std::string observed = fit.measurable ? fmt::format("{:.2f}", fit.order) : "-";
  report(ok,
         fmt::format("{:<12} {:<10}{} {:>6}  >= {} - {:g} (max over eps; {} at fixed eps)", scheme.info.name,
                     "max", row, observed, traits.order, order_margin, traits.classical_order),
         fmt::format("{}: order of the maximum error over eps {}, expected at least {} - {:g}", scheme.info.name,
                     observed, traits.order, order_margin),
         "the scheme's declared uniform order is not reached on this model");
}

void ModelChecks::symmetry(const SchemeEntry& scheme, double eps) {
  Assembly a = assembly(scheme, "two-scale", eps, 1e-14, 1000);
  const Vector start = a.reformulation->prepare(a.u0);
  Vector y = start;
  a.bind(symmetry_step).step(0.0, y);
  a.bind(-symmetry_step).step(symmetry_step, y);
  const double back = max_norm(y - start) / max_norm(start);
  check(fmt::format("{:<8} eps = {:g}: returns to", scheme.info.name, eps), back, symmetry_limit,
        "a symmetric scheme's step h then -h returns the state; if the model is smooth this points at "
        "the scheme");
}

void ModelChecks::convergence(const std::vector<const SchemeEntry*>& schemes,
                              const std::vector<double>& epsilons) {
  std::vector<Vector> references;
  fmt::print(out_, "\n  reference: rk78 on the filtered problem, tol {:g} (its accuracy: the change from tol {:g}), T = {:g}\n",
             reference_tol, 10.0 * reference_tol, t_end);
  for (const double eps : epsilons) {
    const auto m = model(eps);
    const Vector u0 = m->initial_value();
    const Vector u = reference(m, u0);
    references.push_back(m->to_physical(u));
    const Vector coarser = m->to_physical(reference(m, u0, 10.0 * reference_tol));
    reference_accuracy_[eps] = (coarser - references.back()).norm() / references.back().norm();
    if (!m->has_hamiltonian_structure()) continue;  // no energy to conserve (said in the interface checks)
    const double h0 = m->energy(u0);
    check(fmt::format("energy H conserved at eps = {:g}", eps),
          std::abs(m->energy(u) - h0) / std::max(std::abs(h0), 1e-300), 1e-6,
          "the exact flow conserves H = <Mu, u>/(2 eps) + H1(u): nonlinear_field must be J grad H1 of the "
          "model's H1, with the M and J of linear_flow");
  }
  for (const double eps : epsilons) {
    const std::string resonant = resonant_steps(options_.steps, eps);
    if (!resonant.empty())
      fmt::print(
          "    note: at eps = {:g}, {} close to a whole number of half fast periods (pi eps):\n"
          "          a step-size resonance can bend the observed order there\n",
          eps, resonant);
  }
  if (schemes.empty()) {
    fmt::print(out_, "\n  no scheme integrates the two-scale problem: no orders to check\n");
    return;
  }
  fmt::print(out_, "\n  order at T = {:g}, {}, relative error against the reference\n", t_end, step_range(options_.steps));
  fmt::print(out_, "    {:<5} {:<12} {:<10}", "", "scheme", "eps");
  for (const long steps : options_.steps)
    fmt::print(out_, " {:>9}", fmt::format("{}1/{}", steps == options_.steps.front() ? "h = " : "", steps));
  fmt::print(out_, " {:>6}  {}\n", "order", "expected");
  for (const auto* scheme : schemes) {
    if (traits_of(*scheme).classical_order > traits_of(*scheme).order) {
      envelope(*scheme, epsilons, references);
      continue;
    }
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
    if (!traits_of(*scheme).symmetric) continue;
    if (!any_symmetric)
      fmt::print(out_, "\n  {:<60} {:>9} {:>9}\n",
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

}  // namespace

/// The eps and steps of a check (given, or the model's declared regime), refused when bad.
void check_regime(const std::vector<double>& epsilons, const std::vector<long>& steps) {
  for (const double eps : epsilons)
    if (!(eps > 0.0 && eps <= 1.0))
      throw ConfigError("check --eps", fmt::format("got {:g}, expected a number in (0, 1]", eps));
  if (epsilons.empty()) throw ConfigError("check --eps", "no eps to check");
  if (steps.size() < 3)
    throw ConfigError("check --steps", fmt::format("got {} step counts, expected at least 3 to observe an order",
                                                   steps.size()));
  for (size_t i = 0; i < steps.size(); ++i)
    if (steps[i] < 1 || steps[i] > 1000000 || (i > 0 && steps[i] <= steps[i - 1]))
      throw ConfigError("check --steps",
                        fmt::format("got {}, expected increasing step counts from 1 to 1000000", steps[i]));
}

ModelCheckReport check_model(const Registry& registry, const ModelEntry& entry,
                             const std::vector<const SchemeEntry*>& schemes, const ModelCheckOptions& options,
                             std::FILE* out) {
  const auto start = std::chrono::steady_clock::now();
  fmt::print(out, "{} (provided by {})\n", entry.info.name, entry.info.provider);
  // The model's declared regime where the options give none.
  ModelCheckOptions model_options = options;
  if (model_options.epsilons.empty()) model_options.epsilons = entry.verification.epsilons;
  if (model_options.steps.empty()) model_options.steps = entry.verification.steps;
  ModelChecks checks(registry, entry, model_options, out);
  try {
    check_regime(model_options.epsilons, model_options.steps);
    const auto m = checks.model(model_options.epsilons.front());
    fmt::print(out, "  dim {}, {}, default n_tau {}, nonlinearity degree {}\n\n", m->dim(),
               m->is_complex() ? "complex" : "real", entry.default_n_tau, entry.nonlinearity_degree);
    checks.interface(model_options.epsilons.front());
    checks.convergence(schemes, model_options.epsilons);
  } catch (const std::exception& e) {
    checks.fail(e.what());
  }
  ModelCheckReport report;
  report.count = std::max(checks.count(), static_cast<int>(checks.failures().size()));
  report.failures = checks.failures();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report.failures.empty()) {
    fmt::print(out, "\n{}: all {} checks passed ({:.2g} s)\n\n", entry.info.name, report.count, report.seconds);
  } else {
    fmt::print(out, "\n{}: {} of {} checks FAILED ({:.2g} s):\n", entry.info.name, report.failures.size(),
               report.count, report.seconds);
    for (const auto& f : report.failures) fmt::print(out, "  - {}\n", f);
    fmt::print(out, "\n");
  }
  return report;
}

}  // namespace tsi
