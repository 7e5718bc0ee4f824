#pragma once
#include <memory>
#include <string>

#include "tsi/export.hpp"
#include "tsi/field.hpp"
#include "tsi/model.hpp"
#include "tsi/params.hpp"

namespace tsi {

class Registry;

/// The largest A the matrix model takes (rows and columns).
inline constexpr Index max_matrix_model_dim = 1024;

/// A square matrix of numbers from JSON (model.A): an array of rows, each an array of numbers,
/// complex entries as [re, im] pairs. Refuses anything else with a ConfigError naming
/// `path` or the entry (path[i][j]): not an array, empty, ragged or not square, more than
/// max_matrix_model_dim rows, an entry that is no number or not finite (every number is read
/// in its own JSON type first). `complex_entries` is set when an entry has a nonzero
/// imaginary part.
TSI_API Matrix matrix_from_json(const Json& value, const std::string& path, bool& complex_entries);

/// e^{A tau} for a matrix A whose flow is 2 pi-periodic (A = V diag(i k) V^{-1}, k integer):
/// checks e^{2 pi A} = I, then keeps the spectral projectors P_k of A, so that
/// e^{A tau} = sum_k P_k e^{i k tau} exactly for every tau (computed once from e^{A tau} at
/// N > 2 max|k| equispaced phases: the coefficients of a trigonometric polynomial of degree
/// max|k|, without aliasing).
class TSI_API PeriodicMatrixFlow {
 public:
  /// Refuses (ConfigError naming `path`) an A whose e^{2 pi A} differs from I by more than
  /// 1e-9 max(1, 2 pi |A|) in the largest entry, with the deviation measured and A's eigenvalues.
  PeriodicMatrixFlow(Matrix A, const std::string& path);
  Index dim() const { return A_.rows(); }
  const Matrix& A() const { return A_; }
  /// e^{A tau}; real (imaginary parts exactly 0) when A is.
  Matrix at(Real tau) const;
  /// max |k| over the eigenvalues i k of A.
  long max_frequency() const { return max_frequency_; }
  /// The largest entry of e^{2 pi A} - I (what the period check measured).
  Real period_deviation() const { return deviation_; }

 private:
  Matrix A_;
  bool real_ = true;
  long max_frequency_ = 0;
  Real deviation_ = 0;
  std::vector<long> frequencies_;
  std::vector<Matrix> projectors_;
};

/// The general-class model u' = (1/eps) A u + f(t, u) with A a matrix and f a field: e^{A tau}
/// from PeriodicMatrixFlow, f from `field`. With `time_dependent`, the model declares its field
/// as a TimeDependentField and is returned through with_time_as_variable (time_as_variable.hpp),
/// which carries t as one more variable (t' = 1, A padded with a zero row and column, as
/// HOODESolver.jl does): dim() is A's size + 1, physical variables (u0, u_final, errors) are u
/// without t, and runs start at t = 0. `u0` (physical, may be empty) is the default initial value.
TSI_API std::unique_ptr<Model> make_matrix_model(Real eps, PeriodicMatrixFlow flow,
                                                 std::shared_ptr<const Field> field, bool time_dependent,
                                                 bool is_complex, Vector u0, std::string field_name);

/// Registers the "matrix" model and its built-in field "quickstart" (register_core calls it).
TSI_API void register_matrix_model(Registry& registry);

}  // namespace tsi
