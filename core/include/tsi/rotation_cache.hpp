#pragma once
#include <array>
#include <cstring>

#include "tsi/types.hpp"

namespace tsi {

/// cos(w tau) and sin(w tau) of a set of phases tau, recomputed only when the phases change.
/// The linear flows of the models are rotations applied to the same tau grid (and its
/// negative) at every evaluation, so two entries remove all trigonometry from a step.
/// Not thread-safe: a model instance serves one run.
class RotationCache {
 public:
  struct Table {
    RealVector taus, cos, sin;
  };

  /// w, the frequency of the rotations (the charged particle's flow turns by tau / 2).
  explicit RotationCache(double frequency = 1.0) : frequency_(frequency) {}

  /// The table for `taus`, from the cache when the same phases were seen last or before.
  const Table& get(const RealVector& taus) {
    // Bitwise comparison (memcmp is vectorised; an element-wise == loop was 15% of a flow).
    const size_t bytes = static_cast<size_t>(taus.size()) * sizeof(double);
    for (auto& t : tables_)
      if (t.taus.size() == taus.size() && std::memcmp(t.taus.data(), taus.data(), bytes) == 0) return t;
    Table& t = tables_[next_];
    next_ = (next_ + 1) % tables_.size();
    t.taus = taus;
    t.cos = (frequency_ * taus.array()).cos();
    t.sin = (frequency_ * taus.array()).sin();
    return t;
  }

 private:
  double frequency_;
  std::array<Table, 2> tables_;
  size_t next_ = 0;
};

}  // namespace tsi
