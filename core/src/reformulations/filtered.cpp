#include "filtered.hpp"

#include "remainder.hpp"
#include "tsi/phase.hpp"

namespace tsi {

Filtered::Filtered(std::shared_ptr<const Model> model)
    : Reformulation(std::move(model)),
      multipliers_(model_remainder(*model_)),
      has_remainder_(multipliers_.size() > 0),
      tau_(1),
      minus_tau_(1),
      state_(model_->dim(), 1),
      direction_(model_->dim(), 1),
      field_(model_->dim(), 1) {
  if (!has_remainder_) multipliers_ = Vector::Zero(model_->dim());
  diagonal_ = Diagonal(multipliers_);
}

void Filtered::rhs(double t, const Vector& y, Vector& out) {
  nonlinear(t, y, out);
  if (has_remainder_) out += multipliers_.cwiseProduct(y);
}

void Filtered::nonlinear(double t, const Vector& y, Vector& out) {
  ++evaluations_;
  tau_(0) = fast_phase(t, model_->eps());
  state_.col(0) = y;
  model_->filtered_field(tau_, state_, field_);
  out = field_.col(0);
}

void Filtered::nonlinear_derivative(double t, const Vector& y, const Vector& dy, Vector& out) {
  tau_(0) = fast_phase(t, model_->eps());
  minus_tau_(0) = -tau_(0);
  state_.col(0) = y;
  direction_.col(0) = dy;
  model_->linear_flow(tau_, state_);
  model_->linear_flow(tau_, direction_);
  model_->nonlinear_field_derivative(state_, direction_, field_);
  model_->linear_flow(minus_tau_, field_);
  out = field_.col(0);
}

Vector Filtered::read_back(const Vector& y, double t) {
  return model_->linear_flow(fast_phase(t, model_->eps()), y);
}

}  // namespace tsi
