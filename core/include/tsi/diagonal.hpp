#pragma once
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "tsi/types.hpp"

namespace tsi {

/// The diagonal of an operator on a problem's unknowns, stored once per run of equal entries:
/// entry i is values()(i / run()). The two-scale L without a remainder is constant on the dim
/// unknowns of each tau mode, so it and its functions (e^{hL}, h phi1(hL), the weights of a
/// multistep or collocation scheme) hold n_tau values instead of dim x n_tau; with run() = 1
/// every entry is stored. tsi::algebra's diagonal operations take it as they take a Vector.
class Diagonal {
 public:
  Diagonal() = default;
  /// Entry i is values(i / run).
  explicit Diagonal(Vector values, Index run = 1) : values_(std::move(values)), run_(run < 1 ? 1 : run) {}

  /// Entries (unknowns) it acts on.
  Index size() const { return values_.size() * run_; }
  /// Consecutive entries that share one stored value.
  Index run() const { return run_; }
  /// The stored values, one per run.
  const Vector& values() const { return values_; }
  /// Entry i.
  Complex operator()(Index i) const { return values_(i / run_); }
  /// Every entry, one per unknown (a Vector of size()).
  Vector expanded() const {
    Vector out(size());
    for (Index b = 0; b < values_.size(); ++b) out.segment(b * run_, run_).setConstant(values_(b));
    return out;
  }
  /// The operator with conjugate pairs: where pairs(b) = p != 0, the entries of stored value b
  /// (whose value stays values()(b)) have their functions averaged over values()(b) +- i p:
  /// f there is (f(v + i p) + f(v - i p)) / 2. A tau grid's Nyquist mode taken as a naive
  /// real-to-complex code takes it (reformulation.nyquist = average); empty: none.
  Diagonal with_pairs(RealVector pairs) const {
    Diagonal d = *this;
    d.pairs_ = std::move(pairs);
    return d;
  }
  /// f at stored value b (averaged over its pair where it has one), of the operator scaled by `scale`.
  template <class F>
  auto function_at(Index b, Real scale, F&& f) const {
    const Complex v = values_(b);
    if (pairs_.size() == 0 || pairs_(b) == 0) return f(scale * v);
    auto plus = f(scale * (v + Complex(0, pairs_(b))));
    const auto minus = f(scale * (v - Complex(0, pairs_(b))));
    if constexpr (std::is_same_v<std::decay_t<decltype(plus)>, Complex>) {
      return Complex(Real(0.5) * (plus + minus));
    } else {
      for (size_t j = 0; j < plus.size(); ++j) plus[j] = Real(0.5) * (plus[j] + minus[j]);
      return plus;
    }
  }
  /// Threads its entrywise operations in tsi::algebra may use (1: none). The two-scale L
  /// carries the run's tau-grid threads, and the functions of it (diagonal_function, like())
  /// keep them, so that a scheme's combinations of 10^7 unknowns go on the run's threads; the
  /// numbers are the same on any number.
  int threads() const { return threads_; }
  Diagonal with_threads(int threads) const {
    Diagonal d = *this;
    d.threads_ = threads < 1 ? 1 : threads;
    return d;
  }
  /// An operator of the same run and threads with other values (one per run), without pairs.
  Diagonal like(Vector values) const {
    Diagonal d(std::move(values), run_);
    d.threads_ = threads_;
    return d;
  }
  /// Its memory in vectors of its size (1 / run()).
  double state_fraction() const { return size() ? static_cast<double>(values_.size()) / static_cast<double>(size()) : 0.0; }

 private:
  Vector values_;
  Index run_ = 1;
  RealVector pairs_;  // empty, or one per stored value
  int threads_ = 1;
};

/// out_i = f(scale * lambda_i): a function of the diagonal operator scale * L, evaluated
/// once per step size by the exponential schemes (e^{hL}, h phi1(hL), ...), once per stored value.
template <class F>
void diagonal_function(const Diagonal& lambda, Real scale, F&& f, Diagonal& out) {
  const Vector& v = lambda.values();
  Vector values(v.size());
  for (Index i = 0; i < v.size(); ++i) values(i) = lambda.function_at(i, scale, f);
  out = lambda.like(std::move(values));
}

/// The same with one value per unknown (a coefficient a scheme stores as a Vector).
template <class F>
void diagonal_function(const Diagonal& lambda, Real scale, F&& f, Vector& out) {
  Diagonal d;
  diagonal_function(lambda, scale, std::forward<F>(f), d);
  out = d.expanded();
}

/// out_i = f(scale * lambda_i) for a Vector of the diagonal's entries.
template <class F>
void diagonal_function(const Vector& lambda, Real scale, F&& f, Vector& out) {
  out.resize(lambda.size());
  for (Index i = 0; i < lambda.size(); ++i) out(i) = f(scale * lambda(i));
}

/// outs[j]_i = f(scale * lambda_i)[j] for a function with several values per point (the
/// weights of an exponential multistep or collocation scheme), each out shaped like lambda.
template <class F>
void diagonal_functions(const Diagonal& lambda, Real scale, F&& f, std::span<Diagonal* const> outs) {
  const Vector& v = lambda.values();
  std::vector<Vector> values(outs.size(), Vector(v.size()));
  for (Index i = 0; i < v.size(); ++i) {
    const auto w = lambda.function_at(i, scale, f);
    for (size_t j = 0; j < outs.size(); ++j) values[j](i) = w[j];
  }
  for (size_t j = 0; j < outs.size(); ++j) *outs[j] = lambda.like(std::move(values[j]));
}

/// The same for a Vector of the diagonal's entries, each out sized like lambda.
template <class F>
void diagonal_functions(const Vector& lambda, Real scale, F&& f, std::span<Vector* const> outs) {
  for (Vector* out : outs) out->resize(lambda.size());
  for (Index i = 0; i < lambda.size(); ++i) {
    const auto values = f(scale * lambda(i));
    for (size_t j = 0; j < outs.size(); ++j) (*outs[j])(i) = values[j];
  }
}

}  // namespace tsi
