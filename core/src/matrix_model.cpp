// The core's "matrix" model: u' = (1/eps) A u + f(t, u) with A a matrix from the run's JSON
// (SPEC.md section 7) and f a registered field (a plugin's, Python's, or the built-in
// "quickstart"). e^{A tau} comes from A's spectral projectors, computed once per model from
// samples of e^{A tau} by matrix products alone, interruptible between any two.
#include "tsi/matrix_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "tsi/affine_exact.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"
#include "tsi/registry.hpp"
#include "tsi/stop_request.hpp"
#include "tsi/time_as_variable.hpp"

namespace tsi {

void Field::derivative(const RealVector&, ConstMatrixRef, ConstMatrixRef, MatrixRef) const {
  throw Error("this field gives no derivative (has_derivative() is false)");
}

namespace {

// A JSON value as a short text for a message (a large matrix is cut).
std::string shown(const Json& v) {
  std::string s = v.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// One entry of model.A: a number, or [re, im]; every number read in its own JSON type.
bool json_number(const Json& v, double& x) {
  if (v.is_number_integer()) {
    x = v.is_number_unsigned() ? static_cast<double>(v.get<std::uint64_t>()) : static_cast<double>(v.get<std::int64_t>());
    return true;
  }
  if (v.is_number_float()) {
    x = v.get<double>();
    return std::isfinite(x);
  }
  return false;
}

// ---- A's flow by matrix products only -------------------------------------------------------
// Every step of the set-up below is at most one product of two n x n matrices (0.2 s for a real
// and 0.8 s for a complex 1024 x 1024 A on 2 busy cores), and the set-up polls the stop request
// between them: Ctrl-C is honoured within a second at every size. (Eigen's matrix exponential
// and Schur iteration are single calls of up to 16 s at that size, which nothing can interrupt.)

constexpr const char* flow_set_up = "setting up model.A's flow";
// A's eigenvalues (Eigen's Schur iteration) are computed up to this size: 0.25 s at 256, 16 s at
// 1024 on 2 busy cores. A larger A's frequencies are read off its sampled flow instead.
constexpr Index max_eigenvalue_dim = 256;
// Beyond this 1-norm double's rounding of A (2.2e-16 |A|) reaches 1e-6 in its eigenvalues.
constexpr double max_A_norm = 1e10;
constexpr double max_frequency_taken = 1e6;
// The set-up takes N samples of e^{A tau}, one product each: N n^3 at most this.
constexpr double max_cost = 4e10;
// The checks' tolerances are this many rounding units times N max(1, |A|_1) max(1, max|e^{A tau}|)^2:
// the residuals of periodic matrices stay below 1/25 of it (tests/unit/test_matrix_flow.cpp).
constexpr double rounding_allowance = 64;

void poll() { throw_if_stop_requested(flow_set_up); }

template <class M>
M product(const M& x, const M& y) {
  M out(x.rows(), y.cols());
  out.noalias() = x * y;
  poll();
  return out;
}

template <class M>
Real largest_entry(const M& m) {
  return m.cwiseAbs().maxCoeff();
}

// e^X for ||X||_1 <= 2: its Taylor polynomial to the rounding unit by Paterson and Stockmeyer's
// scheme (degree 25 in double: 8 products). A radius of 2 rather than 1/2 saves two squarings,
// which amplify rounding the most for a non-normal A (e^{A tau} 2 to 3 times closer then).
constexpr double taylor_radius = 2;
template <class M>
M taylor_exponential(const M& X) {
  const Real u = std::numeric_limits<Real>::epsilon();
  std::vector<Real> c = {Real(1)};  // 1/k!
  for (Real bound = 1; bound > u / 8;) {  // 2^k / k!: the term of degree k is below it
    const auto k = static_cast<Real>(c.size());
    c.push_back(c.back() / k);
    bound *= Real(taylor_radius) / k;
  }
  const int m = static_cast<int>(c.size()) - 1;
  const int q = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(m)))));
  const Index n = X.rows();
  std::vector<M> power = {M::Identity(n, n), X};  // X^0 .. X^q
  for (int i = 2; i <= q; ++i) power.push_back(product(power.back(), X));
  const auto block = [&](int b) {  // sum_{i < q} c_{bq+i} X^i
    M sum = M::Zero(n, n);
    for (int i = 0; i < q && b * q + i <= m; ++i)
      sum += c[static_cast<std::size_t>(b * q + i)] * power[static_cast<std::size_t>(i)];
    return sum;
  };
  M result = block(m / q);
  for (int b = m / q - 1; b >= 0; --b) result = product(result, power[static_cast<std::size_t>(q)]) + block(b);
  return result;
}

// e^{A tau}, tau > 0: the Taylor polynomial at A tau / 2^s, ||A tau / 2^s||_1 <= 2, squared s times.
template <class M>
M exponential(const M& A, Real norm, Real tau) {
  int s = 0;
  Real scale = tau;
  while (norm * scale > Real(taylor_radius)) {
    scale /= 2;
    ++s;
  }
  M E = taylor_exponential<M>(A * scale);
  for (int i = 0; i < s; ++i) E = product(E, E);
  return E;
}

// A's eigenvalues, sorted by imaginary part, where they are computed.
struct Spectrum {
  enum class State { not_computed, failed, computed } state = State::not_computed;
  std::vector<Complex> values;
};

Spectrum spectrum_of(const Matrix& A) {
  Spectrum s;
  if (A.rows() > max_eigenvalue_dim) return s;
  const Eigen::ComplexEigenSolver<Matrix> solver(A, false);
  poll();
  // On failure (no convergence, or an overflow to inf or NaN) the eigenvalues are not set.
  if (solver.info() != Eigen::Success || !solver.eigenvalues().allFinite()) {
    s.state = Spectrum::State::failed;
    return s;
  }
  s.state = Spectrum::State::computed;
  s.values.assign(solver.eigenvalues().data(), solver.eigenvalues().data() + solver.eigenvalues().size());
  std::sort(s.values.begin(), s.values.end(),
            [](Complex a, Complex b) { return a.imag() != b.imag() ? a.imag() < b.imag() : a.real() < b.real(); });
  return s;
}

