// The nonlinear Klein-Gordon equation in the non-relativistic limit (SPEC.md section 6):
//     e^2 z_tt - lap z + z / e^2 + lambda z^3 = 0,   x in [0, 2 pi)^d periodic, z real, d = 1, 2, 3,
// with tsi's eps = e^2 (time is not rescaled), discretised by the Fourier pseudospectral
// method on tsi::SpectralGrid's N = n_x [x n_y [x n_z]] points (each even). Reference:
// Chartier, Crouseilles, Lemou, Mehats, Numer. Math. 129 (2015) 211-250. Written out below in
// 1-D; in d dimensions k^2 is |k|^2 = k_1^2 + .. + k_d^2, sqrt(2 pi) is (2 pi)^{d/2} and n_x is N.
//
// Variables. q = z, p = e^2 z_t, and for the wave number k (FFT order, the Nyquist index taken
// as k = n_x/2) a_k = (1 + eps k^2)^(1/4), Q_k = a_k q_k, P_k = p_k / a_k, w_k = Q_k - i P_k,
// where q_k, p_k are the discrete Fourier coefficients (1/n_x) sum_j q_j e^{-i k x_j}. The state
// is c = sqrt(2 pi) w, normalised as in the NLS model so that sum |c_k|^2 is a discrete L2 norm.
// Every complex c is the image of exactly one real pair (q, p): since q and p are real,
// conj(w_{-k}) = Q_k + i P_k, so Q_k = (w_k + conj(w_{-k})) / 2 and P_k = i (w_k - conj(w_{-k})) / 2
// (at k = 0 and at the Nyquist index, Q = Re w and P = -Im w).
//
// The equation. q_k' = p_k / e^2 and p_k' = -(k^2 + 1/e^2) q_k - lambda (z^3)_k give, with
// omega_k = e^-2 a_k^2 = e^-2 sqrt(1 + e^2 k^2), Q_k' = omega_k P_k and
// P_k' = -omega_k Q_k - lambda (z^3)_k / a_k, hence
//     w_k' = i omega_k w_k + i lambda (z^3)_k / a_k.
// With omega_k = 1/eps + A_k and the remainder A_k = k^2 / (1 + sqrt(1 + eps k^2)) (written
// without the cancellation of omega_k - 1/eps): J = i, M = I, J R = diag(i A_k)
// (linear_remainder()), and the nonlinearity is J grad H1 for
//     H1 = (lambda / 4) int z^4 dx = (lambda / 4) (2 pi / n_x) sum_j z_j^4,
//     J grad H1 = i lambda sqrt(2 pi) / n_x * a_k^{-1} forward(z^3)_k.
// z on the grid: g = backward(a^{-1} c) / sqrt(2 pi) = q - i (1 - e^2 d_xx)^{-1/2} p on the grid
// (both terms are real grid functions: a_k is even in k), so z_j = Re g_j, pointwise. Then
// H = <c, c> / (2 eps) + (1/2) sum_k A_k |c_k|^2 + H1 is the energy
//     int e^2 z_t^2 / 2 + z_x^2 / 2 + z^2 / (2 e^2) + lambda z^4 / 4 dx
// of the semi-discrete system (the cross terms Im(conj(Q_k) P_k) cancel between k and -k).
//
// Physical variables (model.u0, u_final, errors): the complex grid samples
//     v = z - i (1 - e^2 d_xx)^{-1/2} (e^2 z_t) = g,
// O(1) in e for well-prepared data (z = O(1), z_t = O(1/e^2)); to_physical is
// v = backward(a^{-1} c) / sqrt(2 pi), from_physical its inverse, errors in the discrete L2 norm.
//
// The exact nonlinear flow: u' = J grad H1 changes p alone (p' = -lambda z^3, q fixed), since
// a^{-1} (i a^{-1} forward(z^3)) transforms back to i times a real grid function. z, and with it
// the field, stays constant: the flow is c <- c + t J grad H1(c).
//
// Default initial value (in v, so that u0 is O(1) for every eps):
//     z(x, 0) = cos x / (1 + sin^2 x),   (1 - e^2 d_xx)^{-1/2} (e^2 z_t)(x, 0) = sin x / (2 (1 + cos^2 x)),
// that is v0(x) = cos x / (1 + sin^2 x) - (i/2) sin x / (1 + cos^2 x): analytic and 2 pi periodic,
// z(x, 0) the real part of the NLS paper's u0, the momentum of the same size and shape. Only odd
// modes, decaying like e^{-0.88 |k|} (k = 3, 5, 7: 0.11, 0.018, 0.003). Well prepared uniformly
// in eps: e^2 z_t(0) = (1 - e^2 d_xx)^{1/2} of an eps-independent smooth function is O(1).
// In 2-D and 3-D the products over the directions: z(x, 0) = prod_i cos x_i / (1 + sin^2 x_i),
// and the momentum part (1/2) prod_i sin x_i / (1 + cos^2 x_i). `initial: "plane-wave"` gives
// v0 = a e^{i k.x} instead, an exact solution at lambda = 0 (v0 e^{i omega_k t}).
//
// The literature's data (model.z0, model.eps_z_t0): z(x, 0) and p(x, 0) = e^2 z_t(x, 0) on the grid,
// real, instead of v in model.u0; the model forms c = sqrt(2 pi) (a_k q_k - i p_k / a_k) itself.
// "eps z_t(0)" of Chartier, Crouseilles, Lemou, Mehats is this p: their eps is tsi's, e^2. Their
// z is complex; this model's is real, so a complex sample is refused, never cut to its real part
// (which would solve another problem without a word).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <iterator>
#include <map>
#include <memory>
#include <limits>
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

