#pragma once
#include "tsi/phase.hpp"
#include "tsi/reformulation.hpp"

namespace tsi {

/// The model as it stands: y = u, y' = (1/eps) JM y + J grad H1(y). L is not diagonal in
/// these coordinates, so only schemes that use rhs() (classical solvers) apply.
class Direct final : public Reformulation {
 public:
  explicit Direct(std::shared_ptr<const Model> model);

  Index size() const override { return model_->dim(); }
  const Vector& linear_multipliers() const override { return none_; }
  bool autonomous() const override { return true; }
  void nonlinear(double t, const Vector& y, Vector& out) override;
  void nonlinear_derivative(double t, const Vector& y, const Vector& dy, Vector& out) override;
  void rhs(double t, const Vector& y, Vector& out) override;

  /// Exact flows when the model has an exact nonlinear flow: e^{hL} = e^{JM h/eps}.
  bool has_exact_flows() const override { return model_->has_exact_nonlinear_flow(); }
  void linear_flow(double h, Vector& y) override { y = model_->linear_flow(fast_phase(h, model_->eps()), y); }
  /// One exact nonlinear flow counts as one evaluation of N (the work measure of splitting).
  void nonlinear_flow(double /*t*/, double h, Vector& y) override {
    ++evaluations_;
    model_->nonlinear_flow(h, y);
  }

  Vector prepare(const Vector& u0) override { return u0; }
  Vector read_back(const Vector& y, double /*t*/) override { return y; }

 private:
  Vector none_;
  Matrix state_, direction_, field_;
  Vector mu_, jmu_;
};

}  // namespace tsi
