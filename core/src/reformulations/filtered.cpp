#include "filtered.hpp"

#include "remainder.hpp"
#include "tsi/phase.hpp"

namespace tsi {

Filtered::Filtered(std::shared_ptr<const Model> model, bool real_layout)
    : Reformulation(std::move(model)),
      multipliers_(model_remainder(*model_)),
      has_remainder_(multipliers_.size() > 0),
      // A remainder turns coordinates by complex phases (a real model has none).
      packing_(model_->dim(), real_layout && !model_->is_complex() && !has_remainder_),
      tau_(1),
      minus_tau_(1),
      state_(model_->dim(), 1),
      direction_(model_->dim(), 1),
      field_(model_->dim(), 1) {
  if (!has_remainder_) multipliers_ = Vector::Zero(packing_.size());
  diagonal_ = Diagonal(multipliers_);
}

void Filtered::rhs(Real t, const Vector& y, Vector& out) {
  nonlinear(t, y, out);
  if (has_remainder_) out += multipliers_.cwiseProduct(y);
}

void Filtered::nonlinear(Real t, const Vector& y, Vector& out) {
  ++evaluations_;
  tau_(0) = fast_phase(t, model_->eps());
  load(y, state_);
  model_->filtered_field(tau_, state_, field_);
  store(field_, out);
}

void Filtered::load(const Vector& y, Matrix& values) const {
  if (packing_.on())
    packing_.unpack(y.data(), values.data());
  else
    values.col(0) = y;
}

void Filtered::store(const Matrix& values, Vector& out) const { packing_.pack_into(values.data(), out); }

void Filtered::nonlinear_derivative(Real t, const Vector& y, const Vector& dy, Vector& out) {
  tau_(0) = fast_phase(t, model_->eps());
  minus_tau_(0) = -tau_(0);
  load(y, state_);
  load(dy, direction_);
  model_->linear_flow(tau_, state_);
  model_->linear_flow(tau_, direction_);
  model_->nonlinear_field_derivative(state_, direction_, field_);
  model_->linear_flow(minus_tau_, field_);
  store(field_, out);
}

Vector Filtered::read_back(const Vector& y, Real t) {
  return model_->linear_flow(fast_phase(t, model_->eps()), packing_.unpacked(y));
}

}  // namespace tsi
