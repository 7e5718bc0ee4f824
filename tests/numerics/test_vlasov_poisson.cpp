// vlasov-poisson-2d, the particle-in-cell plasma (SPEC.md section 7): its field against a
// naive implementation of the same definition (deposition, discrete Fourier sums, the peer's
// wave numbers and c2r's reading of the half spectrum, interpolation), its invariants (the charge
// exactly, the momentum turning with the magnetic field), and its particles from files.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "harness.hpp"
#include "tsi/error.hpp"
#include "tsi/npy.hpp"

namespace {

using tsi::Complex;
using tsi::Index;
using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

constexpr double pi = 3.14159265358979323846;

// CIC weights of coordinate x on n cells of width d: nodes i, i + 1 (mod n).
void cic(double x, double d, int n, int node[2], double w[2]) {
  double p = std::fmod(x / d, static_cast<double>(n));
  if (p < 0.0) p += n;
  const int i = static_cast<int>(std::floor(p)) % n;
  const double f = p - std::floor(p);
  node[0] = i;
  node[1] = (i + 1) % n;
  w[0] = 1.0 - f;
  w[1] = f;
}

// E at the particles from the definition, by sums: rho deposited with CIC and its mean taken
// off, rho^ by the DFT, E^ = -i k rho^ / |k|^2 with k_x = 0 .. n_x/2 (the half spectrum) and
// k_y in FFT order, E by the inverse DFT read as FFTW's c2r reads a half spectrum (the real
// parts of the k_x = 0 and n_x/2 bins), E at each particle by the same CIC weights.
std::vector<std::array<double, 2>> naive_field(const std::vector<std::array<double, 4>>& particles, int nx, int ny,
                                               double kx, double ky) {
  const double lx = 2 * pi / kx, ly = 2 * pi / ky, dx = lx / nx, dy = ly / ny;
  const double w = lx * ly / static_cast<double>(particles.size());
  std::vector<double> rho(static_cast<std::size_t>(nx * ny), 0.0);  // rho[jy * nx + ix]
  for (const auto& p : particles) {
    int ix[2], jy[2];
    double wx[2], wy[2];
    cic(p[0], dx, nx, ix, wx);
    cic(p[1], dy, ny, jy, wy);
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) rho[static_cast<std::size_t>(jy[b] * nx + ix[a])] += w * wx[a] * wy[b] / (dx * dy);
  }
  double mean = 0.0;
  for (double r : rho) mean += r / (nx * ny);
  for (double& r : rho) r -= mean;
  std::vector<double> e1(rho.size()), e2(rho.size());
  for (int jy = 0; jy < ny; ++jy)
    for (int ix = 0; ix < nx; ++ix) {
      Complex s1 = 0.0, s2 = 0.0;
      for (int my = 0; my < ny; ++my) {
        const double wave_y = ky * (my < ny / 2 ? my : my - ny);
        for (int mx = 0; mx <= nx / 2; ++mx) {
          const double wave_x = kx * mx, k2 = wave_x * wave_x + wave_y * wave_y;
          Complex rho_hat = 0.0;
          for (int qy = 0; qy < ny; ++qy)
            for (int qx = 0; qx < nx; ++qx)
              rho_hat += rho[static_cast<std::size_t>(qy * nx + qx)] *
                         std::exp(Complex(0.0, -2 * pi * (double(mx * qx) / nx + double(my * qy) / ny)));
          const Complex f1 = k2 > 0 ? Complex(0.0, -wave_x / k2) * rho_hat : 0.0;
          const Complex f2 = k2 > 0 ? Complex(0.0, -wave_y / k2) * rho_hat : 0.0;
          // The inverse along y is complex; along x c2r takes twice the real part of the inner
          // bins and the real part alone of the first and the last.
          const Complex phase_y = std::exp(Complex(0.0, 2 * pi * double(my * jy) / ny));
          const Complex phase_x = std::exp(Complex(0.0, 2 * pi * double(mx * ix) / nx));
          const double factor = (mx == 0 || mx == nx / 2) ? 1.0 : 2.0;
          if (mx == 0 || mx == nx / 2) {
            s1 += factor * std::real(f1 * phase_y) * std::real(phase_x);
            s2 += factor * std::real(f2 * phase_y) * std::real(phase_x);
          } else {
            s1 += factor * std::real(f1 * phase_y * phase_x);
            s2 += factor * std::real(f2 * phase_y * phase_x);
          }
        }
      }
      e1[static_cast<std::size_t>(jy * nx + ix)] = s1.real() / (nx * ny);
      e2[static_cast<std::size_t>(jy * nx + ix)] = s2.real() / (nx * ny);
    }
  std::vector<std::array<double, 2>> out;
  for (const auto& p : particles) {
    int ix[2], jy[2];
    double wx[2], wy[2];
    cic(p[0], dx, nx, ix, wx);
    cic(p[1], dy, ny, jy, wy);
    std::array<double, 2> e{0.0, 0.0};
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        e[0] += wx[a] * wy[b] * e1[static_cast<std::size_t>(jy[b] * nx + ix[a])];
        e[1] += wx[a] * wy[b] * e2[static_cast<std::size_t>(jy[b] * nx + ix[a])];
      }
    out.push_back(e);
  }
  return out;
}

}  // namespace

