#pragma once
#include <memory>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/model.hpp"
#include "tsi/problem.hpp"

namespace tsi {

/// Turns a model into a Problem (SPEC.md section 2) and reads the answer back:
/// two-scale U(t, tau), filtered v = e^{-JM t/eps} u, or direct u.
class TSI_API Reformulation : public Problem {
 public:
  explicit Reformulation(std::shared_ptr<const Model> model) : model_(std::move(model)) {}

  /// The initial state y(0) of the problem for the model's initial value u0.
  virtual Vector prepare(const Vector& u0) = 0;
  /// u(t) in model variables from the problem state y at time t.
  virtual Vector read_back(const Vector& y, double t) = 0;
  /// Fraction of the energy of y in the top quarter of the tau spectrum (0 without tau).
  virtual double tau_roughness(const Vector& /*y*/) const { return 0.0; }
  /// Fraction of the energy of y away from its tau mean (the non-zero tau modes; 0 without
  /// tau). Each characteristic tau - t/eps = const of U is a trajectory of the model; this
  /// measures how far they have spread apart, which the run recorder watches for growth.
  virtual double tau_spread(const Vector& /*y*/) const { return 0.0; }
  /// The times t_n at which the state was re-prepared (two-scale; empty otherwise).
  virtual std::vector<double> repreparation_times() const { return {}; }
  /// The order of the prepared data of the last prepare() (two-scale; 0 otherwise): below the
  /// configured order when the asymptotic recursion stopped at its smallest correction.
  virtual int data_order_reached() const { return 0; }
  /// Threads the reformulation's evaluations use (two-scale on a large tau grid: see
  /// tsi::Context::tau_grid; 1 otherwise).
  virtual int threads() const { return 1; }

  const Model& model() const { return *model_; }

 protected:
  std::shared_ptr<const Model> model_;
};

}  // namespace tsi
