#pragma once
#include <memory>
#include <vector>

#include "tsi/context.hpp"
#include "device_tau_grid.hpp"
#include "tsi/fft.hpp"
#include "tsi/model.hpp"
#include "tsi/real_fft.hpp"
#include "../real_fft_rows.hpp"

namespace tsi {

/// The tau grid of a two-scale problem: N_tau points tau_j = 2 pi j / N_tau, the Fourier modes
/// of U(tau) in the state's layout (d x N_tau coefficients, column j = mode j; a real model's
/// U is real, its coefficients Hermitian, and the real layout keeps modes 0 .. N_tau/2), the
/// transforms both ways, and f_tau evaluated on the grid through the model's bound fields (on
/// the context's threads, each on its own rows and columns). What the problem, its prepared
/// data and its monitors compute, they compute through this.
class TauGrid {
 public:
  /// `evaluations` counts the field's evaluations on the whole grid (the problem's counter).
  /// n_tau must be positive and even (a ConfigError naming reformulation.n_tau otherwise).
  TauGrid(std::shared_ptr<const Model> model, int n_tau, bool real_layout, const Context& context,
          long& evaluations);

  /// True when a TauGrid of this model may use the real layout (a real model without a remainder).
  static bool real_layout_for(const Model& model);

  Index dim() const { return dim_; }
  int n_tau() const { return n_tau_; }
  /// Stored tau modes: N_tau, or N_tau/2 + 1 in the real layout.
  int columns() const { return columns_; }
  bool real_layout() const { return real_layout_; }
  /// Values of a state on this grid (dim x columns).
  Index size() const { return dim_ * columns_; }
  const RealVector& taus() const { return taus_; }
  /// k of each Fourier index; the Nyquist index holds n/2.
  const RealVector& wave_numbers() const { return wave_numbers_; }
  /// Threads the grid's evaluations use (1: the serial path).
  int threads() const { return threads_; }

  /// f_tau(y + mean_shift), coefficients to coefficients in the state's layout: the shift (none:
  /// nullptr) is added to the tau mean on the way to the grid, so the prepared data evaluate f
  /// at c_i + Phi_i without a copy of Phi_i. The grid is formed in out's storage.
  /// `phase`: tau on the diagonal at the evaluation's time (t/eps), for a field that reads
  /// U there (TauGridField::needs_diagonal).
  void nonlinear(const Vector& y, const Vector* mean_shift, Vector& out, Real phase);
  /// What nonlinear_of_constant does to the coefficients while they are in cache: column j
  /// times factors[j] (a factor 0 sets it to 0), then their value at tau = phase into
  /// *at_phase (evaluate's numbers). The order-2 prepared data in one pass.
  struct ColumnFinish {
    std::vector<Complex> factors;
    Real phase = 0.0;
    Vector* at_phase = nullptr;
  };
  /// f_tau of the grid constant in tau, v at every tau: nonlinear(0, &v, out, phase), the same
  /// numbers, without forming and reading a zero state where the grid goes by blocks of rows;
  /// then `finish` (none: null).
  void nonlinear_of_constant(const Vector& v, Vector& out, Real phase, const ColumnFinish* finish = nullptr);

  /// Coefficients of f_tau(W(tau)) for grid values W (d x n_tau), computed in W's storage where
  /// the model evaluates in place. A field that reads the diagonal reads W at tau = 0 (the
  /// callers' grids are constant in tau, but for central difference data).
  Matrix f_coefficients(Matrix grid);
  /// Coefficients of Df_tau(W(tau)) Z(tau) for grid values W, Z (consumed).
  Matrix df_coefficients(Matrix grid, Matrix direction_grid);
  /// Grid values of the coefficients c (all N_tau modes).
  Matrix to_grid(const Matrix& c);
  /// Coefficients (all N_tau modes, normalised) of grid values (consumed).
  Matrix to_coefficients(Matrix grid);
  /// All N_tau modes of coefficients in the state's layout (the real layout: the modes -k
  /// are the conjugates of the modes k).
  Matrix all_modes(ConstMatrixRef stored) const;
  /// The norm of the coefficients of a state as if all N_tau modes were stored.
  Real coefficient_norm(const Vector& y, bool without_mean = false) const;
  /// The squared norm of each stored column of a state's coefficients, weighted as if all N_tau
  /// modes were stored, over every process of a split run: one pass on the grid's threads, the
  /// same numbers on any number of them (sums by fixed blocks of rows, in order).
  RealVector column_energies(const Vector& y) const;
  /// sqrt(squares) over every process of a split run (Context::collective): the 2-norm of a
  /// state, or of tau data, from the sum of its squares on this process's rows.
  Real norm_from_squares(Real squares) const;
  /// The trigonometric interpolant of coefficients c at tau (Nyquist split half/half); c holds
  /// all N_tau modes or the real layout's N_tau/2 + 1.
  Vector evaluate(ConstMatrixRef c, Real tau) const;
  /// The same into out, whose storage is reused when it has dim rows already (a diagonal read
  /// every stage: 10^7 rows allocated and faulted in again each time otherwise).
  void evaluate_into(ConstMatrixRef c, Real tau, Vector& out) const;
  /// A = (d/dtau)^{-1} (I - Pi) on coefficients: mode k / (i k), modes 0 and Nyquist to 0.
  Matrix apply_A(Matrix c) const;
  /// A's multiplier on the Fourier index j: 1 / (i k), 0 on modes 0 and Nyquist.
  Complex antiderivative(int j) const;

