#include "particles.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "tsi/error.hpp"
#include "tsi/npy.hpp"
#include "tsi/phase.hpp"

namespace tsi::pic {
namespace {

// x in the fewest digits that read back to the same double: 2.5e+153, not 2.5000000000000001e+153.
std::string shortest(Real x) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, static_cast<double>(x)).ptr;
  return std::string(text, end);
}

// A Real in [0, 1) from the generator's top 53 bits: the same on every platform
// (std::uniform_real_distribution and std::generate_canonical are not specified that far).
Real uniform(std::mt19937_64& gen) { return static_cast<Real>(gen() >> 11) * 0x1.0p-53; }

}  // namespace

RealVector sample_particles(const Geometry& g, Distribution distribution, Real alpha, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  RealVector u(4 * g.particles);
  const Real lx = g.length_x(), ly = g.length_y();
  for (Index k = 0; k < g.particles; ++k) {
    Real x1 = 0.0, x2 = 0.0;
    if (distribution == Distribution::landau) {
      for (;;) {  // x1 by rejection under 1 + alpha, x2 uniform
        x1 = uniform(gen) * lx;
        if (uniform(gen) * (1.0 + alpha) <= 1.0 + alpha * std::cos(g.k_x * x1)) break;
      }
      x2 = uniform(gen) * ly;
    } else {
      for (;;) {
        x1 = uniform(gen) * lx;
        x2 = uniform(gen) * ly;
        if (uniform(gen) * (2.0 + alpha) <= 1.0 + std::sin(x2) + alpha * std::cos(g.k_x * x1)) break;
      }
    }
    Real v1 = 0.0, v2 = 0.0;
    if (distribution == Distribution::landau) {  // Box-Muller
      const Real r = std::sqrt(-2.0 * std::log(1.0 - uniform(gen))), theta = two_pi * uniform(gen);
      v1 = r * std::cos(theta);
      v2 = r * std::sin(theta);
    } else {
      for (;;) {
        v1 = (uniform(gen) - 0.5) * 10.0;
        v2 = (uniform(gen) - 0.5) * 10.0;
        const Real f = 0.5 * (std::exp(-((v1 - 2.0) * (v1 - 2.0) + v2 * v2) / 2.0) +
                                std::exp(-((v1 + 2.0) * (v1 + 2.0) + v2 * v2) / 2.0));
        if (uniform(gen) <= f) break;
      }
    }
    u.segment(4 * k, 4) << x1, x2, v1, v2;
  }
  return u;
}