TEST_CASE("vlasov-poisson-2d: f = (v, E(x)) with E from deposition, Poisson and interpolation as defined") {
  // Five particles, two of them outside the box (periodic), on an 8 x 6 grid of [0, 4 pi) x [0, 2 pi).
  const std::vector<std::array<double, 4>> particles = {{{0.3, 0.2, 0.5, -1.0}},
                                                        {{5.1, 3.3, -0.2, 0.7}},
                                                        {{11.9, 6.1, 1.5, 0.1}},
                                                        {{-2.0, 7.0, 0.0, -0.4}},
                                                        {{14.0, -1.3, 0.9, 0.9}}};
  auto& h = Harness::instance();
  auto model = h.model_with("vlasov-poisson-2d", 0.1,
                            {{"particles", 5}, {"n_x", 8}, {"n_y", 6}, {"k_x", 0.5}, {"k_y", 1.0}, {"shape", "cic"}});
  REQUIRE(model->dim() == 20);
  CHECK_FALSE(model->is_complex());
  Vector u(20);
  for (Index k = 0; k < 5; ++k)
    for (Index c = 0; c < 4; ++c) u(4 * k + c) = particles[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)];
  const Vector f = model->nonlinear_field(u);
  const auto expected = naive_field(particles, 8, 6, 0.5, 1.0);
  double scale = 0.0;
  for (const auto& e : expected) scale = std::max({scale, std::abs(e[0]), std::abs(e[1])});
  REQUIRE(scale > 0.1);  // a field worth comparing
  for (Index k = 0; k < 5; ++k) {
    CAPTURE(k);
    CHECK(f(4 * k) == u(4 * k + 2));
    CHECK(f(4 * k + 1) == u(4 * k + 3));
    CHECK(std::abs(f(4 * k + 2).real() - expected[static_cast<std::size_t>(k)][0]) <= 1e-13 * scale);
    CHECK(std::abs(f(4 * k + 3).real() - expected[static_cast<std::size_t>(k)][1]) <= 1e-13 * scale);
  }
  // e^{A tau} turns v by R(tau) = exp(tau J) and leaves x.
  const Vector turned = model->linear_flow(0.7, u);
  CHECK(turned(0) == u(0));
  CHECK(std::abs(turned(2) - (std::cos(0.7) * u(2) + std::sin(0.7) * u(3))) < 1e-15);
  CHECK(std::abs(turned(3) - (-std::sin(0.7) * u(2) + std::cos(0.7) * u(3))) < 1e-15);
}

