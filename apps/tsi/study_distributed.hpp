#pragma once
// A study spread beyond one process: shards for a batch scheduler (`--shard i/N`, then
// `--merge`), and, when built with MPI, ranks of one `mpirun` (study_mpi.cpp).
#include <string>
#include <vector>

#include "run.hpp"
#include "study_spec.hpp"
#include "tsi/plugin_loader.hpp"

namespace tsi::app {

/// The `tsi study` command line.
struct StudyCli {
  std::string study_path;               ///< the study file (absent with --merge)
  std::string out_dir;                  ///< --out (required with --merge)
  int jobs = 0;                         ///< --jobs (0: all cores)
  std::vector<std::string> overrides;   ///< --set
  bool plots = true;                    ///< not --no-plots
  std::string shard;                    ///< --shard i/N ("" : the whole study)
  std::vector<std::string> merge_dirs;  ///< --merge DIR... (empty: no merge)
  bool resume = false;                  ///< --resume: keep the finished runs of this study in --out
  bool force = false;                   ///< --force: replace another study's results in --out
  RunSettings settings;                 ///< --threads, --fft-threads, --max-steps
  bool dry_run = false;                 ///< --dry-run: check and summarise, run and write nothing
  bool quiet = false;                   ///< --quiet: no progress line
};

/// Runs `tsi study` as the command line asks: the whole study (study_command), one shard of
/// it, a merge of shards, or, under mpirun with more than one rank, the study over the ranks.
int study_entry(PluginLoader& loader, Registry& registry, const StudyCli& cli);

/// `--shard i/N`: shards are numbered from 1 to N. ConfigError naming --shard otherwise.
struct ShardSpec {
  long index = 1;  ///< 1 .. count
  long count = 1;
};
ShardSpec parse_shard(const std::string& text);

/// What a run is expected to cost, in arbitrary units: its steps times its tau points times
/// its space points (model.n_x, when the model has one). Used to hand out the longest runs
/// first (MPI) and to balance shards.
double expected_run_cost(const Json& config);

/// The runs (indices into study.runs) of shard `index` of `count`: the runs, longest expected
/// first (ties in study order), each given to the shard with the least expected work so far
/// (ties to the lowest index). Deterministic: depends on the study only.
std::vector<size_t> shard_runs(const Study& study, long index, long count);

#ifdef TSI_WITH_MPI
/// Whether this process was started by mpirun (or another launcher), with any number of ranks.
bool mpi_launched();
/// The study over the ranks of MPI_COMM_WORLD (study_mpi.cpp). Every rank calls it.
int mpi_study_command(PluginLoader& loader, Registry& registry, const StudyCli& cli);
#endif

}  // namespace tsi::app
