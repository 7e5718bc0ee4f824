// The nonlinear Klein-Gordon equation with complex z (SPEC.md section 8; the form of Chartier,
// Crouseilles, Lemou and Mehats, Numer. Math. 129 (2015)):
//     eps z_tt - lap z + z / eps + lambda |z|^2 z = 0,   x in [0, 2 pi)^d periodic, d = 1, 2, 3,
// Fourier pseudospectral on tsi::SpectralGrid's N points. The real `klein-gordon` model is the
// case z real (its eps the same, e^2 there).
//
// Variables. With <D> = (1 - eps lap)^{1/2} (symbol a_k^2 = sqrt(1 + eps |k|^2)):
//     u = z - i <D>^{-1} (eps z_t),   v = conj z - i <D>^{-1} (eps conj z_t),   z = (u + conj v) / 2,
//     u_t = (i/eps) <D> u + i lambda <D>^{-1} (|z|^2 z),   v_t = (i/eps) <D> v + i lambda <D>^{-1} conj(|z|^2 z)
// (derived from the equation; MicroMacro.jl's ftau.jl writes the field as -i llambda with
// llambda = -lambda, the same). The state is c = (c_u, c_v), c_u = sqrt(2 pi)^d / N a forward(u)
// (as the real model's c, so that sum |c|^2 is a discrete L2 norm and e^{i tau} is the fast flow):
//     c' = (i/eps) c + i A c + i lambda (2 pi)^{d/2} / N a^{-1} (forward(|z|^2 z), forward(conj(|z|^2 z))),
// A_k = |k|^2 / (1 + sqrt(1 + eps |k|^2)) the remainder, integrated exactly. It is Hamiltonian with
// J = i, M = I and H1 = (lambda / 2) (2 pi)^d / N sum_j |z_j|^4: H = <c, c>/(2 eps) + sum A |c|^2 / 2 + H1
// is the energy int eps |z_t|^2 + |grad z|^2 + |z|^2 / eps + lambda |z|^4 / 2 dx. The charge
// Q = Im int conj(z) eps z_t dx is conserved too (the equation's U(1) symmetry); it is recorded.
// The exact flow of c' = f(c) alone is c + t f(c) (z, hence f, is constant along it): Strang splitting.
// The second-order form z_k'' = -omega_k^2 z_k - (lambda/eps) (|z|^2 z)_k, omega_k = sqrt(1 + eps |k|^2)/eps:
// the trigonometric integrators.
//
// Physical variables (model.u0, u_final, errors): the grid samples of u, then of v (2N complex
// values, shape (2, n_x[, n_y[, n_z]])), as MicroMacro.jl keeps them; errors in the discrete L2 norm.
//
// Data (model.data), in 1-D (products over the directions in 2-D and 3-D, as the real model's):
//   cos-sin        z(0) = (1 + i) cos x, eps z_t(0) = (1 - i) sin x (MicroMacro.jl's data set 3,
//                  with its reference solutions at T = 0.25, N = 128: tests/data/rivals/)
//   faou-schratz   z(0) = cos x, eps z_t(0) = sin(x) / 4 + cos(x) / 2 (Faou and Schratz's 6.3,
//                  MicroMacro.jl's data set 2)
//   cai-zhou       z(0) = (2 + i)/sqrt(5) cos x, eps z_t(0) = (1 + i)/sqrt(2) sin x + cos(x) / 2 (Cai
//                  and Zhou's (6.2), their code's data set 2, their psi_t(0) = psi1/e^2 with e^2 = eps;
//                  Faou and Schratz's 6.2, which MicroMacro.jl's data set 2 defines and then overwrites)
//   bao-dong       z(0) = 2 / (e^{x^2} + e^{-x^2}) = sech(x^2), eps z_t(0) = 0, x centred in the box
//                  (Bao and Dong's; MicroMacro.jl's data set 1, with its llambda = -4, i.e. lambda = 4
//                  here). It needs a box larger than 2 pi: `length` L, the box [-L/2, L/2) per direction.
// `length` L (default 2 pi): the torus's period in each direction; the wave numbers are 2 pi k / L,
// and every integral carries the volume L^dims.
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tsi/collective.hpp"
#include "tsi/error.hpp"
#include "tsi/model.hpp"
#include "tsi/phase.hpp"
#include "tsi/plugin.hpp"
#include "tsi/spectral_grid.hpp"

