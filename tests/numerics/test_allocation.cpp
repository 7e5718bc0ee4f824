// No heap allocation inside a step: the two-scale nonlinearity and an SE1 step reuse
// buffers made once per run. Counted by interposing glibc's malloc family in this test
// program: Eigen, libstdc++'s operator new, libtsi_core and the plugins all go through it.
#include <doctest/doctest.h>

#include <atomic>
#include <cstddef>
#include <string>

#include "harness.hpp"

// AddressSanitizer owns malloc: interposing it there crashes, so under ASan this file is empty.
#if !defined(__SANITIZE_ADDRESS__)

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

namespace {

// Allocations made by ten SE1 steps on the two-scale problem, after a first step that sizes
// the scheme's buffers.
long steady_state_allocations(const std::string& model_name, const tsi::Json& params) {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model_with(model_name, 1e-3, params);
  auto two_scale = h.reformulation("two-scale", model);
  auto se1 = h.scheme("se1")->bind(*two_scale, 0.125);
  tsi::Vector y = two_scale->prepare(model->initial_value());
  se1->step(0.0, y);
  const long before = allocations.load();
  for (int n = 1; n <= 10; ++n) se1->step(0.125 * n, y);
  return allocations.load() - before;
}

}  // namespace

TEST_CASE("a two-scale SE1 step allocates no heap memory once the run is set up") {
  CHECK(steady_state_allocations("henon-heiles", tsi::Json::object()) == 0);
  // The counter works: an Eigen vector does allocate.
  const long probe = allocations.load();
  tsi::Vector copy = tsi::Vector::Zero(64);
  CHECK(allocations.load() - probe >= 1);
  CHECK(copy.size() == 64);
}

TEST_CASE("a two-scale SE1 step on Klein-Gordon (x transforms, a linear remainder) allocates no heap memory") {
  CHECK(steady_state_allocations("klein-gordon", {{"n_x", 32}}) == 0);
}

TEST_CASE("every two-scale scheme, once bound, steps without allocating (multistep history included)") {
  auto& h = tsi::test::Harness::instance();
  auto model = h.model_with("henon-heiles", 1e-3, tsi::Json::object());
  auto two_scale = h.reformulation("two-scale", model);
  for (const auto* entry : tsi::test::two_scale_schemes()) {
    CAPTURE(entry->info.name);
    auto stepper = h.scheme(entry->info.name, tsi::Json::object(), "henon-heiles")->bind(*two_scale, 0.125);
    tsi::Vector y = two_scale->prepare(model->initial_value());
    stepper->step(0.0, y);  // a multistep start-up and the solvers' first sizing
    const long before = allocations.load();
    for (int n = 1; n <= 10; ++n) stepper->step(0.125 * n, y);
    CHECK(allocations.load() - before == 0);
  }
}

TEST_CASE("every two-scale scheme steps without allocating on a large NLS grid (coefficients per tau mode, the field in place, by slices)") {
  // n_x = 2048, n_tau = 64: L and the coefficients one value per tau mode, the tau transforms
  // from y into the caller's vector through their blocks, the NLS field in place 32 columns at
  // a time.
  auto& h = tsi::test::Harness::instance();
  auto model = h.model_with("nls", 0.1, {{"n_x", 2048}});
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}});
  REQUIRE(two_scale->linear_multipliers().run() == 2048);
  for (const auto* entry : tsi::test::two_scale_schemes()) {
    CAPTURE(entry->info.name);
    auto stepper = h.scheme(entry->info.name, tsi::Json::object(), "nls")->bind(*two_scale, 1e-3);
    tsi::Vector y = two_scale->prepare(model->initial_value());
    stepper->step(0.0, y);
    const long before = allocations.load();
    for (int n = 1; n <= 3; ++n) stepper->step(1e-3 * n, y);
    CHECK(allocations.load() - before == 0);
  }
}

TEST_CASE("SE1 steps without allocating on 2-D and 3-D grids (NLS and Klein-Gordon, transforms by direction)") {
  // 64 x 64 and 16 x 16 x 16: 4096 points, the transforms one direction at a time through
  // FftBatch's blocks; Klein-Gordon's in real transforms.
  auto& h = tsi::test::Harness::instance();
  for (const char* name : {"nls", "klein-gordon"})
    for (const tsi::Json& grid : {tsi::Json{{"dims", 2}, {"n_x", 64}}, tsi::Json{{"dims", 3}, {"n_x", 16}}}) {
      CAPTURE(std::string(name));
      CAPTURE(grid.dump());
      auto model = h.model_with(name, 0.1, grid);
      auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 16}});
      auto stepper = h.scheme("se1", tsi::Json::object(), name)->bind(*two_scale, 1e-3);
      tsi::Vector y = two_scale->prepare(model->initial_value());
      stepper->step(0.0, y);
      const long before = allocations.load();
      for (int n = 1; n <= 3; ++n) stepper->step(1e-3 * n, y);
      CHECK(allocations.load() - before == 0);
    }
}

#endif  // !__SANITIZE_ADDRESS__
