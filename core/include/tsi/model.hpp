#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// f_tau over one fixed set of phases (a run's tau grid), bound once per run by
/// Model::bind_tau_grid: what the model precomputes for those phases (rotation tables, phase
/// factors, transform buffers) lives here, so an evaluation neither receives the phases again
/// nor has to recognise them.
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
};

/// A quantity a model declares as conserved (or nearly) besides H, I and m: runs record its
/// relative change and plot it (NLS: the momentum; charged particle: the magnetic moment).
struct TSI_API ModelInvariant {
  std::string name;         ///< a column name: letters, digits and '_' ("P", "mu")
  std::string description;  ///< one line, for the run's files and plots
  std::function<double(const Vector& u)> value;  ///< of a state in model variables
};

/// An exact solution of a model's equation, where the model knows one (the matrix model with
/// an affine field): a reference without discretisation error (a run's reference.scheme "exact").
class TSI_API ExactSolution {
 public:
  virtual ~ExactSolution() = default;
  struct Value {
    Vector x;         ///< u(t), physical variables
    double accuracy;  ///< its estimated relative error (at least the rounding of x to double)
  };
  /// u(t) from u(0) = x0, both in physical variables, for t >= 0.
  virtual Value at(const Vector& x0, double t) const = 0;
};

/// The general class u' = (1/eps) A u + R u + f(u) (SPEC.md section 7): a model gives the
/// action of e^{A tau} (2 pi-periodic), an optional remainder R and f. Most models have the
/// Hamiltonian structure of the paper's class (eq. model), which they declare
/// (has_hamiltonian_structure, apply_M, apply_J, H1):
///     u' = J [ (1/eps) M u + R u + grad H1(u) ],   eps in (0, 1],
/// J symplectic, M self-adjoint, JM = MJ, and tau -> e^{JM tau} 2*pi-periodic. R (default: none)
/// is a linear part bounded in eps but possibly large (a spatial operator), handed over so that
/// every reformulation and scheme integrates it exactly instead of through H1 (linear_remainder).
/// A model states its operators by their action; batched calls take one state per column
/// so that the two-scale reformulation evaluates all tau points in one call.
class TSI_API Model {
 public:
  virtual ~Model() = default;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  double eps() const { return eps_; }

  /// Number of entries of u.
  virtual Index dim() const = 0;
  /// True when u is genuinely complex. A real model (false) is only ever given real states:
  /// the imaginary parts it sees, e.g. on the tau grid after a transform, are rounding, and
  /// its batched functions may compute with the real parts alone (half the work).
  virtual bool is_complex() const = 0;

  /// The exact linear flow e^{JM tau}, applied in place to column j with phase taus[j].
  virtual void linear_flow(const RealVector& taus, MatrixRef states) const = 0;
  /// J grad H1(u) for every column u of `states` (the nonlinear vector field).
  virtual void nonlinear_field(ConstMatrixRef states, MatrixRef out) const = 0;
  /// The field of the two-scale and filtered problems, f_tau(u) = e^{-JM tau} J grad H1(e^{JM tau} u),
  /// for column j at tau = taus[j]. `states` is scratch: it may be left overwritten. The default
  /// is linear_flow, nonlinear_field and linear_flow at -tau, three passes; a model may fuse
  /// them into one. `tsi check` compares the two.
  virtual void filtered_field(const RealVector& taus, MatrixRef states, MatrixRef out) const;
  /// f_tau on a run's fixed tau grid, bound once (the two-scale reformulation's hot path:
  /// after the FFTs, this is a sweep's largest cost). The default calls filtered_field with
  /// the stored phases; the shipped models return an object with their tables precomputed.
  virtual std::unique_ptr<TauGridField> bind_tau_grid(const RealVector& taus) const;
  /// True when every binding from bind_tau_grid owns its work space, so that bindings of
  /// disjoint ranges of one tau grid may evaluate at the same time on different threads (a
  /// large two-scale run then splits its grid over threads: tsi --threads). False by default:
  /// a model whose field shares state (a buffer, a lock, an interpreter) runs on one thread.
  virtual bool independent_tau_grid_bindings() const { return false; }
  /// J Hess H1(u) z for every column pair (u, z): the field's derivative at u in direction z.
  /// The default is a central difference; models with a closed form should override it.
  virtual void nonlinear_field_derivative(ConstMatrixRef states, ConstMatrixRef directions,
                                          MatrixRef out) const;
  /// True when the model declares the Hamiltonian structure (J, M, H1 with f = J grad H1,
  /// e^{A tau} = e^{JM tau}): then runs report H, I and m and `tsi check` tests it. A model of
  /// the general class u' = (1/eps) A u + R u + f(u) with f no Hamiltonian field returns false,
  /// implements apply_A instead of apply_M and apply_J, and no energy is computed or shown.
  virtual bool has_hamiltonian_structure() const { return true; }
  /// A u, the generator of the fast flow e^{A tau} (the direct problem's u' = (1/eps) A u + ...).
  /// The default is J M u; a model without the Hamiltonian structure must override it.
  virtual void apply_A(const Vector& u, Vector& out) const;
  /// M u (Hamiltonian structure; the default throws tsi::Error).
  virtual void apply_M(const Vector& u, Vector& out) const;
  /// J u (Hamiltonian structure; the default throws tsi::Error).
  virtual void apply_J(const Vector& u, Vector& out) const;
  /// The non-stiff part H1 of the Hamiltonian (Hamiltonian structure; the default throws).
  virtual double H1(const Vector& u) const;

