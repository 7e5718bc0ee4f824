// The cubic nonlinear Schroedinger equation on the torus (eq. NLS eq; SPEC.md sections 4, 7):
//     i u_t = -(1/eps) lap u + |u|^2 u,   x in [0, 2 pi)^d periodic, d = 1, 2 or 3 (`dims`),
// discretised by the Fourier pseudospectral method on tsi::SpectralGrid's N = n_x [x n_y [x n_z]]
// points x = 2 pi (j_x / n_x, ..).
//
// State: the N Fourier coefficients c_m = (2 pi)^{d/2} uhat_m of u(x) = sum_m uhat_m e^{i m.x},
// in the grid's order (FFT order in each direction, C order across them; the Nyquist modes
// only enter through m^2). With this normalisation sum |c_m|^2 is the discrete ||u||_{L2}^2
// (Parseval), so the default mass <c, c> is SPEC's m, and
//     J = -i/2,   M = 2 diag(|m|^2),   H1 = (1/2) ||u||_{L4}^4 = (1/2) ((2 pi)^d / N) sum_j |u_j|^4
// give I = (1/(2 eps)) <Mc, c> = (1/eps) ||grad u||_{L2}^2, (1/eps) J M c = -(i/eps) |m|^2 c (the
// linear part of the equation), and J grad H1 = -i |u|^2 u in physical space. The
// semi-discrete system is Hamiltonian for exactly this H1, so H = I + H1 is its invariant.
//
// Physical variables are the samples u_j on the grid (an (n_x[, n_y[, n_z]]) array in C
// order): to_physical is the inverse transform, from_physical the forward one, and errors are
// measured in the discrete L2 norm sqrt((2 pi)^d / N) |u|.
//
// Initial data (`initial`): "paper", the paper's u0(x) = e^{ix} / (1 + sin^2 x) in 1-D and its
// product over the directions in 2-D and 3-D (analytic and periodic, a sum of modes decaying
// like e^{-0.88 |m_i|} in each direction); "plane-wave", u = a e^{i k.x} (`amplitude` a,
// `wave_vector` k), whose exact solution a e^{i k.x} e^{-i (|k|^2/eps + a^2) t} the model
// declares (a run's reference.scheme "exact").
//
// `dealias`: the 2/3 rule (tsi::SpectralGrid::dealias_mask, P): the field is P(-i |u|^2 u) and u0
// is P u0. The run then stays in P's band, where the system is Hamiltonian for the same H1
// restricted to it (the gradient of the restriction is P grad H1), so H is conserved as before.
#include <cmath>
#include <algorithm>
#include <array>
#include <complex>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tsi/collective.hpp"
#include "tsi/error.hpp"
#include "tsi/model.hpp"
#include "tsi/phase.hpp"
#include "tsi/plugin.hpp"
#include "tsi/spectral_grid.hpp"
#if defined(TSI_WITH_CUDA)
#include "nls_device.hpp"
#include "tsi/device_kernels.hpp"
#endif

namespace {

using tsi::Real;
using tsi::Complex;
using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Vector;

/// e^{-i m^2 tau_j} per direction: (n_i/2 + 1) x n_tau each (a small grid's, read in its steps).
using PhaseTables = std::array<tsi::Matrix, 3>;

// a b and a conj(b), written out: std::complex's operator* tests every product for inf/NaN.
Complex times(Complex a, Complex b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}
Complex times_conj(Complex a, Complex b) {
  return {a.real() * b.real() + a.imag() * b.imag(), a.imag() * b.real() - a.real() * b.imag()};
}

// e^{-i m^2 tau} for m = 1, 2, ... in turn, by phase_table's recurrence (the same products).
class PhaseRecurrence {
 public:
  explicit PhaseRecurrence(Real tau) : z_(std::polar(Real(1), -tau)), z2_(z_ * z_), factor_(z_) {}
  Complex next() {
    phase_ *= factor_;
    factor_ *= z2_;
    return phase_;
  }