std::string shown(Complex z) { return fmt::format("{:.6g}{:+.6g}i", z.real(), z.imag()); }

// "A's eigenvalues are ...": the last clause of a refusal.
std::string eigenvalue_clause(const Spectrum& s) {
  if (s.state == Spectrum::State::not_computed)
    return fmt::format("A's eigenvalues are not listed for A larger than {} x {}", max_eigenvalue_dim,
                       max_eigenvalue_dim);
  if (s.state == Spectrum::State::failed)
    return "A's eigenvalues are unknown: the eigenvalue decomposition failed (the complex Schur iteration did not "
           "converge to finite values)";
  std::string list;
  const std::size_t shown_count = std::min<std::size_t>(s.values.size(), 8);
  for (std::size_t i = 0; i < shown_count; ++i) list += (i ? ", " : "") + shown(s.values[i]);
  if (s.values.size() > shown_count) list += fmt::format(", ... ({} in all)", s.values.size());
  return "A's eigenvalues are " + list;
}

}  // namespace

Matrix matrix_from_json(const Json& value, const std::string& path, bool& complex_entries) {
  const std::string expected = "expected a square matrix: an array of rows, each an array of numbers ([re, im] for a complex one)";
  if (!value.is_array()) throw ConfigError(path, "got " + shown(value) + ", " + expected);
  if (value.empty()) throw ConfigError(path, "got [], " + expected);
  const std::size_t n = value.size();
  if (n > static_cast<std::size_t>(max_matrix_model_dim))
    throw ConfigError(path, fmt::format("has {} rows, expected at most {}", n, max_matrix_model_dim));
  for (std::size_t i = 0; i < n; ++i) {
    const Json& row = value[i];
    if (!row.is_array())
      throw ConfigError(fmt::format("{}[{}]", path, i), "got " + shown(row) + ", expected a row: an array of numbers");
    if (row.size() != n)
      throw ConfigError(fmt::format("{}[{}]", path, i),
                        fmt::format("has {} entries, expected {}: A must be square ({} rows)", row.size(), n, n));
  }
  complex_entries = false;
  const auto dim = static_cast<Index>(n);
  Matrix A(dim, dim);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      const Json& v = value[i][j];
      double re = 0.0, im = 0.0;
      const bool ok = json_number(v, re) ||
                      (v.is_array() && v.size() == 2 && json_number(v[0], re) && json_number(v[1], im));
      if (!ok)
        throw ConfigError(fmt::format("{}[{}][{}]", path, i, j),
                          "got " + shown(v) + ", expected a finite number (or [re, im] for a complex entry)");
      if (im != 0.0) complex_entries = true;
      A(static_cast<Index>(i), static_cast<Index>(j)) = Complex(re, im);
    }
  }
  return A;
}

namespace {

// What the set-up finds: A's frequencies k (k >= 0 only for a real A, whose P_{-k} is conj(P_k))
// with their spectral projectors P_k, and the deviation of e^{2 pi A} from I.
struct FlowParts {
  std::vector<long> frequencies;
  std::vector<Matrix> projectors;
  long max_frequency = 0;
  Real deviation = 0;
};

// Sums P_k = (1/N) sum_j e^{-i k tau_j} E_j, tau_j = 2 pi j / N, over samples E_j handed in one by
// one: a block of them at a time, as one product of (n^2 x B) samples by (B x #k) phases (at
// n = 1024, N = 32, 16 frequencies: 0.2 s instead of 3 s of additions).
template <class M>
class ProjectorSums {
 public:
  using Scalar = typename M::Scalar;
  static constexpr bool real = std::is_same_v<Scalar, Real>;

  ProjectorSums(Index n, std::vector<long> ks, long samples)
      : n_(n),
        ks_(std::move(ks)),
        samples_(samples),
        block_(std::clamp<Index>((Index(1) << 23) / (n * n), 1, 64)),
        buffer_(n * n, block_),
        indices_(static_cast<std::size_t>(block_)) {
    const auto count = static_cast<Index>(ks_.size());
    if constexpr (real) {
      re_ = RealMatrix::Zero(n * n, count);
      im_ = RealMatrix::Zero(n * n, count);
    } else {
      sums_ = Matrix::Zero(n * n, count);
    }
  }

  void add(long j, const M& E) {
    buffer_.col(used_) = Eigen::Map<const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>>(E.data(), n_ * n_);
    indices_[static_cast<std::size_t>(used_++)] = j;
    if (used_ == block_) flush();
  }

  std::vector<Matrix> projectors() {
    flush();
    std::vector<Matrix> out;
    for (Index m = 0; m < static_cast<Index>(ks_.size()); ++m) {
      Matrix P(n_, n_);
      if constexpr (real) {
        P.real() = Eigen::Map<const RealMatrix>(re_.col(m).data(), n_, n_);
        P.imag() = Eigen::Map<const RealMatrix>(im_.col(m).data(), n_, n_);
      } else {
        P = Eigen::Map<const Matrix>(sums_.col(m).data(), n_, n_);
      }
      out.push_back(std::move(P));
    }
    return out;
  }

