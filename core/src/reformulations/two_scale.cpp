#include "two_scale.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "remainder.hpp"
#include "sigma_nodes.hpp"
#include "tsi/algebra.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"

namespace tsi {
namespace {

// The tau grid's threads: only for a model whose bindings are independent, never more than
// the grid has rows (the transforms' parts) or columns.
int grid_threads(const Model& model, int n_tau, const Context& context) {
  if (!model.independent_tau_grid_bindings()) return 1;
  const Index threads = std::min<Index>({context.tau_grid_threads_for(model.dim() * n_tau), model.dim(), n_tau});
  return static_cast<int>(std::max<Index>(threads, 1));
}

#if defined(_OPENMP)
int thread_index() { return omp_get_thread_num(); }
int team_size() { return omp_get_num_threads(); }
void barrier() {
#pragma omp barrier
}
#else
int thread_index() { return 0; }
int team_size() { return 1; }
void barrier() {}
#endif

/// The asymptotic recursion's stopping rule: order k (> 2) is kept while its correction to
/// order k - 1 does not grow. Growth at the rounding level of the data is noise, not
/// divergence: those corrections are kept.
bool keeps_decreasing(int k, double correction, double last_correction, double data_norm) {
  const double rounding = 64.0 * std::numeric_limits<double>::epsilon() * data_norm;
  return k <= 2 || correction <= std::max(last_correction, rounding);
}

/// The trajectory's points for data of order p: data of order p differentiate p - 2 times
/// along it (level k differentiates level k - 1), so its polynomial needs degree p - 2 (with 5
/// points, order 7 lost its eps^6 term: 1.7e-12 off at eps = 1/32, 1e-15 with 7). A remainder
/// turns the high modes fast along it: 7 points resolve them (Klein-Gordon, eps = 1e-4: 2e-15
/// off with 5, 5e-19 with 7).
int trajectory_point_count(int order, bool remainder) { return remainder || order > 6 ? 7 : 5; }

/// The trajectory's half length with m points, in units of the time in which the averaged flow
/// at the data moves by their own size: shorter loses digits to the differentiation (eps D / h
/// per level, D's largest row (m - 1)^2), longer to the interpolation ((h speed)^(m-1)). A
/// higher degree allows a longer one (NLS, order 7 at eps = 1/16: 1.9e-12 off at 0.01, 7e-14 at
/// 0.03), the fast rotations of a remainder do not (Klein-Gordon, order 7 at eps = 1/256:
/// 1.7e-14 at 0.01, 1.5e-12 at 0.03). Measured on Henon-Heiles, NLS, the charged particle and
/// Klein-Gordon at eps = 1e-4 .. 1 (docs/high-order.md).
double trajectory_length(int m, bool remainder) { return m > 5 && !remainder ? 0.03 : 0.01; }
// The order of the central quotients' data where the trajectory's sweeps diverge.
constexpr int central_fallback_order = 4;

}  // namespace

TwoScale::TwoScale(std::shared_ptr<const Model> model, int n_tau, int initial_data_order,
                   Repreparation repreparation, DataMethod data_method, bool real_layout, const Context& context)
    : Reformulation(std::move(model)),
      dim_(model_->dim()),
      n_tau_(n_tau),
      real_layout_(real_layout && real_layout_for(*model_) && n_tau > 0 && n_tau % 2 == 0),
      columns_(real_layout_ ? n_tau / 2 + 1 : n_tau),
      data_order_(initial_data_order),
      data_method_(data_method),
      eps_(model_->eps()),
      taus_(n_tau),
      remainder_(model_remainder(*model_)),
      wave_numbers_(n_tau),
      threads_(grid_threads(*model_, n_tau, context)),
      repreparation_(repreparation) {
  if (n_tau <= 0 || n_tau % 2 != 0)
    throw ConfigError("reformulation.n_tau",
                      "got " + std::to_string(n_tau) + ", expected a positive even integer");
  if (initial_data_order < 1 || initial_data_order > max_data_order)
    throw ConfigError("reformulation.initial_data_order", "got " + std::to_string(initial_data_order) +
                                                              ", expected an integer from 1 to " +
                                                              std::to_string(max_data_order));
  if (remainder_.size()) remainder_grid_ = remainder_.replicate(columns_, 1);
  const Index run = remainder_.size() ? 1 : diagonal_run(*model_);
  Vector multipliers(run == 1 ? dim_ * columns_ : columns_);
  for (int j = 0; j < n_tau; ++j) {
    taus_(j) = two_pi * j / n_tau;
    wave_numbers_(j) = j <= n_tau / 2 ? j : j - n_tau;
    if (j >= columns_) continue;  // the real layout stores modes 0 .. n/2
    // Nyquist: -i k / eps is 0 there, as the Fourier differentiation matrix has it.
    const double k = (2 * j == n_tau) ? 0.0 : wave_numbers_(j);
    if (run > 1) {
      multipliers(j) = Complex(0.0, -k / eps_);
      continue;
    }
    multipliers.segment(j * dim_, dim_).setConstant(Complex(0.0, -k / eps_));
    if (remainder_.size()) multipliers.segment(j * dim_, dim_) += remainder_;
  }
  multipliers_ = Diagonal(std::move(multipliers), run);
  const int rows = static_cast<int>(dim_);
  if (real_layout_) {
    real_fft_ = std::make_unique<RealFftBatch>(n_tau, rows, threads_);
    grid_values_.setZero(dim_, n_tau);
  } else {
    fft_ = std::make_unique<FftBatch>(n_tau, rows, threads_, context.fft);
  }
  grid_field_ = model_->bind_tau_grid(taus_);
  for (int p = 0; p <= threads_; ++p) column_begin_.push_back(static_cast<Index>(n_tau) * p / threads_);
  for (int p = 0; threads_ > 1 && p < threads_; ++p)
    column_fields_.push_back(model_->bind_tau_grid(taus_.segment(column_begin_[p], column_begin_[p + 1] - column_begin_[p])));
  if (real_layout_) {
    real_kernels_ = grid_field_->evaluates_real();
    for (const auto& f : column_fields_) real_kernels_ = real_kernels_ && f->evaluates_real();
    bool in_place = real_kernels_ && grid_field_->in_place();
    for (const auto& f : column_fields_) in_place = in_place && f->in_place();
    if (!in_place) field_values_.setZero(dim_, n_tau);
    if (!real_kernels_) {
      complex_grid_.setZero(dim_, n_tau);
      complex_field_.setZero(dim_, n_tau);
    }
  }
}

bool TwoScale::real_layout_for(const Model& model) {
  // A remainder turns coordinates by complex phases: its U is complex (a real model has none).
  return !model.is_complex() && !model.has_linear_remainder();
}

Index TwoScale::diagonal_run(const Model& model) {
  return model_remainder(model).size() == 0 && model.dim() >= min_diagonal_run ? model.dim() : 1;
}

double TwoScale::work_vectors(const Model& model, int initial_data_order, const std::string& data_method,
                              double* preparation) {
  // The closed formulas (orders 2, 3) hold at most 4 grids at once (r2), the central quotients
  // a grid per level of their recursion and its quotient's four, the recursion along a
  // trajectory the previous and the next level at its m points (trajectory_data).
  const bool remainder = model_remainder(model).size() > 0;
  double prepare = 2.0;
  if (initial_data_order >= 2) {
    if (data_method == "central")
      prepare = 3.0 + 2.0 * initial_data_order;
    else if (data_method == "recursion" || initial_data_order > 3)
      prepare = 2.0 * trajectory_point_count(initial_data_order, remainder) + 3.0;
    else
      prepare = initial_data_order == 3 ? 5.0 : 2.0;
  }
  if (preparation) *preparation = prepare;
  return 1.0 + (remainder ? 2.0 : 0.0) + prepare;
}

void TwoScale::nonlinear(double /*t*/, const Vector& y, Vector& out) { nonlinear_shifted(y, nullptr, out); }

void TwoScale::nonlinear_shifted(const Vector& y, const Vector* mean_shift, Vector& out) {
  ++evaluations_;
  if (real_layout_) return nonlinear_real(y, mean_shift, out);
  if (threads_ > 1) return nonlinear_threaded(y, mean_shift, out);
  // The grid in out's storage: the tau transforms go through their small blocks, and a model
  // that evaluates in place needs no grid of the state's size besides out.
  out.resize(size());
  fft_->transform(y.data(), out.data(), 1, 1.0, mean_shift ? mean_shift->data() : nullptr);
  Eigen::Map<Matrix> grid(out.data(), dim_, n_tau_);
  Complex* field = out.data();
  if (grid_field_->in_place()) {
    grid_field_->evaluate(grid, grid);
  } else {
    field_.resize(dim_, n_tau_);
    grid_field_->evaluate(grid, field_);
    field = field_.data();
  }
  fft_->transform(field, out.data(), 0, 1.0 / n_tau_);  // the 1/n of the transform
}

void TwoScale::nonlinear_threaded(const Vector& y, const Vector* mean_shift, Vector& out) {
  // As the serial path: the grid in out's storage, each thread's rows transformed through its
  // own block, the field in place where the model allows it.
  out.resize(size());
  const bool in_place = std::all_of(column_fields_.begin(), column_fields_.end(),
                                    [](const std::unique_ptr<TauGridField>& f) { return f->in_place(); });
  if (!in_place) field_.resize(dim_, n_tau_);
  Eigen::Map<Matrix> grid(out.data(), dim_, n_tau_);
  Complex* field = in_place ? out.data() : field_.data();
  const Complex* shift = mean_shift ? mean_shift->data() : nullptr;
  on_grid_threads([&](int p) { fft_->transform(y.data(), out.data(), 1, 1.0, shift, p); },
                  [&](int p, Index c0, Index cn) {
                    if (in_place)
                      column_fields_[p]->evaluate(grid.middleCols(c0, cn), grid.middleCols(c0, cn));
                    else
                      column_fields_[p]->evaluate(grid.middleCols(c0, cn), field_.middleCols(c0, cn));
                  },
                  [&](int p) { fft_->transform(field, out.data(), 0, 1.0 / n_tau_, nullptr, p); });
}

template <class In, class Field, class Out>
void TwoScale::on_grid_threads(In&& transform_in, Field&& evaluate, Out&& transform_out) {
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads_));
  // Transforms go by rows, the field by columns; every phase reads what the one before wrote
  // on other threads, hence the barriers. A team smaller than asked for (an OpenMP limit)
  // takes several parts per thread.
