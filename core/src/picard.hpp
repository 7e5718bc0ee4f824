#pragma once
#include <algorithm>
#include <cmath>

#include "tsi/fixed_point.hpp"

namespace tsi {

/// Plain Picard iteration x_{k+1} = G(x_k).
class PicardSolver final : public FixedPointSolver {
 public:
  using FixedPointSolver::FixedPointSolver;

 protected:
  int iterate(Vector& x, FixedPointMap g, double& increment) override {
    next_.resize(x.size());
    for (int k = 1; k <= options().max_iter; ++k) {
      g(x, next_);
      // max |next - x|^2 and max |next|^2 in one pass over the data.
      double distance2 = 0.0, scale2 = 0.0;
      for (Index i = 0; i < x.size(); ++i) {
        distance2 = std::max(distance2, std::norm(next_(i) - x(i)));
        scale2 = std::max(scale2, std::norm(next_(i)));
      }
      const double scale = std::sqrt(scale2);
      increment = std::sqrt(distance2) / (scale > 0.0 ? scale : 1.0);
      x.swap(next_);
      if (increment <= options().tol) return k;
    }
    return -1;
  }

 private:
  Vector next_;
};

}  // namespace tsi
