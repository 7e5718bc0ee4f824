#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tsi/context.hpp"
#include "tsi/export.hpp"

namespace tsi {

using Json = nlohmann::json;

enum class ParamType { Number, Integer, Boolean, String, Array, IntegerOrString };

/// Name of a parameter type as users read it ("a number", "an integer", ...).
TSI_API std::string describe(ParamType type);

/// One documented parameter of a registered object: name, type, default, meaning, and
/// the values it accepts.
struct TSI_API ParamSpec {
  std::string name;
  ParamType type = ParamType::Number;
  Json default_value;  ///< null: optional with no default (the object decides)
  std::string description;
  std::string expected;                    ///< the valid values in words, e.g. "a number in (0, 1]"
  std::function<bool(const Json&)> valid;  ///< empty: every value of the type is valid

  /// Restrict a number to an interval; open ends excluded.
  ParamSpec& range(double lo, double hi, bool lo_open = false, bool hi_open = false);
  /// Restrict to an explicit check described by `words`.
  ParamSpec& check(std::function<bool(const Json&)> predicate, std::string words);
  /// Restrict a string to a list of choices.
  ParamSpec& choices(std::vector<std::string> names);
};

using ParamSchema = std::vector<ParamSpec>;

TSI_API ParamSpec number_param(std::string name, Json default_value, std::string description);
TSI_API ParamSpec integer_param(std::string name, Json default_value, std::string description);
TSI_API ParamSpec bool_param(std::string name, Json default_value, std::string description);
TSI_API ParamSpec string_param(std::string name, Json default_value, std::string description);
TSI_API ParamSpec array_param(std::string name, std::string description);
/// A parameter that is a keyword or a count ("never", "auto" or every K steps).
TSI_API ParamSpec integer_or_string_param(std::string name, Json default_value, std::string description);

/// Checks `given` (a JSON object) against `schema`: rejects unknown keys (listing the valid
/// ones), wrong types and out-of-range values with a ConfigError naming `path.key`, and
/// returns the object with every default filled in.
TSI_API Json resolve_params(const ParamSchema& schema, const Json& given, const std::string& path);

/// Typed read access to a resolved parameter object, and the run's context (what it may use
/// of the process: threads), which tsi::assemble gives every entry it creates.
class TSI_API Params {
 public:
  explicit Params(Json values = Json::object(), Context context = {})
      : values_(std::move(values)), context_(context) {}
  double number(const std::string& name) const;
  long integer(const std::string& name) const;
  bool boolean(const std::string& name) const;
  std::string string(const std::string& name) const;
  bool has(const std::string& name) const;  ///< present and not null
  const Json& raw() const { return values_; }
  const Context& context() const { return context_; }

 private:
  const Json& at(const std::string& name) const;
  Json values_;
  Context context_;
};

}  // namespace tsi