#if defined(_OPENMP)
#pragma omp parallel num_threads(threads_)
#endif
  {
    for (int p = thread_index(); p < threads_; p += team_size()) transform_in(p);
    barrier();
    for (int p = thread_index(); p < threads_; p += team_size()) {
      try {
        evaluate(p, column_begin_[p], column_begin_[p + 1] - column_begin_[p]);
      } catch (...) {
        errors[p] = std::current_exception();
      }
    }
    barrier();
    for (int p = thread_index(); p < threads_; p += team_size()) transform_out(p);
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
}

void TwoScale::nonlinear_real(const Vector& y, const Vector* mean_shift, Vector& out) {
  out.resize(size());
  const bool in_place = field_values_.size() == 0;
  const double* field = in_place ? grid_values_.data() : field_values_.data();
  const auto transform_in = [&](int part) {
    // The mean shift is a constant in tau: added to the grid values, as to the mean mode.
    real_fft_->backward(y.data(), grid_values_.data(), part);
    if (!mean_shift) return;
    const Index r0 = part < 0 ? 0 : real_fft_->part_begin(part);
    const Index rn = part < 0 ? dim_ : real_fft_->part_begin(part + 1) - r0;
    grid_values_.middleRows(r0, rn).colwise() += mean_shift->segment(r0, rn).real();
  };
  const double scale = 1.0 / n_tau_;  // the 1/n of the transform
  if (threads_ <= 1) {
    transform_in(-1);
    evaluate_real_grid(*grid_field_, 0, n_tau_);
    real_fft_->forward_unnormalised(field, out.data());
    out *= scale;
    return;
  }
  on_grid_threads(transform_in, [&](int p, Index c0, Index cn) { evaluate_real_grid(*column_fields_[p], c0, cn); },
                  [&](int p) {
                    real_fft_->forward_unnormalised(field, out.data(), p);
                    const Index r0 = real_fft_->part_begin(p), rn = real_fft_->part_begin(p + 1) - r0;
                    Eigen::Map<Matrix>(out.data(), dim_, columns_).middleRows(r0, rn) *= scale;
                  });
}

