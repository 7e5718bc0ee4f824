#include "remainder.hpp"

#include <fmt/format.h>

#include "tsi/error.hpp"

namespace tsi {

Vector model_remainder(const Model& model) {
  const RealVector& omega = model.linear_remainder();
  if (omega.size() == 0) return {};
  if (omega.size() != model.dim())
    throw ConfigError("model", fmt::format("linear_remainder() has {} frequencies, expected dim() = {}",
                                           omega.size(), model.dim()));
  if (!omega.allFinite()) throw ConfigError("model", "linear_remainder() has a non-finite frequency");
  if (!model.is_complex() && omega.cwiseAbs().maxCoeff() > 0.0)
    throw ConfigError("model", "a real model (is_complex() false) cannot have a non-zero linear_remainder(): "
                               "e^{i omega t} would make its real state complex");
  return Complex(0.0, 1.0) * omega.cast<Complex>();
}

}  // namespace tsi
