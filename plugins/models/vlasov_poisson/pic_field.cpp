#include "pic_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "tsi/error.hpp"
#include "tsi/parallel.hpp"
#include "tsi/phase.hpp"

namespace tsi::pic {
namespace {

Real fifth(Real z) {
  const Real z2 = z * z;
  return z2 * z2 * z;
}

// The particle loops are built for the baseline x86-64 and again for AVX2 + FMA (x86-64-v3) and
// AVX-512 (v4); the loader runs the one this CPU has (GCC's function multiversioning). The
// particles' weights then go four or eight to a register. Other compilers build the baseline.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define TSI_PARTICLE_KERNEL __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define TSI_PARTICLE_KERNEL
#endif

// Particles go by blocks: first the cells and weights of the whole block, stored weight by
// weight over its particles (the same arithmetic for every particle, so SIMD lanes take
// particles), then each particle's stencil sum.
constexpr int block = 64;

template <int W>
struct Stencils {
  Real x1[block], x2[block];   // the block's positions, contiguous
  std::int32_t origin[block];  // the padded index of each particle's first node (Field checks the range)
  Real wx[W][block], wy[W][block];
};

// The weights of the nodes first .. first + W - 1 of particle t at fraction d in [0, 1) of its
// cell: M6 (the quintic B-spline, as the peer writes it, at distances 2 + d, 1 + d, d, 1 - d,
// 2 - d, 3 - d) or CIC.
template <int W>
[[gnu::always_inline]] inline void weights(Real d, Real (&w)[W][block], int t) {
  if constexpr (W == 2) {
    w[0][t] = 1.0 - d;
    w[1][t] = d;
  } else {
    static_assert(W == 6);
    constexpr Real c = 1.0 / 120.0;
    const Real a = 1.0 - d;
    const Real a5 = fifth(a), d5 = fifth(d), a1 = fifth(1.0 + a), d1 = fifth(1.0 + d);
    w[0][t] = a5 * c;
    w[1][t] = (a1 - 6.0 * a5) * c;
    w[2][t] = (fifth(2.0 + a) - 6.0 * a1 + 15.0 * a5) * c;
    w[3][t] = (fifth(2.0 + d) - 6.0 * d1 + 15.0 * d5) * c;
    w[4][t] = (d1 - 6.0 * d5) * c;
    w[5][t] = d5 * c;
  }
}

// floor(x / h) wrapped into 0 .. n - 1, without branches. A coordinate that is not finite gets
// cell 0 and a fraction d that is NaN: its weights, and so E, are NaN too.
[[gnu::always_inline]] inline Real wrapped_cell(Real i, Real n) {
  const Real w = i - n * std::floor(i / n);  // exact: i and n are integers
  return w >= 0.0 && w < n ? w : Real(0);
}

struct Grid {
  Real inverse_dx, inverse_dy;
  Real n_x, n_y, padded_x;
};

// The block's positions are copied out of the state first (strided there) so that the cells
// and weights are one loop over contiguous arrays; the part of a last block past the particles
// is zero, and never read.
template <int W>
[[gnu::always_inline]] inline void locate_block(const Real* base, ParticleLayout layout, Index k0, int m,
                                                const Grid& g, Stencils<W>& s) {
  const Index ps = layout.particle_stride, cs = layout.component_stride;
  for (int t = 0; t < m; ++t) {
    const Real* p = base + (k0 + t) * ps;
    s.x1[t] = p[0];
    s.x2[t] = p[cs];
  }
  for (int t = m; t < block; ++t) s.x1[t] = s.x2[t] = 0.0;
  for (int t = 0; t < block; ++t) {
    const Real p1 = s.x1[t] * g.inverse_dx, p2 = s.x2[t] * g.inverse_dy;
    const Real f1 = std::floor(p1), f2 = std::floor(p2);
    const Real i = wrapped_cell(f1, g.n_x), j = wrapped_cell(f2, g.n_y);
    s.origin[t] = static_cast<std::int32_t>(j * g.padded_x + i);  // exact: integers below 2^31
    weights<W>(p1 - f1, s.wx, t);
    weights<W>(p2 - f2, s.wy, t);
  }
}

template <int W>
[[gnu::always_inline]] inline void deposit_all(const Real* base, ParticleLayout layout, Index particles, Real w,
                                               const Grid& g, Real* rho) {
  Stencils<W> s;
  const Index padded_x = static_cast<Index>(g.padded_x);
  for (Index k0 = 0; k0 < particles; k0 += block) {
    const int m = static_cast<int>(std::min<Index>(block, particles - k0));
    locate_block<W>(base, layout, k0, m, g, s);
    for (int t = 0; t < m; ++t)
      for (int b = 0; b < W; ++b) {
        Real* row = rho + s.origin[t] + b * padded_x;
        const Real wy = w * s.wy[b][t];
        for (int a = 0; a < W; ++a) row[a] += wy * s.wx[a][t];
      }
  }
}

// E at the particles from the padded field stored as (E1, E2) pairs: the rows of a stencil are
// 2 W contiguous values, summed with the y weights first (one multiply-add per value, over
// pairs: they stay in vector registers), then with the x weights.
template <int W>
[[gnu::always_inline]] inline void interpolate_all(const Real* base, ParticleLayout layout, Index particles,
                                                   const Grid& g, const Real* e, Real* out) {
  Stencils<W> s;
  const Index padded_x = static_cast<Index>(g.padded_x);
  for (Index k0 = 0; k0 < particles; k0 += block) {
    const int m = static_cast<int>(std::min<Index>(block, particles - k0));
    locate_block<W>(base, layout, k0, m, g, s);
    for (int t = 0; t < m; ++t) {
      Real acc[2 * W] = {};
      for (int b = 0; b < W; ++b) {
        const Real* row = e + 2 * (s.origin[t] + b * padded_x);
        const Real wy = s.wy[b][t];
        for (int a = 0; a < 2 * W; ++a) acc[a] += wy * row[a];
      }
      Real sum[2] = {0.0, 0.0};
      for (int a = 0; a < W; ++a) {
        sum[0] += s.wx[a][t] * acc[2 * a];
        sum[1] += s.wx[a][t] * acc[2 * a + 1];
      }
      out[2 * (k0 + t)] = sum[0];
      out[2 * (k0 + t) + 1] = sum[1];
    }
  }
}

TSI_PARTICLE_KERNEL void deposit_m6(const Real* base, ParticleLayout layout, Index particles, Real w, const Grid& g,
                                    Real* rho) {
  deposit_all<6>(base, layout, particles, w, g, rho);
}
TSI_PARTICLE_KERNEL void deposit_cic(const Real* base, ParticleLayout layout, Index particles, Real w, const Grid& g,
                                     Real* rho) {
  deposit_all<2>(base, layout, particles, w, g, rho);
}
TSI_PARTICLE_KERNEL void interpolate_m6(const Real* base, ParticleLayout layout, Index particles, const Grid& g,
                                        const Real* e, Real* out) {
  interpolate_all<6>(base, layout, particles, g, e, out);
}
TSI_PARTICLE_KERNEL void interpolate_cic(const Real* base, ParticleLayout layout, Index particles, const Grid& g,
                                         const Real* e, Real* out) {
  interpolate_all<2>(base, layout, particles, g, e, out);
}

// n + width - 1 points along one direction. The particle loops index the padded grid with 32
// bits: n is at most 2^14 per direction (the model's own limit), so that the grid stays below 2^31.
Index padded_points(int n, int width, const char* name) {
  constexpr int largest = 1 << 14;
  if (n < 2 || n > largest)
    throw Error(std::string("vlasov-poisson-2d: ") + name + " = " + std::to_string(n) + ", expected an integer from 2 to " +
                std::to_string(largest));
  return static_cast<Index>(n) + width - 1;
}

}  // namespace

Real Geometry::length_x() const { return two_pi / k_x; }
Real Geometry::length_y() const { return two_pi / k_y; }

Field::Field(const Geometry& geometry, const Collective* collective)
    : g_(geometry),
      collective_(collective),
      width_(geometry.shape == Shape::cic ? 2 : 6),
      offset_(geometry.shape == Shape::cic ? 0 : 2),
      padded_x_(padded_points(geometry.n_x, width_, "n_x")),
      padded_y_(padded_points(geometry.n_y, width_, "n_y")),
      inverse_dx_(1.0 / geometry.dx()),
      inverse_dy_(1.0 / geometry.dy()),
      grid_({geometry.n_y, geometry.n_x}),
      transforms_(std::make_unique<RealGridTransforms>(grid_, 2)),
      padded_rho_(RealVector::Zero(padded_x_ * padded_y_)),
      padded_e_(RealVector::Zero(2 * padded_x_ * padded_y_)) {
  // Pieces of at least 2^15 particles, at most 16, and at most 64 MB of their grids.
  const Index cells = padded_x_ * padded_y_;
  deposit_parts_ = std::clamp<Index>(g_.particles >> 15, 1, 16);
  deposit_parts_ = std::max<Index>(1, std::min<Index>(deposit_parts_, (Index(8) << 20) / cells));
  part_rho_.resize((deposit_parts_ - 1) * cells);
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
  const Grid grid{inverse_dx_, inverse_dy_, Real(g_.n_x), Real(g_.n_y), Real(padded_x_)};
  const Index cells = padded_x_ * padded_y_, parts = deposit_parts_;
  const auto kernel = width_ == 2 ? deposit_cic : deposit_m6;
  parallel_for(g_.threads, parts, [&](Index p) {
    const Index first = g_.particles * p / parts, count = g_.particles * (p + 1) / parts - first;
    Real* rho = p == 0 ? padded_rho_.data() : part_rho_.data() + (p - 1) * cells;
    std::fill(rho, rho + cells, Real(0));
    kernel(base + first * layout.particle_stride, layout, count, g_.weight(), grid, rho);
  });
  for (Index p = 1; p < parts; ++p) padded_rho_ += part_rho_.segment((p - 1) * cells, cells);
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
  interpolate_into(base, layout, g_.particles, e_at_.data());
  e_at_solved_ = false;  // E at other positions than the field's own (the diagonal field)
  return e_at_.data();
}

void Field::interpolate_into(const Real* base, ParticleLayout layout, Index count, Real* out) const {
  const Grid grid{inverse_dx_, inverse_dy_, Real(g_.n_x), Real(g_.n_y), Real(padded_x_)};
  (width_ == 2 ? interpolate_cic : interpolate_m6)(base, layout, count, grid, padded_e_.data(), out);
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