 private:
  void flush() {
    if (used_ == 0) return;
    Matrix phases(used_, static_cast<Index>(ks_.size()));
    for (Index b = 0; b < used_; ++b)
      for (Index m = 0; m < phases.cols(); ++m) {
        // k j mod N in integers: the phase stays exact for k and j up to 1e6 and 2^22.
        const long long turns = (static_cast<long long>(ks_[static_cast<std::size_t>(m)]) *
                                 indices_[static_cast<std::size_t>(b)]) % samples_;
        phases(b, m) = std::polar(Real(1) / static_cast<Real>(samples_),
                                  -two_pi * static_cast<Real>(turns) / static_cast<Real>(samples_));
      }
    if constexpr (real) {
      const RealMatrix cosines = phases.real(), sines = phases.imag();
      re_.noalias() += buffer_.leftCols(used_) * cosines;
      im_.noalias() += buffer_.leftCols(used_) * sines;
    } else {
      sums_.noalias() += buffer_.leftCols(used_) * phases;
    }
    used_ = 0;
    poll();
  }

  Index n_;
  std::vector<long> ks_;
  long samples_;
  Index block_, used_ = 0;
  M buffer_;
  std::vector<long> indices_;
  RealMatrix re_, im_;  // a real A's sums
  Matrix sums_;         // a complex A's
};

// The set-up of PeriodicMatrixFlow on A as M: RealMatrix for a real A (products four times
// cheaper), Matrix for a complex one.
template <class M>
class FlowSetUp {
 public:
  static constexpr bool real = std::is_same_v<typename M::Scalar, Real>;

  FlowSetUp(const Matrix& A, Real norm, const std::string& path)
      : complex_A_(A), A_(as_M(A)), n_(A.rows()), norm_(norm), path_(path) {}

  FlowParts run() { return n_ <= max_eigenvalue_dim ? from_eigenvalues() : from_samples(); }

 private:
  static M as_M(const Matrix& A) {
    if constexpr (real)
      return A.real();
    else
      return A;
  }
  M identity() const { return M::Identity(n_, n_); }

  // e^{2 pi A} - I, computed once (where a refusal comes before the samples).
  Real deviation() {
    if (!deviation_) deviation_ = largest_entry(M(exponential(A_, norm_, two_pi) - identity()));
    return *deviation_;
  }

  // Every refusal of a non-periodic A opens alike: what e^{2 pi A} is, then what failed.
  [[noreturn]] void refuse_not_periodic(const std::string& what) {
    const Real d = deviation();
    throw ConfigError(path_, fmt::format("e^(2 pi A) differs from the identity by {:.3g} (its largest entry of "
                                         "e^(2 pi A) - I): {}; e^(A tau) must be 2 pi-periodic: A diagonalisable "
                                         "with eigenvalues i k, k integer (the fast frequency is 1/eps: scale A so "
                                         "that it is); {}",
                                         d, what, eigenvalue_clause(spectrum_)));
  }

  void check_cost(long samples, long frequency) const {
    const double cost = static_cast<double>(samples) * std::pow(static_cast<double>(n_), 3.0);
    if (cost > max_cost)
      throw ConfigError(path_, fmt::format("is {} x {} with frequencies up to {}: its e^(A tau) needs {} samples, one "
                                           "product of {} x {} matrices each ({:.2g} operations), more than this model "
                                           "computes ({:.0e}, {} samples at this size)",
                                           n_, n_, frequency, samples, n_, n_, cost, max_cost,
                                           largest_sample_count()));
  }
  // The largest power of two N >= 4 with N n^3 <= max_cost.
  long largest_sample_count() const {
    long samples = 4;
    while (2.0 * static_cast<double>(samples) * std::pow(static_cast<double>(n_), 3.0) <= max_cost &&
           samples < (1L << 22))
      samples *= 2;
    return samples;
  }

  // Rounding allowed in the checks: rounding_allowance units times N max(1, |A|_1) max(1, max|E_j|)^2.
  // The samples' errors grow with N (a chain of products), |A| and, for a non-normal A, with the
  // square of the conditioning of its eigenvectors, which max|E_j| measures. Where that reaches
  // 1e-6 |A|, the checks could no longer tell a periodic A from another: refused.
  Real tolerance(long samples, Real largest_sample) const {
    const Real conditioning = std::max<Real>(1, largest_sample);
    const Real allowed = Real(rounding_allowance) * std::numeric_limits<Real>::epsilon() *
                         static_cast<Real>(samples) * std::max<Real>(1, norm_) * conditioning * conditioning;
    if (!(allowed <= Real(1e-6) * std::max<Real>(1, norm_)))
      throw ConfigError(path_, fmt::format("has e^(A tau) with entries up to {:.3g} (its eigenvectors that far from "
                                           "orthogonal): the rounding of its {} samples ({:.3g}, {:.0f} units times "
                                           "N max(1, |A|_1) max|e^(A tau)|^2) exceeds 1e-6 |A|_1, too much to tell "
                                           "whether A is periodic; expected a better conditioned A; {}",
                                           largest_sample, samples, allowed, rounding_allowance,
                                           eigenvalue_clause(spectrum_)));
    return allowed;
  }

