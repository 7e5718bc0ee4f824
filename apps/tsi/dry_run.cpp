#include "dry_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "config.hpp"
#include "run_recorder.hpp"
#include "tsi/error.hpp"

namespace tsi::app {
namespace {

std::string value_text(const Json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_array() && value.size() > 6) return fmt::format("[{} values]", value.size());
  if (value.is_object() && value.size() > 6) return fmt::format("{{{} entries}}", value.size());
  return value.dump();
}

std::string count_text(double n) {
  if (!std::isfinite(n)) return "?";
  return n < 1e7 ? fmt::format("{:.0f}", n) : fmt::format("{:.3g}", n);
}

std::string reference_text(const Json& reference, const ReferenceEstimate& e) {
  if (e.exact) return "the model's exact solution (no steps)";
  Json settings = reference;
  settings.erase("scheme");
  settings.erase("reformulation");
  const std::string params = parameters_text(settings);
  std::string s = fmt::format("{} on {}{}", reference.value("scheme", std::string()),
                              reference.value("reformulation", std::string()), params.empty() ? "" : " (" + params + ")");
  if (std::isnan(e.steps))
    s += ": its steps are not estimated (an adaptive solver without substeps_per_period)";
  else
    s += fmt::format(": {}{} steps", e.at_least ? "at least " : "", count_text(e.steps));
  if (e.accuracy_check) s += ", then a second solve at tol / 10 to estimate its accuracy";
  return s;
}

// The varied values of a run, short: "eps=0.1 h=0.01" (the last part of each path).
std::string run_values(const StudyRun& run, const std::vector<std::string>& varied) {
  std::string s = run.label.empty() ? "" : run.label + ":";
  for (const auto& path : varied) {
    if (!run.assignments.contains(path)) continue;
    // The last part of the path, or the section for its name: scheme.name=se1 as scheme=se1.
    std::string key = path.substr(path.rfind('.') == std::string::npos ? 0 : path.rfind('.') + 1);
    if (key == "name" && path.size() > 5) {
      const std::string section = path.substr(0, path.size() - 5);
      key = section.substr(section.rfind('.') == std::string::npos ? 0 : section.rfind('.') + 1);
    }
    if (!s.empty()) s += ' ';
    s += key + "=" + value_text(run.assignments[path]);
  }
  return s;
}

}  // namespace

std::string bytes_text(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int k = 0;
  while (bytes >= 1024.0 && k < 4) bytes /= 1024.0, ++k;
  return k == 0 ? fmt::format("{:.0f} B", bytes) : fmt::format("{:.3g} {}", bytes, units[k]);
}

std::string parameters_text(const Json& section) {
  std::string s;
  if (!section.is_object()) return s;
  for (const auto& [key, value] : section.items()) {
    if (key == "name" || value.is_null()) continue;
    s += (s.empty() ? "" : ", ") + key + " = " + value_text(value);
  }
  return s;
}

RunEstimate estimate_run(const Json& config, const Registry& registry, const RunSettings& settings,
                         bool check_reference) {
  RunPlan plan = plan_run(config, registry, settings, check_reference);
  const Assembly& a = plan.assembly;
  // The recorder checks the model's declared invariants (their names and values) as a run's does.
  { const RunRecorder recorder(*a.model, *a.reformulation, a.u0, config, ""); }
  RunEstimate e;
  e.steps = plan.steps;
  e.warnings = std::move(plan.warnings);
  if (config.contains("output") && config["output"].value("error_estimate", std::string("none")) == "richardson")
    e.error_estimate_steps = 2.5 * static_cast<double>(plan.steps);
  e.state_bytes = static_cast<double>(a.reformulation->size()) * static_cast<double>(sizeof(Complex));
  if (a.footprint.vectors > 0.0) {  // a two-scale run's footprint, as checked against the memory available
    e.peak_vectors = a.footprint.vectors;
    e.peak_breakdown = fmt::format("the state 1, the two-scale problem {:.3g}, and the larger of the scheme's {:.3g} "
                                   "and the prepared data's {:.3g}, freed before the scheme is bound",
                                   a.footprint.problem_vectors, a.footprint.scheme_vectors,
                                   a.footprint.preparation_vectors);
  } else {
    const double scheme = a.scheme->state_vectors(a.reformulation->layout());
    e.peak_vectors = 1.0 + scheme;
    e.peak_breakdown = fmt::format("the state 1, the scheme's {:.3g}", scheme);
  }
  if (config.contains("reference")) e.reference = estimate_reference(config, registry, settings);
  return e;
}

