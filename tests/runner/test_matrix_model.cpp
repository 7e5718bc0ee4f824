// The core's "matrix" model (A a matrix in the run's JSON, f a registered field): HOODESolver.jl's
// quickstart problem with A from JSON and f from a plugin or the core gives the numbers of the
// C++ model tests/fixtures/fixture_general.cpp; a non-periodic A is refused with the deviation
// it measured; a time-dependent f (HOODESolver.jl's linear test, t carried as one more
// variable) converges at the schemes' orders to the exact solution, computed here
// independently (the exponential of an augmented matrix in long double); an n_tau that aliases
// A's frequencies is refused, the next one accurate; an interrupt during the set-up of a
// 1024 x 1024 A ends the run within a second.
#include <doctest/doctest.h>

#include <fmt/format.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <csignal>
#include <string>
#include <vector>
#include <unsupported/Eigen/MatrixFunctions>

#include "run_command.hpp"

namespace {

namespace t = tsi::test;
using t::Json;

const Json quickstart_A = Json::array({Json::array({0, 0, 1, 0}), Json::array({0, 0, 0, 0}),
                                       Json::array({-1, 0, 0, 0}), Json::array({0, 0, 0, 0})});
const Json quickstart_u0 = Json::array({0.55, 0.12, 0.03, 0.89});

Json config(const Json& model, const Json& scheme, double h, double t_end) {
  return {{"model", model},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", 32}}},
          {"scheme", scheme},
          {"time", {{"h", h}, {"t_end", t_end}}}};
}

// u_final of a run (result.json), after checking that it completed and reported no energy.
Eigen::Vector4d final_state(const t::TempDir& dir, const Json& cfg, const std::string& name) {
  const std::string out = dir / name;
  const t::CommandResult r = t::run_tsi(
      {"run", t::write_config(dir, cfg, name + ".json"), "--plugin", t::fixture_plugin("general"), "--out", out});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const Json result = t::read_json(t::fs::path(out) / "result.json");
  CHECK(result["status"] == "completed");
  CHECK_FALSE(result["invariants"].contains("H"));
  REQUIRE(result["u_final"].size() == 4);
  Eigen::Vector4d u;
  for (int i = 0; i < 4; ++i) u(i) = result["u_final"][static_cast<size_t>(i)].get<double>();
  return u;
}

// HOODESolver.jl's linear test: u' = A u / eps + B u + t a + b, u(0) = u0, exactly: z = (u, t, 1)
// solves z' = [[C, a, b], [0, 0, 1], [0, 0, 0]] z with C = A/eps + B.
Eigen::Vector4d linear_exact(double eps, double t_end) {
  using M6 = Eigen::Matrix<long double, 6, 6>;
  M6 Z = M6::Zero();
  const long double B[4][4] = {{0.12L, -0.78L, 0.91L, 0.34L},
                               {-0.45L, 0.56L, 0.03L, 0.54L},
                               {-0.67L, 0.09L, 0.18L, 0.89L},
                               {-0.91L, -0.56L, 0.11L, -0.56L}};
  const long double a[4] = {0.12L, -0.98L, 0.45L, 0.26L}, b[4] = {-0.04L, 0.48L, 0.23L, -0.87L};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) Z(i, j) = B[i][j];
    Z(i, 4) = a[i];
    Z(i, 5) = b[i];
  }
  const long double e = static_cast<long double>(eps);
  Z(0, 2) += 1.0L / e;
  Z(2, 0) -= 1.0L / e;
  Z(4, 5) = 1.0L;
  const M6 E = (static_cast<long double>(t_end) * Z).exp();
  Eigen::Matrix<long double, 6, 1> z0;
  z0 << -0.34L, 0.78L, 0.67L, -5.6L, 0.0L, 1.0L;
  const Eigen::Matrix<long double, 6, 1> z = E * z0;
  Eigen::Vector4d u;
  for (int i = 0; i < 4; ++i) u(i) = static_cast<double>(z(i));
  return u;
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("matrix model: A from JSON with f from a plugin or the core gives the C++ model's numbers") {
  t::TempDir dir;
  const Json schemes[] = {{{"name", "eab"}, {"order", 4}}, {{"name", "collocation"}}};
  for (const Json& scheme : schemes) {
    const std::string name = scheme["name"];
    const Eigen::Vector4d cpp =
        final_state(dir, config({{"name", "fixture-quickstart"}, {"eps", 1e-4}}, scheme, 0.1, 3.0), name + "-cpp");
    const Eigen::Vector4d plugin_f = final_state(
        dir,
        config({{"name", "matrix"}, {"eps", 1e-4}, {"A", quickstart_A}, {"f", "fixture-quickstart-f"}, {"u0", quickstart_u0}},
               scheme, 0.1, 3.0),
        name + "-plugin");
    const Eigen::Vector4d core_f = final_state(
        dir, config({{"name", "matrix"}, {"eps", 1e-4}, {"A", quickstart_A}, {"f", "quickstart"}}, scheme, 0.1, 3.0),
        name + "-core");
    const double d1 = (plugin_f - cpp).norm() / cpp.norm(), d2 = (core_f - cpp).norm() / cpp.norm();
    MESSAGE(name << ": JSON A + plugin f vs C++ model " << d1 << ", JSON A + core f " << d2);
    CHECK(d1 < 1e-12);
    CHECK(d2 < 1e-12);
  }
}

