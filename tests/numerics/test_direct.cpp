// The direct problem in the model's own or in physical variables (reformulation.variables):
// the same solution either way, and a classical solver that reaches small errors on the
// charged particle only in physical variables, where v is not 1/eps times a rounding of p.
#include <doctest/doctest.h>

#include <cmath>

#include "../fixtures/fixture_model.hpp"
#include "harness.hpp"
#include "tsi/error.hpp"

namespace {

using tsi::Vector;
using tsi::test::Harness;

double relative(const Vector& x, const Vector& ref) { return (x - ref).norm() / ref.norm(); }

Vector rk78_direct(const std::string& model_name, double eps, const std::string& variables, double tol) {
  auto& h = Harness::instance();
  auto model = h.model(model_name, eps);
  auto direct = h.reformulation("direct", model, {{"variables", variables}});
  auto rk78 = h.scheme("rk78", {{"tol", tol}});
  return tsi::test::solve(*model, *direct, *rk78, 1.0, 1);
}

// x = u + 1: affine, so T F(T^{-1} x) is not the field in x.
class ShiftedPhysical final : public tsi::fixture::HarmonicModel, public tsi::PhysicalVariables {
 public:
  using HarmonicModel::HarmonicModel;
  const tsi::PhysicalVariables* physical_variables() const override { return this; }
  tsi::Index physical_dim() const override { return 2; }
  Vector to_physical(const Vector& u) const override { return u.array() + 1.0; }
  Vector from_physical(const Vector& x) const override { return x.array() - 1.0; }
};

}  // namespace

TEST_CASE("direct: physical variables give the model-variable solution (Henon-Heiles, NLS, cpd)") {
  for (const char* name : {"henon-heiles", "nls", "cpd"}) {
    CAPTURE(name);
    const Vector in_model = rk78_direct(name, 0.5, "model", 1e-12);
    const Vector in_physical = rk78_direct(name, 0.5, "physical", 1e-12);
    CHECK(relative(in_physical, in_model) < 1e-10);
    CHECK(relative(in_physical, tsi::test::reference_solution(name, 0.5, 1.0)) < 1e-10);
  }
}

TEST_CASE("direct: on the charged particle at eps = 1e-4 only physical variables let rk78 meet its tolerance") {
  // A tolerance on p = 2 eps v - B x is a tolerance 1/(2 eps) larger on v.
  const Vector& ref = tsi::test::reference_solution("cpd", 1e-4, 1.0);
  const double in_model = relative(rk78_direct("cpd", 1e-4, "model", 1e-10), ref);
  const double in_physical = relative(rk78_direct("cpd", 1e-4, "physical", 1e-10), ref);
  CAPTURE(in_model);
  CAPTURE(in_physical);
  CHECK(in_physical < 1e-6);
  CHECK(in_model > 100.0 * in_physical);
}

TEST_CASE("direct: physical variables are refused for a model whose to_physical is not linear") {
  const auto& entry = Harness::instance().registry().reformulation("direct");
  auto model = std::make_shared<ShiftedPhysical>(0.1);
  const tsi::Params params(tsi::resolve_params(entry.info.params, {{"variables", "physical"}}, "reformulation"));
  try {
    entry.create(model, params);
    FAIL("expected a ConfigError");
  } catch (const tsi::ConfigError& e) {
    const std::string what = e.what();
    CAPTURE(what);
    CHECK(what.find("reformulation.variables") != std::string::npos);
    CHECK(what.find("non-linearly") != std::string::npos);
  }
  // The same model in its own variables is fine.
  const tsi::Params own(tsi::resolve_params(entry.info.params, tsi::Json::object(), "reformulation"));
  CHECK_NOTHROW(entry.create(model, own));
}
