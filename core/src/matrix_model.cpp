// The core's "matrix" model: u' = (1/eps) A u + f(t, u) with A a matrix from the run's JSON
// (SPEC.md section 7) and f a registered field (a plugin's, Python's, or the built-in
// "quickstart"). e^{A tau} comes from A's spectral projectors, computed once per model.
#include "tsi/matrix_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <unsupported/Eigen/MatrixFunctions>

#include "tsi/affine_exact.hpp"
#include "tsi/error.hpp"
#include "tsi/phase.hpp"
#include "tsi/registry.hpp"
#include "tsi/time_as_variable.hpp"

namespace tsi {

void Field::derivative(const RealVector&, ConstMatrixRef, ConstMatrixRef, MatrixRef) const {
  throw Error("this field gives no derivative (has_derivative() is false)");
}

namespace {

// A JSON value as a short text for a message (a large matrix is cut).
std::string shown(const Json& v) {
  std::string s = v.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// One entry of model.A: a number, or [re, im]; every number read in its own JSON type.
bool json_number(const Json& v, double& x) {
  if (v.is_number_integer()) {
    x = v.is_number_unsigned() ? static_cast<double>(v.get<std::uint64_t>()) : static_cast<double>(v.get<std::int64_t>());
    return true;
  }
  if (v.is_number_float()) {
    x = v.get<double>();
    return std::isfinite(x);
  }
  return false;
}

std::string eigenvalue_list(const Matrix& A) {
  const Eigen::ComplexEigenSolver<Matrix> solver(A, false);
  std::vector<Complex> values(solver.eigenvalues().data(), solver.eigenvalues().data() + solver.eigenvalues().size());
  std::sort(values.begin(), values.end(),
            [](Complex a, Complex b) { return a.imag() != b.imag() ? a.imag() < b.imag() : a.real() < b.real(); });
  std::string s;
  const std::size_t shown_count = std::min<std::size_t>(values.size(), 8);
  for (std::size_t i = 0; i < shown_count; ++i)
    s += fmt::format("{}{:.6g}{:+.6g}i", i ? ", " : "", values[i].real(), values[i].imag());
  if (values.size() > shown_count) s += fmt::format(", ... ({} in all)", values.size());
  return s;
}

}  // namespace

Matrix matrix_from_json(const Json& value, const std::string& path, bool& complex_entries) {
  const std::string expected = "expected a square matrix: an array of rows, each an array of numbers ([re, im] for a complex one)";
  if (!value.is_array()) throw ConfigError(path, "got " + shown(value) + ", " + expected);
  if (value.empty()) throw ConfigError(path, "got [], " + expected);
  const std::size_t n = value.size();
  if (n > static_cast<std::size_t>(max_matrix_model_dim))
    throw ConfigError(path, fmt::format("has {} rows, expected at most {}", n, max_matrix_model_dim));
  for (std::size_t i = 0; i < n; ++i) {
    const Json& row = value[i];
    if (!row.is_array())
      throw ConfigError(fmt::format("{}[{}]", path, i), "got " + shown(row) + ", expected a row: an array of numbers");
    if (row.size() != n)
      throw ConfigError(fmt::format("{}[{}]", path, i),
                        fmt::format("has {} entries, expected {}: A must be square ({} rows)", row.size(), n, n));
  }
  complex_entries = false;
  const auto dim = static_cast<Index>(n);
  Matrix A(dim, dim);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      const Json& v = value[i][j];
      double re = 0.0, im = 0.0;
      const bool ok = json_number(v, re) ||
                      (v.is_array() && v.size() == 2 && json_number(v[0], re) && json_number(v[1], im));
      if (!ok)
        throw ConfigError(fmt::format("{}[{}][{}]", path, i, j),
                          "got " + shown(v) + ", expected a finite number (or [re, im] for a complex entry)");
      if (im != 0.0) complex_entries = true;
      A(static_cast<Index>(i), static_cast<Index>(j)) = Complex(re, im);
    }
  }
  return A;
}

