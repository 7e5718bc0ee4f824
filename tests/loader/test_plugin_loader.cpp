#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>

#include "tsi/error.hpp"
#include "tsi/plugin.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/version.hpp"

namespace fs = std::filesystem;

namespace {

/// The built fixture tsi_fixture_<name>.so, canonical (the loader stamps canonical paths).
std::string fixture(const std::string& name) {
  const fs::path p = fs::path(TSI_TEST_FIXTURE_DIR) / ("tsi_fixture_" + name + ".so");
  REQUIRE_MESSAGE(fs::exists(p), "fixture not built: " << p.string());
  return fs::canonical(p).string();
}

/// Total number of entries of all kinds.
std::size_t size(const tsi::Registry& r) {
  return r.models().size() + r.reformulations().size() + r.schemes().size();
}

/// Loads `path` into a fresh registry, expecting a PluginError containing `words`, and
/// checks that nothing was registered.
void expect_refused(const std::string& path, const std::string& words) {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  CHECK_THROWS_WITH_AS(loader.load(path), doctest::Contains(words.c_str()), tsi::PluginError);
  CHECK(size(r) == 0);
  CHECK(r.provider() == "core");
  REQUIRE(loader.reports().size() == 1);
  CHECK_FALSE(loader.reports()[0].ok);
}

}  // namespace

TEST_CASE("loader: a good plugin registers its names under its own path") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  const std::string path = fixture("good");
  loader.load(path);
  CHECK(r.model("fixture-model").info.provider == path);
  CHECK(&r.model("fm") == &r.model("fixture-model"));
  CHECK(r.scheme("fixture-scheme").info.provider == path);
  CHECK(r.provider() == "core");
  REQUIRE(loader.reports().size() == 1);
  CHECK(loader.reports()[0].ok);
  CHECK(loader.reports()[0].name == "fixture-good");

  SUBCASE("its factories work") {
    tsi::Params params(
        tsi::resolve_params(r.model("fm").info.params, tsi::Json{{"eps", 0.5}}, "model"));
    auto model = r.model("fm").create(params);
    REQUIRE(model);
    CHECK(model->eps() == doctest::Approx(0.5));
    CHECK(model->dim() == 2);
    CHECK(r.scheme("fixture-scheme").create(tsi::Params{}) != nullptr);
  }
}

TEST_CASE("loader: loading the same file twice is a no-op") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  loader.load(fixture("good"));
  CHECK_NOTHROW(loader.load(fixture("good")));
  CHECK(r.models().size() == 1);
  CHECK(r.schemes().size() == 1);
}

TEST_CASE("loader: a plugin for another ABI is refused") {
  expect_refused(fixture("wrong_abi"), "built for plugin ABI 999, this tsi speaks ABI " +
                                           std::to_string(TSI_PLUGIN_ABI_VERSION));
}

TEST_CASE("loader: a plugin whose structures differ in size is refused, naming the structure") {
  const TsiTypeLayout ours = tsi_plugin_layout().model_entry;
  const std::string both = "tsi::ModelEntry is " + std::to_string(ours.size + 8) + " bytes, alignment " +
                           std::to_string(ours.align) + " in the plugin, " + std::to_string(ours.size) +
                           " bytes, alignment " + std::to_string(ours.align) + " in this tsi";
  expect_refused(fixture("wrong_layout"), both);
}

TEST_CASE("loader: the layout handshake covers the exchanged structures") {
  constexpr TsiPluginLayout layout = tsi_plugin_layout();
  CHECK(layout.model_entry.size == sizeof(tsi::ModelEntry));
  CHECK(layout.scheme_entry.size == sizeof(tsi::SchemeEntry));
  CHECK(layout.entry_info.size == sizeof(tsi::EntryInfo));
  CHECK(layout.entry_info.align == alignof(tsi::EntryInfo));
  CHECK(layout.eigen_max_align_bytes == EIGEN_MAX_ALIGN_BYTES);
#if defined(__SANITIZE_ADDRESS__)
  CHECK(layout.address_sanitizer == 1u);
#else
  CHECK(layout.address_sanitizer == 0u);
#endif
  CHECK(layout.scheme.size == sizeof(tsi::Scheme));
  CHECK(TSI_PLUGIN_ABI_VERSION == 25);  // 4: the remainder, bind_tau_grid, invariants; 5: entry completion, needs_exact_flows; 6: traits from parameters; 7: independent_tau_grid_bindings; 8: bound steppers; 9: real tau grids (TauGridField::evaluate_real), fields, Model::physical_dim, memory of a binding (Scheme::state_vectors, Diagonal, in_place); 10: the run context (Params::context, FftBatch threads); 11: exact solutions (Model::exact_solution, Field::affine_terms); 12: the narrow Model (capabilities: hamiltonian, fused_tau_grid, exact_nonlinear_flow, physical_variables); 13: PhysicalVariables::physical_shape; 14: re-preparation as a state observer (Reformulation::repreparation, no Problem::between_steps), the typed selection, VerificationRegime::params; 15: ModelInvariant::conserved (diagnostics); 16: Context::collective (runs split over processes), Model::split_across_processes and canonicalize_physical; 17: tsi::Real (TSI_PRECISION) in the layout, Real times, step sizes and norms; 18: StepperTraits::remainder_data_order, ModelEntry::linear_remainder; 19: TauGridField::independent_row_group, prepare_rows, evaluate_rows_real; 20: Diagonal::threads, TwoScaleDiagnostics::tau_profile; 21: Model::time_dependent_field (TimeDependentField), Model::nonlinear_field no longer pure; 22: Model::second_order_form (SecondOrderForm), Problem::second_order, StepperTraits::needs_second_order_form; 23: Model::charged_particle_form (ChargedParticleForm), Problem::charged_particle, StepperTraits::needs_charged_particle_form; 24: Problem::oscillation_period (micro-macro, nested Picard); 25: Model::processes(), FieldTransforms and Collective::slab_transforms (spectral grids split over processes)
}