  // The frequencies from A's eigenvalues, then the N > 2 max|k| samples E_j = E_{j-1} e^{A 2 pi/N}.
  FlowParts from_eigenvalues() {
    spectrum_ = spectrum_of(complex_A_);
    if (spectrum_.state == Spectrum::State::failed)
      throw ConfigError(path_, fmt::format("has no eigenvalue decomposition: the complex Schur iteration did not "
                                           "converge to finite values ({} x {}, largest entry {:.3g}, 1-norm {:.3g}); "
                                           "expected a matrix whose eigenvalues are i k with integer k",
                                           n_, n_, largest_entry(complex_A_), norm_));
    FlowParts parts;
    std::set<long> ks;
    Real worst = -1;
    Complex worst_value;
    long worst_k = 0;
    for (const Complex& lambda : spectrum_.values) {
      if (!(std::fabs(lambda.imag()) <= max_frequency_taken))
        throw ConfigError(path_, fmt::format("has the eigenvalue {:.6g}i: frequencies up to 1e6 are taken (the fast "
                                             "frequency is 1/eps: scale A so that it is)",
                                             lambda.imag()));
      const long k = std::lround(lambda.imag());
      const Real distance = std::abs(lambda - Complex(0, static_cast<Real>(k)));
      if (distance > worst) worst = distance, worst_value = lambda, worst_k = k;
      ks.insert(real ? std::abs(k) : k);
      parts.max_frequency = std::max(parts.max_frequency, std::abs(k));
    }
    // A coarse test with a clear message; the reconstruction below is the tight one.
    const Real eigenvalue_tolerance = Real(1e-9) * std::max<Real>(1, norm_);
    if (worst > eigenvalue_tolerance)
      refuse_not_periodic(fmt::format("A's eigenvalue {} is {:.3g} from i k with k = {}, expected at most {:.3g} "
                                      "(1e-9 max(1, |A|_1))",
                                      shown(worst_value), worst, worst_k, eigenvalue_tolerance));
    long samples = 4;
    while (samples < 2 * parts.max_frequency + 2) samples *= 2;
    check_cost(samples, parts.max_frequency);
    parts.frequencies.assign(ks.begin(), ks.end());
    // E_j from e^{A 2 pi 2^b / N}, b < log2 N (squares of the first): E_{j + 2^b} = E_j e^{A 2 pi 2^b/N},
    // depth first, so that each sample is one product and at most log2 N products deep (a
    // chain E_{j-1} e^{A 2 pi/N} would be j deep, its rounding growing with N), and at most
    // log2 N samples are held at once.
    std::vector<M> steps = {exponential(A_, norm_, two_pi / static_cast<Real>(samples))};
    for (long N = samples; N > 1; N /= 2) steps.push_back(product(steps.back(), steps.back()));
    deviation_ = parts.deviation = largest_entry(M(steps.back() - identity()));  // e^{2 pi A} - I
    steps.pop_back();
    ProjectorSums<M> sums(n_, parts.frequencies, samples);
    Real largest_sample = 1;
    const auto visit = [&](const auto& self, const M& E, long j, std::size_t bits) -> void {
      largest_sample = std::max(largest_sample, largest_entry(E));
      sums.add(j, E);
      for (std::size_t b = bits; b-- > 0;) self(self, product(E, steps[b]), j + (1L << b), b);
    };
    visit(visit, identity(), 0, steps.size());
    parts.projectors = sums.projectors();
    check_reconstruction(parts, samples, largest_sample);
    return parts;
  }

  // A larger A: samples at N = 4, 8, ... phases (each level adds N/2 products) until the
  // trigonometric interpolant of the samples has A as its derivative at 0, which it has exactly
  // when the samples resolve A's frequencies (an aliased frequency k' adds i (k - k') P_k').
  // The frequencies are those k whose P_k has a nonzero trace (its rank) in the DFT of tr E_j.
  FlowParts from_samples() {
    const long most = largest_sample_count();
    std::vector<M> generators;  // e^{A 2 pi / N} for N = 4, 8, .., most
    generators.push_back(exponential(A_, norm_, two_pi / static_cast<Real>(most)));
    for (long N = most; N > 4; N /= 2)
      generators.insert(generators.begin(), product(generators.front(), generators.front()));
    const M half_period = product(generators.front(), generators.front());
    deviation_ = largest_entry(M(product(half_period, half_period) - identity()));
    // A far from periodic is refused before any sample (the reconstruction below is the tight test).
    Real largest_sample = 1;
    for (const M& g : generators) largest_sample = std::max(largest_sample, largest_entry(g));
    const Real coarse = Real(1e-6) * std::max<Real>(1, norm_) * largest_sample * largest_sample;
    if (!(*deviation_ <= coarse))
      refuse_not_periodic(
          fmt::format("expected at most {:.3g} (1e-6 max(1, |A|_1) max(1, max|e^(A tau)|)^2)", coarse));

    std::vector<M> samples = {identity(), generators[0]};
    samples.push_back(product(samples[1], generators[0]));
    samples.push_back(product(samples[2], generators[0]));
    for (std::size_t level = 0;; ++level) {
      const long N = static_cast<long>(samples.size());
      // The interpolant's derivative at 0: sum_j d_j E_j, d_j = (2/N) sum_{0<k<N/2} k sin(k tau_j).
      M derivative = M::Zero(n_, n_);
      for (long j = 1; j < N; ++j) {
        Real d = 0;
        for (long k = 1; k < N / 2; ++k)
          d += static_cast<Real>(k) * std::sin(two_pi * static_cast<Real>((k * j) % N) / static_cast<Real>(N));
        derivative += (2 * d / static_cast<Real>(N)) * samples[static_cast<std::size_t>(j)];
        largest_sample = std::max(largest_sample, largest_entry(samples[static_cast<std::size_t>(j)]));
      }
      poll();
      const Real miss = largest_entry(Matrix(complex_A_ - derivative.template cast<Complex>()));
      const Real allowed = tolerance(N, largest_sample);
      // The multiplicities of the frequencies (aliased ones summed): the DFT of the traces. They
      // are integers for any periodic A, resolved or not; an eigenvalue i (k + delta) gives a
      // fraction of about pi delta at once, without refining to the most samples.
      std::vector<Real> rank(static_cast<std::size_t>(N));
      Real fraction = 0;
      long fraction_at = 0;
      for (long k = 0; k < N; ++k) {
        Complex sum(0, 0);
        for (long j = 0; j < N; ++j)
          sum += Complex(samples[static_cast<std::size_t>(j)].trace()) *
                 std::polar(Real(1), -two_pi * static_cast<Real>((k * j) % N) / static_cast<Real>(N));
        sum /= static_cast<Real>(N);
        rank[static_cast<std::size_t>(k)] = std::abs(sum);
        const Real off = std::abs(sum - Complex(std::round(sum.real()), 0));
        if (off > fraction) fraction = off, fraction_at = k < N / 2 ? k : k - N;
      }
      const Real allowed_fraction = allowed * static_cast<Real>(n_) / std::max<Real>(1, norm_);
      if (fraction > allowed_fraction)
        refuse_not_periodic(fmt::format("the multiplicities of A's frequencies (the DFT of tr e^(A tau) at {} "
                                        "phases) are not integers: {:.3g} off at k = {} (modulo {}), expected at "
                                        "most {:.3g}; A has an eigenvalue that is not i k",
                                        N, fraction, fraction_at, N, allowed_fraction));
      if (miss <= allowed && rank[static_cast<std::size_t>(N / 2)] < Real(0.5)) {
        FlowParts parts;
        parts.deviation = *deviation_;
        for (long k = 0; k < N; ++k) {  // k = N - m stands for the frequency -m
          const long frequency = k < N / 2 ? k : k - N;
          if (rank[static_cast<std::size_t>(k)] < Real(0.5) || (real && frequency < 0)) continue;
          parts.frequencies.push_back(frequency);
          parts.max_frequency = std::max(parts.max_frequency, std::abs(frequency));
        }
        std::sort(parts.frequencies.begin(), parts.frequencies.end());
        ProjectorSums<M> sums(n_, parts.frequencies, N);
        for (long j = 0; j < N; ++j) sums.add(j, samples[static_cast<std::size_t>(j)]);
        samples.clear();
        parts.projectors = sums.projectors();
        check_reconstruction(parts, N, largest_sample);
        return parts;
      }
      if (level + 1 == generators.size())
        throw ConfigError(path_, fmt::format("is {} x {} and {} samples of e^(A tau) (the most this model computes at "
                                             "this size: N n^3 <= {:.0e}) do not resolve it: the derivative at 0 of "
                                             "their trigonometric interpolant misses A by {:.3g} (largest entry), "
                                             "expected at most {:.3g}; A's frequencies reach N/2 = {} or more, or A "
                                             "is not diagonalisable with eigenvalues i k, k integer (e^(2 pi A) "
                                             "differs from the identity by {:.3g}); {}",
                                             n_, n_, N, max_cost, miss, allowed, N / 2, *deviation_,
                                             eigenvalue_clause(spectrum_)));
      // Twice the phases: E_{2j} = E_j, E_{2j+1} = E_j e^{A 2 pi / 2N}.
      std::vector<M> finer;
      finer.reserve(2 * samples.size());
      for (M& E : samples) {
        M odd = product(E, generators[level + 1]);
        finer.push_back(std::move(E));
        finer.push_back(std::move(odd));
      }
      samples = std::move(finer);
    }
  }