  /// The second linear part R, by the frequencies omega_j of J R: J R multiplies coordinate j
  /// of u by i omega_j. It must commute with JM (tsi check tests it) and, for a real model, be
  /// empty (a real state cannot turn by a complex phase). Empty (the default): no remainder.
  /// Klein-Gordon's omega_k = <D>_eps - 1/eps = k^2 / (1 + sqrt(1 + eps k^2)): bounded in eps,
  /// up to (n_x/2)^2/2 in k, so that in H1 it would limit every scheme to h <~ 2 / max omega.
  virtual const RealVector& linear_remainder() const;
  bool has_linear_remainder() const { return linear_remainder().size() > 0; }
  /// u <- e^{J R t} u (coordinate j times e^{i omega_j t}); nothing without a remainder.
  void remainder_flow(double t, Vector& u) const;

  /// Oscillatory energy I(u) = <Mu, u> / (2 eps).
  virtual double oscillatory_energy(const Vector& u) const;
  /// Energy of the remainder, <R u, u> / 2 with R u = -J (i omega . u) (0 without one).
  double remainder_energy(const Vector& u) const;
  /// Mass m(u) = <u, u>.
  virtual double mass(const Vector& u) const;
  /// Energy H(u) = I(u) + <Ru, u>/2 + H1(u), exactly conserved by the flow.
  double energy(const Vector& u) const { return oscillatory_energy(u) + remainder_energy(u) + H1(u); }
  /// The model's own invariants beyond H, I and m (none by default).
  virtual std::vector<ModelInvariant> invariants() const { return {}; }

  /// The largest |lambda| over the eigenvalues i*lambda of JM (integers, since e^{JM tau} is
  /// 2*pi-periodic): e^{JM tau} oscillates with frequencies up to this. 1 by default
  /// (Henon-Heiles, charged particle); NLS: (N_x/2)^2. The filtered problem's explicit time
  /// dependence has period 2*pi*eps / max_linear_frequency() at its fastest.
  virtual double max_linear_frequency() const { return 1.0; }

  /// True when the model solves u' = J grad H1(u) exactly (splitting schemes need it).
  virtual bool has_exact_nonlinear_flow() const { return false; }
  /// u <- the exact flow of u' = J grad H1(u) over time t. The default throws tsi::Error.
  virtual void nonlinear_flow(double t, Vector& u) const;

  /// The exact solution, when the model declares one (null by default).
  virtual const ExactSolution* exact_solution() const { return nullptr; }

  /// The model's default initial value u0 (model variables).
  virtual Vector initial_value() const = 0;
  /// Number of entries of a state in physical variables (u0 in a config, u_final, errors):
  /// dim() by default. A model that carries more than the physical state (the matrix model
  /// with a time-dependent f keeps t as one more variable) returns fewer.
  virtual Index physical_dim() const { return dim(); }
  /// Model variables from a user-given initial value in physical variables (identity by default).
  virtual Vector from_physical(const Vector& x) const { return x; }
  /// The physical state errors and output are measured in (identity by default).
  virtual Vector to_physical(const Vector& u) const { return u; }
  /// The norm relative errors are measured in, on physical states (Euclidean by default).
  virtual double error_norm(const Vector& x) const { return x.norm(); }

  /// e^{JM tau} applied to one state.
  Vector linear_flow(double tau, const Vector& u) const;
  /// J grad H1(u) for one state.
  Vector nonlinear_field(const Vector& u) const;

 protected:
  explicit Model(double eps);

 private:
  double eps_;
};

}  // namespace tsi
