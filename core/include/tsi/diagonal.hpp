#pragma once
#include <span>

#include "tsi/types.hpp"

namespace tsi {

/// out_i = f(scale * lambda_i): a function of the diagonal operator scale * L, evaluated
/// once per step size by the exponential schemes (e^{hL}, h phi1(hL), ...).
template <class F>
void diagonal_function(const Vector& lambda, double scale, F&& f, Vector& out) {
  out.resize(lambda.size());
  for (Index i = 0; i < lambda.size(); ++i) out(i) = f(scale * lambda(i));
}

/// outs[j]_i = f(scale * lambda_i)[j] for a function with several values per point (the
/// weights of an exponential multistep or collocation scheme), each out sized like lambda.
template <class F>
void diagonal_functions(const Vector& lambda, double scale, F&& f, std::span<Vector* const> outs) {
  for (Vector* out : outs) out->resize(lambda.size());
  for (Index i = 0; i < lambda.size(); ++i) {
    const auto values = f(scale * lambda(i));
    for (size_t j = 0; j < outs.size(); ++j) (*outs[j])(i) = values[j];
  }
}

}  // namespace tsi