 private:
  Complex z_, z2_, phase_ = Complex(1), factor_;
};

// e^{-i m^2 tau_j} for m = 0 .. n/2 (rows) and every tau_j (columns), by the recurrence
// e^{-i (m+1)^2 tau} = e^{-i m^2 tau} e^{-i (2m+1) tau}: one sincos per column, rounding of
// a few m^2 ulp (as the rounding of m^2 tau itself).
tsi::Matrix phase_table(const tsi::RealVector& taus, int n) {
  tsi::Matrix phases(n / 2 + 1, taus.size());
  for (Index j = 0; j < taus.size(); ++j) {
    PhaseRecurrence recurrence(taus(j));
    phases(0, j) = 1.0;
    for (int m = 1; m <= n / 2; ++m) phases(m, j) = recurrence.next();
  }
  return phases;
}

// The phases e^{-i m_i^2 tau} of one tau, m_i = 0 .. n_i/2 per direction (from the tables
// where given, else by the recurrence), and their products e^{-i |m|^2 tau} at every point.
class Phases {
 public:
  // `slab`: the points this process holds (the whole grid but in a split run).
  Phases(const tsi::SpectralGrid& grid, const tsi::GridSlab& slab) : grid_(grid), slab_(slab) {
    for (int i = 0; i < grid.dims(); ++i)
      per_direction_[static_cast<std::size_t>(i)].resize(grid.shape()[static_cast<std::size_t>(i)] / 2 + 1);
  }
  void set(Real tau, const PhaseTables* tables, Index column) {
    for (int i = 0; i < grid_.dims(); ++i) {
      Vector& phase = per_direction_[static_cast<std::size_t>(i)];
      if (tables) {
        phase = (*tables)[static_cast<std::size_t>(i)].col(column);
        continue;
      }
      PhaseRecurrence recurrence(tau);
      phase(0) = 1.0;
      for (Index m = 1; m < phase.size(); ++m) phase(m) = recurrence.next();
    }
  }
  // use(point, e^{-i |m|^2 tau}) for every coefficient held here, in their order (the grid's C
  // order on one process; a split run's transposed slab: tsi::GridSlab). In 1-D the direction's
  // phase itself (no product: the 1-D values of before the grid, to the bit).
  template <class Use>
  void for_each_point(Use&& use) const {
    if (slab_.transposed) {  // a split run: the second direction slowest, then the first, then the third
      const auto at = [](const Vector& phase, const std::vector<int>& folded, Index j) {
        return phase(folded[static_cast<std::size_t>(j)]);
      };
      Index q = 0;
      for (Index c = 0; c < slab_.columns; ++c) {
        const Complex second = at(per_direction_[1], grid_.folded(1), slab_.first_column + c);
        for (Index j1 = 0; j1 < slab_.n1; ++j1) {
          const Complex lead = times(at(per_direction_[0], grid_.folded(0), j1), second);
          if (grid_.dims() == 2) {
            use(q++, lead);
            continue;
          }
          for (Index j3 = 0; j3 < slab_.n3; ++j3) use(q++, times(lead, at(per_direction_[2], grid_.folded(2), j3)));
        }
      }
      return;
    }
    const std::vector<int>& last = grid_.folded(grid_.dims() - 1);
    const Vector& last_phase = per_direction_[static_cast<std::size_t>(grid_.dims() - 1)];
    const Index n_last = static_cast<Index>(last.size());
    if (grid_.dims() == 1) {
      for (Index q = 0; q < n_last; ++q) use(q, last_phase(last[static_cast<std::size_t>(q)]));
      return;
    }
    const Index rows = slab_.points() / n_last;  // the leading directions' points
    const int n2 = grid_.dims() == 3 ? grid_.shape()[1] : 1;
    for (Index r = 0; r < rows; ++r) {
      const Index a = slab_.first_row + r / n2, b = r % n2;
      Complex lead = per_direction_[0](grid_.folded(0)[static_cast<std::size_t>(a)]);
      if (grid_.dims() == 3) lead = times(lead, per_direction_[1](grid_.folded(1)[static_cast<std::size_t>(b)]));
      for (Index q = 0; q < n_last; ++q) use(r * n_last + q, times(lead, last_phase(last[static_cast<std::size_t>(q)])));
    }
  }

