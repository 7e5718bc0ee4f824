#pragma once
#include <chrono>
#include <limits>
#include <string>
#include <vector>

#include "tsi/collective.hpp"
#include "tsi/params.hpp"
#include "tsi/reformulation.hpp"

namespace tsi::app {

/// What a run records every output.every steps (and at its last step): the invariants H, I, m
/// and their largest relative changes over the recorded steps, the invariants the model
/// declares (Model::invariants) and their largest changes, the tau monitors, and the rows of
/// invariants.csv. It also watches the run: a non-finite state (checked at every step, one
/// pass over the state without allocating) or err_H above monitor.max_err_H (at the recorded
/// steps) stops it (blow-up), and a tau profile rougher than monitor.tau_roughness_warn, or one
/// whose spread away from its tau mean grew by monitor.tau_spread_growth_warn, is reported once.
class RunRecorder {
 public:
  /// A declared invariant's change is relative, |X - X0| / |X0|, when |X0| exceeds this, and
  /// absolute, |X - X0|, otherwise (a quantity that starts at 0, as the NLS momentum of real
  /// data: its rounding would make a relative change meaningless).
  static constexpr double relative_change_threshold = 1e-12;

  /// With a `csv_path`, the rows of invariants.csv go to that file as they are made (written
  /// at least every second and every 64 KiB), not into memory: a run killed part-way leaves
  /// them on disk, and memory stays constant however long the run.
  /// A failed write (a full disk) throws IoError naming the file, after cutting the file back
  /// to its last whole row: the file is always a valid CSV.
  RunRecorder(const Model& model, Reformulation& reformulation, const Vector& u0, const Json& config,
              const std::string& csv_path = "");
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  /// A run split over processes: its stops (a non-finite state anywhere) are decided over all
  /// of them, so that every process stops at the same step.
  void split_over(const Collective* collective) { collective_ = collective; }

  /// Writes the rows not yet on disk and closes the file (IoError when that fails).
  void finish_csv();
  /// Writes the rows not yet on disk, keeping the file open (before a checkpoint).
  void flush_csv() { flush_rows(); }
  /// The time of the last row on disk (NaN before any).
  double csv_written_to() const { return t_written_; }

  /// The step observer: false stops the integration. steps(), t_reached() and u_last() are
  /// those of the last recorded step.
  bool observe(long n, Real t, const Vector& y);

  /// Where the run stands: "running", or "blow-up" with a message.
  const std::string& status() const { return status_; }
  const std::string& message() const { return message_; }
  long steps() const { return steps_; }
  double t_reached() const { return t_; }
  /// u at the last step whose state was finite (model variables).
  const Vector& u_last() const { return u_; }

  Json invariants_json() const;
  double roughness_max() const { return roughness_max_; }
  double spread_max() const { return spread_max_; }
  const Json& warnings() const { return warnings_; }
  /// The rows of invariants.csv (empty when they were streamed to csv_path).
  const std::string& csv() const { return csv_; }
  /// Least-squares slope of the relative change of H, I, m (k = 0, 1, 2) against t over the
  /// rows with t >= drift_from (NaN with fewer than two, and without a Hamiltonian structure):
  /// the drift a study reports.
  double drift(int k) const;

 private:
  // A flag of this process, over every process of a split run.
  bool everywhere(bool flag) const;
  struct Track {
    Real initial = 0, final = 0;  // in the build's precision: changes below double's are kept
    double max_rel_error = 0.0;
  };
  /// A model's invariant: its column in invariants.csv is err_<name> (relative change) or
  /// abs_err_<name> (absolute change), after the value column <name>.
  struct Declared {
    ModelInvariant invariant;
    bool relative = true;
    std::string column;
    Real initial = 0, final = 0;
    double change = 0.0, max_change = 0.0;
    Real min = 0, max = 0;  // a diagnostic's range (conserved = false)
  };
  const Model& model_;
  const Collective* collective_ = nullptr;
  Reformulation& reformulation_;
  bool hamiltonian_;  // H, I, m and their columns only where the model declares the structure
  long every_, n_steps_;
  double max_err_H_, roughness_warn_, spread_growth_warn_;
  Track tracks_[3];  // H, I, m
  std::vector<Declared> declared_;
  Vector u_;
  long steps_ = 0;
  double t_ = 0.0, roughness_max_ = 0.0, spread_max_ = 0.0, spread_baseline_ = 0.0;
  bool spread_baseline_set_ = false;
  bool roughness_warned_ = false, spread_warned_ = false;
  std::string status_ = "running", message_, csv_;
  // Streaming: whole rows wait in pending_ and go to the file descriptor together; written_
  // bytes of whole rows are on disk (the file is cut back to them when a write fails).
  int csv_fd_ = -1;
  std::string csv_path_, pending_;
  long long written_ = 0;
  double t_pending_ = std::numeric_limits<double>::quiet_NaN(), t_written_ = t_pending_;
  std::chrono::steady_clock::time_point last_flush_ = std::chrono::steady_clock::now();
  void flush_rows();
  double drift_from_ = 0.0;
  double drift_sums_[3][5] = {};  // per invariant: n, sum t, sum y, sum t^2, sum t y
  void write_row(const std::string& row, double t);
  Json warnings_ = Json::array();
};

}  // namespace tsi::app
