#include "study_distributed.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <thread>

#include "config.hpp"
#include "dry_run.hpp"
#include "progress.hpp"
#include "plugin_setup.hpp"
#include "run_files.hpp"
#include "split_processes.hpp"
#include "study_command.hpp"
#include "study_report.hpp"
#include "study_runner.hpp"
#include "tsi/error.hpp"
#include "tsi/output.hpp"
#include "tsi/version.hpp"

namespace tsi::app {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// The file a shard writes next to its runs/, and what it records.
constexpr const char* shard_file = "shard.json";

Study load_study(PluginLoader& loader, Registry& registry, const std::string& study_path,
                 const std::vector<std::string>& overrides, const RunSettings& settings) {
  Json spec = load_config_file(study_path);
  if (spec.is_object() && spec.contains("base") && spec["base"].is_object() && spec["base"].contains("plugins"))
    load_config_plugins(loader, spec["base"]["plugins"], study_path);
  return expand_study(spec, registry, overrides, study_path, settings);
}

int default_jobs(int jobs) {
  return jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// --- one shard --------------------------------------------------------------------------------

int shard_command(PluginLoader& loader, Registry& registry, const StudyCli& cli, const ShardSpec& shard) {
  const Study study = load_study(loader, registry, cli.study_path, cli.overrides, cli.settings);
  const std::string out_dir =
      cli.out_dir.empty()
          ? fmt::format("out/{}-shard-{}-of-{}", fs::path(cli.study_path).stem().string(), shard.index, shard.count)
          : cli.out_dir;
  prepare_output_dir(out_dir);
  {
    std::error_code ec;
    if (fs::exists(fs::path(out_dir) / "study.json", ec))
      throw ConfigError("--out", "\"" + out_dir + "\" holds a whole study (study.json); a shard needs a directory of its own");
    const fs::path previous = fs::path(out_dir) / shard_file;
    if (fs::exists(previous, ec)) {
      Json earlier;
      try {
        earlier = load_config_file(previous.string());
      } catch (const Error&) {
        earlier = Json();
      }
      if (!earlier.is_object() || earlier.value("study", Json()) != study.spec ||
          earlier.value("shard", Json()) != Json{{"index", shard.index}, {"count", shard.count}})
        throw ConfigError("--out", "\"" + out_dir + "\" holds another shard (" +
                                       (earlier.is_object() && earlier.contains("shard") && earlier["shard"].is_object()
                                            ? fmt::format("shard {}/{}", earlier["shard"].value("index", 0L),
                                                          earlier["shard"].value("count", 0L))
                                            : std::string("unreadable")) +
                                       "); choose another --out, or remove that directory");
    }
    fs::remove_all(fs::path(out_dir) / "runs", ec);
    fs::remove(previous, ec);
  }
  const std::vector<size_t> mine = shard_runs(study, shard.index, shard.count);
  Study part = study;
  part.runs.clear();
  for (size_t i : mine) part.runs.push_back(study.runs[i]);
  const int jobs = default_jobs(cli.jobs);

  ProgressLine line(stderr_progress_mode(cli.quiet));
  const auto start = Clock::now();
  if (line.mode() == ProgressMode::terminal)
    fmt::print(stderr, "  shard {}/{}: {} of {} runs on {} threads\n", shard.index, shard.count, part.runs.size(),
               study.runs.size(), jobs);
  const auto outcomes = run_study(part, registry, jobs, line.enabled() ? study_progress(line) : StudyProgressFn(), out_dir);
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  line.finish();  // before the summary

  // Every run's files (a run that could not write its own is exit code 3, as without shards).
  std::vector<std::string> io_errors = io_errors_of(part.runs, outcomes);
  Json runs = Json::array();
  for (size_t k = 0; k < part.runs.size(); ++k) {
    try {
      write_run_files(out_dir + "/runs/" + part.runs[k].id, outcomes[k]);
    } catch (const IoError& e) {
      io_errors.emplace_back(e.what());
    }
    runs.push_back({{"id", part.runs[k].id}, {"ok", outcomes[k].ok}, {"message", outcomes[k].message}});
  }
  std::error_code ec;
  const Json record = {{"tsi_version", version_string},
                       {"study", study.spec},
                       {"study_path", fs::absolute(cli.study_path, ec).lexically_normal().string()},
                       {"shard", {{"index", shard.index}, {"count", shard.count}}},
                       {"total_runs", study.runs.size()},
                       {"jobs", jobs},
                       {"wall_seconds", wall},
                       {"runs", runs}};
  write_file_atomically(out_dir + "/" + shard_file, record.dump(2) + "\n");

  const Json rows = study_rows(part, outcomes);
  size_t completed = 0;
  for (const auto& row : rows) completed += row["status"] == "completed" ? 1 : 0;
  for (const auto& row : rows)
    if (row["status"] != "completed")
      fmt::print("  {} {}: {}\n", row["status"].get<std::string>(), row["id"].get<std::string>(),
                 row["message"].get<std::string>());
  fmt::print("  shard {}/{}: {} of the study's {} runs, {} completed, {} not\n", shard.index, shard.count,
             part.runs.size(), study.runs.size(), completed, part.runs.size() - completed);
  fmt::print("  wall time {:.2f} s on {} threads\n", wall, jobs);
  fmt::print("  written: {0}/{1}, {0}/runs/; merge the {2} shards with: tsi study --merge DIR... --out DIR\n", out_dir,
             shard_file, shard.count);
  return study_exit_code(rows, io_errors);
}

// --- merging shards ---------------------------------------------------------------------------

struct ShardRecord {
  std::string dir;
  Json record;
};

std::string shard_name(const Json& record) {
  return fmt::format("{}/{}", record["shard"].value("index", 0L), record["shard"].value("count", 0L));
}

int merge_command(PluginLoader& loader, Registry& registry, const StudyCli& cli) {
  std::vector<ShardRecord> shards;
  for (const auto& dir : cli.merge_dirs) {
    const fs::path file = fs::path(dir) / shard_file;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
      throw ConfigError("--merge", "\"" + dir + "\" holds no " + shard_file +
                                       ": not the output of tsi study --shard i/N (or that shard has not finished)");
    Json record;
    try {
      record = load_config_file(file.string());
    } catch (const Error& e) {
      throw ConfigError("--merge", "\"" + file.string() + "\" is not a readable shard record: " + e.what());
    }
    if (!record.is_object() || !record.contains("study") || !record.contains("shard") || !record["shard"].is_object() ||
        !record["shard"].contains("index") || !record["shard"].contains("count") || !record.contains("runs") ||
        !record["runs"].is_array())
      throw ConfigError("--merge", "\"" + file.string() + "\" is not a shard record (study, shard, runs)");
    shards.push_back({dir, record});
  }
  const ShardRecord& first = shards.front();
  const long count = first.record["shard"].value("count", 0L);
  std::map<long, const ShardRecord*> by_index;
  for (const auto& s : shards) {
    if (s.record["study"] != first.record["study"])
      throw ConfigError("--merge", fmt::format("\"{}\" (shard {}) is a shard of another study than \"{}\" ({}): "
                                               "only the shards of one study can be merged",
                                               s.dir, shard_name(s.record), first.dir,
                                               first.record["study"].value("title", std::string("untitled"))));
    if (s.record["shard"].value("count", 0L) != count)
      throw ConfigError("--merge", fmt::format("\"{}\" is shard {}, \"{}\" is shard {}: the shards of one merge "
                                               "must come from one split",
                                               s.dir, shard_name(s.record), first.dir, shard_name(first.record)));
    const long index = s.record["shard"].value("index", 0L);
    const auto [it, fresh] = by_index.emplace(index, &s);
    if (!fresh)
      throw ConfigError("--merge", fmt::format("shard {} is given twice: \"{}\" and \"{}\"", shard_name(s.record),
                                               it->second->dir, s.dir));
  }
  std::string missing;
  for (long i = 1; i <= count; ++i)
    if (!by_index.count(i)) missing += (missing.empty() ? "" : ", ") + fmt::format("{}/{}", i, count);
  if (!missing.empty())
    throw ConfigError("--merge", fmt::format("{} {} missing: a merge needs all {} shards of the split",
                                             missing.find(',') == std::string::npos ? "shard " + missing : "shards " + missing,
                                             missing.find(',') == std::string::npos ? "is" : "are", count));

  // The study again, as the shards expanded it (their study already has its --set applied).
  const std::string study_path = first.record.value("study_path", std::string());
  const Json& spec = first.record["study"];
  if (spec.is_object() && spec.contains("base") && spec["base"].is_object() && spec["base"].contains("plugins"))
    load_config_plugins(loader, spec["base"]["plugins"], study_path);
  const Study study = expand_study(spec, registry, {}, study_path, {}, false);  // the runs were built by the shards
  if (first.record.value("total_runs", size_t{0}) != study.runs.size())
    throw ConfigError("--merge", fmt::format("the shards were split from {} runs, the study now expands to {} (another "
                                             "tsi version, or changed plugins?)",
                                             first.record.value("total_runs", size_t{0}), study.runs.size()));
  std::map<std::string, std::pair<const ShardRecord*, const Json*>> owner;  // run id -> shard, its entry
  for (const auto& s : shards)
    for (const auto& run : s.record["runs"]) {
      const std::string id = run.value("id", std::string());
      const auto [it, fresh] = owner.emplace(id, std::make_pair(&s, &run));
      if (!fresh)
        throw ConfigError("--merge", fmt::format("run {} is in two shards: {} (\"{}\") and {} (\"{}\")", id,
                                                 shard_name(it->second.first->record), it->second.first->dir,
                                                 shard_name(s.record), s.dir));
    }
  for (const auto& run : study.runs)
    if (!owner.count(run.id))
      throw ConfigError("--merge", fmt::format("run {} is in no shard (were the shards split with another tsi?)", run.id));
  if (owner.size() != study.runs.size())
    throw ConfigError("--merge", "the shards hold runs the study does not have");

  const std::string out_dir = cli.out_dir;
  prepare_output_dir(out_dir);
  for (const auto& s : shards) {
    std::error_code ec;
    if (fs::equivalent(s.dir, out_dir, ec))
      throw ConfigError("--out", "\"" + out_dir + "\" is one of the shards being merged; choose another directory");
  }
  claim_study_dir(out_dir, study);

  const auto start = Clock::now();
  std::vector<RunOutcome> outcomes(study.runs.size());
  int jobs = 0;
  double wall = 0.0;
  for (const auto& s : shards) {
    jobs += s.record.value("jobs", 1);
    wall += s.record.value("wall_seconds", 0.0);
  }
  for (size_t i = 0; i < study.runs.size(); ++i) {
    const auto& [s, entry] = owner.at(study.runs[i].id);
    const fs::path from = fs::path(s->dir) / "runs" / study.runs[i].id;
    const fs::path to = fs::path(out_dir) / "runs" / study.runs[i].id;
    std::error_code ec;
    if (!fs::is_regular_file(from / "result.json", ec))
      throw ConfigError("--merge", fmt::format("shard {} (\"{}\") lacks runs/{}/result.json", shard_name(s->record),
                                               s->dir, study.runs[i].id));
    fs::create_directories(to, ec);
    fs::copy(from, to, fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
    if (ec) throw Error("cannot copy " + from.string() + " to " + to.string() + ": " + ec.message());
    RunOutcome& o = outcomes[i];
    o.result = load_config_file((to / "result.json").string());
    o.csv_file = (to / "invariants.csv").string();  // on disk, as a streamed run's rows are
    o.ok = entry->value("ok", false);
    o.message = entry->value("message", std::string());
  }
  const Json rows = study_rows(study, outcomes);
  write_study_table(out_dir, study, rows, wall, jobs, {{"shards", count}});
  fmt::print("{}", study_text(study, rows));
  fmt::print("  merged {} shards ({:.2f} s of shard wall time) in {:.2f} s\n", count, wall,
             std::chrono::duration<double>(Clock::now() - start).count());
  fmt::print("  written: {0}/table.csv, {0}/study.json, {0}/runs/\n", out_dir);
  call_plots(out_dir, cli.plots);
  return study_exit_code(rows, {});
}

}  // namespace

ShardSpec parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  auto whole = [](const std::string& s, long& out) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    out = std::stol(s);
    return true;
  };
  ShardSpec spec;
  if (slash == std::string::npos || !whole(text.substr(0, slash), spec.index) || !whole(text.substr(slash + 1), spec.count))
    throw ConfigError("--shard", "got \"" + text + "\", expected i/N with whole numbers, e.g. 1/4 (shards are numbered 1 to N)");
  if (spec.count < 1 || spec.count > max_study_runs)
    throw ConfigError("--shard", fmt::format("got \"{}\": N must be from 1 to {}", text, max_study_runs));
  if (spec.index < 1 || spec.index > spec.count)
    throw ConfigError("--shard", fmt::format("got \"{}\": shards are numbered from 1 to N = {}, so i must be in 1..{}",
                                             text, spec.count, spec.count));
  return spec;
}