  // The tight test: A = sum_k i k P_k and I = sum_k P_k to rounding. It refuses an eigenvalue
  // i (k + delta) for delta well below the coarse test's, and a Jordan block at any size.
  void check_reconstruction(const FlowParts& parts, long samples, Real largest_sample) {
    Matrix derivative = Matrix::Zero(n_, n_), sum = Matrix::Zero(n_, n_);
    for (std::size_t m = 0; m < parts.frequencies.size(); ++m) {
      const long k = parts.frequencies[m];
      const Matrix& P = parts.projectors[m];
      const bool paired = real && k > 0;  // P_{-k} = conj(P_k)
      const Complex ik(0, static_cast<Real>(k));
      derivative += paired ? Matrix(ik * P + std::conj(ik) * P.conjugate()) : Matrix(ik * P);
      sum += paired ? Matrix(P + P.conjugate()) : P;
    }
    const Real miss_A = largest_entry(Matrix(derivative - complex_A_));
    const Real miss_I = largest_entry(Matrix(sum - Matrix::Identity(n_, n_)));
    const Real allowed = tolerance(samples, largest_sample);
    if (!(miss_A <= allowed && miss_I <= allowed))
      refuse_not_periodic(fmt::format(
          "sum_k i k P_k over A's spectral projectors P_k (from e^(A tau) at {} phases) misses A by {:.3g}, and "
          "sum_k P_k misses the identity by {:.3g} (largest entries), expected at most {:.3g} ({:.0f} rounding "
          "units times N max(1, |A|_1) max(1, max|e^(A tau)|)^2): an eigenvalue is off i k by more than rounding, "
          "or A is not diagonalisable (a Jordan block such as [[0, 1], [0, 0]] gives e^(A tau) = I + A tau)",
          samples, miss_A, miss_I, allowed, rounding_allowance));
  }

  const Matrix& complex_A_;
  M A_;
  Index n_;
  Real norm_;
  const std::string& path_;
  Spectrum spectrum_;
  std::optional<Real> deviation_;
};

}  // namespace

PeriodicMatrixFlow::PeriodicMatrixFlow(Matrix A, const std::string& path) : A_(std::move(A)) {
  const Index n = A_.rows();
  if (n == 0 || A_.cols() != n) throw ConfigError(path, fmt::format("is {} x {}, expected a nonempty square matrix", n, A_.cols()));
  if (!A_.allFinite()) throw ConfigError(path, "has an entry that is not finite");
  real_ = A_.imag().isZero(0.0);
  const Real norm = A_.cwiseAbs().colwise().sum().maxCoeff();
  if (!(norm <= max_A_norm))
    throw ConfigError(path, fmt::format("has the 1-norm {:.3g} (its largest column sum of |a_ij|), expected at most "
                                        "{:.0e}: beyond it double precision's rounding of A (2.2e-16 |A|) reaches "
                                        "1e-6 in A's eigenvalues, which can then not be told from i k; A's "
                                        "frequencies are at most 1e6 (the fast frequency is 1/eps: scale A so that "
                                        "it is)",
                                        norm, max_A_norm));
  FlowParts parts = real_ ? FlowSetUp<RealMatrix>(A_, norm, path).run() : FlowSetUp<Matrix>(A_, norm, path).run();
  max_frequency_ = parts.max_frequency;
  deviation_ = parts.deviation;
  frequencies_ = std::move(parts.frequencies);
  projectors_ = std::move(parts.projectors);
}

