#include "direct.hpp"

namespace tsi {

Direct::Direct(std::shared_ptr<const Model> model)
    : Reformulation(std::move(model)),
      state_(model_->dim(), 1),
      direction_(model_->dim(), 1),
      field_(model_->dim(), 1),
      mu_(model_->dim()),
      jmu_(model_->dim()) {}

void Direct::nonlinear(double /*t*/, const Vector& y, Vector& out) {
  ++evaluations_;
  state_.col(0) = y;
  model_->nonlinear_field(state_, field_);
  out = field_.col(0);
}

void Direct::nonlinear_derivative(double /*t*/, const Vector& y, const Vector& dy, Vector& out) {
  state_.col(0) = y;
  direction_.col(0) = dy;
  model_->nonlinear_field_derivative(state_, direction_, field_);
  out = field_.col(0);
}

void Direct::rhs(double t, const Vector& y, Vector& out) {
  nonlinear(t, y, out);
  model_->apply_M(y, mu_);
  model_->apply_J(mu_, jmu_);
  out += jmu_ / model_->eps();
}

}  // namespace tsi
