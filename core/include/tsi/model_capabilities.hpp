#pragma once
// What a model may declare beyond the required core of tsi::Model (model.hpp). Each is an
// interface a model implements (usually by inheriting it) and hands out from its getter on
// Model (time_dependent_field(), hamiltonian(), fused_tau_grid(), exact_nonlinear_flow(),
// physical_variables(), exact_solution()); a null getter means the model does not have it,
// and the parts of tsi that need it say so (a splitting scheme needs the exact nonlinear flow,
// energies need the Hamiltonian structure, `tsi check` skips what a model does not declare).
#include <functional>
#include <memory>
#include <vector>
#include <string>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// A field f(t, u) that depends on time, the general class's u' = (1/eps) A u + f(t, u): a model
/// that declares it gives f here, and tsi carries t as one more variable (t' = 1, untouched by
/// e^{A tau}: HOODESolver.jl's way, SPEC.md section 7) where the model is created
/// (with_time_as_variable, time_as_variable.hpp), so that every reformulation and scheme
/// integrates it. Its initial value, physical variables, u_final, errors, invariants and exact
/// solution stay the model's own, without t; runs start at t = 0. Such a model need not override
/// Model::nonlinear_field, and declares no capability that takes no t (hamiltonian(),
/// fused_tau_grid(), exact_nonlinear_flow(): refused when the model is created).
class TSI_API TimeDependentField {
 public:
  virtual ~TimeDependentField() = default;
  /// out.col(j) = f(t(j), states.col(j)) for every column, each state with its own time (a
  /// batch may hold states of different times). `out` has the shape of `states`, is not
  /// zeroed and never aliases it.
  virtual void nonlinear_field_at(const RealVector& t, ConstMatrixRef states, MatrixRef out) const = 0;
  /// out.col(j) = D_u f(t(j), u_j) z_j, the derivative in u at fixed time (tsi adds the
  /// derivative in t itself). The default is a central difference in u; a closed form is better.
  virtual void nonlinear_field_derivative_at(const RealVector& t, ConstMatrixRef states, ConstMatrixRef directions,
                                             MatrixRef out) const;
};

/// f_tau over one fixed set of phases (a run's tau grid), bound once per run by
/// FusedTauGrid::bind_tau_grid: what the model precomputes for those phases (rotation tables,
/// phase factors, transform buffers) lives here, so an evaluation neither receives the phases
/// again nor has to recognise them.
class TSI_API TauGridField {
 public:
  virtual ~TauGridField() = default;
  /// out.col(j) = f_{tau_j}(states.col(j)) for the bound phases tau_j. `states` is scratch:
  /// it may be left overwritten.
  virtual void evaluate(MatrixRef states, MatrixRef out) = 0;
  /// True when the binding also evaluates real grids (evaluate_real): a real model's
  /// two-scale problem keeps its tau grid real (half the memory and work of a complex one).
  /// False by default: the reformulation then copies the real grid through complex buffers.
  virtual bool evaluates_real() const { return false; }
  /// evaluate on real grid values (real models that declare evaluates_real; the default throws).
  virtual void evaluate_real(RealMatrixRef states, RealMatrixRef out);
  /// True when evaluate(states, out) (and evaluate_real) may be called with out and states the
  /// same matrix (each column read before it is written): the two-scale problem then evaluates
  /// in the caller's vector and holds no grid buffer of its own.
  virtual bool in_place() const { return false; }
  /// True when the binding's field also depends on the two-scale state's value on the diagonal,
  /// U(t, t/eps) (the solution's own filtered value at the evaluation's time): a field frozen
  /// along tau, as the UA-PIC codes' electric field solved once per evaluation from the
  /// particles' positions at t. The reformulation then calls set_diagonal before each evaluation.
  virtual bool needs_diagonal() const { return false; }
  /// The diagonal value (dim entries) for the evaluation that follows; it stays valid until
  /// that evaluation returns.
  virtual void set_diagonal(const Vector& /*diagonal*/) {}

