#include "tsi/convergence.hpp"

#include <cmath>

#include "tsi/error.hpp"

namespace tsi {

std::vector<double> successive_orders(const std::vector<double>& h, const std::vector<double>& error) {
  if (h.size() != error.size()) throw Error("successive_orders: h and error differ in length");
  std::vector<double> orders;
  for (size_t i = 0; i + 1 < h.size(); ++i)
    orders.push_back(std::log(error[i] / error[i + 1]) / std::log(h[i] / h[i + 1]));
  return orders;
}

double least_squares_order(const std::vector<double>& h, const std::vector<double>& error) {
  if (h.size() != error.size() || h.size() < 2)
    throw Error("least_squares_order: needs at least two (h, error) pairs of equal length");
  const double n = static_cast<double>(h.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < h.size(); ++i) {
    const double x = std::log(h[i]), y = std::log(error[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace tsi
