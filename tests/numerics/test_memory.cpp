// The memory of a binding: what a scheme says it will hold for a problem's layout before the
// problem is built is what the bound stepper holds; the coefficients of the exponential schemes
// take one value per tau mode on a large two-scale problem; and a run whose footprint exceeds
// the memory it may take is refused before the reformulation is built, naming its sizes.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <utility>

#include "harness.hpp"
#include "tsi/assembly.hpp"
#include "tsi/error.hpp"
#include "tsi/fft.hpp"

namespace {

using tsi::Json;
using tsi::test::Harness;

// NLS with n_x = 128 (enough unknowns for coefficients per tau mode) on n_tau = 16.
Json nls_config(const std::string& scheme, long n_x = 128, long n_tau = 16) {
  return {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", n_x}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", n_tau}}},
          {"scheme", {{"name", scheme}}},
          {"time", {{"h", 0.01}, {"t_end", 0.02}}}};
}

}  // namespace

TEST_CASE("memory: every two-scale scheme holds what it said it would, before the problem was built") {
  auto& h = Harness::instance();
  for (const char* model : {"henon-heiles", "nls"}) {
    CAPTURE(model);
    auto m = h.model_with(model, 0.1, std::string(model) == "nls" ? Json{{"n_x", 128}} : Json::object());
    auto problem = h.reformulation("two-scale", m, {{"n_tau", 16}});
    const tsi::ProblemLayout layout = problem->layout();
    CHECK(layout.size == problem->size());
    // NLS (128 unknowns) stores L once per tau mode; Henon-Heiles (4) per unknown.
    CHECK(layout.diagonal_values == (std::string(model) == "nls" ? 16 : problem->size()));
    for (const auto* entry : tsi::test::two_scale_schemes()) {
      CAPTURE(entry->info.name);
      const auto scheme = h.scheme(entry->info.name, Json::object(), model);
      const double predicted = scheme->state_vectors(layout);
      // Every shipped scheme says (asked at a large layout too: SE1's composition on
      // Henon-Heiles holds 2 x 8 vectors, the allowance's 16 by chance).
      CHECK(scheme->state_vectors({layout.size << 10, layout.diagonal_values}) != tsi::Scheme::unknown_state_vectors);
      CHECK(scheme->bind(*problem, 0.01)->state_vectors() == doctest::Approx(predicted));
    }
  }
}

TEST_CASE("memory: SE1, SE2, FD and ME hold at most 8 vectors of the state's size, eab and collocation 2 r and 3 s + 1") {
  auto& h = Harness::instance();
  auto problem = h.reformulation("two-scale", h.model_with("nls", 0.1, {{"n_x", 128}}), {{"n_tau", 16}});
  // Coefficients per tau mode: 16 values for 2048 unknowns, 1/128 of a vector each. SE1 holds
  // the stage, its N, its base (a small state: ProblemLayout::stores_stage_bases) and Picard's
  // iterate (and 4 coefficients); SE2 the iterate, N, the average and Picard's (2); FD the
  // half step and N (4); ME N and the previous N (5).
  const double coefficient = 1.0 / 128.0;
  const std::pair<const char*, double> expected[] = {
      {"se1", 4.0 + 4 * coefficient}, {"se2", 4.0 + 2 * coefficient}, {"fd", 2.0 + 4 * coefficient}, {"me", 2.0 + 5 * coefficient}};
  for (const auto& [name, vectors] : expected) {
    CAPTURE(name);
    const double held = h.scheme(name, Json::object(), "nls")->bind(*problem, 0.01)->state_vectors();
    CHECK(held <= 8.0);
    CHECK(held == doctest::Approx(vectors));
  }
  // eab of order 4: the history (4) and the start-up's past values (3), 20 coefficients;
  // collocation with 3 stages: the stages, their N and Picard's iterate on the stages (3 each)
  // and one stage, 16 coefficients.
  CHECK(h.scheme("eab", Json::object(), "nls")->bind(*problem, 0.01)->state_vectors() ==
        doctest::Approx(7.0 + 20 * coefficient));
  CHECK(h.scheme("collocation", Json::object(), "nls")->bind(*problem, 0.01)->state_vectors() ==
        doctest::Approx(10.0 + 16 * coefficient));
  // eab with HOODESolver's start-up, counted by hand at r = 4: the history (4), the backward
  // values, their N and the forward values (3 each), no interpolatory past values; the step's
  // 20 coefficients and the stages' e^{-hL}, 1 + 2 + 3 backward and 2 + 3 forward weights (12).
  const auto eab_peer = h.scheme("eab", Json{{"startup", "hoodesolver"}}, "nls");
  CHECK(eab_peer->bind(*problem, 0.01)->state_vectors() == doctest::Approx(13.0 + 32 * coefficient));
  CHECK(eab_peer->state_vectors(problem->layout()) == doctest::Approx(13.0 + 32 * coefficient));
  // Strang on the direct problem holds nothing of the state's size.
  auto direct = h.reformulation("direct", h.model_with("nls", 0.1, {{"n_x", 128}}));
  CHECK(h.scheme("strang")->bind(*direct, 0.01)->state_vectors() == 0.0);
}