namespace {

using tsi::Real;
using tsi::Complex;
using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Vector;


/// z(x, 0) and p(x, 0) = e^2 z_t(x, 0) on the grid, in its C order: initial data in the
/// literature's form (model.z0, model.eps_z_t0).
struct FieldAndMomentum {
  tsi::RealVector z, p;
};

/// cos and sin of a set of phases.
struct Phases {
  Phases() = default;
  explicit Phases(const tsi::RealVector& taus) : cos(taus.array().cos()), sin(taus.array().sin()) {}
  tsi::RealVector cos, sin;
};

class KleinGordon final : public tsi::Model,
                          public tsi::HamiltonianStructure,
                          public tsi::FusedTauGrid,
                          public tsi::ExactNonlinearFlow,
                          public tsi::PhysicalVariables,
                          public tsi::ExactSolution,
                          public tsi::SecondOrderForm {
 public:
  // fftw_threads: FFTW's own threads for large batches (the run's tsi::Context::fft).
  // wave: the plane wave of model.initial = "plane-wave"; data: z and e^2 z_t of model.z0 and
  // model.eps_z_t0; neither: the default data. split: the processes of tsi run --split, each
  // holding a slab of the grid (tsi::grid_slab), or null for the whole grid here.
  KleinGordon(Real eps, std::vector<int> shape, Real lambda, std::optional<tsi::PlaneWave> wave,
              std::optional<FieldAndMomentum> data, tsi::ThreadLimit fftw_threads = {},
              const tsi::Collective* split = nullptr)
      : Model(eps),
        grid_(std::move(shape)),
        slab_(tsi::grid_slab(grid_, split)),
        split_(split),
        n_x_(slab_.points()),
        wave_(wave),
        data_(std::move(data)),
        lambda_(lambda),
        volume_(std::pow(tsi::two_pi, grid_.dims())),
        inverse_a_(n_x_),
        remainder_(n_x_),
        fftw_threads_(fftw_threads),
        full_to_half_(split ? std::vector<tsi::SpectralGrid::HalfIndex>() : grid_.full_to_half()),
        half_to_full_(split ? std::vector<std::array<Index, 2>>() : grid_.half_to_full()),
        batches_(grid_, fftw_threads, split) {
    for (Index j = 0; j < n_x_; ++j) {
      const Real k2 = grid_.laplacian_symbol()(slab_.fourier_point(j));  // |k|^2, the Nyquist index as +n/2
      const Real root = std::sqrt(1.0 + eps * k2);
      inverse_a_(j) = 1.0 / std::sqrt(root);
      remainder_(j) = k2 / (1.0 + root);
    }
    batch(1);  // the single-state plans (filtered, direct, invariants)
  }
  using Model::linear_flow;
  using Model::nonlinear_field;

  Index dim() const override { return n_x_; }
  bool is_complex() const override { return true; }
  const tsi::Collective* processes() const override { return split_; }
  tsi::GridFields grid_fields() const override {
    return {{"v"}, physical_shape(), std::vector<double>(static_cast<std::size_t>(grid_.dims()), tsi::to_double(tsi::two_pi))};
  }

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  const tsi::ExactNonlinearFlow* exact_nonlinear_flow() const override { return this; }
  // The linear equation's plane wave (lambda = 0) is exact.
  const tsi::ExactSolution* exact_solution() const override { return wave_ && lambda_ == 0.0 ? this : nullptr; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }
  const tsi::SecondOrderForm* second_order_form() const override { return this; }

  // e^{JM tau} = e^{i tau}: one phase for every coordinate.
  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) u.col(j) *= std::polar(Real(1), taus(j));
  }

  // i lambda sqrt(2 pi) / n_x a^{-1} forward(z^3), z = Re backward(a^{-1} c) / sqrt(2 pi).
  void nonlinear_field(ConstMatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (split_) return slab_field<false>(Phases{}, batch(c.cols()), c, out);
    fused_field<false>(Phases{}, real_batch(c.cols()), c, out);
  }

  void filtered_field(const tsi::RealVector& taus, MatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (split_) return slab_field<true>(Phases(taus), batch(c.cols()), c, out);
    fused_field<true>(Phases(taus), real_batch(c.cols()), c, out);
  }

  // A run's tau grid: cos and sin of its phases, and transforms of its own (no lock: one run's
  // work space).
  class GridField final : public tsi::TauGridField {
   public:
    GridField(const KleinGordon& model, const tsi::RealVector& taus) : model_(model), phases_(taus) {
      if (model.split_)
        slab_ = tsi::make_field_transforms(model.grid_, taus.size(), model.fftw_threads_, model.split_);
      else
        batch_ = std::make_unique<tsi::RealGridTransforms>(model.grid_, taus.size(), model.fftw_threads_);
    }
    void evaluate(MatrixRef c, MatrixRef out) override {
      if (slab_) return model_.slab_field<true>(phases_, *slab_, c, out);
      model_.fused_field<true>(phases_, *batch_, c, out);
    }

   private:
    const KleinGordon& model_;
    Phases phases_;
    std::unique_ptr<tsi::RealGridTransforms> batch_;  // one process: real transforms
    std::unique_ptr<tsi::FieldTransforms> slab_;      // a split run: its slabs' complex transforms
  };

  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(*this, taus);
  }
  // Each binding owns its tables and transforms: bindings may run on different threads, but
  // not in a split run, whose transforms are collective (every process in the same order).
  bool independent_tau_grid_bindings() const override { return !split_; }

  // f_tau(c) = e^{-i tau} N(e^{i tau} c) in one pass each way, in real transforms. Since e^{JM tau}
  // is the scalar e^{i tau}, backward(a^{-1} e^{i tau} c) = e^{i tau} g with g = backward(a^{-1} c):
  // the phase enters only the real part taken on the grid, z = Re(e^{i tau} g) (up to (2 pi)^{d/2}),
  // and leaves as e^{-i tau} on the way out. The real part of a backward transform of y is the
  // c2r transform of y's Hermitian part (y_m + conj(y_{-m})) / 2, and z^3 is real, so its forward
  // transform is the r2c one, the coefficients of -m the conjugates of those of m. Without
  // Rotate, tau = 0 (the field N itself; `phases` is not read). `c` is read before `out` is
  // written: they may be the same.
  template <bool Rotate>
  void fused_field(const Phases& phases, tsi::RealGridTransforms& b, ConstMatrixRef c, MatrixRef out) const {
    const Index cols = c.cols();
    for (Index j = 0; j < cols; ++j) {
      const Complex turn = Rotate ? Complex(phases.cos(j), phases.sin(j)) : Complex(1.0, 0.0);  // e^{i tau}
      hermitian_part(c.col(j), Rotate, turn, b.spectrum().col(j));
    }
    b.backward();
    // backward(a^{-1} c) = (2 pi)^{d/2} g; z^3 is Re(.)^3 / (2 pi)^{3d/2}, and the field's factor
    // (2 pi)^{d/2} / N: lambda Re(.)^3 / ((2 pi)^d N), real, before the forward transform.
    const Real scale = lambda_ / (volume_ * point_count());
    auto z = b.values();
    z = scale * z.array().cube().matrix();
    b.forward();
    // out = i e^{-i tau} a^{-1} F: i e^{-i tau} = sin tau + i cos tau.
    for (Index j = 0; j < cols; ++j) {
      const Complex turn = Rotate ? Complex(phases.sin(j), phases.cos(j)) : Complex(0.0, 1.0);
      expand_times(b.spectrum().col(j), turn, out.col(j));
    }
  }

  // fused_field on a split run's slabs: the -m of a coefficient lies on another process's slab,
  // so there is no half spectrum to take; z = Re(backward(e^{i tau} a^{-1} c)) pointwise instead,
  // in complex transforms (twice the work of the real ones, the same numbers to rounding).
  template <bool Rotate>
  void slab_field(const Phases& phases, tsi::FieldTransforms& b, ConstMatrixRef c, MatrixRef out) const {
    const Index cols = c.cols();
    auto w = b.data();
    for (Index j = 0; j < cols; ++j) {
      const Complex turn = Rotate ? Complex(phases.cos(j), phases.sin(j)) : Complex(1.0, 0.0);  // e^{i tau}
      for (Index m = 0; m < n_x_; ++m) w(m, j) = inverse_a_(m) * times(c(m, j), turn);
    }
    b.backward();
    const Real scale = lambda_ / (volume_ * point_count());
    for (Index j = 0; j < cols; ++j)
      for (Index p = 0; p < n_x_; ++p) {
        const Real z = w(p, j).real();
        w(p, j) = Complex(scale * z * z * z, 0.0);
      }
    b.forward();
    for (Index j = 0; j < cols; ++j) {
      const Complex turn = Rotate ? Complex(phases.sin(j), phases.cos(j)) : Complex(0.0, 1.0);  // i e^{-i tau}
      for (Index m = 0; m < n_x_; ++m) out(m, j) = inverse_a_(m) * times(w(m, j), turn);
    }
  }

  // D(J grad H1)(c) d = i lambda (2 pi)^{d/2} / N a^{-1} forward(3 z^2 dz), dz the real part of
  // backward(a^{-1} d) / (2 pi)^{d/2}: same scaling as the field.
  void nonlinear_field_derivative(ConstMatrixRef c, ConstMatrixRef d, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const Index cols = c.cols();
    if (split_) {  // in complex transforms, as slab_field
      tsi::FieldTransforms& b = batch(cols);
      auto w = b.data();
      w = inverse_a_.asDiagonal() * c;
      b.backward();
      const tsi::RealMatrix z = w.real();
      w = inverse_a_.asDiagonal() * d;
      b.backward();
      const Real scale = 3.0 * lambda_ / (volume_ * point_count());
      w = (scale * z.array().square() * w.real().array()).matrix().cast<Complex>();
      b.forward();
      out = Complex(0.0, 1.0) * (inverse_a_.asDiagonal() * w);
      return;
    }
    tsi::RealGridTransforms& b = real_batch(cols);
    const Complex one(1.0, 0.0);
    for (Index j = 0; j < cols; ++j) hermitian_part(c.col(j), false, one, b.spectrum().col(j));
    b.backward();
    tsi::RealMatrix& z = b.scratch();
    z = b.values();
    for (Index j = 0; j < cols; ++j) hermitian_part(d.col(j), false, one, b.spectrum().col(j));
    b.backward();
    const Real scale = 3.0 * lambda_ / (volume_ * point_count());
    auto dz = b.values();
    dz = (scale * z.array().square() * dz.array()).matrix();
    b.forward();
    for (Index j = 0; j < cols; ++j) expand_times(b.spectrum().col(j), Complex(0.0, 1.0), out.col(j));
  }

  void apply_M(const Vector& u, Vector& out) const override { out = u; }
  void apply_J(const Vector& u, Vector& out) const override { out = Complex(0.0, 1.0) * u; }

  // (lambda / 4) (2 pi / n_x) sum z_j^4 with z_j = Re backward(a^{-1} c)_j / sqrt(2 pi).
  Real H1(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (split_) {
      tsi::FieldTransforms& b = batch(1);
      b.data().col(0) = inverse_a_.cwiseProduct(c);
      b.backward();
      return lambda_ * summed(b.data().col(0).real().array().pow(4).sum()) / (4.0 * volume_ * point_count());
    }
    tsi::RealGridTransforms& b = real_batch(1);
    hermitian_part(c, false, Complex(1.0, 0.0), b.spectrum().col(0));
    b.backward();
    return lambda_ * b.values().col(0).array().pow(4).sum() / (4.0 * volume_ * point_count());
  }

  const tsi::RealVector& linear_remainder() const override { return remainder_; }

  // z is constant along u' = J grad H1 (the field only moves p), so the field is too.
  void nonlinear_flow(Real t, Vector& c) const override {
    const Vector field = nonlinear_field(c);
    c += t * field;
  }

  // v0(x) = cos x / (1 + sin^2 x) - (i/2) sin x / (1 + cos^2 x) (see the header), or the state
  // of model.z0 and model.eps_z_t0.
  Vector initial_value() const override {
    if (data_) return from_field_and_momentum(*data_);
    Vector v(n_x_);
    tsi::for_each_slab_point(grid_, slab_, [&](Index j, const std::array<Real, 3>& x) {
      if (wave_) {
        v(j) = wave_->at(x);
        return;
      }
      Real z = 1.0, p = 1.0;  // the products over the directions
      for (int i = 0; i < grid_.dims(); ++i) {
        const Real s = std::sin(x[static_cast<std::size_t>(i)]), co = std::cos(x[static_cast<std::size_t>(i)]);
        z = i ? z * (co / (1.0 + s * s)) : co / (1.0 + s * s);
        p = i ? p * (s / (1.0 + co * co)) : s / (1.0 + co * co);
      }
      v(j) = Complex(z, -0.5 * p);
    });
    return from_physical(v);
  }

  // At lambda = 0 every mode turns alone, w_k' = i omega_k w_k with omega_k even in k, so the
  // plane wave v0 = a e^{i k.x} (z = a cos k.x, a wave moving against k) is v0 e^{i omega_k t},
  // omega_k = sqrt(1 + eps |k|^2) / eps. x0 must be that wave (model.u0 not given).
  tsi::ExactSolution::Value at(const Vector& x0, Real t) const override {
    const Vector wave = to_physical(initial_value());
    if ((x0 - wave).norm() > 1e-13 * std::max<Real>(1, wave.norm()))
      throw tsi::Error("klein-gordon: the exact solution is the plane wave of model.initial = \"plane-wave\"; this "
                       "run starts elsewhere (model.u0 given)");
    const Real omega = std::sqrt(1.0 + eps() * wave_->k2()) / eps();
    const Real rounding = std::numeric_limits<Real>::epsilon();
    return {x0 * std::polar(Real(1), omega * t), std::max(rounding, 4.0 * rounding * std::abs(omega * t))};
  }

  Index physical_dim() const override { return n_x_; }
  std::vector<Index> physical_shape() const override { return {grid_.shape().begin(), grid_.shape().end()}; }

  // Grid samples of v -> c = sqrt(2 pi) / n_x * a forward(v). A split run's process takes the
  // whole grid's samples (a u0 file) or its slab's.
  Vector from_physical(const Vector& v) const override {
    if (v.size() != grid_.points() && v.size() != n_x_)
      throw tsi::ConfigError("model.u0", "got " + std::to_string(v.size()) + " samples, expected " +
                                             std::to_string(grid_.points()) + " (the grid " + grid_.describe() + ")");
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = v.size() == n_x_ ? v : Vector(v.segment(slab_.first_point(), n_x_));
    b.forward();
    return (std::sqrt(volume_) / point_count()) * w.col(0).cwiseQuotient(inverse_a_.cast<Complex>());
  }

  // (q, p) on the grid -> c = sqrt(2 pi) / n_x * (a forward(q) - i a^{-1} forward(p)) (the header's
  // Q - i P), which is from_physical(q - i (1 - e^2 d_xx)^{-1/2} p).
  Vector from_field_and_momentum(const FieldAndMomentum& data) const {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    const auto mine = [&](const tsi::RealVector& x) {  // this process's slab of a whole grid's values
      return x.size() == n_x_ ? x : tsi::RealVector(x.segment(slab_.first_point(), n_x_));
    };
    w.col(0) = mine(data.z).cast<Complex>();
    b.forward();
    const Vector q_hat = w.col(0);
    w.col(0) = mine(data.p).cast<Complex>();
    b.forward();
    const Vector c = q_hat.cwiseQuotient(inverse_a_.cast<Complex>()) -
                     Complex(0.0, 1.0) * w.col(0).cwiseProduct(inverse_a_.cast<Complex>());
    return (std::sqrt(volume_) / point_count()) * c;
  }

  // c -> v = backward(a^{-1} c) / sqrt(2 pi).
  Vector to_physical(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = inverse_a_.cwiseProduct(c);
    b.backward();
    return w.col(0) / std::sqrt(volume_);
  }

  // ---- The second-order form ------------------------------------------------------------
  // q_k'' = -omega_k^2 q_k - (lambda / e^2) (z^3)_k for the Fourier coefficients q_k of z (the
  // header's q' = p / e^2, p' = -(k^2 + 1/e^2) q - lambda (z^3)), omega_k = sqrt(1 + eps k^2) / eps:
  // diagonal in Fourier. Positions are (Re q_k, Im q_k) over the whole spectrum (2N reals; q_{-k} =
  // conj q_k, which the integrator keeps: its update is linear with the same omega for k and -k
  // and the force is the transform of a real grid function), velocities those of p_k / e^2.
  Index positions() const override { return 2 * n_x_; }
  tsi::RealVector frequencies() const override {
    tsi::RealVector omega(2 * n_x_);
    for (Index j = 0; j < n_x_; ++j)
      omega(j) = omega(n_x_ + j) = std::sqrt(1.0 + eps() * grid_.laplacian_symbol()(slab_.fourier_point(j))) / eps();
    return omega;
  }
  // z = Re v and (1 - e^2 lap)^{-1/2} p = -Im v on the grid; p_k = a_k^2 (that)_k.
  void to_second_order(const Vector& c, tsi::RealVector& x, tsi::RealVector& v) const override {
    const Vector physical = to_physical(c);
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = physical.real().cast<Complex>();
    b.forward();
    const Vector q = w.col(0) / point_count();
    w.col(0) = (-physical.imag()).cast<Complex>();
    b.forward();
    const Vector p = (w.col(0) / point_count()).cwiseQuotient(inverse_a_.array().square().matrix().cast<Complex>());
    x.resize(2 * n_x_);
    v.resize(2 * n_x_);
    x << q.real(), q.imag();
    v << p.real() / eps(), p.imag() / eps();
  }
  void from_second_order(const tsi::RealVector& x, const tsi::RealVector& v, Vector& c) const override {
    FieldAndMomentum data;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tsi::FieldTransforms& b = batch(1);
      auto w = b.data();
      w.col(0) = x.head(n_x_).cast<Complex>() + Complex(0, 1) * x.tail(n_x_).cast<Complex>();
      b.backward();
      data.z = w.col(0).real();
      w.col(0) = eps() * (v.head(n_x_).cast<Complex>() + Complex(0, 1) * v.tail(n_x_).cast<Complex>());
      b.backward();
      data.p = w.col(0).real();
    }
    c = from_field_and_momentum(data);
  }
  // g_k = -(lambda / e^2) (z^3)_k, z = Re backward(q).
  void force(const tsi::RealVector& x, tsi::RealVector& g) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batch(1);
    auto w = b.data();
    w.col(0) = x.head(n_x_).cast<Complex>() + Complex(0, 1) * x.tail(n_x_).cast<Complex>();
    b.backward();
    w.col(0) = (-lambda_ / eps()) * w.col(0).real().array().cube().matrix().cast<Complex>();
    b.forward();
    g.resize(2 * n_x_);
    g << w.col(0).real() / point_count(), w.col(0).imag() / point_count();
  }

  // Discrete L2 norm of grid samples.
  Real error_norm(const Vector& v) const override {
    return std::sqrt(volume_ / point_count() * summed(v.squaredNorm()));
  }

 private:
  // The transforms for batches of `columns` states, planned on first use and kept. Callers
  // hold mutex_.
  tsi::FieldTransforms& batch(Index columns) const { return batches_.get(columns); }
  // Real transforms for batches of `columns` fields, planned on first use and kept. Callers
  // hold mutex_.
  tsi::RealGridTransforms& real_batch(Index columns) const {
    auto it = real_batches_.find(columns);
    if (it == real_batches_.end())
      it = real_batches_.emplace(columns, std::make_unique<tsi::RealGridTransforms>(grid_, columns, fftw_threads_)).first;
    return *it->second;
  }

  // The half spectrum of the Hermitian part of y = turn a^{-1} c (turn = e^{i tau} where
  // `rotate`): (y_m + conj(y_{-m})) / 2 at every point of the half spectrum.
  template <class In, class Out>
  void hermitian_part(const In& c, bool rotate, Complex turn, Out&& half) const {
    for (Index q = 0; q < static_cast<Index>(half_to_full_.size()); ++q) {
      const auto [m, minus_m] = half_to_full_[static_cast<std::size_t>(q)];
      Complex y = inverse_a_(m) * c(m), y_minus = inverse_a_(minus_m) * c(minus_m);
      if (rotate) {
        y = times(y, turn);
        y_minus = times(y_minus, turn);
      }
      half(q) = Real(0.5) * (y + std::conj(y_minus));
    }
  }

  // out_m = a_m^{-1} turn F_m for every m of the full spectrum, F the half spectrum of a real
  // field (F_{-m} = conj F_m).
  template <class In, class Out>
  void expand_times(const In& half, Complex turn, Out&& out) const {
    for (Index m = 0; m < n_x_; ++m) {
      const auto [at, conjugate] = full_to_half_[static_cast<std::size_t>(m)];
      const Complex f = conjugate ? std::conj(half(at)) : half(at);
      out(m) = inverse_a_(m) * times(f, turn);
    }
  }
  // N, the whole grid's points (the transforms' normalisation).
  Real point_count() const { return static_cast<Real>(grid_.points()); }

  // a b, written out: std::complex's operator* tests every product for inf/NaN.
  static Complex times(Complex a, Complex b) {
    return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
  }

  tsi::SpectralGrid grid_;
  tsi::GridSlab slab_;            // the points held here: the whole grid but in a split run
  const tsi::Collective* split_;  // the processes of tsi run --split, or null
  Index n_x_;                     // the points held here (N on one process)
  std::optional<tsi::PlaneWave> wave_;
  std::optional<FieldAndMomentum> data_;  // model.z0 and model.eps_z_t0
  Real lambda_;
  Real volume_;   // (2 pi)^d
  tsi::RealVector inverse_a_;  // a_k^{-1} = (1 + eps k^2)^{-1/4}
  tsi::RealVector remainder_;  // A_k = k^2 / (1 + sqrt(1 + eps k^2))
  mutable std::mutex mutex_;   // the batches' buffers are shared work space
  tsi::ThreadLimit fftw_threads_;
  std::vector<tsi::SpectralGrid::HalfIndex> full_to_half_;    // where each coefficient is in a half spectrum
  std::vector<std::array<Index, 2>> half_to_full_;            // m and -m of each half-spectrum point
  mutable tsi::GridTransformsPool batches_;                   // complex: the physical variables
  mutable std::map<Index, std::unique_ptr<tsi::RealGridTransforms>> real_batches_;  // real: z and the field
};

