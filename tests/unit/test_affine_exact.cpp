// The exact solution of an affine field's equation (tsi/affine_exact.hpp), computed in
// quadruple precision, against SPEC.md section 7's closed form evaluated another way (Eigen's
// matrix exponential and solves in x87 long double): they agree to rounding where long double
// is good enough (|t C| up to 1e4), and the closed form in long double drifts where |t C| grows,
// which is why the reference is computed in quad. A complex affine field (a real pair) and
// the refusals.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "tsi/affine_exact.hpp"
#include "tsi/error.hpp"

namespace {

using LMatrix = Eigen::Matrix<long double, 4, 4>;
using LVector = Eigen::Matrix<long double, 4, 1>;

// HOODESolver.jl's linear test (the parity issue's values) with the quickstart's A.
struct LinearTest {
  tsi::Matrix A = tsi::Matrix::Zero(4, 4);
  tsi::AffineTerms f;
  tsi::Vector u0 = tsi::Vector(4);
  LinearTest() {
    A(0, 2) = 1.0;
    A(2, 0) = -1.0;
    f.B = tsi::Matrix(4, 4);
    f.B << 0.12, -0.78, 0.91, 0.34, -0.45, 0.56, 0.03, 0.54, -0.67, 0.09, 0.18, 0.89, -0.91, -0.56, 0.11, -0.56;
    f.a = tsi::Vector(4);
    f.a << 0.12, -0.98, 0.45, 0.26;
    f.b = tsi::Vector(4);
    f.b << -0.04, 0.48, 0.23, -0.87;
    u0 << -0.34, 0.78, 0.67, -5.6;
  }
};

LMatrix real_long(const tsi::Matrix& m) {
  LMatrix out;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) out(i, j) = m(i, j).real();
  return out;
}
LVector real_long(const tsi::Vector& v) {
  LVector out;
  for (int i = 0; i < 4; ++i) out(i) = v(i).real();
  return out;
}

// SPEC.md section 7: u(t) = e^{tC} u0 + C^{-1}(e^{tC} - I) b + (C^{-2}(e^{tC} - I) - t C^{-1}) a.
tsi::Vector closed_form(const LinearTest& p, double eps, double t) {
  const LMatrix C = real_long(p.A) / static_cast<long double>(eps) + real_long(p.f.B);
  const LMatrix E = (static_cast<long double>(t) * C).exp();
  const LMatrix I = LMatrix::Identity();
  const auto lu = C.partialPivLu();
  const LVector Cb = lu.solve((E - I) * real_long(p.f.b));
  const LVector Ca = lu.solve(lu.solve((E - I) * real_long(p.f.a))) - static_cast<long double>(t) * lu.solve(real_long(p.f.a));
  const LVector u = E * real_long(p.u0) + Cb + Ca;
  tsi::Vector out(4);
  for (int i = 0; i < 4; ++i) out(i) = static_cast<double>(u(i));
  return out;
}

}  // namespace

TEST_CASE("affine exact solution: quad precision agrees with the closed form in long double") {
  const LinearTest p;
  for (const double eps : {1.0, 0.15, 0.015, 1.5e-3, 1.5e-4}) {
    for (const double t : {0.0, 0.37, 1.0}) {
      const tsi::ExactSolution::Value exact = tsi::affine_exact_solution(p.A, eps, p.f, p.u0, t);
      const tsi::Vector other = closed_form(p, eps, t);
      const double difference = (exact.x - other).norm() / other.norm();
      CAPTURE(eps);
      CAPTURE(t);
      // long double's unit roundoff 5.4e-20 times |t C| (up to 6.7e3) and a few squarings
      CHECK(difference < 1e-14);
      CHECK(exact.accuracy < 2e-16);
      if (t == 0.0) CHECK((exact.x - p.u0).norm() == 0.0);
    }
  }
}

