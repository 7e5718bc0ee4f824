#include "config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tsi/assembly.hpp"
#include "tsi/error.hpp"

namespace tsi::app {
namespace {

const std::vector<std::string> sections = {"model",  "reformulation", "scheme",  "time",
                                           "reference", "output", "monitor", "plugins"};

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

const Json& section_object(const Json& raw, const std::string& key, const Json& fallback) {
  if (!raw.contains(key)) return fallback;
  const Json& s = raw.at(key);
  if (!s.is_object()) throw ConfigError(key, "got " + s.dump() + ", expected an object");
  return s;
}

const ParamSchema& time_schema() {
  static const ParamSchema schema = {
      number_param("h", 0.125, "time step").range(0.0, std::numeric_limits<double>::infinity(), true),
      number_param("t_end", 1.0, "final time").range(0.0, std::numeric_limits<double>::infinity())};
  return schema;
}

const ParamSchema& reference_schema() {
  static const ParamSchema schema = {
      string_param("scheme", "rk78",
                   "the reference solver, or \"exact\": the model's exact solution where it declares one (the "
                   "matrix model with an affine field such as \"linear\"; the other keys are then unused)"),
      string_param("reformulation", "filtered", "the problem the reference solver integrates"),
      number_param("tol", 1e-13, "the reference solver's tolerance").range(smallest_tolerance, 1e-1),
      number_param("h", nullptr, "step of a non-adaptive reference solver; default: t_end")
          .range(0.0, std::numeric_limits<double>::infinity(), true),
      integer_param("n_tau", nullptr,
                    "tau modes of a two-scale reference (even); default: the model's (NLS in 2-D needs 4 max |m|^2)")
          .check([](const Json& v) { return v.get<long>() >= 2 && v.get<long>() <= (1L << 24) && v.get<long>() % 2 == 0; },
                 "an even integer in [2, 16777216]"),
      bool_param("estimate_accuracy", true,
                 "estimate the reference's own error by a second run at tol / 10 and twice the "
                 "substeps per fast period (at least what rounding its state in model variables "
                 "causes)")};
  return schema;
}

// The reference section, resolved: a scheme on a reformulation that it can integrate, with its
// step where it is not adaptive; or "exact" alone (whether the model has one, run.cpp checks).
Json resolve_reference(const Json& raw, double t_end, const Registry& registry) {
  const Json empty = Json::object();
  Json ref = resolve_params(reference_schema(), section_object(raw, "reference", empty), "reference");
  if (ref["scheme"] == exact_reference) return Json{{"scheme", exact_reference}};
  const SchemeEntry& ref_scheme = registry.scheme(ref["scheme"], "reference.scheme");
  const ReformulationEntry& ref_reform = registry.reformulation(ref["reformulation"], "reference.reformulation");
  try {
    registry.check_compatible(ref_scheme, ref_reform);
  } catch (const ConfigError& e) {
    throw ConfigError("reference.reformulation", e.what());
  }
  ref["scheme"] = ref_scheme.info.name;
  ref["reformulation"] = ref_reform.info.name;
  if (!ref["n_tau"].is_null() && ref_reform.info.name != "two-scale")
    throw ConfigError("reference.n_tau", "is given, but the reference integrates the " + ref_reform.info.name +
                                             " problem (n_tau is the two-scale reformulation's)");
  if (!ref_scheme.traits.adaptive && ref["h"].is_null())
    throw ConfigError("reference.h", "the reference scheme \"" + ref_scheme.info.name +
                                         "\" is not adaptive: give its step h");
  if (ref["h"].is_number()) {  // a reference step that does not divide t_end would run another step
    const double h = ref["h"];
    const double steps = t_end / h;
    if (t_end > 0.0 && (!(h <= t_end) || std::abs(steps - std::round(steps)) > 1e-9 * std::max(1.0, steps)))
      throw ConfigError("reference.h", fmt::format("got {}, expected t_end / n for a whole number n of steps "
                                                   "(t_end = {}: {:.6g} steps)",
                                                   h, t_end, steps));
    if (steps > 1e12)
      throw ConfigError("reference.h",
                        fmt::format("t_end / h = {:.3g} steps is too many: at most 1e12, the largest --max-steps", steps));
  }
  return ref;
}

const ParamSchema& output_schema() {
  static const ParamSchema schema = {
      integer_param("every", 1, "record the invariants, the tau monitors and a row of invariants.csv every this many steps (and at the last); other steps only check that the state is finite")
          .check([](const Json& v) { return v.get<long>() >= 1; }, "a positive integer"),
      string_param("error_estimate", "none",
                   "richardson: estimate the error of u(t_end) without a reference, from the same run at h / 2 "
                   "and 2 h (2.5 times the run's cost more; t_end / h even): result.json's error_estimate")
          .choices({"none", "richardson"}),
      integer_param("state_every", 0,
                    "write the state (physical variables, as u_final.npy) to state.npy in the output directory every "
                    "this many steps, replacing the last (0: never): a long run can be resumed from it "
                    "(vlasov-poisson-2d: model.particles)")
          .check([](const Json& v) { return v.get<long>() >= 0; }, "a non-negative integer"),
      integer_param("fields_every", 0,
                    "write the fields of a grid model (nls: u; klein-gordon: v; klein-gordon-complex: u and v; |u|, Re "
                    "u, Im u each) to fields.h5 every this many steps and at the first and last, with fields.xmf for "
                    "ParaView (0: never)")
          .check([](const Json& v) { return v.get<long>() >= 0; }, "a non-negative integer"),
      number_param("checkpoint_seconds", 30.0,
                   "rewrite result.json (status running, the time reached) at most this often while a run goes")
          .range(0.0, 1e9, true, false),
      array_param("times",
                  "times in [0, t_end] at which to write u (result.json's dense_output, and u_times.npy): between the "
                  "steps from the state interpolated in t with the scheme's order and read back at tau = t/eps")
          .check(
              [](const Json& v) {
                if (v.size() > max_output_times) return false;
                for (const Json& t : v)
                  if (!t.is_number() || !std::isfinite(t.get<double>()) || t.get<double>() < 0.0) return false;
                return true;
              },
              "an array of at most 100000 finite times >= 0")};
  return schema;
}

const ParamSchema& monitor_schema() {
  static const ParamSchema schema = {
      number_param("max_err_H", 10.0, "stop the run (blow-up) when err_H exceeds this")
          .range(0.0, std::numeric_limits<double>::infinity(), true),
      number_param("tau_roughness_warn", 1e-10,
                   "warn when this fraction of the energy of U is in the top quarter of the tau spectrum")
          .range(0.0, 1.0, true),
      number_param("tau_spread_growth_warn", 100.0,
                   "warn when the fraction of the energy of U away from its tau mean grows this many times "
                   "over its value at the first recorded step (and above 1e-6): U's characteristics have come apart")
          .range(1.0, std::numeric_limits<double>::infinity())};
  return schema;
}

}  // namespace

std::vector<RunnerSection> runner_sections() {
  const std::vector<RunnerSection> all = {
      {"model", "the model: \"name\" (required) a registered model or alias, then its parameters", nullptr, "models"},
      {"reformulation",
       "the problem the scheme integrates: \"name\" (default two-scale where the scheme supports it, else the "
       "first it supports), then its parameters",
       nullptr, "reformulations"},
      {"scheme", "the scheme: \"name\" (default se1), then its parameters", nullptr, "schemes"},
      {"time", "the step and the final time", &time_schema(), ""},
      {"reference",
       "absent: no error is computed; {} asks for the default reference solution, against which the error of "
       "u(t_end) is measured",
       &reference_schema(), ""},
      {"output", "what is recorded and written while the run goes", &output_schema(), ""},
      {"monitor", "when the run warns or stops", &monitor_schema(), ""},
      {"plugins", "plugin files to load (a list of file names, relative to the config file; default [])", nullptr,
       ""}};
  // every section the resolver accepts is described, and nothing else
  std::vector<std::string> names;
  for (const auto& s : all) names.push_back(s.name);
  if (names != sections) throw Error("runner_sections: out of step with the config's sections");
  return all;
}

Json parse_json(std::istream& in, const std::string& origin) {
  // The parser's callback sees every key and nesting level: a duplicated key (which the parser
  // would silently resolve to the last value) and nesting deeper than any config needs are
  // refused, naming where; the key path also names a number that overflows a double.
  constexpr std::size_t max_depth = 64;
  std::vector<std::set<std::string>> keys;  // per open object (empty sets stand for arrays)
  std::vector<std::string> path;            // the key or index path to the current value
  std::string last_key;
  const auto where = [&] {
    std::string p;
    for (const auto& k : path) p += (p.empty() ? "" : ".") + k;
    return p.empty() ? origin : origin + ": " + p;
  };
  const Json::parser_callback_t check = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        if (keys.size() >= max_depth)
          throw ConfigError(where(), fmt::format("nested deeper than {} levels; no config needs that", max_depth));
        if (!keys.empty()) path.push_back(last_key);
        keys.emplace_back();
        last_key = "[]";
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        keys.pop_back();
        if (!path.empty()) path.pop_back();
        break;
      case Json::parse_event_t::key: {
        const std::string key = parsed.get<std::string>();
        if (!keys.back().insert(key).second)
          throw ConfigError(where(), "duplicate key \"" + key + "\": each key may appear once in an object");
        last_key = key;
        break;
      }
      case Json::parse_event_t::value:
        break;
    }
    return true;
  };
  // The parser takes a NUL byte for the end of the input and would ignore what follows it.
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (const auto nul = text.find('\0'); nul != std::string::npos)
    throw ConfigError(origin, fmt::format("malformed JSON: a NUL byte at offset {}; a config is a text file", nul));
  try {
    return Json::parse(text, check, true, /*ignore_comments=*/true);
  } catch (const Json::parse_error& e) {
    throw ConfigError(origin, std::string("malformed JSON: ") + e.what());
  } catch (const Json::out_of_range&) {
    const std::string field = last_key.empty() || last_key == "[]" ? where() : where() + "." + last_key;
    throw ConfigError(field, "a number out of the range of a double (at most about 1.8e308 in magnitude)");
  }
}

