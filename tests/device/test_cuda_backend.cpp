// The CUDA backend (tsi/device.hpp) against the host: the algebra entry by entry, and the
// two-scale NLS steps of SE1 and eab in 1, 2 and 3 dimensions, to rounding. Built with
// TSI_WITH_CUDA only, run on a machine with a GPU (scripts/device-check.sh); CI has none.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "tsi/algebra.hpp"
#include "tsi/assembly.hpp"
#include "tsi/device.hpp"
#include "tsi/driver.hpp"
#include "tsi/npy.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"

namespace {

using namespace tsi;

// The shipped plugins: TSI_TEST_PLUGIN_DIR, or the environment's where the build tree moved
// (the device machine runs a copy of it elsewhere).
Registry& registry() {
  static Registry r;
  static PluginLoader loader(r);
  static const bool loaded = [] {
    register_core(r);
    const char* dir = std::getenv("TSI_TEST_PLUGIN_DIR");
    loader.load_directory(dir ? dir : TSI_TEST_PLUGIN_DIR);
    return true;
  }();
  (void)loaded;
  return r;
}

Vector random_vector(Index n, unsigned seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> d;
  Vector v(n);
  for (Index i = 0; i < n; ++i) v(i) = Complex(d(g), d(g));
  return v;
}

double relative_difference(const Vector& a, const Vector& b) { return (a - b).norm() / b.norm(); }

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("device algebra: each function equals the host's to rounding, on runs of one and of many entries") {
  REQUIRE(device::available());
  const Index dim = 3000, columns = 8, n = dim * columns;  // dim not a multiple of the block
  const Vector x = random_vector(n, 1), y = random_vector(n, 2), z = random_vector(n, 3), s = random_vector(n, 4);
  const Diagonal per_mode(random_vector(columns, 5), dim), per_entry(random_vector(n, 6)),
      other_run(random_vector(n / 4, 7), 4);
  const Vector dv = random_vector(n, 8);
  struct Case {
    const char* name;
    std::function<void(Vector&)> op;
  };
  const std::vector<Case> cases = {
      {"copy", [&](Vector& o) { algebra::copy(x, o); }},
      {"axpby", [&](Vector& o) { algebra::axpby(0.3, x, -1.7, y, o); }},
      {"axpy", [&](Vector& o) { algebra::copy(y, o), algebra::axpy(2.5, x, o); }},
      {"diagonal_multiply run n", [&](Vector& o) { algebra::diagonal_multiply(per_mode, x, o); }},
      {"diagonal_multiply run 1", [&](Vector& o) { algebra::diagonal_multiply(per_entry, x, o); }},
      {"diagonal_multiply vector", [&](Vector& o) { algebra::diagonal_multiply(dv, x, o); }},
      {"diagonal_multiply_add", [&](Vector& o) { algebra::diagonal_multiply_add(s, per_mode, x, o); }},
      {"diagonal_multiply_add vector", [&](Vector& o) { algebra::diagonal_multiply_add(s, dv, x, o); }},
      {"diagonal_combination 2", [&](Vector& o) { algebra::diagonal_combination(per_mode, x, per_mode, y, o); }},
      {"diagonal_combination 3 runs differ",
       [&](Vector& o) { algebra::diagonal_combination(per_mode, x, other_run, y, per_entry, z, o); }},
      {"diagonal_combination vectors", [&](Vector& o) { algebra::diagonal_combination(dv, x, dv, y, dv, z, o); }},
      {"diagonal_linear_combination", [&](Vector& o) {
         const Diagonal* d[] = {&per_mode, &per_mode, &per_mode};
         const Vector* v[] = {&x, &y, &z};
         algebra::diagonal_linear_combination(&s, d, v, o);
       }},
      {"in place", [&](Vector& o) { algebra::copy(x, o), algebra::diagonal_combination(per_mode, o, per_mode, y, o); }},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    Vector host;
    c.op(host);
    Vector on_device = Vector::Constant(n, Complex(std::nan(""), 0));  // poisoned: every entry must be written
    {
      device::Scope scope(on_device);
      c.op(on_device);
    }
    CHECK(on_device.allFinite());
    CHECK(relative_difference(on_device, host) < 1e-15);
  }
  Vector unused;
  device::Scope scope(unused);
  CHECK(algebra::all_finite(x));
  CHECK(algebra::inner(x, y) == doctest::Approx(tsi::inner(x, y)).epsilon(1e-13));
  CHECK(algebra::max_norm(x) == doctest::Approx(tsi::max_norm(x)).epsilon(1e-15));
  Real m[2];
  algebra::increment_maxima(x, y, m);
  const Real host_increment = (x - y).cwiseAbs2().maxCoeff(), host_scale = x.cwiseAbs2().maxCoeff();
  CHECK(m[0] == doctest::Approx(host_increment).epsilon(1e-15));
  CHECK(m[1] == doctest::Approx(host_scale).epsilon(1e-15));
  Vector bad = x;
  bad(n - 1) = Complex(0, std::nan(""));
  CHECK_FALSE(algebra::all_finite(bad));
}

namespace {

// u(t) from y0 by n steps of the config's scheme: on the host, or in a device scope.
Vector steps(Assembly& a, const Vector& y0, double h, long n, bool on_device, long* evaluations = nullptr) {
  Vector y = y0;
  Stepper& stepper = a.bind(h);
  const long before = a.reformulation->evaluations();
  if (on_device) {
    device::Scope scope(y);
    integrate(stepper, y, n, {});
  } else {
    integrate(stepper, y, n, {});
  }
  if (evaluations) *evaluations = a.reformulation->evaluations() - before;
  return y;
}

Json nls_config(int dims, int n_x, int n_tau, double eps, const std::string& scheme, bool dealias) {
  Json model = {{"name", "nls"}, {"eps", eps}, {"dims", dims}, {"n_x", n_x}, {"dealias", dealias}};
  if (dims >= 2) model["n_y"] = n_x;
  if (dims == 3) model["n_z"] = n_x;
  Json s = {{"name", scheme}};
  if (scheme == "se1") s["tol"] = 1e-13;
  return {{"model", model},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", n_tau}, {"real_layout", false}}},
          {"scheme", s}};
}

}  // namespace

TEST_CASE("device NLS: SE1 and eab steps equal the CPU's to 1e-12 relative in 1, 2 and 3 dimensions, both tau paths") {
  struct Case {
    int dims, n_x, n_tau;
    double eps;
    bool dealias;
  };
  // n_tau a power of two up to 32: the NLS kernels' fused tau transforms (16 and 32: a point's
  // values over two lanes; 8: in one); 12 and 64: the core's cuFFT tau transforms around the
  // kernels' field
  for (const Case c : {Case{1, 64, 32, 0.1, false}, Case{2, 64, 32, 0.1, false}, Case{2, 32, 16, 0.01, true},
                       Case{3, 16, 16, 0.1, false}, Case{2, 32, 8, 0.1, false}, Case{1, 64, 12, 0.1, false},
                       Case{2, 32, 64, 0.1, true}})
    for (const std::string scheme : {"se1", "eab"}) {
      CAPTURE(scheme);
      CAPTURE(c.dims);
      CAPTURE(c.eps);
      Assembly a = assemble_config(nls_config(c.dims, c.n_x, c.n_tau, c.eps, scheme, c.dealias), registry());
      const Vector y0 = a.reformulation->prepare(a.u0);
      long host_evaluations = 0, device_evaluations = 0;
      const Vector host = steps(a, y0, 0.01, 6, false, &host_evaluations);
      const Vector on_device = steps(a, y0, 0.01, 6, true, &device_evaluations);
      const double difference = relative_difference(on_device, host);
      MESSAGE(fmt::format("{}-D n_x = {}, n_tau = {}, eps = {}, {}: relative difference {:.2e}", c.dims, c.n_x, c.n_tau,
                          c.eps, scheme, difference));
      CHECK(difference < 1e-12);
      CHECK(relative_difference(host, y0) > 1e-6);  // the steps moved the state
      CHECK(device_evaluations == host_evaluations);  // the same fixed-point sweeps
    }
}

TEST_CASE("device particle-in-cell: SE1 and eab steps equal the CPU's to 1e-12 relative, CIC and M6, per-tau field") {
  for (const std::string shape : {"cic", "m6"})
    for (const std::string scheme : {"se1", "eab"}) {
      CAPTURE(shape);
      CAPTURE(scheme);
      Json s = {{"name", scheme}};
      if (scheme == "se1") s["tol"] = 1e-13;
      // 20000 particles: the grid's nodes each get many deposits, in the order the atomics land
      const Json config = {
          {"model", {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}, {"particles", 20000}, {"distribution", "peer"},
                     {"alpha", 0.5}, {"n_x", 32}, {"n_y", 16}, {"shape", shape}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}, {"real_layout", false}}},
          {"scheme", s}};
      Assembly a = assemble_config(config, registry());
      const Vector y0 = a.reformulation->prepare(a.u0);
      long host_evaluations = 0, device_evaluations = 0;
      const Vector host = steps(a, y0, 0.05, 4, false, &host_evaluations);
      const Vector on_device = steps(a, y0, 0.05, 4, true, &device_evaluations);
      const double difference = relative_difference(on_device, host);
      MESSAGE(fmt::format("particle-in-cell {}, {}: relative difference {:.2e}", shape, scheme, difference));
      CHECK(difference < 1e-12);
      CHECK(relative_difference(host, y0) > 1e-6);
      CHECK(device_evaluations == host_evaluations);
    }
}

