// A charged particle in three dimensions in a strong uniform magnetic field plus O(1) fields
// (SPEC.md section 8; Hairer, Lubich, Wang, Numer. Math. 144 (2020), section 8):
//     x' = v,   v' = (1/eps) v x B0 + v x B1(x) + E(x),   |B0| = 1.
// The state is u = (x, v), real, dim 6, and the stiff part is uniform:
//     A u = (0, v x B0),   e^{A tau} u = (x, v_par + cos(tau) v_perp - sin(tau) B0 x v_perp),
// 2 pi-periodic (v_par = (B0 . v) B0, v_perp = v - v_par): the two-scale schemes run it as any
// model of the class, f(u) = (v, v x B1(x) + E(x)) being O(1). The Boris schemes take its
// Lorentz-force form, B(x) = B0/eps + B1(x).
//
// Fields (model.fields):
//   hlw       B1 = (-x1, 0, x3), E = (x1, x2, 0) / (x1^2 + x2^2)^{3/2} = -grad 1/|x_perp|, the
//             test of Hairer, Lubich and Wang (B = curl(0, x1/eps + x1 x3, 0)); with their data
//             x(0) = (1/3, 1/4, 1/2), v(0) = (2/5, 2/3, 1) by default;
//   constant  B1 = model.b1 and E = model.e, constant vectors (zero where not given).
// Recorded: the energy |v|^2/2 + U(x) (E = -grad U: U = 1/|x_perp| or -E . x), which the flow
// keeps exactly (the magnetic force does no work), and the magnetic moment
// mu = |v_perp|^2 / (2 |B|) about B = B(x), an adiabatic invariant.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tsi/error.hpp"
#include "tsi/model.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::ConstMatrixRef;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Real;
using tsi::RealVector3;
using tsi::Vector;

enum class Fields { hlw, constant };

// A JSON array of three finite numbers, or null.
bool three_finite_numbers(const tsi::Json& v) {
  if (!v.is_array() || v.size() != 3) return false;
  for (const auto& c : v)
    if (!c.is_number() || !std::isfinite(c.get<double>())) return false;
  return true;
}

RealVector3 vector_of(const tsi::Json& v) {
  return RealVector3(static_cast<Real>(v[0].get<double>()), static_cast<Real>(v[1].get<double>()),
                     static_cast<Real>(v[2].get<double>()));
}

class ChargedParticle3d final : public tsi::Model, public tsi::ChargedParticleForm {
 public:
  ChargedParticle3d(Real eps, const RealVector3& b0, Fields fields, const RealVector3& b1, const RealVector3& e)
      : Model(eps), b0_(b0), fields_(fields), b1_(b1), e_(e) {}
  using Model::linear_flow;
  using Model::nonlinear_field;

  const tsi::ChargedParticleForm* charged_particle_form() const override { return this; }

  Index dim() const override { return 6; }
  bool is_complex() const override { return false; }

  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const RealVector3 v(u(3, j).real(), u(4, j).real(), u(5, j).real());
      const RealVector3 turned = rotate(v, taus(j));
      for (int i = 0; i < 3; ++i) u(3 + i, j) = turned(i);
    }
  }

  void apply_A(const Vector& u, Vector& out) const override {
    const RealVector3 v(u(3).real(), u(4).real(), u(5).real());
    const RealVector3 a = v.cross(b0_);
    out.setZero(6);
    for (int i = 0; i < 3; ++i) out(3 + i) = a(i);
  }

  void nonlinear_field(ConstMatrixRef u, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const RealVector3 x(u(0, j).real(), u(1, j).real(), u(2, j).real());
      const RealVector3 v(u(3, j).real(), u(4, j).real(), u(5, j).real());
      RealVector3 b1, e;
      slow_fields(x, b1, e);
      const RealVector3 a = v.cross(b1) + e;
      for (int i = 0; i < 3; ++i) {
        out(i, j) = v(i);
        out(3 + i, j) = a(i);
      }
    }
  }

  // D f(x, v)(z_x, z_v) = (z_v, z_v x B1 + v x DB1 z_x + DE z_x).
  void nonlinear_field_derivative(ConstMatrixRef u, ConstMatrixRef z, MatrixRef out) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const RealVector3 x(u(0, j).real(), u(1, j).real(), u(2, j).real());
      const RealVector3 v(u(3, j).real(), u(4, j).real(), u(5, j).real());
      const RealVector3 zx(z(0, j).real(), z(1, j).real(), z(2, j).real());
      const RealVector3 zv(z(3, j).real(), z(4, j).real(), z(5, j).real());
      RealVector3 b1, e;
      slow_fields(x, b1, e);
      RealVector3 a = zv.cross(b1);
      if (fields_ == Fields::hlw) {
        const RealVector3 db1(-zx(0), 0, zx(2));
        const Real r2 = x(0) * x(0) + x(1) * x(1), r3 = r2 * std::sqrt(r2);
        const Real xz = x(0) * zx(0) + x(1) * zx(1);
        const RealVector3 de((zx(0) - 3 * x(0) * xz / r2) / r3, (zx(1) - 3 * x(1) * xz / r2) / r3, 0);
        a += v.cross(db1) + de;
      }
      for (int i = 0; i < 3; ++i) {
        out(i, j) = zv(i);
        out(3 + i, j) = a(i);
      }
    }
  }

  Vector initial_value() const override {
    Vector u(6);
    u << Real(1) / 3, Real(1) / 4, Real(1) / 2, Real(2) / 5, Real(2) / 3, Real(1);
    return u;
  }

  // ---- The Lorentz-force form -----------------------------------------------------------
  void to_particle(const Vector& u, RealVector3& x, RealVector3& v) const override {
    x << u(0).real(), u(1).real(), u(2).real();
    v << u(3).real(), u(4).real(), u(5).real();
  }
  void from_particle(const RealVector3& x, const RealVector3& v, Vector& u) const override {
    u.resize(6);
    for (int i = 0; i < 3; ++i) {
      u(i) = x(i);
      u(3 + i) = v(i);
    }
  }
  void fields(const RealVector3& x, RealVector3& B, RealVector3& E) const override {
    slow_fields(x, B, E);
    B += b0_ / eps();
  }

  std::vector<tsi::ModelInvariant> invariants() const override {
    return {{"energy", "|v|^2/2 + U(x) with E = -grad U (hlw: U = 1/|x_perp|; constant: U = -E . x): exact",
             [this](const Vector& u) { return energy_of(u); }},
            {"mu",
             "magnetic moment |v_perp|^2 / (2 |B(x)|) about the total field: adiabatic, O(eps) "
             "oscillations expected, no drift",
             [this](const Vector& u) { return magnetic_moment(u); }}};
  }

 private:
  // e^{-tau B0^} v: the component along B0 kept, the normal one turned by -tau about B0.
  RealVector3 rotate(const RealVector3& v, Real tau) const {
    const RealVector3 par = b0_.dot(v) * b0_, perp = v - par;
    return par + std::cos(tau) * perp - std::sin(tau) * b0_.cross(perp);
  }

  void slow_fields(const RealVector3& x, RealVector3& b1, RealVector3& e) const {
    if (fields_ == Fields::constant) {
      b1 = b1_;
      e = e_;
      return;
    }
    b1 << -x(0), 0, x(2);
    const Real r2 = x(0) * x(0) + x(1) * x(1), r3 = r2 * std::sqrt(r2);
    e << x(0) / r3, x(1) / r3, 0;
  }

  Real energy_of(const Vector& u) const {
    RealVector3 x, v;
    to_particle(u, x, v);
    const Real potential =
        fields_ == Fields::hlw ? 1 / std::sqrt(x(0) * x(0) + x(1) * x(1)) : -e_.dot(x);
    return v.squaredNorm() / 2 + potential;
  }

  Real magnetic_moment(const Vector& u) const {
    RealVector3 x, v, b, e;
    to_particle(u, x, v);
    fields(x, b, e);
    const Real bb = b.norm();
    const RealVector3 perp = v - (b.dot(v) / (bb * bb)) * b;
    return perp.squaredNorm() / (2 * bb);
  }

  RealVector3 b0_;
  Fields fields_;
  RealVector3 b1_, e_;
};

