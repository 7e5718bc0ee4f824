#include <doctest/doctest.h>

#include <limits>

#include "tsi/error.hpp"
#include "tsi/params.hpp"

using tsi::Json;

namespace {

tsi::ParamSchema schema() {
  return {
      tsi::number_param("eps", 0.01, "small parameter").range(0.0, 1.0, true, false),
      tsi::integer_param("n", 64, "resolution").range(4, std::numeric_limits<double>::infinity()),
      tsi::bool_param("verbose", false, "chatty"),
      tsi::string_param("mode", "fast", "how").choices({"fast", "slow"}),
      tsi::array_param("u0", "initial value")};
}

/// The message of the ConfigError that resolving `given` throws.
std::string error_of(const Json& given) {
  try {
    tsi::resolve_params(schema(), given, "model");
  } catch (const tsi::ConfigError& e) {
    return e.what();
  }
  FAIL("no ConfigError for " << given.dump());
  return "";
}

}  // namespace

TEST_CASE("params: defaults are filled in, null defaults stay null") {
  const Json out = tsi::resolve_params(schema(), Json::object(), "model");
  CHECK(out["eps"] == 0.01);
  CHECK(out["n"] == 64);
  CHECK(out["verbose"] == false);
  CHECK(out["mode"] == "fast");
  CHECK(out["u0"].is_null());
  const tsi::Params p(out);
  CHECK(p.number("eps") == doctest::Approx(0.01));
  CHECK(p.integer("n") == 64);
  CHECK_FALSE(p.boolean("verbose"));
  CHECK(p.string("mode") == "fast");
  CHECK_FALSE(p.has("u0"));
}

TEST_CASE("params: given values are kept") {
  const Json out = tsi::resolve_params(
      schema(), Json{{"eps", 1}, {"mode", "slow"}, {"u0", {1.0, 2.0}}, {"verbose", true}}, "model");
  CHECK(out["eps"] == 1);
  CHECK(out["mode"] == "slow");
  CHECK(out["u0"].size() == 2);
  CHECK(tsi::Params(out).boolean("verbose"));
}

TEST_CASE("params: an unknown key is rejected with the sorted list of valid keys") {
  const std::string msg = error_of(Json{{"epsilon", 0.1}});
  CHECK(msg == "model.epsilon: unknown parameter; valid parameters are: eps, mode, n, u0, verbose");
  try {
    tsi::resolve_params(schema(), Json{{"epsilon", 0.1}}, "model");
  } catch (const tsi::ConfigError& e) {
    CHECK(e.field() == "model.epsilon");
  }
}

TEST_CASE("params: wrong types name the field, the value and what was expected") {
  CHECK(error_of(Json{{"eps", "small"}}) ==
        "model.eps: got \"small\", expected a number in (0, 1]");
  CHECK(error_of(Json{{"verbose", 1}}) == "model.verbose: got 1, expected a boolean");
  CHECK(error_of(Json{{"u0", 1.0}}) == "model.u0: got 1.0, expected an array");
  CHECK(error_of(Json{{"n", 4.5}}) == "model.n: got 4.5, expected an integer in [4, inf)");
  CHECK(error_of(Json{{"mode", 3}}) == "model.mode: got 3, expected one of: fast, slow");
}

TEST_CASE("params: out-of-range values are rejected") {
  CHECK(error_of(Json{{"eps", 2}}) == "model.eps: got 2, expected a number in (0, 1]");
  CHECK(error_of(Json{{"eps", 0.0}}) == "model.eps: got 0.0, expected a number in (0, 1]");
  CHECK(error_of(Json{{"n", 2}}) == "model.n: got 2, expected an integer in [4, inf)");
  CHECK(error_of(Json{{"mode", "medium"}}) ==
        "model.mode: got \"medium\", expected one of: fast, slow");
}

TEST_CASE("params: an integer-valued float is accepted as an integer") {
  const Json out = tsi::resolve_params(schema(), Json{{"n", 128.0}}, "model");
  CHECK(out["n"].is_number_integer());
  CHECK(tsi::Params(out).integer("n") == 128);
}

TEST_CASE("params: the section itself must be an object") {
  CHECK(error_of(Json::array({1, 2})) == "model: expected an object, got [1,2]");
}

TEST_CASE("params: check() and describe()") {
  tsi::ParamSchema s{
      tsi::number_param("x", 1.0, "")
          .check([](const Json& v) { return v.get<double>() != 0.0; }, "a nonzero number")};
  CHECK_THROWS_WITH_AS(tsi::resolve_params(s, Json{{"x", 0}}, "a.b"),
                       "a.b.x: got 0, expected a nonzero number", tsi::ConfigError);
  CHECK(tsi::resolve_params(s, Json{{"x", -2}}, "a.b")["x"] == -2);
  CHECK(tsi::describe(tsi::ParamType::Integer) == "an integer");
}

TEST_CASE("params: getters name the parameter that is missing or mistyped") {
  const tsi::Params p(Json{{"a", "text"}, {"b", nullptr}});
  CHECK_THROWS_WITH_AS(p.number("a"), doctest::Contains("\"a\""), tsi::Error);
  CHECK_THROWS_WITH_AS(p.integer("b"), doctest::Contains("\"b\""), tsi::Error);
  CHECK_THROWS_WITH_AS(p.string("c"), doctest::Contains("\"c\""), tsi::Error);
  CHECK_THROWS_AS(p.boolean("a"), tsi::Error);
  CHECK(p.string("a") == "text");
}