RealVector read_particles(const std::string& file) {
  const auto refuse = [&](const std::string& what) {
    return ConfigError("model.particles", file + ": " + what);
  };
  RealVector u;
  if (std::filesystem::path(file).extension() == ".npy") {
    // The header first: a file of the wrong shape or size is refused before its data are read.
    NpyHeader header;
    try {
      header = read_npy_header(file);
    } catch (const Error& e) {
      throw ConfigError("model.particles", e.what());
    }
    const auto& shape = header.shape;
    const std::string got = "an array of shape " + npy_shape_text(shape) + " ('" + header.descr + "')";
    const char* const expected = "expected float64 of shape (N, 4), N >= 1: one row x1 x2 v1 v2 per particle";
    // A flat array does not say how its values group into particles (x1 x2 v1 v2 each, or every x1 first).
    if (shape.size() == 1)
      throw refuse(got + ", " + expected + "; a flat array does not say how its values group into particles: save "
                                           "p.reshape(-1, 4) if they go particle by particle");
    if (shape.size() != 2 || shape[1] != 4)
      throw refuse(got + ", " + expected +
                   (shape.size() == 2 && shape[1] > 4
                        ? "; weights or charges are not read: every particle has the weight |box| / N of a unit "
                          "mean density, so keep the four columns x1 x2 v1 v2"
                        : ""));
    if (header.is_complex) throw refuse(got + ": complex values, " + expected);
    if (shape[0] == 0) throw refuse(got + ": no particles, " + expected);
    if (shape[0] > (std::uint64_t{1} << 28))
      throw refuse(got + ": " + std::to_string(shape[0]) + " particles, expected at most 2^28");
    NpyArray array;
    try {
      array = read_npy(file);
    } catch (const Error& e) {
      throw ConfigError("model.particles", e.what());
    }
    if (array.header.shape != shape)  // the file was replaced between the two reads
      throw refuse("an array of shape " + npy_shape_text(array.header.shape) + ", " + expected);
    u = array.values.real();
  } else {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(file, ec);
    if (ec) throw refuse("cannot read it (" + ec.message() + ")");
    if (bytes == 0 || bytes % 32 != 0)
      throw refuse(std::to_string(bytes) +
                   " bytes, expected a positive multiple of 32 (the raw layout: 4 little-endian float64 per particle; "
                   "a NumPy file must end in .npy)");
    if (bytes / 32 > (std::uintmax_t{1} << 28))
      throw refuse(std::to_string(bytes / 32) + " particles, expected at most 2^28");
    Eigen::VectorXd raw(static_cast<Index>(bytes / 8));  // float64 on disk, whatever Real is
    std::ifstream in(file, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(bytes)))
      throw refuse("cannot read it");
    u = raw.cast<Real>();
  }
  if (u.size() / 4 > (Index{1} << 28)) throw refuse(std::to_string(u.size() / 4) + " particles, expected at most 2^28");
  static constexpr const char* names[4] = {"x1", "x2", "v1", "v2"};
  for (Index i = 0; i < u.size(); ++i)
    if (!std::isfinite(u(i))) {
      std::ostringstream what;
      what << "particle " << i / 4 << " has " << names[i % 4] << " = " << u(i) << "; expected finite values";
      throw refuse(what.str());
    }
  return u;
}

void check_energies(const RealVector& u, const Geometry& geometry, const std::string& file) {
  const Real weight = geometry.weight();
  // The largest |v| whose w |v|^2 / 2 is a finite double.
  const Real limit = std::sqrt(2.0 / weight) * std::sqrt(std::numeric_limits<Real>::max());
  Real kinetic = 0.0;
  for (Index k = 0; k < u.size() / 4; ++k) {
    const Real v1 = u(4 * k + 2), v2 = u(4 * k + 3), energy = 0.5 * weight * (v1 * v1 + v2 * v2);
    kinetic += energy;
    if (std::isfinite(energy) && std::isfinite(kinetic)) continue;
    std::ostringstream what;
    what << file << ": particle " << k << " has |v| = " << shortest(std::hypot(v1, v2)) << " (v1 = " << shortest(v1)
         << ", v2 = " << shortest(v2) << "): "
         << (std::isfinite(energy) ? "with it the total kinetic energy sum w |v|^2 / 2" : "its kinetic energy w |v|^2 / 2")
         << " overflows to inf (w = |box| / N = " << shortest(weight)
         << "), and the energy W and the run's monitors with it";
    what.precision(3);
    what << "; expected velocities of finite energy (|v| well below " << limit << "; a file in other units?)";
    throw ConfigError("model.particles", what.str());
  }
}

void check_positions(const RealVector& u, const Geometry& geometry, const std::string& file) {
  const Real lengths[2] = {geometry.length_x(), geometry.length_y()};
  for (Index k = 0; k < u.size() / 4; ++k)
    for (int c = 0; c < 2; ++c) {
      const Real x = u(4 * k + c), length = lengths[c];
      if (x >= -length && x < 2.0 * length) continue;
      std::ostringstream what;
      what.precision(17);
      what << file << ": particle " << k << " has x" << c + 1 << " = " << x << ", outside [-L, 2L) for the box [0, L) = [0, "
           << length << ") (k_" << (c == 0 ? "x" : "y") << " = " << (c == 0 ? geometry.k_x : geometry.k_y)
           << "); expected positions in the box, or carried out of it by a run by less than its length (a file in "
              "other units, or of another box?)";
      throw ConfigError("model.particles", what.str());
    }
}

}  // namespace tsi::pic
