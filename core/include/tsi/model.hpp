#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/model_capabilities.hpp"
#include "tsi/types.hpp"

namespace tsi {

class Collective;

/// The fields on a periodic grid that a model's physical state is made of: `names` (nls: u;
/// klein-gordon-complex: u, then v), one after the other, each `shape` in C order on the box
/// [0, lengths[i]) per direction. output.fields_every writes them for ParaView (HDF5 and XDMF),
/// and each process of a split run holds a slab of every one. Empty names: not a grid's fields.
struct GridFields {
  std::vector<std::string> names;
  std::vector<Index> shape;
  std::vector<double> lengths;
};

/// The general class u' = (1/eps) A u + R u + f(t, u) (SPEC.md section 7). A model gives a
/// small required core: its size, whether it is complex, the action of e^{A tau}
/// (2 pi-periodic) and f, on batches (one state per column, so that the two-scale
/// reformulation evaluates all tau points in one call), and its initial value. R (default:
/// none) is a linear part bounded in eps but possibly large (a spatial operator), handed over
/// so that every reformulation and scheme integrates it exactly instead of through f
/// (linear_remainder).
///
/// f is nonlinear_field(u) for an autonomous f. A time-dependent f(t, u) is the declared
/// capability TimeDependentField instead (time_dependent_field()): the core then carries t as
/// one more variable (with_time_as_variable, applied where a registered model is created), so
/// that every reformulation and scheme integrates it and none sees the difference.
///
/// Everything else is a declared capability (model_capabilities.hpp), as StepperTraits are for
/// schemes: the Hamiltonian structure of the paper's class (A = J M, f = J grad H1: energies),
/// a fused tau-grid field, an exact nonlinear flow, physical variables, an exact solution,
/// and the model's own invariants. A model declares one by implementing its interface and
/// returning it from the getter (usually `return this;`).
class TSI_API Model {
 public:
  virtual ~Model() = default;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  Real eps() const { return eps_; }

  // ---- The required core ----------------------------------------------------------------

  /// Number of entries of u.
  virtual Index dim() const = 0;
  /// True when u is genuinely complex. A real model (false) is only ever given real states:
  /// the imaginary parts it sees, e.g. on the tau grid after a transform, are rounding, and
  /// its batched functions may compute with the real parts alone (half the work).
  virtual bool is_complex() const = 0;
  /// The exact linear flow e^{A tau}, applied in place to column j with phase taus[j].
  virtual void linear_flow(const RealVector& taus, MatrixRef states) const = 0;
  /// f(u) for every column u of `states` (J grad H1(u) in the Hamiltonian class). Required of
  /// every model but one that declares time_dependent_field(), which gives f(t, u) there; the
  /// default throws, naming both.
  virtual void nonlinear_field(ConstMatrixRef states, MatrixRef out) const;
  /// The model's default initial value u0 (model variables).
  virtual Vector initial_value() const = 0;

  // ---- The general class's optional parts, with defaults ---------------------------------

  /// Df(u) z for every column pair (u, z): the field's derivative at u in direction z.
  /// The default is a central difference; models with a closed form should override it.
  virtual void nonlinear_field_derivative(ConstMatrixRef states, ConstMatrixRef directions,
                                          MatrixRef out) const;
  /// A u, the generator of the fast flow e^{A tau} (the direct problem's u' = (1/eps) A u + ...).
  /// The default is J M u from the Hamiltonian structure; a model without it must override it.
  virtual void apply_A(const Vector& u, Vector& out) const;
  /// The second linear part R, by the frequencies omega_j of R: R multiplies coordinate j
  /// of u by i omega_j. It must commute with A (tsi check tests it) and, for a real model, be
  /// empty (a real state cannot turn by a complex phase). Empty (the default): no remainder.
  /// Klein-Gordon's omega_k = \<D\>_eps - 1/eps = k^2 / (1 + sqrt(1 + eps k^2)): bounded in eps,
  /// up to (n_x/2)^2/2 in k, so that in f it would limit every scheme to h <~ 2 / max omega.
  virtual const RealVector& linear_remainder() const;
  /// The largest |lambda| over the eigenvalues i*lambda of A (integers, since e^{A tau} is
  /// 2*pi-periodic): e^{A tau} oscillates with frequencies up to this. 1 by default
  /// (Henon-Heiles, charged particle); NLS: (N_x/2)^2. The filtered problem's explicit time
  /// dependence has period 2*pi*eps / max_linear_frequency() at its fastest.
  virtual double max_linear_frequency() const { return 1.0; }
  /// The model's own invariants beyond H, I and m (none by default).
  virtual std::vector<ModelInvariant> invariants() const { return {}; }
  /// The processes of a run split over them (tsi run --split: Params' context has a
  /// Collective) when the model holds only this process's share of the state, else null: its
  /// field and its own invariants then reduce over the processes, the core's inner products
  /// (I, m, the default error norm) reduce through it, and physical_shape() is the whole
  /// state's. vlasov-poisson-2d's particles, and the slabs of nls, klein-gordon and
  /// klein-gordon-complex on a 2-D or 3-D grid; the runner refuses to split any other model.
  virtual const Collective* processes() const { return nullptr; }
  bool split_across_processes() const { return processes() != nullptr; }
  /// The fields on a grid the physical state is made of (none by default).
  virtual GridFields grid_fields() const { return {}; }
  /// Physical variables as a state file keeps them for a run to start from (state.npy): a
  /// periodic model's positions brought into its box. Unchanged by default.
  virtual void canonicalize_physical(Vector& /*x*/) const {}

