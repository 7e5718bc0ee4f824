#pragma once
#include <memory>

#include "tsi/export.hpp"
#include "tsi/model.hpp"

namespace tsi {

/// A model whose f depends on time (it declares Model::time_dependent_field()) as one that every
/// reformulation and scheme integrates: t carried as one more variable (HOODESolver.jl's way,
/// SPEC.md section 7),
///     d/dt (u, s) = (1/eps) diag(A, 0) (u, s) + (f(s, u), 1),   s(0) = 0,
/// so that the returned model has dim() = model's + 1, e^{A tau} leaves s alone, f's last entry
/// is 1, and its physical variables (u0, u_final, errors, the exact solution) and invariants are
/// the model's own, without s. Runs start at t = 0. The Registry applies it to every model a
/// registered entry creates; a model without the capability is returned unchanged.
/// Refuses (tsi::Error) a model that also declares a capability that takes no t (hamiltonian(),
/// fused_tau_grid(), exact_nonlinear_flow()).
TSI_API std::unique_ptr<Model> with_time_as_variable(std::unique_ptr<Model> model);

}  // namespace tsi