double expected_run_cost(const Json& config) {
  const double t_end = config["time"].value("t_end", 1.0), h = config["time"].value("h", 1.0);
  const double steps = h > 0.0 ? std::max(1.0, t_end / h) : 1.0;
  const Json n_tau = config["reformulation"].value("n_tau", Json());
  const Json n_x = config["model"].value("n_x", Json());
  return steps * (n_tau.is_number() ? std::max(1.0, n_tau.get<double>()) : 1.0) *
         (n_x.is_number() ? std::max(1.0, n_x.get<double>()) : 1.0);
}

std::vector<size_t> shard_runs(const Study& study, long index, long count) {
  std::vector<size_t> order(study.runs.size());
  std::vector<double> cost(study.runs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i, cost[i] = expected_run_cost(study.runs[i].config);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cost[a] > cost[b]; });
  std::vector<double> load(static_cast<size_t>(count), 0.0);
  std::vector<size_t> mine;
  for (size_t i : order) {
    const size_t to = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[to] += cost[i];
    if (static_cast<long>(to) == index - 1) mine.push_back(i);
  }
  std::sort(mine.begin(), mine.end());
  return mine;
}

// --- a dry run ------------------------------------------------------------------------------------

// The study (or the shard's part of it) expanded and checked as it would run, summarised on
// stdout; nothing is written. Under mpirun, rank 0 alone says it.
int study_dry_run_command(PluginLoader& loader, Registry& registry, const StudyCli& cli, const ShardSpec& shard) {
  if (launched_rank() != 0) return 0;
  const Study study = load_study(loader, registry, cli.study_path, cli.overrides, cli.settings);
  Study part = study;
  if (!cli.shard.empty()) {
    part.runs.clear();
    for (size_t i : shard_runs(study, shard.index, shard.count)) part.runs.push_back(study.runs[i]);
  }
  std::string text;
  const int rc = study_dry_run(cli.study_path, part, registry, default_jobs(cli.jobs), text);
  if (!cli.shard.empty())
    text += fmt::format("  shard {}/{}: {} of the study's {} runs\n", shard.index, shard.count, part.runs.size(),
                        study.runs.size());
  fmt::print("{}", text);
  return rc;
}