TEST_CASE("vlasov-poisson-2d: the density of 10^5 particles, deposited by pieces on two threads, is the definition's") {
  // 3 x 2^15 + 17 particles: the deposition goes by three pieces, each on its own grid, summed
  // in order. E against the naive sums of the definition, and alike on one and two threads.
  constexpr Index n = 3 * (Index(1) << 15) + 17;
  std::vector<std::array<double, 4>> particles(static_cast<std::size_t>(n));
  std::uint64_t state = 12345;
  const auto uniform = [&state]() {  // a 64-bit LCG: the test's own numbers, nothing of tsi's
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (auto& p : particles) p = {4 * pi * uniform(), 2 * pi * (0.5 + 0.5 * uniform() * uniform()), 0.0, 0.0};
  Vector u(4 * n);
  for (Index k = 0; k < n; ++k)
    for (Index c = 0; c < 4; ++c) u(4 * k + c) = particles[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)];
  auto& h = Harness::instance();
  const auto field = [&](int threads) {
    tsi::test::ContextSetting setting(tsi::test::ContextSetting::tau_grid(threads, 1));
    auto model = h.model_with("vlasov-poisson-2d", 0.1, {{"particles", n}, {"n_x", 8}, {"n_y", 6}, {"shape", "cic"}});
    return Vector(model->nonlinear_field(u));
  };
  const Vector one = field(1), two = field(2);
  CHECK((one - two).cwiseAbs().maxCoeff() == 0.0);
  const auto expected = naive_field(particles, 8, 6, 0.5, 1.0);
  double scale = 0.0, worst = 0.0;
  for (const auto& e : expected) scale = std::max({scale, std::abs(e[0]), std::abs(e[1])});
  REQUIRE(scale > 0.1);  // the density is not uniform in x2: a field worth comparing
  for (Index k = 0; k < n; ++k)
    for (int c = 0; c < 2; ++c)
      worst = std::max(worst, std::abs(two(4 * k + 2 + c).real() - expected[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)]));
  // The density sums 10^5 weights per node, in another order than the naive loop's.
  CHECK(worst <= 1e-13 * scale);  // measured 7.9e-15
}

TEST_CASE("vlasov-poisson-2d: the charge is the box's, and the momentum turns with the field") {
  // SE1, eps = 0.1, h = 1/8, T = 1, 256 sampled particles (M6). P(t) = R(t/eps) P(0) for the
  // particle system (the self-force sums to zero), so |P| is kept; Q = |box| = 8 pi^2 exactly.
  auto& h = Harness::instance();
  tsi::Assembly a = h.assemble({{"model", {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}}},
                                {"reformulation", {{"name", "two-scale"}}},
                                {"scheme", {{"name", "se1"}}}});
  const auto invariants = a.model->invariants();
  REQUIRE(invariants.size() == 4);  // W, P, Q and the electric energy W_E, a diagnostic
  CHECK(invariants[3].name == "W_E");
  CHECK_FALSE(invariants[3].conserved);
  const auto value = [&](const char* name, const Vector& u) {
    for (const auto& inv : invariants)
      if (inv.name == name) return inv.value(u);
    FAIL("no invariant ", name);
    return 0.0;
  };
  const double p0 = value("P", a.u0);
  CHECK(value("Q", a.u0) == doctest::Approx(8.0 * pi * pi).epsilon(1e-14));
  // W = the kinetic energy + W_E, the kinetic energy summed here on its own.
  double kinetic = 0.0;
  for (tsi::Index k = 0; k < a.u0.size() / 4; ++k) kinetic += 0.5 * (std::norm(a.u0(4 * k + 2)) + std::norm(a.u0(4 * k + 3)));
  kinetic *= 8.0 * pi * pi / static_cast<double>(a.u0.size() / 4);
  CHECK(value("W_E", a.u0) > 0.0);
  CHECK(value("W", a.u0) == doctest::Approx(kinetic + value("W_E", a.u0)).epsilon(1e-14));
  Vector y = a.reformulation->prepare(a.u0);
  double worst = 0.0;
  tsi::integrate(a.bind(0.125), y, 8, [&](long, double t, const Vector& state) {
    const Vector u = a.reformulation->read_back(state, t);
    worst = std::max(worst, std::abs(value("P", u) - p0) / p0);
    CHECK(value("Q", u) == doctest::Approx(8.0 * pi * pi).epsilon(1e-14));
    return true;
  }, a.reformulation->repreparation());
  CAPTURE(p0);
  CHECK(p0 > 0.0);
  CHECK(worst < 1e-12);  // measured 1.4e-14 (4096 particles)
}

