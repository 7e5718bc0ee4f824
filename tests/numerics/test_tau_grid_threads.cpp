// One two-scale run on several threads (tsi::Context::tau_grid): the tau grid's rows are
// transformed and its columns evaluated by different threads. The split must not change the
// answer, must stay off where the model shares state or the grid is small, and a model error
// on one thread must reach the caller.
#include <doctest/doctest.h>

#include <stdexcept>

#include "harness.hpp"
#include "runner/run_command.hpp"
#include "tsi/error.hpp"
#include "tsi/context.hpp"

namespace {

namespace fs = std::filesystem;
using tsi::Index;
using tsi::Vector;
using tsi::test::Harness;

// The harness's reformulations get `threads` on grids of at least min_values, for a scope.
struct ThreadSetting : tsi::test::ContextSetting {
  ThreadSetting(int threads, long min_values) : ContextSetting(tau_grid(threads, min_values)) {}
};

// u' = J[(1/eps) M u + grad H1] with a linear grad H1 (so any answer is easy to predict), whose
// bindings throw on the columns that do not hold tau = 0: on a split grid, a thread other than
// the first fails.
class ThrowingModel final : public tsi::Model, public tsi::HamiltonianStructure, public tsi::FusedTauGrid {
 public:
  explicit ThrowingModel(bool independent) : Model(0.1), independent_(independent) {}
  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  Index dim() const override { return 64; }
  bool is_complex() const override { return true; }
  void linear_flow(const tsi::RealVector&, tsi::MatrixRef) const override {}
  void nonlinear_field(tsi::ConstMatrixRef u, tsi::MatrixRef out) const override { out = u; }
  void apply_M(const Vector& u, Vector& out) const override { out = 0.0 * u; }
  void apply_J(const Vector& u, Vector& out) const override { out = u; }
  double H1(const Vector&) const override { return 0.0; }
  Vector initial_value() const override { return Vector::Ones(64); }
  bool independent_tau_grid_bindings() const override { return independent_; }

  class Field final : public tsi::TauGridField {
   public:
    explicit Field(bool holds_zero) : holds_zero_(holds_zero) {}
    void evaluate(tsi::MatrixRef u, tsi::MatrixRef out) override {
      if (!holds_zero_) throw std::runtime_error("field failed on a later tau range");
      out = u;
    }

   private:
    bool holds_zero_;
  };
  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    ++bindings_;
    // The whole grid (the serial path, preparation) and the first range evaluate; others throw.
    return std::make_unique<Field>(taus(0) == 0.0);
  }
  mutable int bindings_ = 0;

 private:
  bool independent_;
};

Vector evaluate_nonlinear(tsi::Reformulation& r, const Vector& y) {
  Vector out(y.size());
  r.nonlinear(0.0, y, out);
  return out;
}

}  // namespace

TEST_CASE("tau grid threads: NLS and Klein-Gordon on two threads give the one-thread field and run") {
  auto& h = Harness::instance();
  for (const char* name : {"nls", "klein-gordon"}) {
    CAPTURE(name);
    const auto field_and_run = [&](int threads) {
      ThreadSetting setting(threads, 1);
      auto model = h.model_with(name, 0.01, {{"n_x", 32}});
      auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 64}});
      CHECK(two_scale->two_scale_diagnostics()->threads() == (tsi::tau_grid_threads_available() ? threads : 1));
      const Vector y = two_scale->prepare(model->initial_value());
      auto se1 = h.scheme("se1");
      return std::make_pair(evaluate_nonlinear(*two_scale, y), tsi::test::solve(*model, *two_scale, *se1, 0.5, 4));
    };
    const auto [field1, run1] = field_and_run(1);
    const auto [field2, run2] = field_and_run(2);
    // The same transforms and the same field per column: equal to rounding (measured: equal).
    CHECK((field1 - field2).norm() <= 1e-14 * field1.norm());
    CHECK((run1 - run2).norm() <= 1e-14 * run1.norm());
  }
}

TEST_CASE("tau grid threads: only large grids of models with independent bindings are split") {
  auto& h = Harness::instance();
  {
    ThreadSetting setting(2, 4096);  // the default threshold
    // 16 x 128 = 2048 values: below the threshold. 16 x 256 = 4096: split.
    auto small = h.reformulation("two-scale", h.model_with("nls", 0.01, {{"n_x", 16}}), {{"n_tau", 128}});
    CHECK(small->two_scale_diagnostics()->threads() == 1);
    auto large = h.reformulation("two-scale", h.model_with("nls", 0.01, {{"n_x", 16}}), {{"n_tau", 256}});
    CHECK(large->two_scale_diagnostics()->threads() == (tsi::tau_grid_threads_available() ? 2 : 1));
  }
  {
    ThreadSetting setting(2, 1);
    // Henon-Heiles has 4 rows: never more threads than rows.
    auto hh = h.reformulation("two-scale", h.model("henon-heiles", 0.01), {{"n_tau", 64}});
    CHECK(hh->two_scale_diagnostics()->threads() == (tsi::tau_grid_threads_available() ? 2 : 1));
    ThreadSetting many(8, 1);
    auto hh8 = h.reformulation("two-scale", h.model("henon-heiles", 0.01), {{"n_tau", 64}});
    CHECK(hh8->two_scale_diagnostics()->threads() == (tsi::tau_grid_threads_available() ? 4 : 1));
    // A model that does not declare independent bindings (the default) stays on one thread.
    auto shared = std::make_shared<ThrowingModel>(false);
    auto r = h.reformulation("two-scale", shared, {{"n_tau", 64}});
    CHECK(r->two_scale_diagnostics()->threads() == 1);
    CHECK(shared->bindings_ == 1);
  }
  CHECK_THROWS_AS(tsi::Context::with_threads(0, 1), tsi::ConfigError);
}

