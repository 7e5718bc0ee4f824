#include "direct.hpp"

#include <fmt/format.h>

#include <cmath>

#include "remainder.hpp"
#include "tsi/error.hpp"

namespace tsi {
namespace {

// T(a + 2b) against T(a) + 2 T(b) for two states of the model's kind: a linear T agrees to
// rounding, an affine or nonlinear one does not.
void require_linear_to_physical(const Model& model) {
  // Two states of the model's dimension (not its initial value: a model may have no default).
  Vector a(model.dim()), b(model.dim());
  for (Index i = 0; i < a.size(); ++i) {
    a(i) = 0.1 + 0.9 * static_cast<Real>(i % 7) / 7.0;
    const Real w = 0.3 + 0.7 * static_cast<Real>(i + 1) / static_cast<Real>(a.size());
    b(i) = model.is_complex() ? Complex(w, Real(0.5) * w) : Complex(w, 0);
  }
  const Vector lhs = model.to_physical(a + Real(2) * b);
  const Vector rhs = model.to_physical(a) + Real(2) * model.to_physical(b);
  const Real scale = std::max(max_norm(lhs), max_norm(rhs));
  if (!(max_norm(lhs - rhs) <= 1e-10 * std::max<Real>(scale, 1)))
    throw ConfigError("reformulation.variables",
                      fmt::format("got \"physical\", but the model maps to physical variables non-linearly "
                                  "(T(a + 2b) - T(a) - 2 T(b) = {:.3e}); expected \"model\"",
                                  max_norm(lhs - rhs)));
}

}  // namespace

// A view of the state in the model's own variables for a declared form (second-order,
// Lorentz force): the state unpacked into the model's d values (a buffer of the run) where the
// packing is on, and a model state packed back into it; each evaluation of the form's field
// counts as one of N.
class Direct::FormView {
 protected:
  FormView(const Model& model, const RealPacking& packing, long& evaluations)
      : packing_(packing), evaluations_(evaluations), values_(model.dim()) {}
  // y as the model's values: y itself, or unpacked into the buffer.
  const Vector& values_of(const Vector& y) {
    if (!packing_.on()) return y;
    packing_.unpack(y.data(), values_.data());
    return values_;
  }
  // Where the model writes the values of a state for y: y itself, or the buffer, which
  // store_into then packs into y.
  Vector& values_for(Vector& y) { return packing_.on() ? values_ : y; }
  void store_into(Vector& y) const {
    if (packing_.on()) packing_.pack_into(values_.data(), y);
  }
  void count_evaluation() { ++evaluations_; }

 private:
  const RealPacking& packing_;
  long& evaluations_;
  Vector values_;
};

class Direct::SecondOrder final : public SecondOrderProblem, FormView {
 public:
  SecondOrder(const Model& model, const SecondOrderForm& form, const RealPacking& packing, long& evaluations)
      : FormView(model, packing, evaluations), form_(form), frequencies_(form.frequencies()) {}
  Index positions() const override { return form_.positions(); }
  const RealVector& frequencies() const override { return frequencies_; }
  void split(const Vector& y, RealVector& x, RealVector& v) override { form_.to_second_order(values_of(y), x, v); }
  void join(const RealVector& x, const RealVector& v, Vector& y) override {
    form_.from_second_order(x, v, values_for(y));
    store_into(y);
  }
  void force(const RealVector& x, RealVector& g) override {
    count_evaluation();
    form_.force(x, g);
  }

 private:
  const SecondOrderForm& form_;
  RealVector frequencies_;
};

class Direct::ChargedParticle final : public ChargedParticleProblem, FormView {
 public:
  ChargedParticle(const Model& model, const ChargedParticleForm& form, const RealPacking& packing, long& evaluations)
      : FormView(model, packing, evaluations), form_(form) {}
  void split(const Vector& y, RealVector3& x, RealVector3& v) override { form_.to_particle(values_of(y), x, v); }
  void join(const RealVector3& x, const RealVector3& v, Vector& y) override {
    form_.from_particle(x, v, values_for(y));
    store_into(y);
  }
  void fields(const RealVector3& x, RealVector3& B, RealVector3& E) override {
    count_evaluation();
    form_.fields(x, B, E);
  }

