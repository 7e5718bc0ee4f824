#pragma once
#include <vector>

#include "tsi/export.hpp"

namespace tsi {

/// Observed order between successive step sizes: log(e_i / e_{i+1}) / log(h_i / h_{i+1}).
TSI_API std::vector<double> successive_orders(const std::vector<double>& h, const std::vector<double>& error);

/// Least-squares slope of log(error) against log(h): the observed order over a range.
TSI_API double least_squares_order(const std::vector<double>& h, const std::vector<double>& error);

}  // namespace tsi
