// The plugin SDK end to end: `cmake --install` into a temporary prefix, then
// examples/plugins/fput configured and built from its own build directory against that
// prefix alone (find_package(tsi)), loaded by the installed runner with --plugin and with
// TSI_PLUGIN_PATH, uniformly second order with SE1, and passing `tsi check`; the same for the
// scheme example examples/plugins/expmid; and the public headers on their own.
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

/// Relative error at T = 1 of one SE1 run of the fput model with the installed runner.
double se1_error(const std::string& tsi, const t::TempDir& dir, double eps, long steps,
                 const std::vector<std::string>& plugin_args, const t::CommandEnv& env) {
  const Json config = {{"model", {{"name", "fput"}, {"eps", eps}}},
                       {"scheme", {{"name", "se1"}, {"tol", 1e-12}}},
                       {"time", {{"h", 1.0 / static_cast<double>(steps)}, {"t_end", 1.0}}},
                       {"reference", {{"tol", 1e-12}}}};
  const std::string name = "fput-" + std::to_string(eps) + "-" + std::to_string(steps);
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
  CHECK(mentions(result.at("config").at("model").at("name").get<std::string>(), "fput"));
  return result.at("error").at("relative").get<double>();
}

}  // namespace

TEST_CASE("sdk: an out-of-tree model plugin builds against an installed tsi and runs") {
  t::TempDir tmp("tsi-sdk-test");
  const fs::path prefix = tmp.path() / "prefix", build = tmp.path() / "fput-build";

  // 1. Install: the runner, the core, the shipped plugins, the headers, the CMake package.
  {
    const t::CommandResult r =
        run(TSI_TEST_CMAKE, {"--install", TSI_TEST_BINARY_DIR, "--prefix", prefix.string()});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
  }
  for (const char* file :
       {"bin/tsi", "lib/libtsi_core.so", "lib/tsi/plugins/tsi_henon_heiles.so", "lib/tsi/plugins/tsi_se1.so",
        "lib/tsi/plugins/tsi_rk78.so", "include/tsi/model.hpp", "include/tsi/plugin.hpp",
        "lib/cmake/tsi/tsiConfig.cmake", "lib/cmake/tsi/tsiConfigVersion.cmake",
        "lib/cmake/tsi/tsiTargets.cmake", "lib/cmake/tsi/TsiPlugin.cmake", "include/tsi/assembly.hpp",
        "include/tsi/algebra.hpp", "include/tsi/model_checks.hpp", "share/doc/tsi/SPEC.md", "share/doc/tsi/writing-a-model.md"}) {
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

  // 3. The example builds from its own directory against the prefix alone.
  {
    const t::CommandResult r =
        configure(fs::path(TSI_TEST_SOURCE_DIR) / "examples/plugins/fput", build, prefix);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const t::CommandResult b = run(TSI_TEST_CMAKE, {"--build", build.string()});
    INFO(b.describe());
    REQUIRE(b.exit_code == 0);
  }
  const fs::path plugin = build / "tsi_fput.so";
  REQUIRE(fs::exists(plugin));
  const std::string plugin_path = fs::canonical(plugin).string();

  // 4. `tsi list` shows the external model and the file that provided it.
  {
    const t::CommandResult r = run(tsi, {"--plugin", plugin.string(), "list", "models"});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    CHECK(mentions(r.out, "fput (fpu, fermi-pasta-ulam)"));
    CHECK(mentions(r.out, "provided by " + plugin_path));
    CHECK(mentions(r.out, "default n_tau 64"));
  }

  // 5. Observed order 2 with SE1 at two values of eps: h = 1/4 .. 1/32 at T = 1, against the
  //    rk78 reference on the filtered problem; loaded with --plugin, then with TSI_PLUGIN_PATH.
  const std::vector<long> steps = {4, 8, 16, 32};
  std::vector<double> hs;
  for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
  t::CommandEnv by_path;
  by_path.set["TSI_PLUGIN_PATH"] = build.string();
  const struct {
    double eps;
    std::vector<std::string> plugin_args;
    t::CommandEnv env;
  } series[] = {{1e-2, {"--plugin", plugin.string()}, {}}, {1e-4, {}, by_path}};
  for (const auto& s : series) {
    std::vector<double> errors;
    for (long n : steps) errors.push_back(se1_error(tsi, tmp, s.eps, n, s.plugin_args, s.env));
    const double order = tsi::least_squares_order(hs, errors);
    CAPTURE(s.eps);
    CAPTURE(errors[0]);
    CAPTURE(errors[3]);
    CHECK(std::abs(order - 2.0) <= 0.2);
    CHECK(errors[3] < 1e-3);
  }

  // 6. The plugin passes the conformance checks, run by the example's own ctest (tsi::tsi).
  {
    const t::CommandResult r = run(TSI_TEST_CTEST, {"--test-dir", build.string(), "-V"});
    INFO(r.describe());
    CHECK(r.exit_code == 0);
    CHECK(mentions(r.out, "fput: all"));
    CHECK(mentions(r.out, "checks passed"));
  }

  // 7. A scheme plugin (docs/writing-a-scheme.md) builds the same way and passes its checks
  //    on the shipped Henon-Heiles model, then runs from a config.
  {
    const fs::path scheme_build = tmp.path() / "expmid-build";
    const t::CommandResult r =
        configure(fs::path(TSI_TEST_SOURCE_DIR) / "examples/plugins/expmid", scheme_build, prefix);
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const t::CommandResult b = run(TSI_TEST_CMAKE, {"--build", scheme_build.string()});
    INFO(b.describe());
    REQUIRE(b.exit_code == 0);
    const t::CommandResult c = run(TSI_TEST_CTEST, {"--test-dir", scheme_build.string(), "-V"});
    INFO(c.describe());
    CHECK(c.exit_code == 0);
    CHECK(mentions(c.out, "exp-midpoint"));
    CHECK(mentions(c.out, "henon-heiles: all"));
    const Json config = {{"model", {{"name", "henon-heiles"}, {"eps", 1e-4}}},
                         {"scheme", {{"name", "emp"}}},
                         {"time", {{"h", 0.125}, {"t_end", 1.0}}}};
    const t::CommandResult e = run(tsi, {"--plugin", (scheme_build / "tsi_expmid.so").string(), "run",
                                         t::write_config(tmp, config, "emp.json"), "--out", tmp / "emp"});
    INFO(e.describe());
    CHECK(e.exit_code == 0);
    CHECK(t::read_json(tmp.path() / "emp" / "result.json").at("config").at("scheme").at("name") ==
          "exp-midpoint");
  }

  // 8. The public headers are the whole interface: all of them in one translation unit built
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
