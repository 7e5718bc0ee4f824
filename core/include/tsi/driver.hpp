#pragma once
#include "tsi/export.hpp"
#include "tsi/observer.hpp"
#include "tsi/stepper.hpp"

namespace tsi {

/// The time loop, apart from the steppers (as Boost.Odeint's integrate_const): n_steps
/// steps of the bound stepper's size h from t = 0 on its problem, with t_n = n h computed,
/// never accumulated. After each step the state observer (the reformulation's
/// re-preparation, or none) may rebuild the state, and then the step observer reads it.
/// Returns the number of steps taken.
TSI_API long integrate(Stepper& stepper, Vector& y, long n_steps, const StepObserver& observer,
                       StateObserver* state_observer = nullptr);

}  // namespace tsi
