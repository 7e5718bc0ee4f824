#pragma once
#include "tsi/diagonal.hpp"
#include "tsi/export.hpp"
#include "tsi/model_capabilities.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// What the memory of a binding depends on, known before the problem is built: a scheme's
/// vectors of the state's size (Scheme::state_vectors) follow from it.
struct TSI_API ProblemLayout {
  Index size = 0;             ///< unknowns (complex values of the state)
  Index diagonal_values = 0;  ///< values one diagonal coefficient stores (Diagonal::values)
  /// A diagonal coefficient's memory in vectors of the state's size.
  double diagonal_fraction() const {
    return size > 0 ? static_cast<double>(diagonal_values) / static_cast<double>(size) : 1.0;
  }
  /// Unknowns up to which an implicit scheme keeps its stage's base e^{cz} y (one vector more,
  /// at most 1 MB): each sweep then adds to it instead of forming it again, a stream fewer per
  /// sweep (3% of an SE1 step at NLS n_x = 16, n_tau = 256). Larger states form it in each
  /// sweep's pass, the same products rounded the same way, and save the vector.
  static constexpr Index max_stored_base = Index{1} << 16;
  bool stores_stage_bases() const { return size <= max_stored_base; }
};

/// A problem in the second-order form x'' = -Omega^2 x + g(x) (the direct problem of a model
/// that declares tsi::SecondOrderForm): its state read as positions and velocities, and g.
class TSI_API SecondOrderProblem {
 public:
  virtual ~SecondOrderProblem() = default;
  virtual Index positions() const = 0;
  /// Omega's diagonal (positions() entries, >= 0).
  virtual const RealVector& frequencies() const = 0;
  /// The positions and velocities of a state y of the problem.
  virtual void split(const Vector& y, RealVector& x, RealVector& v) = 0;
  /// The state y of positions x and velocities v.
  virtual void join(const RealVector& x, const RealVector& v, Vector& y) = 0;
  /// g(x); one evaluation of the problem's N (its work measure).
  virtual void force(const RealVector& x, RealVector& g) = 0;
};

/// A problem in the Lorentz-force form x' = v, v' = v x B(x) + E(x) (the direct problem of a
/// model that declares tsi::ChargedParticleForm): its state read as a particle, and the fields.
class TSI_API ChargedParticleProblem {
 public:
  virtual ~ChargedParticleProblem() = default;
  /// The position and velocity of a state y of the problem.
  virtual void split(const Vector& y, RealVector3& x, RealVector3& v) = 0;
  /// The state y of position x and velocity v.
  virtual void join(const RealVector3& x, const RealVector3& v, Vector& y) = 0;
  /// B(x) and E(x); one evaluation of the problem's N (its work measure).
  virtual void fields(const RealVector3& x, RealVector3& B, RealVector3& E) = 0;
};

/// The problem a stepper integrates:  y' = L y + N(t, y).
/// L is diagonal in the problem's coordinates when linear_multipliers() has one entry per
/// unknown (two-scale: -i k / eps per tau-Fourier mode; filtered: all zero); it is empty
/// when L is not diagonal (direct), and then only rhs() is available. It is a tsi::Diagonal:
/// the two-scale L without a remainder is stored once per tau mode, and so are the
/// coefficients a scheme computes from it (tsi::diagonal_function).
class TSI_API Problem {
 public:
  virtual ~Problem() = default;

  /// Number of (complex) unknowns.
  virtual Index size() const = 0;
  /// A zero state of this problem's layout: the prototype steppers allocate their
  /// coefficients and work space from (a device backend allocates on the device here).
  Vector new_state() const { return Vector::Zero(size()); }
  /// The diagonal of L, or an empty one when L is not diagonal in these coordinates.
  virtual const Diagonal& linear_multipliers() const = 0;
  /// Its size and the values a diagonal coefficient stores (for the memory of a binding).
  ProblemLayout layout() const {
    const Diagonal& d = linear_multipliers();
    return {size(), d.size() == size() ? d.values().size() : size()};
  }
  bool has_diagonal_linear_part() const { return linear_multipliers().size() == size(); }
  /// The part of linear_multipliers() that is the model's remainder J R (i omega_j on every
  /// unknown of model coordinate j), or empty without one. A scheme that approximates e^{hL}
  /// (FD's Crank-Nicolson fraction) integrates this part exactly instead: it is bounded in eps
  /// but may be large, and its approximation would cost the order.
  virtual const Vector& remainder_multipliers() const;
  /// The period in t of the fastest component of the explicit time dependence (filtered:
  /// 2 pi eps / Model::max_linear_frequency()), 0 if none.
  /// Adaptive solvers must not step across it: their error estimates alias.
  virtual Real fast_period() const { return 0.0; }
  /// The period in t of the whole explicit time dependence when the problem is the filtered
  /// one, N(t, y) = f_{t/eps}(y): 2 pi eps (e^{A tau} is 2 pi-periodic), 0 otherwise. The
  /// micro-macro and nested Picard schemes evaluate f_tau(y) = N(eps tau, y) on their own tau
  /// grid through it.
  virtual Real oscillation_period() const { return 0.0; }

  /// out = N(t, y).
  virtual void nonlinear(Real t, const Vector& y, Vector& out) = 0;
  /// out = DN(t, y) dy, the derivative of N at y in direction dy.
  virtual void nonlinear_derivative(Real t, const Vector& y, const Vector& dy, Vector& out) = 0;
  /// out = L y + N(t, y).
  virtual void rhs(Real t, const Vector& y, Vector& out) = 0;

  /// True when linear_flow and nonlinear_flow are available (splitting schemes need them).
  virtual bool has_exact_flows() const { return false; }
  /// y <- e^{hL} y. The default throws tsi::Error.
  virtual void linear_flow(Real h, Vector& y);
  /// y <- the exact flow of y' = N(t, y) from t to t + h. The default throws tsi::Error.
  virtual void nonlinear_flow(Real t, Real h, Vector& y);

  /// The problem in the second-order form, or null (the default: the model declares none, or
  /// the reformulation is not the direct one).
  virtual SecondOrderProblem* second_order() { return nullptr; }
  /// The problem in the Lorentz-force form, or null (the default: the model declares none, or
  /// the reformulation is not the direct one).
  virtual ChargedParticleProblem* charged_particle() { return nullptr; }

  /// Evaluations of N (or of rhs) since construction: the work measure of a run.
  long evaluations() const { return evaluations_; }

 protected:
  long evaluations_ = 0;
};

}  // namespace tsi
