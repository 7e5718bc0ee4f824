#include "tsi/driver.hpp"

#include "tsi/phase.hpp"

namespace tsi {

long integrate(Stepper& stepper, Vector& y, long n_steps, const StepObserver& observer) {
  Problem& problem = stepper.problem();
  const double h = stepper.h();
  stepper.reset();
  if (observer && !observer(0, 0.0, y)) return 0;
  for (long n = 0; n < n_steps; ++n) {
    stepper.step(step_time(n, h), y);
    if (problem.between_steps(n + 1, step_time(n + 1, h), y)) stepper.reset();
    if (observer && !observer(n + 1, step_time(n + 1, h), y)) return n + 1;
  }
  return n_steps;
}

}  // namespace tsi