void TwoScale::evaluate_real_grid(TauGridField& field, Index c0, Index cn) {
  auto values = grid_values_.middleCols(c0, cn);
  if (real_kernels_) {
    if (field_values_.size() == 0) return field.evaluate_real(values, values);
    return field.evaluate_real(values, field_values_.middleCols(c0, cn));
  }
  complex_grid_.middleCols(c0, cn) = values.cast<Complex>();
  field.evaluate(complex_grid_.middleCols(c0, cn), complex_field_.middleCols(c0, cn));
  field_values_.middleCols(c0, cn) = complex_field_.middleCols(c0, cn).real();
}

void TwoScale::nonlinear_derivative(double /*t*/, const Vector& y, const Vector& dy, Vector& out) {
  const Matrix result = df_coefficients(to_grid(all_modes(Eigen::Map<const Matrix>(y.data(), dim_, columns_))),
                                        to_grid(all_modes(Eigen::Map<const Matrix>(dy.data(), dim_, columns_))));
  out = Eigen::Map<const Vector>(result.data(), size());  // modes 0 .. columns_ - 1
}

void TwoScale::rhs(double t, const Vector& y, Vector& out) {
  nonlinear(t, y, out);
  algebra::diagonal_multiply_add(out, multipliers_, y, out);
}