 private:
  const tsi::SpectralGrid& grid_;
  tsi::GridSlab slab_;
  std::array<Vector, 3> per_direction_;
};

class Nls final : public tsi::Model,
                  public tsi::HamiltonianStructure,
                  public tsi::FusedTauGrid,
                  public tsi::ExactNonlinearFlow,
                  public tsi::PhysicalVariables,
                  public tsi::ExactSolution
#if defined(TSI_WITH_CUDA)
    , public tsi::DeviceKernels
#endif
{
 public:
  // fftw_threads: FFTW's own threads for large batches (the run's tsi::Context::fft).
  // dealias: the 2/3 rule on the field (and on u0), see the header.
  // wave: the plane wave of model.initial = "plane-wave", else none (the paper's data).
  // split: the processes of tsi run --split, each holding a slab of the grid (tsi::grid_slab),
  // or null for the whole grid here.
  Nls(Real eps, std::vector<int> shape, std::optional<tsi::PlaneWave> wave, bool dealias,
      tsi::ThreadLimit fftw_threads = {}, const tsi::Collective* split = nullptr)
      : Model(eps),
        grid_(std::move(shape)),
        slab_(tsi::grid_slab(grid_, split)),
        split_(split),
        laplacian_(tsi::fourier_slab(grid_.laplacian_symbol(), slab_)),
        wave_(wave),
        dealias_(dealias ? tsi::fourier_slab(grid_.dealias_mask(), slab_) : tsi::RealVector()),
        volume_(std::pow(tsi::two_pi, grid_.dims())),
        batches_(grid_, fftw_threads, split) {
    batch(1);  // the single-state plans (filtered, direct, invariants)
  }

  Index dim() const override { return slab_.points(); }
  const tsi::Collective* processes() const override { return split_; }
  tsi::GridFields grid_fields() const override {
    return {{"u"}, physical_shape(), std::vector<double>(static_cast<std::size_t>(grid_.dims()), tsi::to_double(tsi::two_pi))};
  }
  bool is_complex() const override { return true; }

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  // Dealiased, the field's flow is no longer u e^{-i |u|^2 t} on the grid.
  const tsi::ExactNonlinearFlow* exact_nonlinear_flow() const override { return dealias_.size() ? nullptr : this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }
  const tsi::ExactSolution* exact_solution() const override { return wave_ ? this : nullptr; }

  // e^{JM tau}: mode m times e^{-i |m|^2 tau} = prod_i e^{-i m_i^2 tau}.
  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    Phases phases(grid_, slab_);
    for (Index j = 0; j < u.cols(); ++j) {
      phases.set(taus(j), nullptr, j);
      phases.for_each_point([&](Index p, Complex e) { u(p, j) *= e; });
    }
  }

  // -i |u|^2 u on the grid, in batched transforms each way (a slice of columns at a time).
  // With w = backward(c) = (2 pi)^{d/2} u:  out = -i forward(|w|^2 w) / ((2 pi)^d N).
  void nonlinear_field(ConstMatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(slice(c.cols()));
    const Complex scale(0.0, -1.0 / (volume_ * point_count()));
    for (Index j0 = 0; j0 < c.cols(); j0 += b.columns()) {
      const Index k = std::min(b.columns(), c.cols() - j0);
      auto w = b.data();  // column j: state j0 + j
      w.leftCols(k) = c.middleCols(j0, k);
      if (k < w.cols()) w.rightCols(w.cols() - k).setZero();
      b.backward();
      for (Index j = 0; j < w.cols(); ++j)
        for (Index i = 0; i < w.rows(); ++i) w(i, j) *= scale * std::norm(w(i, j));
      b.forward();
      out.middleCols(j0, k) = w.leftCols(k);
      dealias(out.middleCols(j0, k));
    }
  }

  void filtered_field(const tsi::RealVector& taus, MatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    fused_field(taus, nullptr, phases_, batch(slice(c.cols())), c, out);
  }

