#pragma once
#include <memory>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/model.hpp"
#include "tsi/observer.hpp"
#include "tsi/problem.hpp"

namespace tsi {

/// The tau monitors of one state, from one pass over it (TwoScaleDiagnostics::tau_profile).
struct TauProfile {
  Real roughness = 0.0;  ///< tau_roughness
  Real spread = 0.0;     ///< tau_spread
};

/// What a two-scale reformulation reports besides its problem: its tau monitors and what its
/// preparation did. The run's observers (the recorder) ask it at their own cadence.
class TSI_API TwoScaleDiagnostics {
 public:
  virtual ~TwoScaleDiagnostics() = default;
  /// Both monitors below from one pass over y (a particle state is 10^8 numbers).
  virtual TauProfile tau_profile(const Vector& y) const = 0;
  /// Fraction of the energy of y in the top quarter of the tau spectrum.
  virtual Real tau_roughness(const Vector& y) const = 0;
  /// Fraction of the energy of y away from its tau mean (the non-zero tau modes). Each
  /// characteristic tau - t/eps = const of U is a trajectory of the model; this measures how
  /// far they have spread apart, which the run recorder watches for growth.
  virtual Real tau_spread(const Vector& y) const = 0;
  /// The times t_n at which the state was re-prepared.
  virtual std::vector<double> repreparation_times() const = 0;
  /// The order of the prepared data of the last prepare(): below the configured order when
  /// the asymptotic recursion stopped at its smallest correction.
  virtual int data_order_reached() const = 0;
  /// Threads the tau grid's evaluations use (tsi::Context::tau_grid).
  virtual int threads() const = 0;
};

/// Turns a model into a Problem (SPEC.md section 2) and reads the answer back:
/// two-scale U(t, tau), filtered v = e^{-JM t/eps} u, or direct u.
class TSI_API Reformulation : public Problem {
 public:
  explicit Reformulation(std::shared_ptr<const Model> model) : model_(std::move(model)) {}

  /// The initial state y(0) of the problem for the model's initial value u0.
  virtual Vector prepare(const Vector& u0) = 0;
  /// u(t) in model variables from the problem state y at time t.
  virtual Vector read_back(const Vector& y, Real t) = 0;
  /// The two-scale diagnostics (null for the filtered and direct problems, which have no tau).
  virtual const TwoScaleDiagnostics* two_scale_diagnostics() const { return nullptr; }
  /// The observer that re-prepares the state between steps (two-scale; SPEC.md section 6),
  /// to be given to tsi::integrate; null for the filtered and direct problems.
  virtual StateObserver* repreparation() { return nullptr; }

  const Model& model() const { return *model_; }

 protected:
  std::shared_ptr<const Model> model_;
};

}  // namespace tsi
