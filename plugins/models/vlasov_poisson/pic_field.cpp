#include "pic_field.hpp"

#include <cmath>

#include "tsi/phase.hpp"

namespace tsi::pic {
namespace {

Real fifth(Real z) {
  const Real z2 = z * z;
  return z2 * z2 * z;
}

// The weights of the nodes first .. first + W - 1 of a particle at fraction d in [0, 1) of its
// cell: M6 (the quintic B-spline, as the peer writes it, at distances 2 + d, 1 + d, d, 1 - d,
// 2 - d, 3 - d) or CIC. Branch-free: the same arithmetic for every particle.
template <int W>
void weights(Real d, Real* w) {
  if constexpr (W == 2) {
    w[0] = 1.0 - d;
    w[1] = d;
  } else {
    static_assert(W == 6);
    constexpr Real c = 1.0 / 120.0;
    const Real a = 1.0 - d;
    const Real a5 = fifth(a), d5 = fifth(d), a1 = fifth(1.0 + a), d1 = fifth(1.0 + d);
    w[0] = a5 * c;
    w[1] = (a1 - 6.0 * a5) * c;
    w[2] = (fifth(2.0 + a) - 6.0 * a1 + 15.0 * a5) * c;
    w[3] = (fifth(2.0 + d) - 6.0 * d1 + 15.0 * d5) * c;
    w[4] = (d1 - 6.0 * d5) * c;
    w[5] = d5 * c;
  }
}

// The cell of coordinate x (x / h = cell + d, d in [0, 1)), wrapped into 0 .. n - 1. A
// coordinate that is not finite gets cell 0 and d NaN: its weights, and so E, are NaN too.
int cell(Real x, Real inverse_h, int n, Real& d) {
  const Real p = x * inverse_h;
  Real i = std::floor(p);
  d = p - i;
  if (!(i >= 0.0 && i < n)) {
    i -= n * std::floor(i / n);
    if (i >= n) i -= n;
    if (i < 0.0) i += n;
    if (!(i >= 0.0 && i < n)) i = 0.0;
  }
  return static_cast<int>(i);
}

struct Located {
  Index origin;  // the padded index of the stencil's first node
  Real wx[6], wy[6];
};

template <int W>
Located locate(Real x1, Real x2, Real inverse_dx, Real inverse_dy, int n_x, int n_y, Index padded_x) {
  Located l;
  Real d1 = 0.0, d2 = 0.0;
  const int i = cell(x1, inverse_dx, n_x, d1), j = cell(x2, inverse_dy, n_y, d2);
  weights<W>(d1, l.wx);
  weights<W>(d2, l.wy);
  l.origin = static_cast<Index>(j) * padded_x + i;
  return l;
}

template <int W>
void deposit_all(const Real* base, ParticleLayout layout, Index particles, Real w, Real inverse_dx,
                 Real inverse_dy, int n_x, int n_y, Index padded_x, Real* rho) {
  const Index ps = layout.particle_stride, cs = layout.component_stride;
  for (Index k = 0; k < particles; ++k) {
    const Real* p = base + k * ps;
    const Located l = locate<W>(p[0], p[cs], inverse_dx, inverse_dy, n_x, n_y, padded_x);
    for (int b = 0; b < W; ++b) {
      Real* row = rho + l.origin + b * padded_x;
      const Real s = w * l.wy[b];
      for (int a = 0; a < W; ++a) row[a] += s * l.wx[a];
    }
  }
}

// E at one particle from the padded field stored as (E1, E2) pairs: the rows of its stencil are
// 2 W contiguous values, summed with the y weights first (one multiply-add per value, over
// pairs: the compiler keeps them in vector registers), then with the x weights.
template <int W>
void interpolate(const Located& l, const Real* e, Index padded_x, Real& out1, Real& out2) {
  Real acc[2 * W] = {};
  for (int b = 0; b < W; ++b) {
    const Real* row = e + 2 * (l.origin + b * padded_x);
    const Real wy = l.wy[b];
    for (int a = 0; a < 2 * W; ++a) acc[a] += wy * row[a];
  }
  Real sum[2] = {0.0, 0.0};
  for (int a = 0; a < W; ++a) {
    sum[0] += l.wx[a] * acc[2 * a];
    sum[1] += l.wx[a] * acc[2 * a + 1];
  }
  out1 = sum[0];
  out2 = sum[1];
}

template <int W>
void interpolate_all(const Real* base, ParticleLayout layout, Index particles, Real inverse_dx, Real inverse_dy,
                     int n_x, int n_y, Index padded_x, const Real* e, Real* out) {
  const Index ps = layout.particle_stride, cs = layout.component_stride;
  for (Index k = 0; k < particles; ++k) {
    const Real* p = base + k * ps;
    const Located l = locate<W>(p[0], p[cs], inverse_dx, inverse_dy, n_x, n_y, padded_x);
    interpolate<W>(l, e, padded_x, out[2 * k], out[2 * k + 1]);
  }
}

}  // namespace

Real Geometry::length_x() const { return two_pi / k_x; }
Real Geometry::length_y() const { return two_pi / k_y; }

Field::Field(const Geometry& geometry, const Collective* collective)
    : g_(geometry),
      collective_(collective),
      width_(geometry.shape == Shape::cic ? 2 : 6),
      offset_(geometry.shape == Shape::cic ? 0 : 2),
      padded_x_(geometry.n_x + width_ - 1),
      padded_y_(geometry.n_y + width_ - 1),
      inverse_dx_(1.0 / geometry.dx()),
      inverse_dy_(1.0 / geometry.dy()),
      grid_({geometry.n_y, geometry.n_x}),
      transforms_(std::make_unique<RealGridTransforms>(grid_, 2)),
      padded_rho_(RealVector::Zero(padded_x_ * padded_y_)),
      padded_e_(RealVector::Zero(2 * padded_x_ * padded_y_)) {
  // Wave numbers of the half spectrum (n_y full, x halved), scaled to the box: E^ = -i k rho^ / |k|^2.
  const Index half = grid_.half_points(), half_x = g_.n_x / 2 + 1;
  k1_.resize(half);
  k2_.resize(half);
  inverse_k2_.resize(half);
  for (Index p = 0; p < half; ++p) {
    const int jy = static_cast<int>(p / half_x), ix = static_cast<int>(p % half_x);
    k1_(p) = g_.k_x * ix;
    k2_(p) = g_.k_y * grid_.wave_number(0, jy);
    const Real k_squared = k1_(p) * k1_(p) + k2_(p) * k2_(p);
    inverse_k2_(p) = k_squared > 0.0 ? 1.0 / k_squared : 0.0;  // the mean: no field
  }
}

Field::~Field() = default;

void Field::deposit(const Real* base, ParticleLayout layout) {
  padded_rho_.setZero();
  if (width_ == 2)
    deposit_all<2>(base, layout, g_.particles, g_.weight(), inverse_dx_, inverse_dy_, g_.n_x, g_.n_y, padded_x_,
                   padded_rho_.data());
  else
    deposit_all<6>(base, layout, g_.particles, g_.weight(), inverse_dx_, inverse_dy_, g_.n_x, g_.n_y, padded_x_,
                   padded_rho_.data());
  // Fold the padding onto the periodic grid: padded (J, I) is node (J - offset, I - offset) mod n.
  auto values = transforms_->values();
  Real* rho = values.col(0).data();
  values.col(0).setZero();
  for (Index J = 0; J < padded_y_; ++J) {
    Real* row = rho + ((J - offset_ + g_.n_y) % g_.n_y) * g_.n_x;
    const Real* from = padded_rho_.data() + J * padded_x_;
    for (Index I = 0; I < padded_x_; ++I) row[(I - offset_ + g_.n_x) % g_.n_x] += from[I];
  }
  if (collective_) collective_->sum(rho, static_cast<Index>(g_.n_x) * g_.n_y);  // the whole plasma's
}

void Field::poisson() {
  auto values = transforms_->values();
  const Real cell = g_.dx() * g_.dy();
  values.col(0) /= cell;
  charge_ = values.col(0).sum() * cell;
  values.col(0).array() -= charge_ / (g_.length_x() * g_.length_y());
  values.col(1).setZero();
  transforms_->forward();
  auto spectrum = transforms_->spectrum();
  const Real scale = 1.0 / static_cast<Real>(grid_.points());  // the unnormalised pair's n_x n_y
  for (Index p = 0; p < spectrum.rows(); ++p) {
    const Complex rho_hat = spectrum(p, 0) * (scale * inverse_k2_(p));
    spectrum(p, 0) = Complex(0.0, -k1_(p)) * rho_hat;
    spectrum(p, 1) = Complex(0.0, -k2_(p)) * rho_hat;
  }
  transforms_->backward();
  padded_current_ = false;
}

void Field::pad_field() {
  if (padded_current_) return;
  auto values = transforms_->values();
  const Real* e1 = values.col(0).data();
  const Real* e2 = values.col(1).data();
  for (Index J = 0; J < padded_y_; ++J) {
    const Index row = ((J - offset_ + g_.n_y) % g_.n_y) * g_.n_x;
    for (Index I = 0; I < padded_x_; ++I) {
      const Index node = row + (I - offset_ + g_.n_x) % g_.n_x;
      padded_e_(2 * (J * padded_x_ + I)) = e1[node];
      padded_e_(2 * (J * padded_x_ + I) + 1) = e2[node];
    }
  }
  padded_current_ = true;
}

void Field::solve(const Real* base, ParticleLayout layout) {
  // Split over processes, the last solve is reused only where every process's positions are
  // its own last ones: all of them then skip the density's reduction together.
  const bool same = same_positions(base, layout);
  if (collective_ ? collective_->all(same) : same) return;
  deposit(base, layout);
  poisson();
  const Index ps = layout.particle_stride, cs = layout.component_stride;
  x_solved_.resize(2 * g_.particles);
  for (Index k = 0; k < g_.particles; ++k) {
    x_solved_(2 * k) = base[k * ps];
    x_solved_(2 * k + 1) = base[k * ps + cs];
  }
  solved_ = true;
  e_at_solved_ = false;
}

bool Field::same_positions(const Real* base, ParticleLayout layout) const {
  if (!solved_) return false;
  const Index ps = layout.particle_stride, cs = layout.component_stride;
  for (Index k = 0; k < g_.particles; ++k)
    if (base[k * ps] != x_solved_(2 * k) || base[k * ps + cs] != x_solved_(2 * k + 1)) return false;
  return true;
}

const Real* Field::interpolate(const Real* base, ParticleLayout layout) {
  pad_field();
  e_at_.resize(2 * g_.particles);
  if (width_ == 2)
    interpolate_all<2>(base, layout, g_.particles, inverse_dx_, inverse_dy_, g_.n_x, g_.n_y, padded_x_,
                       padded_e_.data(), e_at_.data());
  else
    interpolate_all<6>(base, layout, g_.particles, inverse_dx_, inverse_dy_, g_.n_x, g_.n_y, padded_x_,
                       padded_e_.data(), e_at_.data());
  e_at_solved_ = false;  // E at other positions than the field's own (the diagonal field)
  return e_at_.data();
}

const Real* Field::at_particles(const Real* base, ParticleLayout layout) {
  solve(base, layout);
  if (!e_at_solved_) {
    interpolate(base, layout);
    e_at_solved_ = true;
  }
  return e_at_.data();
}

Real Field::field_energy() const {
  auto values = transforms_->values();
  return 0.5 * values.squaredNorm() * g_.dx() * g_.dy();
}

}  // namespace tsi::pic