TEST_CASE("loader: a plugin for another tsi major version is refused") {
  expect_refused(fixture("wrong_major"),
                 "built for tsi 99.0.0, this is tsi " + std::string(tsi::version_string));
}

TEST_CASE("loader: a library without the entry point is refused") {
  const std::string path = fixture("no_entry");
  expect_refused(path, path + ": not a tsi plugin (no entry point tsi_plugin_entry)");
}

TEST_CASE("loader: a throwing registration is rolled back") {
  const std::string path = fixture("throws");
  expect_refused(path, path + ": registration failed: boom");
}

TEST_CASE("loader: a missing file is refused") {
  expect_refused("/nonexistent/tsi_nothing.so", "/nonexistent/tsi_nothing.so: no such file");
}

TEST_CASE("loader: a duplicate name names both providers and rolls back") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  const std::string good = fixture("good"), dup = fixture("duplicate");
  loader.load(good);
  const std::size_t before = size(r);
  const std::string clash = "model \"fixture-model\" is already registered by " + good +
                            " (while registering from " + dup + ")";
  CHECK_THROWS_WITH_AS(loader.load(dup), doctest::Contains(clash.c_str()), tsi::PluginError);
  CHECK(size(r) == before);
  CHECK_THROWS_AS(r.scheme("fixture-duplicate-scheme"), tsi::ConfigError);
  CHECK(r.model("fixture-model").info.provider == good);
  CHECK(r.provider() == "core");
}

TEST_CASE("loader: a directory scan collects failures without throwing") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  std::vector<tsi::PluginLoadReport> reports;
  CHECK_NOTHROW(reports = loader.load_directory(TSI_TEST_FIXTURE_DIR));
  // Sorted: duplicate loads before good into the empty registry, so good clashes with it;
  // shipped_duplicate's "henon-heiles" is free here (no shipped plugins in this registry).
  const std::vector<std::pair<const char*, bool>> expected = {
      {"broken_flow", true}, {"broken_fused", true},      {"duplicate", true},        {"general", true},
      {"good", false},
      {"no_entry", false},   {"shipped_duplicate", true}, {"stiff", true},           {"throws", false},
      {"wrong_abi", false},  {"wrong_layout", false},     {"wrong_major", false},     {"wrong_precision", false},
      {"wrong_sanitizer", false}};
  REQUIRE(reports.size() == expected.size());
  for (std::size_t i = 0; i < reports.size(); ++i) {
    CAPTURE(reports[i].path);
    CHECK(reports[i].path == fixture(expected[i].first));
    CHECK(reports[i].ok == expected[i].second);
    CHECK(reports[i].error.empty() == expected[i].second);
  }
  CHECK(reports[4].error.find("already registered") != std::string::npos);
  CHECK(reports[10].error.find("tsi::ModelEntry") != std::string::npos);
  CHECK(r.scheme("fixture-duplicate-scheme").info.provider == fixture("duplicate"));
  CHECK(loader.reports().size() == reports.size());
}

TEST_CASE("loader: a missing directory yields no reports") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  CHECK(loader.load_directory("/nonexistent/plugins").empty());
}

TEST_CASE("loader: a path list loads files and collects failures") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  const auto reports =
      loader.load_path_list(fixture("good") + "::/nonexistent/tsi_x.so:" + fixture("throws"));
  REQUIRE(reports.size() == 3);
  CHECK(reports[0].ok);
  CHECK_FALSE(reports[1].ok);
  CHECK_FALSE(reports[2].ok);
  CHECK(r.model("fm").info.provider == fixture("good"));
}

TEST_CASE("loader: the default directory is known") {
  CHECK_FALSE(tsi::PluginLoader::default_directory().empty());
}

TEST_CASE("loader: a plugin built for another precision (TSI_PRECISION) is refused") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  CHECK_THROWS_WITH_AS(loader.load(fixture("wrong_precision")), doctest::Contains("built for another TSI_PRECISION"),
                       tsi::PluginError);
  CHECK(r.models().empty());
}

TEST_CASE("loader: a plugin built the other way round with respect to AddressSanitizer is refused") {
  tsi::Registry r;
  tsi::PluginLoader loader(r);
  CHECK_THROWS_WITH_AS(loader.load(fixture("wrong_sanitizer")), doctest::Contains("AddressSanitizer"),
                       tsi::PluginError);
  CHECK(r.models().empty());
}
