#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "progress.hpp"
#include "tsi/assembly.hpp"
#include "tsi/collective.hpp"
#include "tsi/error.hpp"
#include "tsi/params.hpp"
#include "tsi/registry.hpp"

namespace tsi::app {

/// Everything a run produced, kept even when it failed part-way.
struct RunOutcome {
  Json result;       ///< the content of result.json
  std::string csv;       ///< the content of invariants.csv (when it was not streamed to csv_file)
  std::string csv_file;  ///< where its rows were streamed as they were computed (empty: in csv)
  bool ok = true;
  std::string message;  ///< why the run failed (empty when ok)
  std::string io_error;  ///< an output that could not be written (IoError: exit code 3); empty otherwise
  /// The final state in physical variables (result.json's u_final) and the reference's (its
  /// error.reference.u_final), written to u_final.npy and reference_u_final.npy; empty when
  /// the run never started (or its outcome was read back from its files).
  Vector u_final, reference_u_final;
  /// A split run's large states (write_split_state): written by every process, so not held
  /// here; the first values of u_final and the counts of values written, for the summary.
  Vector u_final_head;
  Index u_final_written = 0, reference_written = 0;
  /// u at output.times (physical variables, one state per time; empty where the run did not
  /// reach it), written to u_times.npy (NaN there).
  std::vector<double> output_times;
  std::vector<Vector> u_times;
  bool complex_state = false;             ///< complex128 files (a complex model), else float64
  std::vector<std::uint64_t> state_shape;  ///< the files' shape: model.u0's file's, else (dim,)
};

/// States up to this many values are written inline into result.json (u_final, and the
/// reference's); larger ones only as {"file": "u_final.npy", "dtype": ..., "shape": [...]}.
inline constexpr Index max_inline_state = 4096;

/// The file names of the states beside result.json.
inline constexpr const char* u_final_file = "u_final.npy";
inline constexpr const char* reference_u_final_file = "reference_u_final.npy";
inline constexpr const char* u_times_file = "u_times.npy";

/// The reference solution at t_end (physical variables) and how good it is.
struct ReferenceSolution {
  Vector x;
  double wall_seconds = 0.0;
  /// Relative difference to a second run at tighter settings (tol / 10, twice the substeps
  /// per fast period): an estimate of the reference's own error. NaN when not estimated.
  double accuracy = 0.0;
  Json settings;  ///< the resolved reference section
};

/// The most steps a run (t_end / time.h) or its reference may take unless --max-steps says
/// otherwise: generous (hours of work for the cheapest scheme), but a typo's 1e12 is refused.
inline constexpr double default_max_steps = 1e9;

/// What the runner's flags give a run besides its config, built once (tsi run and study, the
/// Python module's run) and passed down: the threads it may use and the most steps it or its
/// reference may take. Nothing is set process wide.
struct RunSettings {
  Context context;                       ///< --threads (its tau grid), --fft-threads (FFTW's own)
  double max_steps = default_max_steps;  ///< --max-steps
  /// --device: "cpu", or "cuda" (the steps on the GPU: tsi/device.hpp; a build with TSI_WITH_CUDA).
  std::string device = "cpu";
  /// tsi run --split: the output directory, on every process (each writes its share of a grid
  /// model's state files of more than max_inline_state values there); empty otherwise.
  std::string split_dir{};
  /// The settings of these flags: a ConfigError naming the flag for a value out of range
  /// (threads below 1; a step limit outside 1 .. 1e12).
  static RunSettings from_flags(int tau_grid_threads, int fft_threads, double max_steps);
};

/// An error another process of a split run has already reported (its exit code is 2; it is
/// not printed again).
struct ReportedElsewhere : Error {
  using Error::Error;
};

/// A split run's processes start together or not at all: each runs `before` (rank 0 prepares
/// the output directory) and builds the run's objects (the model takes its share, and what a
/// split run cannot do is refused), then all learn whether every one could. A process's own
/// refusal is rethrown on it (on ranks other than 0 as ReportedElsewhere when rank 0 refused
/// too: said once); where only others refused, an Error says so.
void agree_to_start(const Collective& split, const Json& resolved, const Registry& registry,
                    const RunSettings& settings, const std::function<void()>& before);

/// Refuses (ConfigError naming time.h) a run whose t_end / h exceeds max_steps, with the
/// estimate and how to lift the limit; computed in double, before anything is narrowed.
void check_run_steps(const Json& resolved, double max_steps);

/// Refuses (ConfigError naming reference or reference.h) a reference that would take more
/// than max_steps steps: an adaptive solver's fast-period cap times t_end, or t_end / reference.h.
void check_reference_cost(const Json& resolved, const Registry& registry, const RunSettings& settings);

/// The work estimate of a run before it starts: check_run_steps, and check_reference_cost
/// when it has a reference.
void check_work_estimate(const Json& resolved, const Registry& registry, const RunSettings& settings);

/// Called after a step of what is being computed ("run", "reference" and "reference check" for
/// the reference's two solves, the error estimate's runs), for a progress line: at the first
/// step, then every few steps (whenever a SteppedClock reads the time, a few ms apart), so that
/// a step pays a decrement and a compare.
using ProgressFn = std::function<void(const StepProgress&)>;

/// A run's objects built and checked as the run builds and checks them before its first step
/// (the same errors): what execute_run integrates, and what `tsi run --dry-run` reports.
struct RunPlan {
  Assembly assembly;
  long steps = 0;                     ///< t_end / h
  std::vector<std::string> warnings;  ///< result.json's warnings known before the run
};

/// Builds a resolved config's objects and checks them: the model's own checks, the memory of a
/// two-scale run, the step counts against --max-steps (and the reference's unless
/// `check_reference` is false: a study's shared reference is checked once), an initial value
/// with finite invariants, output.times, and what a split run cannot do. ConfigError naming
/// the field on bad input; nothing is written.
RunPlan plan_run(const Json& resolved, const Registry& registry, const RunSettings& settings,
                 bool check_reference = true);

/// The work of a reference, estimated before it starts as check_reference_cost checks it.
struct ReferenceEstimate {
  bool exact = false;           ///< the model's exact solution: no steps
  double steps = 0.0;           ///< t_end / reference.h, or an adaptive solver's lower bound
  bool at_least = false;        ///< steps is a lower bound (an adaptive solver's)
  bool accuracy_check = false;  ///< a second solve at tighter settings estimates its accuracy
};
ReferenceEstimate estimate_reference(const Json& resolved, const Registry& registry, const RunSettings& settings);

/// Computes the reference solution a resolved config asks for ("reference" section).
ReferenceSolution compute_reference(const Json& resolved, const Registry& registry, const RunSettings& settings,
                                    const ProgressFn& progress = {});

/// What identifies a reference: the model section, t_end and the reference section. Runs
/// with equal keys share one reference.
std::string reference_key(const Json& resolved);


/// Runs a resolved config (resolve_run_config): builds model, reformulation and scheme from
/// the registry, integrates, records the invariants, and compares with the reference when
/// one is requested (computing it unless `reference` is given). Errors during the run are
/// caught and reported in the outcome; bad input (ConfigError) propagates.
/// With `stream_dir`, the rows of invariants.csv are written to
/// stream_dir/invariants.csv.partial as they are computed (write_run_files renames it).
RunOutcome execute_run(const Json& resolved, const Registry& registry, const RunSettings& settings,
                       const ProgressFn& progress = {}, const ReferenceSolution* reference = nullptr,
                       const std::string& stream_dir = "");

/// The physical state as JSON: real numbers, or [re, im] pairs for a complex model.
Json state_to_json(const Vector& x, bool complex_state);

/// result.json's entry for a state written to `file`: the state itself (state_to_json) up to
/// max_inline_state values, else {"file": file, "dtype": "float64" | "complex128", "shape": [...]}.
Json state_entry(const Vector& x, bool complex_state, const std::vector<std::uint64_t>& shape, const std::string& file);
/// The entry that names the file alone: {"file": file, "dtype": ..., "shape": shape} (also a split
/// run's state that its processes wrote in shares, which no process holds whole).
Json state_file_entry(bool complex_state, const std::vector<std::uint64_t>& shape, const std::string& file);

}  // namespace tsi::app
