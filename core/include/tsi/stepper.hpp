#pragma once
#include <algorithm>
#include <concepts>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/problem.hpp"

namespace tsi {

/// What a scheme is and what it needs from the problem; declared at registration so the
/// registry can refuse incompatible pairs before anything runs.
struct TSI_API StepperTraits {
  /// The order the maximum of the error over eps, step-size resonances included, falls at.
  int order_with_resonances() const { return resonant_order >= 0 ? std::min(resonant_order, order) : order; }
  int order = 2;                         ///< order uniform in eps (on two-scale data)
  /// The order at a fixed eps as h -> 0 when it exceeds `order` (0: equal): a scheme whose
  /// error bound C h^order holds uniformly while at a given eps it falls faster or erratically
  /// below it (a composition, exponential collocation); its order is checked on the maximum
  /// of the errors over eps.
  int classical_order = 0;
  /// The uniform order including step-size resonances h ~ k pi eps, when it is below `order`
  /// (-1: equal; 0: bounded, no order): SE1 and SE2 reach `order` uniformly only under a
  /// numerical non-resonance condition (the paper's, section 4); at h = k pi eps their error
  /// falls at order 1 (docs/explanation/high-order.md). `tsi check` judges the maximum over eps,
  /// resonances included, by it.
  int resonant_order = -1;
  bool symmetric = false;                ///< step(h) then step(-h) returns the start
  bool implicit = false;                 ///< has implicit stages (fixed-point iteration)
  bool multistep = false;                ///< needs a start-up; reset() starts a new trajectory
  bool adaptive = false;                 ///< chooses its own substeps inside step()
  bool needs_diagonal_linear_part = false;  ///< uses Problem::linear_multipliers (exponential schemes)
  bool needs_exact_flows = false;        ///< uses Problem::linear_flow and nonlinear_flow (splitting)
  bool needs_second_order_form = false;  ///< uses Problem::second_order (trigonometric integrators)
  bool needs_charged_particle_form = false;  ///< uses Problem::charged_particle (Boris schemes)
  int initial_data_order = 1;            ///< two-scale prepared data needed for uniform order
  /// The prepared data needed instead on a model with a linear remainder R (ModelEntry::
  /// linear_remainder), when more (0: initial_data_order). The data's defect grows with
  /// eps |R|; a scheme that turns it by a wrong phase (FD's Crank-Nicolson fraction) needs
  /// it smaller (Klein-Gordon: docs/explanation/high-order.md).
  int remainder_data_order = 0;
  /// The prepared data this scheme needs on a model with (true) or without a remainder.
  int data_order_for(bool linear_remainder) const {
    return linear_remainder ? std::max(initial_data_order, remainder_data_order) : initial_data_order;
  }
  std::vector<std::string> reformulations;  ///< the reformulations it can integrate
};

/// Counters of the implicit stages (all zero for explicit schemes).
struct TSI_API SolverStats {
  long solves = 0;          ///< implicit stages solved
  long iterations = 0;      ///< fixed-point sweeps in total
  long iterations_max = 0;  ///< most sweeps one stage took
  long not_converged = 0;   ///< stages that hit max_iter without reaching tol
  std::vector<long> sweeps_histogram;  ///< entry k: stages that took k sweeps
  double iterations_mean() const { return solves ? double(iterations) / double(solves) : 0.0; }
  /// Adds another solver's counters (a composition's parts).
  void add(const SolverStats& other) {
    solves += other.solves;
    iterations += other.iterations;
    iterations_max = std::max(iterations_max, other.iterations_max);
    not_converged += other.not_converged;
    if (sweeps_histogram.size() < other.sweeps_histogram.size()) sweeps_histogram.resize(other.sweeps_histogram.size(), 0);
    for (size_t k = 0; k < other.sweeps_histogram.size(); ++k) sweeps_histogram[k] += other.sweeps_histogram[k];
  }
};

/// A scheme bound to one problem and one step size h (OrdinaryDiffEq's alg_cache,
/// GeometricIntegrators' integrator): it owns its coefficients and work space, allocated from
/// the problem's prototype state when it is bound, so a step depends on nothing it was given
/// before but a multistep history. Another problem or another h is another binding
/// (Scheme::bind); nothing is cached by key.
class TSI_API Stepper {
 public:
  Stepper(Problem& problem, Real h) : problem_(problem), h_(h) {}
  virtual ~Stepper() = default;
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  Problem& problem() const { return problem_; }
  /// The step size it was bound to (negative: it steps backwards).
  Real h() const { return h_; }
  /// Forget any history: the next step() starts a new trajectory.
  virtual void reset() {}
  /// Advance y from t to t + h() in place.
  virtual void step(Real t, Vector& y) = 0;
  /// Statistics of the implicit stages so far.
  virtual SolverStats stats() const { return {}; }
  /// Vectors of the problem's size the binding holds (coefficients, stages, history, its
  /// solver's work space), the state excluded: its memory is this times the state's.
  virtual double state_vectors() const = 0;

 protected:
  Problem& problem_;
  Real h_;
};

/// A scheme: the method with its resolved parameters, apart from any problem. bind() makes
/// the Stepper for one problem and step size; a composition binds its base once per substep
/// length, from one Scheme.
class TSI_API Scheme {
 public:
  /// What state_vectors(layout) answers for a scheme that does not say: an allowance.
  static constexpr double unknown_state_vectors = 16.0;

  virtual ~Scheme() = default;
  virtual std::unique_ptr<Stepper> bind(Problem& problem, Real h) const = 0;
  /// The vectors of the state's size a binding to a problem of this layout will hold (what its
  /// Stepper's state_vectors() reports), known before the problem is built or anything of its
  /// size allocated: a run's footprint check uses it.
  virtual double state_vectors(const ProblemLayout& /*layout*/) const { return unknown_state_vectors; }
};

/// The common scheme: its steppers are Bound(problem, h, settings), and their memory is
/// Bound::state_vectors_for(layout, settings) where Bound declares it (static).
template <class Bound, class Settings>
class BindingScheme final : public Scheme {
 public:
  explicit BindingScheme(Settings settings) : settings_(std::move(settings)) {}
  std::unique_ptr<Stepper> bind(Problem& problem, Real h) const override {
    return std::make_unique<Bound>(problem, h, settings_);
  }
  double state_vectors(const ProblemLayout& layout) const override {
    if constexpr (requires { { Bound::state_vectors_for(layout, settings_) } -> std::convertible_to<double>; })
      return Bound::state_vectors_for(layout, settings_);
    else
      return Scheme::state_vectors(layout);
  }

 private:
  Settings settings_;
};

/// A BindingScheme<Bound, Settings> as a Scheme (a registry entry's create).
template <class Bound, class Settings>
std::unique_ptr<Scheme> make_scheme(Settings settings) {
  return std::make_unique<BindingScheme<Bound, Settings>>(std::move(settings));
}

}  // namespace tsi
