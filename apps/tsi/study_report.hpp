#pragma once
#include <string>
#include <vector>

#include "run.hpp"
#include "study_spec.hpp"

namespace tsi::app {

/// One row per run (the columns of table.csv), with derived quantities: the observed order
/// against the next larger h of the same series, and the drift slopes of err_H, err_I,
/// err_m (least squares over the last 90% of the run). The largest change of each invariant
/// the run's model declares is in the column it has in invariants.csv (err_P, abs_err_P, err_mu),
/// after the fixed columns of table.csv (empty for the runs of other models).
Json study_rows(const Study& study, const std::vector<RunOutcome>& outcomes);

/// Per-series convergence data: h, errors, successive and least-squares orders, and the
/// uniform error (max over eps) per scheme and h.
Json convergence_summary(const Json& rows);

/// Wall time to reach each target error per (scheme or label, eps) series, by log-log
/// interpolation between the two runs that bracket it (null when none do).
Json work_at_error(const Json& rows, const std::vector<double>& targets);

/// Least-squares slope of column `column` against t over t >= t_from, from invariants.csv.
double drift_slope(const std::string& csv, const std::string& column, double t_from);

/// Writes DIR/table.csv, DIR/study.json and DIR/runs/<id>/{result.json, invariants.csv}.
/// A run whose files cannot be written (a full disk) does not stop the others nor the table:
/// the messages of those that failed (IoError) are returned; the table's own failure throws.
std::vector<std::string> write_study_files(const std::string& dir, const Study& study, const std::vector<RunOutcome>& outcomes,
                       const Json& rows, double wall_seconds, int jobs);

/// Writes DIR/table.csv and DIR/study.json only (the run files are already in place: a merge
/// of shards, or runs written by the MPI ranks that ran them). `execution` (an object) adds
/// how the study was run to study.json, e.g. {"mpi_ranks": 4} or {"shards": 8}.
void write_study_table(const std::string& dir, const Study& study, const Json& rows, double wall_seconds, int jobs,
                       const Json& execution = Json::object());

/// The tables printed on the terminal, by kind.
std::string study_text(const Study& study, const Json& rows);

}  // namespace tsi::app
