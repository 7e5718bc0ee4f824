#pragma once
#include <cstddef>
#include <limits>
#include <vector>

#include "tsi/export.hpp"

/// The verification arithmetic shared by `tsi check`, the tests and the study reports:
/// observed orders and drift lines, fitted the same way everywhere.
namespace tsi {

/// Observed order between successive step sizes: log(e_i / e_{i+1}) / log(h_i / h_{i+1}).
TSI_API std::vector<double> successive_orders(const std::vector<double>& h, const std::vector<double>& error);

/// Least-squares slope of log(error) against log(h): the observed order over a range.
TSI_API double least_squares_order(const std::vector<double>& h, const std::vector<double>& error);

/// An observed order and what it was fitted over.
struct TSI_API OrderFit {
  bool finite = true;       ///< every error finite (no blow-up, no failed run)
  bool measurable = false;  ///< at least min_points errors to fit
  double order = std::numeric_limits<double>::quiet_NaN();
  std::size_t first = 0;  ///< the fit used errors[first, first + used)
  std::size_t used = 0;
};

/// The least-squares order over the errors above `floor`, h from coarse to fine: the
/// contiguous run that starts at the first error above the floor and ends before the first
/// one at or below it (the reference's and the rounding's plateau). Never fitted across a gap:
/// a non-finite error (blow-up, failed run) anywhere makes the fit not finite, and nothing is
/// fitted past it. measurable when the run has at least min_points errors.
TSI_API OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& error, double floor,
                           std::size_t min_points = 3);

/// The least-squares line y = intercept + slope t over the samples with t >= t_from, and the
/// root-mean-square residual about it (the noise a drift must exceed to be one).
struct TSI_API DriftFit {
  double slope = std::numeric_limits<double>::quiet_NaN();
  double intercept = std::numeric_limits<double>::quiet_NaN();
  double residual_rms = std::numeric_limits<double>::quiet_NaN();
  std::size_t points = 0;
};
TSI_API DriftFit drift_fit(const std::vector<double>& t, const std::vector<double>& y, double t_from);

}  // namespace tsi
