// The core's assembler: every default completed by the entry that owns it, from the whole
// selection, and declared capabilities refused before anything runs.
#include <doctest/doctest.h>

#include <cmath>

#include "harness.hpp"
#include "tsi/assembly.hpp"
#include "tsi/error.hpp"

namespace {

using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

Json selection(const std::string& model, const std::string& scheme, double eps = 1.0) {
  return {{"model", {{"name", model}, {"eps", eps}}}, {"scheme", {{"name", scheme}}}};
}

// u(T) in physical variables for SE2 with the given quadrature nodes (null: the completed default).
Vector se2_solution(const Json& nodes, long steps) {
  Json config = selection("cpd", "se2");
  config["scheme"]["tol"] = 1e-14;
  if (!nodes.is_null()) config["scheme"]["quadrature_nodes"] = nodes;
  auto a = Harness::instance().assemble(config);
  Vector y = a.reformulation->prepare(a.u0);
  const double h = 1.0 / static_cast<double>(steps);
  tsi::integrate(a.bind(h), y, steps, {}, a.reformulation->repreparation());
  return a.model->to_physical(a.reformulation->read_back(y, tsi::step_time(steps, h)));
}

}  // namespace

TEST_CASE("assembly: each entry completes its defaults from the selection") {
  const auto& registry = Harness::instance().registry();
  // SE2's nodes follow the model's nonlinearity: polynomial of degree 3 -> 2, non-polynomial -> 6.
  CHECK(tsi::resolve_selection(selection("henon-heiles", "se2"), registry).scheme.params["quadrature_nodes"] == 2);
  CHECK(tsi::resolve_selection(selection("nls", "se2"), registry).scheme.params["quadrature_nodes"] == 2);
  CHECK(tsi::resolve_selection(selection("cpd", "se2"), registry).scheme.params["quadrature_nodes"] == 6);
  Json given = selection("cpd", "se2");
  given["scheme"]["quadrature_nodes"] = 3;
  CHECK(tsi::resolve_selection(given, registry).scheme.params["quadrature_nodes"] == 3);
  // The two-scale reformulation: n_tau from the model, data order from the scheme.
  const tsi::ResolvedSelection fd = tsi::resolve_selection(selection("nls", "fd"), registry);
  CHECK(fd.reformulation.name == "two-scale");
  CHECK(fd.reformulation.params["n_tau"] == registry.model("nls").default_n_tau);
  CHECK(fd.reformulation.params["initial_data_order"] == 3);
  // The sections as a config writes them (result.json's config).
  CHECK(fd.sections()["reformulation"]["name"] == "two-scale");
  CHECK(fd.sections()["scheme"]["name"] == "fd");
  CHECK(tsi::resolve_selection(selection("nls", "se1"), registry).reformulation.params["initial_data_order"] == 2);
  // On a model with a linear remainder FD takes data of order 4 (its traits' remainder_data_order).
  CHECK(registry.model("klein-gordon").linear_remainder);
  CHECK_FALSE(registry.model("nls").linear_remainder);
  CHECK(tsi::resolve_selection(selection("klein-gordon", "fd"), registry).reformulation.params["initial_data_order"] == 4);
  CHECK(tsi::resolve_selection(selection("klein-gordon", "se1"), registry).reformulation.params["initial_data_order"] == 2);
  // Aliases resolve to canonical names.
  CHECK(tsi::resolve_selection(selection("henon-heiles", "se1-tsi"), registry).scheme.name == "se1");
}

TEST_CASE("assembly: the charged particle's SE2 runs with the nodes its force needs") {
  // The 6-node default agrees with a 12-node rule to the fixed-point tolerance's level, while
  // the 2 nodes a model-blind default gave are off by far more.
  const Vector six = se2_solution(Json(), 8), twelve = se2_solution(12, 8), two = se2_solution(2, 8);
  const double six_off = (six - twelve).norm() / twelve.norm(), two_off = (two - twelve).norm() / twelve.norm();
  CAPTURE(six_off);
  CAPTURE(two_off);
  CHECK(six_off < 1e-9);
  CHECK(two_off > 100 * six_off);
}

TEST_CASE("assembly: declared needs are refused before anything is built, naming both sides") {
  auto& h = Harness::instance();
  Json config = selection("henon-heiles", "se1");
  config["reformulation"] = {{"name", "direct"}};
  CHECK_THROWS_WITH_AS(h.assemble(config), doctest::Contains("reformulation.name"), tsi::ConfigError);
  Json unknown = selection("henon-heiles", "se1");
  unknown["scheme"]["quadrature_nodes"] = 2;  // an SE2 parameter
  CHECK_THROWS_WITH_AS(h.assemble(unknown), doctest::Contains("scheme.quadrature_nodes"), tsi::ConfigError);
  CHECK_THROWS_WITH_AS(h.assemble(Json{{"scheme", {{"name", "se1"}}}}), doctest::Contains("model.name"),
                       tsi::ConfigError);
}
