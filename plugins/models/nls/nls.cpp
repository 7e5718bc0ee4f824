// The cubic nonlinear Schroedinger equation on the torus (eq. NLS eq; SPEC.md section 4):
//     i u_t = -(1/eps) u_xx + |u|^2 u,   x in [0, 2 pi) periodic,
// discretised by the Fourier pseudospectral method with N_x points x_j = 2 pi j / N_x.
//
// State: the N_x Fourier coefficients c_m = sqrt(2 pi) * uhat_m of u(x) = sum_m uhat_m e^{i m x},
// in FFT order (index k holds the wave number m = k for k < N_x/2, m = k - N_x above; the
// Nyquist mode only enters through m^2). With this normalisation sum |c_m|^2 is the discrete
// ||u||_{L2}^2 (Parseval), so the default mass <c, c> is SPEC's m, and
//     J = -i/2,   M = 2 diag(m^2),   H1 = (1/2) ||u||_{L4}^4 = (pi/N_x) sum_j |u_j|^4
// give I = (1/(2 eps)) <Mc, c> = (1/eps) ||u_x||_{L2}^2, (1/eps) J M c = -(i/eps) m^2 c (the
// linear part of the equation), and J grad H1 = -i |u|^2 u in physical space. The
// semi-discrete system is Hamiltonian for exactly this H1, so H = I + H1 is its invariant.
//
// Physical variables are the samples u_j on the x grid: to_physical is the inverse transform,
// from_physical the forward one, and errors are measured in the discrete L2 norm
// sqrt(2 pi / N_x) |u|.
#include <cmath>
#include <algorithm>
#include <complex>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tsi/error.hpp"
#include "tsi/grid_fft.hpp"
#include "tsi/model.hpp"
#include "tsi/phase.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Complex;
using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Vector;


