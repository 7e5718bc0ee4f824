#include "study_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "config.hpp"
#include "plugin_setup.hpp"
#include "run_files.hpp"
#include "tsi/error.hpp"
#include "study_report.hpp"
#include "study_runner.hpp"

namespace tsi::app {
namespace {

using Clock = std::chrono::steady_clock;

std::string shell_quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

StudyProgressFn study_progress(ProgressLine& line) {
  return [&line](const StudyProgress& p) {
    const auto now = line.now();
    if (line.due(now)) line.offer(now, study_progress_text(p, line.elapsed(now)));
  };
}

std::string plot_script_path() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path().parent_path() / "share" / "tsi" / "plot_study.py";
    if (std::filesystem::exists(installed)) return installed.string();
  }
  return TSI_SOURCE_SCRIPT_DIR "/plot_study.py";
}

void call_plots(const std::string& out_dir, bool plots) {
  if (!plots) return;
  const std::string script = plot_script_path();
  std::fflush(stdout);  // the script prints too: keep the order
  const int have_matplotlib = std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1");
  if (have_matplotlib == 0 && std::filesystem::exists(script)) {
    const int rc = std::system(("/usr/bin/python3 " + shell_quoted(script) + " " + shell_quoted(out_dir)).c_str());
    if (rc != 0) fmt::print("  plotting failed; rerun: python3 {} {}\n", script, out_dir);
  } else {
    fmt::print("  no plots: install python3-matplotlib, then run: python3 {} {}\n", script, out_dir);
  }
}

std::vector<std::string> io_errors_of(const std::vector<StudyRun>& runs, const std::vector<RunOutcome>& outcomes) {
  std::vector<std::string> errors;
  for (size_t i = 0; i < runs.size() && i < outcomes.size(); ++i)
    if (!outcomes[i].io_error.empty()) errors.push_back(runs[i].id + ": " + outcomes[i].message);
  return errors;
}

int study_exit_code(const Json& rows, const std::vector<std::string>& io_errors) {
  if (!io_errors.empty()) {
    for (size_t k = 0; k < io_errors.size() && k < 8; ++k) spdlog::error("{}", io_errors[k]);
    if (io_errors.size() > 8) spdlog::error("... and {} more outputs that could not be written", io_errors.size() - 8);
    return 3;
  }
  for (const auto& row : rows)
    if (row["status"] == "failed") return 1;
  return 0;
}

int study_command(PluginLoader& loader, Registry& registry, const std::string& study_path, std::string out_dir,
                  int jobs, const std::vector<std::string>& overrides, bool plots, const RunSettings& settings,
                  bool resume, bool force, bool quiet) {
  Json spec = load_config_file(study_path);
  if (spec.is_object() && spec.contains("base") && spec["base"].is_object() && spec["base"].contains("plugins"))
    load_config_plugins(loader, spec["base"]["plugins"], study_path);
  const Study study = expand_study(spec, registry, overrides, study_path, settings);
  if (out_dir.empty()) out_dir = "out/" + std::filesystem::path(study_path).stem().string();
  prepare_output_dir(out_dir);
  resume = claim_study_dir(out_dir, study, resume, force);
  // --resume: the runs that finished (completed or blew up) are read back, the others run.
  std::vector<RunOutcome> finished(study.runs.size());
  std::vector<bool> skip(study.runs.size(), false);
  size_t kept = 0;
  if (resume) {
    for (size_t i = 0; i < study.runs.size(); ++i) {
      const std::string dir = out_dir + "/runs/" + study.runs[i].id;
      std::error_code ec;
      if (!std::filesystem::exists(dir + "/invariants.csv", ec)) continue;
      try {
        Json result = load_config_file(dir + "/result.json");
        const std::string status = result.value("status", std::string());
        if ((status != "completed" && status != "blow-up") || result.value("config", Json()) != study.runs[i].config)
          continue;
        finished[i].ok = true;
        finished[i].message = result.value("message", std::string());
        finished[i].csv_file = dir + "/invariants.csv";  // in place: written again as itself
        finished[i].result = std::move(result);
        skip[i] = true;
        ++kept;
      } catch (const Error&) {
        // unreadable: run it again
      }
    }
  }
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  ProgressLine line(stderr_progress_mode(quiet));
  const auto start = Clock::now();
  if (line.mode() == ProgressMode::terminal) fmt::print(stderr, "  {} runs on {} threads\n", study.runs.size() - kept, jobs);
  if (resume) fmt::print("  resumed: {} of {} runs finished earlier are kept, {} to run\n", kept, study.runs.size(),
                         study.runs.size() - kept);
  auto outcomes = run_study(study, registry, jobs, line.enabled() ? study_progress(line) : StudyProgressFn(), out_dir, skip);
  for (size_t i = 0; i < outcomes.size(); ++i)
    if (skip[i]) outcomes[i] = std::move(finished[i]);
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  line.finish();  // before the tables

  const Json rows = study_rows(study, outcomes);
  // Every run's files, then the table; an output that could not be written is exit code 3.
  std::vector<std::string> io_errors = io_errors_of(study.runs, outcomes);
  for (auto& e : write_study_files(out_dir, study, outcomes, rows, wall, jobs)) io_errors.push_back(std::move(e));
  fmt::print("{}", study_text(study, rows));
  fmt::print("  wall time {:.2f} s on {} threads\n", wall, jobs);
  fmt::print("  written: {0}/table.csv, {0}/study.json, {0}/runs/\n", out_dir);
  call_plots(out_dir, plots);
  return study_exit_code(rows, io_errors);
}

}  // namespace tsi::app
