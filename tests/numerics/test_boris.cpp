// The Boris family (SPEC.md section 8) on the 3-D charged particle: Hairer, Lubich and Wang's test
// against the errors of an independent implementation run outside the project
// (tests/data/rivals/boris_variants.py, its output boris_variants.out), the variants' orders at
// a fixed ratio h/eps, the filtered variants' exactness in constant fields against the closed-form
// solution, the classical Boris's gyration angle for h >> eps, and the planar cpd.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "harness.hpp"
#include "tsi/convergence.hpp"
#include "tsi/error.hpp"

namespace {

using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

// The position error |x^N - x(T)| of `scheme` on the HLW test at eps, h = r eps, N = round(1/h),
// T = N h (as boris_variants.py), against rk78 (tol 1e-14) on the filtered problem.
double position_error(const Json& scheme, double eps, double r, const std::string& model_name = "charged-particle-3d") {
  auto& harness = Harness::instance();
  auto model = harness.model(model_name, eps);
  auto direct = harness.reformulation("direct", model);
  const double h = r * eps;
  const long n = std::lround(1.0 / h);
  const double t_end = static_cast<double>(n) * h;
  const Vector x = tsi::test::solve(*model, *direct, *harness.scheme("boris", scheme), t_end, n);
  const Vector& reference = tsi::test::reference_solution(model_name, eps, t_end);
  return (x - reference).head(x.size() / 2).norm();
}

// boris_variants.out's table 1: errors by (eps exponent, r) and column name.
std::map<std::pair<int, int>, std::map<std::string, double>> independent_errors() {
  std::ifstream in(std::string(TSI_TEST_SOURCE_DIR) + "/tests/data/rivals/boris_variants.out");
  REQUIRE(in);
  std::map<std::pair<int, int>, std::map<std::string, double>> table;
  std::string line;
  bool inside = false;
  std::vector<std::string> columns;
  while (std::getline(in, line)) {
    if (line.rfind("## Table 1", 0) == 0) inside = true;
    else if (line.rfind("## Table 2", 0) == 0) break;
    if (!inside || line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<std::string> cells;
    for (std::string cell; std::getline(fields, cell, '\t');) cells.push_back(cell);
    if (cells[0] == "eps") {
      columns = cells;
      continue;
    }
    const int j = -std::stoi(cells[0].substr(2));  // "2^-10": 10
    for (size_t c = 4; c < cells.size(); ++c) table[{j, std::stoi(cells[1])}][columns[c]] = std::stod(cells[c]);
  }
  return table;
}

const Json classical = {{"variant", "classical"}};
const Json implicit_one = {{"variant", "filtered"}};
const Json implicit_converged = {{"variant", "filtered"}, {"iterations", 20}};
const Json explicit_point = {{"variant", "filtered"}, {"explicit", true}};
const Json large_step = {{"variant", "large-step"}};

}  // namespace

TEST_CASE("boris on charged-particle-3d: Hairer-Lubich-Wang's test gives the independent implementation's errors") {
  const auto table = independent_errors();
  REQUIRE(table.size() == 20);
  // Printed to three digits: they agree to half a unit of the third (up to 5e-3 relative), with
  // 1e-4 relative for the references (each 3e-12 from the exact x(T)).
  const std::vector<std::pair<std::string, Json>> variants = {{"classical", classical},
                                                              {"exp-A", explicit_point},
                                                              {"imp-A", implicit_converged},
                                                              {"imp-A1", implicit_one},
                                                              {"large-step*", large_step}};
  for (const int j : {10, 11})
    for (const int r : {2, 4, 8, 14})
      for (const auto& variant : variants) {
        const std::string& column = variant.first;
        const Json& scheme = variant.second;
        const double expected = table.at({j, r}).at(column);
        const double error = position_error(scheme, std::ldexp(1.0, -j), r);
        CAPTURE(column);
        CAPTURE(j);
        CAPTURE(r);
        const double unit = std::pow(10.0, std::floor(std::log10(expected)) - 2);
        CHECK(std::abs(error - expected) <= 0.5 * unit + 1e-4 * expected);
      }
}

TEST_CASE("boris on charged-particle-3d: second order in position at a fixed h/eps for the filtered Boris, first "
          "for its explicit point, none for the classical one") {
  // HLW's Theorem 3.1: at a fixed ratio the position error is O(eps^2) = O(h^2) for Imp-A and O(eps)
  // for Exp-A, so halving eps and h together divides it by 4 and by 2.
  for (const int r : {2, 4, 8, 14}) {
    std::vector<double> filtered, exp_a, plain;
    for (const int j : {10, 11, 12}) {
      const double eps = std::ldexp(1.0, -j);
      filtered.push_back(position_error(implicit_one, eps, r));
      exp_a.push_back(position_error(explicit_point, eps, r));
      plain.push_back(position_error(classical, eps, r));
    }
    for (size_t k = 0; k + 1 < filtered.size(); ++k) {
      const double f = filtered[k] / filtered[k + 1], e = exp_a[k] / exp_a[k + 1];
      MESSAGE(fmt::format("h/eps = {}: filtered {:.2e} / {:.2e} = {:.2f}, explicit {:.2f}, classical {:.2e} / {:.2e}",
                          r, filtered[k], filtered[k + 1], f, e, plain[k], plain[k + 1]));
      CHECK(f > 3.6);
      CHECK(f < 4.4);
      CHECK(e > 1.9);
      CHECK(e < 2.1);
      // The classical Boris's errors are 10 to 1000 times the filtered one's at every ratio.
      CHECK(plain[k] > 10 * filtered[k]);
    }
  }
}

TEST_CASE("boris: the classical variant is second order where h |B| is small") {
  // eps = 1/4: h |B| = 4 h from 0.02 to 0.005.
  std::vector<double> hs, errors;
  for (const long n : {200, 400, 800}) {
    hs.push_back(1.0 / static_cast<double>(n));
    errors.push_back(position_error(classical, 0.25, 4.0 / static_cast<double>(n)));
  }
  const tsi::OrderFit fit = tsi::fit_order(hs, errors, 1e-12);
  REQUIRE(fit.measurable);
  MESSAGE(fmt::format("classical at eps = 1/4: {:.2e}, {:.2e}, {:.2e}, order {:.2f}", errors[0], errors[1], errors[2],
                      fit.order));
  CHECK(fit.order > 1.95);
  CHECK(fit.order < 2.05);
}

// x' = v, v' = v x B + E with B and E constant: v_par grows by E_par t, the drift
// v_D = E x B / |B|^2, and the rest turns by -|B| t about B (closed form, no integrator).
Vector constant_field_solution(const tsi::RealVector3& B, const tsi::RealVector3& E, const tsi::RealVector3& x0,
                               const tsi::RealVector3& v0, double t) {
  const double b = B.norm();
  const tsi::RealVector3 u = B / b, drift = E.cross(B) / (b * b);
  const double e_par = u.dot(E), v_par = u.dot(v0);
  const tsi::RealVector3 w = v0 - v_par * u - drift;  // normal to B
  const tsi::RealVector3 uw = u.cross(w);
  const tsi::RealVector3 v = (v_par + e_par * t) * u + drift + std::cos(b * t) * w - std::sin(b * t) * uw;
  const tsi::RealVector3 x = x0 + (v_par * t + e_par * t * t / 2) * u + drift * t + std::sin(b * t) / b * w -
                             (1 - std::cos(b * t)) / b * uw;
  Vector out(6);
  for (int i = 0; i < 3; ++i) {
    out(i) = x(i);
    out(3 + i) = v(i);
  }
  return out;
}

TEST_CASE("boris: the filtered variants are exact in constant fields, the classical one turns the gyration by "
          "2 atan(h |B| / 2) a step") {
  auto& harness = Harness::instance();
  const double eps = 1.0 / 1024;
  const Json fields = {{"fields", "constant"}, {"b1", {0.3, -0.2, 0.0}}, {"e", {0.5, -0.4, 0.7}}};
  auto model = harness.model_with("charged-particle-3d", eps, fields);
  auto direct = harness.reformulation("direct", model);
  const tsi::RealVector3 B(0.3, -0.2, 1 / eps), E(0.5, -0.4, 0.7);
  const tsi::RealVector3 x0(1.0 / 3, 1.0 / 4, 1.0 / 2), v0(2.0 / 5, 2.0 / 3, 1.0);
  for (const double r : {3.3, 7.0}) {
    const long n = std::lround(1.0 / (r * eps));
    const double t_end = static_cast<double>(n) * r * eps;
    const Vector exact = constant_field_solution(B, E, x0, v0, t_end);
    for (const Json& scheme : {implicit_one, explicit_point}) {
      const Vector x = tsi::test::solve(*model, *direct, *harness.scheme("boris", scheme), t_end, n);
      const double dx = (x - exact).head(3).norm(), dv = (x - exact).tail(3).norm();
      MESSAGE(fmt::format("{} at h/eps = {}: |dx| = {:.1e}, |dv| = {:.1e}", scheme.dump(), r, dx, dv));
      // To rounding: about 1e-16 of |x| ~ 1 a step, added over n = 303 and 141 steps.
      CHECK(dx < 1e-15 * static_cast<double>(n));
      CHECK(dv < 1e-15 * static_cast<double>(n));
    }
  }
  // E = 0 and B = e_3 / eps: the classical Boris's v^{n+1/2} turns by theta = 2 atan(h |B| / 2) a
  // step (the Cayley transform of h B), not by h |B|. From the start v^{1/2} = v^0 + h/2 v^0 x B,
  // v^n = (v^{n-1/2} + v^{n+1/2}) / 2 is v^0 turned by -n theta with its length; the positions
  // go round a circle of radius (1 + (h |B| / 2)^2) |v_perp| / |B|, not the gyroradius
  // |v_perp| / |B|: at h = 8 eps the phase is off by n (8 - 2 atan 4) and the radius is 17 times.
  auto planar = harness.model_with("charged-particle-3d", eps, {{"fields", "constant"}});
  auto planar_direct = harness.reformulation("direct", planar);
  const long n = 100;
  const double h = 8 * eps, b = 1 / eps;
  const auto boris = harness.scheme("boris", classical);
  std::vector<tsi::RealVector3> positions;
  tsi::RealVector3 v = tsi::RealVector3::Zero();
  for (const long k : {n, n + 1, n + 2}) {
    const Vector x = tsi::test::solve(*planar, *planar_direct, *boris, static_cast<double>(k) * h, k);
    positions.emplace_back(x(0).real(), x(1).real(), 0.0);  // in the plane normal to B (x_3 moves with v_3)
    if (k == n) v << x(3).real(), x(4).real(), x(5).real();
  }
  const double theta = 2 * std::atan(h * b / 2);
  const double start = std::atan2(v0(1), v0(0)), observed = std::atan2(v(1), v(0));
  CHECK(std::abs(std::remainder(observed - (start - static_cast<double>(n) * theta), 2 * M_PI)) < 1e-10);
  CHECK(std::abs(std::remainder(observed - (start - static_cast<double>(n) * h * b), 2 * M_PI)) > 0.1);
  CHECK(std::abs(std::hypot(v(0), v(1)) - std::hypot(v0(0), v0(1))) < 1e-12);
  // The circumradius of three successive positions.
  const double p = (positions[1] - positions[0]).norm(), q = (positions[2] - positions[1]).norm(),
               s = (positions[2] - positions[0]).norm();
  const double area = (positions[1] - positions[0]).cross(positions[2] - positions[0]).norm() / 2;
  const double radius = p * q * s / (4 * area), gyroradius = std::hypot(v0(0), v0(1)) / b;
  MESSAGE(fmt::format("classical at h = 8 eps: radius {:.4e} = {:.3f} gyroradii", radius, radius / gyroradius));
  CHECK(std::abs(radius / gyroradius - (1 + (h * b / 2) * (h * b / 2))) < 1e-8);
}

TEST_CASE("boris on cpd: in the planar particle's uniform field the filtered Boris is at least second order at a "
          "fixed h/eps, the classical one 1000 times less accurate") {
  // B = e_3 / eps is uniform, so Bbar = B and the explicit point gives the same steps. The errors
  // fall 8 to 9 times per halving from eps = 2^-9 on (eps^3): the particle moves O(eps) over T = 1
  // (its drift eps E x B), and the second-order error carries that factor. The classical Boris
  // keeps the O(h) gyroradius of its start.
  for (const int r : {2, 4, 8}) {
    std::vector<double> filtered, exp_a, plain;
    for (const int j : {8, 9, 10}) {
      const double eps = std::ldexp(1.0, -j);
      filtered.push_back(position_error(implicit_one, eps, r, "cpd"));
      exp_a.push_back(position_error(explicit_point, eps, r, "cpd"));
      plain.push_back(position_error(classical, eps, r, "cpd"));
    }
    for (size_t k = 0; k + 1 < filtered.size(); ++k) {
      MESSAGE(fmt::format("cpd h/eps = {}: filtered {:.2e} -> {:.2e} ({:.2f}), classical {:.2e} -> {:.2e}", r,
                          filtered[k], filtered[k + 1], filtered[k] / filtered[k + 1], plain[k], plain[k + 1]));
      CHECK(filtered[k] / filtered[k + 1] > 3.6);
      CHECK(exp_a[k] == filtered[k]);
      CHECK(plain[k] > 1000 * filtered[k]);
    }
  }
}