Matrix TwoScale::to_grid(const Matrix& c) {
  if (real_layout_) {
    RealMatrix values(dim_, n_tau_);
    real_fft_->backward(c.data(), values.data());  // modes 0 .. N/2: the first columns of c
    return values.cast<Complex>();
  }
  Matrix grid(dim_, n_tau_);
  fft_->transform(c.data(), grid.data(), 1);
  return grid;
}

Matrix TwoScale::to_coefficients(Matrix grid) {
  if (real_layout_) {
    const RealMatrix values = grid.real();
    grid.resize(0, 0);
    Matrix c(dim_, columns_);
    real_fft_->forward_unnormalised(values.data(), c.data());
    c *= 1.0 / n_tau_;
    return all_modes(c);
  }
  fft_->transform(grid.data(), grid.data(), 0, 1.0 / n_tau_);
  return grid;
}

Matrix TwoScale::all_modes(ConstMatrixRef stored) const {
  if (!real_layout_) return stored;
  Matrix c(dim_, n_tau_);
  c.leftCols(columns_) = stored;
  for (int j = 1; 2 * j < n_tau_; ++j) c.col(n_tau_ - j) = stored.col(j).conjugate();
  return c;
}

double TwoScale::coefficient_norm(const Vector& y, bool without_mean) const {
  const Eigen::Map<const Matrix> c(y.data(), dim_, columns_);
  double sum = 0.0;
  for (int j = without_mean ? 1 : 0; j < columns_; ++j)
    sum += (real_layout_ && j > 0 && 2 * j < n_tau_ ? 2.0 : 1.0) * c.col(j).squaredNorm();
  return std::sqrt(sum);
}

Matrix TwoScale::f_coefficients(Matrix w) {
  ++evaluations_;
  if (grid_field_->in_place()) {
    grid_field_->evaluate(w, w);
    return to_coefficients(std::move(w));
  }
  Matrix f(dim_, n_tau_);
  grid_field_->evaluate(w, f);
  w.resize(0, 0);
  return to_coefficients(std::move(f));
}

Matrix TwoScale::df_coefficients(Matrix w, Matrix z) {
  ++evaluations_;
  model_->linear_flow(taus_, w);
  model_->linear_flow(taus_, z);
  Matrix df(dim_, n_tau_);
  model_->nonlinear_field_derivative(w, z, df);
  w.resize(0, 0);
  z.resize(0, 0);
  model_->linear_flow(RealVector(-taus_), df);
  return to_coefficients(std::move(df));
}