TEST_CASE("tau grid threads: a model error on another thread reaches the caller") {
  if (!tsi::tau_grid_threads_available()) return;  // nothing runs on another thread
  auto& h = Harness::instance();
  ThreadSetting setting(2, 1);
  auto model = std::make_shared<ThrowingModel>(true);
  auto r = h.reformulation("two-scale", model, {{"n_tau", 64}});
  REQUIRE(r->two_scale_diagnostics()->threads() == 2);
  const Vector y = Vector::Ones(r->size());
  CHECK_THROWS_WITH(evaluate_nonlinear(*r, y), "field failed on a later tau range");
  // The team is usable again after the failure (no thread left waiting at a barrier).
  CHECK_THROWS_WITH(evaluate_nonlinear(*r, y), "field failed on a later tau range");
}

TEST_CASE("tau grid threads: tsi --threads records its threads and gives the one-thread result") {
  const tsi::test::TempDir dir("tsi-tau-threads");
  tsi::Json config = tsi::test::read_json(tsi::test::example_config("nls-se1.json"));
  config["model"]["n_x"] = 64;  // 64 x 256: split
  config.erase("reference");
  const auto path = tsi::test::write_config(dir, config, "nls64.json");
  const auto one = tsi::test::run_tsi({"--threads", "1", "run", path, "--out", dir / "one"});
  const auto two = tsi::test::run_tsi({"--threads", "2", "run", path, "--out", dir / "two"});
  REQUIRE_MESSAGE(one.exit_code == 0, one.describe());
  REQUIRE_MESSAGE(two.exit_code == 0, two.describe());
  const tsi::Json a = tsi::test::read_json(fs::path(dir / "one") / "result.json");
  const tsi::Json b = tsi::test::read_json(fs::path(dir / "two") / "result.json");
  CHECK(a["threads"] == 1);
  CHECK(b["threads"] == (tsi::tau_grid_threads_available() ? 2 : 1));
  CHECK(a["u_final"] == b["u_final"]);
  const auto bad = tsi::test::run_tsi({"--threads", "0", "run", path, "--out", dir / "bad"});
  CHECK(bad.exit_code == 2);
  CHECK(tsi::test::contains(bad.err, "--threads"));
}

TEST_CASE("tau grid threads: both tau monitors from one pass, by their definitions, alike on two threads") {
  // Henon-Heiles (real: the real layout, modes 0 .. n/2) and NLS on 2^15 points (complex: all n modes), a
  // prepared state made rough by hand: tau_roughness is the energy of the modes |k| > 3n/8 over
  // all of it, tau_spread that of the modes k != 0, the modes -k of the real layout counted
  // as their conjugates k.
  auto& h = Harness::instance();
  for (const char* model : {"henon-heiles", "nls"}) {
    CAPTURE(model);
    const auto monitors = [&](int threads) {
      ThreadSetting setting(threads, 1);
      tsi::Json m = {{"name", model}, {"eps", 0.1}};
      if (std::string(model) == "nls") m["n_x"] = 1 << 15;  // 2^15 rows: two of the sums' blocks
      tsi::Assembly a = h.assemble({{"model", m},
                                    {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}}},
                                    {"scheme", {{"name", "se1"}}}});
      Vector y = a.reformulation->prepare(a.u0);
      for (Index i = 0; i < y.size(); ++i) y(i) += tsi::Complex(1e-3 * std::sin(0.3 * static_cast<double>(i)), 0.0);
      const auto* d = a.reformulation->two_scale_diagnostics();
      REQUIRE(d != nullptr);
      const tsi::TauProfile p = d->tau_profile(y);
      CHECK(p.roughness == d->tau_roughness(y));
      CHECK(p.spread == d->tau_spread(y));
      const Index dim = a.model->dim(), columns = y.size() / dim;
      double total = 0.0, top = 0.0, away = 0.0;
      for (Index j = 0; j < columns; ++j) {
        const int k = columns == 16 ? static_cast<int>(j < 8 ? j : j - 16) : static_cast<int>(j);  // FFT order
        const double weight = columns == 9 && j > 0 && j < 8 ? 2.0 : 1.0;
        const double e = weight * y.segment(j * dim, dim).squaredNorm();
        total += e;
        if (8 * std::abs(k) > 3 * 16) top += e;
        if (j > 0) away += e;
      }
      CHECK(p.roughness == doctest::Approx(top / total).epsilon(1e-13));
      CHECK(p.spread == doctest::Approx(away / total).epsilon(1e-13));
      CHECK(p.roughness > 1e-8);  // made rough: a value worth comparing
      return p;
    };
    const tsi::TauProfile one = monitors(1), two = monitors(2);
    CHECK(one.roughness == two.roughness);
    CHECK(one.spread == two.spread);
  }
}
