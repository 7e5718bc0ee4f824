#include "anderson.hpp"

#include <algorithm>

namespace tsi {
namespace {
constexpr int max_depth = 8;
// Small matrices with compile-time bounds: the least-squares solve never touches the heap.
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_depth, max_depth>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_depth, 1>;
}  // namespace

AndersonSolver::AndersonSolver(FixedPointOptions options)
    : FixedPointSolver(options), depth_(std::clamp(options.anderson_depth, 1, max_depth)) {}

int AndersonSolver::iterate(Vector& x, FixedPointMap g, double& increment) {
  const Index n = x.size();
  if (residual_diffs_.rows() != n) {
    gx_.resize(n), residual_.resize(n), residual_prev_.resize(n), gx_prev_.resize(n);
    residual_diffs_.resize(n, depth_), map_diffs_.resize(n, depth_);
  }
  int stored = 0, next_column = 0;
  for (int k = 1; k <= options().max_iter; ++k) {
    g(x, gx_);
    residual_ = gx_ - x;
    const double scale = max_norm(gx_);
    increment = max_norm(residual_) / (scale > 0.0 ? scale : 1.0);
    if (increment <= options().tol) {
      x = gx_;
      return k;
    }
    if (k > 1) {
      residual_diffs_.col(next_column) = residual_ - residual_prev_;
      map_diffs_.col(next_column) = gx_ - gx_prev_;
      next_column = (next_column + 1) % depth_;
      stored = std::min(stored + 1, depth_);
    }
    residual_prev_ = residual_;
    gx_prev_ = gx_;
    if (stored == 0) {
      x = gx_;
      continue;
    }
    // gamma = argmin |residual - D gamma| over real gamma: normal equations, lightly
    // regularised against nearly parallel differences.
    SmallMatrix gram(stored, stored);
    SmallVector rhs(stored);
    for (int i = 0; i < stored; ++i) {
      rhs(i) = residual_diffs_.col(i).dot(residual_).real();
      for (int j = 0; j <= i; ++j)
        gram(i, j) = gram(j, i) = residual_diffs_.col(i).dot(residual_diffs_.col(j)).real();
    }
    gram.diagonal().array() += 1e-13 * gram.diagonal().maxCoeff();
    const SmallVector gamma = gram.ldlt().solve(rhs);
    x = gx_;
    for (int i = 0; i < stored; ++i) x -= gamma(i) * map_diffs_.col(i);
  }
  return -1;
}

}  // namespace tsi
