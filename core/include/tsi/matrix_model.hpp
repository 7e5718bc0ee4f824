#pragma once
#include <memory>
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/field.hpp"
#include "tsi/model.hpp"
#include "tsi/params.hpp"

namespace tsi {

class Registry;
struct ModelEntry;

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
/// keeps the spectral projectors P_k of A, so that e^{A tau} = sum_k P_k e^{i k tau} exactly for
/// every tau. They come from N > 2 max|k| equispaced samples E_j = e^{A 2 pi j/N} (the
/// coefficients of a trigonometric polynomial of degree max|k|, without aliasing), each one
/// product E_{j + 2^b} = E_j e^{A 2 pi 2^b/N}; e^{A 2 pi/N} by scaling and squaring a Taylor
/// polynomial. The set-up is matrix products only and polls tsi::throw_if_stop_requested
/// between any two (an interrupt is honoured within a second up to max_matrix_model_dim: a
/// product of two 1024 x 1024 matrices takes 0.1 to 0.8 s). The frequencies k are A's
/// eigenvalues up to 256 x 256; above, the samples are refined (N = 4, 8, ...) until they
/// resolve A, and the k are read off the DFT of their traces.
class TSI_API PeriodicMatrixFlow {
 public:
  /// Refuses (ConfigError naming `path`, with e^{2 pi A} - I and A's eigenvalues where known):
  /// a 1-norm above 1e10; an eigenvalue farther than 1e-9 max(1, |A|_1) from i k or with
  /// |k| > 1e6; a failed eigenvalue decomposition; more than 4e10 / n^3 samples; and, the tight
  /// test, projectors that do not give back A = sum_k i k P_k and I = sum_k P_k to rounding,
  /// 64 units times N max(1, |A|_1) max(1, max|e^{A tau}|)^2 (a Jordan block, eigenvalues
  /// i (k + delta) with delta above rounding: 1e-14 k for a normal A); above 256 x 256 also
  /// non-integer multiplicities in the DFT of tr e^{A tau_j}; and an A whose rounding allowance
  /// exceeds 1e-6 |A|_1 (eigenvectors so far from orthogonal that no test can tell).
  PeriodicMatrixFlow(Matrix A, const std::string& path);
  Index dim() const { return A_.rows(); }
  const Matrix& A() const { return A_; }
  /// e^{A tau}; real (imaginary parts exactly 0) when A is.
  Matrix at(Real tau) const;
  /// states.col(j) <- e^{A taus(j)} states.col(j) for every column: one product of each P_k
  /// with all the columns (at n = 1024, 64 columns: 5 to 10 times faster than at() per column).
  void apply(const RealVector& taus, MatrixRef states) const;
  /// max |k| over the eigenvalues i k of A.
  long max_frequency() const { return max_frequency_; }
  /// The largest entry of e^{2 pi A} - I (as the set-up computed it).
  Real period_deviation() const { return deviation_; }

 private:
  Matrix A_;
  bool real_ = true;
  long max_frequency_ = 0;
  Real deviation_ = 0;
  std::vector<long> frequencies_;  // a real A's k >= 0 only (P_{-k} = conj(P_k))
  std::vector<Matrix> projectors_;
};

/// Refuses (ConfigError on reformulation.n_tau) a two-scale n_tau that does not resolve a matrix
/// model's f_tau: with A's frequencies up to K, e^{-A tau} f(e^{A tau} U) has tau harmonics up
/// to 2K for any non-constant field f, so n_tau must exceed 4K (measured on HOODESolver.jl's
/// linear test with A = K x its quickstart A: 1.1e-2 at n_tau = 4K, 1.6e-9 at 4K + 2, K = 4).
/// Does nothing for another model (`entry` not the core's "matrix"): a model's
/// max_linear_frequency() alone does not say what n_tau it needs (NLS runs at n_x = 8192 with
/// n_tau = 64 on purpose). assemble() calls it before the reformulation is built.
TSI_API void check_matrix_model_n_tau(const ModelEntry& entry, const Model& model, long n_tau);

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
