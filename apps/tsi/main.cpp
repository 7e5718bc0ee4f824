// tsi: the runner. Wires model, reformulation and scheme together from a JSON config.
//   tsi list [models|reformulations|schemes|fields] [--json]   (entries of --plugin FILE marked)
//   tsi run CONFIG.json [--out DIR] [--set key.path=value ...] [--max-steps N] [--dry-run] [--quiet]
//   tsi study STUDY.json [--out DIR] [--jobs N] [--shard i/N] [--max-steps N] [--resume | --force] [--dry-run] [--quiet]
//   tsi study --merge DIR... --out DIR;  -h: short help, --help: long help
// Exit codes: 0 success, 1 a run failed (its files are still written), 2 bad input, 3 an output
// could not be written (what could be is kept valid), 128 + N interrupted by signal N.
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "check_command.hpp"
#include "interrupt.hpp"
#include "config.hpp"
#include "dry_run.hpp"
#include "help_text.hpp"
#include "list_command.hpp"
#include "plugin_setup.hpp"
#include "progress.hpp"
#include "run.hpp"
#include "run_files.hpp"
#include "split_processes.hpp"
#include "study_command.hpp"
#include "study_distributed.hpp"
#include "summary.hpp"
#include "tsi/error.hpp"
#include "tsi/stop_request.hpp"
#include "tsi/fft.hpp"
#include "tsi/context.hpp"
#include "tsi/version.hpp"

namespace {

using tsi::Json;

int run_command(tsi::PluginLoader& loader, tsi::Registry& registry, const std::string& config_path,
                std::string out_dir, const std::vector<std::string>& overrides, const tsi::app::RunSettings& settings,
                bool dry_run, bool quiet) {
  Json raw = tsi::app::load_config_file(config_path);
  for (const auto& assignment : overrides) tsi::app::apply_override(raw, assignment);
  tsi::app::resolve_config_files(raw, config_path);  // model.u0 as a file: relative to the config, as plugins
  if (raw.is_object() && raw.contains("plugins"))
    tsi::app::load_config_plugins(loader, raw["plugins"], config_path);
  const Json config = tsi::app::resolve_run_config(raw, registry);
  // Too many steps are refused before --out is touched; the reference's cost after the run's
  // own objects are checked (their memory first), still before anything is computed.
  tsi::app::check_run_steps(config, settings.max_steps);
  if (out_dir.empty()) out_dir = "out/" + std::filesystem::path(config_path).stem().string();
  if (dry_run) return tsi::app::run_dry_run(config_path, config, registry, settings, out_dir);  // writes nothing
  const tsi::Collective* split = settings.context.collective;
  const bool writer = !split || split->rank() == 0;  // a split run's files are rank 0's
  if (split) {
    tsi::app::agree_to_start(*split, config, registry, settings, [&] { if (writer) tsi::app::prepare_output_dir(out_dir); });
  } else {
    tsi::app::prepare_output_dir(out_dir);
  }

  // The progress line: rank 0's only; erased before the summary (and before an error).
  tsi::app::ProgressLine line(writer ? tsi::app::stderr_progress_mode(quiet) : tsi::app::ProgressMode::off);
  tsi::app::StepProgressLine progress(line);
  tsi::app::RunSettings run_settings = settings;
  if (split) run_settings.split_dir = out_dir;  // every process writes its share of a large state there
  const tsi::app::RunOutcome outcome =
      tsi::app::execute_run(config, registry, run_settings, line.enabled() ? tsi::app::ProgressFn(std::ref(progress)) : nullptr,
                            nullptr, writer ? out_dir : std::string());
  line.finish();
  if (!writer) return outcome.ok ? 0 : 1;  // the same status on every rank: its stops are agreed
  tsi::app::write_run_files(out_dir, outcome);  // IoError (exit 3) when result.json cannot be written
  fmt::print("{}", tsi::app::run_summary(outcome, out_dir));
  if (!outcome.io_error.empty()) {  // the run's own files are written as far as they could be
    spdlog::error("{}", outcome.message);
    return 3;
  }
  if (!outcome.ok) {
    spdlog::error("run {}: {}", outcome.result.value("status", std::string("failed")), outcome.message);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_default_logger(spdlog::stderr_color_st("tsi"));
  spdlog::set_pattern("tsi: %^%l%$: %v");

  CLI::App app{"tsi: uniformly accurate two-scale integrators for highly oscillatory systems"};
  // Command-line mistakes read like every other bad input: "tsi: error: --OPTION: message".
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "tsi: error: " + std::string(e.what()) + "\nRun with --help for more information.\n";
  });
  app.require_subcommand(1);
  // -h the short help (the options), --help the long one (with exit codes and examples); both on
  // stdout. Set before the subcommands, which take them over.
  app.set_help_flag("-h", "print the short help (the options) and exit");
  app.set_help_all_flag("--help", "print the long help (what is written, exit codes, examples) and exit");
  app.set_version_flag("--version", tsi::version_string);
  std::vector<std::string> plugin_files;
  app.add_option("--plugin", plugin_files, "load a plugin library (repeatable)")->check(CLI::ExistingFile);
  int fft_threads = 1;
  app.add_option("--fft-threads", fft_threads,
                 "threads for each FFT batch of at least 65536 values (NLS from n_x = 256 with n_tau = 256; "
                 "measured 1.2x faster on 2 cores there, slower on smaller grids); default 1")
      ->check(CLI::Range(1, 1024));
  int threads = 0;  // 0: the default below
  app.add_option("--threads", threads,
                 "threads for one two-scale run's tau grid (field and tau transforms), used where the grid has at "
                 "least 4096 values (NLS and Klein-Gordon from n_x = 16 at n_tau = 256: 1.4-2.1x on 2 cores; "
                 "smaller grids lose); default: all cores for run, 1 per run for study and check (their runs "
                 "already share the cores)")
      ->check(CLI::Range(1, 1024));

