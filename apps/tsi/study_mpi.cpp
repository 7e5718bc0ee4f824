// `mpirun -np N tsi study STUDY.json --out DIR`: the runs of a study over the ranks of
// MPI_COMM_WORLD, with dynamic load balancing.
//
// Rank 0 hands out the work: first the shared references (each computed once, by whichever
// rank asks first), then the runs, longest expected first (expected_run_cost). A run whose
// reference is not computed yet waits for it; the reference is sent along with the first run
// a rank gets that needs it, and kept there. Every rank, rank 0 included (on a thread of its
// own), computes; each run's files are written by the rank that ran it, and the table,
// study.json and plots once, by rank 0, as `--jobs 1` writes them.
//
// Messages are JSON text (MPI_CHAR). Waiting is by MPI_Iprobe and short sleeps, not blocking
// receives: Open MPI's blocking receive spins at 100% CPU, which would take a core from the
// runs when the ranks share the machine.
#include <fmt/format.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <functional>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "config.hpp"
#include "interrupt.hpp"
#include "plugin_setup.hpp"
#include "run_files.hpp"
#include "progress.hpp"
#include "study_command.hpp"
#include "study_distributed.hpp"
#include "study_runner.hpp"
#include "study_report.hpp"
#include "tsi/error.hpp"
#include "tsi/fft.hpp"

namespace tsi::app {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int tag_to_master = 1, tag_to_worker = 2;

// --- messages -------------------------------------------------------------------------------

void send_json(const Json& message, int destination, int tag) {
  const std::string text = message.dump(-1, ' ', false, Json::error_handler_t::replace);
  MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, destination, tag, MPI_COMM_WORLD);
}

// A message from `source` (or any) with `tag`, if one has arrived.
std::optional<std::pair<int, Json>> try_receive(int source, int tag) {
  int flag = 0;
  MPI_Status status;
  MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, &status);
  if (!flag) return std::nullopt;
  int size = 0;
  MPI_Get_count(&status, MPI_CHAR, &size);
  std::string text(static_cast<size_t>(size), '\0');
  MPI_Recv(text.data(), size, MPI_CHAR, status.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return std::make_pair(status.MPI_SOURCE, Json::parse(text));
}

