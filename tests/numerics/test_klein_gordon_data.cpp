// The Klein-Gordon model's initial data in the literature's form (model.z0 = z(x, 0),
// model.eps_z_t0 = e^2 z_t(x, 0)): the state it makes against naive DFTs of
// v = z - i (1 - e^2 d_xx)^{-1/2} (e^2 z_t) and against the PDE's energy, the default data given
// this way against the default run, on a grid of two directions of different sizes (C order),
// and complex samples refused rather than cut to their real part.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "harness.hpp"
#include "runner/run_command.hpp"
#include "tsi/error.hpp"

namespace {

using tsi::Complex;
using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

const Complex I(0.0, 1.0);

// A grid of one or two directions, fields in C order (the last direction fastest), and naive
// DFTs on it (no FFTW): the independent side of the checks.
struct Grid {
  std::vector<long> shape;
  long points() const { return shape.size() == 1 ? shape[0] : shape[0] * shape[1]; }
  // The index along each direction of point j.
  std::array<long, 2> index(long j) const {
    return shape.size() == 1 ? std::array<long, 2>{j, 0} : std::array<long, 2>{j / shape[1], j % shape[1]};
  }
  std::array<double, 2> x(long j) const {
    const auto i = index(j);
    std::array<double, 2> out{0.0, 0.0};
    for (std::size_t d = 0; d < shape.size(); ++d) out[d] = tsi::two_pi * static_cast<double>(i[d]) / static_cast<double>(shape[d]);
    return out;
  }
  // The wave numbers of FFT index m, the Nyquist index as +n/2.
  std::array<double, 2> k(long m) const {
    const auto i = index(m);
    std::array<double, 2> out{0.0, 0.0};
    for (std::size_t d = 0; d < shape.size(); ++d)
      out[d] = 2 * i[d] <= shape[d] ? static_cast<double>(i[d]) : static_cast<double>(i[d] - shape[d]);
    return out;
  }
  double k2(long m) const { return k(m)[0] * k(m)[0] + k(m)[1] * k(m)[1]; }
  double phase(long m, long j) const { return k(m)[0] * x(j)[0] + k(m)[1] * x(j)[1]; }

  // f_m = (1/N) sum_j f_j e^{-i k_m . x_j}.
  Vector dft(const Vector& f) const {
    Vector out = Vector::Zero(points());
    for (long m = 0; m < points(); ++m)
      for (long j = 0; j < points(); ++j) out(m) += f(j) * std::polar(1.0, -phase(m, j));
    return out / static_cast<double>(points());
  }
  Vector idft(const Vector& c) const {
    Vector out = Vector::Zero(points());
    for (long j = 0; j < points(); ++j)
      for (long m = 0; m < points(); ++m) out(j) += c(m) * std::polar(1.0, phase(m, j));
    return out;
  }
  // (1 - eps lap)^power on grid values.
  Vector multiplier(const Vector& f, double eps, double power) const {
    Vector c = dft(f);
    for (long m = 0; m < points(); ++m) c(m) *= std::pow(1.0 + eps * k2(m), power);
    return idft(c);
  }

  template <class F>
  Vector sample(F f) const {
    Vector out(points());
    for (long j = 0; j < points(); ++j) out(j) = f(x(j));
    return out;
  }
};

// The default data, as the model's header states it: z = prod cos x_i / (1 + sin^2 x_i) and
// (1 - e^2 lap)^{-1/2} (e^2 z_t) = (1/2) prod sin x_i / (1 + cos^2 x_i).
double default_z(const std::array<double, 2>& x, std::size_t dims) {
  double z = 1.0;
  for (std::size_t d = 0; d < dims; ++d) z *= std::cos(x[d]) / (1.0 + std::sin(x[d]) * std::sin(x[d]));
  return z;
}
double default_smoothed_momentum(const std::array<double, 2>& x, std::size_t dims) {
  double p = 0.5;
  for (std::size_t d = 0; d < dims; ++d) p *= std::sin(x[d]) / (1.0 + std::cos(x[d]) * std::cos(x[d]));
  return p;
}

// Real grid values as a JSON array of numbers.
Json samples(const Vector& f) {
  Json out = Json::array();
  for (long j = 0; j < f.size(); ++j) out.push_back(f(j).real());
  return out;
}

double max_difference(const Json& a, const Json& b) {
  double out = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j)
    for (std::size_t c = 0; c < 2; ++c) out = std::max(out, std::abs(a[j][c].get<double>() - b[j][c].get<double>()));
  return out;
}

}  // namespace

