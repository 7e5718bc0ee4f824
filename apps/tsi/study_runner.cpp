#include "study_runner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "config.hpp"
#include "interrupt.hpp"
#include "tsi/error.hpp"
#include "tsi/fft.hpp"
#include "tsi/version.hpp"

namespace tsi::app {
namespace {

// Calls work(i) for i in [0, n) on `jobs` threads; work must not throw.
void parallel_for(size_t n, int jobs, const std::function<void(size_t)>& work) {
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i; (i = next++) < n;) work(i);
  };
  std::vector<std::thread> threads;
  const size_t count = std::min<size_t>(n, static_cast<size_t>(std::max(1, jobs)));
  for (size_t t = 1; t < count; ++t) threads.emplace_back(worker);
  worker();
  for (auto& t : threads) t.join();
}

}  // namespace

RunOutcome failed_run_outcome(const StudyRun& run, const std::string& message) {
  RunOutcome o;
  o.ok = false;
  o.message = message;
  o.result = {{"tsi_version", version_string}, {"config", run.config}, {"status", "failed"},
              {"message", message}, {"warnings", Json::array()}};
  return o;
}

bool claim_study_dir(const std::string& out_dir, const Study& study, bool resume, bool force) {
  namespace fs = std::filesystem;
  const fs::path previous = fs::path(out_dir) / "study.json";
  std::error_code ec;
  if (fs::exists(previous, ec)) {
    Json earlier;
    try {
      earlier = load_config_file(previous.string()).value("study", Json());
    } catch (const Error&) {
      earlier = Json();
    }
    if (earlier != study.spec && !force)
      throw ConfigError(resume ? "--resume" : "--out",
                        "\"" + out_dir + "\" holds the results of another study (" +
                            (earlier.is_object() ? earlier.value("title", std::string("untitled")) : "unreadable") +
                            "); choose another --out, or replace them with --force");
    if (earlier != study.spec)  // --force: the other study's files go (only what tsi writes)
      for (const char* name : {"study.json", "table.csv", "convergence.png", "conservation.png", "work_precision.png"})
        fs::remove(fs::path(out_dir) / name, ec);
  } else {
    resume = false;  // nothing to resume
  }
  if (!resume) fs::remove_all(fs::path(out_dir) / "runs", ec);
  return resume;
}

