// A time-dependent f(t, u) integrated by carrying t as one more variable (time_as_variable.hpp):
// the wrapped model sees its own u and the time of each state; the reformulations and schemes
// see an autonomous model of one more entry.
#include "tsi/time_as_variable.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "tsi/error.hpp"

namespace tsi {

namespace {

class TimeAsVariable final : public Model, public PhysicalVariables {
 public:
  explicit TimeAsVariable(std::unique_ptr<Model> model)
      : Model(model->eps()), model_(std::move(model)), field_(*model_->time_dependent_field()), d_(model_->dim()) {
    const char* without_t = model_->hamiltonian()              ? "hamiltonian()"
                            : model_->fused_tau_grid()         ? "fused_tau_grid()"
                            : model_->exact_nonlinear_flow()   ? "exact_nonlinear_flow()"
                                                               : nullptr;
    if (without_t)
      throw Error(std::string("a model that declares time_dependent_field() (f(t, u)) declares ") + without_t +
                  " too, which takes no t: return null from " + without_t +
                  " (its f is time_dependent_field()'s, evaluated at each state's own time)");
    const RealVector& omega = model_->linear_remainder();
    if (omega.size() > 0) {
      remainder_ = RealVector::Zero(d_ + 1);  // t turns by no phase
      remainder_.head(d_) = omega;
    }
  }

  Index dim() const override { return d_ + 1; }
  bool is_complex() const override { return model_->is_complex(); }

  void linear_flow(const RealVector& taus, MatrixRef states) const override {
    model_->linear_flow(taus, states.topRows(d_));
  }

  void nonlinear_field(ConstMatrixRef states, MatrixRef out) const override {
    field_.nonlinear_field_at(times(states), states.topRows(d_), out.topRows(d_));
    out.row(d_).setOnes();
  }

  // D(f, 1)(u, s)(z, z_s) = (D_u f(s, u) z + d_t f(s, u) z_s, 0): the model's derivative in u,
  // and the one in t by a central difference where a direction has a t component.
  void nonlinear_field_derivative(ConstMatrixRef states, ConstMatrixRef directions, MatrixRef out) const override {
    const RealVector t = times(states);
    field_.nonlinear_field_derivative_at(t, states.topRows(d_), directions.topRows(d_), out.topRows(d_));
    out.row(d_).setZero();
    const RealVector dt = times(directions);
    if (dt.isZero(0.0)) return;
    const Real delta = std::cbrt(std::numeric_limits<Real>::epsilon());
    RealVector step(t.size()), plus(t.size()), minus(t.size());
    for (Index j = 0; j < t.size(); ++j) {
      step(j) = delta * std::max<Real>(1, std::fabs(t(j)));
      plus(j) = t(j) + step(j);
      minus(j) = t(j) - step(j);
    }
    Matrix f_plus(d_, t.size()), f_minus(d_, t.size());
    field_.nonlinear_field_at(plus, states.topRows(d_), f_plus);
    field_.nonlinear_field_at(minus, states.topRows(d_), f_minus);
    for (Index j = 0; j < t.size(); ++j)
      if (dt(j) != 0.0) out.col(j).head(d_) += (f_plus.col(j) - f_minus.col(j)) * (dt(j) / (2 * step(j)));
  }

  Vector initial_value() const override { return with_time(model_->initial_value()); }

  void apply_A(const Vector& u, Vector& out) const override {
    Vector head(d_);
    model_->apply_A(u.head(d_), head);
    out = Vector::Zero(d_ + 1);
    out.head(d_) = head;
  }
  const RealVector& linear_remainder() const override { return remainder_; }
  double max_linear_frequency() const override { return model_->max_linear_frequency(); }

  std::vector<ModelInvariant> invariants() const override {
    std::vector<ModelInvariant> out = model_->invariants();
    for (ModelInvariant& invariant : out)
      invariant.value = [value = std::move(invariant.value), d = d_](const Vector& u) { return value(u.head(d)); };
    return out;
  }
  const Collective* processes() const override { return model_->processes(); }
  void canonicalize_physical(Vector& x) const override { model_->canonicalize_physical(x); }

  // Physical variables are the model's own (its PhysicalVariables, if any), without t.
  const PhysicalVariables* physical_variables() const override { return this; }
  Index physical_dim() const override { return model_->physical_dim(); }
  Vector from_physical(const Vector& x) const override { return with_time(model_->from_physical(x)); }
  Vector to_physical(const Vector& u) const override { return model_->to_physical(u.head(d_)); }
  Real error_norm(const Vector& x) const override { return model_->error_norm(x); }
  std::vector<Index> physical_shape() const override { return model_->physical_shape(); }

  const ExactSolution* exact_solution() const override { return model_->exact_solution(); }

 private:
  // The time of every column: its last entry.
  RealVector times(ConstMatrixRef states) const {
    RealVector t(states.cols());
    for (Index j = 0; j < states.cols(); ++j) t(j) = states(d_, j).real();
    return t;
  }
  // Model variables with t = 0 appended: runs start there.
  Vector with_time(const Vector& u) const {
    if (u.size() != d_)
      throw Error("a model with a time-dependent f gave a state of " + std::to_string(u.size()) +
                  " entries, expected its dim() = " + std::to_string(d_));
    Vector out = Vector::Zero(d_ + 1);
    out.head(d_) = u;
    return out;
  }

  std::unique_ptr<Model> model_;
  const TimeDependentField& field_;
  Index d_;
  RealVector remainder_;
};

}  // namespace

std::unique_ptr<Model> with_time_as_variable(std::unique_ptr<Model> model) {
  if (!model || !model->time_dependent_field()) return model;
  return std::make_unique<TimeAsVariable>(std::move(model));
}

}  // namespace tsi
