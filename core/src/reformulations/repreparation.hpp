#pragma once
#include <vector>

#include "prepared_data.hpp"
#include "tau_grid.hpp"
#include "tsi/observer.hpp"

namespace tsi {

/// When a two-scale run re-prepares its data (SPEC.md section 6, "Re-preparation").
struct Repreparation {
  enum class Mode { Never, Every, Auto } mode = Mode::Never;
  long every = 0;         ///< Every: each this many steps
  /// Auto: re-prepare when U's distance from the prepared data at its own diagonal value,
  /// |U - P(v_n, s_n)|, exceeds this fraction of P's own tau variation |P - mean P|.
  Real defect = 0.1;
  Real defect_floor = 1e-4;  ///< Auto: defects below this fraction of |U| never trigger
  long min_gap = 10;  ///< Auto: tested (one evaluation of r1) every this many steps
};

/// Applies a Repreparation rule between the steps of a two-scale run: v_n = U(t_n, s_n),
/// s_n = t_n/eps mod 2 pi, and U rebuilt as prepared data centred at s_n (U(t_n, s_n) = v_n
/// exactly, so u(t_n) is unchanged), when the rule says so. It keeps the times it did. The
/// driver calls it as an observer of the state (TwoScale::repreparation).
class Repreparer final : public StateObserver {
 public:
  Repreparer(const TauGrid& grid, PreparedData& data, Real eps, Repreparation rule)
      : grid_(grid), data_(data), eps_(eps), rule_(rule) {}

  /// After step n (at time t): re-prepares y when due; true when it did.
  bool after_step(long n, Real t, Vector& y) override;
  /// A new run: no re-preparation yet (the initial data are the last prepared, at step 0).
  void reset() {
    times_.clear();
    last_prepared_ = 0;
  }
  const std::vector<double>& times() const { return times_; }

 private:
  const TauGrid& grid_;
  PreparedData& data_;
  Real eps_;
  Repreparation rule_;
  std::vector<double> times_;
  long last_prepared_ = 0;  // the step of the last preparation
  Vector value_;            // U(t, t/eps) of the state re-prepared, its storage kept
  Vector prepared_;         // the next prepared state's storage: the state it replaced last time
};

}  // namespace tsi
