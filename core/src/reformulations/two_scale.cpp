#include "two_scale.hpp"

#include <algorithm>
#include <cmath>

#include "remainder.hpp"
#include "tsi/algebra.hpp"
#include "tsi/phase.hpp"

namespace tsi {

TwoScale::TwoScale(std::shared_ptr<const Model> model, int n_tau, int initial_data_order,
                   Repreparation repreparation, DataMethod data_method, bool real_layout, const Context& context)
    : Reformulation(std::move(model)),
      eps_(model_->eps()),
      remainder_(model_remainder(*model_)),
      grid_(model_, n_tau, real_layout, context, evaluations_),
      data_(grid_, eps_, remainder_, initial_data_order, data_method),
      repreparer_(grid_, data_, eps_, repreparation) {
  const Index dim = grid_.dim();
  const int columns = grid_.columns();
  if (remainder_.size()) remainder_grid_ = remainder_.replicate(columns, 1);
  const Index run = remainder_.size() ? 1 : diagonal_run(*model_);
  Vector multipliers(run == 1 ? dim * columns : columns);
  for (int j = 0; j < columns; ++j) {  // the real layout stores modes 0 .. n/2
    // Nyquist: -i k / eps is 0 there, as the Fourier differentiation matrix has it.
    const Real k = (2 * j == n_tau) ? 0.0 : grid_.wave_numbers()(j);
    if (run > 1) {
      multipliers(j) = Complex(0.0, -k / eps_);
      continue;
    }
    multipliers.segment(j * dim, dim).setConstant(Complex(0.0, -k / eps_));
    if (remainder_.size()) multipliers.segment(j * dim, dim) += remainder_;
  }
  multipliers_ = Diagonal(std::move(multipliers), run).with_threads(grid_.threads());  // the schemes' combinations too
}

void TwoScale::average_nyquist() {
  const int n_tau = grid_.n_tau(), nyquist = n_tau / 2;
  const Index run = multipliers_.run();
  RealVector pairs = RealVector::Zero(multipliers_.values().size());
  const Real k = nyquist / eps_;
  if (run > 1)
    pairs(nyquist) = k;
  else
    pairs.segment(nyquist * grid_.dim(), grid_.dim()).setConstant(k);
  multipliers_ = multipliers_.with_pairs(std::move(pairs));
}

Index TwoScale::diagonal_run(const Model& model) {
  return model_remainder(model).size() == 0 && model.dim() >= min_diagonal_run ? model.dim() : 1;
}

double TwoScale::work_vectors(const Model& model, int initial_data_order, const std::string& data_method,
                              double* preparation) {
  const bool remainder = model_remainder(model).size() > 0;
  const double prepare = PreparedData::work_vectors(model, initial_data_order, data_method);
  if (preparation) *preparation = prepare;
  return 1.0 + (remainder ? 2.0 : 0.0) + prepare;
}

void TwoScale::nonlinear(Real t, const Vector& y, Vector& out) { grid_.nonlinear(y, nullptr, out, fast_phase(t, eps_)); }

void TwoScale::nonlinear_derivative(Real /*t*/, const Vector& y, const Vector& dy, Vector& out) {
  const Index dim = grid_.dim();
  const int columns = grid_.columns();
  const Matrix result =
      grid_.df_coefficients(grid_.to_grid(grid_.all_modes(Eigen::Map<const Matrix>(y.data(), dim, columns))),
                            grid_.to_grid(grid_.all_modes(Eigen::Map<const Matrix>(dy.data(), dim, columns))));
  out = Eigen::Map<const Vector>(result.data(), size());  // modes 0 .. columns - 1
}

void TwoScale::rhs(Real t, const Vector& y, Vector& out) {
  nonlinear(t, y, out);
  algebra::diagonal_multiply_add(out, multipliers_, y, out);
}

Vector TwoScale::prepare(const Vector& u0) {
  repreparer_.reset();
  return data_.at(u0, 0.0);
}

Vector TwoScale::read_back(const Vector& y, Real t) {
  const Real tau = fast_phase(t, eps_);
  return model_->linear_flow(tau, grid_.evaluate(Eigen::Map<const Matrix>(y.data(), grid_.dim(), grid_.columns()), tau));
}

TauProfile TwoScale::tau_profile(const Vector& y) const {
  const RealVector energies = grid_.column_energies(y);  // one pass, summed over every process
  const Real total = energies.sum();
  Real top = 0.0;
  for (int j = 0; j < grid_.columns(); ++j)
    if (8.0 * std::abs(grid_.wave_numbers()(j)) > 3.0 * grid_.n_tau()) top += energies(j);  // |k| > 3/8 n: top quarter
  if (!(total > 0.0)) return {0.0, 0.0};
  return {top / total, energies.tail(grid_.columns() - 1).sum() / total};
}

Real TwoScale::tau_roughness(const Vector& y) const { return tau_profile(y).roughness; }
Real TwoScale::tau_spread(const Vector& y) const { return tau_profile(y).spread; }

}  // namespace tsi
