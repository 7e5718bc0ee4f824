#include "tsi/fixed_point.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "anderson.hpp"
#include "picard.hpp"
#include "tsi/algebra.hpp"
#include "tsi/error.hpp"

namespace tsi {

ParamSchema fixed_point_params() {
  return {string_param("solver", "picard", "fixed-point method for the implicit stages")
              .choices({"picard", "anderson"}),
          number_param("tol", 1e-10, "fixed-point tolerance on the relative max-norm increment")
              .range(0.0, 1.0, true, true),
          integer_param("max_iter", 200, "most fixed-point sweeps per implicit stage")
              .check([](const Json& v) { return v.get<long>() >= 1 && v.get<long>() <= 1000000; },
                     "an integer from 1 to 1000000"),
          integer_param("anderson_depth", 3, "Anderson: previous residuals mixed into each update")
              .check([](const Json& v) { return v.get<long>() >= 1 && v.get<long>() <= 8; },
                     "an integer from 1 to 8"),
          string_param("on_failure", "warn",
                       "a stage that misses tol in max_iter sweeps: warn (count, continue) or stop")
              .choices({"warn", "stop"}),
          string_param("guess", "previous",
                       "starting guess: the previous step's stage (previous) or the linear part (linear)")
              .choices({"previous", "linear"})};
}

FixedPointOptions fixed_point_options(const Params& params) {
  FixedPointOptions o;
  o.method = params.string("solver");
  o.tol = params.number("tol");
  o.max_iter = static_cast<int>(params.integer("max_iter"));
  o.anderson_depth = static_cast<int>(params.integer("anderson_depth"));
  o.on_failure = params.string("on_failure");
  o.guess = params.string("guess");
  o.collective = params.context().collective;
  return o;
}

FixedPointSolver::FixedPointSolver(FixedPointOptions options) : options_(std::move(options)) {
  // Grown to the largest count seen, not sized by max_iter (up to 1e6: 8 MB per solver for a
  // histogram whose counts sit below a few dozen).
  stats_.sweeps_histogram.assign(static_cast<size_t>(std::min(options_.max_iter, 64)) + 1, 0);
}

Real FixedPointSolver::increment(const Vector& next, const Vector& x) const {
  Real m[2];
  algebra::increment_maxima(next, x, m);
  if (options_.collective) options_.collective->max(m, 2);
  return algebra::relative_increment(m);
}

bool FixedPointSolver::solve(Vector& x, FixedPointMap g) {
  Real increment = 0.0;
  const int sweeps = iterate(x, g, increment);
  const bool converged = sweeps >= 0;
  const long used = converged ? sweeps : options_.max_iter;
  ++stats_.solves;
  stats_.iterations += used;
  stats_.iterations_max = std::max(stats_.iterations_max, used);
  if (static_cast<size_t>(used) >= stats_.sweeps_histogram.size())
    stats_.sweeps_histogram.resize(static_cast<size_t>(used) + 1, 0);
  ++stats_.sweeps_histogram[static_cast<size_t>(used)];
  if (!converged) {
    ++stats_.not_converged;
    if (options_.on_failure == "stop")
      throw Error(fmt::format("the fixed-point iteration ({}) did not converge in max_iter = {} sweeps: "
                              "relative increment {:.3e} > tol = {:.3e}",
                              options_.method, options_.max_iter, increment, options_.tol));
  }
  return converged;
}

double fixed_point_state_vectors(const FixedPointOptions& options) {
  return options.method == "anderson" ? AndersonSolver::state_vectors_for(options.anderson_depth) : 1.0;
}

std::unique_ptr<FixedPointSolver> make_fixed_point_solver(const FixedPointOptions& options) {
  if (options.method == "picard") return std::make_unique<PicardSolver>(options);
  if (options.method == "anderson") return std::make_unique<AndersonSolver>(options);
  throw ConfigError("scheme.solver", "got \"" + options.method + "\", expected one of: picard, anderson");
}

}  // namespace tsi
