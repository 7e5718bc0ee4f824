// The fixed-point solvers on maps whose fixed point is known in closed form.
#include <doctest/doctest.h>

#include <cmath>

#include "tsi/error.hpp"
#include "tsi/fixed_point.hpp"

namespace {

// G(x) = A x + b with a real contraction A (a rotation scaled by 0.9, acting on the real
// and imaginary parts): fixed point x* = (I - A)^{-1} b.
struct AffineMap {
  double c = 0.9 * std::cos(0.4), s = 0.9 * std::sin(0.4);
  tsi::Vector b = (tsi::Vector(2) << tsi::Complex(1.0, -2.0), tsi::Complex(0.5, 3.0)).finished();
  void operator()(const tsi::Vector& x, tsi::Vector& out) const {
    out.resize(2);
    out(0) = c * x(0) - s * x(1) + b(0);
    out(1) = s * x(0) + c * x(1) + b(1);
  }
  tsi::Vector fixed_point() const {
    Eigen::Matrix2d a;
    a << c, -s, s, c;
    const Eigen::Matrix2d inverse = (Eigen::Matrix2d::Identity() - a).inverse();
    tsi::Vector x(2);
    for (int i = 0; i < 2; ++i)
      x(i) = tsi::Complex(inverse.row(i).dot(b.real()), inverse.row(i).dot(b.imag()));
    return x;
  }
};

tsi::FixedPointOptions options(const std::string& method, double tol, int max_iter) {
  tsi::FixedPointOptions o;
  o.method = method, o.tol = tol, o.max_iter = max_iter;
  return o;
}

}  // namespace

TEST_CASE("Picard and Anderson reach the same fixed point, Anderson in fewer sweeps") {
  const AffineMap g;
  const tsi::Vector exact = g.fixed_point();
  long sweeps[2];
  int i = 0;
  for (const char* method : {"picard", "anderson"}) {
    auto solver = tsi::make_fixed_point_solver(options(method, 1e-13, 1000));
    tsi::Vector x = tsi::Vector::Zero(2);
    CHECK(solver->solve(x, g));
    CAPTURE(method);
    CHECK((x - exact).cwiseAbs().maxCoeff() < 1e-11 * exact.cwiseAbs().maxCoeff());
    sweeps[i++] = solver->stats().iterations;
  }
  CAPTURE(sweeps[0]);
  CAPTURE(sweeps[1]);
  CHECK(sweeps[0] > 200);          // a contraction of 0.9 needs about 280 Picard sweeps
  CHECK(sweeps[1] * 10 < sweeps[0]);  // Anderson solves an affine 2-D map in a few
}

TEST_CASE("a stage that misses tol is counted, or stops the run with on_failure = stop") {
  const AffineMap g;
  auto warn = tsi::make_fixed_point_solver(options("picard", 1e-13, 5));
  tsi::Vector x = tsi::Vector::Zero(2);
  CHECK_FALSE(warn->solve(x, g));
  CHECK(warn->stats().not_converged == 1);
  CHECK(warn->stats().sweeps_histogram.at(5) == 1);

  auto o = options("anderson", 1e-13, 1);
  o.on_failure = "stop";
  auto stop = tsi::make_fixed_point_solver(o);
  x.setZero();
  CHECK_THROWS_WITH_AS(stop->solve(x, g), doctest::Contains("max_iter = 1"), tsi::Error);
}

TEST_CASE("an unknown fixed-point method is a configuration error naming the choices") {
  CHECK_THROWS_WITH_AS(tsi::make_fixed_point_solver(options("newton", 1e-10, 10)),
                       doctest::Contains("picard, anderson"), tsi::ConfigError);
}