int study_entry(PluginLoader& loader, Registry& registry, const StudyCli& cli) {
  if (!cli.merge_dirs.empty()) {
    if (cli.dry_run) throw ConfigError("--dry-run", "cannot be combined with --merge (which only reads shards)");
    if (!cli.study_path.empty())
      throw ConfigError("--merge", "takes shard directories only, not a study file (got \"" + cli.study_path +
                                       "\" too): tsi study --merge DIR1 DIR2 ... --out DIR");
    if (!cli.shard.empty()) throw ConfigError("--shard", "cannot be combined with --merge");
    if (!cli.overrides.empty()) throw ConfigError("--set", "cannot be combined with --merge: the shards hold their study");
    if (cli.out_dir.empty()) throw ConfigError("--out", "required with --merge: the directory of the merged study");
    return merge_command(loader, registry, cli);
  }
  if (cli.study_path.empty())
    throw ConfigError("study", "missing the study file: tsi study STUDY.json [--out DIR] [--shard i/N], "
                               "or tsi study --merge DIR1 DIR2 ... --out DIR");
  const ShardSpec shard = cli.shard.empty() ? ShardSpec{} : parse_shard(cli.shard);
  if (cli.resume && cli.force) throw ConfigError("--resume", "cannot be combined with --force (which replaces the results)");
  if ((cli.resume || cli.force) && !cli.shard.empty())
    throw ConfigError(cli.resume ? "--resume" : "--force", "applies to a whole study, not to a shard");
  if (cli.dry_run) return study_dry_run_command(loader, registry, cli, shard);
#ifdef TSI_WITH_MPI
  if (mpi_launched()) {
    if (!cli.shard.empty()) throw ConfigError("--shard", "cannot be combined with mpirun: use one or the other");
    if (cli.resume || cli.force)
      throw ConfigError(cli.resume ? "--resume" : "--force", "is not available under mpirun: run without mpirun, "
                                                             "or choose another --out");
    return mpi_study_command(loader, registry, cli);
  }
#endif
  if (!cli.shard.empty()) return shard_command(loader, registry, cli, shard);
  return study_command(loader, registry, cli.study_path, cli.out_dir, cli.jobs, cli.overrides, cli.plots,
                       cli.settings, cli.resume, cli.force);
}

}  // namespace tsi::app