Matrix TwoScale::apply_A(Matrix c) const {
  for (int j = 0; j < n_tau_; ++j) {
    if (antiderivative(j) == 0.0)
      c.col(j).setZero();
    else
      c.col(j) /= Complex(0.0, wave_numbers_(j));
  }
  return c;
}

Complex TwoScale::antiderivative(int j) const {
  return j == 0 || 2 * j == n_tau_ ? Complex(0.0) : 1.0 / Complex(0.0, wave_numbers_(j));
}

Matrix TwoScale::r1(const Vector& w) { return apply_A(f_coefficients(w.replicate(1, n_tau_))); }

Matrix TwoScale::r2(const Vector& w) {
  // At most four grids at once: the constant grid of w is made again for each use.
  Matrix f = f_coefficients(w.replicate(1, n_tau_));
  Vector drift = f.col(0);  // the averaged field at w, Pi f(w) + JR w: constant in tau
  if (remainder_.size()) drift += remainder_.cwiseProduct(w);
  Matrix remainder_term;
  if (remainder_.size()) remainder_term = remainder_.asDiagonal() * apply_A(apply_A(f));
  Matrix af_grid = to_grid(apply_A(std::move(f)));
  Matrix r = apply_A(df_coefficients(w.replicate(1, n_tau_), std::move(af_grid)));
  r -= apply_A(apply_A(df_coefficients(w.replicate(1, n_tau_), drift.replicate(1, n_tau_))));
  if (remainder_.size()) r += remainder_term;
  return r;
}

double TwoScale::tau_spread(const Vector& y) const {
  const double total = std::pow(coefficient_norm(y), 2);
  return total > 0.0 ? std::pow(coefficient_norm(y, true), 2) / total : 0.0;
}

Vector TwoScale::evaluate(ConstMatrixRef c, double tau) const {
  Vector value = Vector::Zero(dim_);
  if (c.cols() != n_tau_) {  // the real layout: modes k and -k together, 2 Re(c_k e^{i k tau})
    for (int j = 0; j < c.cols(); ++j) {
      if (j == 0)
        value += c.col(0).real().cast<Complex>();
      else if (2 * j == n_tau_)
        value += c.col(j).real().cast<Complex>() * std::cos(0.5 * n_tau_ * tau);
      else
        value += (2.0 * (c.col(j) * std::polar(1.0, j * tau)).real()).cast<Complex>();
    }
    return value;
  }
  for (int j = 0; j < n_tau_; ++j) {
    if (2 * j == n_tau_)  // half at +n/2, half at -n/2: a real U stays real
      value += c.col(j) * std::cos(0.5 * n_tau_ * tau);
    else
      value += c.col(j) * std::polar(1.0, wave_numbers_(j) * tau);
  }
  return value;
}

Vector TwoScale::prepare(const Vector& u0) {
  data_order_reached_ = data_order_;
  repreparation_times_.clear();
  last_prepared_ = 0;
  return prepared_at(u0, 0.0);
}

Vector TwoScale::prepared_at(const Vector& v, double s) {
  Matrix c;
  if (data_method_ == DataMethod::central)
    c = central_data(v, s, data_order_);
  else if (data_method_ == DataMethod::recursion || data_order_ > 3)
    c = trajectory_data(v, s);
  else
    c = closed_data(v, s);
  Vector out = Eigen::Map<const Vector>(c.data(), size());
  return out;
}

Matrix TwoScale::closed_data(const Vector& v, double s) {
  Matrix c;
  if (data_order_ < 2) c = Matrix::Zero(dim_, n_tau_);
  if (data_order_ >= 2) {
    // eq. (2nd data) centred at s; order 3 evaluates r1 at vbar = v - eps r1(v)(s) and adds
    // eps^2 r2(v). s = 0 is the initial data.
    Matrix r = r1(v);
    if (data_order_ == 3) {
      const Vector vbar = v - eps_ * evaluate(r, s);
      r.resize(0, 0);  // r2's grids next, without it
      r = eps_ * r2(v);
      r = r1(vbar) + r;
    }
    r *= eps_;
    c = std::move(r);
    c.col(0) -= evaluate(c, s);  // U(s) = v exactly: subtract the value at tau = s
  }
  c.col(0) += v;
  return c;
}