  // A run's tau grid: its phases, and transforms of its own for a slice of the grid's columns
  // (no lock: one run's work space). It evaluates in place: each slice of columns is read
  // into the transforms before it is written.
  class GridField final : public tsi::TauGridField {
   public:
    GridField(const Nls& model, const tsi::RealVector& taus)
        : model_(model),
          taus_(taus),
          phases_(model.grid_, model.slab_),
          batch_(tsi::make_field_transforms(model.grid_, model.slice(taus.size()), model.batches_.fftw_threads(),
                                            model.split_)) {
      // A small grid keeps its phases in tables (read, not recomputed: 15% of a step at
      // n_x = 16, n_tau = 256); a large one computes them as it goes.
      Index size = 0;
      for (const int n : model.grid_.shape()) size += (n / 2 + 1) * taus.size();
      if (size <= max_phase_table)
        for (int i = 0; i < model.grid_.dims(); ++i)
          tables_[static_cast<std::size_t>(i)] = phase_table(taus, model.grid_.shape()[static_cast<std::size_t>(i)]);
    }
    void evaluate(MatrixRef c, MatrixRef out) override {
      model_.fused_field(taus_, tables_[0].size() ? &tables_ : nullptr, phases_, *batch_, c, out);
    }
    bool in_place() const override { return true; }

   private:
    static constexpr Index max_phase_table = Index{1} << 15;  // 512 kB
    const Nls& model_;
    tsi::RealVector taus_;
    PhaseTables tables_;
    Phases phases_;
    std::unique_ptr<tsi::FieldTransforms> batch_;
  };

#if defined(TSI_WITH_CUDA)
  // f_tau on the device (nls_device.cu): the host's phase tables and folded indices uploaded,
  // so that the device's phases are the host's to the bit.
  class DeviceField final : public tsi::DeviceTauGridField {
   public:
    explicit DeviceField(std::unique_ptr<nls_device::Kernels> kernels) : kernels_(std::move(kernels)) {}
    void evaluate(Complex* grid, Real scale) override { kernels_->evaluate(grid, scale); }
    bool evaluate_coefficients(const Complex* y, Complex* out, Real scale) override {
      return kernels_->evaluate_coefficients(y, out, scale);
    }

