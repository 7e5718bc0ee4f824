#include "repreparation.hpp"

#include <algorithm>

#include "tsi/phase.hpp"

namespace tsi {

bool Repreparer::after_step(long n, Real t, Vector& y) {
  if (rule_.mode == Repreparation::Mode::Never) return false;
  if (rule_.mode == Repreparation::Mode::Every && n % rule_.every != 0) return false;
  if (rule_.mode == Repreparation::Mode::Auto && (n - last_prepared_) % rule_.min_gap != 0)
    return false;
  const Real s = fast_phase(t, eps_);
  Vector& v = value_;  // kept between re-preparations
  grid_.evaluate_into(Eigen::Map<const Matrix>(y.data(), grid_.dim(), grid_.columns()), s, v);
  Vector& prepared = prepared_;  // the buffer of the state re-prepared before (swapped out below)
  data_.at(v, s, prepared);
  if (rule_.mode == Repreparation::Mode::Auto) {
    // U is due when it has drifted off the prepared data through its own diagonal value by more
    // than a fraction of that data's tau variation (column 0 of the coefficients is the mean).
    const Real variation = grid_.coefficient_norm(prepared, true);
    // A defect below defect_floor |U| is the scheme's own error, not the characteristics coming
    // apart (NLS at eps = 0.01: re-preparing on it made err_H 9x worse than never).
    const Real threshold =
        std::max(rule_.defect * variation, rule_.defect_floor * grid_.coefficient_norm(prepared));
    if (!(grid_.coefficient_norm(y - prepared) > threshold)) return false;
  }
  y.swap(prepared);
  times_.push_back(to_double(t));
  last_prepared_ = n;
  return true;
}

}  // namespace tsi