PeriodicMatrixFlow::PeriodicMatrixFlow(Matrix A, const std::string& path) : A_(std::move(A)) {
  const Index n = A_.rows();
  if (n == 0 || A_.cols() != n) throw ConfigError(path, fmt::format("is {} x {}, expected a nonempty square matrix", n, A_.cols()));
  if (!A_.allFinite()) throw ConfigError(path, "has an entry that is not finite");
  real_ = A_.imag().isZero(0.0);
  const Real norm = A_.cwiseAbs().rowwise().sum().maxCoeff();
  const Matrix period = (Complex(two_pi) * A_).exp();
  deviation_ = (period - Matrix::Identity(n, n)).cwiseAbs().maxCoeff();
  const Real tolerance = Real(1e-9) * std::max<Real>(1, two_pi * norm);
  if (!(deviation_ <= tolerance))
    throw ConfigError(path, fmt::format("e^(2 pi A) differs from the identity by {:.3g} (its largest entry of "
                                        "e^(2 pi A) - I), expected at most {:.3g} (1e-9 max(1, 2 pi |A|)): "
                                        "e^(A tau) must be 2 pi-periodic, A's eigenvalues i k with integer k (the "
                                        "fast frequency is 1/eps: scale A so that it is); A's eigenvalues are {}",
                                        deviation_, tolerance, eigenvalue_list(A_)));
  // The frequencies k of the eigenvalues i k, then P_k from e^{A tau_j} at N > 2 max|k| phases.
  const Eigen::ComplexEigenSolver<Matrix> solver(A_, false);
  std::set<long> ks;
  for (Index i = 0; i < n; ++i) {
    const Real k = solver.eigenvalues()(i).imag();
    if (!(std::fabs(k) <= 1e6))
      throw ConfigError(path, fmt::format("has the eigenvalue {:.6g}i: frequencies up to 1e6 are taken (the fast "
                                          "frequency is 1/eps: scale A so that it is)",
                                          k));
    ks.insert(std::lround(k));
  }
  for (const long k : ks) max_frequency_ = std::max(max_frequency_, std::abs(k));
  long samples = 4;
  while (samples < 2 * max_frequency_ + 2) samples *= 2;
  const double cost = static_cast<double>(samples) * std::pow(static_cast<double>(n), 3.0);
  if (cost > 4e10)
    throw ConfigError(path, fmt::format("is {} x {} with frequencies up to {}: its e^(A tau) needs {} matrix "
                                        "exponentials of that size ({:.2g} operations), more than this model "
                                        "computes (4e10)",
                                        n, n, max_frequency_, samples, cost));
  frequencies_.assign(ks.begin(), ks.end());
  projectors_.assign(frequencies_.size(), Matrix::Zero(n, n));
  for (long j = 0; j < samples; ++j) {
    const Real tau = two_pi * static_cast<Real>(j) / static_cast<Real>(samples);
    const Matrix E = (Complex(tau) * A_).exp();
    for (std::size_t m = 0; m < frequencies_.size(); ++m)
      projectors_[m] += std::polar(1 / static_cast<Real>(samples), -static_cast<Real>(frequencies_[m]) * tau) * E;
  }
}

Matrix PeriodicMatrixFlow::at(Real tau) const {
  Matrix E = Matrix::Zero(dim(), dim());
  for (std::size_t m = 0; m < frequencies_.size(); ++m)
    E += std::polar(Real(1), static_cast<Real>(frequencies_[m]) * tau) * projectors_[m];
  if (real_) E.imag().setZero();
  return E;
}

namespace {

// A time-dependent field is the model's TimeDependentField: make_matrix_model hands it to
// with_time_as_variable, which carries t, and the model itself is of A's size alone.
class MatrixModel final : public Model, public FusedTauGrid, public TimeDependentField {
 public:
  MatrixModel(Real eps, PeriodicMatrixFlow flow, std::shared_ptr<const Field> field, bool time_dependent,
              bool is_complex, Vector u0, std::string field_name)
      : Model(eps),
        flow_(std::move(flow)),
        field_(std::move(field)),
        d_(flow_.dim()),
        time_(time_dependent),
        complex_(is_complex),
        u0_(std::move(u0)),
        field_name_(std::move(field_name)) {
    // An affine f (B u + t a + b) has an exact solution; with t not carried, only where a = 0.
    const AffineTerms* terms = field_->affine_terms();
    if (terms && d_ <= max_affine_exact_dim && terms->B.rows() == d_ && (time_ || terms->a.isZero(0.0)))
      exact_ = AffineExact(flow_.A(), this->eps(), *terms);
  }