Matrix PeriodicMatrixFlow::at(Real tau) const {
  Matrix E = Matrix::Zero(dim(), dim());
  for (std::size_t m = 0; m < frequencies_.size(); ++m) {
    // A real A keeps k >= 0: P_k e^{ik tau} + conj(P_k e^{ik tau}) has the real part 2 Re(P_k e^{ik tau}).
    const Real weight = real_ && frequencies_[m] > 0 ? 2 : 1;
    E += std::polar(weight, static_cast<Real>(frequencies_[m]) * tau) * projectors_[m];
  }
  if (real_) E.imag().setZero();
  return E;
}

void PeriodicMatrixFlow::apply(const RealVector& taus, MatrixRef states) const {
  const Index n = dim(), m = states.cols();
  if (real_) {
    // e^{A tau} s = sum_k w_k (cos(k tau) Re P_k - sin(k tau) Im P_k) s, on [Re s, Im s]: real products.
    RealMatrix parts(n, 2 * m), sum = RealMatrix::Zero(n, 2 * m), by_re(n, 2 * m), by_im(n, 2 * m);
    parts.leftCols(m) = states.real();
    parts.rightCols(m) = states.imag();
    for (std::size_t f = 0; f < frequencies_.size(); ++f) {
      const RealMatrix re = projectors_[f].real(), im = projectors_[f].imag();
      by_re.noalias() = re * parts;
      by_im.noalias() = im * parts;
      const Real weight = frequencies_[f] > 0 ? 2 : 1;
      for (Index j = 0; j < m; ++j) {
        const Complex phase = std::polar(weight, static_cast<Real>(frequencies_[f]) * taus(j));
        for (const Index c : {j, j + m}) sum.col(c) += phase.real() * by_re.col(c) - phase.imag() * by_im.col(c);
      }
    }
    states.real() = sum.leftCols(m);
    states.imag() = sum.rightCols(m);
    return;
  }
  Matrix sum = Matrix::Zero(n, m), turned(n, m);
  for (std::size_t f = 0; f < frequencies_.size(); ++f) {
    turned.noalias() = projectors_[f] * states;
    for (Index j = 0; j < m; ++j)
      sum.col(j) += std::polar(Real(1), static_cast<Real>(frequencies_[f]) * taus(j)) * turned.col(j);
  }
  states = sum;
}

void check_matrix_model_n_tau(const ModelEntry& entry, const Model& model, long n_tau) {
  if (entry.info.name != "matrix" || entry.info.provider != "core") return;
  const auto k = static_cast<long>(model.max_linear_frequency());
  if (n_tau > 4 * k) return;
  const long needed = 4 * k + 2;
  long power = 2;
  while (power < needed) power *= 2;
  const std::string hint =
      needed > (1L << 20)
          ? fmt::format("beyond the largest n_tau ({}): this A runs on the filtered or direct reformulation only",
                        1L << 20)
          : fmt::format("{} or more ({} the next power of two)", needed, power);
  throw ConfigError("reformulation.n_tau",
                    fmt::format("got {}, but model.A has frequencies up to {}: f_tau(U) = e^(-A tau) f(e^(A tau) U) "
                                "then has tau harmonics up to 2 x {} = {} for any field f (more for a nonlinear one), "
                                "and n_tau points resolve |k| < n_tau/2 only, aliasing the rest (a two-scale "
                                "reference takes its own reference.n_tau); expected n_tau > 4 x {} = {}: {}",
                                n_tau, k, k, 2 * k, k, 4 * k, hint));
}

namespace {

// A time-dependent field is the model's TimeDependentField: make_matrix_model hands it to
// with_time_as_variable, which carries t, and the model itself is of A's size alone.
class MatrixModel final : public Model, public FusedTauGrid, public TimeDependentField {
 public:
  MatrixModel(Real eps, PeriodicMatrixFlow flow, std::shared_ptr<const Field> field, bool time_dependent,
              bool is_complex, Vector u0, std::string field_name)
      : Model(eps),
        flow_(std::move(flow)),
        field_(std::move(field)),
        d_(flow_.dim()),
        time_(time_dependent),
        complex_(is_complex),
        u0_(std::move(u0)),
        field_name_(std::move(field_name)) {
    // An affine f (B u + t a + b) has an exact solution; with t not carried, only where a = 0.
    const AffineTerms* terms = field_->affine_terms();
    if (terms && d_ <= max_affine_exact_dim && terms->B.rows() == d_ && (time_ || terms->a.isZero(0.0)))
      exact_ = AffineExact(flow_.A(), this->eps(), *terms);
  }

  Index dim() const override { return d_; }
  bool is_complex() const override { return complex_; }
  // No Hamiltonian structure: f is any field, A any matrix with a 2 pi-periodic e^{A tau}. The
  // fused tau grid evaluates f at t = 0: an autonomous field's only.
  const TimeDependentField* time_dependent_field() const override { return time_ ? this : nullptr; }
  const FusedTauGrid* fused_tau_grid() const override { return time_ ? nullptr : this; }
  double max_linear_frequency() const override { return std::max(1.0, static_cast<double>(flow_.max_frequency())); }

  void linear_flow(const RealVector& taus, MatrixRef states) const override { flow_.apply(taus, states); }

