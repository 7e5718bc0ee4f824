#include "tsi/model_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <limits>
#include <tuple>

#include "tsi/assembly.hpp"
#include "tsi/convergence.hpp"
#include "tsi/driver.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"

namespace tsi {
namespace {

constexpr Real t_end = 1.0;

constexpr Real reference_tol = 1e-14;
constexpr Real order_margin = 0.2, high_order_margin = 0.5;
constexpr Real symmetry_step = 0.25, symmetry_limit = 1e-10;
// Errors below this measure the reference and the tau resolution (n_tau), not the scheme:
// they are left out of the order fit (a round-off plateau filter).
constexpr Real error_floor = 1e-7;
// Orders above 2 fall below 1e-7 within the steps checked: their errors are fitted down to
// this on twice the tau grid, still above the reference's accuracy at reference_tol.
constexpr Real envelope_floor = 1e-10;
// A model's default n_tau resolves tau to the errors of order 2; the higher orders reach the
// tau grid's own error (NLS at eps = 1, n_tau = 256: 2.2e-8), so they run on twice the grid.
constexpr int high_order_tau_factor = 2;
// Schemes of uniform order above 2, or with a higher order at fixed eps, run on the finer tau
// grid and are fitted down to envelope_floor; order 2 on the model's grid down to error_floor.
bool high_order(const StepperTraits& t) { return t.order > 2 || t.classical_order > t.order; }
int tau_factor(const StepperTraits& t) { return high_order(t) ? high_order_tau_factor : 1; }
Real fit_floor(const StepperTraits& t) { return high_order(t) ? envelope_floor : error_floor; }
// The eps log-spaced over the given range for the maximum over eps (besides the given ones and
// the step-size resonances inside it).
constexpr int dense_eps_points = 32;



/// A state of the model's kind away from any special point: u0 plus a fixed perturbation.
Vector sample_state(const Model& model, const Vector& u0, Real phase) {
  const Real scale = std::max<Real>(max_norm(u0), 0.1);
  Vector w = u0;
  for (Index i = 0; i < w.size(); ++i) {
    const Real a = std::sin(1.7 * static_cast<Real>(i) + phase),
                 b = std::cos(0.9 * static_cast<Real>(i) + 2 * phase);
    w(i) += Real(0.1) * scale * (model.is_complex() ? Complex(a, b) : Complex(a, 0));
  }
  return w;
}

/// The eps of a check, sorted down, each once: the given ones and, if `dense`, 32 log-spaced
/// over their range and the step-size resonances of `steps` inside it.
std::vector<Real> eps_sample(const std::vector<Real>& epsilons, const std::vector<long>& steps, bool dense);

/// The steps that lie close to a whole number of half fast periods (pi eps), within 0.06 of
/// one, as "h = 1/16, h = 1/32 are" (empty when none).
std::string resonant_steps(const std::vector<long>& steps, Real eps, Real max_half_periods = 1e300) {
  std::string out;
  int count = 0;
  for (const long n : steps) {
    const Real half_periods = 1.0 / (static_cast<Real>(n) * 0.5 * two_pi * eps);
    const Real nearest = std::round(half_periods);
    if (nearest >= 1.0 && nearest <= max_half_periods && std::abs(half_periods - nearest) <= 0.06) {
      out += fmt::format("{}h = 1/{}", out.empty() ? "" : ", ", n);
      ++count;
    }
  }
  return out.empty() ? out : out + (count > 1 ? " are" : " is");
}

Real relative(const Vector& a, const Vector& b, Real scale) {
  return max_norm(a - b) / std::max<Real>(scale, 1e-300);
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

  void interface(Real eps);
  void convergence(const std::vector<const SchemeEntry*>& schemes, const std::vector<Real>& epsilons);

  /// A failure outside any single check (the model could not even be built).
  void fail(const std::string& why) {
    fmt::print(out_, "    {:<5} {}\n", "FAIL", why);
    failures_.push_back(why);
  }
  const std::vector<std::string>& failures() const { return failures_; }
  const std::vector<std::string>& undecided() const { return undecidable_; }
  /// The model section of the checks' configs: the user's --set model parameters and eps.
  Json model_section(Real eps) const {
    Json m = options_.model_params;
    m["name"] = entry_.info.name;
    m["eps"] = to_double(eps);
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
  std::shared_ptr<const Model> model(Real eps) const {
    Json params = model_section(eps);
    params.erase("name");
    return entry_.create(Params(resolve_params(entry_.info.params, params, "model")));
  }

  int count() const { return count_; }

 private:
  /// A check that cannot decide: said, counted apart, never a failure.
  void undecidable(const std::string& line, const std::string& why) {
    ++count_;
    fmt::print(out_, "    {:<5} {}\n", "undec", line);
    undecidable_.push_back(why);
  }
  void report(bool ok, const std::string& line, const std::string& failure, const std::string& hint) {
    ++count_;
    fmt::print(out_, "    {:<5} {}\n", ok ? "ok" : "FAIL", line);
    if (!ok) failures_.push_back(failure + (hint.empty() ? "" : "\n      " + hint));
  }
  void check(const std::string& what, Real value, Real limit, const std::string& hint) {
    const bool ok = std::isfinite(value) && value <= limit;
    report(ok, fmt::format("{:<52} {:>9.2e} {:>9.0e}", what, value, limit),
           fmt::format("{}: {:.2e} exceeds {:.0e}", what, value, limit), hint);
  }

  /// A run's objects through the core's assembler (as `tsi run` builds them): the scheme's tol
  /// and max_iter where it takes them, every other default completed by the entries.
  Assembly assembly(const SchemeEntry& scheme, const std::string& reformulation, Real eps, Real tol,
                    int max_iter) const {
    Json scheme_section = {{"name", scheme.info.name}};
    for (const auto& p : scheme.info.params) {
      if (p.name == "tol") scheme_section["tol"] = to_double(tol);
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
  Real field_stiffness(Real eps) const;
  /// The measured cause of a missed order, as advice (empty when nothing stands out).
  std::string diagnose(const SchemeEntry& scheme, Real eps, const Vector& x_ref) const;
  Vector reference(std::shared_ptr<const Model> m, const Vector& u0, Real tol = reference_tol) const;
  /// Below this an error measures the reference: twice its change from tol to 10 tol (which is
  /// about 6x its error at tol; Klein-Gordon at eps = 1e-4: 2.5e-9 at tol 1e-14), at least `floor`.
  Real reference_floor(Real eps, Real floor) const {
    const auto it = reference_accuracy_.find(eps);
    return std::max(floor, it == reference_accuracy_.end() ? 0.0 : 2.0 * it->second);
  }
  std::map<Real, Real> reference_accuracy_;
  /// The reference at eps in physical variables, computed once (with its accuracy); returns it
  /// in the model's variables when computed now (empty when it was there already).
  Vector add_reference(Real eps);
  std::map<Real, Vector> references_;
  /// The relative errors at T for the given numbers of steps.
  std::vector<Real> errors(const SchemeEntry& scheme, Real eps, const Vector& x_ref,
                             const std::vector<long>& steps, int n_tau_factor = 1, int data_order = 0) const;
  /// The errors at eps for `steps` (the checked ones, or finer), on the scheme's tau grid,
  /// computed once per scheme, eps and steps.
  std::vector<Real> errors_at(const SchemeEntry& scheme, Real eps, const std::vector<long>& steps);
  std::map<std::tuple<std::string, Real, std::vector<long>>, std::vector<Real>> errors_;
  /// One eps's row (information).
  void orders(const SchemeEntry& scheme, Real eps, const std::vector<Real>& errs);
  /// The verdict: the order of the maximum error over the eps sample.
  void envelope(const SchemeEntry& scheme, const std::vector<Real>& sample);
  void symmetry(const SchemeEntry& scheme, Real eps);

  const Registry& registry_;
  const ModelEntry& entry_;
  const ModelCheckOptions& options_;
  std::FILE* out_;
  std::vector<long> finer_steps_;
  std::vector<std::string> failures_, undecidable_;
  int count_ = 0;
};

void ModelChecks::interface(Real eps) {
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
  const Real w_norm = max_norm(w);

  check("linear_flow(2 pi) u = u", relative(mod.linear_flow(two_pi, w), w, w_norm), 1e-10,
        "linear_flow(tau) must be e^{JM tau}, 2 pi periodic: JM has eigenvalues i k with integer k "
        "(the fast frequency is 1/eps; scale M so that it is)");
  check("linear_flow(a) linear_flow(b) = linear_flow(a + b)",
        relative(mod.linear_flow(0.7, mod.linear_flow(1.9, w)), mod.linear_flow(2.6, w), w_norm), 1e-10,
        "linear_flow must be the exact flow of a linear equation (a one-parameter group)");

  const HamiltonianStructure* structure = mod.hamiltonian();
  const bool hamiltonian = structure != nullptr;
  if (!hamiltonian)
    fmt::print(out_, "    {:<5} {}\n", "note",
               "the model declares no Hamiltonian structure: the checks of J, M, H1 and of energy conservation are "
               "skipped (its f is not a Hamiltonian field)");
  Vector au(n);
  if (hamiltonian) {
    Vector mw(n);
    structure->apply_M(w, mw);
    structure->apply_J(mw, au);
  } else {
    mod.apply_A(w, au);
  }
  const Real omega = mod.max_linear_frequency(), delta = 1e-5 / omega;
  const Vector derivative = (mod.linear_flow(delta, w) - mod.linear_flow(-delta, w)) / (2 * delta);
  check(hamiltonian ? "d/dtau linear_flow(tau) u at 0 = J M u" : "d/dtau linear_flow(tau) u at 0 = A u",
        relative(derivative, au, std::max<Real>(max_norm(au), omega * w_norm)), 1e-6,
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
  // The registration's flag sets the prepared data some schemes get (FD: order 4 with R).
  if (mod.has_linear_remainder())
    report(entry_.linear_remainder,
           fmt::format("{:<52} {:>9} {:>9}", "a remainder is declared (ModelEntry::linear_remainder)",
                       entry_.linear_remainder ? "true" : "false", "true"),
           "the model has a linear_remainder() but its registration's ModelEntry::linear_remainder is false",
           "set linear_remainder = true in the model's registration: schemes such as FD choose their prepared "
           "data's order by it");

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
  Real batch = 0.0;
  for (Index j = 0; j < 3; ++j) {
    Matrix f1(n, 1), d1(n, 1);
    mod.nonlinear_field(states.col(j), f1);
    mod.nonlinear_field_derivative(states.col(j), dirs.col(j), d1);
    const Real scale = max_norm(states.col(j));
    batch = std::max<Real>({batch, relative(flowed.col(j), mod.linear_flow(taus(j), states.col(j)), scale),
                      relative(field.col(j), f1.col(0), std::max<Real>(max_norm(f1.col(0)), scale)),
                      relative(dfield.col(j), d1.col(0), std::max<Real>(max_norm(d1.col(0)), scale))});
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
  Real fused_error = 0.0;
  for (Index j = 0; j < 3; ++j) {
    const Real scale = std::max<Real>(max_norm(field_back.col(j)), 1e-300);
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
    const Real imag = std::max<Real>({fl.imag().cwiseAbs().maxCoeff() / max_norm(rw),
                                  f.imag().cwiseAbs().maxCoeff() / std::max<Real>(max_norm(f.col(0)), 1e-300),
                                  d.imag().cwiseAbs().maxCoeff() / std::max<Real>(max_norm(d.col(0)), 1e-300)});
    check("real states stay real (is_complex() is false)", imag, 1e-14,
          "a real model keeps zero imaginary parts in linear_flow and nonlinear_field");
  }

  const Real h = 1e-6 * std::max<Real>(1, w_norm);
  Matrix plus(n, 1), minus(n, 1), analytic(n, 1);
  mod.nonlinear_field(w + h * z, plus);
  mod.nonlinear_field(w - h * z, minus);
  mod.nonlinear_field_derivative(w, z, analytic);
  const Vector quotient = (plus - minus).col(0) / (2 * h);
  check("nonlinear_field_derivative = difference quotient",
        relative(analytic.col(0), quotient,
                 std::max<Real>({max_norm(quotient), max_norm(plus.col(0)) / w_norm, 1e-12})),
        1e-6, "nonlinear_field_derivative(u, z) must be J Hess H1(u) z, the derivative of nonlinear_field");
}

Vector ModelChecks::reference(std::shared_ptr<const Model> m, const Vector& u0, Real tol) const {
  Assembly a = assembly(registry_.scheme("rk78", "reference.scheme"), "filtered", m->eps(), tol, 200);
  Vector y = a.reformulation->prepare(u0);
  integrate(a.bind(t_end), y, 1, {}, a.reformulation->repreparation());
  return a.reformulation->read_back(y, t_end);
}

std::vector<Real> ModelChecks::errors(const SchemeEntry& scheme, Real eps, const Vector& x_ref,
                                        const std::vector<long>& steps, int n_tau_factor, int data_order) const {
  std::vector<Real> out;
  for (const long n : steps) {
    Assembly a = assembly(scheme, "two-scale", eps, 1e-14, 1000);
    if (n_tau_factor != 1 || data_order > 0) {  // the same run on a finer tau grid, or other data
      Json config = {{"model", model_section(eps)}, {"reformulation", reformulation_section("two-scale")},
                     {"scheme", {{"name", scheme.info.name}}}};
      for (const auto& p : scheme.info.params)
        if (options_.scheme_params.contains(p.name)) config["scheme"][p.name] = options_.scheme_params[p.name];
      const ResolvedSelection resolved = resolve_selection(config, registry_);
      config["reformulation"]["n_tau"] = n_tau_factor * resolved.reformulation.params["n_tau"].get<long>();
      if (data_order > 0) config["reformulation"]["initial_data_order"] = data_order;
      for (const auto& p : scheme.info.params)
        if (p.name == "tol") config["scheme"]["tol"] = 1e-14;
      a = assemble_config(config, registry_);
    }
    const Real h = t_end / static_cast<Real>(n);
    Vector y = a.reformulation->prepare(a.u0);
    Real error = std::numeric_limits<Real>::quiet_NaN();
    try {
      integrate(a.bind(h), y, n, {}, a.reformulation->repreparation());
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

// Errors and step sizes as doubles for the order fits (logarithms: double is ample).
std::vector<double> doubles(const std::vector<Real>& values) { return {values.begin(), values.end()}; }

std::vector<Real> step_sizes(const std::vector<long>& steps) {
  std::vector<Real> h;
  for (const long n : steps) h.push_back(t_end / static_cast<Real>(n));
  return h;
}

std::string step_range(const std::vector<long>& steps) {
  return fmt::format("h = 1/{} .. 1/{}", steps.front(), steps.back());
}

}  // namespace

Real ModelChecks::field_stiffness(Real eps) const {
  const auto m = model(eps);
  const Vector u0 = m->initial_value();
  Vector z = sample_state(*m, Vector::Zero(m->dim()), 0.7);
  Real rate = 0.0;
  Matrix out(m->dim(), 1);
  for (int k = 0; k < 30; ++k) {  // the growth of z under J Hess H1(u0): its largest eigenvalue's modulus
    const Real norm = z.norm();
    if (!(norm > 0.0)) return 0.0;
    z /= norm;
    m->nonlinear_field_derivative(u0, z, out);
    rate = out.col(0).norm();
    z = out.col(0);
  }
  return rate;
}

std::string ModelChecks::diagnose(const SchemeEntry& scheme, Real eps, const Vector& x_ref) const {
  std::vector<std::string> causes;
  const Real coarsest = t_end / static_cast<Real>(options_.steps.front());
  const Real stiffness = field_stiffness(eps);
  if (coarsest * stiffness > 1.0)
    causes.push_back(fmt::format(
        "measured: J Hess H1 at u0 has size {:.3g}, so h = {:g} times it is {:.2g}: the nonlinear part is "
        "stiff and limits h to about 2 / {:.3g} = {:.2g} whatever eps. If a large linear part sits in H1, "
        "hand it over as Model::linear_remainder (docs/explanation/model-interface.md) so that it is integrated exactly",
        stiffness, coarsest, coarsest * stiffness, stiffness, 2.0 / stiffness));
  const std::vector<long> finest = {options_.steps.back()};
  const Real plain = errors(scheme, eps, x_ref, finest).front();
  const Real doubled = errors(scheme, eps, x_ref, finest, 2).front();
  if (std::isfinite(plain) && std::isfinite(doubled) && std::abs(plain - doubled) > 0.25 * std::abs(doubled))
    causes.push_back(fmt::format(
        "measured: doubling n_tau moves the error at h = 1/{} from {:.2e} to {:.2e}: the tau grid does not "
        "resolve the tau dependence; raise the model's default_n_tau (or reformulation.n_tau)",
        finest.front(), plain, doubled));
  // Prepared data of one order more: U smoother in tau, its modes that h does not resolve smaller.
  const int data = traits_of(scheme).data_order_for(entry_.linear_remainder);
  const int more = std::max(data, options_.reformulation_params.value("initial_data_order", 0)) + 1;
  if (more <= 8) {
    const Real richer = errors(scheme, eps, x_ref, finest, 1, more).front();
    if (std::isfinite(plain) && std::isfinite(richer) && std::abs(plain - richer) > 0.5 * std::abs(richer))
      causes.push_back(fmt::format(
          "measured: prepared data of order {} move the error at h = 1/{} from {:.2e} to {:.2e}: the data's "
          "order limits the scheme here (the tau modes h does not resolve carry the data's defect); the scheme "
          "declares data of order {} (reformulation.initial_data_order raises it)",
          more, finest.front(), plain, richer, data));
  }
  std::string out;
  for (const auto& c : causes) out += (out.empty() ? "" : "\n      ") + c;
  return out;
}

void ModelChecks::orders(const SchemeEntry& scheme, Real eps, const std::vector<Real>& errs) {
  // One eps: its errors and observed order, for information; the verdict is the envelope's.
  const OrderFit fit = fit_order(doubles(step_sizes(options_.steps)), doubles(errs), to_double(reference_floor(eps, fit_floor(traits_of(scheme)))));
  std::string row;
  for (const Real& e : errs) row += fmt::format(" {:>9.2e}", e);
  const std::string observed = !fit.finite ? "inf" : fit.measurable ? fmt::format("{:.2f}", fit.order) : "-";
  const std::string resonant = resonant_steps(options_.steps, eps, 2.0);
  fmt::print(out_, "    {:<5} {:<12} {:<10.4g}{} {:>6}{}\n", "", scheme.info.name, eps, row, observed,
             resonant.empty() ? "" : fmt::format("  ({} pi eps or 2 pi eps)", resonant));
}

void ModelChecks::envelope(const SchemeEntry& scheme, const std::vector<Real>& sample) {
  // Uniform order q: the maximum of the error over eps is at most C h^q. At one eps the error
  // may dip below that bound or rise in a step-size resonance, so the order is judged on the
  // maximum over the dense sample (resonances inside it), fitted above the references' floors.
  // Schemes that lose order at resonances declare it (resonant_order): the bound is theirs.
  const StepperTraits traits = traits_of(scheme);
  const int q = traits.order_with_resonances();
  const Real margin = q > 2 ? high_order_margin : order_margin;
  const Real base_floor = fit_floor(traits);
  struct Envelope {
    std::vector<Real> worst;
    std::vector<Real> at;  // the eps of each maximum
    Real largest_floor = 0.0;
  };
  const auto envelope_over = [&](const std::vector<long>& steps, const std::vector<Real>& epsilons) {
    Envelope env{std::vector<Real>(steps.size(), 0.0), std::vector<Real>(steps.size(), 0.0), 0.0};
    for (const Real& eps : epsilons) {
      const std::vector<Real> errs = errors_at(scheme, eps, steps);
      const Real floor = reference_floor(eps, base_floor);
      env.largest_floor = std::max(env.largest_floor, floor);
      for (size_t i = 0; i < steps.size(); ++i) {
        // An error below its own reference's accuracy measures that reference: left out.
        const Real e = !std::isfinite(errs[i]) ? std::numeric_limits<Real>::infinity()
                                                 : (errs[i] > floor ? errs[i] : 0.0);
        if (e > env.worst[i] || (std::isinf(e) && !std::isinf(env.worst[i]))) {
          env.worst[i] = e;
          env.at[i] = eps;
        }
      }
    }
    return env;
  };
  const Envelope env = envelope_over(options_.steps, sample);
  const OrderFit fit = fit_order(doubles(step_sizes(options_.steps)), doubles(env.worst), to_double(base_floor));
  std::string row;
  for (const Real& e : env.worst) row += e > 0.0 ? fmt::format(" {:>9.2e}", e) : fmt::format(" {:>9}", "(ref)");
  const std::string observed = !fit.finite ? "inf" : fit.measurable ? fmt::format("{:.2f}", fit.order) : "-";
  std::string declared = fmt::format(">= {} - {:g}", q, margin);
  if (q < traits.order)
    declared += q > 0 ? fmt::format(" (uniform order {} away from step-size resonances, {} in them)", traits.order, q)
                      : fmt::format(" (uniform order {} away from step-size resonances, bounded in them)", traits.order);
  if (traits.classical_order > traits.order) declared += fmt::format(" ({} at fixed eps)", traits.classical_order);
  const std::string name = fmt::format("{:<12} {:<10}", scheme.info.name, "max");
  if (fit.finite && (!fit.measurable || fit.used < 3)) {
    // Too few errors above the references' accuracy to fit: no verdict either way.
    undecidable(fmt::format("{}{} {:>6}  {}", name, row, observed, declared),
                fmt::format("{}: {} of the {} step sizes have a maximum error above this check's floor (up to "
                            "{:.1e}: the references' accuracy, at least {:.0e} for this scheme): too few to observe "
                            "an order, the check cannot decide; larger steps (--steps) or eps where the errors are "
                            "larger would",
                            scheme.info.name, fit.used, options_.steps.size(), env.largest_floor, base_floor));
    return;
  }
  bool ok = fit.finite && fit.order >= q - margin;
  if (!ok && fit.finite && sample.size() == 1 && traits.classical_order > traits.order) {
    // At one eps the error of such a scheme falls at its fixed-eps order or scatters below its
    // uniform bound (collocation between eps ~ h and eps ~ h / 100): one eps cannot refute the
    // bound, the maximum over a range of eps can.
    undecidable(fmt::format("{}{} {:>6}  {}", name, row, observed, declared),
                fmt::format("{}: at the single eps = {:g} the observed order is {}, but its error at a fixed eps "
                            "may scatter below its uniform bound ({} at fixed eps): one eps cannot decide its "
                            "uniform order; give two eps or more (--eps) for the maximum over their range",
                            scheme.info.name, sample.front(), observed, traits.classical_order));
    return;
  }
  std::string note;
  OrderFit finer;
  if (!ok && fit.finite) {
    // The steps may be pre-asymptotic for this model: if the maximum over steps four times
    // finer falls at the order, that fit counts.
    const Envelope fine = envelope_over(finer_steps_, sample);
    finer = fit_order(doubles(step_sizes(finer_steps_)), doubles(fine.worst), to_double(base_floor));
    ok = finer.finite && finer.measurable && finer.order >= q - margin;
    if (finer.measurable) note = fmt::format("  ({:.2f} over {})", finer.order, step_range(finer_steps_));
  }
  OrderFit bound;
  // The top of the bound's range that this model can show: the largest eps of its declared
  // regime (the particle model's n_tau = 16 does not resolve tau at eps = 1: 1.8e-4 whatever h).
  const std::vector<double>& regime = entry_.verification.epsilons;
  const Real top = regime.empty() ? Real(1) : std::min<Real>(1, *std::max_element(regime.begin(), regime.end()));
  if (!ok && fit.finite && sample.front() < top) {
    // Uniform order q is a bound over every eps in (0, 1]. Over a part of that range the
    // maximum may fall slower and still stay under the bound: while h ~ eps at the top of the
    // part, the errors there climb from the averaged regime's constant to the resolved one's
    // (FD on Klein-Gordon, eps <= 1e-2: from 0.03 h^2 to 0.1 h^2, under the 0.3 h^2 reached at
    // eps ~ 0.1), or at a step-size resonance stay at the data's defect, O(eps^2) < h^2 (the
    // particle model; docs/benchmarks/high-order.md). A miss is judged once more on the maximum over
    // [eps_min, top], the bound's own range as far as the model shows it, sampled as densely.
    std::vector<Real> wider = eps_sample({sample.front(), top}, options_.steps, true);
    wider.insert(wider.end(), sample.begin(), sample.end());
    wider = eps_sample(wider, {}, false);  // sorted, each eps once
    const std::array<const std::vector<long>*, 2> step_lists = {&options_.steps, &finer_steps_};
    for (const std::vector<long>* steps : step_lists) {
      const Envelope w = envelope_over(*steps, wider);
      bound = fit_order(doubles(step_sizes(*steps)), doubles(w.worst), to_double(base_floor));
      ok = bound.finite && bound.measurable && bound.used >= 3 && bound.order >= q - margin;
      if (bound.measurable)
        note += fmt::format("  ({:.2f} for eps in [{:g}, {:g}] over {}{})", bound.order, sample.back(), top, step_range(*steps),
                            ok ? ": the uniform bound holds, the range given lies below it" : "");
      if (ok || !bound.finite) break;
    }
  }
  std::string hint;
  if (!ok) {
    // Diagnose at the eps that set the maximum at the finest step.
    const Real eps = env.at.back() > 0.0 ? env.at.back() : sample.front();
    hint = diagnose(scheme, eps, references_.at(eps));
    if (hint.empty())
      hint = fit.finite ? "nothing measured stands out (the field is not stiff at u0 and n_tau resolves tau): the "
                          "two-scale schemes reach their order only on a model of the problem class; see the "
                          "interface lines above"
                        : "a run blew up or its implicit stages diverged, and the field is not stiff at u0: if the "
                          "model is strongly nonlinear in this eps range, the steps do not resolve it; try --steps "
                          "with more steps, or the eps of its regime with --eps";
  }
  report(ok, fmt::format("{}{} {:>6}  {}{}", name, row, observed, declared, note),
         fmt::format("{}: order of the maximum error over eps {}{}, expected {}", scheme.info.name,
                     fit.finite ? observed : "- (not finite)", note, declared),
         hint);
}

void ModelChecks::symmetry(const SchemeEntry& scheme, Real eps) {
  Assembly a = assembly(scheme, "two-scale", eps, 1e-14, 1000);
  const Vector start = a.reformulation->prepare(a.u0);
  Vector y = start;
  a.bind(symmetry_step).step(0.0, y);
  a.bind(-symmetry_step).step(symmetry_step, y);
  const Real back = max_norm(y - start) / max_norm(start);
  check(fmt::format("{:<8} eps = {:g}: returns to", scheme.info.name, eps), back, symmetry_limit,
        "a symmetric scheme's step h then -h returns the state; if the model is smooth this points at "
        "the scheme");
}

std::vector<Real> ModelChecks::errors_at(const SchemeEntry& scheme, Real eps, const std::vector<long>& steps) {
  auto key = std::make_tuple(scheme.info.name, eps, steps);
  auto it = errors_.find(key);
  if (it == errors_.end()) {
    add_reference(eps);
    const int factor = tau_factor(traits_of(scheme));
    it = errors_.emplace(std::move(key), errors(scheme, eps, references_.at(eps), steps, factor)).first;
  }
  return it->second;
}

std::vector<Real> eps_sample(const std::vector<Real>& epsilons, const std::vector<long>& steps, bool dense) {
  std::vector<Real> out = epsilons;
  const auto [lo, hi] = std::minmax_element(epsilons.begin(), epsilons.end());
  if (dense && *hi > *lo) {
    // 32 log-spaced over the range, and the step-size resonances h = k pi eps (k = 1, 2) of
    // every step inside it: the maximum over eps then contains each step's worst case.
    for (int j = 0; j < dense_eps_points; ++j)
      out.push_back(*lo * std::pow(*hi / *lo, static_cast<Real>(j) / (dense_eps_points - 1)));
    for (const long n : steps)
      for (int k = 1; k <= 2; ++k) {
        const Real eps = t_end / static_cast<Real>(n) / (k * std::numbers::pi);
        if (eps > *lo && eps < *hi) out.push_back(eps);
      }
  }
  std::sort(out.begin(), out.end(), std::greater<>());
  // Equal eps once (to a relative 1e-9: the given ones and the log grid's ends coincide).
  std::vector<Real> unique;
  for (const Real& e : out)
    if (unique.empty() || std::abs(unique.back() - e) > 1e-9 * e) unique.push_back(e);
  return unique;
}

Vector ModelChecks::add_reference(Real eps) {
  if (references_.count(eps)) return Vector();
  const auto m = model(eps);
  const Vector u0 = m->initial_value();
  const Vector u = reference(m, u0);
  const Vector& physical = references_[eps] = m->to_physical(u);
  const Vector coarser = m->to_physical(reference(m, u0, 10.0 * reference_tol));
  // What the check can resolve at this eps: the reference's own accuracy, and what rounding
  // the state in model variables once per step does to the physical error over the finest
  // run's steps (the charged particle at eps = 1e-6: v = (p + B q) / (2 eps) makes one ulp of
  // p 5e-11 of v, and 512 steps of it reach 1e-9).
  const Real rounding = m->rounding_floor(u) * static_cast<Real>(options_.steps.back());
  reference_accuracy_[eps] = std::max<Real>((coarser - physical).norm() / physical.norm(), rounding);
  return u;
}

void ModelChecks::convergence(const std::vector<const SchemeEntry*>& schemes,
                              const std::vector<Real>& epsilons) {
  const std::vector<Real> sample = eps_sample(epsilons, options_.steps, options_.dense_eps_sample);
  fmt::print(out_, "\n  reference: rk78 on the filtered problem, tol {:g} (its accuracy: the change from tol {:g}), T = {:g}\n",
             reference_tol, 10.0 * reference_tol, t_end);
  for (const Real& eps : sample) {
    const Vector u = add_reference(eps);
    const auto m = model(eps);
    if (u.size() == 0 || !m->has_hamiltonian_structure() ||
        std::find(epsilons.begin(), epsilons.end(), eps) == epsilons.end())
      continue;  // no energy to conserve (said in the interface checks), or an eps of the dense sample only
    const Vector u0 = m->initial_value();
    const Real h0 = m->energy(u0);
    check(fmt::format("energy H conserved at eps = {:g}", eps),
          std::abs(m->energy(u) - h0) / std::max<Real>(std::abs(h0), 1e-300), 1e-6,
          "the exact flow conserves H = <Mu, u>/(2 eps) + H1(u): nonlinear_field must be J grad H1 of the "
          "model's H1, with the M and J of linear_flow");
  }
  if (schemes.empty()) {
    fmt::print(out_, "\n  no scheme integrates the two-scale problem: no orders to check\n");
    return;
  }
  fmt::print(out_, "\n  order at T = {:g}, {}, relative error against the reference\n", t_end, step_range(options_.steps));
  if (options_.dense_eps_sample && sample.size() > epsilons.size())
    fmt::print(out_,
               "  the verdict (max) is on the maximum over {} eps from {:g} to {:g}: the given ones, {} log-spaced "
               "between them, and the step-size resonances h = k pi eps (k = 1, 2) inside; the rows per eps are "
               "for information\n",
               sample.size(), sample.back(), sample.front(), dense_eps_points);
  else if (sample.size() > 1)
    fmt::print(out_, "  the verdict (max) is on the maximum over the {} eps given\n", sample.size());
  else
    fmt::print(out_, "  the verdict (max) is on the errors at eps = {:g}; give two eps or more (--eps) for the maximum over a dense sample of their range\n",
               sample.front());
  fmt::print(out_, "    {:<5} {:<12} {:<10}", "", "scheme", "eps");
  for (const long steps : options_.steps)
    fmt::print(out_, " {:>9}", fmt::format("{}1/{}", steps == options_.steps.front() ? "h = " : "", steps));
  fmt::print(out_, " {:>6}  {}\n", "order", "expected");
  for (const auto* scheme : schemes) {
    try {
      for (const Real& eps : epsilons) orders(*scheme, eps, errors_at(*scheme, eps, options_.steps));
      envelope(*scheme, sample);
    } catch (const std::exception& e) {
      report(false, fmt::format("{:<12} {:<10} {}", scheme->info.name, "max", e.what()),
             fmt::format("{}: {}", scheme->info.name, e.what()), "");
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
    for (const Real& eps : epsilons) {
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
  for (const auto& [key, value] : entry.verification.params.items())
    if (!model_options.model_params.contains(key)) model_options.model_params[key] = value;
  ModelChecks checks(registry, entry, model_options, out);
  try {
    check_regime(model_options.epsilons, model_options.steps);
    const auto m = checks.model(model_options.epsilons.front());
    fmt::print(out, "  dim {}, {}, default n_tau {}, nonlinearity degree {}{}\n\n", m->dim(),
               m->is_complex() ? "complex" : "real", entry.default_n_tau, entry.nonlinearity_degree,
               model_options.model_params.empty() ? std::string()
                                                  : ", model parameters " + model_options.model_params.dump());
    checks.interface(model_options.epsilons.front());
    checks.convergence(schemes, std::vector<Real>(model_options.epsilons.begin(), model_options.epsilons.end()));
  } catch (const std::exception& e) {
    checks.fail(e.what());
  }
  ModelCheckReport report;
  report.count = std::max(checks.count(), static_cast<int>(checks.failures().size()));
  report.failures = checks.failures();
  report.undecidable = checks.undecided();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report.failures.empty() && report.undecidable.empty()) {
    fmt::print(out, "\n{}: all {} checks passed ({:.2g} s)\n\n", entry.info.name, report.count, report.seconds);
  } else if (report.failures.empty()) {
    fmt::print(out, "\n{}: {} checks passed, {} undecidable ({:.2g} s):\n", entry.info.name,
               report.count - static_cast<int>(report.undecidable.size()), report.undecidable.size(), report.seconds);
    for (const auto& u : report.undecidable) fmt::print(out, "  - {}\n", u);
    fmt::print(out, "\n");
  } else {
    fmt::print(out, "\n{}: {} of {} checks FAILED ({:.2g} s):\n", entry.info.name, report.failures.size(),
               report.count, report.seconds);
    for (const auto& f : report.failures) fmt::print(out, "  - {}\n", f);
    fmt::print(out, "\n");
  }
  return report;
}

}  // namespace tsi
