#include "tsi/problem.hpp"

#include "tsi/error.hpp"

namespace tsi {

const Vector& Problem::remainder_multipliers() const {
  static const Vector none;
  return none;
}

void Problem::linear_flow(Real /*h*/, Vector& /*y*/) {
  throw Error("this problem has no exact linear flow (has_exact_flows() is false)");
}

void Problem::nonlinear_flow(Real /*t*/, Real /*h*/, Vector& /*y*/) {
  throw Error("this problem has no exact nonlinear flow (has_exact_flows() is false)");
}

}  // namespace tsi
