// A synthetic real model of any size for the scale benchmarks: `copies` independent
// Henon-Heiles systems (SPEC.md section 4), u = (q1, q2, p1, p2) of copy c at entries 4c .. 4c+3,
// copy c starting from 0.12 (1 + 0.5 c / copies) in every coordinate. Its two-scale problem has
// the memory and transform pattern of a particle model (many short real rows) with a field that
// costs a few flops per unknown, so that a step's cost is the transforms' and the memory's.
#include <cmath>
#include <memory>

#include "tsi/model.hpp"
#include "tsi/params.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Index;
using tsi::MatrixRef;
using tsi::Vector;

class HenonHeilesEnsemble final : public tsi::Model, public tsi::HamiltonianStructure, public tsi::FusedTauGrid {
 public:
  HenonHeilesEnsemble(double eps, Index copies) : Model(eps), copies_(copies) {}

  const tsi::HamiltonianStructure* hamiltonian() const override { return this; }
  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }

  Index dim() const override { return 4 * copies_; }
  bool is_complex() const override { return false; }

  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const double c = std::cos(taus(j)), s = std::sin(taus(j));
      for (Index k = 0; k < copies_; ++k) {
        const double q1 = u(4 * k, j).real(), p1 = u(4 * k + 2, j).real();
        u(4 * k, j) = c * q1 + s * p1;
        u(4 * k + 2, j) = -s * q1 + c * p1;
      }
    }
  }

  void nonlinear_field(tsi::ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j)
      for (Index k = 0; k < copies_; ++k) {
        const double q1 = u(4 * k, j).real(), q2 = u(4 * k + 1, j).real(), p2 = u(4 * k + 3, j).real();
        out(4 * k, j) = 0.0;
        out(4 * k + 1, j) = p2;
        out(4 * k + 2, j) = -2.0 * q1 * q2;
        out(4 * k + 3, j) = -q2 - q1 * q1 + q2 * q2;
      }
  }

  class GridField final : public tsi::TauGridField {
   public:
    explicit GridField(const tsi::RealVector& taus) : cos_(taus.array().cos()), sin_(taus.array().sin()) {}
    void evaluate(MatrixRef u, MatrixRef out) override { fused_field(cos_, sin_, u, out); }
    bool evaluates_real() const override { return true; }
    bool in_place() const override { return true; }  // each column read before it is written
    void evaluate_real(tsi::RealMatrixRef u, tsi::RealMatrixRef out) override { fused_field(cos_, sin_, u, out); }

   private:
    tsi::RealVector cos_, sin_;
  };
  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(taus);
  }
  bool independent_tau_grid_bindings() const override { return true; }

  // f_tau in one pass per column (Henon-Heiles' fused field, copy by copy).
  template <class Grid>
  static void fused_field(const tsi::RealVector& cos, const tsi::RealVector& sin, Grid& u, Grid& out) {
    const Index copies = u.rows() / 4;
    for (Index j = 0; j < u.cols(); ++j) {
      const double c = cos(j), s = sin(j);
      for (Index k = 0; k < copies; ++k) {
        const double q1 = c * std::real(u(4 * k, j)) + s * std::real(u(4 * k + 2, j)), q2 = std::real(u(4 * k + 1, j)),
                     p2 = std::real(u(4 * k + 3, j));
        const double g = -2.0 * q1 * q2;
        out(4 * k, j) = -s * g;
        out(4 * k + 1, j) = p2;
        out(4 * k + 2, j) = c * g;
        out(4 * k + 3, j) = -q2 - q1 * q1 + q2 * q2;
      }
    }
  }

  void apply_M(const Vector& u, Vector& out) const override {
    out = u;
    for (Index k = 0; k < copies_; ++k) out(4 * k + 1) = out(4 * k + 3) = 0.0;
  }
  void apply_J(const Vector& u, Vector& out) const override {
    out.resize(u.size());
    for (Index k = 0; k < copies_; ++k) {
      out(4 * k) = u(4 * k + 2);
      out(4 * k + 1) = u(4 * k + 3);
      out(4 * k + 2) = -u(4 * k);
      out(4 * k + 3) = -u(4 * k + 1);
    }
  }
  double H1(const Vector& u) const override {
    double sum = 0.0;
    for (Index k = 0; k < copies_; ++k) {
      const double q1 = u(4 * k).real(), q2 = u(4 * k + 1).real(), p2 = u(4 * k + 3).real();
      sum += 0.5 * q2 * q2 + 0.5 * p2 * p2 + q1 * q1 * q2 - q2 * q2 * q2 / 3.0;
    }
    return sum;
  }

  Vector initial_value() const override {
    Vector u(dim());
    for (Index k = 0; k < copies_; ++k)
      u.segment(4 * k, 4).setConstant(0.12 * (1.0 + 0.5 * static_cast<double>(k) / static_cast<double>(copies_)));
    return u;
  }

 private:
  Index copies_;
};

void register_ensemble(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "henon-heiles-ensemble";
  entry.info.summary = "benchmarks: `copies` independent Henon-Heiles systems, a real model of dim 4 copies";
  entry.info.params = {tsi::integer_param("copies", 1, "independent Henon-Heiles systems (dim 4 copies)")
                           .check([](const tsi::Json& v) { return v.get<long>() >= 1 && v.get<long>() <= (1L << 28); },
                                  "an integer from 1 to 2^28")};
  entry.default_n_tau = 16;
  entry.nonlinearity_degree = 2;
  entry.create = [](const tsi::Params& p) {
    return std::make_unique<HenonHeilesEnsemble>(p.number("eps"), static_cast<Index>(p.integer("copies")));
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("henon-heiles-ensemble", register_ensemble)
