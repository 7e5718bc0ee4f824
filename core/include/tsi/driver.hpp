#pragma once
#include <functional>

#include "tsi/export.hpp"
#include "tsi/problem.hpp"
#include "tsi/stepper.hpp"

namespace tsi {

/// Called at t_0 and after every step with the step index, t_n = n h and the state.
/// Returning false stops the integration after that step.
using StepObserver = std::function<bool(long n, double t, const Vector& y)>;

/// The time loop, apart from the steppers (as Boost.Odeint's integrate_const): n_steps
/// steps of the bound stepper's size h from t = 0 on its problem, with t_n = n h computed,
/// never accumulated. Returns the number of steps taken.
TSI_API long integrate(Stepper& stepper, Vector& y, long n_steps, const StepObserver& observer);

}  // namespace tsi