TEST_CASE("vlasov-poisson-2d: particles from a .npy N x 4 array and from the peer's raw layout") {
  const auto dir = std::filesystem::temp_directory_path() / "tsi_test_vlasov_poisson";
  std::filesystem::create_directories(dir);
  const std::vector<double> values = {0.3, 0.2, 0.5, -1.0, 5.1, 3.3, -0.2, 0.7, 11.9, 6.1, 1.5, 0.1};
  const std::string npy = (dir / "particles.npy").string(), raw = (dir / "particles.bin").string();
  tsi::write_npy(npy, std::span<const double>(values), {3, 4});
  {
    std::ofstream out(raw, std::ios::binary);
    out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * 8));
  }
  auto& h = Harness::instance();
  for (const std::string& file : {npy, raw}) {
    CAPTURE(file);
    auto model = h.model_with("vlasov-poisson-2d", 0.1, {{"particles", file}});
    REQUIRE(model->dim() == 12);
    const Vector u0 = model->initial_value();
    for (Index i = 0; i < 12; ++i) CHECK(u0(i) == values[static_cast<std::size_t>(i)]);
    CHECK(model->physical_shape() == std::vector<Index>{3, 4});
  }
  // A raw file of a size that is not whole particles, and a missing file, name the field.
  {
    std::ofstream out((dir / "odd.bin").string(), std::ios::binary);
    out.write(reinterpret_cast<const char*>(values.data()), 40);
  }
  CHECK_THROWS_WITH_AS(h.model_with("vlasov-poisson-2d", 0.1, {{"particles", (dir / "odd.bin").string()}}),
                       doctest::Contains("model.particles"), tsi::ConfigError);
  CHECK_THROWS_WITH_AS(h.model_with("vlasov-poisson-2d", 0.1, {{"particles", (dir / "missing.bin").string()}}),
                       doctest::Contains("model.particles"), tsi::ConfigError);
  // Non-finite values, and a position more than a box length outside the box (the default box
  // is [0, 4 pi) x [0, 2 pi)), name the particle and the coordinate; 11.9 + 4 pi, carried out
  // by a run, is kept.
  const auto refused = [&](Index at, double value, const char* expected) {
    std::vector<double> changed = values;
    changed[static_cast<std::size_t>(at)] = value;
    const std::string file = (dir / "changed.npy").string();
    tsi::write_npy(file, std::span<const double>(changed), {3, 4});
    CHECK_THROWS_WITH_AS(h.model_with("vlasov-poisson-2d", 0.1, {{"particles", file}}), doctest::Contains(expected),
                         tsi::ConfigError);
  };
  refused(5, std::nan(""), "particle 1 has x2 = nan");
  refused(7, INFINITY, "particle 1 has v2 = inf");
  refused(8, 3.0 * 4.0 * pi, "particle 2 has x1 = 37.69");
  refused(1, -6.3, "particle 0 has x2 = -6.2999");
  {
    std::vector<double> carried = values;
    carried[8] += 4.0 * pi;
    const std::string file = (dir / "carried.npy").string();
    tsi::write_npy(file, std::span<const double>(carried), {3, 4});
    CHECK(h.model_with("vlasov-poisson-2d", 0.1, {{"particles", file}})->initial_value()(8) == carried[8]);
  }
  std::filesystem::remove_all(dir);
}