  Index dim() const override { return d_; }
  bool is_complex() const override { return complex_; }
  // No Hamiltonian structure: f is any field, A any matrix with a 2 pi-periodic e^{A tau}. The
  // fused tau grid evaluates f at t = 0: an autonomous field's only.
  const TimeDependentField* time_dependent_field() const override { return time_ ? this : nullptr; }
  const FusedTauGrid* fused_tau_grid() const override { return time_ ? nullptr : this; }
  double max_linear_frequency() const override { return std::max(1.0, static_cast<double>(flow_.max_frequency())); }

  void linear_flow(const RealVector& taus, MatrixRef states) const override {
    for (Index j = 0; j < states.cols(); ++j) {
      const Vector turned = flow_.at(taus(j)) * states.col(j);
      states.col(j) = turned;
    }
  }

  void apply_A(const Vector& u, Vector& out) const override { out = flow_.A() * u; }

  void nonlinear_field(ConstMatrixRef states, MatrixRef out) const override {
    if (time_) return Model::nonlinear_field(states, out);  // refused: f(t, u) is nonlinear_field_at
    field_->evaluate(RealVector::Zero(states.cols()), states, out);
  }
  void nonlinear_field_at(const RealVector& t, ConstMatrixRef states, MatrixRef out) const override {
    field_->evaluate(t, states, out);
  }

  void nonlinear_field_derivative(ConstMatrixRef states, ConstMatrixRef directions, MatrixRef out) const override {
    if (time_ || !field_->has_derivative()) return Model::nonlinear_field_derivative(states, directions, out);
    field_->derivative(RealVector::Zero(states.cols()), states, directions, out);
  }
  void nonlinear_field_derivative_at(const RealVector& t, ConstMatrixRef states, ConstMatrixRef directions,
                                     MatrixRef out) const override {
    if (!field_->has_derivative()) return TimeDependentField::nonlinear_field_derivative_at(t, states, directions, out);
    field_->derivative(t, states, directions, out);
  }

  // f_tau on a fixed tau grid: e^{A tau_j} and e^{-A tau_j} tabulated once per binding.
  class GridField final : public TauGridField {
   public:
    GridField(const MatrixModel& model, const RealVector& taus)
        : model_(model), taus_(taus), t_(RealVector::Zero(taus.size())), turned_(model.d_, taus.size()),
          field_(model.d_, taus.size()) {
      const double bytes = 2.0 * static_cast<double>(taus.size()) * static_cast<double>(model.d_ * model.d_) * 16.0;
      tabulated_ = bytes <= 512e6;  // else each evaluation forms e^{+-A tau_j} again
      if (!tabulated_) return;
      forward_.reserve(static_cast<std::size_t>(taus.size()));
      backward_.reserve(static_cast<std::size_t>(taus.size()));
      for (Index j = 0; j < taus.size(); ++j) {
        forward_.push_back(model.flow_.at(taus(j)));
        backward_.push_back(model.flow_.at(-taus(j)));
      }
    }
    void evaluate(MatrixRef states, MatrixRef out) override {
      for (Index j = 0; j < states.cols(); ++j) {
        const auto k = static_cast<std::size_t>(j);
        if (tabulated_)
          turned_.col(j).noalias() = forward_[k] * states.col(j);
        else
          turned_.col(j) = model_.flow_.at(taus_(j)) * states.col(j);
      }
      model_.field_->evaluate(t_, turned_, field_);
      for (Index j = 0; j < states.cols(); ++j) {
        const auto k = static_cast<std::size_t>(j);
        if (tabulated_)
          out.col(j).noalias() = backward_[k] * field_.col(j);
        else
          out.col(j) = model_.flow_.at(-taus_(j)) * field_.col(j);
      }
    }

   private:
    const MatrixModel& model_;
    RealVector taus_, t_;  // t_: 0, an autonomous field's
    Matrix turned_, field_;
    bool tabulated_ = false;
    std::vector<Matrix> forward_, backward_;
  };

