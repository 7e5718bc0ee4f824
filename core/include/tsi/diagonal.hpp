#pragma once
#include "tsi/types.hpp"

namespace tsi {

/// out_i = f(scale * lambda_i): a function of the diagonal operator scale * L, evaluated
/// once per step size by the exponential schemes (e^{hL}, h phi1(hL), ...).
template <class F>
void diagonal_function(const Vector& lambda, double scale, F&& f, Vector& out) {
  out.resize(lambda.size());
  for (Index i = 0; i < lambda.size(); ++i) out(i) = f(scale * lambda(i));
}

}  // namespace tsi
