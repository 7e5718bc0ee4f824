// The schemes' vector arithmetic on a diagonal that carries threads (tsi::Diagonal::threads):
// the same numbers as on one thread, each entry its definition, where the threads' ranges cut
// runs of equal entries; and tsi::parallel_for visits each index once.
#include <doctest/doctest.h>

#include <array>
#include <atomic>
#include <vector>

#include "tsi/algebra.hpp"
#include "tsi/parallel.hpp"

namespace {

using tsi::Complex;
using tsi::Diagonal;
using tsi::Index;
using tsi::Vector;

// 200,000 entries (above the 2^16 from which the work is split), runs of 40,000: two threads'
// ranges meet at entry 100,000, inside the third run.
constexpr Index n = 200000, run = 40000;

Vector pattern(int seed, Index size) {
  Vector v(size);
  for (Index i = 0; i < size; ++i)
    v(i) = Complex(std::sin(0.37 * static_cast<double>(i) + seed), std::cos(0.11 * static_cast<double>(i) * seed + 1.0));
  return v;
}

double max_difference(const Vector& a, const Vector& b) { return (a - b).cwiseAbs().maxCoeff(); }

}  // namespace

TEST_CASE("algebra on a diagonal with threads: the one-thread numbers, each entry its definition") {
  const Vector x1 = pattern(1, n), x2 = pattern(2, n), x3 = pattern(3, n);
  for (const bool per_entry : {false, true}) {
    CAPTURE(per_entry);
    // Runs of 40,000 entries, or one value per entry; the third always per entry (mixed runs).
    const Diagonal d1 = per_entry ? Diagonal(pattern(4, n)) : Diagonal(pattern(4, n / run), run);
    const Diagonal d2 = per_entry ? Diagonal(pattern(5, n)) : Diagonal(pattern(5, n / run), run);
    const Diagonal d3(pattern(6, n));
    const auto all = [&](int threads) {
      const Diagonal t1 = d1.with_threads(threads), t2 = d2.with_threads(threads), t3 = d3.with_threads(threads);
      std::array<Vector, 5> out;
      tsi::algebra::diagonal_multiply(t1, x1, out[0]);
      tsi::algebra::diagonal_multiply_add(x1, t1, x2, out[1]);
      tsi::algebra::diagonal_combination(t1, x1, t2, x2, out[2]);
      tsi::algebra::diagonal_combination(t1, x1, t2, x2, t3, x3, out[3]);
      const std::array<const Diagonal*, 2> d = {&t1, &t2};
      const std::array<const Vector*, 2> x = {&x2, &x3};
      tsi::algebra::diagonal_linear_combination(&x1, d, x, out[4]);
      return out;
    };
    const auto one = all(1), two = all(2);
    for (std::size_t k = 0; k < one.size(); ++k) {
      CAPTURE(k);
      CHECK(max_difference(one[k], two[k]) == 0.0);
    }
    Vector definition[5];
    for (auto& v : definition) v.resize(n);
    for (Index i = 0; i < n; ++i) {
      definition[0](i) = d1(i) * x1(i);
      definition[1](i) = x1(i) + d1(i) * x2(i);
      definition[2](i) = d1(i) * x1(i) + d2(i) * x2(i);
      definition[3](i) = d1(i) * x1(i) + d2(i) * x2(i) + d3(i) * x3(i);
      definition[4](i) = x1(i) + d1(i) * x2(i) + d2(i) * x3(i);
    }
    for (std::size_t k = 0; k < 5; ++k) {
      CAPTURE(k);
      CHECK(max_difference(two[k], definition[k]) <= 1e-15);  // |terms| <= 3: a rounding at most
    }
  }
  // The functions of a diagonal keep its threads, and `like` keeps them with other values.
  const Diagonal lambda = Diagonal(pattern(7, 5), run).with_threads(2);
  Diagonal e;
  tsi::diagonal_function(lambda, 0.5, [](Complex z) { return std::exp(z); }, e);
  CHECK(e.threads() == 2);
  CHECK(e.run() == run);
  CHECK(lambda.like(pattern(8, 5)).threads() == 2);
  CHECK(Diagonal(pattern(8, 5), run).threads() == 1);
}

TEST_CASE("parallel_for visits each index once, on one thread or several") {
  for (const int threads : {1, 2, 3}) {
    CAPTURE(threads);
    std::vector<std::atomic<int>> visits(1001);
    tsi::parallel_for(threads, 1001, [&](Index i) { visits[static_cast<std::size_t>(i)].fetch_add(1); });
    int wrong = 0;
    for (const auto& v : visits) wrong += v.load() != 1;
    CHECK(wrong == 0);
  }
  int calls = 0;
  tsi::parallel_for(2, 0, [&](Index) { ++calls; });
  CHECK(calls == 0);
}
