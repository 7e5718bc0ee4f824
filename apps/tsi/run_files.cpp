#include "run_files.hpp"

#include <filesystem>
#include <fstream>
#include <limits>

#include "tsi/error.hpp"
#include "tsi/npy.hpp"
#include "tsi/output.hpp"

namespace tsi::app {

void prepare_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw ConfigError("--out", "\"" + dir + "\" is a file, expected a directory for the results");
  fs::create_directories(dir, ec);
  if (ec) throw ConfigError("--out", "cannot create \"" + dir + "\": " + ec.message());
  const fs::path probe = fs::path(dir) / ".tsi-write-test";
  {
    std::ofstream out(probe);
    out << "tsi\n";
    out.flush();
    if (!out) throw ConfigError("--out", "\"" + dir + "\" is not writable");
  }
  fs::remove(probe, ec);
}

namespace {

// The file shape of one state of n values: the outcome's (model.u0's file's) where it holds n
// values, else (n,).
std::vector<std::uint64_t> one_state_shape(const RunOutcome& outcome, std::uint64_t n) {
  std::uint64_t product = 1;
  for (const std::uint64_t d : outcome.state_shape) product *= d;
  return outcome.state_shape.empty() || product != n ? std::vector<std::uint64_t>{n} : outcome.state_shape;
}

// Writes one state file of a run, or removes a stale one a previous run left in DIR when this
// outcome has no such state (a run that never started); an outcome read back from its files
// (--resume: it has the entry in result.json but no state in memory) leaves the file alone.
void write_state_file(const std::string& path, const Vector& x, const RunOutcome& outcome, bool has_entry) {
  if (x.size() > 0) {
    write_npy(path, x, outcome.complex_state, one_state_shape(outcome, static_cast<std::uint64_t>(x.size())));
  } else if (!has_entry) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
}

}  // namespace

void write_run_files(const std::string& dir, const RunOutcome& outcome) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError("cannot create the output directory " + dir + ": " + ec.message());
  // The states first: result.json may point to them. One that cannot be written (a full disk)
  // fails the run in the result.json written after it, and is exit code 3 like any output.
  std::string state_error;
  try {
    const Json& result = outcome.result;
    const bool reference_entry = result.contains("error") && result["error"].contains("reference") &&
                                 result["error"]["reference"].contains("u_final");
    write_state_file(dir + "/" + u_final_file, outcome.u_final, outcome, result.contains("u_final"));
    write_state_file(dir + "/" + reference_u_final_file, outcome.reference_u_final, outcome, reference_entry);
    if (!outcome.u_times.empty() && outcome.u_final.size() > 0) {  // u at output.times, one row per time
      const Index per_time = outcome.u_final.size();
      std::vector<std::uint64_t> shape = {outcome.u_times.size()};
      const std::vector<std::uint64_t> one = one_state_shape(outcome, static_cast<std::uint64_t>(per_time));
      shape.insert(shape.end(), one.begin(), one.end());
      // Row by row (NaN where the run did not reach the time): no second copy of them all.
      write_npy_rows(dir + "/" + u_times_file, outcome.u_times, per_time, outcome.complex_state, shape);
    }
  } catch (const IoError& e) {
    state_error = e.what();
  }
  if (outcome.csv_file.empty()) {
    write_file_atomically(dir + "/invariants.csv", outcome.csv);
  } else {  // streamed while the run went: complete now
    std::filesystem::rename(outcome.csv_file, dir + "/invariants.csv", ec);
  }
  // result.json even when the rows are gone (the directory was removed mid-run): what the
  // run computed is in it.
  Json result = outcome.result;
  if (!state_error.empty()) {
    result["status"] = "failed";
    result["message"] = state_error + (outcome.message.empty() ? "" : "; " + outcome.message);
  }
  try {
    write_file_atomically(dir + "/result.json", result.dump(2) + "\n");
  } catch (const IoError& e) {
    // A checkpoint's result.json ("running") must not outlive the run: a short record of the
    // failure may still fit where the whole one did not; failing that, the stale one goes.
    const Json failed = {{"status", "failed"},
                         {"message", std::string(e.what()) + "; the run's own status: " +
                                         result.value("status", std::string("unknown"))},
                         {"t_reached", result.value("t_reached", Json())},
                         {"steps", result.value("steps", Json())}};
    try {
      write_file_atomically(dir + "/result.json", failed.dump(2) + "\n");
    } catch (const IoError&) {
      std::error_code removed;
      std::filesystem::remove(dir + "/result.json", removed);
    }
    throw;
  }
  if (ec) throw IoError("cannot rename " + outcome.csv_file + " to " + dir + "/invariants.csv: " + ec.message());
  if (!state_error.empty()) throw IoError(state_error);
}

}  // namespace tsi::app