namespace {

using tsi::Complex;
using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::Matrix;
using tsi::MatrixRef;
using tsi::Real;
using tsi::Vector;

enum class Data { cos_sin, faou_schratz, cai_zhou, bao_dong };

class KleinGordonComplex final : public tsi::Model,
                                 public tsi::HamiltonianStructure,
                                 public tsi::ExactNonlinearFlow,
                                 public tsi::PhysicalVariables,
                                 public tsi::SecondOrderForm {
 public:
  // split: the processes of tsi run --split, each holding a slab of the grid (tsi::grid_slab) of
  // u and of v, or null for the whole grid here.
  KleinGordonComplex(Real eps, std::vector<int> shape, Real lambda, Data data, Real length,
                     tsi::ThreadLimit fftw_threads, const tsi::Collective* split)
      : Model(eps),
        grid_(std::move(shape)),
        slab_(tsi::grid_slab(grid_, split)),
        split_(split),
        n_(slab_.points()),
        lambda_(lambda),
        data_(data),
        length_(length),
        volume_(std::pow(length, grid_.dims())),
        a_(n_),
        inverse_a_(n_),
        remainder_(2 * n_),
        batches_(grid_, fftw_threads, split) {
    for (Index j = 0; j < n_; ++j) {
      const Real k2 = grid_.laplacian_symbol()(slab_.fourier_point(j)) * std::pow(tsi::two_pi / length_, 2);  // (2 pi k / L)^2
      const Real root = std::sqrt(1.0 + eps * k2);
      a_(j) = std::sqrt(root);
      inverse_a_(j) = 1.0 / a_(j);
      remainder_(j) = remainder_(n_ + j) = k2 / (1.0 + root);
    }
  }
  using Model::linear_flow;
  using Model::nonlinear_field;

  Index dim() const override { return 2 * n_; }
  bool is_complex() const override { return true; }
  const tsi::Collective* processes() const override { return split_; }
  tsi::GridFields grid_fields() const override {
    return {{"u", "v"}, {grid_.shape().begin(), grid_.shape().end()},
            std::vector<double>(static_cast<std::size_t>(grid_.dims()), tsi::to_double(length_))};
  }
  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }
  const tsi::ExactNonlinearFlow* exact_nonlinear_flow() const override { return this; }
  const tsi::SecondOrderForm* second_order_form() const override { return this; }
  const tsi::RealVector& linear_remainder() const override { return remainder_; }

  // e^{JM tau} = e^{i tau} on every coordinate.
  void linear_flow(const tsi::RealVector& taus, MatrixRef c) const override {
    for (Index j = 0; j < c.cols(); ++j) c.col(j) *= std::polar(Real(1), taus(j));
  }

  // Every column (a tau grid's states) in one batch of transforms.
  void nonlinear_field(ConstMatrixRef c, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const Matrix z = field_z(c);
    spectral_field(lambda_ * (z.array().abs2() * z.array()).matrix(), out);
  }

