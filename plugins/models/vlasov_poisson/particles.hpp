#pragma once
// The initial particles of vlasov-poisson-2d: sampled with a seeded generator from a perturbed
// Maxwellian, or read from a file (a .npy N x 4 array of x1 x2 v1 v2, or the UA-PIC peer's raw
// little-endian float64 layout, the same four numbers per particle).
#include <cstdint>
#include <string>

#include "pic_field.hpp"

namespace tsi::pic {

/// The distributions the model samples.
enum class Distribution {
  landau,  ///< density 1 + alpha cos(k_x x1), Maxwellian velocities (unit temperature)
  peer     ///< the peer's: density 1 + sin(x2) + alpha cos(k_x x1), two streams at v1 = +-2 (truncated to [-5, 5]^2)
};

/// N particles (x1, x2, v1, v2) at entries 4k .. 4k + 3 of a real vector, by rejection from
/// the distribution with a 64-bit Mersenne twister seeded with `seed` (the same particles on
/// every machine with IEEE doubles and a correctly rounded libm).
RealVector sample_particles(const Geometry& geometry, Distribution distribution, Real alpha, std::uint64_t seed);

/// The particles of a file: `.npy` (float64 or float32 of shape (N, 4); a flat array, which does
/// not say how its values group, is refused), any other name the peer's raw layout (a multiple
/// of 32 bytes). A tsi::ConfigError naming model.particles for a file that cannot be read, of
/// the wrong shape or size, or with values that are not finite.
RealVector read_particles(const std::string& file);

/// Refuses (a tsi::ConfigError naming model.particles, the particle and its |v|) velocities
/// whose kinetic energy w |v|^2 / 2, or whose sum over the particles, overflows: the energy W
/// would be inf and its monitors NaN from the first step.
void check_energies(const RealVector& u, const Geometry& geometry, const std::string& file);

/// Refuses (a tsi::ConfigError naming model.particles) particles whose positions are farther
/// than one box length outside the box, [-L, 2L) per coordinate: a file in other units or of
/// another box. Positions a run has carried out of the box (tsi and the peer keep them
/// unwrapped) are kept as they are within that margin; tsi's state files (state.npy) hold them
/// wrapped into the box, so a run of any length can be resumed from them.
void check_positions(const RealVector& u, const Geometry& geometry, const std::string& file);

}  // namespace tsi::pic
