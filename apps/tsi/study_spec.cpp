#include "study_spec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

#include "config.hpp"
#include "run.hpp"
#include "tsi/error.hpp"
#include "tsi/stop_request.hpp"

namespace tsi::app {
namespace {

const std::vector<std::string> kinds = {"convergence", "conservation", "work-precision"};

// Plugins are loaded once, from base.plugins, before the study expands: a run's own list (a
// path a vary, a case or a --set assigns) would never be loaded, so it is refused.
void refuse_plugins_path(const std::string& path, const std::string& where) {
  if (path == "plugins" || path.rfind("plugins.", 0) == 0 || path.rfind("plugins[", 0) == 0)
    throw ConfigError(where, "plugins are loaded once for the whole study, before it expands: list them in "
                             "base.plugins (or pass --plugin FILE), not per run");
}

// A "vary" object as ordered (path, values) pairs; each list must be non-empty.
std::vector<std::pair<std::string, Json>> vary_lists(const Json& vary, const std::string& where) {
  if (!vary.is_object()) throw ConfigError(where, "got " + vary.dump() + ", expected an object of path: [values]");
  std::vector<std::pair<std::string, Json>> out;
  for (const auto& [path, values] : vary.items()) {
    if (!values.is_array() || values.empty())
      throw ConfigError(where + "." + path, "got " + values.dump() + ", expected a non-empty list of values");
    refuse_plugins_path(path, where + "." + path);
    out.emplace_back(path, values);
  }
  return out;
}

std::string describe_assignments(const Json& assignments) {
  std::string s;
  for (const auto& [path, value] : assignments.items()) s += (s.empty() ? "" : ", ") + path + "=" + value.dump();
  return s;
}

// The leaf paths of a "set" object ("scheme": {"name": "rk78"} sets scheme.name).
void leaf_paths(const std::string& prefix, const Json& value, std::vector<std::string>& out) {
  if (value.is_object() && !value.empty()) {
    for (const auto& [key, inner] : value.items()) leaf_paths(prefix + "." + key, inner, out);
    return;
  }
  out.push_back(prefix);
}

Json::json_pointer pointer(const std::string& dotted) {
  // Token by token: a key may hold '~' or '/', which a pointer's text would read as escapes.
  Json::json_pointer p;
  std::stringstream ss(dotted);
  for (std::string key; std::getline(ss, key, '.');) p /= key;
  return p;
}

// A string entry of a study object, or `fallback` when absent.
std::string string_entry(const Json& object, const std::string& key, const std::string& fallback,
                         const std::string& where) {
  if (!object.contains(key)) return fallback;
  const Json& v = object.at(key);
  if (!v.is_string()) throw ConfigError(where, "got " + v.dump() + ", expected a string");
  return v.get<std::string>();
}

bool is_unknown_parameter(const ConfigError& e) {
  return std::string(e.what()).find("unknown parameter") != std::string::npos;
}

}  // namespace

Study expand_study(const Json& spec, const Registry& registry, const std::vector<std::string>& overrides,
                   const std::string& study_path, const RunSettings& settings, bool build_runs) {
  if (!spec.is_object()) throw ConfigError("study", "got " + spec.dump() + ", expected a JSON object");
  for (const auto& [key, value] : spec.items())
    if (key != "kind" && key != "title" && key != "base" && key != "vary" && key != "cases")
      throw ConfigError(key, "unknown study key; valid keys are: base, cases, kind, title, vary");
  Study study;
  study.settings = settings;
  study.spec = spec;
  study.kind = string_entry(spec, "kind", "convergence", "kind");
  if (std::find(kinds.begin(), kinds.end(), study.kind) == kinds.end())
    throw ConfigError("kind", "got \"" + study.kind + "\", expected one of: convergence, conservation, work-precision");
  study.title = string_entry(spec, "title", "", "title");
  if (!spec.contains("base") || !spec["base"].is_object())
    throw ConfigError("base", "missing or not an object; it is the run config every run starts from");
  Json base = spec["base"];
  const auto common = vary_lists(spec.value("vary", Json::object()), "vary");
  Json cases = spec.value("cases", Json::array({Json::object()}));
  if (!cases.is_array() || cases.empty()) throw ConfigError("cases", "expected a non-empty list of cases");

  for (const auto& assignment : overrides) {  // its syntax first: "--set time.h" lacks a value
    Json scratch = Json::object();
    apply_override(scratch, assignment);
    const std::string path = assignment.substr(0, assignment.find('='));
    refuse_plugins_path(path, "--set " + path);
  }
  // A --set on a path the study varies (or a case sets) would be silently replaced: refused.
  for (const auto& assignment : overrides) {
    const std::string path = assignment.substr(0, assignment.find('='));
    std::string where;
    if (spec.value("vary", Json::object()).is_object() && spec.value("vary", Json::object()).contains(path))
      where = "vary." + path;
    for (size_t c = 0; c < cases.size() && where.empty(); ++c) {
      if (!cases[c].is_object()) continue;
      const Json vary = cases[c].value("vary", Json::object()), set = cases[c].value("set", Json::object());
      std::vector<std::string> set_paths;
      if (set.is_object())
        for (const auto& [key, value] : set.items()) leaf_paths(key, value, set_paths);
      if (vary.is_object() && vary.contains(path)) where = fmt::format("cases[{}].vary.{}", c, path);
      for (const auto& p : set_paths)
        if (where.empty() && (p == path || p.rfind(path + ".", 0) == 0 || path.rfind(p + ".", 0) == 0))
          where = fmt::format("cases[{}].set.{}", c, p);
    }
    if (!where.empty())
      throw ConfigError("--set " + path, "the study varies this path (" + where +
                                             "), which would replace the value set; change the study's list instead");
  }
  for (const auto& assignment : overrides) apply_override(base, assignment);
  study.spec["base"] = base;
  std::map<std::string, std::string> dropped_message;  // base path -> why a run refused it

  for (size_t c = 0; c < cases.size(); ++c) {
    const Json& one = cases[c];
    const std::string where = fmt::format("cases[{}]", c);
    if (!one.is_object()) throw ConfigError(where, "got " + one.dump() + ", expected an object");
    for (const auto& [key, value] : one.items())
      if (key != "label" && key != "set" && key != "vary")
        throw ConfigError(where + "." + key, "unknown key of a case; valid keys are: label, set, vary");
    const std::string label = string_entry(one, "label", "", where + ".label");
    Json config = base;
    const Json set = one.value("set", Json::object());  // a named copy: items() must not outlive it
    if (!set.is_object()) throw ConfigError(where + ".set", "got " + set.dump() + ", expected an object of path: value");
    std::vector<std::string> set_paths;
    for (const auto& [path, value] : set.items()) {
      refuse_plugins_path(path, where + ".set." + path);
      assign_path(config, path, value, where + ".set." + path);
      leaf_paths(path, value, set_paths);
    }
    for (const auto& path : set_paths)  // a path a case sets varies from case to case: a column too
      if (std::find(study.varied.begin(), study.varied.end(), path) == study.varied.end())
        study.varied.push_back(path);
    auto lists = common;
    for (auto& [path, values] : vary_lists(one.value("vary", Json::object()), where + ".vary")) {
      const std::string& name = path;  // (clang 14 cannot capture a structured binding)
      auto it = std::find_if(lists.begin(), lists.end(), [&](const auto& p) { return p.first == name; });
      if (it != lists.end()) it->second = values; else lists.emplace_back(path, values);
    }
    for (const auto& [path, values] : lists)
      if (std::find(study.varied.begin(), study.varied.end(), path) == study.varied.end())
        study.varied.push_back(path);

    // Its size, counted before anything is expanded (and in double: it may not fit a size_t).
    double product = 1.0;
    for (const auto& [path, values] : lists) product *= static_cast<double>(values.size());
    product += static_cast<double>(study.runs.size());  // with the cases before this one
    if (product > static_cast<double>(max_study_runs))
      throw ConfigError(lists.empty() ? where : "vary", fmt::format("the study expands to {:.4g} runs; at most {} are "
                                                                   "allowed: split it, or vary fewer values",
                                                                   product, max_study_runs));
    // The cartesian product, last path fastest (an odometer over the lists).
    std::vector<size_t> index(lists.size(), 0);
    for (bool done = false; !done;) {
      StudyRun run;
      run.id = fmt::format("r{:04d}", study.runs.size() + 1);
      run.label = label;
      run.assignments = Json::object();
      Json raw = config;
      for (const auto& path : set_paths)
        if (raw.contains(pointer(path))) run.assignments[path] = raw.at(pointer(path));
      for (size_t k = 0; k < lists.size(); ++k) {
        const Json& value = lists[k].second[index[k]];
        run.assignments[lists[k].first] = value;
        assign_path(raw, lists[k].first, value, "vary." + lists[k].first);
      }
      resolve_config_files(raw, study_path);  // model.u0 as a file: relative to the study
      for (;;) {
        try {
          run.config = resolve_run_config(raw, registry);
          break;
        } catch (const ConfigError& e) {
          // A base setting this run's scheme or model does not take (scheme.tol for fd when the
          // study varies se1 and fd) is left out of this run and reported; a setting no run
          // takes is still an error (after the expansion), so that typos are caught.
          const std::string& field = e.field();
          if (is_unknown_parameter(e) && !field.empty() && base.contains(pointer(field)) &&
              !run.assignments.contains(field) && raw.contains(pointer(field))) {
            raw.at(pointer(field).parent_pointer()).erase(pointer(field).back());
            study.not_used[field].push_back(run.id);
            dropped_message.emplace(field, std::string(e.what()).substr(field.size() + 2));
            continue;
          }
          const std::string what = e.what();
          const std::string message = field.empty() ? what : what.substr(field.size() + 2);
          throw ConfigError(field, fmt::format("{} (run {}: {})", message, run.id,
                                               describe_assignments(run.assignments)));
        }
      }
      study.runs.push_back(std::move(run));
      done = true;
      for (size_t k = lists.size(); k-- > 0;) {
        if (++index[k] < lists[k].second.size()) {
          done = false;
          break;
        }
        index[k] = 0;
      }
    }
  }
  for (const auto& [path, ids] : study.not_used.items())
    if (ids.size() == study.runs.size())
      throw ConfigError(path, dropped_message[path] + " (set in the base, and no run of the study takes it)");
  // The work estimate of every run and of each distinct reference, before any runs.
  std::set<std::string> references;
  for (const auto& run : study.runs) {
    try {
      check_run_steps(run.config, settings.max_steps);
      if (run.config.contains("reference") && references.insert(reference_key(run.config)).second)
        check_reference_cost(run.config, registry, settings);
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      const std::string message = e.field().empty() ? what : what.substr(e.field().size() + 2);
      throw ConfigError(e.field(), fmt::format("{} (run {}: {})", message, run.id, describe_assignments(run.assignments)));
    }
  }
  // Each run's objects built once and dropped: what only its model or data can say (a grid
  // that does not fit, a u0 of the wrong shape, the model's own checks) is said now.
  std::set<std::string> built;
  for (const auto& run : study.runs) {
    if (!build_runs) break;
    Json key = run.config;
    if (key.contains("time")) key["time"].erase("h");
    if (!built.insert(key.dump()).second) continue;
    throw_if_stop_requested("checking the study's runs before any runs");
    try {
      plan_run(run.config, registry, settings, false);
    } catch (const Interrupted&) {
      throw;
    } catch (const Error& e) {  // a ConfigError keeps its field; a data file's error has none
      const auto* config_error = dynamic_cast<const ConfigError*>(&e);
      const std::string field = config_error ? config_error->field() : std::string();
      const std::string what = e.what();
      const std::string message = field.empty() ? what : what.substr(field.size() + 2);
      throw ConfigError(field, fmt::format("{} (run {}: {})", message, run.id, describe_assignments(run.assignments)));
    }
  }
  return study;
}

}  // namespace tsi::app
