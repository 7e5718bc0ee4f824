#include "tsi/driver.hpp"

#include "tsi/phase.hpp"

namespace tsi {

long integrate(Problem& problem, Stepper& stepper, Vector& y, double h, long n_steps,
               const StepObserver& observer) {
  stepper.reset();
  if (observer && !observer(0, 0.0, y)) return 0;
  for (long n = 0; n < n_steps; ++n) {
    stepper.step(problem, step_time(n, h), h, y);
    if (problem.between_steps(n + 1, step_time(n + 1, h), y)) stepper.reset();
    if (observer && !observer(n + 1, step_time(n + 1, h), y)) return n + 1;
  }
  return n_steps;
}

}  // namespace tsi
