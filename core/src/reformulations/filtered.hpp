#pragma once
#include "real_packing.hpp"
#include "tsi/phase.hpp"
#include "tsi/reformulation.hpp"

namespace tsi {

/// The filtered problem (eq. filtered): v = e^{-JM t/eps} u,  v' = J R v + f_{t/eps}(v).
/// No stiff linear part: L = J R, the model's remainder (diagonal, i omega; zero without one),
/// which exponential schemes integrate exactly. Non-autonomous with period 2*pi*eps in t.
/// A real model's v is real: with `real_layout` its state holds the d values two to an entry
/// (tsi::RealPacking; half the memory, the same numbers).
class Filtered final : public Reformulation {
 public:
  explicit Filtered(std::shared_ptr<const Model> model, bool real_layout = true);

  Index size() const override { return packing_.size(); }
  /// True when the state holds a real model's values two to an entry.
  bool real_layout() const { return packing_.on(); }
  const Diagonal& linear_multipliers() const override { return diagonal_; }
  const Vector& remainder_multipliers() const override { return has_remainder_ ? multipliers_ : none_; }
  /// The shortest period of the explicit time dependence: 2 pi eps over the model's
  /// largest linear frequency (2 pi eps for Henon-Heiles; 2 pi eps / 64 for NLS with N_x = 16).
  Real fast_period() const override { return two_pi * model_->eps() / model_->max_linear_frequency(); }
  /// 2 pi eps: N(t, y) = f_{t/eps}(y) has this period in t.
  Real oscillation_period() const override { return two_pi * model_->eps(); }
  void nonlinear(Real t, const Vector& y, Vector& out) override;
  void nonlinear_derivative(Real t, const Vector& y, const Vector& dy, Vector& out) override;
  void rhs(Real t, const Vector& y, Vector& out) override;

  Vector prepare(const Vector& u0) override { return packing_.packed(u0); }
  Vector read_back(const Vector& y, Real t) override;

 private:
  Vector multipliers_;  // i omega of the remainder, or zeros
  bool has_remainder_;
  RealPacking packing_;
  Diagonal diagonal_;  // multipliers_ as L's diagonal
  Vector none_;
  // y into column 0 of a model-sized matrix, and back (through the packing when it is on).
  void load(const Vector& y, Matrix& values) const;
  void store(const Matrix& values, Vector& out) const;
  RealVector tau_, minus_tau_;  // one phase and its negative, reused
  Matrix state_, direction_, field_;
};

}  // namespace tsi