// A JSON value as a message shows it, cut to 60 characters.
std::string shown(const tsi::Json& v) {
  const std::string s = v.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// A JSON number that is finite, as x.
bool finite_number(const tsi::Json& v, Real& x) {
  if (!v.is_number()) return false;
  x = v.get<Real>();
  return std::isfinite(x);
}

// model.z0 or model.eps_z_t0: one real number per grid point, in the grid's C order as model.u0
// ([re, 0] is taken as re). A complex sample is refused, naming it: reading its real part would
// solve another problem without a word.
tsi::RealVector real_samples(const tsi::Json& value, const std::string& field, const tsi::SpectralGrid& grid) {
  const auto points = static_cast<std::size_t>(grid.points());
  const std::string expected = std::to_string(points) + " real numbers, one per grid point (the grid " +
                               grid.describe() + ") in C order (the last direction fastest), as model.u0";
  if (!value.is_array()) throw tsi::ConfigError(field, "got " + shown(value) + ", expected " + expected);
  if (value.size() != points)
    throw tsi::ConfigError(field, "got " + std::to_string(value.size()) + " samples, expected " + expected);
  tsi::RealVector samples(grid.points());
  for (std::size_t j = 0; j < points; ++j) {
    const tsi::Json& v = value[j];
    const std::string entry = field + "[" + std::to_string(j) + "]";
    Real re = 0.0, im = 0.0;
    const bool ok = finite_number(v, re) ||
                    (v.is_array() && v.size() == 2 && finite_number(v[0], re) && finite_number(v[1], im));
    if (!ok) throw tsi::ConfigError(entry, "got " + shown(v) + ", expected a finite real number");
    if (im != 0.0)
      throw tsi::ConfigError(entry, "got " + shown(v) +
                                        ", expected a real number: this model's z is real; complex z (Chartier, "
                                        "Crouseilles, Lemou, Mehats) is the model klein-gordon-complex");
    samples(static_cast<Index>(j)) = re;
  }
  return samples;
}

// The initial data of model.z0 and model.eps_z_t0 (either may be left out: zero), or none where
// neither is given. They replace the default data; model.u0 (v itself) and the plane wave are
// other data, refused beside them.
std::optional<FieldAndMomentum> field_and_momentum(const tsi::Params& p, const std::vector<int>& shape) {
  const char* names[2] = {"z0", "eps_z_t0"};
  const char* const* given = std::find_if(std::begin(names), std::end(names), [&](const char* n) { return p.has(n); });
  if (given == std::end(names)) return std::nullopt;
  const std::string field = std::string("model.") + *given;
  if (p.has("u0"))
    throw tsi::ConfigError(field, "is given together with model.u0, which is the physical variable v = z - i (1 - "
                                  "e^2 d_xx)^{-1/2} (e^2 z_t) itself: give either u0 or z0 and eps_z_t0, not both");
  if (p.string("initial") == "plane-wave")
    throw tsi::ConfigError(field, "is given, but model.initial is \"plane-wave\": z0 and eps_z_t0 replace the "
                                  "default data, not the plane wave; give one or the other");
  const tsi::SpectralGrid grid(shape);
  FieldAndMomentum data{tsi::RealVector::Zero(grid.points()), tsi::RealVector::Zero(grid.points())};
  if (p.has("z0")) data.z = real_samples(p.raw().at("z0"), "model.z0", grid);
  if (p.has("eps_z_t0")) data.p = real_samples(p.raw().at("eps_z_t0"), "model.eps_z_t0", grid);
  return data;
}

void register_klein_gordon(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "klein-gordon";
  entry.info.aliases = {"kg"};
  entry.info.summary =
      "nonlinear Klein-Gordon e^2 z_tt - lap z + z/e^2 + lambda z^3 = 0 on the torus [0, 2 pi)^dims, eps = e^2, "
      "Fourier in space, dim n_x [n_y [n_z]]";
  entry.info.params = tsi::spectral_grid_params("samples of v, not of z,");
  for (tsi::ParamSpec& spec : tsi::initial_data_params(
           "default", "z = cos x / (1 + sin^2 x) and its momentum, products over the directions"))
    entry.info.params.push_back(std::move(spec));
  // u0 is the registry's common parameter, documented here for what it is in this model: v, not z.
  const auto any = [](const tsi::Json&) { return true; };
  entry.info.params.push_back(
      tsi::array_param("u0",
                       "initial value in physical variables: samples of v = z - i (1 - e^2 d_xx)^{-1/2} (e^2 z_t) on "
                       "the grid, NOT of z (for z and e^2 z_t give model.z0 and model.eps_z_t0); default: the "
                       "model's own")
          .check(any, "an array of numbers (complex ones as [re, im]) or the name of a .npy file"));
  entry.info.params.push_back(
      tsi::array_param("z0",
                       "initial data in the literature's form, instead of u0: z(x, 0), one real number per grid "
                       "point in C order (as u0); default 0 where eps_z_t0 is given. z is real here: a complex "
                       "sample is refused")
          .check(any, "an array of real numbers, one per grid point"));
  entry.info.params.push_back(
      tsi::array_param("eps_z_t0",
                       "initial data in the literature's form, with z0: eps z_t(x, 0) = e^2 z_t(x, 0), the momentum, "
                       "not z_t itself (tsi's eps is e^2, as in Chartier-Crouseilles-Lemou-Mehats' \"eps "
                       "z_t(0)\"), one real number per grid point in C order; default 0")
          .check(any, "an array of real numbers, one per grid point"));
  entry.info.params.push_back(
      tsi::number_param("lambda", 1.0, "coefficient of the cubic term lambda z^3")
          .check([](const tsi::Json& v) { return std::isfinite(v.get<double>()); }, "a finite number"));
  entry.default_n_tau = 32;
  entry.nonlinearity_degree = 3;
  entry.linear_remainder = true;  // i A_k, A_k = k^2 / (1 + sqrt(1 + eps k^2))
  // From h = 1/16: coarser steps are pre-asymptotic for the modes 3, 5, 7 of the default u0
  // (h A_k >~ 1). eps = 1e-2 is left out (h = 1/16 and 1/32 lie within 1% of whole numbers of
  // half fast periods, a step-size resonance), and so is 1/16, where FD is pre-asymptotic down
  // to h = 1/128 (order 0.90 over 1/16 .. 1/128, 1.74 over 1/64 .. 1/512).
  entry.verification = {{1.0, 1.0 / 256, 1e-4, 1e-6}, {16, 32, 64, 128}};
  entry.create = [](const tsi::Params& p) {
    std::vector<int> shape = tsi::spectral_grid_shape(p);
    std::optional<FieldAndMomentum> data = field_and_momentum(p, shape);
    const std::optional<tsi::PlaneWave> wave = tsi::plane_wave(p, shape);
    return std::make_unique<KleinGordon>(p.number("eps"), std::move(shape), p.number("lambda"), wave, std::move(data),
                                         p.context().fft, p.context().collective);
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("klein-gordon", register_klein_gordon)
