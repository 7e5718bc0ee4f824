#pragma once
// The particle-in-cell field of vlasov-poisson-2d (SPEC.md section 7): the charge density
// deposited from the particles on an n_x x n_y grid of the periodic box [0, 2 pi / k_x) x
// [0, 2 pi / k_y), -lap phi = rho - mean(rho) solved by FFT, and E = -grad phi interpolated
// back at the particles with the deposition's own shape function (so that the self-force sums
// to zero and the total momentum turns with the magnetic field).
#include <memory>

#include "tsi/collective.hpp"
#include "tsi/spectral_grid.hpp"
#include "tsi/types.hpp"

namespace tsi::pic {

/// The shape function of deposition and interpolation: cloud in cell (linear, 2 x 2 nodes) or
/// the quintic B-spline M6 (6 x 6 nodes; the UA-PIC peer's 7 x 7 stencil, whose outer weight is 0).
enum class Shape { cic, m6 };

/// The box, its grid and the particles' common weight.
struct Geometry {
  int n_x = 16, n_y = 16;
  Real k_x = 0.5, k_y = 1.0;
  Shape shape = Shape::m6;
  Index particles = 1;       ///< the particles this process holds
  Index all_particles = 0;   ///< the plasma's, when split over processes (0: the same)
  int threads = 1;           ///< the run's (its tau-grid threads): the deposition's pieces go on them

  Real length_x() const;
  Real length_y() const;
  Real dx() const { return length_x() / n_x; }
  Real dy() const { return length_y() / n_y; }
  /// |box| / N: the particles carry the box's unit mean density between them.
  Real weight() const {
    return length_x() * length_y() / static_cast<Real>(all_particles > 0 ? all_particles : particles);
  }
};

/// Where a state column keeps particle k's x1, x2, v1, v2: at base[k * particle_stride +
/// c * component_stride], c = 0 .. 3 (a real column: strides 4 and 1; a complex one read as
/// doubles, real parts: 8 and 2).
struct ParticleLayout {
  Index particle_stride = 4, component_stride = 1;
};

/// The grid field of one set of particle positions, with its own buffers and transforms (one
/// per thread of a tau grid). Deposition and interpolation work on grids padded by the
/// stencil's width (the nodes of a particle are contiguous there, never wrapped one by one);
/// the padding is folded onto the periodic grid after a deposition and filled from it before
/// an interpolation. With a Collective (a run split over processes), the density is summed
/// over them before the solve, so every process has the whole plasma's field, and each call
/// is collective: every process makes the same calls in the same order.
class Field {
 public:
  explicit Field(const Geometry& geometry, const Collective* collective = nullptr);
  ~Field();
  Field(const Field&) = delete;
  Field& operator=(const Field&) = delete;

  /// rho deposited from the positions of the N particles at `base` (layout), then E; nothing
  /// to do for the positions of the last solve (the columns of the constant grid order-2 data
  /// evaluate, or W, Q and W_E of one state, share one solve).
  void solve(const Real* base, ParticleLayout layout);
  /// E at each of the N particles at `base`: (E1, E2) of particle k at 2k, 2k + 1, from the
  /// field of these same positions (computed once for the positions of the last solve).
  const Real* at_particles(const Real* base, ParticleLayout layout);
  /// E of the last solve at each of the N particles at `base` (as at_particles' values).
  const Real* interpolate(const Real* base, ParticleLayout layout);
  /// Readies the last solve's field for interpolate_into (one thread, before them).
  void prepare_interpolation() { pad_field(); }
  /// E of the last solve at the `count` particles at `base`, (E1, E2) of particle k at out[2k],
  /// out[2k + 1], after prepare_interpolation. Const: threads may call it at once.
  void interpolate_into(const Real* base, ParticleLayout layout, Index count, Real* out) const;
  /// (1/2) int |E|^2 over the box (the grid's rectangle rule) of the last solve.
  Real field_energy() const;
  /// int rho over the box before the mean was taken off (N w = |box| when nothing is lost).
  Real charge() const { return charge_; }

 private:
  void deposit(const Real* base, ParticleLayout layout);
  void poisson();
  void pad_field();
  bool same_positions(const Real* base, ParticleLayout layout) const;

  Geometry g_;
  const Collective* collective_;
  int width_, offset_;          // stencil nodes first - offset .. first - offset + width - 1
  Index padded_x_, padded_y_;   // n + width - 1
  Real inverse_dx_, inverse_dy_;
  SpectralGrid grid_;  // (n_y, n_x) in C order: x the last direction, halved by the real transforms
  std::unique_ptr<RealGridTransforms> transforms_;  // 2 columns: rho, then E1 and E2
  RealVector padded_rho_;  // padded_y x padded_x, x fastest
  // The deposition goes by deposit_parts_ contiguous pieces of the particles, each on its own
  // padded grid, summed in order: a number fixed by N and the grid, not by the threads, so
  // the density is the same on any number of them.
  Index deposit_parts_ = 1;
  RealVector part_rho_;  // deposit_parts_ - 1 padded grids (piece 0 goes to padded_rho_)
  RealVector padded_e_;    // the same points, (E1, E2) pairs
  bool padded_current_ = false;                    // padded E is the last solve's
  RealVector k1_, k2_, inverse_k2_;  // per point of the half spectrum
  RealVector x_solved_;  // the positions of the last solve
  bool solved_ = false;
  RealVector e_at_;           // E at the particles of the last interpolation
  bool e_at_solved_ = false;  // ... and those are the positions of the last solve
  Real charge_ = 0.0;
};

}  // namespace tsi::pic