// Waits (without spinning a core) for a message.
Json receive(int source, int tag) {
  for (int idle = 0;; ++idle) {
    if (auto m = try_receive(source, tag)) return m->second;
    if (idle > 100) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

Json reference_to_json(const ReferenceSolution& r) {
  Json re = Json::array(), im = Json::array();
  for (Index i = 0; i < r.x.size(); ++i) re.push_back(to_double(r.x(i).real())), im.push_back(to_double(r.x(i).imag()));
  return {{"re", re}, {"im", im}, {"wall_seconds", r.wall_seconds},
          {"accuracy", std::isnan(r.accuracy) ? Json() : Json(r.accuracy)}, {"settings", r.settings}};
}

ReferenceSolution reference_from_json(const Json& j) {
  ReferenceSolution r;
  r.x.resize(static_cast<Index>(j["re"].size()));
  for (Index i = 0; i < r.x.size(); ++i)
    r.x(i) = Complex(j["re"][static_cast<size_t>(i)].get<double>(), j["im"][static_cast<size_t>(i)].get<double>());
  r.wall_seconds = j["wall_seconds"];
  r.accuracy = j["accuracy"].is_number() ? j["accuracy"].get<double>() : std::numeric_limits<double>::quiet_NaN();
  r.settings = j["settings"];
  return r;
}

Json outcome_to_json(const RunOutcome& o) {
  return {{"result", o.result}, {"csv", o.csv},         {"csv_file", o.csv_file},
          {"ok", o.ok},         {"message", o.message}, {"io_error", o.io_error}};
}

RunOutcome outcome_from_json(const Json& j) {
  RunOutcome o;
  o.result = j["result"];
  o.csv = j["csv"];
  o.csv_file = j["csv_file"];
  o.ok = j["ok"];
  o.message = j["message"];
  o.io_error = j["io_error"];
  return o;
}

RunOutcome not_run(const StudyRun& run) {
  RunOutcome o = failed_run_outcome(run, fmt::format("not run: the study was interrupted by signal {}", interrupt_signal()));
  o.result["status"] = "interrupted";
  return o;
}

// Writes a run's files; a failure to write is the run's failure, reported in the table.
void write_run(const std::string& out_dir, const StudyRun& run, RunOutcome& outcome) {
  try {
    write_run_files(out_dir + "/runs/" + run.id, outcome);
  } catch (const std::exception& e) {
    outcome.ok = false;
    outcome.io_error = e.what();
    outcome.message = std::string("its files could not be written: ") + e.what();
    outcome.result["status"] = "failed";
    outcome.result["message"] = outcome.message;
  }
}

// --- what every rank knows: the study and its distinct references ------------------------------

struct Plan {
  Study study;
  std::string out_dir;
  std::vector<size_t> reference_run;     ///< per reference: the first run that needs it
  std::vector<long> run_reference;       ///< per run: its reference (-1: none)
};

Plan make_plan(PluginLoader& loader, Registry& registry, const StudyCli& cli) {
  Plan p;
  Json spec = load_config_file(cli.study_path);
  if (spec.is_object() && spec.contains("base") && spec["base"].is_object() && spec["base"].contains("plugins"))
    load_config_plugins(loader, spec["base"]["plugins"], cli.study_path);
  p.study = expand_study(spec, registry, cli.overrides, cli.study_path, cli.settings);
  p.out_dir = cli.out_dir.empty() ? "out/" + std::filesystem::path(cli.study_path).stem().string() : cli.out_dir;
  std::map<std::string, long> index;
  for (size_t i = 0; i < p.study.runs.size(); ++i) {
    const Json& config = p.study.runs[i].config;
    long r = -1;
    if (config.contains("reference")) {
      const auto [it, fresh] = index.emplace(reference_key(config), static_cast<long>(p.reference_run.size()));
      if (fresh) p.reference_run.push_back(i);
      r = it->second;
    }
    p.run_reference.push_back(r);
  }
  return p;
}

// --- a worker: does what it is given ------------------------------------------------------------

class Worker {
 public:
  Worker(const Plan& plan, const Registry& registry) : plan_(plan), registry_(registry) {}

  Json execute(const Json& task) {
    const long index = task["index"];
    if (task["kind"] == "reference") {
      Json reply = {{"kind", "reference"}, {"index", index}};
      try {
        const ReferenceSolution r =
            compute_reference(plan_.study.runs[plan_.reference_run[static_cast<size_t>(index)]].config, registry_,
                              plan_.study.settings);
        references_[index] = r;
        reply["ok"] = true;
        reply["reference"] = reference_to_json(r);
      } catch (const std::exception& e) {
        reply["ok"] = false;
        reply["error"] = e.what();
      }
      return reply;
    }
    const StudyRun& run = plan_.study.runs[static_cast<size_t>(index)];
    const long r = plan_.run_reference[static_cast<size_t>(index)];
    if (task.contains("reference")) references_[r] = reference_from_json(task["reference"]);
    RunOutcome outcome;
    if (interrupted()) {
      outcome = not_run(run);
    } else {
      try {
        outcome = execute_run(run.config, registry_, plan_.study.settings, {}, r >= 0 ? &references_.at(r) : nullptr,
                              plan_.out_dir + "/runs/" + run.id);
      } catch (const IoError& e) {  // its output directory could not be made or written
        outcome = failed_run_outcome(run, e.what());
        outcome.io_error = e.what();
      } catch (const std::exception& e) {
        outcome = failed_run_outcome(run, e.what());
      }
    }
    write_run(plan_.out_dir, run, outcome);
    return {{"kind", "run"}, {"index", index}, {"outcome", outcome_to_json(outcome)}};
  }

 private:
  const Plan& plan_;
  const Registry& registry_;
  std::map<long, ReferenceSolution> references_;
};

// Rank 0's own worker, on a thread: tasks in, replies out, through a mutex.
class LocalWorker {
 public:
  LocalWorker(const Plan& plan, const Registry& registry) : worker_(plan, registry), thread_([this] { loop(); }) {}
  ~LocalWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  void give(Json task) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      task_ = std::move(task);
    }
    wake_.notify_all();
  }
  std::optional<Json> take_reply() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<Json> r;
    r.swap(reply_);
    return r;
  }

 private:
  void loop() {
    for (;;) {
      Json task;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [this] { return stop_ || task_.has_value(); });
        if (stop_) return;
        task = std::move(*task_);
        task_.reset();
      }
      Json reply;
      try {
        reply = worker_.execute(task);
      } catch (const std::exception& e) {  // execute catches the run's own errors; this is the rest
        reply = {{"kind", "fatal"}, {"error", e.what()}};
      }
      std::lock_guard<std::mutex> lock(mutex_);
      reply_ = std::move(reply);
    }
  }

  Worker worker_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Json> task_, reply_;
  bool stop_ = false;
  std::thread thread_;  // last: started once the rest exists
};