namespace {

// Particles of the UA-PIC peer's raw dumps (tests/data/uapic: UAPIC.jl's fortran/bupdate.F90
// with b = 1, N = 2048, built outside tsi; tests/data/uapic/README.md says how), as an N x 4 array.
Eigen::Array<double, Eigen::Dynamic, 4, Eigen::RowMajor> peer_particles(const std::string& name) {
  const std::string path = std::string(TSI_TEST_SOURCE_DIR) + "/tests/data/uapic/" + name;
  std::ifstream in(path, std::ios::binary);
  REQUIRE_MESSAGE(in.good(), "cannot read ", path);
  Eigen::Array<double, Eigen::Dynamic, 4, Eigen::RowMajor> p(2048, 4);
  in.read(reinterpret_cast<char*>(p.data()), static_cast<std::streamsize>(sizeof(double) * p.size()));
  REQUIRE(in.gcount() == static_cast<std::streamsize>(sizeof(double) * p.size()));
  return p;
}

// tsi's etd2rk run from the peer's initial particles in the peer's set-up (eps = 0.1, 128 x 64
// cells, M6, n_tau = 16, dt = pi/16, re-prepared every step with the first-order corrected
// data, the field frozen along tau, the Nyquist mode averaged), after `steps` steps: the
// largest relative difference of one particle's (x, v) from the peer's.
double largest_difference(long steps, const std::string& peer) {
  auto& h = Harness::instance();
  const double dt = pi / 16.0;
  tsi::Assembly a = h.assemble(
      {{"model",
        {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}, {"n_x", 128}, {"n_y", 64}, {"shape", "m6"},
         {"particles", std::string(TSI_TEST_SOURCE_DIR) + "/tests/data/uapic/n2048_init.bin"},
         {"tau_field", "diagonal"}}},
       {"reformulation",
        {{"name", "two-scale"}, {"n_tau", 16}, {"initial_data_order", 2}, {"reprepare", 1}, {"nyquist", "average"}}},
       {"scheme", {{"name", "etd2rk"}}}});
  Vector y = a.reformulation->prepare(a.u0);
  tsi::integrate(a.bind(dt), y, steps, [](long, double, const Vector&) { return true; }, a.reformulation->repreparation());
  const Vector u = a.reformulation->read_back(y, static_cast<double>(steps) * dt);
  const auto expected = peer_particles(peer);
  double worst = 0.0;
  for (tsi::Index k = 0; k < expected.rows(); ++k) {
    double diff = 0.0, norm = 0.0;
    for (int c = 0; c < 4; ++c) {
      diff += std::norm(u(4 * k + c) - expected(k, c));
      norm += expected(k, c) * expected(k, c);
    }
    worst = std::max(worst, std::sqrt(diff / norm));
  }
  return worst;
}

}  // namespace

TEST_CASE("vlasov-poisson-2d: etd2rk reproduces the UA-PIC peer's first step and, with its field refreshed, its 8 steps") {
  // Measured 1.3e-15 (one step) and 5e-15 (8 steps) at N = 204,800 with the peer's own particles.
  CHECK(largest_difference(1, "n2048_step1.bin") < 1e-12);
  CHECK(largest_difference(8, "n2048_step8_fresh_field.bin") < 1e-12);
  // The unmodified peer prepares steps 2 .. 8 with E(0, x_0) (its stale particles%e): tsi,
  // which prepares each step from its own state, differs from it by that alone.
  CHECK(largest_difference(8, "n2048_step8_peer.bin") > 1e-4);
}

TEST_CASE("vlasov-poisson-2d: the diagonal field by blocks of particles is the whole grid's, on any number of threads") {
  // Frozen along tau, the diagonal's field makes each particle's f its own: the real tau grid
  // then goes 64 particles at a time (TauGridField::evaluate_rows_real), the complex one
  // (real_layout false) through the whole grid. 1000 particles: a last block of 40.
  auto& h = Harness::instance();
  const auto run = [&](bool real_layout) {
    tsi::Assembly a = h.assemble(
        {{"model",
          {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}, {"n_x", 32}, {"n_y", 16}, {"particles", 1000},
           {"distribution", "peer"}, {"alpha", 0.5}, {"tau_field", "diagonal"}}},
         {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}, {"real_layout", real_layout}}},
         {"scheme", {{"name", "etd2rk"}}}});
    Vector y = a.reformulation->prepare(a.u0);
    tsi::integrate(a.bind(0.1), y, 3, [](long, double, const Vector&) { return true; },
                   a.reformulation->repreparation());
    return Vector(a.reformulation->read_back(y, 0.3));
  };
  const Vector whole_grid = run(false);
  const Vector blocks = run(true);
  CHECK((blocks - whole_grid).norm() / whole_grid.norm() < 1e-13);
  CHECK((blocks - whole_grid).norm() > 0.0);  // two routes: rounding apart, not the same code
  tsi::test::ContextSetting two_threads(tsi::test::ContextSetting::tau_grid(2, 1));
  const Vector threaded = run(true);
  CHECK((threaded - blocks).cwiseAbs().maxCoeff() == 0.0);  // each block alike on any thread
}
