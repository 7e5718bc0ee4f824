#include "tsi/convergence.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

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

namespace tsi {

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& error, double floor,
                   std::size_t min_points) {
  if (h.size() != error.size()) throw Error("fit_order: h and error differ in length");
  OrderFit f;
  for (const double e : error) f.finite = f.finite && std::isfinite(e);
  if (!f.finite) return f;
  std::size_t i = 0;
  while (i < error.size() && error[i] <= floor) ++i;
  f.first = i;
  while (i < error.size() && error[i] > floor) ++i;
  f.used = i - f.first;
  f.measurable = f.used >= std::max<std::size_t>(min_points, 2);
  if (f.measurable) {
    const auto b = static_cast<std::ptrdiff_t>(f.first), e = static_cast<std::ptrdiff_t>(i);
    f.order = least_squares_order({h.begin() + b, h.begin() + e}, {error.begin() + b, error.begin() + e});
  }
  return f;
}

DriftFit drift_fit(const std::vector<double>& t, const std::vector<double>& y, double t_from) {
  if (t.size() != y.size()) throw Error("drift_fit: t and y differ in length");
  double n = 0, st = 0, sy = 0, stt = 0, sty = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!(t[i] >= t_from)) continue;
    n += 1, st += t[i], sy += y[i], stt += t[i] * t[i], sty += t[i] * y[i];
  }
  DriftFit f;
  f.points = static_cast<std::size_t>(n);
  const double denominator = n * stt - st * st;
  if (n < 2 || !(denominator > 0)) return f;
  f.slope = (n * sty - st * sy) / denominator;
  f.intercept = (sy - f.slope * st) / n;
  double ss = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= t_from) ss += std::pow(y[i] - f.intercept - f.slope * t[i], 2);
  f.residual_rms = std::sqrt(ss / n);
  return f;
}

}  // namespace tsi
