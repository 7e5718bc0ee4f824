#include "pic_field.hpp"

#include <cmath>

#include "tsi/phase.hpp"

namespace tsi::pic {
namespace {

// The quintic B-spline M6 at q >= 0 (support [0, 3)), as the peer writes it.
double m6(double q) {
  const auto p5 = [](double a) { return a * a * a * a * a; };
  if (q < 1.0) return (p5(3.0 - q) - 6.0 * p5(2.0 - q) + 15.0 * p5(1.0 - q)) / 120.0;
  if (q < 2.0) return (p5(3.0 - q) - 6.0 * p5(2.0 - q)) / 120.0;
  if (q < 3.0) return p5(3.0 - q) / 120.0;
  return 0.0;
}

}  // namespace

double Geometry::length_x() const { return two_pi / k_x; }
double Geometry::length_y() const { return two_pi / k_y; }

Stencil stencil(Shape shape, double x_over_cell, int n) {
  double p = std::fmod(x_over_cell, static_cast<double>(n));
  if (p < 0.0) p += n;
  const double cell = std::floor(p);
  const double d = p - cell;
  const int i = static_cast<int>(cell);  // n when p rounded up to n: the nodes are wrapped below
  Stencil s;
  if (shape == Shape::cic) {
    s.width = 2;
    s.node = {i, i + 1};
    s.w = {1.0 - d, d};
  } else {  // nodes i - 2 .. i + 3 at distances 2 + d .. 3 - d
    s.width = 6;
    for (int a = 0; a < 6; ++a) {
      s.node[static_cast<std::size_t>(a)] = i - 2 + a;
      s.w[static_cast<std::size_t>(a)] = m6(std::abs(static_cast<double>(a - 2) - d));
    }
  }
  for (int a = 0; a < s.width; ++a) {
    int& node = s.node[static_cast<std::size_t>(a)];
    node = (node % n + n) % n;
  }
  return s;
}

Field::Field(const Geometry& geometry)
    : g_(geometry),
      grid_({geometry.n_y, geometry.n_x}),
      transforms_(std::make_unique<RealGridTransforms>(grid_, 2)),
      rho_(RealVector::Zero(grid_.points())) {
  // Wave numbers of the half spectrum (n_y full, x halved), scaled to the box: E^ = -i k rho^ / |k|^2.
  const Index half = grid_.half_points(), half_x = g_.n_x / 2 + 1;
  k1_.resize(half);
  k2_.resize(half);
  inverse_k2_.resize(half);
  for (Index p = 0; p < half; ++p) {
    const int jy = static_cast<int>(p / half_x), ix = static_cast<int>(p % half_x);
    k1_(p) = g_.k_x * ix;
    k2_(p) = g_.k_y * grid_.wave_number(0, jy);
    const double k_squared = k1_(p) * k1_(p) + k2_(p) * k2_(p);
    inverse_k2_(p) = k_squared > 0.0 ? 1.0 / k_squared : 0.0;  // the mean: no field
  }
  e1_ = transforms_->values().col(0).data();
  e2_ = transforms_->values().col(1).data();
}

Field::~Field() = default;

void Field::solve(const double* base, ParticleLayout layout) {
  rho_.setZero();
  const double w = g_.weight();
  for (Index k = 0; k < g_.particles; ++k) {
    const double* particle = base + k * layout.particle_stride;
    const Stencil sx = stencil(g_.shape, particle[0] / g_.dx(), g_.n_x);
    const Stencil sy = stencil(g_.shape, particle[layout.component_stride] / g_.dy(), g_.n_y);
    for (int b = 0; b < sy.width; ++b) {
      double* row = rho_.data() + static_cast<Index>(sy.node[static_cast<std::size_t>(b)]) * g_.n_x;
      const double wy = w * sy.w[static_cast<std::size_t>(b)];
      for (int a = 0; a < sx.width; ++a) row[sx.node[static_cast<std::size_t>(a)]] += wy * sx.w[static_cast<std::size_t>(a)];
    }
  }
  const double cell = g_.dx() * g_.dy();
  rho_ /= cell;
  charge_ = rho_.sum() * cell;
  auto values = transforms_->values();
  values.col(0) = rho_.array() - charge_ / (g_.length_x() * g_.length_y());
  values.col(1).setZero();
  transforms_->forward();
  auto spectrum = transforms_->spectrum();
  const double scale = 1.0 / static_cast<double>(grid_.points());  // the unnormalised pair's n_x n_y
  for (Index p = 0; p < spectrum.rows(); ++p) {
    const Complex rho_hat = spectrum(p, 0) * (scale * inverse_k2_(p));
    spectrum(p, 0) = Complex(0.0, -k1_(p)) * rho_hat;
    spectrum(p, 1) = Complex(0.0, -k2_(p)) * rho_hat;
  }
  transforms_->backward();
}

void Field::at(double x1, double x2, double& e1, double& e2) const {
  const Stencil sx = stencil(g_.shape, x1 / g_.dx(), g_.n_x);
  const Stencil sy = stencil(g_.shape, x2 / g_.dy(), g_.n_y);
  const double* f1 = e1_;
  const double* f2 = e2_;
  e1 = e2 = 0.0;
  for (int b = 0; b < sy.width; ++b) {
    const Index row = static_cast<Index>(sy.node[static_cast<std::size_t>(b)]) * g_.n_x;
    double r1 = 0.0, r2 = 0.0;
    for (int a = 0; a < sx.width; ++a) {
      const Index node = row + sx.node[static_cast<std::size_t>(a)];
      r1 += sx.w[static_cast<std::size_t>(a)] * f1[node];
      r2 += sx.w[static_cast<std::size_t>(a)] * f2[node];
    }
    e1 += sy.w[static_cast<std::size_t>(b)] * r1;
    e2 += sy.w[static_cast<std::size_t>(b)] * r2;
  }
}

double Field::field_energy() const {
  const Index points = grid_.points();
  return 0.5 * (Eigen::Map<const RealVector>(e1_, points).squaredNorm() + Eigen::Map<const RealVector>(e2_, points).squaredNorm()) *
         g_.dx() * g_.dy();
}

}  // namespace tsi::pic
