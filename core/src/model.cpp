#include "tsi/model.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "central_difference.hpp"
#include "tsi/collective.hpp"
#include "tsi/error.hpp"

namespace tsi {

Model::Model(Real eps) : eps_(eps) {
  if (!(eps > 0.0 && eps <= 1.0)) throw ConfigError("model.eps", "expected a number in (0, 1]");
}

void Model::nonlinear_field(ConstMatrixRef, MatrixRef) const {
  if (time_dependent_field())
    throw Error("this model's f depends on t (time_dependent_field()): it is evaluated through "
                "with_time_as_variable, which carries t, not through Model::nonlinear_field");
  throw Error("this model gives no field: override Model::nonlinear_field (f(u)) or declare "
              "time_dependent_field() (f(t, u))");
}

void Model::nonlinear_field_derivative(ConstMatrixRef states, ConstMatrixRef directions,
                                       MatrixRef out) const {
  central_difference([this](ConstMatrixRef u, MatrixRef f) { nonlinear_field(u, f); }, states, directions, out);
}

void TimeDependentField::nonlinear_field_derivative_at(const RealVector& t, ConstMatrixRef states,
                                                       ConstMatrixRef directions, MatrixRef out) const {
  central_difference([this, &t](ConstMatrixRef u, MatrixRef f) { nonlinear_field_at(t, u, f); }, states, directions,
                     out);
}

void Model::filtered_field(const RealVector& taus, MatrixRef states, MatrixRef out) const {
  if (const FusedTauGrid* fused = fused_tau_grid()) return fused->filtered_field(taus, states, out);
  linear_flow(taus, states);
  nonlinear_field(states, out);
  const RealVector minus_taus = -taus;
  linear_flow(minus_taus, out);
}

void TauGridField::evaluate_real(RealMatrixRef, RealMatrixRef) {
  throw Error("this tau-grid binding does not evaluate real grids (evaluates_real() is false)");
}

void TauGridField::evaluate_rows_real(RealMatrixRef, Index) const {
  throw Error("this tau-grid binding does not evaluate blocks of rows (independent_row_group() is 0)");
}

void FusedTauGrid::filtered_field(const RealVector& taus, MatrixRef states, MatrixRef out) const {
  bind_tau_grid(taus)->evaluate(states, out);
}

namespace {

// A binding that calls source.filtered_field with the stored phases: a Model (flow, field and
// flow back, for a model without the fused capability) or a FusedTauGrid.
template <class Source>
class StoredPhasesField final : public TauGridField {
 public:
  StoredPhasesField(const Source& source, RealVector taus) : source_(source), taus_(std::move(taus)) {}
  void evaluate(MatrixRef states, MatrixRef out) override { source_.filtered_field(taus_, states, out); }