 private:
  const ChargedParticleForm& form_;
};

Direct::Direct(std::shared_ptr<const Model> model, Variables variables, bool real_layout)
    : Reformulation(std::move(model)),
      physical_(variables == Variables::physical),
      size_(model_->dim()),
      state_(model_->dim(), 1),
      direction_(model_->dim(), 1),
      field_(model_->dim(), 1),
      mu_(model_->dim()),
      au_(model_->dim()),
      remainder_(model_remainder(*model_)),
      packing_(model_->dim(), real_layout && !model_->is_complex() && remainder_.size() == 0) {
  if (physical_) {
    if (model_->physical_dim() != model_->dim())
      throw ConfigError("reformulation.variables",
                        fmt::format("got \"physical\", but the model's state has {} entries and its physical "
                                    "state {} (it carries t for a time-dependent field): use \"model\"",
                                    model_->dim(), model_->physical_dim()));
    require_linear_to_physical(*model_);
    size_ = model_->physical_dim();
  }
  if (packing_.on()) {
    x_.setZero(size_);
    result_.setZero(size_);
  }
  if (const SecondOrderForm* form = model_->second_order_form(); form && !physical_)
    second_order_ = std::make_unique<SecondOrder>(*model_, *form, packing_, evaluations_);
  if (const ChargedParticleForm* form = model_->charged_particle_form(); form && !physical_)
    charged_particle_ = std::make_unique<ChargedParticle>(*model_, *form, packing_, evaluations_);
}

const Vector& Direct::values_of(const Vector& y) {
  if (!packing_.on()) return y;
  packing_.unpack(y.data(), x_.data());
  return x_;
}

void Direct::store(const Vector& values, Vector& out) const {
  if (&out != &values) packing_.pack_into(values.data(), out);
}

void Direct::linear_flow(Real h, Vector& y) {
  if (!packing_.on()) {
    y = model_->linear_flow(fast_phase(h, model_->eps()), y);
    model_->remainder_flow(h, y);
    return;
  }
  Vector x = model_->linear_flow(fast_phase(h, model_->eps()), values_of(y));
  model_->remainder_flow(h, x);
  store(x, y);
}

void Direct::nonlinear_flow(Real /*t*/, Real h, Vector& y) {
  ++evaluations_;
  if (!packing_.on()) return model_->nonlinear_flow(h, y);
  packing_.unpack(y.data(), x_.data());
  model_->nonlinear_flow(h, x_);
  store(x_, y);
}

void Direct::model_nonlinear(const Vector& u, Vector& out) {
  state_.col(0) = u;
  model_->nonlinear_field(state_, field_);
  out = field_.col(0);
}

void Direct::model_rhs(const Vector& u, Vector& out) {
  model_nonlinear(u, out);
  if (const HamiltonianStructure* h = model_->hamiltonian()) {  // J M u through the run's buffers (apply_A's default allocates)
    h->apply_M(u, mu_);
    h->apply_J(mu_, au_);
  } else {
    model_->apply_A(u, au_);
  }
  out += au_ / model_->eps();
  if (remainder_.size()) out += remainder_.cwiseProduct(u);
}

void Direct::evaluate(const Vector& y, Vector& out, bool with_linear_part) {
  ++evaluations_;
  const Vector& x = values_of(y);
  Vector& result = packing_.on() ? result_ : out;
  const auto field = [&](const Vector& u) { with_linear_part ? model_rhs(u, result) : model_nonlinear(u, result); };
  if (!physical_) {
    field(x);
  } else {  // in the model's variables, read back in the physical ones
    field(model_->from_physical(x));
    result = model_->to_physical(result);
  }
  store(result, out);
}

void Direct::nonlinear(Real /*t*/, const Vector& y, Vector& out) { evaluate(y, out, false); }

void Direct::nonlinear_derivative(Real /*t*/, const Vector& y, const Vector& dy, Vector& out) {
  const Vector x = packing_.unpacked(y), dx = packing_.unpacked(dy);
  state_.col(0) = physical_ ? model_->from_physical(x) : x;
  direction_.col(0) = physical_ ? model_->from_physical(dx) : dx;
  model_->nonlinear_field_derivative(state_, direction_, field_);
  store(physical_ ? model_->to_physical(field_.col(0)) : Vector(field_.col(0)), out);
}

void Direct::rhs(Real /*t*/, const Vector& y, Vector& out) { evaluate(y, out, true); }

}  // namespace tsi
