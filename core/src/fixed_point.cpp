#include "tsi/fixed_point.hpp"

#include <algorithm>

namespace tsi {

void FixedPointSolver::record(int sweeps, bool converged) {
  ++stats_.solves;
  stats_.iterations += sweeps;
  stats_.iterations_max = std::max<long>(stats_.iterations_max, sweeps);
  if (!converged) ++stats_.not_converged;
}

}  // namespace tsi