TEST_CASE("device runner: tsi run --device cuda writes the CPU's u(t_end) to 1e-12 relative") {
  const std::string dir = fmt::format("device-run-{}", ::getpid());
  const std::string config = dir + "/nls.json";
  REQUIRE(std::system(("mkdir -p " + dir).c_str()) == 0);
  {
    Json c = nls_config(2, 32, 32, 0.05, "se1", false);
    c["time"] = {{"h", 0.01}, {"t_end", 0.1}};
    c["output"] = {{"every", 5}};
    std::FILE* f = std::fopen(config.c_str(), "w");
    REQUIRE(f);
    std::fputs(c.dump().c_str(), f);
    std::fclose(f);
  }
  const std::string runner = std::getenv("TSI_TEST_RUNNER") ? std::getenv("TSI_TEST_RUNNER") : TSI_TEST_RUNNER;
  REQUIRE(std::system((runner + " run " + config + " --quiet --out " + dir + "/cpu > /dev/null").c_str()) == 0);
  REQUIRE(std::system((runner + " run " + config + " --quiet --device cuda --out " + dir + "/cuda > /dev/null").c_str()) == 0);
  const Vector cpu = read_npy(dir + "/cpu/u_final.npy").values, gpu = read_npy(dir + "/cuda/u_final.npy").values;
  REQUIRE(cpu.size() == 32 * 32);
  CHECK(relative_difference(gpu, cpu) < 1e-12);
  CHECK(Json::parse(read_text(dir + "/cuda/result.json"))["device"].get<std::string>().rfind("cuda: ", 0) == 0);
  CHECK(Json::parse(read_text(dir + "/cpu/result.json"))["device"] == "cpu");
  // what the device does not run is refused before anything runs, naming the field
  CHECK(std::system((runner + " run " + config + " --quiet --device cuda --set scheme.name=se2 --out " + dir +
                     "/refused 2> " + dir + "/refused.txt").c_str()) != 0);
  (void)!std::system(("rm -rf " + dir).c_str());
}
