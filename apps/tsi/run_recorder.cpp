#include "run_recorder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <set>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "config.hpp"
#include "tsi/algebra.hpp"
#include "tsi/device.hpp"
#include "tsi/error.hpp"

namespace tsi::app {
namespace {
// |X - X0| / |X0| (absolute when X0 = 0).
double relative_change(Real value, Real initial) {
  return to_double(std::abs(value - initial) / (initial != 0 ? std::abs(initial) : Real(1)));
}

// A declared invariant's name and change column become columns of invariants.csv and its name a
// key of result.json: letters, digits and '_', and no column another quantity has.
void check_invariant_name(const std::string& name, const std::string& column, const std::set<std::string>& taken) {
  const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
  if (!valid)
    throw Error(fmt::format("the model declares an invariant named \"{}\": expected letters, digits and '_'", name));
  if (taken.count(name) || taken.count(column))
    throw Error(fmt::format("the model declares an invariant named \"{}\": its columns {} and {} must not be "
                            "taken already (t, H, I, m, err_H, err_I, err_m, tau_roughness, tau_spread, or another invariant's)",
                            name, name, column));
}
}  // namespace

RunRecorder::RunRecorder(const Model& model, Reformulation& reformulation, const Vector& u0,
                         const Json& config, const std::string& csv_path)
    : model_(model),
      reformulation_(reformulation),
      hamiltonian_(model.has_hamiltonian_structure()),
      every_(config["output"]["every"]),
      n_steps_(step_count(config)),
      max_err_H_(config["monitor"]["max_err_H"]),
      roughness_warn_(config["monitor"]["tau_roughness_warn"]),
      spread_growth_warn_(config["monitor"]["tau_spread_growth_warn"]),
      u_(u0),
      csv_(hamiltonian_ ? "t,H,I,m,err_H,err_I,err_m,tau_roughness,tau_spread\n" : "t,tau_roughness,tau_spread\n") {
  // H, I and m exist only for a model that declares the Hamiltonian structure.
  if (hamiltonian_) {
    const Real initial[3] = {model.energy(u0), model.oscillatory_energy(u0), model.mass(u0)};
    for (int k = 0; k < 3; ++k) tracks_[k].initial = tracks_[k].final = initial[k];
  }
  std::set<std::string> taken = {"t", "H", "I", "m", "err_H", "err_I", "err_m", "tau_roughness", "tau_spread"};
  for (auto& invariant : model.invariants()) {
    if (!invariant.value)
      throw Error(fmt::format("the model declares an invariant \"{}\" without a value function", invariant.name));
    Declared d;
    d.initial = d.final = invariant.value(u0);
    d.relative = std::abs(d.initial) > relative_change_threshold;
    d.min = d.max = d.initial;
    d.column = invariant.conserved ? (d.relative ? "err_" : "abs_err_") + invariant.name : invariant.name;
    check_invariant_name(invariant.name, d.column, taken);
    taken.insert({invariant.name, d.column});
    d.invariant = std::move(invariant);
    declared_.push_back(std::move(d));
  }
  csv_.pop_back();  // the header's newline
  for (const auto& d : declared_) csv_ += "," + d.invariant.name + (d.invariant.conserved ? "," + d.column : "");
  csv_ += "\n";
  drift_from_ = 0.1 * static_cast<double>(config["time"]["t_end"]);  // as the study reports have it
  if (!csv_path.empty()) {
    csv_path_ = csv_path;
    csv_fd_ = ::open(csv_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (csv_fd_ < 0) throw IoError("cannot write " + csv_path + ": " + std::strerror(errno));
    pending_.swap(csv_);
    flush_rows();  // the header, at once
  }
}

RunRecorder::~RunRecorder() {
  if (csv_fd_ < 0) return;
  try {
    flush_rows();
  } catch (const std::exception&) {  // already cut back to its last whole row
  }
  ::close(csv_fd_);
}

void RunRecorder::finish_csv() {
  if (csv_fd_ < 0) return;
  flush_rows();
  const int fd = csv_fd_;
  csv_fd_ = -1;
  if (::close(fd) != 0) throw IoError("cannot write " + csv_path_ + ": " + std::strerror(errno));
}

void RunRecorder::flush_rows() {
  last_flush_ = std::chrono::steady_clock::now();
  if (pending_.empty() || csv_fd_ < 0) return;
  size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(csv_fd_, pending_.data() + done, pending_.size() - done);
    if (n >= 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (errno == EINTR) continue;
    // A full disk or a file size limit: keep the whole rows written before, drop the rest,
    // and stop writing (the run stops on this error).
    const int err = errno;
    const bool cut = ::ftruncate(csv_fd_, static_cast<off_t>(written_)) == 0;
    ::close(csv_fd_);
    csv_fd_ = -1;
    pending_.clear();
    throw IoError(fmt::format("cannot write {}: {}{}", csv_path_, std::strerror(err),
                              cut ? "" : " (and it could not be cut back to its last whole row)"));
  }
  written_ += static_cast<long long>(pending_.size());
  t_written_ = t_pending_;
  pending_.clear();
}

void RunRecorder::write_row(const std::string& row, double t) {
  if (csv_path_.empty()) {
    csv_ += row;
    return;
  }
  if (csv_fd_ < 0) return;  // a write failed: the run is being stopped
  pending_ += row;
  t_pending_ = t;
  // On disk within a second of being computed, and never more than 64 KiB in memory.
  if (pending_.size() >= 65536 || std::chrono::steady_clock::now() - last_flush_ > std::chrono::seconds(1))
    flush_rows();
}

double RunRecorder::drift(int k) const {
  const double* s = drift_sums_[k];
  const double denominator = s[0] * s[3] - s[1] * s[1];
  return s[0] >= 2 && denominator > 0 ? (s[0] * s[4] - s[1] * s[2]) / denominator
                                      : std::numeric_limits<double>::quiet_NaN();
}

bool RunRecorder::everywhere(bool flag) const { return collective_ ? collective_->all(flag) : flag; }

bool RunRecorder::observe(long n, Real t, const Vector& y) {
  // Between the recorded steps (every output.every-th and the last) only the cheap check: the
  // problem state is finite. One pass over it, no read-back and no allocation.
  if (n % every_ != 0 && n != n_steps_) {
    if (everywhere(algebra::all_finite(y))) return true;
    status_ = "blow-up";
    message_ = fmt::format("the solution became non-finite at t = {:.6g} (step {}); the last recorded state is "
                           "from t = {:.6g} (step {}, output.every = {})",
                           t, n, t_, steps_, every_);
    return false;
  }
  const device::HostView host(y);  // --device cuda: y's entries back on the host, and what follows computed there
  Vector u = reformulation_.read_back(y, t);
  Real values[3] = {0, 0, 0};
  if (hamiltonian_) values[0] = model_.energy(u), values[1] = model_.oscillatory_energy(u), values[2] = model_.mass(u);
  if (!everywhere(u.allFinite() && std::isfinite(values[0] + values[1] + values[2]))) {
    status_ = "blow-up";
    message_ = fmt::format("the solution became non-finite at t = {:.6g} (step {})", t, n);
    return false;
  }
  double errors[3] = {0.0, 0.0, 0.0};
  for (int k = 0; hamiltonian_ && k < 3; ++k) {
    errors[k] = relative_change(values[k], tracks_[k].initial);
    tracks_[k].final = values[k];
    tracks_[k].max_rel_error = std::max(tracks_[k].max_rel_error, errors[k]);
  }
  const TwoScaleDiagnostics* tau = reformulation_.two_scale_diagnostics();  // no tau: both 0
  const TauProfile profile = tau ? tau->tau_profile(y) : TauProfile{};
  const double roughness = to_double(profile.roughness);
  roughness_max_ = std::max(roughness_max_, roughness);
  if (roughness > roughness_warn_ && !roughness_warned_) {
    roughness_warned_ = true;
    warnings_.push_back(fmt::format(
        "the tau profile roughened at t = {:.6g}: {:.2e} of the energy of U is in the top quarter "
        "of the tau spectrum (monitor.tau_roughness_warn = {:g}); the run is no longer resolved in "
        "tau: increase reformulation.n_tau",
        t, roughness, roughness_warn_));
  }
  // Coherence: each characteristic of U is a trajectory of the model, and the scheme's accuracy
  // on the diagonal tau = t/eps rests on their staying together. Measured on NLS at eps = 0.1:
  // the spread sits at 2.4e-6 while SE1 follows the solution, then grows a thousandfold within
  // 15 time units while the mass error goes from 1e-5 to 1, and the top of the tau spectrum
  // stays far below tau_roughness_warn.
  const double spread = to_double(profile.spread);
  spread_max_ = std::max(spread_max_, spread);
  // The baseline is the first recorded step's spread (step output.every, not always step 1).
  if (!spread_baseline_set_) {
    spread_baseline_ = spread;
    spread_baseline_set_ = true;
  } else if (!spread_warned_ && spread > 1e-6 && spread > spread_growth_warn_ * spread_baseline_) {
    spread_warned_ = true;
    warnings_.push_back(fmt::format(
        "the tau profile of U lost its coherence at t = {:.6g}: the fraction of its energy away from the "
        "tau mean grew from {:.2e} at the first recorded step to {:.2e} (monitor.tau_spread_growth_warn = {:g}); "
        "the characteristics of U have come apart, so the solution past this time mixes different "
        "trajectories and its error and invariants may be far off (seen over long times for eps >= 0.1, "
        "or with large h; a smaller h or another scheme may delay it)",
        t, spread_baseline_, spread, spread_growth_warn_));
  }
  u_.swap(u);  // no copy of a state of 10^7 numbers
  steps_ = n;
  t_ = to_double(t);
  std::string non_finite;  // a conserved invariant of the model that is no longer a number
  for (auto& d : declared_) {
    d.final = d.invariant.value(u_);
    d.change = to_double(std::abs(d.final - d.initial) / (d.relative ? std::abs(d.initial) : Real(1)));
    // std::max drops a NaN (inf - inf): kept, the record and the summary show nan, never 0.
    d.max_change = std::isnan(d.change) ? d.change : std::max(d.max_change, d.change);
    d.min = std::min(d.min, d.final);
    d.max = std::max(d.max, d.final);
    if (d.invariant.conserved && !std::isfinite(d.final) && non_finite.empty())
      non_finite = fmt::format("{} = {}", d.invariant.name, to_double(d.final));
  }
  const bool blow_up = errors[0] > max_err_H_;
  if (n % every_ == 0 || n == n_steps_ || blow_up) {
    std::string row = hamiltonian_ ? fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}", t,
                                                 values[0], values[1], values[2], errors[0], errors[1], errors[2],
                                                 roughness, spread)
                                   : fmt::format("{:.17g},{:.6e},{:.6e}", t, roughness, spread);
    for (const auto& d : declared_)
      row += d.invariant.conserved ? fmt::format(",{:.17g},{:.6e}", d.final, d.change) : fmt::format(",{:.17g}", d.final);
    write_row(row + "\n", t_);
    if (t >= drift_from_)
      for (int k = 0; hamiltonian_ && k < 3; ++k) {
        // The printed value, as a drift fitted to the file would see it.
        const double printed = std::stod(fmt::format("{:.6e}", errors[k]));
        double* s = drift_sums_[k];
        s[0] += 1, s[1] += t_, s[2] += printed, s[3] += t_ * t_, s[4] += t_ * printed;
      }
  }
  if (blow_up) {
    status_ = "blow-up";
    message_ = fmt::format("err_H = {:.3e} exceeded monitor.max_err_H = {:g} at t = {:.6g} (step {})",
                           errors[0], max_err_H_, t, n);
    return false;
  }
  // A finite state whose conserved invariant overflowed (velocities near 1e154): its changes
  // are NaN from here on, so the run stops as failed rather than report them. (A split run's
  // invariants are sums over every process: all of them stop here alike.)
  if (!non_finite.empty()) {
    status_ = "blow-up";
    message_ = fmt::format("the invariant {} at t = {:.6g} (step {}) is not a finite number: the state's values are "
                           "too large for it to be monitored",
                           non_finite, t, n);
    return false;
  }
  return true;
}

Json RunRecorder::invariants_json() const {
  Json out = Json::object();
  const char* names[3] = {"H", "I", "m"};
  for (int k = 0; hamiltonian_ && k < 3; ++k)
    out[names[k]] = {{"initial", to_double(tracks_[k].initial)},
                     {"final", to_double(tracks_[k].final)},
                     {"max_rel_error", tracks_[k].max_rel_error}};
  for (const auto& d : declared_) {
    if (!d.invariant.conserved) {  // a diagnostic: its range (no column of changes)
      out[d.invariant.name] = {{"initial", to_double(d.initial)}, {"final", to_double(d.final)},
                               {"min", to_double(d.min)},         {"max", to_double(d.max)},
                               {"conserved", false},       {"description", d.invariant.description}};
      continue;
    }
    out[d.invariant.name] = {{"initial", to_double(d.initial)},
                             {"final", to_double(d.final)},
                             {"max_change", d.max_change},
                             {"change", d.relative ? "relative" : "absolute"},
                             {"column", d.column},
                             {"description", d.invariant.description}};
  }
  return out;
}

}  // namespace tsi::app