   private:
    std::unique_ptr<nls_device::Kernels> kernels_;
  };
  std::unique_ptr<tsi::DeviceTauGridField> bind_device_tau_grid(const tsi::RealVector& taus) const override {
    nls_device::Setup setup;
    setup.shape = grid_.shape();
    for (int i = 0; i < grid_.dims(); ++i) {
      setup.folded.push_back(grid_.folded(i));
      const tsi::Matrix table = phase_table(taus, grid_.shape()[static_cast<std::size_t>(i)]);
      setup.phases.emplace_back(table.data(), table.data() + table.size());
    }
    if (dealias_.size()) setup.dealias_mask.assign(dealias_.data(), dealias_.data() + dealias_.size());
    setup.field_scale = 1.0 / (volume_ * point_count());
    setup.n_tau = static_cast<int>(taus.size());
    return std::make_unique<DeviceField>(nls_device::make_kernels(setup));
  }
#endif

  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(*this, taus);
  }
  // Each binding owns its tables and transforms: bindings may run on different threads, but
  // not in a split run, whose transforms are collective (every process in the same order).
  bool independent_tau_grid_bindings() const override { return !split_; }

  // f_tau in one pass each way: the phases e^{-i |m|^2 tau} are applied while the states are
  // copied into the batch, and their conjugates (the flow at -tau) while the result is copied
  // out; the cubic term is written out in real arithmetic (-i a w = (a im, -a re)). The phases
  // come from phase_table's recurrence per direction (the same products as its table: with
  // `tables`, its values are read). A slice of b.columns() columns at a time, each read before
  // it is written: out may be c.
  void fused_field(const tsi::RealVector& taus, const PhaseTables* tables, Phases& phases, tsi::FieldTransforms& b,
                   MatrixRef c, MatrixRef out) const {
    const Real scale = 1.0 / (volume_ * point_count());
    for (Index j0 = 0; j0 < c.cols(); j0 += b.columns()) {
      const Index k = std::min(b.columns(), c.cols() - j0);
      auto w = b.data();  // column j: state j0 + j
      for (Index j = 0; j < k; ++j) {
        phases.set(taus(j0 + j), tables, j0 + j);
        phases.for_each_point([&](Index p, Complex e) { w(p, j) = times(c(p, j0 + j), e); });
      }
      if (k < w.cols()) w.rightCols(w.cols() - k).setZero();
      b.backward();
      Real* q = reinterpret_cast<Real*>(w.data());
      for (Index i = 0; i < 2 * w.size(); i += 2) {
        const Real re = q[i], im = q[i + 1], a = scale * (re * re + im * im);
        q[i] = a * im;
        q[i + 1] = -a * re;
      }
      b.forward();
      for (Index j = 0; j < k; ++j) {
        phases.set(taus(j0 + j), tables, j0 + j);
        phases.for_each_point([&](Index p, Complex e) { out(p, j0 + j) = times_conj(w(p, j), e); });
      }
      dealias(out.middleCols(j0, k));
    }
  }

  // D(-i |u|^2 u) z = -i (2 |u|^2 z + u^2 conj(z)), on the grid, same scaling as above.
  void nonlinear_field_derivative(ConstMatrixRef c, ConstMatrixRef dc, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    // A large batch (the prepared data's, a run's tau grid) gets transforms of its own for this
    // call, freed after it: the derivative is not needed while the run steps.
    std::unique_ptr<tsi::FieldTransforms> own;
    if (slice(c.cols()) < c.cols())
      own = tsi::make_field_transforms(grid_, slice(c.cols()), batches_.fftw_threads(), split_);
    tsi::FieldTransforms& b = own ? *own : batch(c.cols());
    tsi::Matrix& grid = b.scratch();
    const Complex scale(0.0, -1.0 / (volume_ * point_count()));
    for (Index j0 = 0; j0 < c.cols(); j0 += b.columns()) {
      const Index k = std::min(b.columns(), c.cols() - j0);
      auto w = b.data();  // column j: state j0 + j
      w.leftCols(k) = c.middleCols(j0, k);
      if (k < w.cols()) w.rightCols(w.cols() - k).setZero();
      b.backward();
      grid = w;
      w.leftCols(k) = dc.middleCols(j0, k);
      b.backward();
      for (Index j = 0; j < w.cols(); ++j)
        for (Index i = 0; i < w.rows(); ++i) {
          const Complex g = grid(i, j), z = w(i, j);
          w(i, j) = scale * (2.0 * std::norm(g) * z + g * g * std::conj(z));
        }
      b.forward();
      out.middleCols(j0, k) = w.leftCols(k);
      dealias(out.middleCols(j0, k));
    }
  }

  void apply_M(const Vector& u, Vector& out) const override {
    out = Real(2) * laplacian_.cwiseProduct(u);
  }

  void apply_J(const Vector& u, Vector& out) const override { out = Complex(0.0, -0.5) * u; }

  // (1/2) ||u||_{L4}^4 = (1/2) ((2 pi)^d / N) sum |u_j|^4 = sum |w_j|^4 / (2 (2 pi)^d N).
  Real H1(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = c;
    b.backward();
    return summed(w.col(0).cwiseAbs2().squaredNorm()) / (2.0 * volume_ * point_count());
  }

  // The momentum along direction i, P_i = sum_m m_i |c_m|^2 = Im int conj(u) d_i u dx
  // (P = ||u||^2 for u = e^{ix}), the Nyquist modes weighted 0 as the spectral derivative weights
  // them. The NLS flow conserves it (translation invariance); the collocated |u|^2 u does not
  // quite: the semi-discrete system is invariant under translations by whole grid steps only,
  // and P changes by the aliasing of the cubic term. Measured with rk78 (tol 1e-13) on the direct
  // problem from the paper's 1-D u0 (whose modes are odd, so the Nyquist mode stays 0): relative
  // change 2.9e-5 .. 3.7e-5 over t = 1 (eps = 0.01 .. 1) and 2.3e-4 over t = 10 at n_x = 16,
  // 7.8e-10 over t = 10 at n_x = 32, and from n_x = 64 no more than H changes (1e-15 .. 4e-14
  // over t = 1: the rounding of rk78's steps).
  Real momentum(int direction, const Vector& c) const {
    const int n = grid_.shape()[static_cast<std::size_t>(direction)];
    Index stride = 1;  // C order: the last direction's index runs fastest
    for (int i = direction + 1; i < grid_.dims(); ++i) stride *= grid_.shape()[static_cast<std::size_t>(i)];
    Real p = 0.0;
    for (Index q = 0; q < c.size(); ++q) {
      const int j = static_cast<int>((slab_.fourier_point(q) / stride) % n);
      if (2 * j != n) p += grid_.wave_number(direction, j) * std::norm(c(q));
    }
    return summed(p);
  }

  std::vector<tsi::ModelInvariant> invariants() const override {
    const std::string what =
        "; exact for NLS, kept by the Fourier collocation up to aliasing (relative 4e-5 over t = 1 at n_x = 16 in "
        "1-D, rounding at n_x = 64)";
    if (grid_.dims() == 1)
      return {{"P", "momentum sum_m m |c_m|^2 = Im int conj(u) u_x dx" + what,
               [this](const Vector& c) { return momentum(0, c); }}};
    std::vector<tsi::ModelInvariant> all;
    const char* axes = "xyz";
    for (int i = 0; i < grid_.dims(); ++i) {
      const std::string axis(1, axes[i]);
      all.push_back({"P_" + axis, "momentum sum_m m_" + axis + " |c_m|^2 = Im int conj(u) u_" + axis + " dx" + what,
                     [this, i](const Vector& c) { return momentum(i, c); }});
    }
    return all;
  }

  // The fastest mode turns with e^{-i |m|^2 tau}, |m|^2 = sum (n_i/2)^2.
  double max_linear_frequency() const override { return tsi::to_double(grid_.max_laplacian_symbol()); }

  // u' = -i |u|^2 u keeps |u| fixed pointwise: u -> u e^{-i |u|^2 t} on the grid.
  void nonlinear_flow(Real t, Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = c;
    b.backward();
    const Real to_u2 = 1.0 / volume_;  // |u|^2 = |w|^2 / (2 pi)^d
    const Real points = static_cast<Real>(grid_.points());
    for (Index i = 0; i < w.rows(); ++i) w(i, 0) *= std::polar(Real(1) / points, -t * std::norm(w(i, 0)) * to_u2);
    b.forward();
    c = w.col(0);
  }

  Vector initial_value() const override {
    Vector x(slab_.points());
    tsi::for_each_slab_point(grid_, slab_, [&](Index p, const std::array<Real, 3>& at) {
      if (wave_) {
        x(p) = wave_->at(at);
        return;
      }
      // the paper's e^{ix} / (1 + sin^2 x), a factor per direction
      Complex value = paper_profile(at[0]);
      for (int i = 1; i < grid_.dims(); ++i) value *= paper_profile(at[static_cast<std::size_t>(i)]);
      x(p) = value;
    });
    return from_physical(x);  // dealiased there
  }

  // The plane wave a e^{i k.x} e^{-i (|k|^2/eps + a^2) t}: x0 times the phase, where x0 is that
  // wave (a run from another model.u0 has no exact solution: an error names it).
  tsi::ExactSolution::Value at(const Vector& x0, Real t) const override {
    const Vector wave = to_physical(initial_value());
    if ((x0 - wave).norm() > 1e-13 * std::max<Real>(1, wave.norm()))
      throw tsi::Error("nls: the exact solution is the plane wave of model.initial = \"plane-wave\"; this run "
                       "starts elsewhere (model.u0 given)");
    const Real frequency = wave_->k2() / eps() + wave_->amplitude * wave_->amplitude;
    // The phase is rounded to a few ulp of frequency * t, as the schemes' own e^{-i |m|^2 t / eps}.
    const Real rounding = std::numeric_limits<Real>::epsilon();
    return {x0 * std::polar(Real(1), -frequency * t), std::max(rounding, 4.0 * rounding * std::abs(frequency * t))};
  }

  Index physical_dim() const override { return slab_.points(); }
  std::vector<Index> physical_shape() const override { return {grid_.shape().begin(), grid_.shape().end()}; }

  // Grid samples -> c = (2 pi)^{d/2} / N * forward(samples). A split run's process takes the
  // whole grid's samples (a u0 file) or its slab's.
  Vector from_physical(const Vector& x) const override {
    if (x.size() != grid_.points() && x.size() != slab_.points())
      throw tsi::ConfigError("model.u0", "got " + std::to_string(x.size()) + " samples, expected " +
                                             std::to_string(grid_.points()) + " (the grid " + grid_.describe() + ")");
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = x.size() == slab_.points() ? x : Vector(x.segment(slab_.first_point(), slab_.points()));
    b.forward();
    Vector c = w.col(0) * (std::sqrt(volume_) / static_cast<Real>(grid_.points()));
    dealias(c);
    return c;
  }

  // c -> grid samples u_j = backward(c)_j / (2 pi)^{d/2}.
  Vector to_physical(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = c;
    b.backward();
    return w.col(0) / std::sqrt(volume_);
  }

  // Discrete L2 norm of grid samples.
  Real error_norm(const Vector& x) const override {
    return std::sqrt(volume_ / static_cast<Real>(grid_.points()) * summed(x.squaredNorm()));
  }

 private:
  // The transforms for batches of `columns` states, planned on first use and kept: a run
  // sees two or three batch sizes (1 and N_tau), so nothing is planned inside a step after
  // the first call. Callers hold mutex_.
  tsi::FieldTransforms& batch(Index columns) const { return batches_.get(columns); }

  // Columns a batched call transforms at once: a large batch (a run's tau grid) goes through
  // the transforms a slice at a time, so the model's work space is a slice of the state: 32
  // columns, and at most 2^18 values (4 MB; a 2-D or 3-D field is transformed one at a time
  // anyway, so a larger slice only costs memory: 256 x 256 takes 4 columns, 64^3 one).
  static constexpr Index slice_columns = 32;
  static constexpr Index slice_values = Index{1} << 18;
  Index slice(Index columns) const {
    if (grid_.points() * columns < (Index{1} << 16)) return columns;
    return std::min({columns, slice_columns, std::max<Index>(1, slice_values / grid_.points())});
  }

  Real point_count() const { return static_cast<Real>(grid_.points()); }

  // With the 2/3 rule, the modes outside its band set to zero (columns of coefficients).
  template <class Columns>
  void dealias(Columns&& c) const {
    if (dealias_.size())
      for (Index j = 0; j < c.cols(); ++j) c.col(j).array() *= dealias_.array();
  }

  static Complex paper_profile(Real x) {
    const Real s = std::sin(x);
    return std::polar(Real(1), x) / (1.0 + s * s);
  }

  tsi::SpectralGrid grid_;
  tsi::GridSlab slab_;               // the points held here: the whole grid but in a split run
  const tsi::Collective* split_;     // the processes of tsi run --split, or null
  tsi::RealVector laplacian_;        // |m|^2 on the slab
  std::optional<tsi::PlaneWave> wave_;
  tsi::RealVector dealias_;    // the 2/3 rule's mask, or empty
  Real volume_;              // (2 pi)^d
  mutable std::mutex mutex_;   // the batches' buffers and phases_ are shared work space
  mutable tsi::GridTransformsPool batches_;
  mutable Phases phases_{grid_, slab_};
};