 private:
  /// f_tau on the real tau grid (real layout), in grid_values_ where the binding evaluates in
  /// place, else into field_values_, on columns [c0, c0 + cn) with binding `field`.
  void evaluate_real_grid(TauGridField& field, Index c0, Index cn);
  /// nonlinear on the device (a tsi::device::Scope open on this thread).
  void device_nonlinear(const Vector& y, const Vector* mean_shift, Vector& out);
  /// nonlinear in the real layout.
  void nonlinear_real(const Vector& y, const Vector* mean_shift, Vector& out);
  /// nonlinear in the real layout by blocks of rows (row_blocks_): a block's coefficients to
  /// its values, f, and back, in a buffer per thread; the blocks split over threads_. y null:
  /// the zero state (the values are the shift's).
  void nonlinear_by_rows(const Vector* y, const Vector* mean_shift, Vector& out, const ColumnFinish* finish = nullptr);
  /// finish on rows r0 .. r0 + rn of coefficients c (the state's layout).
  void finish_rows(const ColumnFinish& finish, const std::vector<Complex>& phase_factors, Complex* c, Index r0,
                   Index rn) const;
  /// The factors of evaluate's sum at tau, one per stored column.
  std::vector<Complex> evaluation_factors(Index columns, Real tau) const;
  /// evaluate's sum for rows r0 .. r0 + rn of coefficients c (columns of dim_ rows) into value.
  void evaluate_rows(const Complex* c, Index columns, const std::vector<Complex>& factors, Index r0, Index rn,
                     Complex* value) const;
  /// nonlinear on the tau grid split over threads_: each thread transforms its rows and
  /// evaluates the field on its columns (between barriers); the same numbers as the serial path.
  void nonlinear_threaded(const Vector& y, const Vector* mean_shift, Vector& out);
  /// Keeps the diagonal value and hands it to every binding (fields that read it only).
  void set_diagonal(const Eigen::Ref<const Vector>& diagonal);
  /// Hands diagonal_ (already set) to every binding.
  void bind_diagonal();
  /// A field evaluation on threads_ threads: transform_in(p) and transform_out(p) on part p's
  /// rows, evaluate(p, c0, cn) on its columns [c0, c0 + cn), with barriers between; an
  /// exception from evaluate reaches the caller once every thread has finished.
  template <class In, class Field, class Out>
  void on_grid_threads(In&& transform_in, Field&& evaluate, Out&& transform_out);

  std::shared_ptr<const Model> model_;
  Index dim_;
  int n_tau_;
  bool real_layout_;
  int columns_;
  long* evaluations_;
  RealVector taus_;
  RealVector wave_numbers_;
  std::unique_ptr<TauGridField> grid_field_;  // f_tau on taus_, bound once
  int threads_;
  const Collective* collective_;  // the processes of a split run, or null
  std::vector<Index> column_begin_;  // threads_ + 1 boundaries of the threads' tau columns
  std::vector<std::unique_ptr<TauGridField>> column_fields_;  // f_tau on each thread's columns
  bool needs_diagonal_ = false;  // the bindings read U on the diagonal
  Vector diagonal_;  // the bindings' diagonal value, alive while they evaluate
  // Complex layout:
  std::unique_ptr<FftBatch> fft_;  // the tau transforms, both ways, in threads_ parts (from and to the caller's memory)
  Matrix field_;   // the field on the grid where the model does not evaluate in place (first use)
  // Real layout:
  std::unique_ptr<RealFftBatch> real_fft_;
  RealMatrix grid_values_;   // U on the real tau grid (and f_tau(U) where the binding evaluates in place)
  RealMatrix field_values_;  // f_tau(U) where it does not
  bool real_kernels_ = false;  // the bindings evaluate real grids; otherwise through complex copies:
  Matrix complex_grid_, complex_field_;
  // Real layout, a field independent across groups of rows: transforms and field by blocks of
  // rows, each in a small buffer (none of the grid's size).
  std::unique_ptr<RealFftRows> row_blocks_;
  std::unique_ptr<DeviceTauGrid> device_;  // made on the first evaluation on the device
};

}  // namespace tsi
