// No heap allocation inside a step: the two-scale nonlinearity and an SE1 step reuse
// buffers made once per run. Counted by interposing glibc's malloc family in this test
// program: Eigen, libstdc++'s operator new, libtsi_core and the plugins all go through it.
#include <doctest/doctest.h>

#include <atomic>
#include <cstddef>

#include "harness.hpp"

namespace {
std::atomic<long> allocations{0};
}

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);

void* malloc(std::size_t size) {
  ++allocations;
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  ++allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) {
  ++allocations;
  return __libc_realloc(p, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  ++allocations;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  ++allocations;
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : 12;  // ENOMEM
}
}

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

TEST_CASE("a two-scale SE1 step on Klein-Gordon (x transforms, a linear remainder) allocates no heap memory") {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model_with("klein-gordon", 1e-3, {{"n_x", 32}});
  auto two_scale = h.reformulation("two-scale", model);
  auto se1 = h.scheme("se1");
  tsi::Vector y = two_scale->prepare(model->initial_value());
  se1->step(*two_scale, 0.0, 0.125, y);  // the first step sizes the scheme's buffers
  const long before = allocations.load();
  for (int n = 1; n <= 10; ++n) se1->step(*two_scale, 0.125 * n, 0.125, y);
  CHECK(allocations.load() - before == 0);
}