int worker_main(const Plan& plan, const Registry& registry) {
  Worker worker(plan, registry);
  send_json({{"kind", "ready"}}, 0, tag_to_master);
  for (;;) {
    const Json task = receive(0, tag_to_worker);
    if (task["kind"] == "stop") return 0;
    Json reply;
    try {
      reply = worker.execute(task);
    } catch (const std::exception& e) {
      reply = {{"kind", "fatal"}, {"error", e.what()}};
    }
    send_json(reply, 0, tag_to_master);
  }
}

// --- rank 0: hands out the work and writes the study ----------------------------------------------

class Master {
 public:
  Master(const Plan& plan, int ranks) : plan_(plan), ranks_(ranks) {
    const size_t n_ref = plan.reference_run.size(), n_run = plan.study.runs.size();
    reference_state_.assign(n_ref, State::pending);
    references_.resize(n_ref);
    reference_errors_.resize(n_ref);
    run_state_.assign(n_run, State::pending);
    outcomes_.resize(n_run);
    has_reference_.resize(static_cast<size_t>(ranks));
    // Longest first: references by the cost of the longest run that needs them (their own
    // cost grows with t_end / eps as the runs' does not), runs by their expected cost.
    std::vector<double> cost(n_run), reference_cost(n_ref, 0.0);
    for (size_t i = 0; i < n_run; ++i) {
      cost[i] = expected_run_cost(plan.study.runs[i].config);
      if (plan.run_reference[i] >= 0) {
        const Json& c = plan.study.runs[i].config;
        double& rc = reference_cost[static_cast<size_t>(plan.run_reference[i])];
        rc = std::max(rc, c["time"].value("t_end", 1.0) / c["model"].value("eps", 1.0));
      }
    }
    for (size_t i = 0; i < n_run; ++i) run_order_.push_back(i);
    std::stable_sort(run_order_.begin(), run_order_.end(), [&](size_t a, size_t b) { return cost[a] > cost[b]; });
    for (size_t r = 0; r < n_ref; ++r) reference_order_.push_back(r);
    std::stable_sort(reference_order_.begin(), reference_order_.end(),
                     [&](size_t a, size_t b) { return reference_cost[a] > reference_cost[b]; });
    total_ = n_ref + n_run;
  }