void register_nls(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "nls";
  entry.info.summary =
      "cubic NLS i u_t = -(1/eps) lap u + |u|^2 u on the torus [0, 2 pi)^dims (eq. NLS eq), Fourier in space, "
      "dim n_x [n_y [n_z]]";
  entry.info.params = tsi::spectral_grid_params("samples of u");
  for (tsi::ParamSpec& spec :
       tsi::initial_data_params("paper", "e^{ix} / (1 + sin^2 x), its product over the directions"))
    entry.info.params.push_back(std::move(spec));
  entry.info.params.push_back(tsi::bool_param(
      "dealias", false,
      "the 2/3 rule: the field's modes with some |m_i| > n_i/3 set to zero, and u0's too (the run stays in the "
      "band, where H is conserved; no exact nonlinear flow, so no Strang)"));
  entry.default_n_tau = 256;
  entry.nonlinearity_degree = 3;
  entry.verification = {{1.0, 1.0 / 16, 1.0 / 256}, {4, 8, 16, 32}};
  entry.create = [](const tsi::Params& p) {
    std::vector<int> shape = tsi::spectral_grid_shape(p);
    const std::optional<tsi::PlaneWave> wave = tsi::plane_wave(p, shape);
    return std::make_unique<Nls>(p.number("eps"), std::move(shape), wave, p.boolean("dealias"), p.context().fft,
                                 p.context().collective);
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("nls", register_nls)
