#include "tau_grid.hpp"

#include "tsi/collective.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "tsi/device.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"
#include "tsi/stop_request.hpp"

namespace tsi {
namespace {

// n_tau, checked before anything of its size is allocated.
int checked_n_tau(int n_tau) {
  if (n_tau <= 0 || n_tau % 2 != 0)
    throw ConfigError("reformulation.n_tau", "got " + std::to_string(n_tau) + ", expected a positive even integer");
  return n_tau;
}

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

}  // namespace

TauGrid::TauGrid(std::shared_ptr<const Model> model, int n_tau, bool real_layout, const Context& context,
                 long& evaluations)
    : model_(std::move(model)),
      dim_(model_->dim()),
      n_tau_(checked_n_tau(n_tau)),
      real_layout_(real_layout && real_layout_for(*model_)),
      columns_(real_layout_ ? n_tau / 2 + 1 : n_tau),
      evaluations_(&evaluations),
      taus_(n_tau),
      wave_numbers_(n_tau),
      threads_(grid_threads(*model_, n_tau, context)),
      collective_(context.collective) {
  for (int j = 0; j < n_tau; ++j) {
    taus_(j) = two_pi * j / n_tau;
    wave_numbers_(j) = j <= n_tau / 2 ? j : j - n_tau;
  }
  const int rows = static_cast<int>(dim_);
  if (real_layout_) {
    real_fft_ = std::make_unique<RealFftBatch>(n_tau, rows, threads_);
  } else {
    fft_ = std::make_unique<FftBatch>(n_tau, rows, threads_, context.fft);
  }
  grid_field_ = model_->bind_tau_grid(taus_);
  needs_diagonal_ = grid_field_->needs_diagonal();
  // A real field independent across groups of rows goes by blocks of 64 groups (64 particles x
  // 16 tau points are 32 kB of values), the one binding on every thread: no grid of the
  // state's size, no binding per thread.
  if (const Index group = grid_field_->independent_row_group();
      real_layout_ && grid_field_->evaluates_real() && group > 0) {
    if (dim_ % group != 0)
      throw Error("tau grid: the model's independent row groups (" + std::to_string(group) +
                  " rows) do not divide its dimension " + std::to_string(dim_));
    real_kernels_ = true;
    row_blocks_ = std::make_unique<RealFftRows>(n_tau, dim_, 64 * group);
    return;
  }
  for (int p = 0; p <= threads_; ++p) column_begin_.push_back(static_cast<Index>(n_tau) * p / threads_);
  for (int p = 0; threads_ > 1 && p < threads_; ++p)
    column_fields_.push_back(model_->bind_tau_grid(taus_.segment(column_begin_[p], column_begin_[p + 1] - column_begin_[p])));
  if (real_layout_) {
    real_kernels_ = grid_field_->evaluates_real();
    grid_values_.setZero(dim_, n_tau);
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

bool TauGrid::real_layout_for(const Model& model) {
  // A remainder turns coordinates by complex phases: its U is complex (a real model has none).
  return !model.is_complex() && !model.has_linear_remainder();
}

void TauGrid::set_diagonal(const Eigen::Ref<const Vector>& diagonal) {
  diagonal_ = diagonal;  // into the kept storage
  bind_diagonal();
}

void TauGrid::bind_diagonal() {
  grid_field_->set_diagonal(diagonal_);
  for (auto& field : column_fields_) field->set_diagonal(diagonal_);
}

void TauGrid::nonlinear(const Vector& y, const Vector* mean_shift, Vector& out, Real phase) {
  throw_if_stop_requested("evaluating the nonlinearity on the tau grid");  // seconds on a large grid
  ++*evaluations_;
  if (device::current()) return device_nonlinear(y, mean_shift, out);
  if (needs_diagonal_) {
    evaluate_into(Eigen::Map<const Matrix>(y.data(), dim_, columns_), phase, diagonal_);
    if (mean_shift) diagonal_ += *mean_shift;
    bind_diagonal();
  }
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

void TauGrid::device_nonlinear(const Vector& y, const Vector* mean_shift, Vector& out) {
  if (real_layout_ || needs_diagonal_ || mean_shift)
    throw Error("--device cuda: the device's tau grid takes a complex model whose field does not read U on the "
                "diagonal (reformulation.real_layout: false for a real one), and no shifted evaluations");
  if (!device_) device_ = make_device_tau_grid(*model_, taus_, dim_, n_tau_);
  const Complex* in = device::read(y);
  device_->nonlinear(in, device::write(out, size()));
}

void TauGrid::nonlinear_threaded(const Vector& y, const Vector* mean_shift, Vector& out) {
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
void TauGrid::on_grid_threads(In&& transform_in, Field&& evaluate, Out&& transform_out) {
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

void TauGrid::nonlinear_of_constant(const Vector& v, Vector& out, Real phase, const ColumnFinish* finish) {
  if (!row_blocks_) {
    out.setZero(size());
    nonlinear(out, &v, out, phase);
    if (finish) {
      if (finish->at_phase) finish->at_phase->resize(dim_);
      finish_rows(*finish, evaluation_factors(columns_, finish->phase), out.data(), 0, dim_);
    }
    return;
  }
  ++*evaluations_;
  if (needs_diagonal_) set_diagonal(v);  // a constant grid's value at any tau
  nonlinear_by_rows(nullptr, &v, out, finish);
}

void TauGrid::finish_rows(const ColumnFinish& finish, const std::vector<Complex>& phase_factors, Complex* c, Index r0,
                          Index rn) const {
  for (int j = 0; j < columns_; ++j) {
    Eigen::Map<Vector> column(c + j * dim_ + r0, rn);
    const Complex factor = finish.factors[static_cast<std::size_t>(j)];
    if (factor == Complex(0))
      column.setZero();
    else
      column *= factor;
  }
  if (finish.at_phase) evaluate_rows(c, columns_, phase_factors, r0, rn, finish.at_phase->data() + r0);
}

void TauGrid::nonlinear_by_rows(const Vector* y, const Vector* mean_shift, Vector& out, const ColumnFinish* finish) {
  out.resize(size());
  std::vector<Complex> phase_factors;
  if (finish) {
    if (finish->at_phase) finish->at_phase->resize(dim_);
    phase_factors = evaluation_factors(columns_, finish->phase);
  }
  grid_field_->prepare_rows();
  const TauGridField& field = *grid_field_;
  const RealFftRows& blocks = *row_blocks_;
  const Real scale = 1.0 / n_tau_;  // the 1/n of the transform
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads_));
  // Each block is computed the same way on any number of threads: the same numbers.
#if defined(_OPENMP)
#pragma omp parallel num_threads(threads_) if (threads_ > 1)
#endif
  {
    RealMatrix buffer(blocks.block_rows(), n_tau_);
#if defined(_OPENMP)
#pragma omp for schedule(static)
#endif
    for (Index b = 0; b < blocks.blocks(); ++b) {
      auto& error = errors[static_cast<std::size_t>(thread_index())];
      if (error) continue;  // this thread failed: the others finish, the caller gets the error
      try {
        const Index r0 = blocks.block_begin(b), rn = blocks.rows_of(b);
        Eigen::Map<RealMatrix> values(buffer.data(), rn, n_tau_);
        if (y)
          blocks.backward(y->data(), b, values.data());
        else
          values.setZero();
        if (mean_shift) values.colwise() += mean_shift->segment(r0, rn).real();
        field.evaluate_rows_real(values, r0);
        blocks.forward_unnormalised(values.data(), b, out.data());
        for (int j = 0; j < columns_; ++j) out.segment(j * dim_ + r0, rn) *= scale;
        if (finish) finish_rows(*finish, phase_factors, out.data(), r0, rn);  // while the rows are in cache
      } catch (...) {
        error = std::current_exception();
      }
    }
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
}

void TauGrid::nonlinear_real(const Vector& y, const Vector* mean_shift, Vector& out) {
  if (row_blocks_) return nonlinear_by_rows(&y, mean_shift, out);
  out.resize(size());
  const bool in_place = field_values_.size() == 0;
  const Real* field = in_place ? grid_values_.data() : field_values_.data();
  const auto transform_in = [&](int part) {
    // The mean shift is a constant in tau: added to the grid values, as to the mean mode.
    real_fft_->backward(y.data(), grid_values_.data(), part);
    if (!mean_shift) return;
    const Index r0 = part < 0 ? 0 : real_fft_->part_begin(part);
    const Index rn = part < 0 ? dim_ : real_fft_->part_begin(part + 1) - r0;
    grid_values_.middleRows(r0, rn).colwise() += mean_shift->segment(r0, rn).real();
  };
  const Real scale = 1.0 / n_tau_;  // the 1/n of the transform
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

void TauGrid::evaluate_real_grid(TauGridField& field, Index c0, Index cn) {
  auto values = grid_values_.middleCols(c0, cn);
  if (real_kernels_) {
    if (field_values_.size() == 0) return field.evaluate_real(values, values);
    return field.evaluate_real(values, field_values_.middleCols(c0, cn));
  }
  complex_grid_.middleCols(c0, cn) = values.cast<Complex>();
  field.evaluate(complex_grid_.middleCols(c0, cn), complex_field_.middleCols(c0, cn));
  field_values_.middleCols(c0, cn) = complex_field_.middleCols(c0, cn).real();
}


Matrix TauGrid::to_grid(const Matrix& c) {
  if (real_layout_) {
    RealMatrix values(dim_, n_tau_);
    real_fft_->backward(c.data(), values.data());  // modes 0 .. N/2: the first columns of c
    return values.cast<Complex>();
  }
  Matrix grid(dim_, n_tau_);
  fft_->transform(c.data(), grid.data(), 1);
  return grid;
}

Matrix TauGrid::to_coefficients(Matrix grid) {
  if (real_layout_) {
    const RealMatrix values = grid.real();
    grid.resize(0, 0);
    Matrix c(dim_, columns_);
    real_fft_->forward_unnormalised(values.data(), c.data());
    c *= Real(1) / n_tau_;
    return all_modes(c);
  }
  fft_->transform(grid.data(), grid.data(), 0, 1.0 / n_tau_);
  return grid;
}

Matrix TauGrid::all_modes(ConstMatrixRef stored) const {
  if (!real_layout_) return stored;
  Matrix c(dim_, n_tau_);
  c.leftCols(columns_) = stored;
  for (int j = 1; 2 * j < n_tau_; ++j) c.col(n_tau_ - j) = stored.col(j).conjugate();
  return c;
}

Real TauGrid::coefficient_norm(const Vector& y, bool without_mean) const {
  const RealVector energies = column_energies(y);
  return std::sqrt(energies.tail(columns_ - (without_mean ? 1 : 0)).sum());
}

RealVector TauGrid::column_energies(const Vector& y) const {
  const Eigen::Map<const Matrix> c(y.data(), dim_, columns_);
  constexpr Index block = Index(1) << 14;  // rows per partial sum: fixed, so threads change nothing
  const Index blocks = (dim_ + block - 1) / block;
  RealMatrix partial(blocks, columns_);
#if defined(_OPENMP)
#pragma omp parallel for num_threads(threads_) schedule(static) if (threads_ > 1 && blocks > 1)
#endif
  for (Index b = 0; b < blocks; ++b) {
    const Index r0 = b * block, rn = std::min(block, dim_ - r0);
    for (int j = 0; j < columns_; ++j) partial(b, j) = c.col(j).segment(r0, rn).squaredNorm();
  }
  RealVector energies(columns_);
  for (int j = 0; j < columns_; ++j)
    energies(j) = (real_layout_ && j > 0 && 2 * j < n_tau_ ? 2.0 : 1.0) * partial.col(j).sum();
  if (collective_) collective_->sum(energies.data(), columns_);
  return energies;
}

Real TauGrid::norm_from_squares(Real squares) const {
  if (collective_) collective_->sum(&squares, 1);
  return std::sqrt(squares);
}

Matrix TauGrid::f_coefficients(Matrix w) {
  throw_if_stop_requested("evaluating the nonlinearity on the tau grid");  // seconds on a large grid
  ++*evaluations_;
  if (needs_diagonal_) set_diagonal(w.col(0));
  if (grid_field_->in_place()) {
    grid_field_->evaluate(w, w);
    return to_coefficients(std::move(w));
  }
  Matrix f(dim_, n_tau_);
  grid_field_->evaluate(w, f);
  w.resize(0, 0);
  return to_coefficients(std::move(f));
}

Matrix TauGrid::df_coefficients(Matrix w, Matrix z) {
  throw_if_stop_requested("evaluating the nonlinearity on the tau grid");  // seconds on a large grid
  ++*evaluations_;
  if (needs_diagonal_) set_diagonal(w.col(0));
  model_->linear_flow(taus_, w);
  model_->linear_flow(taus_, z);
  Matrix df(dim_, n_tau_);
  model_->nonlinear_field_derivative(w, z, df);
  w.resize(0, 0);
  z.resize(0, 0);
  model_->linear_flow(RealVector(-taus_), df);
  return to_coefficients(std::move(df));
}

Matrix TauGrid::apply_A(Matrix c) const {
  for (int j = 0; j < n_tau_; ++j) {
    if (antiderivative(j) == Complex(0))
      c.col(j).setZero();
    else
      c.col(j) /= Complex(0.0, wave_numbers_(j));
  }
  return c;
}

Complex TauGrid::antiderivative(int j) const {
  return j == 0 || 2 * j == n_tau_ ? Complex(0) : Real(1) / Complex(0, wave_numbers_(j));
}


std::vector<Complex> TauGrid::evaluation_factors(Index columns, Real tau) const {
  const bool real = columns != n_tau_;  // the real layout: modes k and -k together, 2 Re(c_k e^{i k tau})
  std::vector<Complex> factors(static_cast<std::size_t>(columns));
  for (int j = 0; j < columns; ++j)
    factors[static_cast<std::size_t>(j)] = 2 * j == n_tau_ ? Complex(std::cos(0.5 * n_tau_ * tau))  // half at +-n/2
                                           : real          ? std::polar(Real(1), j * tau)
                                                           : std::polar(Real(1), wave_numbers_(j) * tau);
  return factors;
}

void TauGrid::evaluate_rows(const Complex* c, Index columns, const std::vector<Complex>& factors, Index r0, Index rn,
                            Complex* value) const {
  if (columns != n_tau_) {  // the real parts only, mode by mode (the imaginary parts stay 0)
    Real* v = reinterpret_cast<Real*>(value);
    for (Index r = 0; r < rn; ++r) v[2 * r + 1] = 0.0;
    for (int j = 0; j < columns; ++j) {
      const Real* x = reinterpret_cast<const Real*>(c + j * dim_ + r0);
      const Complex f = factors[static_cast<std::size_t>(j)];
      if (j == 0) {
        for (Index r = 0; r < rn; ++r) v[2 * r] = x[2 * r];
      } else if (2 * j == n_tau_) {  // stored with the half of both signs: its real part
        for (Index r = 0; r < rn; ++r) v[2 * r] += f.real() * x[2 * r];
      } else {  // 2 Re(c_k e^{i k tau})
        const Real re = 2.0 * f.real(), im = 2.0 * f.imag();
        for (Index r = 0; r < rn; ++r) v[2 * r] += re * x[2 * r] - im * x[2 * r + 1];
      }
    }
    return;
  }
  Eigen::Map<Vector> v(value, rn);
  v.setZero();
  for (int j = 0; j < columns; ++j) {
    const Complex f = factors[static_cast<std::size_t>(j)];
    const Eigen::Map<const Vector> col(c + j * dim_ + r0, rn);
    if (2 * j == n_tau_)
      v += col * f.real();
    else
      v += col * f;
  }
}

Vector TauGrid::evaluate(ConstMatrixRef c, Real tau) const {
  Vector value;
  evaluate_into(c, tau, value);
  return value;
}

void TauGrid::evaluate_into(ConstMatrixRef c, Real tau, Vector& value) const {
  value.resize(dim_);
  const std::vector<Complex> factors = evaluation_factors(c.cols(), tau);
  // By blocks of rows, each summed over the modes in order (the same numbers on any number of
  // threads): a particle state read back every step is 10^7 rows.
  constexpr Index block = 1 << 14;
  const Index blocks = (dim_ + block - 1) / block;
#if defined(_OPENMP)
#pragma omp parallel for num_threads(threads_) schedule(static) if (threads_ > 1 && blocks > 1)
#endif
  for (Index b = 0; b < blocks; ++b) {
    const Index r0 = b * block;
    evaluate_rows(c.data(), c.cols(), factors, r0, std::min(block, dim_ - r0), value.data() + r0);
  }
}

}  // namespace tsi
