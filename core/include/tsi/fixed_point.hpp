#pragma once
#include "tsi/export.hpp"
#include "tsi/params.hpp"
#include "tsi/stepper.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Settings of a fixed-point (Picard) iteration x = G(x).
struct TSI_API FixedPointOptions {
  double tol = 1e-10;  ///< stop when max|x_{k+1} - x_k| <= tol * max|x_{k+1}|
  int max_iter = 200;  ///< give up (and count a failure) after this many sweeps
};

/// The parameters every implicit scheme takes for its fixed-point iteration: tol, max_iter.
TSI_API ParamSchema fixed_point_params();
/// FixedPointOptions from resolved parameters that include fixed_point_params().
TSI_API FixedPointOptions fixed_point_options(const Params& params);

/// Solves x = G(x) by Picard iteration and keeps the statistics a run reports.
class TSI_API FixedPointSolver {
 public:
  explicit FixedPointSolver(FixedPointOptions options = {}) : options_(options) {}

  /// Iterates from the guess in x; g(x, out) writes G(x) into out. Returns true when the
  /// increment test passed, false when max_iter sweeps did not reach tol (x holds the last
  /// iterate and the failure is counted).
  template <class G>
  bool solve(Vector& x, G&& g) {
    next_.resize(x.size());
    for (int k = 1; k <= options_.max_iter; ++k) {
      g(x, next_);
      const double increment = (next_ - x).cwiseAbs().maxCoeff();
      const double scale = max_norm(next_);
      x.swap(next_);
      if (increment <= options_.tol * scale || increment == 0.0) {
        record(k, true);
        return true;
      }
    }
    record(options_.max_iter, false);
    return false;
  }

  const SolverStats& stats() const { return stats_; }
  const FixedPointOptions& options() const { return options_; }

 private:
  void record(int sweeps, bool converged);
  FixedPointOptions options_;
  SolverStats stats_;
  Vector next_;
};

}  // namespace tsi