Json load_config_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ConfigError(path, "is a directory, expected a JSON config file");
  std::ifstream in(path);
  if (!in) throw ConfigError(path, "cannot open the config file (missing or unreadable)");
  return parse_json(in, path);
}

void apply_override(Json& config, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("--set", "got \"" + assignment + "\", expected key.path=value");
  const std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  Json value;
  try {
    std::istringstream in(text);
    value = parse_json(in, "--set " + path);
  } catch (const ConfigError& e) {
    if (std::string(e.what()).find("malformed JSON") == std::string::npos) throw;
    value = text;  // a bare word is a string
  }
  assign_path(config, path, value, "--set " + path);
}

void assign_path(Json& config, const std::string& path, const Json& value, const std::string& origin) {
  std::vector<std::string> keys;
  std::stringstream ss(path);
  for (std::string key; std::getline(ss, key, '.');) {
    if (key.empty()) throw ConfigError(origin, "empty component in the key path \"" + path + "\"");
    keys.push_back(key);
  }
  if (keys.empty()) throw ConfigError(origin, "empty key path");
  if (keys.size() > 16)
    throw ConfigError(origin.substr(0, 80), fmt::format("a key path of {} components; no config is deeper than a few",
                                                        keys.size()));
  if (std::find(sections.begin(), sections.end(), keys.front()) == sections.end())
    throw ConfigError(origin, "unknown section \"" + keys.front() + "\"; valid sections are: " + join(sections));
  Json* node = &config;
  for (size_t i = 0; i + 1 < keys.size(); ++i) {
    if (!node->is_object()) throw ConfigError(origin, "cannot descend into a value that is not an object");
    node = &(*node)[keys[i]];
    if (node->is_null()) *node = Json::object();
  }
  if (!node->is_object()) throw ConfigError(origin, "the parent of the key is not an object");
  (*node)[keys.back()] = value;
}

