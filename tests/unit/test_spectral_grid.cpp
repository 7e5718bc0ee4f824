// tsi::SpectralGrid and tsi::GridTransforms: the layout (C order, FFT order per direction), the
// symbols, and the batched d-dimensional transforms against plane waves computed by hand.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>

#include "tsi/error.hpp"
#include "tsi/phase.hpp"
#include "tsi/spectral_grid.hpp"

namespace {

using tsi::Complex;
using tsi::Index;

TEST_CASE("spectral grid: C order, wave numbers, |m|^2, the 2/3 mask and the coordinates") {
  const tsi::SpectralGrid grid({4, 6, 8});
  CHECK(grid.points() == 192);
  CHECK(grid.describe() == "4 x 6 x 8");
  CHECK(grid.wave_number(1, 2) == 2);
  CHECK(grid.wave_number(1, 3) == -3);  // the Nyquist index as -n/2
  CHECK(grid.wave_number(2, 7) == -1);
  // Point (a, b, c) at (a 6 + b) 8 + c: (1, 5, 6) has m = (1, -1, -2), |m|^2 = 6.
  CHECK(grid.laplacian_symbol()((1 * 6 + 5) * 8 + 6) == 6.0);
  CHECK(grid.laplacian_symbol()((2 * 6 + 3) * 8 + 4) == 4.0 + 9.0 + 16.0);  // the three Nyquist modes
  CHECK(grid.max_laplacian_symbol() == 29.0);
  // 2/3 rule: kept where 3 |m_i| <= n_i: |m_1| <= 1 (3 of 4), |m_2| <= 2 (5 of 6), |m_3| <= 2 (5 of 8).
  CHECK(grid.dealias_mask().sum() == 3.0 * 5.0 * 5.0);
  int visited = 0;
  grid.for_each_point([&](Index p, const std::array<double, 3>& x) {
    if (p == (1 * 6 + 5) * 8 + 6) {
      CHECK(x[0] == doctest::Approx(tsi::two_pi / 4));
      CHECK(x[1] == doctest::Approx(5 * tsi::two_pi / 6));
      CHECK(x[2] == doctest::Approx(6 * tsi::two_pi / 8));
    }
    ++visited;
  });
  CHECK(visited == 192);
}

TEST_CASE("spectral grid: a plane wave transforms to one coefficient, in every column of a batch") {
  // Small grids go through one batched plan, from 4096 points the multi-dimensional ones by direction.
  for (const std::vector<int>& shape : {std::vector<int>{8}, std::vector<int>{6, 4}, std::vector<int>{4, 6, 8},
                                        std::vector<int>{64, 64}, std::vector<int>{128, 32}, std::vector<int>{16, 8, 32}}) {
    const tsi::SpectralGrid grid(shape);
    tsi::GridTransforms transforms(grid, 3);
    auto data = transforms.data();
    REQUIRE(data.rows() == grid.points());
    // Column j holds e^{i k_j . x} for three wave vectors; k = (1, -1, 2) truncated to the dims.
    const std::array<std::array<int, 3>, 3> waves = {{{1, -1, 2}, {0, 2, -3}, {-1, 0, 1}}};
    grid.for_each_point([&](Index p, const std::array<double, 3>& x) {
      for (Index j = 0; j < 3; ++j) {
        double phase = 0.0;
        for (int i = 0; i < grid.dims(); ++i) phase += waves[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] * x[static_cast<std::size_t>(i)];
        data(p, j) = std::polar(1.0, phase);
      }
    });
    const tsi::Matrix samples = data;
    transforms.forward();
    for (Index j = 0; j < 3; ++j) {
      // The coefficient of k sits at index k mod n in each direction, C order; it is N.
      Index at = 0;
      for (int i = 0; i < grid.dims(); ++i) {
        const int n = shape[static_cast<std::size_t>(i)];
        at = at * n + ((waves[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] % n + n) % n);
      }
      CAPTURE(grid.describe());
      CAPTURE(j);
      CHECK(std::abs(data(at, j) - Complex(static_cast<double>(grid.points()))) < 1e-14 * static_cast<double>(grid.points()));
      CHECK(data.col(j).norm() == doctest::Approx(static_cast<double>(grid.points())).epsilon(1e-13));
    }
    transforms.backward();  // backward(forward(a)) = N a
    CHECK((data - static_cast<double>(grid.points()) * samples).norm() < 1e-11 * samples.norm() * static_cast<double>(grid.points()));
  }
}

TEST_CASE("spectral grid: a shape of 0 or 4 directions, or an odd size, is an error that says so") {
  CHECK_THROWS_WITH_AS(tsi::SpectralGrid({}), doctest::Contains("expected 1, 2 or 3"), tsi::Error);
  CHECK_THROWS_WITH_AS(tsi::SpectralGrid({4, 4, 4, 4}), doctest::Contains("expected 1, 2 or 3"), tsi::Error);
  CHECK_THROWS_WITH_AS(tsi::SpectralGrid({4, 5}), doctest::Contains("direction 2 has 5 points"), tsi::Error);
}

}  // namespace

namespace {

TEST_CASE("spectral grid: real-to-complex transforms give the complex transform's half spectrum, and back") {
  // Batched (small grids) and by direction (from 4096 points), with odd half widths (n_d/2 + 1).
  for (const std::vector<int>& shape : {std::vector<int>{8}, std::vector<int>{6, 4}, std::vector<int>{4, 6, 10},
                                        std::vector<int>{64, 64}, std::vector<int>{32, 128}, std::vector<int>{16, 8, 34}}) {
    const tsi::SpectralGrid grid(shape);
    CAPTURE(grid.describe());
    tsi::RealGridTransforms real(grid, 2);
    tsi::GridTransforms full(grid, 2);
    real.values().setRandom();
    const tsi::RealMatrix values = real.values();
    full.data() = values.cast<Complex>();
    real.forward();
    full.forward();
    const auto to_half = grid.full_to_half();
    const auto to_full = grid.half_to_full();
    REQUIRE(static_cast<Index>(to_full.size()) == grid.half_points());
    double worst = 0.0;
    for (Index j = 0; j < 2; ++j)
      for (Index p = 0; p < grid.points(); ++p) {
        const auto [at, conjugate] = to_half[static_cast<std::size_t>(p)];
        const Complex stored = real.spectrum()(at, j);
        worst = std::max(worst, std::abs((conjugate ? std::conj(stored) : stored) - full.data()(p, j)));
      }
    CHECK(worst < 1e-12 * static_cast<double>(grid.points()));
    // half_to_full: the stored coefficient is that of m, and the conjugate of that of -m.
    double worst_m = 0.0, worst_minus_m = 0.0;
    for (Index q = 0; q < grid.half_points(); ++q) {
      const auto [m, minus_m] = to_full[static_cast<std::size_t>(q)];
      worst_m = std::max(worst_m, std::abs(real.spectrum()(q, 0) - full.data()(m, 0)));
      worst_minus_m = std::max(worst_minus_m, std::abs(real.spectrum()(q, 0) - std::conj(full.data()(minus_m, 0))));
    }
    CHECK(worst_m < 1e-12 * static_cast<double>(grid.points()));
    CHECK(worst_minus_m < 1e-12 * static_cast<double>(grid.points()));
    real.backward();  // backward(forward(a)) = N a
    CHECK((real.values() - static_cast<double>(grid.points()) * values).norm() <
          1e-13 * values.norm() * static_cast<double>(grid.points()));
  }
}

}  // namespace
