// Bound steppers: a scheme bound to a problem and a step size owns its coefficients, so one
// Scheme bound to two problems of the same size (or to two step sizes) steps each exactly as
// a scheme bound to it alone would; nothing is cached by key.
#include <doctest/doctest.h>

#include "harness.hpp"

namespace {

using tsi::Vector;

// u after `steps` steps of `stepper` from the prepared data of `problem`'s model.
Vector run(tsi::Stepper& stepper, tsi::Reformulation& problem, int steps) {
  Vector y = problem.prepare(problem.model().initial_value());
  for (int n = 0; n < steps; ++n) stepper.step(n * stepper.h(), y);
  return y;
}

}  // namespace

TEST_CASE("one scheme bound to two problems of the same size keeps each problem's coefficients") {
  auto& h = tsi::test::Harness::instance();
  // Same size (Henon-Heiles, n_tau 64), different L: -i k / eps differs between the two.
  auto a = h.reformulation("two-scale", h.model_with("henon-heiles", 1e-2, tsi::Json::object()));
  auto b = h.reformulation("two-scale", h.model_with("henon-heiles", 1e-3, tsi::Json::object()));
  REQUIRE(a->size() == b->size());
  for (const char* name : {"se1", "se2", "fd", "me", "eab", "collocation", "composition"}) {
    CAPTURE(name);
    const auto shared = h.scheme(name, tsi::Json::object(), "henon-heiles");
    const auto on_a = shared->bind(*a, 0.1);
    const auto on_b = shared->bind(*b, 0.1);
    const Vector interleaved_a = run(*on_a, *a, 3);
    const Vector interleaved_b = run(*on_b, *b, 3);
    // The same steps from a scheme that never saw the other problem.
    const Vector alone_b = run(*h.scheme(name, tsi::Json::object(), "henon-heiles")->bind(*b, 0.1), *b, 3);
    CHECK(interleaved_b == alone_b);  // bit for bit
    CHECK((interleaved_a - interleaved_b).norm() > 1e-6);  // the two problems do differ
  }
}

TEST_CASE("a binding remembers its step size: h and -h are two bindings of one scheme") {
  auto& h = tsi::test::Harness::instance();
  auto problem = h.reformulation("two-scale", h.model_with("henon-heiles", 1e-2, tsi::Json::object()));
  const auto se1 = h.scheme("se1");
  const auto forward = se1->bind(*problem, 0.1), backward = se1->bind(*problem, -0.1);
  CHECK(forward->h() == 0.1);
  CHECK(backward->h() == -0.1);
  CHECK(&forward->problem() == problem.get());
  const Vector start = problem->prepare(problem->model().initial_value());
  Vector y = start;
  for (int n = 0; n < 5; ++n) forward->step(0.1 * n, y);
  for (int n = 5; n > 0; --n) backward->step(0.1 * n, y);
  CHECK(tsi::max_norm(y - start) / tsi::max_norm(start) < 1e-10);  // SE1 is symmetric
  CHECK(forward->state_vectors() >= 7.0);
}