TEST_CASE("klein-gordon: z0 and eps_z_t0 make the state of v = z - i (1 - e^2 d_xx)^{-1/2} (e^2 z_t)") {
  auto& h = Harness::instance();
  const Grid grid{{16}};
  // z and z_t not trigonometric polynomials (every mode present), z_t of size 1/e^2 as well
  // prepared data has it, so p = e^2 z_t = O(1).
  const Vector z = grid.sample([](const std::array<double, 2>& x) { return std::exp(std::sin(x[0])) - 1.2; });
  const Vector p = grid.sample([](const std::array<double, 2>& x) { return 0.7 * std::cos(2.0 * x[0] + 0.3) / (2.0 - std::sin(x[0])); });
  for (double lambda : {1.0, -0.5})
    for (double eps : {1.0, 0.25, 1e-3}) {
      CAPTURE(lambda);
      CAPTURE(eps);
      auto model = h.model_with("klein-gordon", eps,
                                {{"n_x", 16}, {"lambda", lambda}, {"z0", samples(z)}, {"eps_z_t0", samples(p)}});
      const Vector c = model->initial_value();
      const Vector v = z - I * grid.multiplier(p, eps, -0.5);
      const Vector v_model = model->to_physical(c);
      CHECK((v_model - v).norm() < 1e-14 * v.norm());
      CHECK((v_model.real() - z.real()).norm() < 1e-14 * z.norm());
      // The same state as u0 = v gives (the two ways in agree).
      CHECK((model->from_physical(v) - c).norm() < 1e-14 * c.norm());
      // eps_z_t0 is e^2 z_t, not z_t: the energy is the PDE's
      // int e^2 z_t^2/2 + z_x^2/2 + z^2/(2 e^2) + lambda z^4/4 dx with z_t = p / e^2, the rule of the
      // grid for the rest and int z_x^2 = 2 pi sum k^2 |z_k|^2 (the Nyquist mode's k^2 as the model's).
      double energy = 0.0;
      for (long j = 0; j < 16; ++j) {
        const double zj = z(j).real(), pj = p(j).real();
        energy += pj * pj / (2.0 * eps) + zj * zj / (2.0 * eps) + lambda * std::pow(zj, 4) / 4.0;
      }
      energy *= tsi::two_pi / 16;
      const Vector z_hat = grid.dft(z);
      for (long m = 0; m < 16; ++m) energy += tsi::two_pi * grid.k2(m) * std::norm(z_hat(m)) / 2.0;
      CHECK(model->energy(c) == doctest::Approx(energy).epsilon(1e-13));
    }
  // Either alone: the other is zero.
  auto z_only = h.model_with("klein-gordon", 0.25, {{"n_x", 16}, {"z0", samples(z)}});
  CHECK((z_only->to_physical(z_only->initial_value()) - z).norm() < 1e-14 * z.norm());
  auto p_only = h.model_with("klein-gordon", 0.25, {{"n_x", 16}, {"eps_z_t0", samples(p)}});
  const Vector v_p = -I * grid.multiplier(p, 0.25, -0.5);
  CHECK((p_only->to_physical(p_only->initial_value()) - v_p).norm() < 1e-14 * v_p.norm());
}

TEST_CASE("klein-gordon: the default data given as z0 and eps_z_t0 are the default, in 1-D and on an 8 x 6 grid") {
  auto& h = Harness::instance();
  for (const Grid& grid : {Grid{{16}}, Grid{{8, 6}}}) {
    const std::size_t dims = grid.shape.size();
    for (double eps : {1.0, 1e-3}) {
      CAPTURE(dims);
      CAPTURE(eps);
      const Vector z = grid.sample([&](const std::array<double, 2>& x) { return default_z(x, dims); });
      // p = (1 - e^2 lap)^{1/2} of the smoothed momentum, by naive DFTs.
      const Vector p = grid.multiplier(
          grid.sample([&](const std::array<double, 2>& x) { return default_smoothed_momentum(x, dims); }), eps, 0.5);
      Json params = {{"dims", dims}, {"n_x", grid.shape[0]}};
      if (dims == 2) params["n_y"] = grid.shape[1];
      auto plain = h.model_with("klein-gordon", eps, params);
      params["z0"] = samples(z);
      params["eps_z_t0"] = samples(p);
      auto given = h.model_with("klein-gordon", eps, params);
      const Vector c = plain->initial_value(), c_given = given->initial_value();
      CHECK((c_given - c).norm() < 1e-14 * c.norm());
      // z_t given where e^2 z_t is expected is other data, which the check above tells apart.
      if (eps < 1.0) {
        params["eps_z_t0"] = samples(p / eps);
        CHECK((h.model_with("klein-gordon", eps, params)->initial_value() - c).norm() > c.norm());
      }
    }
  }
}

