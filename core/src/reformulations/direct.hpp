#pragma once
#include <memory>

#include "real_packing.hpp"
#include "tsi/phase.hpp"
#include "tsi/reformulation.hpp"

namespace tsi {

/// The model as it stands: y = u, y' = (1/eps) JM y + J R y + J grad H1(y). L is not diagonal
/// in these coordinates, so only schemes that use rhs() (classical solvers) or the exact flows
/// (splitting: e^{hL} = e^{JR h} e^{JM h/eps}, the remainder included) apply.
///
/// With Variables::physical the state is x = T u, T = the model's to_physical, and
/// x' = T F(T^{-1} x): the problem as a user would integrate it in the variables errors are
/// measured in. This matters when T is ill-conditioned in eps (the charged particle's
/// v = (p + B q) / (2 eps)): a tolerance on u is then a tolerance 1/eps larger on x.
/// T must be linear; the constructor checks it.
///
/// A real model's state is real: with `real_layout` it holds the d values two to an entry
/// (tsi::RealPacking; half the memory, the same numbers).
class Direct final : public Reformulation {
 public:
  enum class Variables { model, physical };
  explicit Direct(std::shared_ptr<const Model> model, Variables variables = Variables::model,
                  bool real_layout = true);

  Index size() const override { return packing_.size(); }
  /// True when the state holds a real model's values two to an entry.
  bool real_layout() const { return packing_.on(); }
  const Diagonal& linear_multipliers() const override { return none_; }
  void nonlinear(Real t, const Vector& y, Vector& out) override;
  void nonlinear_derivative(Real t, const Vector& y, const Vector& dy, Vector& out) override;
  void rhs(Real t, const Vector& y, Vector& out) override;

  /// Exact flows when the model has an exact nonlinear flow: e^{hL} = e^{JM h/eps}.
  bool has_exact_flows() const override { return !physical_ && model_->has_exact_nonlinear_flow(); }
  void linear_flow(Real h, Vector& y) override;
  /// One exact nonlinear flow counts as one evaluation of N (the work measure of splitting).
  void nonlinear_flow(Real t, Real h, Vector& y) override;

  /// The model's second-order form on this state (model variables only), or null.
  SecondOrderProblem* second_order() override { return second_order_.get(); }
  /// The model's Lorentz-force form on this state (model variables only), or null.
  ChargedParticleProblem* charged_particle() override { return charged_particle_.get(); }

  Vector prepare(const Vector& u0) override { return packing_.packed(physical_ ? model_->to_physical(u0) : u0); }
  Vector read_back(const Vector& y, Real /*t*/) override {
    const Vector x = packing_.unpacked(y);
    return physical_ ? model_->from_physical(x) : x;
  }

 private:
  // The state as d values: y itself, or y unpacked into x_.
  const Vector& values_of(const Vector& y);
  // `values` (d) into out (packed when the packing is on; out may then not be `values`).
  void store(const Vector& values, Vector& out) const;
  // out = N(y), or L y + N(y) with the linear part: one evaluation, through the packing and the
  // physical variables.
  void evaluate(const Vector& y, Vector& out, bool with_linear_part);
  void model_nonlinear(const Vector& u, Vector& out);
  void model_rhs(const Vector& u, Vector& out);

  bool physical_;
  Index size_;
  Diagonal none_;
  Matrix state_, direction_, field_;
  Vector mu_, au_;  // M u and A u
  Vector remainder_;  // i omega per coordinate (empty without a remainder)
  RealPacking packing_;
  Vector x_, result_;  // the state and N as d values, where the packing is on
  class FormView;  // a declared form's view of the state (direct.cpp)
  class SecondOrder;
  std::unique_ptr<SecondOrderProblem> second_order_;  // where the model declares the form
  class ChargedParticle;
  std::unique_ptr<ChargedParticleProblem> charged_particle_;  // likewise
};

}  // namespace tsi