Matrix TwoScale::central_data(const Vector& v, double s, int order) {
  // The base point from the fixed point u = v - Phi(u)(s), one iteration per order (each gains
  // a factor eps), as HOODESolver.jl does: U = u + Phi^k(u_prev), exact at s by construction.
  // The expansion is asymptotic: at eps near 1 its corrections stop decreasing (Henon-Heiles at
  // eps = 1: 2.3e-3 at order 5, 2.6e-3 at 6, 4.0 at 8), so it is truncated where they grow,
  // at its smallest term, and the order reached is recorded.
  Matrix data = Matrix::Zero(dim_, n_tau_), c = data;
  data.col(0) = v;
  Vector u = v;
  double last_correction = std::numeric_limits<double>::infinity();
  data_order_reached_ = 1;
  for (int k = 2; k <= order; ++k) {
    Matrix next = central_phi(u, k);
    const Vector next_u = v - evaluate(next, s);
    Matrix candidate = next;
    candidate.col(0) += next_u;
    const double correction = (candidate - data).norm();
    if (!keeps_decreasing(k, correction, last_correction, data.norm())) break;
    last_correction = correction;
    data.swap(candidate);
    u = next_u;
    data_order_reached_ = k;
  }
  return data;
}

Matrix TwoScale::central_phi(const Vector& u, int k) {
  if (k <= 1) return Matrix::Zero(dim_, n_tau_);
  const Matrix previous = central_phi(u, k - 1);
  const Matrix f = f_coefficients(u.replicate(1, n_tau_) + to_grid(previous));
  Matrix rhs = f;
  if (remainder_.size()) rhs += remainder_.asDiagonal() * previous;
  if (k >= 3) {
    // D Phi^{k-1}(u) G by the central difference of fourth order with step d = eps^((k-2)/4):
    // its error, d^4 times the fifth derivative of Phi^{k-1} (O(eps)), is O(eps^(k-1)) and
    // eps^k after the factor eps A, as the recursion needs. HOODESolver's forward quotient
    // with step eps^(k-2) divides rounding errors by eps^(k-2) at every level (about
    // (k-1)(k-2)/2 log10(1/eps) digits lost at order k); this step loses none up to order 6
    // (docs/high-order.md has the measurement).
    Vector g = f.col(0);
    if (remainder_.size()) g += remainder_.cwiseProduct(u);
    const double d = std::pow(eps_, 0.25 * (k - 2));
    const auto at = [&](double shift) { return central_phi(u + shift * d * g, k - 1); };
    const Matrix derivative = (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * d);
    rhs -= derivative;
  }
  return eps_ * apply_A(rhs);
}

