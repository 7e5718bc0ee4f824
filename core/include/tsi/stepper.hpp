#pragma once
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/problem.hpp"

namespace tsi {

/// What a scheme is and what it needs from the problem; declared at registration so the
/// registry can refuse incompatible pairs before anything runs.
struct TSI_API StepperTraits {
  int order = 2;                         ///< order uniform in eps (on two-scale data)
  /// The order at a fixed eps as h -> 0 when it exceeds `order` (0: equal): a scheme whose
  /// error bound C h^order holds uniformly while at a given eps it falls faster or erratically
  /// below it (a composition, exponential collocation); its order is checked on the maximum
  /// of the errors over eps.
  int classical_order = 0;
  bool symmetric = false;                ///< step(h) then step(-h) returns the start
  bool implicit = false;                 ///< has implicit stages (fixed-point iteration)
  bool multistep = false;                ///< needs a start-up; reset() starts a new trajectory
  bool adaptive = false;                 ///< chooses its own substeps inside step()
  bool needs_diagonal_linear_part = false;  ///< uses Problem::linear_multipliers (exponential schemes)
  bool needs_exact_flows = false;        ///< uses Problem::linear_flow and nonlinear_flow (splitting)
  int initial_data_order = 1;            ///< two-scale prepared data needed for uniform order
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
};

/// Advances a Problem by one step.
class TSI_API Stepper {
 public:
  virtual ~Stepper() = default;
  /// Forget any history: the next step() starts a new trajectory.
  virtual void reset() {}
  /// Advance y from t to t + h in place (h < 0 steps backwards).
  virtual void step(Problem& problem, double t, double h, Vector& y) = 0;
  /// Statistics of the implicit stages so far.
  virtual SolverStats stats() const { return {}; }
};

}  // namespace tsi
