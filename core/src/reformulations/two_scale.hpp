#pragma once
#include <optional>
#include <string>
#include <vector>

#include "tsi/context.hpp"
#include "tsi/fft.hpp"
#include "tsi/real_fft.hpp"
#include "tsi/reformulation.hpp"

namespace tsi {

struct SigmaNodes;

/// The two-scale reformulation (eq. 2scale eq): U(t, tau) on N_tau Fourier modes,
///     dU/dt = L U + f_tau(U),   L = -(1/eps) d/dtau + J R,
/// stored as Fourier coefficients, d x N_tau column-major (column j = mode j), so that L is
/// diagonal: -i k / eps + i omega_i for tau mode k and model coordinate i (omega: the model's
/// remainder, zero without one). The Nyquist mode's -i k / eps is 0 (SPEC.md section 2).
/// A real model's U(tau) is real: its coefficients are Hermitian (c_{-k} = conj c_k), and the
/// state keeps modes k = 0 .. N_tau/2 only (d x (N_tau/2 + 1), the real layout: half the
/// memory), transformed by real-to-complex FFTs on a real tau grid.
/// When a two-scale run re-prepares its data (SPEC.md section 6, "Re-preparation").
struct Repreparation {
  enum class Mode { Never, Every, Auto } mode = Mode::Never;
  long every = 0;         ///< Every: each this many steps
  /// Auto: re-prepare when U's distance from the prepared data at its own diagonal value,
  /// |U - P(v_n, s_n)|, exceeds this fraction of P's own tau variation |P - mean P|.
  double defect = 0.1;
  double defect_floor = 1e-4;  ///< Auto: defects below this fraction of |U| never trigger
  long min_gap = 10;  ///< Auto: tested (one evaluation of r1) every this many steps
};

class TwoScale final : public Reformulation {
 public:
  /// The largest order of prepared data.
  static constexpr int max_data_order = 8;
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

  /// How prepared data of order 2 and above is computed (docs/high-order.md, "Prepared data
  /// of any order").
  enum class DataMethod {
    automatic,  ///< SPEC.md's closed formulas for orders 1-3, the recursion along a trajectory above
    recursion,  ///< the recursion along an averaged trajectory at every order
    central,    ///< the recursion with central difference quotients at every order (5^(k-2) evaluations)
  };

  /// `real_layout`: keep a real model's state in the real layout (false: all N_tau modes, as
  /// for a complex model; the same numbers to rounding). `context`: the threads the run may
  /// use on its tau grid and in FFTW.
  TwoScale(std::shared_ptr<const Model> model, int n_tau, int initial_data_order,
           Repreparation repreparation = {}, DataMethod data_method = DataMethod::automatic,
           bool real_layout = true, const Context& context = {});

  Index size() const override { return dim_ * columns_; }
  /// True when the state holds modes 0 .. N_tau/2 of a real U (the real layout).
  bool real_layout() const { return real_layout_; }
  /// True when a real_layout TwoScale of this model would use the real layout.
  static bool real_layout_for(const Model& model);
  const Diagonal& linear_multipliers() const override { return multipliers_; }
  const Vector& remainder_multipliers() const override { return remainder_grid_; }
  void nonlinear(double t, const Vector& y, Vector& out) override;
  void nonlinear_derivative(double t, const Vector& y, const Vector& dy, Vector& out) override;
  void rhs(double t, const Vector& y, Vector& out) override;

  /// Prepared initial data of the configured order (eq. 2nd data; SPEC.md for order 3).
  Vector prepare(const Vector& u0) override;
  /// u(t) = e^{JM t/eps} U(t, t/eps), U evaluated off the grid by its interpolant.
  Vector read_back(const Vector& y, double t) override;
  double tau_roughness(const Vector& y) const override;
  double tau_spread(const Vector& y) const override;
  /// Re-prepares U when the rule says so: v_n = U(t_n, s_n), s_n = t_n/eps mod 2 pi, and U
  /// rebuilt as prepared data centred at s_n (U(t_n, s_n) = v_n exactly, u(t_n) unchanged).
  bool between_steps(long n, double t, Vector& y) override;
  std::vector<double> repreparation_times() const override { return repreparation_times_; }
  int data_order_reached() const override { return data_order_reached_; }
  int threads() const override { return threads_; }

