// u between the steps (output.times): the two-scale state interpolated in t with the scheme's
// order and read back at tau = t/eps. Its error at times between the steps is that of the
// steps around them (within 2x), measured against rk78 on the filtered problem at each time.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace {

namespace fs = std::filesystem;
namespace t = tsi::test;
using t::Json;

// A state from result.json: numbers, or [re, im] pairs.
std::vector<std::complex<double>> state(const Json& values) {
  std::vector<std::complex<double>> out;
  for (const Json& v : values)
    out.emplace_back(v.is_array() ? v[0].get<double>() : v.get<double>(), v.is_array() ? v[1].get<double>() : 0.0);
  return out;
}

double relative_difference(const std::vector<std::complex<double>>& a, const std::vector<std::complex<double>>& b) {
  double d = 0.0, n = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    d += std::norm(a[i] - b[i]);
    n += std::norm(b[i]);
  }
  return std::sqrt(d / n);
}

Json run(const t::TempDir& dir, const Json& config, const std::string& name) {
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config, name + ".json"), "--out", dir / name});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  return t::read_json(fs::path(dir / name) / "result.json");
}

}  // namespace

TEST_CASE("dense output: off the steps as accurate as on them (Henon-Heiles, NLS, SE1, eab, ME, eps 1e-2 and 1e-4)") {
  const t::TempDir dir("tsi-dense");
  const std::vector<double> on = {0.25, 0.5, 0.75}, off = {0.3, 0.33, 0.55, 0.8};
  struct Case {
    Json model;
    std::string scheme;
    double h;
  };
  for (const Case& c : {Case{{{"name", "henon-heiles"}, {"eps", 0.01}}, "se1", 0.125},
                        Case{{{"name", "nls"}, {"eps", 0.01}, {"n_x", 16}}, "se1", 0.125},
                        Case{{{"name", "henon-heiles"}, {"eps", 0.01}}, "eab", 0.125},
                        Case{{{"name", "henon-heiles"}, {"eps", 1e-4}}, "me", 0.0625}}) {
    CAPTURE(c.model.dump());
    CAPTURE(c.scheme);
    const Json base = {{"model", c.model}, {"reformulation", {{"name", "two-scale"}}}, {"scheme", {{"name", c.scheme}}}};
    Json config = base;
    std::vector<double> times = on;
    times.insert(times.end(), off.begin(), off.end());
    config["time"] = {{"h", c.h}, {"t_end", 1.0}};
    config["output"] = {{"times", times}};
    const Json result = run(dir, config, "dense");
    const Json& dense = result.at("dense_output");
    REQUIRE(dense.at("u").size() == times.size());
    double on_error = 0.0, off_error = 0.0;
    for (size_t k = 0; k < times.size(); ++k) {
      // The reference at that time: rk78 on the filtered problem (one step of the scheme to t,
      // its result.json carrying the reference's u there).
      Json reference = base;
      reference["time"] = {{"h", times[k]}, {"t_end", times[k]}};
      reference["reference"] = {{"scheme", "rk78"}, {"reformulation", "filtered"}, {"tol", 1e-13}};
      const Json r = run(dir, reference, "reference");
      const double e = relative_difference(state(dense["u"][k]), state(r["error"]["reference"]["u_final"]));
      CAPTURE(times[k]);
      CAPTURE(e);
      CHECK(e < 1e-3);
      (k < on.size() ? on_error : off_error) = std::max(k < on.size() ? on_error : off_error, e);
    }
    CAPTURE(on_error);
    CAPTURE(off_error);
    CHECK(off_error <= 2.0 * on_error);
  }
}

TEST_CASE("dense output: a time on a step is that step, t_end is u_final, times are checked") {
  const t::TempDir dir("tsi-dense-grid");
  Json config = t::small_config();
  config["model"]["u0"] = {0.1, 0.2, 0.15, -0.05};
  const double h = config["time"]["h"].get<double>();
  config["output"] = {{"times", {1.0, 2 * h, 0.0}}};
  const Json result = run(dir, config, "grid");
  const Json& u = result.at("dense_output").at("u");
  CHECK(u[0] == result.at("u_final"));  // bit for bit: the weights are exactly 1 and 0
  CHECK(state(u[2]) == state(config["model"]["u0"]));  // t = 0: u0 read back from the prepared data
  CHECK(fs::is_regular_file(fs::path(dir / "grid") / "u_times.npy"));

  for (const Json& bad : {Json{{"times", {0.5, 1.5}}}, Json{{"times", {-0.1}}}, Json{{"times", "0.5"}}}) {
    Json c = config;
    c["output"] = bad;
    const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, c, "bad.json"), "--out", dir / "bad"});
    INFO(r.describe());
    CHECK(r.exit_code == 2);
    CHECK(t::contains(r.err, "output.times"));
  }
  Json reprepared = config;
  reprepared["reformulation"]["reprepare"] = 4;
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, reprepared, "rep.json"), "--out", dir / "rep"});
  CHECK(r.exit_code == 2);
  CHECK(t::contains(r.err, "cannot be combined with reformulation.reprepare"));
}