TEST_CASE("matrix model: a non-periodic A (the quickstart's times 1.1) is refused, naming the deviation") {
  t::TempDir dir;
  Json A = quickstart_A;
  A[0][2] = 1.1;
  A[2][0] = -1.1;
  const t::CommandResult r = t::run_tsi(
      {"run", t::write_config(dir, config({{"name", "matrix"}, {"eps", 1e-4}, {"A", A}}, {{"name", "se1"}}, 0.1, 1.0)),
       "--out", dir / "out"});
  INFO(r.describe());
  CHECK(r.exit_code == 2);
  CHECK(t::contains(r.err, "tsi: error: model.A: e^(2 pi A) differs from the identity by 0.588"));
  CHECK(t::contains(r.err, "expected at most"));
  CHECK(t::contains(r.err, "0+1.1i"));
}

TEST_CASE("matrix model: a time-dependent f converges at the schemes' orders to the exact solution") {
  // HOODESolver.jl's linear test at T = 1, n_tau = 16 (F_tau has tau modes up to 2). SE1 is
  // fitted where it is in its asymptotic range: at eps = 0.015 its error is nearly flat from
  // h = 1/4 to 1/16 (2.4e-3, 1.3e-3, 7.1e-4) before it settles to order 2; at eps = 1.5e-4 it
  // levels off below 1e-6 (5.3e-7 at h = 1/256, where h is 4 fast periods).
  t::TempDir dir;
  struct Case {
    double eps;
    Json scheme;
    double order;
    std::vector<double> steps;
  };
  const Json se1 = {{"name", "se1"}}, eab = {{"name", "eab"}, {"order", 4}};
  const std::vector<double> coarse = {1.0 / 4, 1.0 / 8, 1.0 / 16, 1.0 / 32};
  const Case cases[] = {{0.015, se1, 2.0, {1.0 / 32, 1.0 / 64, 1.0 / 128, 1.0 / 256}},
                        {0.015, eab, 4.0, coarse},
                        {1.5e-4, se1, 2.0, {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64}},
                        {1.5e-4, eab, 4.0, coarse}};
  for (const Case& c : cases) {
    const double eps = c.eps;
    const Eigen::Vector4d exact = linear_exact(eps, 1.0);
    {
      std::vector<double> errors;
      for (const double h : c.steps) {
        const Json model = {{"name", "matrix"}, {"eps", eps}, {"A", quickstart_A}, {"f", "fixture-linear"}};
        Json cfg = config(model, c.scheme, h, 1.0);
        cfg["reformulation"]["n_tau"] = 16;
        const Eigen::Vector4d u =
            final_state(dir, cfg, fmt::format("{}-{}-{}", c.scheme["name"].get<std::string>(), eps, errors.size()));
        errors.push_back((u - exact).norm() / exact.norm());
      }
      // The least-squares slope of log(error) against log(h).
      double sx = 0, sy = 0, sxx = 0, sxy = 0;
      const auto n = static_cast<double>(errors.size());
      for (std::size_t i = 0; i < errors.size(); ++i) {
        const double x = std::log(c.steps[i]), y = std::log(errors[i]);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
      }
      const double order = (n * sxy - sx * sy) / (n * sxx - sx * sx);
      std::string shown;
      for (const double e : errors) shown += fmt::format(" {:.3e}", e);
      MESSAGE(c.scheme.dump() << " eps = " << eps << ": errors" << shown << ", order " << order);
      CHECK(order == doctest::Approx(c.order).epsilon(0.1));
    }
  }
}