std::string run_dry_text(const std::string& config_path, const Json& config, const RunEstimate& e,
                         const std::string& out_dir) {
  std::string s = fmt::format("dry run of {}: checked as a run would be; nothing was run or written\n", config_path);
  const auto line = [&s](const char* what, const std::string& text) { s += fmt::format("  {:<15}{}\n", what, text); };
  for (const char* section : {"model", "reformulation", "scheme"}) {
    const Json& c = config[section];
    const std::string params = parameters_text(c);
    line(section, c.value("name", std::string()) + (params.empty() ? "" : " (" + params + ")"));
  }
  line("time", fmt::format("t_end = {}, h = {}: {} steps", config["time"]["t_end"].get<double>(),
                           config["time"]["h"].get<double>(), e.steps));
  if (e.reference) line("reference", reference_text(config["reference"], *e.reference));
  if (e.error_estimate_steps > 0.0)
    line("error estimate", fmt::format("Richardson: {} more steps (the run again at h / 2 and 2 h)",
                                       count_text(e.error_estimate_steps)));
  line("memory", fmt::format("the state {} ({:.0f} complex values); about {} at the peak ({:.3g} vectors of the "
                             "state's size: {})",
                             bytes_text(e.state_bytes), e.state_bytes / static_cast<double>(sizeof(Complex)),
                             bytes_text(e.peak_bytes()), e.peak_vectors, e.peak_breakdown));
  for (const auto& w : e.warnings) line("warning", w);
  line("would write", out_dir + "/ (result.json, invariants.csv)");
  return s;
}

int run_dry_run(const std::string& config_path, const Json& config, const Registry& registry,
                const RunSettings& settings, const std::string& out_dir) {
  const Collective* split = settings.context.collective;
  if (split) agree_to_start(*split, config, registry, settings, [] {});  // refused alike, said once
  const RunEstimate estimate = estimate_run(config, registry, settings);
  if (split && split->rank() != 0) return 0;
  std::string text = run_dry_text(config_path, config, estimate, out_dir);
  if (split) text += fmt::format("  {:<15}over {} processes: the state and memory above are rank 0's share\n", "split", split->size());
  fmt::print("{}", text);
  return 0;
}

int study_dry_run(const std::string& study_path, const Study& study, const Registry& registry, int jobs,
                  std::string& text) {
  text = fmt::format("dry run of {}: {} study \"{}\", {} runs, checked as they would run; nothing was run or "
                     "written\n",
                     study_path, study.kind, study.title, study.runs.size());
  std::vector<std::string> values(study.runs.size());
  size_t width = 6;
  for (size_t i = 0; i < study.runs.size(); ++i) {
    values[i] = run_values(study.runs[i], study.varied);
    width = std::max(width, std::min<size_t>(values[i].size(), 48));
  }
  text += fmt::format("  {:<6} {:<{}} {:>10} {:>11}  {}\n", "run", "values", width, "steps", "peak memory", "reference");
  std::map<std::string, std::string> reference_of;  // reference_key -> the first run that needs it
  double total_steps = 0.0, reference_steps = 0.0, largest_peak = 0.0;
  bool references_at_least = false, accuracy_checks = false;
  size_t failing = 0;
  for (size_t i = 0; i < study.runs.size(); ++i) {
    const StudyRun& run = study.runs[i];
    std::string reference;
    bool first_of_reference = false;
    if (run.config.contains("reference")) {
      const auto [it, inserted] = reference_of.emplace(reference_key(run.config), run.id);
      first_of_reference = inserted;
      if (!inserted) reference = "the same as " + it->second;
    }
    try {
      // A shared reference's cost is checked once, by expand_study, as run_study computes it once.
      const RunEstimate e = estimate_run(run.config, registry, study.settings, false);
      total_steps += static_cast<double>(e.steps) + e.error_estimate_steps;
      largest_peak = std::max(largest_peak, e.peak_bytes());
      if (e.reference && first_of_reference) {
        const ReferenceEstimate& r = *e.reference;
        reference = r.exact ? "exact" : (r.at_least ? ">= " : "") + count_text(r.steps) + " steps";
        if (!r.exact && std::isfinite(r.steps)) reference_steps += r.steps;
        references_at_least = references_at_least || r.at_least;
        accuracy_checks = accuracy_checks || r.accuracy_check;
      }
      text += fmt::format("  {:<6} {:<{}} {:>10} {:>11}  {}\n", run.id, values[i], width,
                          count_text(static_cast<double>(e.steps) + e.error_estimate_steps),
                          bytes_text(e.peak_bytes()), reference);
    } catch (const std::exception& ex) {  // run_study records the run as failed, and goes on
      ++failing;
      text += fmt::format("  {:<6} {:<{}} would fail: {}\n", run.id, values[i], width, ex.what());
    }
  }
  text += fmt::format("  total: {} runs, {} steps", study.runs.size(), count_text(total_steps));
  if (!reference_of.empty())
    text += fmt::format("; {} references, {}{} steps{}", reference_of.size(), references_at_least ? "at least " : "",
                        count_text(reference_steps),
                        accuracy_checks ? " (and a second solve of each to check its accuracy)" : "");
  text += fmt::format("\n  memory: the largest run holds about {} at its peak; {} at once on {} threads at most\n",
                      bytes_text(largest_peak), bytes_text(largest_peak * static_cast<double>(std::min<size_t>(static_cast<size_t>(std::max(1, jobs)), study.runs.size()))),
                      jobs);
  if (failing > 0) text += fmt::format("  {} of {} runs would fail when they start\n", failing, study.runs.size());
  return failing > 0 ? 1 : 0;
}

}  // namespace tsi::app
