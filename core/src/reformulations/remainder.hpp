#pragma once
#include "tsi/model.hpp"

namespace tsi {

/// The diagonal of the model's remainder J R in its coordinates, i omega_j (empty without one).
/// A remainder of the wrong size, non-finite, or on a real model is a ConfigError naming the model.
Vector model_remainder(const Model& model);

}  // namespace tsi
