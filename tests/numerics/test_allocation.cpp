// No heap allocation inside a step: the two-scale nonlinearity and an SE1 step reuse
// buffers made once per run. Counted by replacing the global operator new in this test
// program (it sees allocations made inside libtsi_core and the plugins too).
#include <doctest/doctest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "harness.hpp"

namespace {
std::atomic<long> allocations{0};
}

void* operator new(std::size_t size) {
  ++allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

TEST_CASE("a two-scale SE1 step allocates no heap memory once the run is set up") {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model("henon-heiles", 1e-3);
  auto two_scale = h.reformulation("two-scale", model);
  auto se1 = h.scheme("se1");
  tsi::Vector y = two_scale->prepare(model->initial_value());
  se1->step(*two_scale, 0.0, 0.125, y);  // the first step sizes the scheme's buffers
  const long before = allocations.load();
  for (int n = 1; n <= 10; ++n) se1->step(*two_scale, 0.125 * n, 0.125, y);
  CHECK(allocations.load() - before == 0);
  // The counter works: an Eigen vector of this size does allocate.
  const long probe = allocations.load();
  tsi::Vector copy = y;
  CHECK(allocations.load() - probe >= 1);
  CHECK(copy.size() == y.size());
}