Matrix TwoScale::trajectory_data(const Vector& v, double s) {
  // The recursion of central_data, with D Phi^{k-1}(u) G taken as d/dsigma along one trajectory
  // sigma -> c(sigma) of the averaged flow c' = G(c) through the base point: on it every level
  // closes on the points c_i = c(h x_i) themselves, Phi^k(c_i) = eps A [ f(c_i + Phi^{k-1}(c_i))
  // + JR Phi^{k-1}(c_i) - (d/dsigma Phi^{k-1})(c_i) ], one evaluation per point and level. One
  // trajectory serves every level: a G off by dG costs eps^2 dG (eps A, and D Phi = O(eps)), so
  // the trajectory of the most accurate averaged field serves all orders below it.
  data_order_reached_ = 1;
  if (data_order_ < 2) {
    Matrix data = Matrix::Zero(dim_, n_tau_);
    data.col(0) = v;
    return data;
  }
  Matrix f = f_coefficients(v.replicate(1, n_tau_));
  if (data_order_ == 2) {  // Phi^2 = eps A f needs no trajectory
    Matrix phi = apply_A(std::move(f));
    phi *= eps_;
    phi.col(0) += v - evaluate(phi, s);
    data_order_reached_ = 2;
    return phi;
  }
  // The trajectory's half length h: a fixed fraction of the time in which the averaged flow
  // at v moves by |v|. Shorter loses digits to the differentiation (eps D/h per level), longer
  // to the interpolation of the trajectory (measured: docs/high-order.md).
  const bool remainder = remainder_.size() > 0;
  const SigmaNodes nodes(trajectory_point_count(data_order_, remainder));
  Vector drift = f.col(0);
  f.resize(0, 0);
  if (remainder) drift += remainder_.cwiseProduct(v);
  const double speed = drift.norm() / v.norm();
  const double length = trajectory_length(static_cast<int>(nodes.x.size()), remainder);
  const double h = speed > 0.0 && std::isfinite(speed) ? length / speed : length;
  const int m = static_cast<int>(nodes.x.size()), c = nodes.center;
  const std::optional<std::vector<Vector>> trajectory = averaged_trajectory(v, s, nodes, h, drift);
  // No trajectory where the expansion diverges from its first orders on (eps near 1): there the
  // central quotients' coarse steps (d = 1 at eps = 1) give the better data (the charged
  // particle at eps = 1, re-prepared: err_H 6.4e-4 against 1.3e-3 by the trajectory), up to
  // order 4 (38 evaluations: orders beyond it gain nothing there).
  if (!trajectory) return central_data(v, s, std::min(data_order_, central_fallback_order));
  const std::vector<Vector>& points = *trajectory;
  Matrix data = Matrix::Zero(dim_, n_tau_);
  data.col(0) = v;
  std::vector<Vector> previous(m, Vector::Zero(size())), next(m, Vector(size())), drifts(m);
  double last_correction = std::numeric_limits<double>::infinity();
  for (int k = 2; k <= data_order_; ++k) {
    trajectory_level(points, previous, nodes, h, next, drifts, k == data_order_ ? c : -1);
    Matrix candidate = all_modes(Eigen::Map<const Matrix>(next[c].data(), dim_, columns_));
    candidate.col(0) += v - evaluate(candidate, s);  // U(s) = v exactly
    const double correction = (candidate - data).norm();
    if (!keeps_decreasing(k, correction, last_correction, data.norm())) break;
    last_correction = correction;
    data.swap(candidate);
    data_order_reached_ = k;
    previous.swap(next);
  }
  return data;
}

std::optional<std::vector<Vector>> TwoScale::averaged_trajectory(const Vector& v, double s, const SigmaNodes& nodes,
                                                                 double h, const Vector& drift) {
  // Sweeps of the whole system at once: Phi at the points gains an order, the base point
  // u = v - Phi(u)(s) follows it, and the trajectory takes a Picard step with the averaged field
  // they give. The data of order p then lose eps |du| to the base point and eps^2 |dc| to the
  // trajectory (measured); the sweeps stop when these fall below the data's own error.
  const int m = static_cast<int>(nodes.x.size()), c = nodes.center;
  std::vector<Vector> points = picard_step(v, std::vector<Vector>(m, drift), nodes, h);
  std::vector<Vector> phi(m, Vector::Zero(size())), next(m, Vector(size())), drifts(m);
  const double target =
      std::max(64.0 * std::numeric_limits<double>::epsilon(), 1e-3 * std::pow(eps_, data_order_)) * v.norm();
  // The sweeps gain about a factor eps each; where they gain less (Klein-Gordon at eps = 1e-2:
  // 5-10x) the data's own truncation is as slow, and a few sweeps more suffice.
  const int max_sweeps = data_order_ + 4;
  Vector u = v;
  double last_change = std::numeric_limits<double>::infinity();
  for (int sweep = 1; sweep <= max_sweeps; ++sweep) {
    trajectory_level(points, phi, nodes, h, next, drifts);
    const Vector next_u = v - evaluate(Eigen::Map<const Matrix>(next[c].data(), dim_, columns_), s);
    std::vector<Vector> next_points = picard_step(next_u, drifts, nodes, h);
    double change = 0.0, moved = 0.0;
    for (int i = 0; i < m; ++i) {
      change = std::max(change, coefficient_norm(next[i] - phi[i]));
      moved = std::max(moved, (next_points[i] - points[i]).norm());
    }
    // Near eps = 1 the sweeps can diverge with the asymptotic series: no trajectory then.
    if (sweep > 2 && !(change < 2.0 * last_change)) return std::nullopt;
    last_change = change;
    const double error = eps_ * (next_u - u).norm() + eps_ * eps_ * moved;
    phi.swap(next);
    points.swap(next_points);
    u = next_u;
    if (error <= target) break;
  }
  return points;
}