  std::vector<RunOutcome> run(const Registry& registry, const std::function<void(size_t, size_t)>& progress) {
    LocalWorker local(plan_, registry);
    std::set<int> idle;                 // ranks waiting for a task
    std::set<int> busy;                 // ranks with a task
    idle.insert(0);
    for (bool working = true; working;) {
      bool news = false;
      if (auto reply = local.take_reply()) {
        handle(0, *reply, idle, busy);
        news = true;
      }
      while (auto m = try_receive(MPI_ANY_SOURCE, tag_to_master)) {
        handle(m->first, m->second, idle, busy);
        news = true;
      }
      if (news && progress) progress(done_, total_);
      for (auto it = idle.begin(); it != idle.end();) {
        std::optional<Json> task = next_task(*it);
        if (!task) break;
        if (*it == 0)
          local.give(std::move(*task));
        else
          send_json(*task, *it, tag_to_worker);
        busy.insert(*it);
        it = idle.erase(it);
      }
      working = done_ < total_;
      if (!news && working) std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    for (int rank = 1; rank < ranks_; ++rank) send_json({{"kind", "stop"}}, rank, tag_to_worker);
    return std::move(outcomes_);
  }

 private:
  enum class State { pending, assigned, done };

  void handle(int rank, const Json& m, std::set<int>& idle, std::set<int>& busy) {
    busy.erase(rank);
    if (m["kind"] == "fatal") {  // the rank cannot go on: its task goes back to the others
      fmt::print(stderr, "tsi: rank {} stopped: {}\n", rank, m.value("error", std::string()));
      dead_.insert(rank);
      if (const auto it = assigned_.find(rank); it != assigned_.end()) {
        (it->second.first ? reference_state_[it->second.second] : run_state_[it->second.second]) = State::pending;
        assigned_.erase(it);
      }
      if (dead_.size() == static_cast<size_t>(ranks_)) throw Error("every rank stopped: " + m.value("error", std::string()));
      return;
    }
    assigned_.erase(rank);
    idle.insert(rank);
    if (m["kind"] == "reference") {
      const size_t r = m["index"];
      if (m["ok"].get<bool>()) {
        references_[r] = m["reference"];
        has_reference_[static_cast<size_t>(rank)].insert(r);
      } else {
        reference_errors_[r] = m["error"];
      }
      reference_state_[r] = State::done;
      ++done_;
    } else if (m["kind"] == "run") {
      const size_t i = m["index"];
      outcomes_[i] = outcome_from_json(m["outcome"]);
      run_state_[i] = State::done;
      ++done_;
    }
  }

  // The next task for `rank`, or none for now. Runs that cannot run (their reference failed,
  // or the study was interrupted) are settled here, on rank 0.
  std::optional<Json> next_task(int rank) {
    if (dead_.count(rank)) return std::nullopt;
    const bool stopping = interrupted();
    for (size_t r : reference_order_) {
      if (reference_state_[r] != State::pending) continue;
      if (stopping) {
        reference_errors_[r] = fmt::format("not computed: the study was interrupted by signal {}", interrupt_signal());
        reference_state_[r] = State::done;
        ++done_;
        continue;
      }
      reference_state_[r] = State::assigned;
      assigned_[rank] = {true, r};
      return Json{{"kind", "reference"}, {"index", r}};
    }
    for (size_t i : run_order_) {
      if (run_state_[i] != State::pending) continue;
      const StudyRun& run = plan_.study.runs[i];
      const long r = plan_.run_reference[i];
      if (stopping) {
        settle(i, not_run(run));
        continue;
      }
      if (r >= 0 && reference_state_[static_cast<size_t>(r)] != State::done) continue;  // not yet
      if (r >= 0 && !reference_errors_[static_cast<size_t>(r)].empty()) {
        settle(i, failed_run_outcome(run, "the reference solution failed: " + reference_errors_[static_cast<size_t>(r)]));
        continue;
      }
      Json task = {{"kind", "run"}, {"index", i}};
      if (r >= 0 && has_reference_[static_cast<size_t>(rank)].insert(static_cast<size_t>(r)).second)
        task["reference"] = references_[static_cast<size_t>(r)];
      run_state_[i] = State::assigned;
      assigned_[rank] = {false, i};
      return task;
    }
    return std::nullopt;
  }

  void settle(size_t i, RunOutcome outcome) {
    write_run(plan_.out_dir, plan_.study.runs[i], outcome);
    outcomes_[i] = std::move(outcome);
    run_state_[i] = State::done;
    ++done_;
  }

  const Plan& plan_;
  int ranks_;
  size_t total_ = 0, done_ = 0;
  std::vector<State> reference_state_, run_state_;
  std::vector<Json> references_;
  std::vector<std::string> reference_errors_;
  std::vector<RunOutcome> outcomes_;
  std::vector<size_t> run_order_, reference_order_;
  std::vector<std::set<size_t>> has_reference_;
  std::map<int, std::pair<bool, size_t>> assigned_;  // rank -> (is a reference, index)
  std::set<int> dead_;
};

}  // namespace

