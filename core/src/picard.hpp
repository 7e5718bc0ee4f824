#pragma once
#include "tsi/algebra.hpp"
#include "tsi/fixed_point.hpp"
#include "tsi/stop_request.hpp"

namespace tsi {

/// Plain Picard iteration x_{k+1} = G(x_k).
class PicardSolver final : public FixedPointSolver {
 public:
  using FixedPointSolver::FixedPointSolver;
  double state_vectors() const override { return 1.0; }

 protected:
  int iterate(Vector& x, FixedPointMap g, Real& increment) override {
    next_.resize(x.size());
    for (int k = 1; k <= options().max_iter; ++k) {
      throw_if_stop_requested("iterating an implicit stage (a step left unfinished)");  // a sweep can take seconds
      g(x, next_);
      increment = this->increment(next_, x);
      algebra::swap(x, next_);
      if (increment <= options().tol) return k;
    }
    return -1;
  }

 private:
  Vector next_;
};

}  // namespace tsi