TEST_CASE("memory: the footprint check counts the bound scheme's vectors and refuses a run over the limit") {
  auto& h = Harness::instance();
  const auto footprint = [&](const std::string& scheme) {
    tsi::AssemblyOptions options;
    return tsi::assemble_config(nls_config(scheme), h.registry(), options).footprint;
  };
  const tsi::Footprint se1 = footprint("se1"), eab = footprint("eab");
  CHECK(se1.state_bytes == 16.0 * 128 * 16);
  CHECK(se1.scheme_vectors == doctest::Approx(4.0 + 4.0 / 128));  // its stage base too (a small state)
  CHECK(eab.scheme_vectors == doctest::Approx(7.0 + 20.0 / 128));
  // eab's data (order 6) are prepared along a trajectory of 5 points: two levels of the
  // recursion at each, more than its binding, which comes after them in a run.
  CHECK(eab.preparation_vectors > eab.scheme_vectors);
  CHECK(eab.vectors == doctest::Approx(1.0 + eab.problem_vectors + eab.preparation_vectors));
  CHECK(se1.vectors ==
        doctest::Approx(1.0 + se1.problem_vectors + std::max(se1.scheme_vectors, se1.preparation_vectors)));
  CHECK(eab.bytes() > se1.bytes());

  // A limit just above the footprint admits the run, one just below refuses it before the
  // reformulation is built, naming the sizes and the scheme's share.
  tsi::AssemblyOptions options;
  options.memory_bytes = 1.01 * eab.bytes();
  CHECK(tsi::assemble_config(nls_config("eab"), h.registry(), options).reformulation != nullptr);
  options.memory_bytes = 0.99 * eab.bytes();
  try {
    (void)tsi::assemble_config(nls_config("eab"), h.registry(), options);
    FAIL("a run over the memory limit was built");
  } catch (const tsi::ConfigError& e) {
    const std::string what = e.what();
    CAPTURE(what);
    CHECK(what.find("reformulation.n_tau") != std::string::npos);
    CHECK(what.find("got 16: with the model's 128 unknowns a run needs") != std::string::npos);
    CHECK(what.find("128 x 16 complex values") != std::string::npos);
    CHECK(what.find("of scheme \"eab\"") != std::string::npos);
    CHECK(what.find("the memory limit has") != std::string::npos);
  }
  // The same limit admits SE1, whose footprint is smaller.
  CHECK(se1.bytes() < options.memory_bytes);
  CHECK(tsi::assemble_config(nls_config("se1"), h.registry(), options).reformulation != nullptr);
}

TEST_CASE("memory: the footprint counts the whole grid that unbuffered tau transforms hold") {
  // The complex layout's tau transforms go through small blocks from 32 tau points and 32
  // unknowns on; below that (or split by FFTW's threads) the batch holds a dim x n_tau buffer.
  auto& h = Harness::instance();
  const auto footprint = [&](long n_tau, int fft_threads) {
    tsi::AssemblyOptions options;
    options.context = tsi::Context::with_threads(1, fft_threads);
    options.context.fft.min_values = 0;
    return tsi::assemble_config(nls_config("se1", 128, n_tau), h.registry(), options).footprint;
  };
  CHECK(tsi::FftBatch::buffers(32, 128));
  CHECK_FALSE(tsi::FftBatch::buffers(16, 128));
  CHECK_FALSE(tsi::FftBatch::buffers(32, 16));
  CHECK_FALSE(tsi::FftBatch::buffers(32, 128, true));
  // The buffer's presence, as the batch itself reports it.
  CHECK(tsi::FftBatch(32, 128).buffered());
  CHECK_FALSE(tsi::FftBatch(16, 128).buffered());
  const tsi::Footprint small = footprint(16, 1), large = footprint(32, 1), split = footprint(32, 2);
  CHECK(small.problem_vectors == doctest::Approx(large.problem_vectors + 1.0));
  // With FFTW's threads the batch is strided wherever they are set up: counted, an upper bound.
  CHECK(split.problem_vectors == doctest::Approx(large.problem_vectors + 1.0));
}