  // ---- Declared capabilities (model_capabilities.hpp): null where the model has none -----

  /// f(t, u), a field that depends on time, in place of nonlinear_field (the core carries t).
  virtual const TimeDependentField* time_dependent_field() const { return nullptr; }
  /// The Hamiltonian structure (J, M, H1): energies and their checks.
  virtual const HamiltonianStructure* hamiltonian() const { return nullptr; }
  /// f_tau in one pass and bound to a tau grid (else flow, field and flow back).
  virtual const FusedTauGrid* fused_tau_grid() const { return nullptr; }
  /// The exact flow of u' = f(u) (splitting schemes).
  virtual const ExactNonlinearFlow* exact_nonlinear_flow() const { return nullptr; }
  /// Physical variables other than the model's own.
  virtual const PhysicalVariables* physical_variables() const { return nullptr; }
  /// The exact solution of the whole equation.
  virtual const ExactSolution* exact_solution() const { return nullptr; }
  /// The second-order form x'' = -Omega^2 x + g(x) (trigonometric integrators).
  virtual const SecondOrderForm* second_order_form() const { return nullptr; }
  /// The Lorentz-force form x' = v, v' = v x B(x) + E(x) (Boris schemes).
  virtual const ChargedParticleForm* charged_particle_form() const { return nullptr; }

  // ---- What the rest of tsi uses, built on the above (not virtual) -----------------------

  bool has_time_dependent_field() const { return time_dependent_field() != nullptr; }
  bool has_hamiltonian_structure() const { return hamiltonian() != nullptr; }
  bool has_exact_nonlinear_flow() const { return exact_nonlinear_flow() != nullptr; }
  bool has_second_order_form() const { return second_order_form() != nullptr; }
  bool has_charged_particle_form() const { return charged_particle_form() != nullptr; }
  bool has_linear_remainder() const { return linear_remainder().size() > 0; }

  /// e^{A tau} applied to one state.
  Vector linear_flow(Real tau, const Vector& u) const;
  /// The same in u's own storage (a read-back of 10^7 numbers: no copy).
  Vector linear_flow(Real tau, Vector&& u) const;
  /// f(u) for one state.
  Vector nonlinear_field(const Vector& u) const;
  /// f_tau(u) = e^{-A tau} f(e^{A tau} u) for column j at tau = taus[j]; `states` is scratch.
  /// The fused capability's, else linear_flow, nonlinear_field and linear_flow at -tau.
  void filtered_field(const RealVector& taus, MatrixRef states, MatrixRef out) const;
  /// f_tau on a run's fixed tau grid: the fused capability's binding, else filtered_field
  /// with the stored phases.
  std::unique_ptr<TauGridField> bind_tau_grid(const RealVector& taus) const;
  /// True when bindings of one tau grid may evaluate on different threads.
  bool independent_tau_grid_bindings() const;
  /// u <- the exact flow of u' = f(u) over time t (tsi::Error without the capability).
  void nonlinear_flow(Real t, Vector& u) const;
  /// u <- e^{R t} u (coordinate j times e^{i omega_j t}); nothing without a remainder.
  void remainder_flow(Real t, Vector& u) const;

  /// Oscillatory energy I(u) = <Mu, u> / (2 eps) (tsi::Error without the Hamiltonian structure).
  Real oscillatory_energy(const Vector& u) const;
  /// Energy of the remainder, <R' u, u> / 2 with R' u = -J (i omega . u) (0 without one).
  Real remainder_energy(const Vector& u) const;
  /// Mass m(u) = <u, u>.
  Real mass(const Vector& u) const;
  /// Energy H(u) = I(u) + <R'u, u>/2 + H1(u), exactly conserved by the flow.
  Real energy(const Vector& u) const;

  /// Entries of a physical state (dim() without physical variables).
  Index physical_dim() const;
  /// Model variables from a physical state (identity without physical variables).
  Vector from_physical(const Vector& x) const;
  /// The physical state of u (identity without physical variables).
  Vector to_physical(const Vector& u) const;
  /// The norm of relative errors, on physical states (Euclidean without physical variables).
  Real error_norm(const Vector& x) const;
  /// The shape of a physical state in C order (u_final.npy's): (physical_dim()) by default.
  std::vector<Index> physical_shape() const;
  /// The relative error in physical variables that rounding the model state u alone causes
  /// (one ulp per entry, alternating in sign): no solution held in model variables is more
  /// accurate. Large where to_physical is ill-conditioned (the charged particle's
  /// v = (p + B q) / (2 eps)).
  Real rounding_floor(const Vector& u) const;

 protected:
  explicit Model(Real eps);
  /// A number summed over processes() (itself on one process): a split model's sums of its
  /// share (H1, its invariants, its error norm) made whole.
  Real summed(Real local) const;

 private:
  Real eps_;
};

}  // namespace tsi
