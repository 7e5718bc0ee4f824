#include "tsi/driver.hpp"

#include "tsi/phase.hpp"

namespace tsi {

long integrate(Stepper& stepper, Vector& y, long n_steps, const StepObserver& observer,
               StateObserver* state_observer) {
  const Real h = stepper.h();
  stepper.reset();
  if (observer && !observer(0, 0.0, y)) return 0;
  for (long n = 0; n < n_steps; ++n) {
    stepper.step(step_time(n, h), y);
    const Real t = step_time(n + 1, h);
    if (state_observer && state_observer->after_step(n + 1, t, y)) stepper.reset();
    if (observer && !observer(n + 1, t, y)) return n + 1;
  }
  return n_steps;
}

}  // namespace tsi