  std::unique_ptr<TauGridField> bind_tau_grid(const RealVector& taus) const override {
    return std::make_unique<GridField>(*this, taus);
  }

  const ExactSolution* exact_solution() const override { return exact_ ? &*exact_ : nullptr; }

  Vector initial_value() const override {
    if (u0_.size() != d_)
      throw ConfigError("model.u0", fmt::format("the field \"{}\" gives no default initial value for this A: give "
                                                "model.u0 ({} {})",
                                                field_name_, d_, complex_ ? "numbers or [re, im] pairs" : "numbers"));
    return u0_;
  }

 private:
  class AffineExact final : public ExactSolution {
   public:
    AffineExact(Matrix A, Real eps, AffineTerms terms) : A_(std::move(A)), eps_(eps), terms_(std::move(terms)) {}
    Value at(const Vector& x0, Real t) const override { return affine_exact_solution(A_, eps_, terms_, x0, t); }

   private:
    Matrix A_;
    Real eps_;
    AffineTerms terms_;
  };

  PeriodicMatrixFlow flow_;
  std::optional<AffineExact> exact_;
  std::shared_ptr<const Field> field_;
  Index d_;
  bool time_, complex_;
  Vector u0_;
  std::string field_name_;
};

// HOODESolver.jl's quickstart f(u) = (0, u4, 2 u1 u2, -u2 - u1^2 + u2^2): the default field.
class QuickstartField final : public Field {
 public:
  void evaluate(const RealVector&, ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out(0, j) = 0.0;
      out(1, j) = u(3, j);
      out(2, j) = Real(2) * u(0, j) * u(1, j);
      out(3, j) = -u(1, j) - u(0, j) * u(0, j) + u(1, j) * u(1, j);
    }
  }
  bool has_derivative() const override { return true; }
  void derivative(const RealVector&, ConstMatrixRef u, ConstMatrixRef z, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      out(0, j) = 0.0;
      out(1, j) = z(3, j);
      out(2, j) = Real(2) * (z(0, j) * u(1, j) + u(0, j) * z(1, j));
      out(3, j) = -z(1, j) - Real(2) * u(0, j) * z(0, j) + Real(2) * u(1, j) * z(1, j);
    }
  }
};

// HOODESolver.jl's linear test f(t, u) = B u + t a + b (its values: the parity issue; exact
// solution: SPEC.md section 7).
class LinearTestField final : public Field {
 public:
  LinearTestField() {
    // The peer's decimal numbers as doubles, whatever Real is: the same problem in every precision.
    terms_.B = (Eigen::Matrix4d() << 0.12, -0.78, 0.91, 0.34, -0.45, 0.56, 0.03, 0.54, -0.67, 0.09, 0.18, 0.89, -0.91,
                -0.56, 0.11, -0.56)
                   .finished()
                   .cast<Complex>();
    terms_.a = Eigen::Vector4d(0.12, -0.98, 0.45, 0.26).cast<Complex>();
    terms_.b = Eigen::Vector4d(-0.04, 0.48, 0.23, -0.87).cast<Complex>();
  }
  void evaluate(const RealVector& t, ConstMatrixRef u, MatrixRef out) const override {
    out.noalias() = terms_.B * u;
    for (Index j = 0; j < u.cols(); ++j) out.col(j) += t(j) * terms_.a + terms_.b;
  }
  bool has_derivative() const override { return true; }
  void derivative(const RealVector&, ConstMatrixRef, ConstMatrixRef z, MatrixRef out) const override {
    out.noalias() = terms_.B * z;
  }
  const AffineTerms* affine_terms() const override { return &terms_; }

 private:
  AffineTerms terms_;
};

Json quickstart_A() {
  return Json::array({Json::array({0, 0, 1, 0}), Json::array({0, 0, 0, 0}), Json::array({-1, 0, 0, 0}),
                      Json::array({0, 0, 0, 0})});
}

}  // namespace

std::unique_ptr<Model> make_matrix_model(Real eps, PeriodicMatrixFlow flow, std::shared_ptr<const Field> field,
                                         bool time_dependent, bool is_complex, Vector u0, std::string field_name) {
  if (!field) throw Error("make_matrix_model: no field");
  return with_time_as_variable(std::make_unique<MatrixModel>(eps, std::move(flow), std::move(field), time_dependent,
                                                             is_complex, std::move(u0), std::move(field_name)));
}

