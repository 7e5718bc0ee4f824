#include "tsi/params.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tsi/error.hpp"

namespace tsi {

namespace {

/// "path.key", or just "key" at the top level.
std::string join_path(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

/// A JSON float with an integral value that fits a long.
bool integral_float(const Json& v) {
  if (!v.is_number_float()) return false;
  const double x = v.get<double>();
  return std::floor(x) == x && std::fabs(x) < std::ldexp(1.0, 63);
}

bool has_type(ParamType type, const Json& v) {
  switch (type) {
    case ParamType::Number:
      return v.is_number();
    case ParamType::Integer:
      return v.is_number_integer() || integral_float(v);
    case ParamType::Boolean:
      return v.is_boolean();
    case ParamType::String:
      return v.is_string();
    case ParamType::Array:
      return v.is_array();
    case ParamType::IntegerOrString:
      return v.is_string() || v.is_number_integer() || integral_float(v);
  }
  return false;
}

ParamSpec make_spec(std::string name, ParamType type, Json default_value, std::string description) {
  ParamSpec spec;
  spec.name = std::move(name);
  spec.type = type;
  spec.default_value = std::move(default_value);
  spec.description = std::move(description);
  return spec;
}

}  // namespace

std::string describe(ParamType type) {
  switch (type) {
    case ParamType::Number:
      return "a number";
    case ParamType::Integer:
      return "an integer";
    case ParamType::Boolean:
      return "a boolean";
    case ParamType::String:
      return "a string";
    case ParamType::Array:
      return "an array";
    case ParamType::IntegerOrString:
      return "an integer or a string";
  }
  return "a value";
}

ParamSpec& ParamSpec::range(double lo, double hi, bool lo_open, bool hi_open) {
  // An infinite end is always shown open: "[1, inf)".
  expected = fmt::format("{} in {}{}, {}{}", describe(type), lo_open || std::isinf(lo) ? "(" : "[",
                         lo, hi, hi_open || std::isinf(hi) ? ")" : "]");
  valid = [lo, hi, lo_open, hi_open](const Json& v) {
    if (!v.is_number()) return false;
    const double x = v.get<double>();
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  };
  return *this;
}

ParamSpec& ParamSpec::check(std::function<bool(const Json&)> predicate, std::string words) {
  if (valid) {
    valid = [first = std::move(valid), second = std::move(predicate)](const Json& v) {
      return first(v) && second(v);
    };
  } else {
    valid = std::move(predicate);
  }
  expected = std::move(words);
  return *this;
}

ParamSpec& ParamSpec::choices(std::vector<std::string> names) {
  expected = "one of: " + join(names);
  valid = [names = std::move(names)](const Json& v) {
    return v.is_string() &&
           std::find(names.begin(), names.end(), v.get<std::string>()) != names.end();
  };
  return *this;
}

ParamSpec number_param(std::string name, Json default_value, std::string description) {
  return make_spec(std::move(name), ParamType::Number, std::move(default_value),
                   std::move(description));
}

ParamSpec integer_param(std::string name, Json default_value, std::string description) {
  return make_spec(std::move(name), ParamType::Integer, std::move(default_value),
                   std::move(description));
}

ParamSpec bool_param(std::string name, Json default_value, std::string description) {
  return make_spec(std::move(name), ParamType::Boolean, std::move(default_value),
                   std::move(description));
}

ParamSpec string_param(std::string name, Json default_value, std::string description) {
  return make_spec(std::move(name), ParamType::String, std::move(default_value),
                   std::move(description));
}

ParamSpec array_param(std::string name, std::string description) {
  return make_spec(std::move(name), ParamType::Array, Json(), std::move(description));
}

ParamSpec integer_or_string_param(std::string name, Json default_value, std::string description) {
  return make_spec(std::move(name), ParamType::IntegerOrString, std::move(default_value), std::move(description));
}

Json resolve_params(const ParamSchema& schema, const Json& given, const std::string& path) {
  if (!given.is_object()) throw ConfigError(path, "expected an object, got " + given.dump());
  const auto find = [&schema](const std::string& key) {
    return std::find_if(schema.begin(), schema.end(),
                        [&key](const ParamSpec& s) { return s.name == key; });
  };
  Json out = Json::object();
  for (const auto& [key, value] : given.items()) {
    const auto spec = find(key);
    if (spec == schema.end()) {
      std::vector<std::string> names;
      for (const auto& s : schema) names.push_back(s.name);
      std::sort(names.begin(), names.end());
      throw ConfigError(join_path(path, key),
                        names.empty() ? "unknown parameter; this section takes no parameters"
                                      : "unknown parameter; valid parameters are: " + join(names));
    }
    if (value.is_null()) continue;  // explicit null: the default applies
    const std::string wanted = spec->expected.empty() ? describe(spec->type) : spec->expected;
    const std::string field = join_path(path, key), got = value.dump();  // (clang 14 cannot capture bindings)
    const auto reject = [&] { return ConfigError(field, "got " + got + ", expected " + wanted); };
    if (!has_type(spec->type, value)) throw reject();
    Json v = (spec->type == ParamType::Integer && value.is_number_float())
                 ? Json(static_cast<long>(value.get<double>()))
                 : value;
    if (spec->valid && !spec->valid(v)) throw reject();
    out[key] = std::move(v);
  }
  for (const auto& spec : schema) {
    if (!out.contains(spec.name)) out[spec.name] = spec.default_value;
  }
  return out;
}

const Json& Params::at(const std::string& name) const {
  if (!has(name)) throw Error("parameter \"" + name + "\" is not set");
  return values_.at(name);
}

double Params::number(const std::string& name) const {
  const Json& v = at(name);
  if (!v.is_number()) throw Error("parameter \"" + name + "\" is not a number: " + v.dump());
  return v.get<double>();
}

long Params::integer(const std::string& name) const {
  const Json& v = at(name);
  if (v.is_number_integer()) return v.get<long>();
  if (integral_float(v)) return static_cast<long>(v.get<double>());
  throw Error("parameter \"" + name + "\" is not an integer: " + v.dump());
}

bool Params::boolean(const std::string& name) const {
  const Json& v = at(name);
  if (!v.is_boolean()) throw Error("parameter \"" + name + "\" is not a boolean: " + v.dump());
  return v.get<bool>();
}

std::string Params::string(const std::string& name) const {
  const Json& v = at(name);
  if (!v.is_string()) throw Error("parameter \"" + name + "\" is not a string: " + v.dump());
  return v.get<std::string>();
}

bool Params::has(const std::string& name) const {
  return values_.is_object() && values_.contains(name) && !values_.at(name).is_null();
}

}  // namespace tsi