  void apply_A(const Vector& u, Vector& out) const override { out = flow_.A() * u; }

  void nonlinear_field(ConstMatrixRef states, MatrixRef out) const override {
    if (time_) return Model::nonlinear_field(states, out);  // refused: f(t, u) is nonlinear_field_at
    field_->evaluate(RealVector::Zero(states.cols()), states, out);
  }
  void nonlinear_field_at(const RealVector& t, ConstMatrixRef states, MatrixRef out) const override {
    field_->evaluate(t, states, out);
  }

  void nonlinear_field_derivative(ConstMatrixRef states, ConstMatrixRef directions, MatrixRef out) const override {
    if (time_ || !field_->has_derivative()) return Model::nonlinear_field_derivative(states, directions, out);
    field_->derivative(RealVector::Zero(states.cols()), states, directions, out);
  }
  void nonlinear_field_derivative_at(const RealVector& t, ConstMatrixRef states, ConstMatrixRef directions,
                                     MatrixRef out) const override {
    if (!field_->has_derivative()) return TimeDependentField::nonlinear_field_derivative_at(t, states, directions, out);
    field_->derivative(t, states, directions, out);
  }

  // f_tau on a fixed tau grid: e^{A tau_j} and e^{-A tau_j} tabulated once per binding.
  class GridField final : public TauGridField {
   public:
    GridField(const MatrixModel& model, const RealVector& taus)
        : model_(model), taus_(taus), t_(RealVector::Zero(taus.size())), turned_(model.d_, taus.size()),
          field_(model.d_, taus.size()) {
      const double bytes = 2.0 * static_cast<double>(taus.size()) * static_cast<double>(model.d_ * model.d_) * 16.0;
      tabulated_ = bytes <= 512e6;  // else each evaluation applies the projectors to all columns
      if (!tabulated_) return;
      forward_.reserve(static_cast<std::size_t>(taus.size()));
      backward_.reserve(static_cast<std::size_t>(taus.size()));
      for (Index j = 0; j < taus.size(); ++j) {
        forward_.push_back(model.flow_.at(taus(j)));
        backward_.push_back(model.flow_.at(-taus(j)));
      }
    }
    void evaluate(MatrixRef states, MatrixRef out) override {
      if (!tabulated_) {  // one product of each P_k with all the columns, each way
        turned_ = states;
        model_.flow_.apply(taus_, turned_);
        model_.field_->evaluate(t_, turned_, field_);
        model_.flow_.apply(-taus_, field_);
        out = field_;
        return;
      }
      for (Index j = 0; j < states.cols(); ++j)
        turned_.col(j).noalias() = forward_[static_cast<std::size_t>(j)] * states.col(j);
      model_.field_->evaluate(t_, turned_, field_);
      for (Index j = 0; j < states.cols(); ++j)
        out.col(j).noalias() = backward_[static_cast<std::size_t>(j)] * field_.col(j);
    }

   private:
    const MatrixModel& model_;
    RealVector taus_, t_;  // t_: 0, an autonomous field's
    Matrix turned_, field_;
    bool tabulated_ = false;
    std::vector<Matrix> forward_, backward_;
  };

  std::unique_ptr<TauGridField> bind_tau_grid(const RealVector& taus) const override {
    return std::make_unique<GridField>(*this, taus);
  }

  const ExactSolution* exact_solution() const override { return exact_ ? &*exact_ : nullptr; }

  Vector initial_value() const override {
    if (u0_.size() != d_)
      throw ConfigError("model.u0", fmt::format("the field \"{}\" gives no default initial value for this A: give "
                                                "model.u0 ({} {})",
                                                field_name_, d_, complex_ ? "numbers or [re, im] pairs" : "numbers"));
    return u0_;
  }

 private:
  class AffineExact final : public ExactSolution {
   public:
    AffineExact(Matrix A, Real eps, AffineTerms terms) : A_(std::move(A)), eps_(eps), terms_(std::move(terms)) {}
    Value at(const Vector& x0, Real t) const override { return affine_exact_solution(A_, eps_, terms_, x0, t); }

   private:
    Matrix A_;
    Real eps_;
    AffineTerms terms_;
  };

  PeriodicMatrixFlow flow_;
  std::optional<AffineExact> exact_;
  std::shared_ptr<const Field> field_;
  Index d_;
  bool time_, complex_;
  Vector u0_;
  std::string field_name_;
};

// HOODESolver.jl's quickstart f(u) = (0, u4, 2 u1 u2, -u2 - u1^2 + u2^2): the default field.
class QuickstartField final : public Field {
 public:
  void evaluate(const RealVector&, ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out(0, j) = 0.0;
      out(1, j) = u(3, j);
      out(2, j) = Real(2) * u(0, j) * u(1, j);
      out(3, j) = -u(1, j) - u(0, j) * u(0, j) + u(1, j) * u(1, j);
    }
  }
  bool has_derivative() const override { return true; }
  void derivative(const RealVector&, ConstMatrixRef u, ConstMatrixRef z, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out(0, j) = 0.0;
      out(1, j) = z(3, j);
      out(2, j) = Real(2) * (z(0, j) * u(1, j) + u(0, j) * z(1, j));
      out(3, j) = -z(1, j) - Real(2) * u(0, j) * z(0, j) + Real(2) * u(1, j) * z(1, j);
    }
  }
};