  auto* list = app.add_subcommand("list", "list registered models, reformulations, schemes and fields (those of --plugin FILE marked)");
  std::string what;
  bool as_json = false;
  list->add_option("what", what,
                   "models, reformulations, schemes or fields (default: all four); config: the run config's "
                   "sections and keys");
  list->add_flag("--json", as_json, "print JSON");

  auto* run = app.add_subcommand("run", "run one config and write result.json and invariants.csv");
  std::string config_path, out_dir;
  std::vector<std::string> overrides;
  run->add_option("config", config_path, "the run config (JSON)")->required();
  run->add_option("--out", out_dir, "output directory (default: out/<config name>)");
  run->add_option("--set", overrides, "override a config value: key.path=value (repeatable)");
  double max_steps = tsi::app::default_max_steps;
  const std::string max_steps_help =
      "refuse a run (or its reference) estimated to take more than N steps, before it starts (default 1e9)";
  run->add_option("--max-steps", max_steps, max_steps_help);
  std::string device = "cpu";
  run->add_option("--device", device,
                  "where the steps run: cpu, or cuda (a build with TSI_WITH_CUDA: the two-scale NLS with se1 or eab "
                  "on the GPU; docs/how-to/gpu.md)")
      ->check(CLI::IsMember({"cpu", "cuda"}));
  bool dry_run = false, quiet = false;
  run->add_flag("--dry-run", dry_run, "check the config as a run would and print its steps, memory and reference; "
                                      "run and write nothing");
  run->add_flag("--quiet,-q", quiet, "no progress line");
  bool split = false;
  run->add_flag("--split", split,
                "split the run's state over MPI ranks: mpirun -np P tsi run CONFIG --split (vlasov-poisson-2d's "
                "particles; nls, klein-gordon and klein-gordon-complex in 2-D and 3-D: slabs of the grid, n_x and "
                "n_y multiples of P; one thread per rank unless --threads; rank 0 writes the files)");

  auto* study = app.add_subcommand("study", "run a study (a base config and lists of values) in parallel");
  std::string study_path, study_out;
  int jobs = 0;
  bool no_plots = false;
  std::vector<std::string> study_overrides;
  std::string shard;
  std::vector<std::string> merge_dirs;
  study->add_option("study", study_path, "the study file (JSON); absent with --merge");
  study->add_option("--out", study_out, "output directory (default: out/<study name>)");
  study->add_option("--jobs,-j", jobs, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  study->add_option("--set", study_overrides, "override a value of the base config: key.path=value");
  study->add_flag("--no-plots", no_plots, "do not call the plotting script");
  study->add_option("--max-steps", max_steps, max_steps_help + " (each run)");
  study->add_option("--shard", shard, "run only shard i of N (i = 1..N) into --out; see --merge");
  study->add_option("--merge", merge_dirs, "merge the output directories of all shards of a study into --out")
      ->expected(1, -1);
  bool resume = false, force = false;
  study->add_flag("--resume", resume, "keep the runs of this study that finished in --out (an interrupted study), run the rest");
  study->add_flag("--force", force, "replace the results of another study in --out instead of refusing");
  study->add_flag("--dry-run", dry_run, "check every run as it would run and print their steps, memory and "
                                        "references; run and write nothing");
  study->add_flag("--quiet,-q", quiet, "no progress line");

  // tsi check [MODEL] [--plugin FILE] [--scheme NAME] [--eps EPS] (check_command.hpp)
  auto* check = app.add_subcommand("check", "run the conformance checks on a model or plugin");
  tsi::app::CheckOptions check_options;
  check->add_option("model", check_options.model, "the model to check (default: the plugins' models, or all)");
  check->add_option("--plugin", check_options.plugins, "load this plugin and check what it provides")
      ->check(CLI::ExistingFile);
  check->add_option("--scheme", check_options.schemes, "check with this two-scale scheme only (repeatable)");
  check->add_option("--eps", check_options.epsilons, "eps of the order checks (repeatable; default: the model's declared regime)");
  check->add_option("--steps", check_options.steps,
                    "numbers of steps over T = 1 of the order fits (repeatable, increasing; default: the model's regime)");
  std::vector<std::string> check_overrides;
  check->add_option("--set", check_overrides,
                    "a parameter of the model, the two-scale reformulation or the schemes checked: model.KEY=VALUE, "
                    "reformulation.KEY=VALUE or scheme.KEY=VALUE (repeatable), e.g. model.n_x=64, reformulation.n_tau=128, "
                    "scheme.order=3");
  // The runner's own options (--plugin) may also follow a subcommand: tsi run CONFIG --plugin FILE.
  for (auto* sub : app.get_subcommands([](CLI::App*) { return true; })) sub->fallthrough();
  // end tsi check

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (dynamic_cast<const CLI::CallForAllHelp*>(&e)) {  // --help: what -h leaves out, after the options
      app.footer(tsi::app::long_help(""));
      for (auto* sub : app.get_subcommands([](CLI::App*) { return true; })) sub->footer(tsi::app::long_help(sub->get_name()));
    }
    return app.exit(e) == 0 ? 0 : 2;
  }
  // A run or study stops at its next step on SIGINT or SIGTERM and writes what it has; the
  // exit code is then the shell's for that signal (128 + signal), after the files are on disk.
  // Installed before anything is read, so that a signal at any moment of a run is kept.
  if (run->parsed() || study->parsed()) tsi::app::install_interrupt_handlers();