TEST_CASE("klein-gordon: a run from the default data as z0 and eps_z_t0 is the default run") {
  const tsi::test::TempDir dir("tsi-kg-data");
  Json config = Json::parse(tsi::test::read_text(tsi::test::example_config("kg-se1.json")));
  config.erase("reference");
  const Grid grid{{config["model"]["n_x"].get<long>()}};
  const double eps = config["model"]["eps"];
  const auto plain = tsi::test::run_tsi({"run", tsi::test::write_config(dir, config, "a.json"), "--out", dir / "a"});
  REQUIRE_MESSAGE(plain.exit_code == 0, plain.describe());

  config["model"]["z0"] =
      samples(grid.sample([](const std::array<double, 2>& x) { return default_z(x, 1); }));
  config["model"]["eps_z_t0"] = samples(grid.multiplier(
      grid.sample([](const std::array<double, 2>& x) { return default_smoothed_momentum(x, 1); }), eps, 0.5));
  const auto given = tsi::test::run_tsi({"run", tsi::test::write_config(dir, config, "b.json"), "--out", dir / "b"});
  REQUIRE_MESSAGE(given.exit_code == 0, given.describe());
  const Json a = tsi::test::read_json(dir.path() / "a" / "result.json").at("u_final");
  const Json b = tsi::test::read_json(dir.path() / "b" / "result.json").at("u_final");
  REQUIRE(a.size() == b.size());
  REQUIRE(a.size() == static_cast<std::size_t>(grid.points()));
  const double difference = max_difference(a, b);
  MESSAGE("largest difference of u_final: " << difference);
  CHECK(difference < 1e-13);

}

TEST_CASE("klein-gordon: complex, short, non-finite and doubled data are refused, naming the field") {
  auto& h = Harness::instance();
  const auto refusal = [&](const Json& params) {
    try {
      (void)h.model_with("klein-gordon", 0.1, params);
    } catch (const tsi::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  Json z = Json::array(), cos_sin = Json::array();
  for (long j = 0; j < 8; ++j) {
    const double x = tsi::two_pi * static_cast<double>(j) / 8;
    z.push_back(std::cos(x));
    cos_sin.push_back({std::cos(x), std::cos(x)});  // CosSin's z(0) = (1 + i) cos x
  }
  const std::string complex = refusal({{"n_x", 8}, {"z0", cos_sin}});
  CHECK(tsi::test::contains(complex, "model.z0[0]: got [1.0,1.0], expected a real number: this model's z is real"));
  Json with_zero = z;
  with_zero[3] = {with_zero[3].get<double>(), 0.0};  // [re, 0] is a real number
  CHECK(refusal({{"n_x", 8}, {"z0", with_zero}}) == "accepted");
  Json momentum = z;
  momentum[5] = {0.5, -1e-300};
  CHECK(tsi::test::contains(refusal({{"n_x", 8}, {"eps_z_t0", momentum}}), "model.eps_z_t0[5]: got [0.5,-1e-300]"));
  CHECK(tsi::test::contains(refusal({{"n_x", 10}, {"z0", z}}), "model.z0: got 8 samples, expected 10 real numbers"));
  CHECK(tsi::test::contains(refusal({{"n_x", 4}, {"dims", 2}, {"z0", z}}), "expected 16 real numbers"));
  Json not_finite = z;
  not_finite[2] = "NaN";
  CHECK(tsi::test::contains(refusal({{"n_x", 8}, {"z0", not_finite}}), "model.z0[2]: got \"NaN\", expected a finite"));
  CHECK(tsi::test::contains(refusal({{"n_x", 8}, {"eps_z_t0", z}, {"u0", z}}), "model.eps_z_t0: is given together with model.u0"));
  CHECK(tsi::test::contains(refusal({{"n_x", 8}, {"z0", z}, {"initial", "plane-wave"}}), "model.z0: is given, but model.initial"));
}
