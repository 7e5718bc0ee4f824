#pragma once
#include <vector>

#include "tsi/fixed_point.hpp"

namespace tsi {

/// Anderson acceleration (type II) of the fixed-point map: each update mixes the last
/// `anderson_depth` residual differences by a least-squares fit. The state is treated as a
/// real vector (real mixing coefficients), so maps that are not complex-analytic, such as
/// |u|^2 u, are accelerated correctly.
class AndersonSolver final : public FixedPointSolver {
 public:
  explicit AndersonSolver(FixedPointOptions options);
  double state_vectors() const override { return state_vectors_for(depth_); }
  /// Its vectors with this depth (clamped as the solver clamps it).
  static double state_vectors_for(int depth);

 protected:
  int iterate(Vector& x, FixedPointMap g, Real& increment) override;

 private:
  int depth_;
  Vector gx_, residual_, residual_prev_, gx_prev_;
  std::vector<Vector> residual_diffs_, map_diffs_;  // a ring of the last depth_ differences
};

}  // namespace tsi
