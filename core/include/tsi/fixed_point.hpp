#pragma once
#include <memory>
#include <string>

#include "tsi/collective.hpp"
#include "tsi/export.hpp"
#include "tsi/function_ref.hpp"
#include "tsi/params.hpp"
#include "tsi/stepper.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Settings of the fixed-point iteration x = G(x) of an implicit stage.
struct TSI_API FixedPointOptions {
  std::string method = "picard";  ///< "picard" or "anderson"
  double tol = 1e-10;              ///< stop when max|G(x) - x| <= tol * max|G(x)|
  int max_iter = 200;              ///< sweeps (evaluations of G) before giving up
  int anderson_depth = 3;          ///< Anderson: how many previous residuals to mix
  std::string on_failure = "warn"; ///< "warn": count and continue; "stop": throw tsi::Error
  std::string guess = "previous";  ///< starting guess of the scheme: "previous" step's stage, or "linear" part only
  /// The processes a split state lies on (Params' context): the convergence test and Anderson's
  /// inner products are taken over all of them, so every process sweeps as often. Null: one.
  const Collective* collective = nullptr;
};

/// The parameters every implicit scheme takes for its fixed-point iteration.
TSI_API ParamSchema fixed_point_params();
/// FixedPointOptions from resolved parameters that include fixed_point_params().
TSI_API FixedPointOptions fixed_point_options(const Params& params);

/// The right-hand side of x = G(x): g(x, out) writes G(x) into out.
using FixedPointMap = FunctionRef<void(const Vector&, Vector&)>;

/// Solves x = G(x) from a starting guess and keeps the statistics a run reports
/// (a swappable part, as SUNDIALS' nonlinear solver objects). Allocates only on the first
/// solve of a given size.
class TSI_API FixedPointSolver {
 public:
  explicit FixedPointSolver(FixedPointOptions options);
  virtual ~FixedPointSolver() = default;

  /// Iterates from the guess in x. Returns true when the increment test passed; on failure
  /// x holds the last iterate, the failure is counted, and with on_failure = "stop" a
  /// tsi::Error is thrown.
  bool solve(Vector& x, FixedPointMap g);

  const SolverStats& stats() const { return stats_; }
  const FixedPointOptions& options() const { return options_; }
  /// Work vectors of the iterate's size the solver keeps (Picard 1, Anderson 4 + 2 depth).
  virtual double state_vectors() const = 0;

 protected:
  /// One solve: returns the number of sweeps, or -1 when max_iter did not reach tol.
  virtual int iterate(Vector& x, FixedPointMap g, Real& increment) = 0;
  /// The relative increment from x to next, over every process of a split state.
  Real increment(const Vector& next, const Vector& x) const;

 private:
  FixedPointOptions options_;
  SolverStats stats_;
};

/// Where an implicit stage's iteration starts (a part of its own, apart from the scheme and
/// the solver): the previous step's stage values (guess "previous", an O(h^2) predictor)
/// once a step has been taken since the last reset, else the linear part alone.
class TSI_API StageGuess {
 public:
  explicit StageGuess(const FixedPointOptions& options) : use_previous_(options.guess == "previous") {}
  /// True when the scheme should start from its previous stage values.
  bool from_previous() const { return use_previous_ && have_previous_; }
  /// A step has stored its stage values.
  void stored() { have_previous_ = true; }
  /// A new trajectory: no previous stage values.
  void reset() { have_previous_ = false; }

 private:
  bool use_previous_;
  bool have_previous_ = false;
};

/// The work vectors of the iterate's size the solver the options ask for keeps
/// (FixedPointSolver::state_vectors, known before it is made).
TSI_API double fixed_point_state_vectors(const FixedPointOptions& options);

/// The solver the options ask for (Picard or Anderson).
TSI_API std::unique_ptr<FixedPointSolver> make_fixed_point_solver(const FixedPointOptions& options);

}  // namespace tsi