  // D(|z|^2 z) dz = 2 |z|^2 dz + z^2 conj(dz), dz = (du + conj dv) / 2.
  void nonlinear_field_derivative(ConstMatrixRef c, ConstMatrixRef d, MatrixRef out) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const Matrix z = field_z(c), dz = field_z(d);
    spectral_field(
        lambda_ * (Real(2) * z.array().abs2() * dz.array() + z.array().square() * dz.array().conjugate()).matrix(), out);
  }

  // Along c' = f(c), z stays constant (dz = (i <D>^{-1} F + conj(i <D>^{-1} conj F)) / 2 = 0, <D>^{-1}
  // being real and even), and so does f: the flow is c + t f(c).
  void nonlinear_flow(Real t, Vector& c) const override {
    const Vector field = nonlinear_field(c);
    c += t * field;
  }

  void apply_M(const Vector& u, Vector& out) const override { out = u; }
  void apply_J(const Vector& u, Vector& out) const override { out = Complex(0.0, 1.0) * u; }
  Real H1(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const Matrix z = field_z(c);
    return lambda_ / 2 * volume_ / point_count() * summed(z.array().abs2().square().sum());
  }

  // Q = Im int conj(z) eps z_t = L^d / N sum_j Im(conj(z_j) (eps z_t)_j) on the grid, with
  // z = (u + conj v) / 2 and eps z_t = <D> (conj v - u) / (2 i) (<D> in Fourier). On the grid, not
  // in Fourier: v's coefficient of -k, which conj v needs, lies on another process's slab.
  Real charge(const Vector& c) const {
    const Vector uv = to_physical(c);
    std::lock_guard<std::mutex> lock(mutex_);
    const Vector u = uv.head(n_), conj_v = uv.tail(n_).conjugate();
    tsi::FieldTransforms& b = batches_.get(1);
    b.data().col(0) = (conj_v - u) / Complex(0, 2);
    b.forward();
    b.data().col(0) = a_.array().square().matrix().cwiseProduct(b.data().col(0)) / point_count();
    b.backward();
    Real q = 0;
    for (Index j = 0; j < n_; ++j) q += (std::conj((u(j) + conj_v(j)) / Real(2)) * b.data()(j, 0)).imag();
    return volume_ / point_count() * summed(q);
  }

  std::vector<tsi::ModelInvariant> invariants() const override {
    return {{"Q", "charge Im int conj(z) eps z_t dx: exact (the U(1) symmetry)",
             [this](const Vector& c) { return charge(c); }}};
  }

  Vector initial_value() const override {
    Vector uv(2 * n_);
    Vector z(n_), p(n_);
    tsi::for_each_slab_point(grid_, slab_, [&](Index j, const std::array<Real, 3>& x) {
      Complex zz = 1, pp = 1;
      for (int i = 0; i < grid_.dims(); ++i) {
        const Real xi = x[static_cast<std::size_t>(i)] * (length_ / tsi::two_pi);  // in [0, L)
        const Real s = std::sin(xi), co = std::cos(xi);
        if (data_ == Data::bao_dong) {
          const Real c = xi - length_ / 2;  // centred
          zz *= 2 / (std::exp(c * c) + std::exp(-c * c));
          pp = 0;
        } else if (data_ == Data::cos_sin) {
          zz *= Complex(1, 1) * co;
          pp *= Complex(1, -1) * s;
        } else if (data_ == Data::cai_zhou) {
          zz *= Complex(2, 1) / std::sqrt(Real(5)) * co;
          pp *= Complex(1, 1) / std::sqrt(Real(2)) * s + co / 2;
        } else {
          zz *= co;
          pp *= s / 4 + co / 2;
        }
      }
      z(j) = zz;
      p(j) = pp;
    });
    // u = z - i <D>^{-1} p, v = conj z - i <D>^{-1} conj p.
    std::lock_guard<std::mutex> lock(mutex_);
    uv.head(n_) = z - Complex(0, 1) * inverse_D(p);
    uv.tail(n_) = z.conjugate() - Complex(0, 1) * inverse_D(p.conjugate());
    return from_samples(uv);
  }

  Index physical_dim() const override { return 2 * n_; }
  std::vector<Index> physical_shape() const override {
    std::vector<Index> shape{2};
    for (const int n : grid_.shape()) shape.push_back(n);
    return shape;
  }
  // A split run's process takes the whole grid's samples (a u0 file) or its slabs'.
  Vector from_physical(const Vector& uv) const override {
    const Index whole = grid_.points();
    if (uv.size() != 2 * whole && uv.size() != 2 * n_)
      throw tsi::ConfigError("model.u0", "got " + std::to_string(uv.size()) + " samples, expected " +
                                             std::to_string(2 * whole) + ": u, then v, on the grid " + grid_.describe());
    std::lock_guard<std::mutex> lock(mutex_);
    if (uv.size() == 2 * n_) return from_samples(uv);
    Vector mine(2 * n_);
    mine << uv.segment(slab_.first_point(), n_), uv.segment(whole + slab_.first_point(), n_);
    return from_samples(mine);
  }
  Vector to_physical(const Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    Vector uv(2 * n_);
    tsi::FieldTransforms& b = batches_.get(1);
    for (int half = 0; half < 2; ++half) {
      b.data().col(0) = inverse_a_.cwiseProduct(c.segment(half * n_, n_));
      b.backward();
      uv.segment(half * n_, n_) = b.data().col(0) / std::sqrt(volume_);
    }
    return uv;
  }
  Real error_norm(const Vector& uv) const override {
    return std::sqrt(volume_ / point_count() * summed(uv.squaredNorm()));
  }

  // ---- The second-order form: z_k'' = -omega_k^2 z_k - (lambda / eps) (|z|^2 z)_k --------------
  // omega_k = sqrt(1 + eps |k|^2) / eps, for the Fourier coefficients z_k = forward(z)_k / N; the
  // positions are (Re z_k, Im z_k) (2N reals), the velocities those of (z_t)_k.
  Index positions() const override { return 2 * n_; }
  tsi::RealVector frequencies() const override {
    tsi::RealVector omega(2 * n_);
    for (Index j = 0; j < n_; ++j) omega(j) = omega(n_ + j) = a_(j) * a_(j) / eps();
    return omega;
  }
  // z = (u + conj v) / 2 and eps z_t = <D> (conj v - u) / (2 i) on the grid.
  void to_second_order(const Vector& c, tsi::RealVector& x, tsi::RealVector& v) const override {
    const Vector uv = to_physical(c);
    std::lock_guard<std::mutex> lock(mutex_);
    const Vector u = uv.head(n_), conj_v = uv.tail(n_).conjugate();
    tsi::FieldTransforms& b = batches_.get(1);
    b.data().col(0) = (u + conj_v) / Real(2);
    b.forward();
    const Vector z = b.data().col(0) / point_count();
    b.data().col(0) = (conj_v - u) / Complex(0, 2);
    b.forward();
    const Vector p = a_.array().square().matrix().cwiseProduct(b.data().col(0)) / point_count();  // (eps z_t)_k
    x.resize(2 * n_);
    v.resize(2 * n_);
    x << z.real(), z.imag();
    v << p.real() / eps(), p.imag() / eps();
  }
  // u = z - i <D>^{-1} (eps z_t), v = conj z - i <D>^{-1} conj(eps z_t).
  void from_second_order(const tsi::RealVector& x, const tsi::RealVector& v, Vector& c) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batches_.get(1);
    b.data().col(0) = x.head(n_).cast<Complex>() + Complex(0, 1) * x.tail(n_).cast<Complex>();
    b.backward();
    const Vector z = b.data().col(0);
    b.data().col(0) = eps() * (v.head(n_).cast<Complex>() + Complex(0, 1) * v.tail(n_).cast<Complex>());
    b.backward();
    const Vector p = b.data().col(0);
    Vector uv(2 * n_);
    uv.head(n_) = z - Complex(0, 1) * inverse_D(p);
    uv.tail(n_) = z.conjugate() - Complex(0, 1) * inverse_D(p.conjugate());
    c = from_samples(uv);
  }
  // g_k = -(lambda / eps) (|z|^2 z)_k, z = backward(z_k).
  void force(const tsi::RealVector& x, tsi::RealVector& g) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    tsi::FieldTransforms& b = batches_.get(1);
    b.data().col(0) = x.head(n_).cast<Complex>() + Complex(0, 1) * x.tail(n_).cast<Complex>();
    b.backward();
    const Vector z = b.data().col(0);
    b.data().col(0) = (-lambda_ / eps()) * (z.array().abs2() * z.array()).matrix();
    b.forward();
    g.resize(2 * n_);
    g << b.data().col(0).real() / point_count(), b.data().col(0).imag() / point_count();
  }

 private:
  // N, the whole grid's points (the transforms' normalisation).
  Real point_count() const { return static_cast<Real>(grid_.points()); }

  // c from the samples (u, v): c_u = (2 pi)^{d/2} / N a forward(u). Callers hold mutex_.
  Vector from_samples(const Vector& uv) const {
    Vector c(2 * n_);
    tsi::FieldTransforms& b = batches_.get(1);
    for (int half = 0; half < 2; ++half) {
      b.data().col(0) = uv.segment(half * n_, n_);
      b.forward();
      c.segment(half * n_, n_) = (std::sqrt(volume_) / point_count()) * a_.cwiseProduct(b.data().col(0));
    }
    return c;
  }

  // <D>^{-1} g on the grid. Callers hold mutex_.
  Vector inverse_D(const Vector& g) const {
    tsi::FieldTransforms& b = batches_.get(1);
    b.data().col(0) = g;
    b.forward();
    b.data().col(0) = inverse_a_.array().square().matrix().cwiseProduct(b.data().col(0)) / point_count();
    b.backward();
    return b.data().col(0);
  }

  // z = (u + conj v) / 2 on the grid for every column, u = backward(a^{-1} c_u) / (2 pi)^{d/2}.
  // Callers hold mutex_.
  Matrix field_z(ConstMatrixRef c) const {
    tsi::FieldTransforms& b = batches_.get(c.cols());
    b.data() = inverse_a_.asDiagonal() * c.topRows(n_);
    b.backward();
    Matrix z = b.data();
    b.data() = inverse_a_.asDiagonal() * c.bottomRows(n_);
    b.backward();
    z = (z + b.data().conjugate()) / (2 * std::sqrt(volume_));
    return z;
  }

  // out = i (2 pi)^{d/2} / N a^{-1} (forward(f), forward(conj f)), column by column. Callers hold
  // mutex_.
  void spectral_field(const Matrix& f, MatrixRef out) const {
    tsi::FieldTransforms& b = batches_.get(f.cols());
    const Complex scale(0, std::sqrt(volume_) / point_count());
    b.data() = f;
    b.forward();
    out.topRows(n_) = scale * (inverse_a_.asDiagonal() * b.data());
    b.data() = f.conjugate();
    b.forward();
    out.bottomRows(n_) = scale * (inverse_a_.asDiagonal() * b.data());
  }

  tsi::SpectralGrid grid_;
  tsi::GridSlab slab_;            // the points held here: the whole grid but in a split run
  const tsi::Collective* split_;  // the processes of tsi run --split, or null
  Index n_;                       // the points held here (N on one process)
  Real lambda_;
  Data data_;
  Real length_;                // the torus's period L in each direction
  Real volume_;                // L^d
  tsi::RealVector a_;          // (1 + eps |k|^2)^{1/4}
  tsi::RealVector inverse_a_;  // its inverse
  tsi::RealVector remainder_;  // A_k on u's and on v's coefficients
  mutable std::mutex mutex_;   // the transforms' buffers are shared work space
  mutable tsi::GridTransformsPool batches_;
};

