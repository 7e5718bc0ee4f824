// A model of the general class u' = (1/eps) A u + f(u) (SPEC.md section 7) as a tsi model
// plugin: a van der Pol oscillator (x, y) driven by a fast linear oscillator (p, q) of
// frequency 1/eps, which it drives back,
//
//   x' = y
//   y' = mu (1 - x^2) y - x + c p
//   p' =  q / eps
//   q' = -p / eps - c y,
//
// so that u = (x, y, p, q), A turns (p, q) by the angle tau (e^{A tau} is 2 pi-periodic, as
// the class requires) and f(u) = (y, mu (1 - x^2) y - x + c p, 0, -c y). The van der Pol
// term pumps energy in at small amplitude and takes it out at large amplitude (a limit cycle
// of amplitude about 2), so f is no Hamiltonian field: the model declares no Hamiltonian
// structure (hamiltonian() stays null), gives A itself (apply_A), and its runs show no energy.
// Everything else is the required core of tsi::Model and the closed-form derivative of f.
#include <cmath>
#include <memory>

#include "tsi/model.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Real;
using tsi::Vector;

class VanDerPol final : public tsi::Model {
 public:
  VanDerPol(Real eps, Real mu, Real c) : Model(eps), mu_(mu), c_(c) {}

  Index dim() const override { return 4; }
  bool is_complex() const override { return false; }

  // e^{A tau}: (p, q) <- (cos tau p + sin tau q, -sin tau p + cos tau q); x and y stay.
  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const Real c = std::cos(taus(j)), s = std::sin(taus(j));
      const tsi::Complex p = u(2, j), q = u(3, j);
      u(2, j) = c * p + s * q;
      u(3, j) = -s * p + c * q;
    }
  }

  // A u = (0, 0, q, -p): the generator of the flow above (the direct problem integrates
  // u' = (1/eps) A u + f(u) with it; `tsi check` compares it with the flow's derivative).
  void apply_A(const Vector& u, Vector& out) const override {
    out = Vector::Zero(4);
    out(2) = u(3);
    out(3) = -u(2);
  }

  void nonlinear_field(ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const tsi::Complex x = u(0, j), y = u(1, j), p = u(2, j);
      out(0, j) = y;
      out(1, j) = mu_ * (Real(1) - x * x) * y - x + c_ * p;
      out(2, j) = 0;
      out(3, j) = -c_ * y;
    }
  }

  // Df(u) z, in closed form (the default would be a central difference).
  void nonlinear_field_derivative(ConstMatrixRef u, ConstMatrixRef z, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const tsi::Complex x = u(0, j), y = u(1, j);
      out(0, j) = z(1, j);
      out(1, j) = mu_ * ((Real(1) - x * x) * z(1, j) - Real(2) * x * y * z(0, j)) - z(0, j) + c_ * z(2, j);
      out(2, j) = 0;
      out(3, j) = -c_ * z(1, j);
    }
  }

  // Near the limit cycle, the fast oscillator at amplitude 1.
  Vector initial_value() const override {
    Vector u = Vector::Zero(4);
    u(0) = 2;
    u(2) = 1;
    return u;
  }

 private:
  Real mu_, c_;
};

void register_van_der_pol(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "van-der-pol";
  entry.info.aliases = {"vdp"};
  entry.info.summary =
      "van der Pol oscillator coupled to a fast oscillator of frequency 1/eps: general class, no Hamiltonian "
      "structure (example plugin)";
  entry.info.params = {tsi::number_param("mu", 1.0, "strength of the van der Pol term mu (1 - x^2) y")
                           .check([](const tsi::Json& v) { return v.get<double>() >= 0.0; }, "a number >= 0"),
                       tsi::number_param("c", 1.0, "coupling of the slow and the fast oscillator")};
  entry.default_n_tau = 32;
  entry.nonlinearity_degree = 3;  // f is cubic in u (the x^2 y)
  entry.create = [](const tsi::Params& p) {
    return std::make_unique<VanDerPol>(p.number("eps"), p.number("mu"), p.number("c"));
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("van-der-pol", register_van_der_pol)
