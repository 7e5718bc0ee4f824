#include "tsi/fixed_point.hpp"

#include <algorithm>

namespace tsi {

ParamSchema fixed_point_params() {
  return {number_param("tol", 1e-10, "fixed-point tolerance on the relative max-norm increment")
              .range(0.0, 1.0, true, true),
          integer_param("max_iter", 200, "most fixed-point sweeps per implicit stage")
              .check([](const Json& v) { return v.get<long>() >= 1; }, "a positive integer")};
}

FixedPointOptions fixed_point_options(const Params& params) {
  return {params.number("tol"), static_cast<int>(params.integer("max_iter"))};
}

void FixedPointSolver::record(int sweeps, bool converged) {
  ++stats_.solves;
  stats_.iterations += sweeps;
  stats_.iterations_max = std::max<long>(stats_.iterations_max, sweeps);
  if (!converged) ++stats_.not_converged;
}

}  // namespace tsi
