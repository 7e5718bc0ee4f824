#include "anderson.hpp"

#include <algorithm>

#include "tsi/algebra.hpp"
#include "tsi/stop_request.hpp"

namespace tsi {
namespace {
constexpr int max_depth = 8;
// Small matrices with compile-time bounds: the least-squares solve never touches the heap.
using SmallMatrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic, 0, max_depth, max_depth>;
using SmallVector = Eigen::Matrix<Real, Eigen::Dynamic, 1, 0, max_depth, 1>;
}  // namespace

double AndersonSolver::state_vectors_for(int depth) { return 4.0 + 2.0 * std::clamp(depth, 1, max_depth); }

AndersonSolver::AndersonSolver(FixedPointOptions options)
    : FixedPointSolver(options), depth_(std::clamp(options.anderson_depth, 1, max_depth)) {}

int AndersonSolver::iterate(Vector& x, FixedPointMap g, Real& increment) {
  if (residual_diffs_.size() != static_cast<size_t>(depth_)) residual_diffs_.resize(depth_), map_diffs_.resize(depth_);
  int stored = 0, next_column = 0;
  for (int k = 1; k <= options().max_iter; ++k) {
    throw_if_stop_requested("iterating an implicit stage (a step left unfinished)");  // a sweep can take seconds
    g(x, gx_);
    algebra::axpby(1.0, gx_, -1.0, x, residual_);
    increment = this->increment(gx_, x);
    if (increment <= options().tol) {
      algebra::copy(gx_, x);
      return k;
    }
    if (k > 1) {
      algebra::axpby(1.0, residual_, -1.0, residual_prev_, residual_diffs_[next_column]);
      algebra::axpby(1.0, gx_, -1.0, gx_prev_, map_diffs_[next_column]);
      next_column = (next_column + 1) % depth_;
      stored = std::min(stored + 1, depth_);
    }
    algebra::copy(residual_, residual_prev_);
    algebra::copy(gx_, gx_prev_);
    if (stored == 0) {
      algebra::copy(gx_, x);
      continue;
    }
    // gamma = argmin |residual - D gamma| over real gamma: normal equations, lightly
    // regularised against nearly parallel differences.
    SmallMatrix gram(stored, stored);
    SmallVector rhs(stored);
    for (int i = 0; i < stored; ++i) {
      rhs(i) = algebra::inner(residual_diffs_[i], residual_);
      for (int j = 0; j <= i; ++j) gram(i, j) = gram(j, i) = algebra::inner(residual_diffs_[i], residual_diffs_[j]);
    }
    if (options().collective) {  // the inner products of the whole split state
      options().collective->sum(rhs.data(), stored);
      options().collective->sum(gram.data(), static_cast<Index>(stored) * stored);
    }
    gram.diagonal().array() += 1e-13 * gram.diagonal().maxCoeff();
    const SmallVector gamma = gram.ldlt().solve(rhs);
    algebra::copy(gx_, x);
    for (int i = 0; i < stored; ++i) algebra::axpy(-gamma(i), map_diffs_[i], x);
  }
  return -1;
}

}  // namespace tsi
