#pragma once
#include <functional>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Reads the state at t_0 and after every step, with the step index and t_n = n h (the run
/// recorder, dense output, progress). Returning false stops the integration after that step.
using StepObserver = std::function<bool(long n, Real t, const Vector& y)>;

/// An observer that may rebuild the state after a step without changing the solution it
/// represents: the two-scale re-preparation (Reformulation::repreparation). It runs before
/// the step observer, which then sees the rebuilt state.
class TSI_API StateObserver {
 public:
  virtual ~StateObserver() = default;
  /// After step n (state y at t_n): true when it rebuilt y. The driver then restarts the
  /// stepper (Stepper::reset), as a multistep scheme must.
  virtual bool after_step(long n, Real t, Vector& y) = 0;
};

}  // namespace tsi