TEST_CASE("matrix model: against the linear test's exact solution eab of orders 3 to 6 is uniform in eps") {
  // The core's "linear" field with reference.scheme "exact" (quad precision). Order r of the
  // envelope over eps = 0.15, 1.5e-4, 1.5e-7 (h = 1/8 .. 1/64: below the ratio of its errors at
  // 1/4 and 1/8 is still pre-asymptotic at eps = 0.15), and each eps alone; collocation (s = 3,
  // uniform order 2 declared) keeps its envelope under its h = 1/4 error times (4 h)^2.
  t::TempDir dir;
  const std::vector<double> epsilons = {0.15, 1.5e-4, 1.5e-7};
  int runs = 0;
  auto error = [&](const Json& scheme, double eps, double h) {
    Json cfg = config({{"name", "matrix"}, {"eps", eps}, {"f", "linear"}}, scheme, h, 1.0);
    cfg["reference"] = {{"scheme", "exact"}};
    const std::string name = fmt::format("run-{}", runs++);
    const std::string out = dir / name;
    const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, cfg, name + ".json"), "--out", out});
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    const Json result = t::read_json(t::fs::path(out) / "result.json");
    REQUIRE(result["error"]["reference"]["scheme"] == "exact");
    CHECK(result["error"]["reference"]["estimated_relative_accuracy"].get<double>() < 2e-16);
    return result["error"]["relative"].get<double>();
  };
  auto slope = [](const std::vector<double>& hs, const std::vector<double>& errors) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const auto n = static_cast<double>(hs.size());
    for (std::size_t i = 0; i < hs.size(); ++i) {
      const double x = std::log(hs[i]), y = std::log(errors[i]);
      sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
  };
  const std::vector<double> hs = {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64};
  for (int r = 3; r <= 6; ++r) {
    const Json scheme = {{"name", "eab"}, {"order", r}};
    std::vector<double> envelope(hs.size(), 0.0);
    for (const double eps : epsilons) {
      std::vector<double> errors;
      for (std::size_t i = 0; i < hs.size(); ++i) {
        errors.push_back(error(scheme, eps, hs[i]));
        envelope[i] = std::max(envelope[i], errors.back());
      }
      const double order = slope(hs, errors);
      MESSAGE("eab r = " << r << ", eps = " << eps << ": errors " << errors[0] << " .. " << errors.back() << ", order "
                         << order);
      CHECK(order == doctest::Approx(r).epsilon(0.06));
    }
    const double order = slope(hs, envelope);
    MESSAGE("eab r = " << r << ": order of the envelope " << order);
    CHECK(order == doctest::Approx(r).epsilon(0.06));
  }
  const Json collocation = {{"name", "collocation"}, {"stages", 3}, {"tol", 1e-15}, {"max_iter", 1000}};
  const std::vector<double> coarse = {1.0 / 4, 1.0 / 8, 1.0 / 16, 1.0 / 32};
  std::vector<double> envelope(coarse.size(), 0.0);
  for (const double eps : epsilons)
    for (std::size_t i = 0; i < coarse.size(); ++i) envelope[i] = std::max(envelope[i], error(collocation, eps, coarse[i]));
  for (std::size_t i = 1; i < coarse.size(); ++i) {
    MESSAGE("collocation h = " << coarse[i] << ": envelope " << envelope[i] << ", order-2 bound "
                               << envelope[0] * std::pow(4.0 * coarse[i], 2.0));
    CHECK(envelope[i] <= envelope[0] * std::pow(4.0 * coarse[i], 2.0));
  }
}