std::vector<RunOutcome> run_study(const Study& study, const Registry& registry, int jobs,
                                  const StudyProgressFn& progress, const std::string& out_dir,
                                  const std::vector<bool>& skip) {
  const auto skipped = [&](size_t i) { return i < skip.size() && skip[i]; };
  // Distinct references, each computed once, for the runs to run.
  std::map<std::string, size_t> reference_index;
  std::vector<const Json*> reference_configs;
  for (size_t i = 0; i < study.runs.size(); ++i) {
    const auto& run = study.runs[i];
    if (skipped(i) || !run.config.contains("reference")) continue;
    if (reference_index.emplace(reference_key(run.config), reference_configs.size()).second)
      reference_configs.push_back(&run.config);
  }
  const size_t total = reference_configs.size() + study.runs.size();
  // Where the study is, for its progress line: the units finished, those under way with their
  // fraction done, and the one last started or advanced.
  std::mutex progress_mutex;
  size_t done = 0;
  std::map<size_t, double> under_way;  // task -> fraction done
  std::string current;
  size_t current_task = 0;
  const auto report = [&] {  // under progress_mutex
    StudyProgress p{done, total, under_way.size(), 0.0, current, 0.0};
    for (const auto& [task, fraction] : under_way) p.running_done += fraction;
    if (const auto it = under_way.find(current_task); it != under_way.end()) p.current_fraction = it->second;
    progress(p);
  };
  const auto unit_name = [&](size_t task) {
    return task < reference_configs.size() ? std::string("reference") : study.runs[task - reference_configs.size()].id;
  };
  const auto started = [&](size_t task) {
    if (!progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    under_way[task] = 0.0;
    current = unit_name(task);
    current_task = task;
    report();
  };
  auto tick = [&](size_t task) {
    std::lock_guard<std::mutex> lock(progress_mutex);
    ++done;
    if (!progress) return;
    under_way.erase(task);
    if (current_task == task) {  // another unit under way, if any, is the current one
      current = under_way.empty() ? std::string() : unit_name(under_way.begin()->first);
      current_task = under_way.empty() ? total : under_way.begin()->first;
    }
    report();
  };
  // A unit's steps (every few steps, execute_run's calls) passed on at most every quarter
  // second: a long run keeps the line moving.
  const auto unit_progress = [&](size_t task) -> ProgressFn {
    if (!progress) return {};
    return [&, task, last = std::make_shared<ProgressClock::time_point>(ProgressClock::now())](const StepProgress& p) {
      const auto now = ProgressClock::now();
      if (now - *last < std::chrono::milliseconds(250)) return;
      *last = now;
      std::lock_guard<std::mutex> lock(progress_mutex);
      under_way[task] = p.steps > 0 ? static_cast<double>(p.step) / static_cast<double>(p.steps) : 0.0;
      current = unit_name(task);
      current_task = task;
      report();
    };
  };

  // The references first (the smallest eps, the longest, first), then the runs, from one
  // queue: a worker that takes a run whose reference is still being computed waits for that
  // one only, and the others go on (a study no longer waits for its slowest reference).
  std::stable_sort(reference_configs.begin(), reference_configs.end(), [](const Json* a, const Json* b) {
    return a->at("model").value("eps", 1.0) < b->at("model").value("eps", 1.0);
  });
  for (size_t r = 0; r < reference_configs.size(); ++r) reference_index[reference_key(*reference_configs[r])] = r;
  std::vector<ReferenceSolution> references(reference_configs.size());
  std::vector<std::string> reference_errors(reference_configs.size());
  std::vector<std::promise<void>> computed(reference_configs.size());
  std::vector<std::shared_future<void>> ready;
  for (auto& p : computed) ready.push_back(p.get_future().share());

  // One-time process costs are not charged to whichever run comes first: FFTW sets up its
  // planner on the first plan (0.8 ms measured, against 0.2 ms for a whole small run).
  { const FftBatch warm_up(2, 1); }
  std::vector<RunOutcome> outcomes(study.runs.size());
  const size_t n_references = reference_configs.size();
  parallel_for(n_references + study.runs.size(), jobs, [&](size_t task) {
    if (task < n_references) {
      started(task);
      try {
        references[task] = compute_reference(*reference_configs[task], registry, study.settings, unit_progress(task));
      } catch (const std::exception& e) {
        reference_errors[task] = e.what();
      } catch (...) {
        reference_errors[task] = "an unknown error";
      }
      computed[task].set_value();  // always: the runs waiting for it go on
      tick(task);
      return;
    }
    const size_t i = task - n_references;
    if (skipped(i)) {  // its outcome is the caller's (resumed from its files)
      tick(task);
      return;
    }
    const StudyRun& run = study.runs[i];
    const ReferenceSolution* reference = nullptr;
    const auto not_run = [&] {  // not started (its reference may have been cut short too)
      outcomes[i] = failed_run_outcome(run, fmt::format("not run: the study was interrupted by signal {}", interrupt_signal()));
      outcomes[i].result["status"] = "interrupted";
      tick(task);
    };
    if (interrupted()) return not_run();
    if (run.config.contains("reference")) {
      const size_t r = reference_index.at(reference_key(run.config));
      ready[r].wait();  // taken by a worker before any run was: never a deadlock
      if (interrupted()) return not_run();
      if (!reference_errors[r].empty()) {
        outcomes[i] = failed_run_outcome(run, "the reference solution failed: " + reference_errors[r]);
        tick(task);
        return;
      }
      reference = &references[r];
    }
    started(task);
    try {
      outcomes[i] = execute_run(run.config, registry, study.settings, unit_progress(task), reference,
                                out_dir.empty() ? std::string() : out_dir + "/runs/" + run.id);
    } catch (const IoError& e) {  // its output directory could not be made or written
      outcomes[i] = failed_run_outcome(run, e.what());
      outcomes[i].io_error = e.what();
    } catch (const std::exception& e) {
      outcomes[i] = failed_run_outcome(run, e.what());
    }
    tick(task);
  });
  return outcomes;
}

}  // namespace tsi::app