void register_klein_gordon_complex(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "klein-gordon-complex";
  entry.info.aliases = {"kg-complex"};
  entry.info.summary =
      "nonlinear Klein-Gordon with complex z, eps z_tt - lap z + z/eps + lambda |z|^2 z = 0 on the torus [0, L)^dims "
      "(Chartier-Crouseilles-Lemou-Mehats), state (u, v) in Fourier, dim 2 n_x [n_y [n_z]]";
  entry.info.params = tsi::spectral_grid_params("samples of u, then of v,");
  entry.info.params.push_back(
      tsi::string_param("data", "cos-sin",
                        "initial data: \"cos-sin\" (z = (1+i) cos x, eps z_t = (1-i) sin x), \"faou-schratz\" "
                        "(z = cos x, eps z_t = sin(x)/4 + cos(x)/2) or \"cai-zhou\" (z = (2+i)/sqrt5 cos x, eps z_t = "
                        "(1+i)/sqrt2 sin x + cos(x)/2) or \"bao-dong\" (z = sech(x^2), eps z_t = 0, x centred in the box: "
                        "give a length of about 16 and lambda 4 for Bao and Dong's); products over the directions in "
                        "2-D and 3-D")
          .choices({"cos-sin", "faou-schratz", "cai-zhou", "bao-dong"}));
  entry.info.params.push_back(tsi::number_param("length", tsi::two_pi,
                                                "the torus's period L in each direction (wave numbers 2 pi k / L)")
                                  .range(1e-3, 1e6));
  entry.info.params.push_back(
      tsi::number_param("lambda", 1.0, "coefficient of the cubic term lambda |z|^2 z")
          .check([](const tsi::Json& v) { return std::isfinite(v.get<double>()); }, "a finite number"));
  entry.default_n_tau = 32;
  entry.nonlinearity_degree = 3;
  entry.linear_remainder = true;
  entry.verification = {{1.0, 1.0 / 256, 1e-4, 1e-6}, {16, 32, 64, 128}};
  entry.create = [](const tsi::Params& p) {
    std::vector<int> shape = tsi::spectral_grid_shape(p);
    const std::string name = p.string("data");
    const Data data = name == "faou-schratz" ? Data::faou_schratz
                      : name == "cai-zhou"   ? Data::cai_zhou
                      : name == "bao-dong"   ? Data::bao_dong
                                             : Data::cos_sin;
    return std::make_unique<KleinGordonComplex>(p.number("eps"), std::move(shape), p.number("lambda"), data,
                                                static_cast<Real>(p.number("length")), p.context().fft,
                                                p.context().collective);
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("klein-gordon-complex", register_klein_gordon_complex)
