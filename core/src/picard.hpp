#pragma once
#include <algorithm>
#include <cmath>

#include "tsi/fixed_point.hpp"

namespace tsi {

/// max_i |a_i - b_i|^2 and max_i |a_i|^2 in one pass over the doubles, in two independent lanes
/// so the compiler can keep the maxima in vector registers (std::max over complex norms in
/// one chain ran at the latency of a compare: 30% of a charged-particle step).
inline void max_squares(const Vector& a, const Vector& b, double& distance2, double& scale2) {
  const double* pa = reinterpret_cast<const double*>(a.data());
  const double* pb = reinterpret_cast<const double*>(b.data());
  const Index n = 2 * a.size();
  double d[2] = {0.0, 0.0}, s[2] = {0.0, 0.0};
  Index i = 0;
  for (; i + 4 <= n; i += 4)
    for (int l = 0; l < 2; ++l) {
      const Index k = i + 2 * l;
      const double dr = pa[k] - pb[k], di = pa[k + 1] - pb[k + 1];
      const double dd = dr * dr + di * di;
      const double ss = pa[k] * pa[k] + pa[k + 1] * pa[k + 1];
      d[l] = dd > d[l] ? dd : d[l];
      s[l] = ss > s[l] ? ss : s[l];
    }
  for (; i < n; i += 2) {
    const double dr = pa[i] - pb[i], di = pa[i + 1] - pb[i + 1];
    d[0] = std::max(d[0], dr * dr + di * di);
    s[0] = std::max(s[0], pa[i] * pa[i] + pa[i + 1] * pa[i + 1]);
  }
  distance2 = std::max(d[0], d[1]);
  scale2 = std::max(s[0], s[1]);
}

/// Plain Picard iteration x_{k+1} = G(x_k).
class PicardSolver final : public FixedPointSolver {
 public:
  using FixedPointSolver::FixedPointSolver;

 protected:
  int iterate(Vector& x, FixedPointMap g, double& increment) override {
    next_.resize(x.size());
    for (int k = 1; k <= options().max_iter; ++k) {
      g(x, next_);
      double distance2 = 0.0, scale2 = 0.0;
      max_squares(next_, x, distance2, scale2);
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