void register_charged_particle_3d(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "charged-particle-3d";
  entry.info.aliases = {"cp3d"};
  entry.info.summary =
      "charged particle in 3-D, x' = v, v' = (1/eps) v x B0 + v x B1(x) + E(x): uniform stiff field, O(1) fields "
      "(Hairer-Lubich-Wang's test by default), state (x, v), dim 6";
  tsi::ParamSpec b0 = tsi::array_param("b0", "direction of the strong uniform field B0/eps: a unit vector [b1, b2, b3]")
                          .check(
                              [](const tsi::Json& v) {
                                return three_finite_numbers(v) && std::abs(vector_of(v).norm() - 1) <= 1e-12;
                              },
                              "three finite numbers of norm 1 (within 1e-12)");
  b0.default_value = tsi::Json::array({0, 0, 1});
  entry.info.params = {
      b0,
      tsi::string_param("fields", "hlw",
                        "the O(1) fields: \"hlw\" (B1 = (-x1, 0, x3), E = (x1, x2, 0)/(x1^2 + x2^2)^{3/2}, Hairer, "
                        "Lubich and Wang's test) or \"constant\" (B1 = model.b1, E = model.e)")
          .choices({"hlw", "constant"}),
      tsi::array_param("b1", "fields = constant: the uniform field B1 [b1, b2, b3] added to B0/eps; default 0")
          .check(three_finite_numbers, "three finite numbers"),
      tsi::array_param("e", "fields = constant: the uniform electric field E [e1, e2, e3]; default 0")
          .check(three_finite_numbers, "three finite numbers"),
  };
  // e^{A tau} has the frequencies 0 and +-1 only, but U(t, tau) roughens in tau where eps is not
  // small: each tau turns the initial velocity, and at eps = 1 some of these trajectories pass near
  // the axis x_1 = x_2 = 0 where HLW's E is singular (SE1, h = 1/128, T = 1: relative error 0.48,
  // 1.8e-2 and 5.5e-5 at n_tau = 16, 64, 256; the run's tau monitor warns).
  entry.default_n_tau = 64;
  // The two-scale schemes' uniform order at T = 1 from Hairer-Lubich-Wang's data, where n_tau = 64
  // resolves U.
  entry.verification = {{1.0 / 16, 1.0 / 1024}, {8, 16, 32, 64}};
  entry.create = [](const tsi::Params& p) {
    const Fields fields = p.string("fields") == "constant" ? Fields::constant : Fields::hlw;
    RealVector3 b1 = RealVector3::Zero(), e = RealVector3::Zero();
    for (const char* name : {"b1", "e"}) {
      if (!p.has(name)) continue;
      if (fields != Fields::constant)
        throw tsi::ConfigError(std::string("model.") + name,
                               "given with fields = \"hlw\", whose fields are fixed; expected it only with fields = "
                               "\"constant\"");
      (std::string(name) == "b1" ? b1 : e) = vector_of(p.raw().at(name));
    }
    return std::make_unique<ChargedParticle3d>(p.number("eps"), vector_of(p.raw().at("b0")), fields, b1, e);
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("charged-particle-3d", register_charged_particle_3d)
