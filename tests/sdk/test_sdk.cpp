// The plugin SDK end to end: `cmake --install` into a temporary prefix, then every example
// plugin the prefix ships (share/tsi/examples/plugins: the Hamiltonian model fput-example, the scheme
// expmid, the general-class model van_der_pol) configured and built from there, in a build
// directory of its own, against that prefix alone (find_package(tsi)), loaded by the installed
// runner, passing `tsi check`, and run with a measured order; and the public headers on their
// own. An API change that breaks a plugin breaks this test first.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "runner/run_command.hpp"
#include "tsi/convergence.hpp"

namespace {

namespace fs = std::filesystem;
namespace t = tsi::test;
using tsi::test::Json;

bool mentions(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// A child process with no LD_LIBRARY_PATH: the installed files must find each other.
t::CommandResult run(const std::string& program, const std::vector<std::string>& args,
                     t::CommandEnv env = {}) {
  env.unset.push_back("LD_LIBRARY_PATH");
  return t::run_command(program, args, env);
}

/// cmake -S source -B build against the prefix, with the compiler and generator of this build.
t::CommandResult configure(const fs::path& source, const fs::path& build, const fs::path& prefix,
                           const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args = {"-S",
                                   source.string(),
                                   "-B",
                                   build.string(),
                                   "-G",
                                   TSI_TEST_GENERATOR,
                                   "-DCMAKE_BUILD_TYPE=Release",
                                   "-DCMAKE_PREFIX_PATH=" + prefix.string(),
                                   "-DCMAKE_CXX_COMPILER=" TSI_TEST_CXX_COMPILER,
                                   "-DCMAKE_CXX_FLAGS=" TSI_TEST_CXX_FLAGS,
                                   "-DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF"};
  if (!std::string(TSI_TEST_MAKE_PROGRAM).empty())
    args.push_back("-DCMAKE_MAKE_PROGRAM=" TSI_TEST_MAKE_PROGRAM);
  args.insert(args.end(), extra.begin(), extra.end());
  return run(TSI_TEST_CMAKE, args);
}

/// Relative error at T = 1 of one run of `model` with `scheme` and `steps` steps, with the
/// installed runner, against its reference (tol 1e-12).
double run_error(const std::string& tsi, const t::TempDir& dir, const std::string& model, double eps,
                 const std::string& scheme, long steps, const std::vector<std::string>& plugin_args,
                 const t::CommandEnv& env = {}) {
  const Json config = {{"model", {{"name", model}, {"eps", eps}}},
                       {"scheme", {{"name", scheme}}},
                       {"time", {{"h", 1.0 / static_cast<double>(steps)}, {"t_end", 1.0}}},
                       {"reference", {{"tol", 1e-12}}}};
  const std::string name = model + "-" + scheme + "-" + std::to_string(eps) + "-" + std::to_string(steps);
  const std::string file = t::write_config(dir, config, name + ".json");
  std::vector<std::string> args = plugin_args;
  for (const char* a : {"run", file.c_str()}) args.emplace_back(a);
  args.push_back("--out");
  args.push_back(dir / name);
  const t::CommandResult r = run(tsi, args, env);
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json result = t::read_json(dir.path() / name / "result.json");
  REQUIRE(result.at("status") == "completed");
  CHECK(result.at("config").at("model").at("name") == model);
  CHECK(result.at("config").at("scheme").at("name") == scheme);
  return result.at("error").at("relative").get<double>();
}

/// The errors of run_error at h = 1/4 .. 1/32 (T = 1) and their least-squares order.
struct Series {
  std::vector<double> errors;
  double order = 0.0;
};
Series error_series(const std::string& tsi, const t::TempDir& dir, const std::string& model, double eps,
                    const std::string& scheme, const std::vector<std::string>& plugin_args,
                    const t::CommandEnv& env = {}) {
  Series s;
  std::vector<double> hs;
  for (long n : {4L, 8L, 16L, 32L}) {
    hs.push_back(1.0 / static_cast<double>(n));
    s.errors.push_back(run_error(tsi, dir, model, eps, scheme, n, plugin_args, env));
  }
  s.order = tsi::least_squares_order(hs, s.errors);
  return s;
}

/// Configures and builds the example project `source` (an installed example's directory) in
/// `build` against `prefix`, and returns the plugin it made, build/tsi_<name>.so.
fs::path build_example(const fs::path& source, const fs::path& build, const fs::path& prefix,
                       const std::string& name) {
  const t::CommandResult r = configure(source, build, prefix);
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const t::CommandResult b = run(TSI_TEST_CMAKE, {"--build", build.string()});
  INFO(b.describe());
  REQUIRE(b.exit_code == 0);
  const fs::path plugin = build / ("tsi_" + name + ".so");
  REQUIRE(fs::exists(plugin));
  return plugin;
}

/// The example's own ctest: `tsi check` of the installed runner on the plugin.
void check_example(const fs::path& build, const std::string& passed) {
  const t::CommandResult r = run(TSI_TEST_CTEST, {"--test-dir", build.string(), "-V"});
  INFO(r.describe());
  CHECK(r.exit_code == 0);
  CHECK(mentions(r.out, passed));
  CHECK(mentions(r.out, "checks passed"));
}

}  // namespace

TEST_CASE("sdk: the installed example plugins build against an installed tsi and run") {
  t::TempDir tmp("tsi-sdk-test");
  const fs::path prefix = tmp.path() / "prefix", build = tmp.path() / "fput-build";
  const fs::path examples = prefix / "share/tsi/examples/plugins";

  // 1. Install: the runner, the core, the shipped plugins, the headers, the CMake package.
  {
    const t::CommandResult r =
        run(TSI_TEST_CMAKE, {"--install", TSI_TEST_BINARY_DIR, "--prefix", prefix.string()});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
  }
  for (const char* file :
       {"bin/tsi", "lib/libtsi_core.so", "lib/tsi/plugins/tsi_henon_heiles.so", "lib/tsi/plugins/tsi_fput.so",
        "lib/tsi/plugins/tsi_se1.so",
        "lib/tsi/plugins/tsi_rk78.so", "include/tsi/model.hpp", "include/tsi/plugin.hpp",
        "lib/cmake/tsi/tsiConfig.cmake", "lib/cmake/tsi/tsiConfigVersion.cmake",
        "lib/cmake/tsi/tsiTargets.cmake", "lib/cmake/tsi/TsiPlugin.cmake", "include/tsi/assembly.hpp",
        "include/tsi/algebra.hpp", "include/tsi/model_checks.hpp", "share/doc/tsi/SPEC.md", "share/doc/tsi/model-interface.md",
        "share/tsi/examples/plugins/fput/CMakeLists.txt", "share/tsi/examples/plugins/fput/fput.cpp",
        "share/tsi/examples/plugins/expmid/CMakeLists.txt", "share/tsi/examples/plugins/expmid/expmid.cpp",
        "share/tsi/examples/plugins/van_der_pol/CMakeLists.txt", "share/tsi/examples/plugins/van_der_pol/van_der_pol.cpp",
        "share/tsi/examples/plugins/van_der_pol/van-der-pol-se1.json"}) {
    CHECK_MESSAGE(fs::exists(prefix / file), "not installed: " << file);
  }
  CHECK_FALSE(fs::exists(prefix / "lib/tsi/plugins/tsi_fixture_good.so"));  // test fixtures stay out
  const std::string tsi = (prefix / "bin" / "tsi").string();

  // 2. The installed runner finds its own plugins, relative to itself.
  {
    const t::CommandResult r = run(tsi, {"list", "models", "--json"});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const Json models = Json::parse(r.out).at("models");
    bool found = false;
    for (const auto& m : models)
      if (m.at("name") == "henon-heiles") {
        found = true;
        CHECK(m.at("provider").get<std::string>() ==
              fs::canonical(prefix / "lib/tsi/plugins/tsi_henon_heiles.so").string());
      }
    CHECK(found);
  }

  // 3. The Hamiltonian example builds from the prefix's copy against the prefix alone.
  const fs::path plugin = build_example(examples / "fput", build, prefix, "fput");
  const std::string plugin_path = fs::canonical(plugin).string();

  // 4. `tsi list` shows the external model, the file that provided it, and marks it as the
  //    --plugin file's (the shipped models stay unmarked). The example registers as
  //    fput-example beside the shipped fput, the same model: both load in one process.
  {
    const t::CommandResult r = run(tsi, {"--plugin", plugin.string(), "list", "models"});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    CHECK(mentions(r.out, "  fput-example  Fermi-Pasta-Ulam-Tsingou chain"));
    CHECK(mentions(r.out, "  fput (fpu, fermi-pasta-ulam)  Fermi-Pasta-Ulam-Tsingou chain"));
    CHECK(mentions(r.out, "dim 4m  [from tsi_fput.so]\n"));
    CHECK(mentions(r.out, "provided by " + plugin_path));
    CHECK(mentions(r.out, "default n_tau 64"));
    CHECK(r.out.find("[from") == r.out.rfind("[from"));  // one marked entry
  }

  // 5. Observed order 2 with SE1 at two values of eps: h = 1/4 .. 1/32 at T = 1, against the
  //    rk78 reference on the filtered problem; loaded with --plugin, then with TSI_PLUGIN_PATH.
  t::CommandEnv by_path;
  by_path.set["TSI_PLUGIN_PATH"] = build.string();
  const struct {
    double eps;
    std::vector<std::string> plugin_args;
    t::CommandEnv env;
  } series[] = {{1e-2, {"--plugin", plugin.string()}, {}}, {1e-4, {}, by_path}};
  for (const auto& s : series) {
    const Series fput = error_series(tsi, tmp, "fput-example", s.eps, "se1", s.plugin_args, s.env);
    CAPTURE(s.eps);
    CAPTURE(fput.errors[0]);
    CAPTURE(fput.errors[3]);
    CHECK(std::abs(fput.order - 2.0) <= 0.2);  // measured 1.93 (eps = 1e-2), 1.97 (1e-4)
    CHECK(fput.errors[3] < 1e-3);              // measured 4.9e-4, 5.6e-4
    // The shipped fput, loaded in the same process, computes the same numbers.
    const Series shipped = error_series(tsi, tmp, "fput", s.eps, "se1", s.plugin_args, s.env);
    for (size_t i = 0; i < shipped.errors.size(); ++i)
      CHECK(std::abs(shipped.errors[i] - fput.errors[i]) <= 1e-10 * fput.errors[i]);
  }

  // 6. The plugin passes the conformance checks, run by the example's own ctest (tsi::tsi).
  check_example(build, "fput-example: all");

  // 7. The scheme example (docs/tutorials/scheme-plugin.md) builds the same way, passes its checks on
  //    the shipped Henon-Heiles model, and is second order there at eps = 1e-4 (away from the
  //    step-size resonances h = k pi eps, where it loses an order).
  {
    const fs::path scheme_build = tmp.path() / "expmid-build";
    const fs::path scheme = build_example(examples / "expmid", scheme_build, prefix, "expmid");
    check_example(scheme_build, "henon-heiles: all");
    const Series emp = error_series(tsi, tmp, "henon-heiles", 1e-4, "exp-midpoint", {"--plugin", scheme.string()});
    CAPTURE(emp.errors[0]);
    CAPTURE(emp.errors[3]);
    CHECK(std::abs(emp.order - 2.0) <= 0.2);  // measured 2.00
    CHECK(emp.errors[3] < 2e-4);              // measured 7.7e-5
  }

  // 8. The general-class example (no Hamiltonian structure) builds the same way, passes its
  //    checks, runs its own installed config without energies, and is uniformly second order
  //    with SE1: the same errors at eps = 1e-4 and 1e-5.
  {
    const fs::path general_build = tmp.path() / "van-der-pol-build";
    const fs::path general = build_example(examples / "van_der_pol", general_build, prefix, "van_der_pol");
    check_example(general_build, "van-der-pol: all");
    const std::vector<std::string> plugin_args = {"--plugin", general.string()};

    std::vector<std::string> args = plugin_args;
    args.insert(args.end(), {"run", (examples / "van_der_pol/van-der-pol-se1.json").string(), "--out",
                             (tmp.path() / "vdp-example").string()});
    const t::CommandResult e = run(tsi, args);
    INFO(e.describe());
    REQUIRE(e.exit_code == 0);
    const Json result = t::read_json(tmp.path() / "vdp-example" / "result.json");
    CHECK(result.at("status") == "completed");
    CHECK(result.at("error").at("relative").get<double>() < 2e-4);  // measured 8.1e-5 (eps 1e-4, h 1/16)
    CHECK_FALSE(result.value("invariants", Json::object()).contains("H"));  // no energy without the structure

    const Series at_4 = error_series(tsi, tmp, "van-der-pol", 1e-4, "se1", plugin_args);
    const Series at_5 = error_series(tsi, tmp, "van-der-pol", 1e-5, "se1", plugin_args);
    CAPTURE(at_4.errors[3]);
    CAPTURE(at_5.errors[3]);
    CHECK(std::abs(at_4.order - 2.0) <= 0.2);  // measured 2.01
    CHECK(std::abs(at_5.order - 2.0) <= 0.2);  // measured 2.01
    CHECK(at_4.errors[3] < 1e-4);              // measured 2.0e-5
    CHECK(std::abs(at_4.errors[3] / at_5.errors[3] - 1.0) < 0.05);  // measured 0.6 %
  }

  // 9. The public headers are the whole interface: all of them in one translation unit built
  //    against the prefix, linked against tsi::core; and the package's version check.
  {
    const fs::path consumer = fs::path(TSI_TEST_SOURCE_DIR) / "tests/sdk/consumer";
    const t::CommandResult r =
        configure(consumer, tmp.path() / "consumer", prefix, {"-DTSI_WANT_VERSION=0.1"});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const t::CommandResult b = run(TSI_TEST_CMAKE, {"--build", (tmp.path() / "consumer").string()});
    INFO(b.describe());
    REQUIRE(b.exit_code == 0);
    const t::CommandResult e = run((tmp.path() / "consumer" / "all_headers").string(), {});
    INFO(e.describe());
    CHECK(e.exit_code == 0);
    CHECK(mentions(e.out, "reformulations 3, order 2.0"));
    // a program outside the prefix finds the shipped plugins next to the installed library
    CHECK(mentions(e.out, "plugin directory " + fs::canonical(prefix / "lib/tsi/plugins").string() + "\n"));

    const t::CommandResult v =
        configure(consumer, tmp.path() / "consumer-v1", prefix, {"-DTSI_WANT_VERSION=1.0"});
    INFO(v.describe());
    CHECK(v.exit_code != 0);
    CHECK(mentions(v.out + v.err, "requested version \"1.0\""));
  }
}