  std::unique_ptr<tsi::Collective> processes;  // tsi run --split: MPI's ranks, finalised last
  try {
    if (run->parsed() && split) {
      processes = tsi::app::start_split_processes();
    } else if (run->parsed() && tsi::app::launched_processes() > 1) {
      if (tsi::app::launched_rank() != 0) throw tsi::app::ReportedElsewhere("launched without --split");
      throw tsi::ConfigError("--split", fmt::format("tsi run was started on {} MPI processes without --split: each "
                                                    "would run the whole run and write the same files; add --split "
                                                    "to split one run over them, or use tsi study for many runs",
                                                    tsi::app::launched_processes()));
    }
    // The run's settings, built once from the flags and passed down (nothing process wide):
    // a run's tau grid on every core unless --threads says otherwise, a study's runs on one
    // each, a split run's ranks on one each (one rank per core).
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    tsi::app::RunSettings settings = tsi::app::RunSettings::from_flags(
        threads > 0 ? threads : run->parsed() && !processes ? cores : 1, fft_threads, max_steps);
    settings.context.collective = processes.get();
    settings.device = device;
    tsi::Registry registry;
    tsi::PluginLoader loader(registry);
    for (const auto& warning : tsi::app::load_plugins(loader, registry, plugin_files))
      spdlog::warn("plugin not loaded: {}", warning);
    if (list->parsed()) {
      // the entries of the --plugin files are marked: what a plugin added, at a glance
      fmt::print("{}", as_json ? tsi::app::list_json(registry, what, plugin_files).dump(2) + "\n"
                               : tsi::app::list_text(registry, what, plugin_files));
      return 0;
    }
    if (check->parsed()) {
      tsi::Json check_sections = {{"model", tsi::Json::object()},
                                  {"reformulation", tsi::Json::object()},
                                  {"scheme", tsi::Json::object()}};
      for (const auto& assignment : check_overrides) {
        if (assignment.rfind("model.", 0) != 0 && assignment.rfind("reformulation.", 0) != 0 &&
            assignment.rfind("scheme.", 0) != 0)
          throw tsi::ConfigError("check --set", "got \"" + assignment +
                                                    "\", expected model.KEY=VALUE, reformulation.KEY=VALUE or "
                                                    "scheme.KEY=VALUE");
        tsi::app::apply_override(check_sections, assignment);
      }
      check_options.model_params = check_sections["model"];
      check_options.reformulation_params = check_sections["reformulation"];
      check_options.scheme_params = check_sections["scheme"];
      return tsi::app::check_command(loader, registry, check_options, plugin_files);
    }
    const int rc = study->parsed()
                       ? tsi::app::study_entry(loader, registry,
                                               {study_path, study_out, jobs, study_overrides, !no_plots, shard, merge_dirs, resume, force,
                                                settings, dry_run, quiet})
                       : run_command(loader, registry, config_path, out_dir, overrides, settings, dry_run, quiet);
    if (tsi::app::interrupted() && rc != 3) {  // an output that failed is said first
      spdlog::error("interrupted by signal {}: what was computed is written", tsi::app::interrupt_signal());
      return 128 + tsi::app::interrupt_signal();
    }
    return rc;
  } catch (const tsi::Interrupted& e) {  // a stop asked for during a set-up: nothing computed yet
    spdlog::error("{}", e.what());
    return 128 + e.signal();
  } catch (const tsi::IoError& e) {  // an output could not be written: not the input's fault
    spdlog::error("{}", e.what());
    return 3;
  } catch (const tsi::Error& e) {
    // A split run's ranks refuse a bad input alike (tsi::app::agree_to_start): said once.
    if (!dynamic_cast<const tsi::app::ReportedElsewhere*>(&e)) spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("unexpected: {}", e.what());
    return 2;
  }
}