// HOODESolver.jl's linear test f(t, u) = B u + t a + b (its values: the parity issue; exact
// solution: SPEC.md section 7).
class LinearTestField final : public Field {
 public:
  LinearTestField() {
    // The peer's decimal numbers as doubles, whatever Real is: the same problem in every precision.
    terms_.B = (Eigen::Matrix4d() << 0.12, -0.78, 0.91, 0.34, -0.45, 0.56, 0.03, 0.54, -0.67, 0.09, 0.18, 0.89, -0.91,
                -0.56, 0.11, -0.56)
                   .finished()
                   .cast<Complex>();
    terms_.a = Eigen::Vector4d(0.12, -0.98, 0.45, 0.26).cast<Complex>();
    terms_.b = Eigen::Vector4d(-0.04, 0.48, 0.23, -0.87).cast<Complex>();
  }
  void evaluate(const RealVector& t, ConstMatrixRef u, MatrixRef out) const override {
    out.noalias() = terms_.B * u;
    for (Index j = 0; j < u.cols(); ++j) out.col(j) += t(j) * terms_.a + terms_.b;
  }
  bool has_derivative() const override { return true; }
  void derivative(const RealVector&, ConstMatrixRef, ConstMatrixRef z, MatrixRef out) const override {
    out.noalias() = terms_.B * z;
  }
  const AffineTerms* affine_terms() const override { return &terms_; }

 private:
  AffineTerms terms_;
};

Json quickstart_A() {
  return Json::array({Json::array({0, 0, 1, 0}), Json::array({0, 0, 0, 0}), Json::array({-1, 0, 0, 0}),
                      Json::array({0, 0, 0, 0})});
}

}  // namespace

std::unique_ptr<Model> make_matrix_model(Real eps, PeriodicMatrixFlow flow, std::shared_ptr<const Field> field,
                                         bool time_dependent, bool is_complex, Vector u0, std::string field_name) {
  if (!field) throw Error("make_matrix_model: no field");
  return with_time_as_variable(std::make_unique<MatrixModel>(eps, std::move(flow), std::move(field), time_dependent,
                                                             is_complex, std::move(u0), std::move(field_name)));
}

void register_matrix_model(Registry& registry) {
  FieldEntry quickstart;
  quickstart.info.name = "quickstart";
  quickstart.info.summary = "HOODESolver.jl's quickstart f(u) = (0, u4, 2 u1 u2, -u2 - u1^2 + u2^2), 4 entries, "
                            "default u0 (0.55, 0.12, 0.03, 0.89)";
  quickstart.dim = 4;
  quickstart.initial_value = Eigen::Vector4d(0.55, 0.12, 0.03, 0.89).cast<Complex>();
  quickstart.create = [](Index) { return std::make_shared<QuickstartField>(); };
  registry.add_field(std::move(quickstart));

  FieldEntry linear;
  linear.info.name = "linear";
  linear.info.summary = "HOODESolver.jl's linear test f(t, u) = B u + t a + b, 4 entries, default u0 "
                        "(-0.34, 0.78, 0.67, -5.6); exact solution (reference.scheme \"exact\")";
  linear.dim = 4;
  linear.time_dependent = true;
  linear.initial_value = Eigen::Vector4d(-0.34, 0.78, 0.67, -5.6).cast<Complex>();
  linear.create = [](Index) { return std::make_shared<LinearTestField>(); };
  registry.add_field(std::move(linear));

  ModelEntry entry;
  entry.info.name = "matrix";
  entry.info.summary = "u' = (1/eps) A u + f(t, u) with A a 2 pi-periodic matrix given in the run's JSON and f a "
                       "registered field (model.f: a plugin's, Python's tsi.register_field, \"quickstart\" or \"linear\")";
  ParamSpec a = array_param("A", "the matrix A (rows of numbers, [re, im] for complex ones); e^(2 pi A) must be I. "
                                 "Default: HOODESolver.jl's quickstart A, turning (u1, u3)");
  a.default_value = quickstart_A();
  entry.info.params.push_back(std::move(a));
  entry.info.params.push_back(string_param("f", "quickstart",
                                           "the field f(t, u): the name of a registered field (tsi list fields)"));
  entry.default_n_tau = 32;
  entry.nonlinearity_degree = 0;  // f is any field: SE2 takes 6 Gauss nodes (exact to degree 10)
  // The default problem's regime (the quickstart, T = 1, h = 1/4 .. 1/32): at eps = 1e-2 and
  // 1e-3, h = 1/32 is about a half fast period (pi eps) or a whole number of them, and SE1, SE2
  // or the composition miss their orders there (step-size resonance); at 0.1 and 1e-4 every
  // scheme reaches its order.
  entry.verification.epsilons = {0.1, 1e-4};
  const Registry* fields = &registry;
  entry.create = [fields](const Params& p) -> std::unique_ptr<Model> {
    bool complex_entries = false;
    Matrix A = matrix_from_json(p.raw().at("A"), "model.A", complex_entries);
    const FieldEntry& f = fields->field(p.string("f"), "model.f");
    if (f.dim != 0 && f.dim != A.rows())
      throw ConfigError("model.A", fmt::format("is {} x {}, but the field \"{}\" (model.f) takes states of {} "
                                               "entries: expected a {} x {} matrix",
                                               A.rows(), A.rows(), f.info.name, f.dim, f.dim, f.dim));
    if (complex_entries && !f.is_complex)
      throw ConfigError("model.A", fmt::format("has complex entries, but the field \"{}\" (model.f) is real: a real "
                                               "field takes real states only (declare the field complex)",
                                               f.info.name));
    PeriodicMatrixFlow flow(std::move(A), "model.A");
    const Index d = flow.dim();
    std::shared_ptr<const Field> field = f.create(d);
    if (!field) throw ConfigError("model.f", "the field \"" + f.info.name + "\" created nothing");
    Vector u0 = f.initial_value.size() == d ? f.initial_value : Vector();
    return make_matrix_model(p.number("eps"), std::move(flow), std::move(field), f.time_dependent,
                             complex_entries || f.is_complex, std::move(u0), f.info.name);
  };
  registry.add_model(std::move(entry));
}

}  // namespace tsi
