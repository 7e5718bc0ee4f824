#pragma once
#include <memory>
#include <string>
#include <vector>

#include "prepared_data.hpp"
#include "repreparation.hpp"
#include "tau_grid.hpp"
#include "tsi/context.hpp"
#include "tsi/reformulation.hpp"

namespace tsi {

/// The two-scale reformulation (eq. 2scale eq): U(t, tau) on N_tau Fourier modes,
///     dU/dt = L U + f_tau(U),   L = -(1/eps) d/dtau + J R,
/// stored as Fourier coefficients, d x N_tau column-major (column j = mode j), so that L is
/// diagonal: -i k / eps + i omega_i for tau mode k and model coordinate i (omega: the model's
/// remainder, zero without one). The Nyquist mode's -i k / eps is 0 (SPEC.md section 2).
/// A real model's U(tau) is real: its coefficients are Hermitian (c_{-k} = conj c_k), and the
/// state keeps modes k = 0 .. N_tau/2 only (d x (N_tau/2 + 1), the real layout: half the
/// memory), transformed by real-to-complex FFTs on a real tau grid.
/// Its parts: the tau grid (TauGrid: its modes, transforms and f_tau on it), the prepared data
/// (PreparedData), their re-preparation between steps (Repreparer), and this, the problem the
/// schemes integrate, with read-back and the tau monitors.
class TwoScale final : public Reformulation, public TwoScaleDiagnostics {
 public:
  /// The largest order of prepared data.
  static constexpr int max_data_order = PreparedData::max_order;
  /// Models of at least this many unknowns without a remainder store L (and the schemes their
  /// coefficients) once per tau mode; smaller ones per unknown (their vectors are small, and
  /// whole-vector products are faster there than runs of a few entries).
  static constexpr Index min_diagonal_run = 64;
  /// The run of L's diagonal for this model (tsi::Diagonal::run): dim, or 1.
  static Index diagonal_run(const Model& model);
  /// The vectors of its size a two-scale problem holds besides the state at the peak of a run,
  /// known before it is built: its work space (a grid buffer where the model's field is not
  /// evaluated in place, allowed for here; a remainder's multipliers) and the largest
  /// preparation of data of this order and method (their temporaries; freed before the run's
  /// steps). `preparation` gets the latter alone.
  static double work_vectors(const Model& model, int initial_data_order, const std::string& data_method,
                             double* preparation = nullptr);

  using DataMethod = tsi::DataMethod;

  /// `real_layout`: keep a real model's state in the real layout (false: all N_tau modes, as
  /// for a complex model; the same numbers to rounding). `context`: the threads the run may
  /// use on its tau grid and in FFTW.
  TwoScale(std::shared_ptr<const Model> model, int n_tau, int initial_data_order,
           Repreparation repreparation = {}, DataMethod data_method = DataMethod::automatic,
           bool real_layout = true, const Context& context = {});
  /// The Nyquist mode's functions of L averaged over +-i (n_tau/2)/eps (reformulation.nyquist =
  /// average: a naive real-to-complex code's, the UA-PIC peer's); L itself keeps 0 there.
  void average_nyquist();

  Index size() const override { return grid_.size(); }
  /// True when the state holds modes 0 .. N_tau/2 of a real U (the real layout).
  bool real_layout() const { return grid_.real_layout(); }
  /// True when a real_layout TwoScale of this model would use the real layout.
  static bool real_layout_for(const Model& model) { return TauGrid::real_layout_for(model); }
  const Diagonal& linear_multipliers() const override { return multipliers_; }
  const Vector& remainder_multipliers() const override { return remainder_grid_; }
  void nonlinear(Real t, const Vector& y, Vector& out) override;
  void nonlinear_derivative(Real t, const Vector& y, const Vector& dy, Vector& out) override;
  void rhs(Real t, const Vector& y, Vector& out) override;

  /// Prepared initial data of the configured order (eq. 2nd data; SPEC.md for order 3).
  Vector prepare(const Vector& u0) override;
  /// u(t) = e^{JM t/eps} U(t, t/eps), U evaluated off the grid by its interpolant.
  Vector read_back(const Vector& y, Real t) override;
  const TwoScaleDiagnostics* two_scale_diagnostics() const override { return this; }
  TauProfile tau_profile(const Vector& y) const override;
  Real tau_roughness(const Vector& y) const override;
  Real tau_spread(const Vector& y) const override;
  /// Re-prepares U when the rule says so: v_n = U(t_n, s_n), s_n = t_n/eps mod 2 pi, and U
  /// rebuilt as prepared data centred at s_n (U(t_n, s_n) = v_n exactly, u(t_n) unchanged).
  StateObserver* repreparation() override { return &repreparer_; }
  std::vector<double> repreparation_times() const override { return repreparer_.times(); }
  int data_order_reached() const override { return data_.order_reached(); }
  int threads() const override { return grid_.threads(); }

 private:
  Real eps_;
  Vector remainder_;  // i omega per model coordinate (empty without a remainder)
  TauGrid grid_;
  PreparedData data_;
  Diagonal multipliers_;  // per tau mode without a remainder (diagonal_run), else per unknown
  Vector remainder_grid_;  // remainder_ on every tau point (empty without a remainder)
  Repreparer repreparer_;
};

}  // namespace tsi