  /// Rows per group of a field that, once its diagonal is set, is independent across groups of
  /// rows (each particle's f depends on its own coordinates and the frozen field only); 0, the
  /// default, when it is not. The two-scale problem of a real model then transforms and
  /// evaluates its tau grid a block of rows at a time, in cache (evaluate_rows_real), instead of
  /// streaming the whole grid through memory between the transforms and the field.
  virtual Index independent_row_group() const { return 0; }
  /// Readies the field of the diagonal set last for evaluate_rows_real: called on one thread,
  /// before the blocks.
  virtual void prepare_rows() {}
  /// f in place on a block of real grid values (values.rows() rows, whole groups, all columns;
  /// row 0 is row first_row of the grid). Called from several threads at once on disjoint
  /// blocks after prepare_rows, hence const. The default throws.
  virtual void evaluate_rows_real(RealMatrixRef values, Index first_row) const;
};

/// The filtered field f_tau(u) = e^{-A tau} f(e^{A tau} u) in one pass instead of the three
/// (flow, field, flow back) a model without it gets: the two-scale reformulation's hot path.
/// `tsi check` compares both routes with the definition.
class TSI_API FusedTauGrid {
 public:
  virtual ~FusedTauGrid() = default;
  /// f_tau on a run's fixed tau grid, bound once (tables precomputed for those phases).
  virtual std::unique_ptr<TauGridField> bind_tau_grid(const RealVector& taus) const = 0;
  /// f_tau for column j at taus[j], phases given per call (the filtered problem, whose phase
  /// moves with t). The default binds the phases and evaluates once.
  virtual void filtered_field(const RealVector& taus, MatrixRef states, MatrixRef out) const;
  /// True when every binding owns its work space, so that bindings of disjoint ranges of one
  /// tau grid may evaluate at the same time on different threads (tsi --threads). False by
  /// default: a model whose field shares state (a buffer, a lock, an interpreter) runs on one
  /// thread.
  virtual bool independent_tau_grid_bindings() const { return false; }
};

/// A binding that calls fused.filtered_field with the stored phases: bind_tau_grid for a model
/// whose fused field takes its phases per call and precomputes nothing.
TSI_API std::unique_ptr<TauGridField> bind_filtered_field(const FusedTauGrid& fused, const RealVector& taus);

/// The Hamiltonian structure of the paper's class (eq. model): A = J M and f = J grad H1, so
///     u' = J [ (1/eps) M u + R u + grad H1(u) ],
/// J symplectic, M self-adjoint, JM = MJ. Where a model declares it, runs report the energy
/// H, the oscillatory energy I and the mass m, and `tsi check` tests the structure.
class TSI_API HamiltonianStructure {
 public:
  virtual ~HamiltonianStructure() = default;
  /// out = M u.
  virtual void apply_M(const Vector& u, Vector& out) const = 0;
  /// out = J u.
  virtual void apply_J(const Vector& u, Vector& out) const = 0;
  /// The non-stiff part H1 of the Hamiltonian.
  virtual Real H1(const Vector& u) const = 0;
};

/// The exact flow of u' = f(u) alone (splitting schemes and the direct problem's exact
/// sub-flows need it).
class TSI_API ExactNonlinearFlow {
 public:
  virtual ~ExactNonlinearFlow() = default;
  /// u <- the exact flow of u' = f(u) over time t.
  virtual void nonlinear_flow(Real t, Vector& u) const = 0;
};