 private:
  /// Coefficients of f_tau(W(tau)) for grid values W (d x n_tau), computed in W's storage where
  /// the model evaluates in place.
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
  double coefficient_norm(const Vector& y, bool without_mean = false) const;
  /// f_tau on the real tau grid (real layout), in grid_values_ where the binding evaluates in
  /// place, else into field_values_, on columns [c0, c0 + cn) with binding `field`.
  void evaluate_real_grid(TauGridField& field, Index c0, Index cn);
  /// nonlinear_shifted in the real layout.
  void nonlinear_real(const Vector& y, const Vector* mean_shift, Vector& out);
  /// A field evaluation on threads_ threads: transform_in(p) and transform_out(p) on part p's
  /// rows, evaluate(p, c0, cn) on its columns [c0, c0 + cn), with barriers between; an
  /// exception from evaluate reaches the caller once every thread has finished.
  template <class In, class Field, class Out>
  void on_grid_threads(In&& transform_in, Field&& evaluate, Out&& transform_out);
  /// A = (d/dtau)^{-1} (I - Pi) on coefficients: mode k / (i k), modes 0 and Nyquist to 0.
  Matrix apply_A(Matrix c) const;
  /// A's multiplier on the Fourier index j: 1 / (i k), 0 on modes 0 and Nyquist.
  Complex antiderivative(int j) const;
  /// r1(w) = A f_.(w), as coefficients.
  Matrix r1(const Vector& w);
  /// r2(w) = A[Df(w) A f(w)] - A^2[Df(w) (Pi f(w) + JR w)] + JR A^2 f(w), as coefficients
  /// (SPEC.md's r2; the JR terms come from the remainder in the averaged flow).
  Matrix r2(const Vector& w);
  /// Prepared data of the configured order centred at the phase s: U(s) = v exactly (s = 0:
  /// the initial data).
  Vector prepared_at(const Vector& v, double s);
  /// The closed formulas of SPEC.md (orders 1-3), as coefficients.
  Matrix closed_data(const Vector& v, double s);
  /// The derivative-free recursion (SPEC.md, "Higher order") to `order` with central
  /// difference quotients, as coefficients.
  Matrix central_data(const Vector& v, double s, int order);
  /// Phi^k(u): the mean-free tau dependence of data of order k at base point u, coefficients:
  ///   Phi^1 = 0,  Phi^k(u) = eps A [ f(u + Phi^{k-1}(u)) + JR Phi^{k-1}(u) - D Phi^{k-1}(u) G ],
  ///   G = Pi f(u + Phi^{k-1}(u)) + JR u,
  /// with D Phi^{k-1}(u) G a fourth-order central difference (see the definition).
  Matrix central_phi(const Vector& u, int k);
  /// The same recursion evaluated along one trajectory of the averaged flow, on which
  /// D Phi^{k-1} G is d/dsigma (docs/high-order.md), as coefficients.
  Matrix trajectory_data(const Vector& v, double s);
  /// The averaged trajectory for trajectory_data: the points c_i = c(h x_i) of the trajectory
  /// through the base point u = v - Phi(u)(s), found with the data themselves (one order of
  /// Phi and one Picard step per sweep) from the line through v along `drift`, the averaged
  /// field at v. Returns the points (u is points[nodes.center]), none where the sweeps diverge.
  std::optional<std::vector<Vector>> averaged_trajectory(const Vector& v, double s, const SigmaNodes& nodes,
                                                         double h, const Vector& drift);
  /// One level of the recursion at every point c_i of a trajectory (or at `only` alone):
  ///   next_i = eps A [ f(c_i + previous_i) + JR previous_i - (d/dsigma previous)(sigma_i) ],
  /// with drift_i = Pi f(c_i + previous_i) + JR c_i, the averaged field there.
  void trajectory_level(const std::vector<Vector>& points, const std::vector<Vector>& previous,
                        const SigmaNodes& nodes, double h, std::vector<Vector>& next,
                        std::vector<Vector>& drift, int only = -1);
  /// The points u + int_0^{sigma_i} drift of the trajectory through u, by the interpolant of
  /// the drift at the points (a Picard step).
  std::vector<Vector> picard_step(const Vector& u, const std::vector<Vector>& drift, const SigmaNodes& nodes,
                                  double h) const;
  /// The trigonometric interpolant of coefficients c at tau (Nyquist split half/half); c holds
  /// all N_tau modes or the real layout's N_tau/2 + 1.
  Vector evaluate(ConstMatrixRef c, double tau) const;

  /// nonlinear_shifted on the tau grid split over threads_: each thread transforms its rows and
  /// evaluates the field on its columns (between barriers); the same numbers as the serial path.
  void nonlinear_threaded(const Vector& y, const Vector* mean_shift, Vector& out);
  /// N(y + mean_shift), the shift added to the tau mean (column 0) of y on the way to the grid:
  /// the prepared data evaluate f at c_i + Phi_i without a copy of Phi_i (none: nullptr).
  void nonlinear_shifted(const Vector& y, const Vector* mean_shift, Vector& out);

  Index dim_;
  int n_tau_;
  bool real_layout_;
  int columns_;  // stored tau modes: N_tau, or N_tau/2 + 1 in the real layout
  int data_order_;
  DataMethod data_method_;
  int data_order_reached_ = 0;  // the order the last preparation reached (recursion: may stop early)
  double eps_;
  RealVector taus_;
  Vector remainder_;  // i omega per model coordinate (empty without a remainder)
  std::unique_ptr<TauGridField> grid_field_;  // f_tau on taus_, bound once
  RealVector wave_numbers_;  // k of each Fourier index; the Nyquist index holds n/2
  Diagonal multipliers_;  // per tau mode without a remainder (diagonal_run), else per unknown
  Vector remainder_grid_;  // remainder_ on every tau point (empty without a remainder)
  int threads_;  // threads on the tau grid (Context::tau_grid_threads_for); 1: the serial path
  std::vector<Index> column_begin_;  // threads_ + 1 boundaries of the threads' tau columns
  std::vector<std::unique_ptr<TauGridField>> column_fields_;  // f_tau on each thread's columns
  // Complex layout:
  std::unique_ptr<FftBatch> fft_;  // the tau transforms, both ways, in threads_ parts (from and to the caller's memory)
  Matrix field_;   // the field on the grid where the model does not evaluate in place (first use)
  // Real layout:
  std::unique_ptr<RealFftBatch> real_fft_;
  RealMatrix grid_values_;   // U on the real tau grid (and f_tau(U) where the binding evaluates in place)
  RealMatrix field_values_;  // f_tau(U) where it does not
  bool real_kernels_ = false;  // the bindings evaluate real grids; otherwise through complex copies:
  Matrix complex_grid_, complex_field_;
  Repreparation repreparation_;
  std::vector<double> repreparation_times_;
  long last_prepared_ = 0;  // the step of the last preparation
};

}  // namespace tsi