void resolve_config_files(Json& raw, const std::string& config_path) {
  if (!raw.is_object() || !raw.contains("model") || !raw["model"].is_object()) return;
  Json& model = raw["model"];
  for (const char* key : model_file_keys) {
    if (!model.contains(key) || !model[key].is_string() || model[key].get<std::string>().empty()) continue;
    const std::filesystem::path file = model[key].get<std::string>();
    if (file.is_absolute()) continue;
    std::error_code ec;
    const std::filesystem::path resolved =
        std::filesystem::absolute(std::filesystem::path(config_path).parent_path() / file, ec);
    if (!ec) model[key] = resolved.lexically_normal().string();
  }
}

Json without_name(const Json& section) {
  Json out = section;
  out.erase("name");
  return out;
}

Json resolve_run_config(const Json& raw, const Registry& registry) {
  if (!raw.is_object()) throw ConfigError("config", "got " + raw.dump() + ", expected a JSON object");
  for (const auto& [key, value] : raw.items())
    if (std::find(sections.begin(), sections.end(), key) == sections.end())
      throw ConfigError(key, "unknown section; valid sections are: " + join(sections));

  const Json empty = Json::object();
  Json out = resolve_selection(raw, registry).sections();  // model, reformulation, scheme: the core's assembler

  out["time"] = resolve_params(time_schema(), section_object(raw, "time", empty), "time");
  const long steps = step_count(out);  // t_end must be a whole number of steps

  if (raw.contains("reference") && !raw.at("reference").is_null())
    out["reference"] = resolve_reference(raw, out["time"]["t_end"], registry);

  out["output"] = resolve_params(output_schema(), section_object(raw, "output", empty), "output");
  out["monitor"] = resolve_params(monitor_schema(), section_object(raw, "monitor", empty), "monitor");
  if (out["output"]["error_estimate"] == "richardson" && steps % 2 != 0)
    throw ConfigError("output.error_estimate",
                      fmt::format("\"richardson\" reruns the run at h / 2 and 2 h: it needs an even number of steps "
                                  "t_end / h, got {}",
                                  steps));

  out["plugins"] = Json::array();
  if (raw.contains("plugins")) {
    const Json& plugins = raw.at("plugins");
    if (!plugins.is_array()) throw ConfigError("plugins", "got " + plugins.dump() + ", expected a list of file names");
    for (const auto& p : plugins) {
      if (!p.is_string()) throw ConfigError("plugins", "got " + p.dump() + ", expected a file name");
      out["plugins"].push_back(p);
    }
  }
  return out;
}

ResolvedSelection resolved_selection(const Json& resolved) {
  const auto entry = [&](const char* key) {
    const Json& section = resolved.at(key);
    return ResolvedEntry{section.at("name").get<std::string>(), without_name(section)};
  };
  return {entry("model"), entry("reformulation"), entry("scheme")};
}

long step_count(const Json& resolved) {
  const double h = resolved.at("time").at("h"), t_end = resolved.at("time").at("t_end");
  const double steps = t_end / h;
  const double whole = std::round(steps);
  if (t_end > 0.0 && !(h <= t_end))
    throw ConfigError("time.h", fmt::format("got {}, expected at most t_end = {} (a run of no step would compare "
                                            "the initial state with the reference at t_end)",
                                            h, t_end));
  if (std::abs(steps - whole) > 1e-9 * std::max(1.0, steps))
    throw ConfigError("time.h", fmt::format("t_end = {} is not a whole number of steps of h = {} "
                                            "({:.6g} steps); choose h = t_end / n",
                                            t_end, h, steps));
  if (whole > 1e12) throw ConfigError("time.h", fmt::format("t_end / h = {:.3g} steps is too many: at most 1e12, the largest --max-steps", steps));
  return static_cast<long>(whole);
}

}  // namespace tsi::app