/// The second-order form x'' = -Omega^2 x + g(x) of a model whose state is positions x and
/// velocities x' (Hamiltonian with a quadratic kinetic energy and a stiff quadratic potential
/// diagonal in x): what trigonometric (Gautschi-type) integrators take (SPEC.md section 8).
/// Omega is diagonal with entries >= 0 and holds the model's 1/eps (FPUT's stiff springs: omega
/// = 1/eps on the elongations, 0 on the centres).
class TSI_API SecondOrderForm {
 public:
  virtual ~SecondOrderForm() = default;
  /// n, the number of positions.
  virtual Index positions() const = 0;
  /// Omega's diagonal (n entries, >= 0).
  virtual RealVector frequencies() const = 0;
  /// The positions and velocities (n each) of a model state u.
  virtual void to_second_order(const Vector& u, RealVector& x, RealVector& v) const = 0;
  /// The model state of positions x and velocities v.
  virtual void from_second_order(const RealVector& x, const RealVector& v, Vector& u) const = 0;
  /// g(x) (n entries).
  virtual void force(const RealVector& x, RealVector& g) const = 0;
};

/// A position or field vector of three-dimensional space.
using RealVector3 = Eigen::Matrix<Real, 3, 1>;

/// The Lorentz-force form of a charged-particle model,
///     x' = v,   v' = v x B(x) + E(x),   x, v in R^3,
/// with B holding the model's 1/eps (B = B0/eps + B1(x)): what the Boris schemes take
/// (SPEC.md section 8). A planar model (cpd) embeds its plane as x_3 = v_3 = 0, B along e_3
/// and E in the plane.
class TSI_API ChargedParticleForm {
 public:
  virtual ~ChargedParticleForm() = default;
  /// The position and velocity of a model state u.
  virtual void to_particle(const Vector& u, RealVector3& x, RealVector3& v) const = 0;
  /// The model state of position x and velocity v.
  virtual void from_particle(const RealVector3& x, const RealVector3& v, Vector& u) const = 0;
  /// The magnetic field B(x) (with its 1/eps) and the electric field E(x) at x.
  virtual void fields(const RealVector3& x, RealVector3& B, RealVector3& E) const = 0;
};

/// Physical variables different from the model's own (an initial value in a config, u_final,
/// errors and their norm): without it they are the model's variables, errors in the Euclidean
/// norm.
class TSI_API PhysicalVariables {
 public:
  virtual ~PhysicalVariables() = default;
  /// Entries of a physical state (a model that carries more, as the matrix model with a
  /// time-dependent f carries t, returns fewer than dim()).
  virtual Index physical_dim() const = 0;
  /// Model variables from a physical state.
  virtual Vector from_physical(const Vector& x) const = 0;
  /// The physical state of model variables u.
  virtual Vector to_physical(const Vector& u) const = 0;
  /// The norm relative errors are measured in, on physical states (Euclidean by default).
  virtual Real error_norm(const Vector& x) const { return x.norm(); }
  /// The shape of a physical state as an array in C order, the shape of u_final.npy (a grid's
  /// (n_x, n_y, n_z)); by default flat, (physical_dim()).
  virtual std::vector<Index> physical_shape() const { return {physical_dim()}; }
};

/// A quantity a model declares as conserved (or nearly) besides H, I and m: runs record its
/// relative change and plot it (NLS: the momentum; charged particle: the magnetic moment). Or,
/// with conserved = false, a quantity recorded as it goes (its values only).
struct TSI_API ModelInvariant {
  std::string name;         ///< a column name: letters, digits and '_' ("P", "mu")
  std::string description;  ///< one line, for the run's files and plots
  std::function<Real(const Vector& u)> value;  ///< of a state in model variables
  /// false: a diagnostic recorded beside the invariants (the particle-in-cell electric energy):
  /// its value in each row and its range, no change tracked.
  bool conserved = true;
};

/// An exact solution of a model's equation, where the model knows one (the matrix model with
/// an affine field): a reference without discretisation error (a run's reference.scheme "exact").
class TSI_API ExactSolution {
 public:
  virtual ~ExactSolution() = default;
  struct Value {
    Vector x;         ///< u(t), physical variables
    Real accuracy;  ///< its estimated relative error (at least the rounding of x to double)
  };
  /// u(t) from u(0) = x0, both in physical variables, for t >= 0.
  virtual Value at(const Vector& x0, Real t) const = 0;
};

}  // namespace tsi