TEST_CASE("affine exact solution: at eps = 1.5e-7 quad keeps its digits where long double does not") {
  const LinearTest p;
  const tsi::ExactSolution::Value exact = tsi::affine_exact_solution(p.A, 1.5e-7, p.f, p.u0, 1.0);
  const tsi::Vector other = closed_form(p, 1.5e-7, 1.0);
  const double drift = (exact.x - other).norm() / exact.x.norm();
  MESSAGE("eps = 1.5e-7: quad self-consistency " << exact.accuracy << ", long double closed form off by " << drift);
  CHECK(exact.accuracy < 2e-16);  // the second evaluation (8 times the scaling) agrees to the double rounding
  CHECK(drift < 1e-10);  // the same solution to long double's accuracy at |t C| = 6.7e6 (measured 9e-12)
}

TEST_CASE("affine exact solution: a complex field is its real pair") {
  // u' = (1/eps) i u + B u + t a + b with complex B, a, b, against the same system written as
  // a real one of twice the size (z = x + i y).
  const double eps = 0.05, t = 0.8;
  tsi::Matrix A = tsi::Matrix::Zero(2, 2);
  A(0, 0) = tsi::Complex(0.0, 1.0);
  A(1, 1) = tsi::Complex(0.0, -2.0);
  tsi::AffineTerms f;
  f.B = tsi::Matrix(2, 2);
  f.B << tsi::Complex(0.1, 0.2), tsi::Complex(-0.3, 0.05), tsi::Complex(0.4, -0.1), tsi::Complex(0.0, 0.3);
  f.a = tsi::Vector(2);
  f.a << tsi::Complex(0.5, -0.2), tsi::Complex(0.1, 0.7);
  f.b = tsi::Vector(2);
  f.b << tsi::Complex(-0.3, 0.0), tsi::Complex(0.2, 0.2);
  tsi::Vector u0(2);
  u0 << tsi::Complex(1.0, -0.5), tsi::Complex(0.25, 2.0);
  const tsi::ExactSolution::Value z = tsi::affine_exact_solution(A, eps, f, u0, t);

  auto real_pair = [](const tsi::Matrix& m) {
    const tsi::Index n = m.rows();
    tsi::Matrix r = tsi::Matrix::Zero(2 * n, 2 * n);
    r.topLeftCorner(n, n) = m.real().cast<tsi::Complex>();
    r.bottomRightCorner(n, n) = m.real().cast<tsi::Complex>();
    r.topRightCorner(n, n) = (-m.imag()).cast<tsi::Complex>();
    r.bottomLeftCorner(n, n) = m.imag().cast<tsi::Complex>();
    return r;
  };
  auto stacked = [](const tsi::Vector& v) {
    tsi::Vector r(2 * v.size());
    r << v.real().cast<tsi::Complex>(), v.imag().cast<tsi::Complex>();
    return r;
  };
  tsi::AffineTerms g{real_pair(f.B), stacked(f.a), stacked(f.b)};
  const tsi::ExactSolution::Value x = tsi::affine_exact_solution(real_pair(A), eps, g, stacked(u0), t);
  const tsi::Vector back = x.x.head(2) + tsi::Complex(0.0, 1.0) * x.x.tail(2);
  CHECK((z.x - back).norm() / z.x.norm() < 1e-15);
  CHECK(z.x.imag().norm() > 0.1);
}

TEST_CASE("affine exact solution: refuses more than 32 unknowns, a negative time and mismatched sizes") {
  const LinearTest p;
  CHECK_THROWS_WITH_AS(tsi::affine_exact_solution(p.A, 0.1, p.f, p.u0, -1.0),
                       doctest::Contains("expected t >= 0 finite and eps > 0"), tsi::Error);
  tsi::AffineTerms short_a = p.f;
  short_a.a = tsi::Vector::Zero(3);
  CHECK_THROWS_WITH_AS(tsi::affine_exact_solution(p.A, 0.1, short_a, p.u0, 1.0), doctest::Contains("expected one size"),
                       tsi::Error);
  const tsi::Matrix big = tsi::Matrix::Zero(33, 33);
  tsi::AffineTerms big_f{big, tsi::Vector::Zero(33), tsi::Vector::Zero(33)};
  CHECK_THROWS_WITH_AS(tsi::affine_exact_solution(big, 0.1, big_f, tsi::Vector::Zero(33), 1.0),
                       doctest::Contains("offered up to 32 unknowns, this one has 33"), tsi::Error);
}