TEST_CASE("matrix model: an n_tau that aliases A's frequencies is refused, the next even one is accurate") {
  // HOODESolver.jl's linear test with A = K times the quickstart's A (frequencies 0 and +-K):
  // f_tau has tau harmonics up to 2K, which n_tau points resolve when n_tau/2 > 2K. Measured
  // before the refusal existed (eab 4, h = 1/64, eps = 0.01): 1.1e-2 at n_tau = 16 and 1.6e-9 at
  // 18 for K = 4, 1.5e-2 at 32 and 1.5e-9 at 34 for K = 8; 1.4e-9 for K = 1 at any n_tau.
  t::TempDir dir;
  auto run = [&](long K, const Json& n_tau, const std::string& name) {
    Json A = quickstart_A;
    A[0][2] = K;
    A[2][0] = -K;
    Json cfg = config({{"name", "matrix"}, {"eps", 0.01}, {"A", A}, {"f", "linear"}}, {{"name", "eab"}, {"order", 4}},
                      1.0 / 64, 1.0);
    cfg["reformulation"].erase("n_tau");
    if (!n_tau.is_null()) cfg["reformulation"]["n_tau"] = n_tau;
    cfg["reference"] = {{"scheme", "exact"}};
    return t::run_tsi({"run", t::write_config(dir, cfg, name + ".json"), "--out", dir / name});
  };
  auto error = [&](const t::CommandResult& r, const std::string& name) {
    INFO(r.describe());
    REQUIRE(r.exit_code == 0);
    return t::read_json(t::fs::path(dir / name) / "result.json")["error"]["relative"].get<double>();
  };
  const double floor = error(run(1, 18, "k1"), "k1");
  for (const long K : {4L, 8L}) {
    const t::CommandResult aliased = run(K, 4 * K, fmt::format("aliased-{}", K));
    INFO(aliased.describe());
    CHECK(aliased.exit_code == 2);
    CHECK(t::contains(aliased.err, fmt::format("tsi: error: reformulation.n_tau: got {}, but model.A has "
                                               "frequencies up to {}",
                                               4 * K, K)));
    CHECK(t::contains(aliased.err, fmt::format("expected n_tau > 4 x {} = {}: {} or more", K, 4 * K, 4 * K + 2)));
    const std::string name = fmt::format("resolved-{}", K);
    const double resolved = error(run(K, 4 * K + 2, name), name);
    MESSAGE("K = " << K << ": error " << resolved << " at n_tau = " << 4 * K + 2 << ", " << floor << " for K = 1");
    CHECK(resolved < 2 * floor);
  }
  // Without n_tau the model's default (32) is held to the same: K = 8 needs 34.
  const t::CommandResult by_default = run(8, Json(), "default");
  INFO(by_default.describe());
  CHECK(by_default.exit_code == 2);
  CHECK(t::contains(by_default.err, "tsi: error: reformulation.n_tau: got 32, but model.A has frequencies up to 8"));
}

TEST_CASE("matrix model: an interrupt during the set-up of a 1024 x 1024 A ends the run within a second") {
  // Frequencies 0 .. 15 (the most a 1024 x 1024 A takes): its set-up is about 50 products of
  // 1024 x 1024 matrices (6 s on 2 busy cores; before they were 33 matrix exponentials and
  // an eigenvalue solve, 620 s on one core, deaf to Ctrl-C). The signal comes at 1 s.
  const int n = 1024;
  Json A = Json::array();
  for (int i = 0; i < n; ++i) {
    Json row = Json::array();
    for (int j = 0; j < n; ++j) {
      const int k = (i / 2) % 16;
      row.push_back(j == (i ^ 1) ? (i % 2 == 0 ? k : -k) : 0);
    }
    A.push_back(std::move(row));
  }
  t::TempDir dir;
  Json cfg = config({{"name", "matrix"}, {"eps", 0.1}, {"A", A}, {"f", "fixture-zero-f"},
                     {"u0", Json(std::vector<double>(n, 1.0))}},
                    {{"name", "se1"}}, 0.5, 1.0);
  cfg["reformulation"]["n_tau"] = 64;
  t::CommandEnv env;
  env.send_signal = SIGINT;
  env.signal_after_seconds = 1.0;
  const auto start = std::chrono::steady_clock::now();
  const t::CommandResult r = t::run_tsi(
      {"--plugin", t::fixture_plugin("general"), "run", t::write_config(dir, cfg), "--out", dir / "out"}, env);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  INFO(r.describe());
  MESSAGE("exit " << r.exit_code << " after " << seconds << " s (SIGINT at 1 s)");
  CHECK(r.signal == 0);
  CHECK(r.exit_code == 128 + SIGINT);
  CHECK(t::contains(r.err, "interrupted by signal 2 while setting up model.A's flow"));
  CHECK(seconds < 3.0);
}

TEST_CASE("matrix model: an exact reference is refused for a model that declares none") {
  t::TempDir dir;
  Json cfg = config({{"name", "matrix"}, {"eps", 1e-2}}, {{"name", "se1"}}, 0.1, 1.0);
  cfg["reference"] = {{"scheme", "exact"}};
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, cfg), "--out", dir / "out"});
  INFO(r.describe());
  CHECK(r.exit_code == 2);
  CHECK(t::contains(r.err, "tsi: error: reference.scheme: got \"exact\", but the model \"matrix\" declares no exact "
                           "solution"));
}

TEST_CASE("matrix model: the fields are listed") {
  const t::CommandResult r = t::run_tsi({"--plugin", t::fixture_plugin("general"), "list", "fields"});
  INFO(r.describe());
  CHECK(r.exit_code == 0);
  CHECK(t::contains(r.out, "quickstart"));
  CHECK(t::contains(r.out, "fixture-linear"));
  CHECK(t::contains(r.out, "4 entries, time-dependent, real"));
}

}  // TEST_SUITE
