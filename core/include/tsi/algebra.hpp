#pragma once
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <span>

#include "tsi/device.hpp"
#include "tsi/diagonal.hpp"
#include "tsi/export.hpp"
#include "tsi/function_ref.hpp"
#include "tsi/types.hpp"

/// The vector arithmetic of the schemes and fixed-point solvers, in one place (as
/// Boost.Odeint's algebra and operations, or PETSc's Vec): a scheme combines states only
/// through these functions, so a distributed or GPU state later replaces this file, the
/// two-scale transforms and the model kernels, and no scheme. Every function is one fused pass
/// over the data (Eigen's vectorised complex products, without std::complex's NaN checks),
/// entrywise so that `out` may alias an input, and allocates only when `out` has the wrong size.
/// While a tsi::device::Scope is open on the thread, each function runs on the device instead
/// (tsi/device.hpp: the same operations, one kernel each).
namespace tsi::algebra {

/// out = x.
inline void copy(const Vector& x, Vector& out) {
  if (device::current()) return device::copy(x, out);
  out = x;
}

/// Exchanges a and b (no copy).
inline void swap(Vector& a, Vector& b) { a.swap(b); }

/// out = 0, with n entries.
inline void set_zero(Index n, Vector& out) {
  if (device::current()) return device::set_zero(n, out);
  out.setZero(n);
}

/// out = a x + b y (out may alias x or y).
inline void axpby(Real a, const Vector& x, Real b, const Vector& y, Vector& out) {
  if (device::current()) return device::axpby(a, x, b, y, out);
  out = a * x + b * y;
}

/// y += a x.
inline void axpy(Real a, const Vector& x, Vector& y) {
  if (device::current()) return device::axpby(a, x, Real(1), y, y);
  y += a * x;
}

/// out = d . x (entrywise: the action of a diagonal operator; out may alias x).
inline void diagonal_multiply(const Vector& d, const Vector& x, Vector& out) {
  if (device::current()) {
    const Vector* ds[] = {&d};
    const Vector* xs[] = {&x};
    return device::vector_combination(nullptr, ds, xs, out);
  }
  out = d.cwiseProduct(x);
}

/// out = x + d . y: an implicit stage's map, base + h phi1(hL) N (out may alias x or y).
inline void diagonal_multiply_add(const Vector& x, const Vector& d, const Vector& y, Vector& out) {
  if (device::current()) {
    const Vector* ds[] = {&d};
    const Vector* xs[] = {&y};
    return device::vector_combination(&x, ds, xs, out);
  }
  out = x + d.cwiseProduct(y);
}

/// out = d1 . x1 + d2 . x2: the step of an exponential scheme, e^{hL} u + h phi1(hL) N
/// (out may alias x1 or x2).
inline void diagonal_combination(const Vector& d1, const Vector& x1, const Vector& d2, const Vector& x2,
                                 Vector& out) {
  if (device::current()) {
    const Vector* ds[] = {&d1, &d2};
    const Vector* xs[] = {&x1, &x2};
    return device::vector_combination(nullptr, ds, xs, out);
  }
  out = d1.cwiseProduct(x1) + d2.cwiseProduct(x2);
}

/// out = d1 . x1 + d2 . x2 + d3 . x3 (multistep schemes; out may alias any x).
inline void diagonal_combination(const Vector& d1, const Vector& x1, const Vector& d2, const Vector& x2,
                                 const Vector& d3, const Vector& x3, Vector& out) {
  if (device::current()) {
    const Vector* ds[] = {&d1, &d2, &d3};
    const Vector* xs[] = {&x1, &x2, &x3};
    return device::vector_combination(nullptr, ds, xs, out);
  }
  out = d1.cwiseProduct(x1) + d2.cwiseProduct(x2) + d3.cwiseProduct(x3);
}

/// out = start + sum_j d_j . x_j over k pairs (start may be null: none), in one pass over
/// memory (SUNDIALS' N_VLinearCombination, with diagonal coefficients): the terms accumulate
/// in a block of entries that stays in cache, in the order given. out may alias start or any x_j.
inline void diagonal_linear_combination(const Vector* start, std::span<const Vector* const> d,
                                        std::span<const Vector* const> x, Vector& out) {
  if (device::current()) return device::vector_combination(start, d, x, out);
  const Index n = start ? start->size() : x.front()->size();
  out.resize(n);
  constexpr Index block = 256;
  Eigen::Matrix<Complex, block, 1> sum;
  for (Index b = 0; b < n; b += block) {
    const Index m = std::min(block, n - b);
    auto acc = sum.head(m);
    if (start)
      acc = start->segment(b, m);
    else
      acc.setZero();
    for (size_t j = 0; j < x.size(); ++j) acc += d[j]->segment(b, m).cwiseProduct(x[j]->segment(b, m));
    out.segment(b, m) = acc;
  }
}

/// The same operations with a Diagonal (stored once per run of equal entries: the two-scale
/// coefficients, n_tau values instead of dim x n_tau): the same products entry by entry, a run
/// at a time (diagonals of different runs go entry by entry), on the diagonal's threads.
namespace detail {
/// The run all of ds share, or 0 when they differ.
inline Index common_run(std::initializer_list<const Diagonal*> ds) {
  Index run = (*ds.begin())->run();
  for (const Diagonal* d : ds)
    if (d->run() != run) return 0;
  return run;
}
/// The most threads any of ds carries.
inline int common_threads(std::initializer_list<const Diagonal*> ds) {
  int threads = 1;
  for (const Diagonal* d : ds) threads = std::max(threads, d->threads());
  return threads;
}
/// Calls body(begin, end) on `threads` contiguous ranges of [0, n) at the same time (OpenMP,
/// in the core: a plugin needs no OpenMP of its own), or once on all of it.
TSI_API void for_ranges(int threads, Index n, FunctionRef<void(Index, Index)> body);
/// Calls piece(value, begin, count) for the entries [i0, i1) of each run of length r (r >= 1).
template <class Piece>
inline void for_run_pieces(Index r, Index i0, Index i1, Piece&& piece) {
  for (Index lo = i0; lo < i1;) {
    const Index b = lo / r, hi = std::min(i1, (b + 1) * r);
    piece(b, lo, hi - lo);
    lo = hi;
  }
}
}  // namespace detail

/// out = d . x (out may alias x).
inline void diagonal_multiply(const Diagonal& d, const Vector& x, Vector& out) {
  if (device::current()) {
    const Diagonal* ds[] = {&d};
    const Real none[] = {0};
    const Vector* xs[] = {&x};
    return device::linear_combination(nullptr, ds, none, xs, out);
  }
  out.resize(x.size());
  const Index r = d.run();
  const Vector& v = d.values();
  detail::for_ranges(d.threads(), x.size(), [&](Index i0, Index i1) {
    if (r == 1) {
      out.segment(i0, i1 - i0) = v.segment(i0, i1 - i0).cwiseProduct(x.segment(i0, i1 - i0));
      return;
    }
    detail::for_run_pieces(r, i0, i1, [&](Index b, Index lo, Index m) { out.segment(lo, m) = v(b) * x.segment(lo, m); });
  });
}

/// out = x + d . y (out may alias x or y).
inline void diagonal_multiply_add(const Vector& x, const Diagonal& d, const Vector& y, Vector& out) {
  if (device::current()) {
    const Diagonal* ds[] = {&d};
    const Real none[] = {0};
    const Vector* xs[] = {&y};
    return device::linear_combination(&x, ds, none, xs, out);
  }
  out.resize(x.size());
  const Index r = d.run();
  const Vector& v = d.values();
  detail::for_ranges(d.threads(), x.size(), [&](Index i0, Index i1) {
    if (r == 1) {
      const Index m = i1 - i0;
      out.segment(i0, m) = x.segment(i0, m) + v.segment(i0, m).cwiseProduct(y.segment(i0, m));
      return;
    }
    detail::for_run_pieces(r, i0, i1,
                           [&](Index b, Index lo, Index m) { out.segment(lo, m) = x.segment(lo, m) + v(b) * y.segment(lo, m); });
  });
}

/// out = d1 . x1 + d2 . x2 (out may alias x1 or x2).
inline void diagonal_combination(const Diagonal& d1, const Vector& x1, const Diagonal& d2, const Vector& x2,
                                 Vector& out) {
  if (device::current()) {
    const Diagonal* ds[] = {&d1, &d2};
    const Real none[] = {0, 0};
    const Vector* xs[] = {&x1, &x2};
    return device::linear_combination(nullptr, ds, none, xs, out);
  }
  out.resize(x1.size());
  const Index r = detail::common_run({&d1, &d2});
  const Vector &v1 = d1.values(), &v2 = d2.values();
  detail::for_ranges(detail::common_threads({&d1, &d2}), x1.size(), [&](Index i0, Index i1) {
    if (r == 1) {
      const Index m = i1 - i0;
      out.segment(i0, m) = v1.segment(i0, m).cwiseProduct(x1.segment(i0, m)) + v2.segment(i0, m).cwiseProduct(x2.segment(i0, m));
    } else if (r > 1) {
      detail::for_run_pieces(r, i0, i1, [&](Index b, Index lo, Index m) {
        out.segment(lo, m) = v1(b) * x1.segment(lo, m) + v2(b) * x2.segment(lo, m);
      });
    } else {
      for (Index i = i0; i < i1; ++i) out(i) = d1(i) * x1(i) + d2(i) * x2(i);
    }
  });
}

/// out = d1 . x1 + d2 . x2 + d3 . x3 (out may alias any x).
inline void diagonal_combination(const Diagonal& d1, const Vector& x1, const Diagonal& d2, const Vector& x2,
                                 const Diagonal& d3, const Vector& x3, Vector& out) {
  if (device::current()) {
    const Diagonal* ds[] = {&d1, &d2, &d3};
    const Real none[] = {0, 0, 0};
    const Vector* xs[] = {&x1, &x2, &x3};
    return device::linear_combination(nullptr, ds, none, xs, out);
  }
  out.resize(x1.size());
  const Index r = detail::common_run({&d1, &d2, &d3});
  const Vector &v1 = d1.values(), &v2 = d2.values(), &v3 = d3.values();
  detail::for_ranges(detail::common_threads({&d1, &d2, &d3}), x1.size(), [&](Index i0, Index i1) {
    if (r == 1) {
      const Index m = i1 - i0;
      out.segment(i0, m) = v1.segment(i0, m).cwiseProduct(x1.segment(i0, m)) +
                           v2.segment(i0, m).cwiseProduct(x2.segment(i0, m)) + v3.segment(i0, m).cwiseProduct(x3.segment(i0, m));
    } else if (r > 1) {
      detail::for_run_pieces(r, i0, i1, [&](Index b, Index lo, Index m) {
        out.segment(lo, m) = v1(b) * x1.segment(lo, m) + v2(b) * x2.segment(lo, m) + v3(b) * x3.segment(lo, m);
      });
    } else {
      for (Index i = i0; i < i1; ++i) out(i) = d1(i) * x1(i) + d2(i) * x2(i) + d3(i) * x3(i);
    }
  });
}

/// out = start + sum_j d_j . x_j over k pairs (start may be null: none), in one pass over memory,
/// the terms accumulated in the order given, as above (out may alias start or any x_j).
inline void diagonal_linear_combination(const Vector* start, std::span<const Diagonal* const> d,
                                        std::span<const Vector* const> x, Vector& out) {
  if (device::current()) return device::linear_combination(start, d, {}, x, out);
  const Index n = start ? start->size() : x.front()->size();
  out.resize(n);
  Index r = d.empty() ? 1 : d.front()->run();
  int threads = 1;
  for (const Diagonal* dj : d) {
    if (dj->run() != r) r = 0;
    threads = std::max(threads, dj->threads());
  }
  detail::for_ranges(threads, n, [&](Index i0, Index i1) {
    if (r == 0) {  // runs that differ: entry by entry
      for (Index i = i0; i < i1; ++i) {
        Complex acc = start ? (*start)(i) : Complex(0);
        for (size_t j = 0; j < x.size(); ++j) acc += (*d[j])(i) * (*x[j])(i);
        out(i) = acc;
      }
      return;
    }
    constexpr Index block = 256;
    Eigen::Matrix<Complex, block, 1> sum;
    // Blocks of at most `block` entries inside one run: every coefficient is one value there
    // (r = 1: a segment of each diagonal).
    for (Index b = i0; b < i1;) {
      const Index run_end = r == 1 ? i1 : std::min(i1, (b / r + 1) * r);
      const Index m = std::min(block, run_end - b);
      auto acc = sum.head(m);
      if (start)
        acc = start->segment(b, m);
      else
        acc.setZero();
      if (r == 1) {
        for (size_t j = 0; j < x.size(); ++j) acc += d[j]->values().segment(b, m).cwiseProduct(x[j]->segment(b, m));
      } else {
        const Index v = b / r;
        for (size_t j = 0; j < x.size(); ++j) acc += d[j]->values()(v) * x[j]->segment(b, m);
      }
      out.segment(b, m) = acc;
      b += m;
    }
  });
}

/// True when every entry of x is finite: one pass, no allocation (the check a run makes at
/// every step, between the steps its observers record).
inline bool all_finite(const Vector& x) { return device::current() ? device::all_finite(x) : x.allFinite(); }

/// Re <x, y> = Re sum conj(x_i) y_i: the inner product of the state as a real vector.
inline Real inner(const Vector& x, const Vector& y) { return device::current() ? device::inner(x, y) : tsi::inner(x, y); }

/// max_i |x_i|.
inline Real max_norm(const Vector& x) { return device::current() ? device::max_norm(x) : tsi::max_norm(x); }

/// The squares of max_i |next_i - x_i| and of max_i |next_i| into m[0] and m[1]: one pass over
/// the doubles in two independent lanes, so the maxima stay in vector registers (std::max over
/// complex norms in one chain ran at the latency of a compare: 30% of a charged-particle step).
inline void increment_maxima(const Vector& next, const Vector& x, Real m[2]) {
  if (device::current()) return device::increment_maxima(next, x, m);
  const Real* pa = reinterpret_cast<const Real*>(next.data());
  const Real* pb = reinterpret_cast<const Real*>(x.data());
  const Index n = 2 * next.size();
  Real d[2] = {0, 0}, s[2] = {0, 0};
  Index i = 0;
  for (; i + 4 <= n; i += 4)
    for (int l = 0; l < 2; ++l) {
      const Index k = i + 2 * l;
      const Real dr = pa[k] - pb[k], di = pa[k + 1] - pb[k + 1];
      const Real dd = dr * dr + di * di;
      const Real ss = pa[k] * pa[k] + pa[k + 1] * pa[k + 1];
      d[l] = dd > d[l] ? dd : d[l];
      s[l] = ss > s[l] ? ss : s[l];
    }
  for (; i < n; i += 2) {
    const Real dr = pa[i] - pb[i], di = pa[i + 1] - pb[i + 1];
    d[0] = std::max(d[0], dr * dr + di * di);
    s[0] = std::max(s[0], pa[i] * pa[i] + pa[i + 1] * pa[i + 1]);
  }
  m[0] = std::max(d[0], d[1]);
  m[1] = std::max(s[0], s[1]);
}

/// The relative increment from increment_maxima's squares (the denominator 1 when next is 0).
inline Real relative_increment(const Real m[2]) {
  const Real scale = std::sqrt(m[1]);
  return std::sqrt(m[0]) / (scale > 0 ? scale : Real(1));
}

/// max_i |next_i - x_i| / max_i |next_i| (the denominator 1 when next is 0): the fixed-point
/// solvers' convergence test.
inline Real relative_increment(const Vector& next, const Vector& x) {
  Real m[2];
  increment_maxima(next, x, m);
  return relative_increment(m);
}

}  // namespace tsi::algebra
