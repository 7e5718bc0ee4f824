// The exact solution of an affine field's equation in quadruple precision (HOODESolver.jl's
// linear test, SPEC.md section 7): the reference against which uniform orders are measured
// down to and below the double rounding floor.
#include "tsi/affine_exact.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tsi/error.hpp"

namespace tsi {
namespace {

__extension__ typedef __float128 Quad;

// A dense square matrix of quads, row-major: the sizes are small (at most 2 (32 + 2)).
struct QuadMatrix {
  Index n = 0;
  std::vector<Quad> v;
  explicit QuadMatrix(Index size) : n(size), v(static_cast<std::size_t>(size * size), Quad(0)) {}
  Quad& operator()(Index i, Index j) { return v[static_cast<std::size_t>(i * n + j)]; }
  Quad operator()(Index i, Index j) const { return v[static_cast<std::size_t>(i * n + j)]; }
};

QuadMatrix product(const QuadMatrix& x, const QuadMatrix& y) {
  QuadMatrix out(x.n);
  for (Index i = 0; i < x.n; ++i)
    for (Index k = 0; k < x.n; ++k) {
      const Quad xik = x(i, k);
      if (xik == Quad(0)) continue;
      for (Index j = 0; j < x.n; ++j) out(i, j) += xik * y(k, j);
    }
  return out;
}

Quad magnitude(Quad x) { return x < Quad(0) ? -x : x; }

// A Real as a Quad and back: exact in every precision (quad's Real holds a __float128).
Quad quad_of(Real x) {
#if defined(TSI_PRECISION_QUAD)
  return x.backend().value();
#else
  return Quad(x);
#endif
}
Real real_of(Quad x) { return Real(x); }

double max_abs(const QuadMatrix& x) {
  Quad m = 0;
  for (const Quad e : x.v) m = magnitude(e) > m ? magnitude(e) : m;
  return static_cast<double>(m);
}

// e^{Z} by Taylor's series on Z / 2^s, |Z / 2^s|_1 <= 1/8, then s squarings (extra_squarings more
// than the norm asks for, to estimate the rounding error).
QuadMatrix exponential(const QuadMatrix& Z, int extra_squarings) {
  double norm = 0.0;  // the 1-norm, in double: it only chooses s
  for (Index j = 0; j < Z.n; ++j) {
    double column = 0.0;
    for (Index i = 0; i < Z.n; ++i) column += std::fabs(static_cast<double>(Z(i, j)));
    norm = std::max(norm, column);
  }
  const int s = std::max(0, static_cast<int>(std::ceil(std::log2(std::max(norm, 1e-300) * 8.0)))) + extra_squarings;
  QuadMatrix X = Z;
  const Quad scale = std::ldexp(1.0, -s);
  for (Quad& e : X.v) e *= scale;
  QuadMatrix E(Z.n), term(Z.n);
  for (Index i = 0; i < Z.n; ++i) E(i, i) = term(i, i) = 1;
  // |X| <= 1/8: the k-th term is below 8^-k / k!, under quad's 1e-34 by k = 30.
  for (int k = 1; k <= 40; ++k) {
    term = product(term, X);
    for (Quad& e : term.v) e /= Quad(k);
    for (std::size_t i = 0; i < E.v.size(); ++i) E.v[i] += term.v[i];
    if (max_abs(term) < 1e-40) break;
  }
  for (int i = 0; i < s; ++i) E = product(E, E);
  return E;
}

}  // namespace

ExactSolution::Value affine_exact_solution(const Matrix& A, Real eps, const AffineTerms& f, const Vector& u0,
                                           Real t) {
  const Index n = A.rows();
  if (n > max_affine_exact_dim)
    throw Error(fmt::format("the exact solution of an affine field is offered up to {} unknowns, this one has {}",
                            max_affine_exact_dim, n));
  if (A.cols() != n || f.B.rows() != n || f.B.cols() != n || f.a.size() != n || f.b.size() != n || u0.size() != n)
    throw Error(fmt::format("affine_exact_solution: A is {} x {}, B {} x {}, a {}, b {}, u0 {}: expected one size",
                            n, A.cols(), f.B.rows(), f.B.cols(), f.a.size(), f.b.size(), u0.size()));
  if (!(t >= 0.0) || !std::isfinite(t) || !(eps > 0.0))
    throw Error(fmt::format("affine_exact_solution: t = {}, eps = {}: expected t >= 0 finite and eps > 0", t, eps));
  // Complex numbers as real pairs: the augmented Z of size m = n + 2 acts on (Re z, Im z).
  const Index m = n + 2, size = 2 * m;
  QuadMatrix Z(size);
  const Quad inverse_eps = Quad(1) / quad_of(eps), time = quad_of(t);
  auto set = [&](Index i, Index j, Complex c) {
    const Quad re = quad_of(c.real()) * time, im = quad_of(c.imag()) * time;
    Z(i, j) = re;
    Z(i + m, j + m) = re;
    Z(i, j + m) = -im;
    Z(i + m, j) = im;
  };
  for (Index i = 0; i < n; ++i) {
    for (Index j = 0; j < n; ++j) {
      set(i, j, f.B(i, j));
      // A / eps in quad: the division is exact to quad, not rounded to double first.
      Z(i, j) += quad_of(A(i, j).real()) * inverse_eps * time;
      Z(i + m, j + m) += quad_of(A(i, j).real()) * inverse_eps * time;
      Z(i, j + m) -= quad_of(A(i, j).imag()) * inverse_eps * time;
      Z(i + m, j) += quad_of(A(i, j).imag()) * inverse_eps * time;
    }
    set(i, n, f.a(i));
    set(i, n + 1, f.b(i));
  }
  set(n, n + 1, Complex(1));
  std::vector<Quad> z0(static_cast<std::size_t>(size), Quad(0));
  for (Index i = 0; i < n; ++i) {
    z0[static_cast<std::size_t>(i)] = quad_of(u0(i).real());
    z0[static_cast<std::size_t>(i + m)] = quad_of(u0(i).imag());
  }
  z0[static_cast<std::size_t>(n + 1)] = 1;
  // Z's entries carry t / eps rounded to quad: a phase error of about quad's epsilon times |t Z|,
  // common to both evaluations below (their spread cannot show it). Past 1e-3 radians there is
  // no exact solution to give (eps = 1e-300: |t Z| = 1e300, 1000 squarings ending in NaN).
  double size_of_tZ = 0.0;  // the 1-norm
  for (Index j = 0; j < size; ++j) {
    double column = 0.0;
    for (Index i = 0; i < size; ++i) column += std::fabs(static_cast<double>(Z(i, j)));
    size_of_tZ = std::max(size_of_tZ, column);
  }
  const double phase_rounding = size_of_tZ * std::ldexp(1.0, -112);  // quad's epsilon
  if (!(phase_rounding <= 1e-3))
    throw ConfigError("reference.scheme",
                      fmt::format("got \"exact\", but at t = {} and eps = {} the exact solution's phases reach "
                                  "|t (A/eps + B)| = {:.3g}, which quadruple precision resolves only to {:.3g} "
                                  "radians (it carries 113 bits): there is no exact solution to compare with; "
                                  "expected t |A| / eps up to 5e30, or a reference solver, e.g. \"rk78\"",
                                  t, eps, size_of_tZ, phase_rounding));
  auto solve = [&](int extra) {
    const QuadMatrix E = exponential(Z, extra);
    std::vector<Quad> z(static_cast<std::size_t>(size), Quad(0));
    for (Index i = 0; i < size; ++i)
      for (Index j = 0; j < size; ++j) z[static_cast<std::size_t>(i)] += E(i, j) * z0[static_cast<std::size_t>(j)];
    return z;
  };
  const std::vector<Quad> z = solve(0), check = solve(3);
  Quad norm2 = 0, diff2 = 0;
  ExactSolution::Value out{Vector(n), 0.0};
  for (Index i = 0; i < n; ++i) {
    const auto re = static_cast<std::size_t>(i), im = static_cast<std::size_t>(i + m);
    out.x(i) = Complex(real_of(z[re]), real_of(z[im]));
    norm2 += z[re] * z[re] + z[im] * z[im];
    diff2 += (z[re] - check[re]) * (z[re] - check[re]) + (z[im] - check[im]) * (z[im] - check[im]);
  }
  const Real norm = std::sqrt(real_of(norm2));
  if (!std::isfinite(norm) || !std::isfinite(real_of(diff2)))
    throw ConfigError("reference.scheme",
                      fmt::format("got \"exact\", but the exact solution at t = {} (eps = {}) is not finite in "
                                  "quadruple precision (|u(t)| beyond 1e4932): no exact solution to compare with; "
                                  "expected a shorter t_end, or a reference solver, e.g. \"rk78\"",
                                  t, eps));
  const Real spread = norm > 0 ? std::sqrt(real_of(diff2)) / norm : 0;
  out.accuracy = std::max({spread, Real(phase_rounding), std::numeric_limits<Real>::epsilon() / 2});
  return out;
}

}  // namespace tsi