void register_matrix_model(Registry& registry) {
  FieldEntry quickstart;
  quickstart.info.name = "quickstart";
  quickstart.info.summary = "HOODESolver.jl's quickstart f(u) = (0, u4, 2 u1 u2, -u2 - u1^2 + u2^2), 4 entries, "
                            "default u0 (0.55, 0.12, 0.03, 0.89)";
  quickstart.dim = 4;
  quickstart.initial_value = Eigen::Vector4d(0.55, 0.12, 0.03, 0.89).cast<Complex>();
  quickstart.create = [](Index) { return std::make_shared<QuickstartField>(); };
  registry.add_field(std::move(quickstart));

  FieldEntry linear;
  linear.info.name = "linear";
  linear.info.summary = "HOODESolver.jl's linear test f(t, u) = B u + t a + b, 4 entries, default u0 "
                        "(-0.34, 0.78, 0.67, -5.6); exact solution (reference.scheme \"exact\")";
  linear.dim = 4;
  linear.time_dependent = true;
  linear.initial_value = Eigen::Vector4d(-0.34, 0.78, 0.67, -5.6).cast<Complex>();
  linear.create = [](Index) { return std::make_shared<LinearTestField>(); };
  registry.add_field(std::move(linear));

  ModelEntry entry;
  entry.info.name = "matrix";
  entry.info.summary = "u' = (1/eps) A u + f(t, u) with A a 2 pi-periodic matrix given in the run's JSON and f a "
                       "registered field (model.f: a plugin's, Python's tsi.register_field, \"quickstart\" or \"linear\")";
  ParamSpec a = array_param("A", "the matrix A (rows of numbers, [re, im] for complex ones); e^(2 pi A) must be I. "
                                 "Default: HOODESolver.jl's quickstart A, turning (u1, u3)");
  a.default_value = quickstart_A();
  entry.info.params.push_back(std::move(a));
  entry.info.params.push_back(string_param("f", "quickstart",
                                           "the field f(t, u): the name of a registered field (tsi list fields)"));
  entry.default_n_tau = 32;
  entry.nonlinearity_degree = 0;  // f is any field: SE2 takes 6 Gauss nodes (exact to degree 10)
  // The default problem's regime (the quickstart, T = 1, h = 1/4 .. 1/32): at eps = 1e-2 and
  // 1e-3, h = 1/32 is about a half fast period (pi eps) or a whole number of them, and SE1, SE2
  // or the composition miss their orders there (step-size resonance); at 0.1 and 1e-4 every
  // scheme reaches its order.
  entry.verification.epsilons = {0.1, 1e-4};
  const Registry* fields = &registry;
  entry.create = [fields](const Params& p) -> std::unique_ptr<Model> {
    bool complex_entries = false;
    Matrix A = matrix_from_json(p.raw().at("A"), "model.A", complex_entries);
    const FieldEntry& f = fields->field(p.string("f"), "model.f");
    if (f.dim != 0 && f.dim != A.rows())
      throw ConfigError("model.A", fmt::format("is {} x {}, but the field \"{}\" (model.f) takes states of {} "
                                               "entries: expected a {} x {} matrix",
                                               A.rows(), A.rows(), f.info.name, f.dim, f.dim, f.dim));
    if (complex_entries && !f.is_complex)
      throw ConfigError("model.A", fmt::format("has complex entries, but the field \"{}\" (model.f) is real: a real "
                                               "field takes real states only (declare the field complex)",
                                               f.info.name));
    PeriodicMatrixFlow flow(std::move(A), "model.A");
    const Index d = flow.dim();
    std::shared_ptr<const Field> field = f.create(d);
    if (!field) throw ConfigError("model.f", "the field \"" + f.info.name + "\" created nothing");
    Vector u0 = f.initial_value.size() == d ? f.initial_value : Vector();
    return make_matrix_model(p.number("eps"), std::move(flow), std::move(field), f.time_dependent,
                             complex_entries || f.is_complex, std::move(u0), f.info.name);
  };
  registry.add_model(std::move(entry));
}

}  // namespace tsi