bool mpi_launched() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"}) {
    const char* value = std::getenv(name);
    if (value && std::atoi(value) >= 1) return true;
  }
  return false;
}

int mpi_study_command(PluginLoader& loader, Registry& registry, const StudyCli& cli) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  struct Finalize {
    ~Finalize() { MPI_Finalize(); }
  } finalize;
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);

  // Rank 0 checks the study and --out first; the others start only once it has.
  std::optional<Plan> plan;
  std::exception_ptr failure;
  int ok = 1;
  if (rank == 0) {
    try {
      plan = make_plan(loader, registry, cli);
      prepare_output_dir(plan->out_dir);
      claim_study_dir(plan->out_dir, plan->study);
    } catch (...) {
      failure = std::current_exception();
      ok = 0;
    }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!ok) {
    if (failure) std::rethrow_exception(failure);  // reported once, by rank 0
    return 2;
  }
  { const FftBatch warm_up(2, 1); }  // as run_study: FFTW's planner set-up is charged to no run

  if (rank != 0) {
    try {
      plan = make_plan(loader, registry, cli);
    } catch (const std::exception& e) {
      send_json({{"kind", "fatal"}, {"error", e.what()}}, 0, tag_to_master);
      while (receive(0, tag_to_worker)["kind"] != "stop") {
      }
      return 2;
    }
    return worker_main(*plan, registry);
  }

  ProgressLine line(stderr_progress_mode(cli.quiet));  // rank 0's only
  const auto start = Clock::now();
  const StudyProgressFn show = study_progress(line);
  if (cli.jobs > 1) fmt::print(stderr, "tsi: note: --jobs is not used under mpirun; each rank runs one run at a time\n");
  if (line.mode() == ProgressMode::terminal) fmt::print(stderr, "  {} runs on {} MPI ranks\n", plan->study.runs.size(), ranks);
  std::vector<RunOutcome> outcomes;
  try {
    outcomes = Master(*plan, ranks).run(registry, [&](size_t done, size_t total) {
      if (line.enabled()) show({done, total, 0, 0.0, std::string(), 0.0});
    });
  } catch (const std::exception& e) {
    line.finish();
    fmt::print(stderr, "tsi: error: {}\n", e.what());
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 3);
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  line.finish();  // before the tables

  const Json rows = study_rows(plan->study, outcomes);
  write_study_table(plan->out_dir, plan->study, rows, wall, ranks, {{"mpi_ranks", ranks}});
  fmt::print("{}", study_text(plan->study, rows));
  fmt::print("  wall time {:.2f} s on {} MPI ranks\n", wall, ranks);
  fmt::print("  written: {0}/table.csv, {0}/study.json, {0}/runs/\n", plan->out_dir);
  call_plots(plan->out_dir, cli.plots);
  return study_exit_code(rows, io_errors_of(plan->study.runs, outcomes));
}

}  // namespace tsi::app