void TwoScale::trajectory_level(const std::vector<Vector>& points, const std::vector<Vector>& previous,
                                const SigmaNodes& nodes, double h, std::vector<Vector>& next,
                                std::vector<Vector>& drift, int only) {
  const int m = static_cast<int>(points.size());
  const auto phi = [&](int j) { return Eigen::Map<const Matrix>(previous[j].data(), dim_, columns_); };
  for (int i = 0; i < m; ++i) {
    if (only >= 0 && i != only) continue;
    nonlinear_shifted(previous[i], &points[i], next[i]);  // f at c_i + previous_i(tau)
    Eigen::Map<Matrix> rhs(next[i].data(), dim_, columns_);
    drift[i] = rhs.col(0);
    if (remainder_.size()) drift[i] += remainder_.cwiseProduct(points[i]);
    // One pass per tau mode over the m points' data (each mode a few hundred kB at most).
    for (int col = 0; col < columns_; ++col) {
      auto mode = rhs.col(col);
      const Complex factor = eps_ * antiderivative(col);
      if (factor == 0.0) {
        mode.setZero();
        continue;
      }
      if (remainder_.size()) mode += remainder_.cwiseProduct(phi(i).col(col));
      for (int j = 0; j < m; ++j)
        if (nodes.differentiate(i, j) != 0.0) mode -= (nodes.differentiate(i, j) / h) * phi(j).col(col);
      mode *= factor;
    }
  }
}

std::vector<Vector> TwoScale::picard_step(const Vector& u, const std::vector<Vector>& drift, const SigmaNodes& nodes,
                                          double h) const {
  const int m = static_cast<int>(drift.size());
  std::vector<Vector> points(m, u);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) points[i] += (h * nodes.integrate(i, j)) * drift[j];
  return points;
}

bool TwoScale::between_steps(long n, double t, Vector& y) {
  if (repreparation_.mode == Repreparation::Mode::Never) return false;
  if (repreparation_.mode == Repreparation::Mode::Every && n % repreparation_.every != 0) return false;
  if (repreparation_.mode == Repreparation::Mode::Auto && (n - last_prepared_) % repreparation_.min_gap != 0)
    return false;
  const double s = fast_phase(t, eps_);
  const Vector v = evaluate(Eigen::Map<const Matrix>(y.data(), dim_, columns_), s);
  Vector prepared = prepared_at(v, s);
  if (repreparation_.mode == Repreparation::Mode::Auto) {
    // U is due when it has drifted off the prepared data through its own diagonal value by more
    // than a fraction of that data's tau variation (column 0 of the coefficients is the mean).
    const double variation = coefficient_norm(prepared, true);
    // A defect below defect_floor |U| is the scheme's own error, not the characteristics coming
    // apart (NLS at eps = 0.01: re-preparing on it made err_H 9x worse than never).
    const double threshold =
        std::max(repreparation_.defect * variation, repreparation_.defect_floor * coefficient_norm(prepared));
    if (!(coefficient_norm(y - prepared) > threshold)) return false;
  }
  y.swap(prepared);
  repreparation_times_.push_back(t);
  last_prepared_ = n;
  return true;
}

Vector TwoScale::read_back(const Vector& y, double t) {
  const double tau = fast_phase(t, eps_);
  return model_->linear_flow(tau, evaluate(Eigen::Map<const Matrix>(y.data(), dim_, columns_), tau));
}

double TwoScale::tau_roughness(const Vector& y) const {
  const Eigen::Map<const Matrix> c(y.data(), dim_, columns_);
  double total = 0.0, top = 0.0;
  for (int j = 0; j < columns_; ++j) {
    const double e = (real_layout_ && j > 0 && 2 * j < n_tau_ ? 2.0 : 1.0) * c.col(j).squaredNorm();
    total += e;
    if (8.0 * std::abs(wave_numbers_(j)) > 3.0 * n_tau_) top += e;  // |k| > 3/8 n: top quarter
  }
  return total > 0.0 ? top / total : 0.0;
}

}  // namespace tsi
