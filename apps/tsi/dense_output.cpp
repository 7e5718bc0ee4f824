#include "dense_output.hpp"

#include <algorithm>
#include <cmath>

#include "tsi/phase.hpp"
#include "tsi/stop_request.hpp"

namespace tsi::app {

DenseOutput::DenseOutput(std::vector<double> times, int degree, double h, long n_steps, const Model& model,
                         Reformulation& reformulation)
    : times_(std::move(times)),
      degree_(static_cast<int>(std::clamp<long>(degree, 1, std::max(1L, n_steps)))),
      h_(h),
      model_(model),
      reformulation_(reformulation),
      values_(times_.size()) {
  for (std::size_t k = 0; k < times_.size(); ++k) {
    // The interval [t_j, t_j+1] of the time, and p + 1 steps around it (centred where the run
    // has steps on both sides, one-sided at its ends).
    const long j = std::clamp(static_cast<long>(std::floor(times_[k] / h)), 0L, std::max(0L, n_steps - 1));
    const long first = std::clamp(j - (degree_ - 1) / 2, 0L, std::max(0L, n_steps - degree_));
    pending_.push_back({k, first, std::min(first + degree_, n_steps)});
  }
  std::sort(pending_.begin(), pending_.end(), [](const Pending& a, const Pending& b) {
    return a.last < b.last || (a.last == b.last && a.first < b.first);
  });
}

void DenseOutput::observe(long n, const Vector& y) {
  last_observed_ = n;
  // The stencils still pending start at pending_[next_].first or later (the firsts grow with
  // the lasts), and n is below every later one's last: n is needed when the next one reaches it.
  if (next_ == pending_.size() || n < pending_[next_].first) return;
  states_[n] = y;
  // Many times may fall in one step's reach: an interrupt stops their evaluation (the run then
  // stops at this step, and the times left are reported as not reached).
  for (; next_ < pending_.size() && pending_[next_].last <= n && !stop_requested(); ++next_)
    evaluate(pending_[next_], n);
  // Steps no pending stencil reaches back to are dropped.
  const long keep_from = next_ == pending_.size() ? n + 1 : pending_[next_].first;
  states_.erase(states_.begin(), states_.lower_bound(keep_from));
}

void DenseOutput::finish() {
  const long last = last_observed_;
  for (; next_ < pending_.size() && !stop_requested(); ++next_) {
    const Pending& p = pending_[next_];
    if (last >= 0 && times_[p.index] <= step_time(last, h_) && p.first <= last) evaluate(p, last);
  }
  states_.clear();
}

void DenseOutput::evaluate(const Pending& p, long last_available) {
  const Real t = times_[p.index];
  const long last = std::min(p.last, last_available);
  // Lagrange's weights on the stencil's times t_i = i h (computed, not accumulated, as the
  // steps' own): exactly 1 and 0 at a step's own time, so a time on the grid is that step.
  Vector u = Vector::Zero(states_.at(p.first).size());
  for (long i = p.first; i <= last; ++i) {
    const Real ti = step_time(i, h_);
    Real w = 1;
    for (long k = p.first; k <= last; ++k)
      if (k != i) w *= (t - step_time(k, h_)) / (ti - step_time(k, h_));
    if (w != 0.0) u += w * states_.at(i);
  }
  values_[p.index] = model_.to_physical(reformulation_.read_back(u, t));
}

}  // namespace tsi::app