 private:
  const Source& source_;
  RealVector taus_;
};

[[noreturn]] void no_hamiltonian(const char* what) {
  throw Error(std::string("this model declares no Hamiltonian structure (Model::hamiltonian() is null): it has no ") +
              what);
}

}  // namespace

std::unique_ptr<TauGridField> bind_filtered_field(const FusedTauGrid& fused, const RealVector& taus) {
  return std::make_unique<StoredPhasesField<FusedTauGrid>>(fused, taus);
}

std::unique_ptr<TauGridField> Model::bind_tau_grid(const RealVector& taus) const {
  if (const FusedTauGrid* fused = fused_tau_grid()) return fused->bind_tau_grid(taus);
  return std::make_unique<StoredPhasesField<Model>>(*this, taus);
}

bool Model::independent_tau_grid_bindings() const {
  const FusedTauGrid* fused = fused_tau_grid();
  return fused && fused->independent_tau_grid_bindings();
}

const RealVector& Model::linear_remainder() const {
  static const RealVector none;
  return none;
}

void Model::remainder_flow(Real t, Vector& u) const {
  const RealVector& omega = linear_remainder();
  if (omega.size() == 0) return;
  for (Index j = 0; j < u.size(); ++j) u(j) *= std::polar(Real(1), omega(j) * t);
}

Real Model::remainder_energy(const Vector& u) const {
  const RealVector& omega = linear_remainder();
  if (omega.size() == 0) return 0.0;
  const HamiltonianStructure* h = hamiltonian();
  if (!h) no_hamiltonian("energy of the remainder");
  // R' u = -J (i omega . u), since J^{-1} = -J for a symplectic J.
  const Vector i_omega_u = (Complex(0.0, 1.0) * omega.cast<Complex>()).cwiseProduct(u);
  Vector r(u.size());
  h->apply_J(i_omega_u, r);
  return -0.5 * summed(inner(r, u));
}

void Model::apply_A(const Vector& u, Vector& out) const {
  const HamiltonianStructure* h = hamiltonian();
  if (!h) no_hamiltonian("J M: a model of the general class overrides apply_A");
  Vector mu(u.size());
  h->apply_M(u, mu);
  h->apply_J(mu, out);
}

void Model::nonlinear_flow(Real t, Vector& u) const {
  const ExactNonlinearFlow* flow = exact_nonlinear_flow();
  if (!flow) throw Error("this model has no exact nonlinear flow (Model::exact_nonlinear_flow() is null)");
  flow->nonlinear_flow(t, u);
}

Real Model::oscillatory_energy(const Vector& u) const {
  const HamiltonianStructure* h = hamiltonian();
  if (!h) no_hamiltonian("oscillatory energy");
  Vector mu(u.size());
  h->apply_M(u, mu);
  return summed(inner(mu, u)) / (2.0 * eps_);
}

Real Model::mass(const Vector& u) const { return summed(inner(u, u)); }

Real Model::energy(const Vector& u) const {
  const HamiltonianStructure* h = hamiltonian();
  if (!h) no_hamiltonian("energy");
  return oscillatory_energy(u) + remainder_energy(u) + h->H1(u);
}

std::vector<Index> Model::physical_shape() const {
  const PhysicalVariables* p = physical_variables();
  return p ? p->physical_shape() : std::vector<Index>{dim()};
}

Index Model::physical_dim() const {
  const PhysicalVariables* p = physical_variables();
  return p ? p->physical_dim() : dim();
}

Vector Model::from_physical(const Vector& x) const {
  const PhysicalVariables* p = physical_variables();
  return p ? p->from_physical(x) : x;
}

Vector Model::to_physical(const Vector& u) const {
  const PhysicalVariables* p = physical_variables();
  return p ? p->to_physical(u) : u;
}

Real Model::error_norm(const Vector& x) const {
  const PhysicalVariables* p = physical_variables();
  return p ? p->error_norm(x) : std::sqrt(summed(x.squaredNorm()));
}

Real Model::rounding_floor(const Vector& u) const {
  Vector rounded = u;
  for (Index i = 0; i < u.size(); ++i) {
    const Real sign = i % 2 == 0 ? 1.0 : -1.0, ulp = std::numeric_limits<Real>::epsilon();
    rounded(i) = Complex(u(i).real() * (1.0 + sign * ulp), u(i).imag() * (1.0 - sign * ulp));
  }
  const Vector x = to_physical(u);
  return error_norm(to_physical(rounded) - x) / std::max<Real>(error_norm(x), 1e-300);
}

Real Model::summed(Real local) const {
  const Collective* split = processes();
  return split ? split->sum(local) : local;
}

Vector Model::linear_flow(Real tau, const Vector& u) const { return linear_flow(tau, Vector(u)); }

Vector Model::linear_flow(Real tau, Vector&& u) const {
  RealVector taus(1);
  taus(0) = tau;
  Eigen::Map<Matrix> state(u.data(), u.size(), 1);
  linear_flow(taus, state);
  return std::move(u);
}

Vector Model::nonlinear_field(const Vector& u) const {
  Matrix out(u.size(), 1);
  nonlinear_field(Matrix(u), out);
  return out.col(0);
}

}  // namespace tsi