class Nls final : public tsi::Model,
                  public tsi::HamiltonianStructure,
                  public tsi::FusedTauGrid,
                  public tsi::ExactNonlinearFlow,
                  public tsi::PhysicalVariables {
 public:
  // fftw_threads: FFTW's own threads for large batches (the run's tsi::Context::fft).
  Nls(double eps, int n_x, tsi::ThreadLimit fftw_threads = {})
      : Model(eps), n_x_(n_x), wave_numbers_(n_x), batches_(n_x, fftw_threads) {
    for (int k = 0; k < n_x; ++k) wave_numbers_(k) = 2 * k < n_x ? k : k - n_x;
    batch(1);  // the single-state plans (filtered, direct, invariants)
  }

  Index dim() const override { return n_x_; }
  bool is_complex() const override { return true; }

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  const tsi::ExactNonlinearFlow* exact_nonlinear_flow() const override { return this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }

  // e^{JM tau}: mode m times e^{-i m^2 tau}.
  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    const tsi::Matrix phase = phase_table(taus, n_x_);
    const int half = n_x_ / 2;
    for (Index j = 0; j < u.cols(); ++j)
      for (int m = 1; m <= half; ++m) {
        u(m, j) *= phase(m, j);
        if (n_x_ - m != m) u(n_x_ - m, j) *= phase(m, j);
      }
  }

  // -i |u|^2 u on the grid, in batched transforms each way (a slice of columns at a time).
  // With w = backward(c) = sqrt(2 pi) u:  out = -i forward(|w|^2 w) / (2 pi N_x).
  void nonlinear_field(ConstMatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::GridFft& b = batch(slice(c.cols()));
    const Complex scale(0.0, -1.0 / (tsi::two_pi * n_x_));
    for (Index j0 = 0; j0 < c.cols(); j0 += b.columns()) {
      const Index k = std::min(b.columns(), c.cols() - j0);
      auto w = b.data();  // row j: state j0 + j
      w.topRows(k) = c.middleCols(j0, k).transpose();
      if (k < w.rows()) w.bottomRows(w.rows() - k).setZero();
      b.backward();
      for (Index i = 0; i < n_x_; ++i)
        for (Index j = 0; j < w.rows(); ++j) w(j, i) *= scale * std::norm(w(j, i));
      b.forward();
      out.middleCols(j0, k) = w.topRows(k).transpose();
    }
  }

  void filtered_field(const tsi::RealVector& taus, MatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    fused_field(taus, nullptr, batch(slice(c.cols())), c, out);
  }

  // A run's tau grid: its phases, and transforms of its own for a slice of the grid's columns
  // (no lock: one run's work space). It evaluates in place: each slice of columns is read
  // into the transforms before it is written.
  class GridField final : public tsi::TauGridField {
   public:
    GridField(const Nls& model, const tsi::RealVector& taus)
        : model_(model), taus_(taus), batch_(model.n_x_, model.slice(taus.size()), model.batches_.fftw_threads()) {
      // A small grid keeps its phases in a table (read, not recomputed: 15% of a step at
      // n_x = 16, n_tau = 256); a large one computes them as it goes (no table of half the
      // state's size).
      if ((model.n_x_ / 2 + 1) * taus.size() <= max_phase_table) phase_ = phase_table(taus, model.n_x_);
    }
    void evaluate(MatrixRef c, MatrixRef out) override {
      model_.fused_field(taus_, phase_.size() ? &phase_ : nullptr, batch_, c, out);
    }
    bool in_place() const override { return true; }

   private:
    static constexpr Index max_phase_table = Index{1} << 15;  // 512 kB
    const Nls& model_;
    tsi::RealVector taus_;
    tsi::Matrix phase_;
    tsi::GridFft batch_;
  };

  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(*this, taus);
  }
  // Each binding owns its tables and transforms: bindings may run on different threads.
  bool independent_tau_grid_bindings() const override { return true; }

  // f_tau in one pass each way: the phases e^{-i m^2 tau} are applied while the states are
  // copied (transposed) into the x-batch, and their conjugates (the flow at -tau) while the
  // result is copied out; the cubic term is written out in real arithmetic (-i a w = (a im, -a re)).
  // The phases come from phase_table's recurrence, column by column as they are needed (the
  // same products: no table of the state's half size). A slice of b.columns() columns at a
  // time, each read before it is written: out may be c.
  // use(m, e^{-i m^2 tau}) for m = 1 .. N_x/2: from column `col` of `phase` (phase_table's
  // values) where there is one, else by the recurrence (no sincos per column with a table).
  template <class Use>
  void for_each_phase(double tau, const tsi::Matrix* phase, Index col, Use&& use) const {
    const int half = n_x_ / 2;
    if (phase) {
      for (int m = 1; m <= half; ++m) use(m, (*phase)(m, col));
      return;
    }
    PhaseRecurrence recurrence(tau);
    for (int m = 1; m <= half; ++m) use(m, recurrence.next());
  }

  // With `phase` (phase_table's values for taus), the phases are read from it instead.
  void fused_field(const tsi::RealVector& taus, const tsi::Matrix* phase, tsi::GridFft& b, MatrixRef c,
                   MatrixRef out) const {
    const double scale = 1.0 / (tsi::two_pi * n_x_);
    for (Index j0 = 0; j0 < c.cols(); j0 += b.columns()) {
      const Index k = std::min(b.columns(), c.cols() - j0);
      auto w = b.data();  // row j: state j0 + j
      for (Index j = 0; j < k; ++j) {
        w(j, 0) = c(0, j0 + j);
        for_each_phase(taus(j0 + j), phase, j0 + j, [&](int m, Complex e) {
          w(j, m) = times(c(m, j0 + j), e);
          if (n_x_ - m != m) w(j, n_x_ - m) = times(c(n_x_ - m, j0 + j), e);
        });
      }
      if (k < w.rows()) w.bottomRows(w.rows() - k).setZero();
      b.backward();
      double* p = reinterpret_cast<double*>(w.data());
      for (Index i = 0; i < 2 * w.size(); i += 2) {
        const double re = p[i], im = p[i + 1], a = scale * (re * re + im * im);
        p[i] = a * im;
        p[i + 1] = -a * re;
      }
      b.forward();
      for (Index j = 0; j < k; ++j) {
        out(0, j0 + j) = w(j, 0);
        for_each_phase(taus(j0 + j), phase, j0 + j, [&](int m, Complex e) {
          out(m, j0 + j) = times_conj(w(j, m), e);
          if (n_x_ - m != m) out(n_x_ - m, j0 + j) = times_conj(w(j, n_x_ - m), e);
        });
      }
    }
  }

  // D(-i |u|^2 u) z = -i (2 |u|^2 z + u^2 conj(z)), on the grid, same scaling as above.
  void nonlinear_field_derivative(ConstMatrixRef c, ConstMatrixRef dc, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    // A large batch (the prepared data's, a run's tau grid) gets transforms of its own for this
    // call, freed after it: the derivative is not needed while the run steps.
    std::unique_ptr<tsi::GridFft> own;
    if (slice(c.cols()) < c.cols()) own = std::make_unique<tsi::GridFft>(n_x_, slice(c.cols()), batches_.fftw_threads());
    tsi::GridFft& b = own ? *own : batch(c.cols());
    tsi::Matrix& grid = b.scratch();
    const Complex scale(0.0, -1.0 / (tsi::two_pi * n_x_));
    for (Index j0 = 0; j0 < c.cols(); j0 += b.columns()) {
      const Index k = std::min(b.columns(), c.cols() - j0);
      auto w = b.data();  // row j: state j0 + j
      w.topRows(k) = c.middleCols(j0, k).transpose();
      if (k < w.rows()) w.bottomRows(w.rows() - k).setZero();
      b.backward();
      grid = w;
      w.topRows(k) = dc.middleCols(j0, k).transpose();
      b.backward();
      for (Index i = 0; i < n_x_; ++i)
        for (Index j = 0; j < w.rows(); ++j) {
          const Complex g = grid(j, i), z = w(j, i);
          w(j, i) = scale * (2.0 * std::norm(g) * z + g * g * std::conj(z));
        }
      b.forward();
      out.middleCols(j0, k) = w.topRows(k).transpose();
    }
  }

  void apply_M(const Vector& u, Vector& out) const override {
    out.resize(n_x_);
    for (Index k = 0; k < n_x_; ++k) out(k) = 2.0 * wave_numbers_(k) * wave_numbers_(k) * u(k);
  }

  void apply_J(const Vector& u, Vector& out) const override { out = Complex(0.0, -0.5) * u; }

  // (1/2) ||u||_{L4}^4 = (pi / N_x) sum |u_j|^4 = sum |w_j|^4 / (4 pi N_x).
  double H1(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::GridFft& b = batch(1);
    auto w = b.data();
    w.row(0) = c.transpose();
    b.backward();
    return w.row(0).cwiseAbs2().squaredNorm() / (2.0 * tsi::two_pi * n_x_);
  }

  // The momentum P = sum_m m |c_m|^2 = 2 pi sum_m m |uhat_m|^2 = -i <u, u_x> = Im int conj(u) u_x dx
  // (P = ||u||^2 for u = e^{ix}), the Nyquist mode weighted 0 as the spectral derivative weights it.
  // The NLS flow conserves it (translation invariance); the collocated |u|^2 u does not quite: the
  // semi-discrete system is invariant under translations by whole grid steps only, and P changes
  // by the aliasing of the cubic term. Measured with rk78 (tol 1e-13) on the direct problem from
  // the paper's u0 (whose modes are odd, so the Nyquist mode stays 0): relative change 2.9e-5 ..
  // 3.7e-5 over t = 1 (eps = 0.01 .. 1) and 2.3e-4 over t = 10 at n_x = 16, 7.8e-10 over t = 10
  // at n_x = 32, and from n_x = 64 no more than H changes (1e-15 .. 4e-14 over t = 1: the
  // rounding of rk78's steps).
  double momentum(const Vector& c) const {
    double p = 0.0;
    for (Index k = 0; k < n_x_; ++k)
      if (2 * k != n_x_) p += wave_numbers_(k) * std::norm(c(k));
    return p;
  }

  std::vector<tsi::ModelInvariant> invariants() const override {
    return {{"P",
             "momentum sum_m m |c_m|^2 = Im int conj(u) u_x dx; exact for NLS, kept by the Fourier "
             "collocation up to aliasing (relative 4e-5 over t = 1 at n_x = 16, rounding at n_x = 64)",
             [this](const Vector& c) { return momentum(c); }}};
  }

  // The fastest mode, m = N_x/2, turns with e^{-i (N_x/2)^2 tau}.
  double max_linear_frequency() const override { return 0.25 * n_x_ * n_x_; }

  // u' = -i |u|^2 u keeps |u| fixed pointwise: u -> u e^{-i |u|^2 t} on the grid.
  void nonlinear_flow(double t, Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::GridFft& b = batch(1);
    auto w = b.data();
    w.row(0) = c.transpose();
    b.backward();
    const double to_u2 = 1.0 / tsi::two_pi;  // |u|^2 = |w|^2 / (2 pi)
    for (Index i = 0; i < n_x_; ++i) w(0, i) *= std::polar(1.0 / n_x_, -t * std::norm(w(0, i)) * to_u2);
    b.forward();
    c = w.row(0).transpose();
  }

  // u0(x) = (cos x + i sin x) / (1 + sin^2 x) (the paper's).
  Vector initial_value() const override {
    Vector x(n_x_);
    for (Index j = 0; j < n_x_; ++j) {
      const double xj = tsi::two_pi * static_cast<double>(j) / n_x_, s = std::sin(xj);
      x(j) = std::polar(1.0, xj) / (1.0 + s * s);
    }
    return from_physical(x);
  }

  Index physical_dim() const override { return n_x_; }

  // Grid samples -> c = sqrt(2 pi) / N_x * forward(samples).
  Vector from_physical(const Vector& x) const override {
    if (x.size() != n_x_)
      throw tsi::ConfigError(
          "model.u0", "got " + std::to_string(x.size()) + " samples, expected n_x = " + std::to_string(n_x_));
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::GridFft& b = batch(1);
    auto w = b.data();
    w.row(0) = x.transpose();
    b.forward();
    return w.row(0).transpose() * (std::sqrt(tsi::two_pi) / n_x_);
  }

  // c -> grid samples u_j = backward(c)_j / sqrt(2 pi).
  Vector to_physical(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::GridFft& b = batch(1);
    auto w = b.data();
    w.row(0) = c.transpose();
    b.backward();
    return w.row(0).transpose() / std::sqrt(tsi::two_pi);
  }

  // Discrete L2 norm of grid samples.
  double error_norm(const Vector& x) const override { return std::sqrt(tsi::two_pi / n_x_) * x.norm(); }

 private:
  // The transforms for batches of `columns` states, planned on first use and kept: a run
  // sees two or three batch sizes (1 and N_tau), so nothing is planned inside a step after
  // the first call. Callers hold mutex_.
  tsi::GridFft& batch(Index columns) const { return batches_.get(columns); }

  // Columns a batched call transforms at once: a large batch (a run's tau grid) goes through
  // the x transforms a slice at a time, so the model's work space is a slice of the state.
  static constexpr Index slice_columns = 32;
  Index slice(Index columns) const {
    return static_cast<Index>(n_x_) * columns >= (Index{1} << 16) ? std::min(columns, slice_columns) : columns;
  }

  // e^{-i m^2 tau} for m = 1, 2, ... in turn, by phase_table's recurrence (the same products).
  class PhaseRecurrence {
   public:
    explicit PhaseRecurrence(double tau) : z_(std::polar(1.0, -tau)), z2_(z_ * z_), factor_(z_) {}
    Complex next() {
      phase_ *= factor_;
      factor_ *= z2_;
      return phase_;
    }

   private:
    Complex z_, z2_, phase_ = 1.0, factor_;
  };

  // e^{-i m^2 tau_j} for m = 0 .. N_x/2 (rows) and every tau_j (columns), by the recurrence
  // e^{-i (m+1)^2 tau} = e^{-i m^2 tau} e^{-i (2m+1) tau}: one sincos per column, rounding of
  // a few m^2 ulp (as the rounding of m^2 tau itself).
  static tsi::Matrix phase_table(const tsi::RealVector& taus, int n_x) {
    tsi::Matrix phases(n_x / 2 + 1, taus.size());
    for (Index j = 0; j < taus.size(); ++j) {
      const Complex z = std::polar(1.0, -taus(j)), z2 = z * z;
      Complex phase = 1.0, factor = z;  // e^{-i m^2 tau}, e^{-i (2m+1) tau}
      phases(0, j) = 1.0;
      for (int m = 1; m <= n_x / 2; ++m) {
        phase *= factor;
        factor *= z2;
        phases(m, j) = phase;
      }
    }
    return phases;
  }

  // a b and a conj(b), written out: std::complex's operator* tests every product for inf/NaN.
  static Complex times(Complex a, Complex b) {
    return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
  }
  static Complex times_conj(Complex a, Complex b) {
    return {a.real() * b.real() + a.imag() * b.imag(), a.imag() * b.real() - a.real() * b.imag()};
  }

  int n_x_;
  tsi::RealVector wave_numbers_;
  mutable std::mutex mutex_;  // the batches' buffers are shared work space
  mutable tsi::GridFftPool batches_;
};

void register_nls(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "nls";
  entry.info.summary =
      "cubic NLS i u_t = -(1/eps) u_xx + |u|^2 u on the torus (eq. NLS eq), Fourier in x, dim n_x";
  entry.info.params = {
      tsi::integer_param("n_x", 16, "Fourier modes (grid points) in x; u0 is given as samples on this grid")
          .check(
              [](const tsi::Json& v) {
                return v.get<long>() >= 2 && v.get<long>() <= (1L << 20) && v.get<long>() % 2 == 0;
              },
              "an even integer in [2, 1048576]")};
  entry.default_n_tau = 256;
  entry.nonlinearity_degree = 3;
  entry.verification = {{1.0, 1.0 / 16, 1.0 / 256}, {4, 8, 16, 32}};
  entry.create = [](const tsi::Params& p) {
    return std::make_unique<Nls>(p.number("eps"), static_cast<int>(p.integer("n_x")), p.context().fft);
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("nls", register_nls)
