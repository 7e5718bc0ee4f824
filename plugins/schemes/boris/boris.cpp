// The Boris family for x' = v, v' = v x B(x) + E(x), B = B0/eps + B1(x) (SPEC.md section 8),
// on a model that declares the Lorentz-force form (cpd, charged-particle-3d). Formulas and
// where each was confirmed: tests/data/rivals/boris.md.
//
// All variants are staggered: the scheme carries (x^n, v^{n-1/2}), and a step is
//     v_+ = v^{n-1/2} + h/2 Psi E^n,   v_- = (rotation about B) v_+,   v^{n+1/2} = v_- + h/2 Psi E^n,
//     x^{n+1} = x^n + h v^{n+1/2},
// with E^n = E(x^n). The run's state is (x^n, v^n): v^n is formed from the two half steps
// around it, and a step that finds the state it left (the usual case) goes on from its own
// v^{n+1/2}; any other state starts a trajectory from (x^n, v^n).
//
//   classical   Boris (1970): Psi = I, the rotation the Cayley transform of h B^n
//               (tan(theta/2) = h |B| / 2), v^n = (v^{n-1/2} + v^{n+1/2})/2; start
//               v^{1/2} = v^0 + h/2 (v^0 x B^0 + E^0). Second order for h |B| small; for
//               h >> eps it turns the gyration by the wrong angle and starts with a gyroradius
//               O(h) instead of O(eps).
//   filtered    Hairer, Lubich, Wang, Numer. Math. 144 (2020), Algorithm 2.1 ((2.3)-(2.10)):
//               Psi = tanch(h B^n^ / 2), the rotation exp(-h Bbar^), Bbar = B(xbar^n), with
//               xbar^n = theta x^n + (1 - theta) x_c^n between x^n and the guiding centre
//               x_c^n = x^n + v^n x B^n / |B^n|^2, theta = 1/sinc^2(h |B^n| / 2) ((2.5):
//               second order in x and v_par for h ~ eps, their Theorem 3.1); implicit through
//               v^n, solved by `iterations` fixed-point passes (one suffices, HLW p. 791).
//               v^n = Phi1(h Bbar^) (v_- + v_+)/2 - h Ups(h B^n^) E^n; start (2.10).
//               explicit = true takes xbar = x^n (their Exp-A: first order).
//   large-step  classical Boris from the initial velocity's component along B(x^0) alone (the
//               normal component filtered out): Hairer, Lubich, Shi, Numer. Math. (2022),
//               as far as their abstract and Lubich and Shi (BIT 2023)'s introduction state it;
//               their start and error theorem could not be read (boris.md, section 3).
//
// The filter functions are matrix functions g(h B^) of the 3x3 B^ w = B x w, evaluated by
// Rodriguez's formula: g(0) on the direction of B, Re g(i h|B|) + Im g(i h|B|) B^/|B| on the
// normal plane.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "tsi/error.hpp"
#include "tsi/plugin.hpp"

namespace {

using tsi::Index;
using tsi::Real;
using tsi::RealVector3;
using tsi::Vector;

enum class Variant { classical, filtered, large_step };

struct Settings {
  Variant variant = Variant::filtered;
  bool explicit_point = false;  // filtered: xbar = x^n (Exp-A)
  int iterations = 1;           // filtered, implicit: fixed-point passes for xbar^n
};

std::string number(Real x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", static_cast<double>(x));
  return text;
}

Real sinc(Real y) { return y == 0 ? Real(1) : std::sin(y) / y; }

// g(h B^) w for g given by its value g0 = g(0) and g(i y) = re + i im, y = h |B|.
RealVector3 apply(const RealVector3& B, Real g0, Real re, Real im, const RealVector3& w) {
  const Real b = B.norm();
  if (b == 0) return g0 * w;
  const RealVector3 u = B / b;
  const RealVector3 par = u.dot(w) * u, perp = w - par;
  return g0 * par + re * perp + im * u.cross(perp);
}

// The filter functions at y = h |B| (HLW 2020, Algorithm 2.1 and Appendix).
struct Filters {
  Real y = 0;
  Real tanc_half = 1;    // Psi(i y) = tan(y/2) / (y/2)
  Real inv_sinc = 1;     // Phi1(i y) = y / sin y
  Real ups_im = 0;       // Ups(i y) = -i (1/sinc y - 1) / y
  Real theta = 1;        // 1 / sinc^2(y/2)
  explicit Filters(Real hb) : y(hb) {
    if (y == 0) return;
    tanc_half = std::tan(y / 2) / (y / 2);
    inv_sinc = 1 / sinc(y);
    ups_im = -(inv_sinc - 1) / y;
    const Real s = sinc(y / 2);
    theta = 1 / (s * s);
  }
  // The poles: Psi at y = (2k+1) pi, Phi1 and Ups at k pi, theta at 2k pi (y != 0), all where
  // sin y = 0; refused within 1e-8 of one (Phi1 = y / sin y above 1e8 y).
  bool near_resonance() const {
    constexpr Real guard = 1e-8;
    return y != 0 && std::abs(std::sin(y)) < guard;
  }
};

tsi::ChargedParticleProblem& particle_of(tsi::Problem& problem) {
  tsi::ChargedParticleProblem* form = problem.charged_particle();
  if (!form)
    throw tsi::ConfigError("scheme.name", "got \"boris\" on a problem without the Lorentz-force form x' = v, v' = v "
                                          "x B(x) + E(x); expected the direct reformulation of a model that declares "
                                          "it (cpd, charged-particle-3d)");
  return *form;
}

class Boris final : public tsi::Stepper {
 public:
  Boris(tsi::Problem& problem, Real h, const Settings& settings)
      : Stepper(problem, h), form_(particle_of(problem)), settings_(settings) {}

  void reset() override {
    resumable_ = false;
    fresh_ = true;
  }

  void step(Real /*t*/, Vector& y) override {
    if (!resumable_ || y != y_left_) {
      form_.split(y, x_, v_);
      half_ = start(x_, v_);
      fresh_ = false;
    }
    x_ += h_ * half_;
    // The velocity update at x^{n+1}: v^{n+3/2} for the next step, v^{n+1} for the state.
    half_ = update(x_, half_, v_);
    form_.join(x_, v_, y);
    y_left_ = y;
    resumable_ = true;
  }

  double state_vectors() const override { return 2; }  // the state it left, and a few 3-vectors

 private:
  // v^{1/2} from (x^0, v^0).
  RealVector3 start(const RealVector3& x, RealVector3 v) {
    RealVector3 B, E;
    form_.fields(x, B, E);
    if (settings_.variant == Variant::large_step && fresh_) {
      const Real b = B.norm();
      if (b > 0) v = (B.dot(v) / (b * b)) * B;  // only the component along B(x^0)
    }
    if (settings_.variant != Variant::filtered) return v + (h_ / 2) * (v.cross(B) + E);
    // HLW (2.10), n = 0: v^{1/2} = phi1(-h Bbar^)(v^0 + h Ups(h B^) E) + h/2 Psi(h B^) E.
    const Filters f = filters(B);
    RealVector3 Bbar = B;
    if (!settings_.explicit_point) {
      RealVector3 Ebar;
      form_.fields(evaluation_point(x, v, B, f), Bbar, Ebar);
    }
    const Filters fbar = settings_.explicit_point ? f : filters(Bbar);
    const RealVector3 w = v + h_ * apply(B, 0, 0, f.ups_im, E);
    // phi1(-z) at z = i y: sinc(y) - i (1 - cos y) / y.
    const Real yb = fbar.y;
    const Real phi_im = yb == 0 ? Real(0) : -(1 - std::cos(yb)) / yb;
    return apply(Bbar, 1, sinc(yb), phi_im, w) + (h_ / 2) * apply(B, 1, f.tanc_half, 0, E);
  }

  // From v^{n-1/2} at x^n: returns v^{n+1/2} and sets v^n.
  RealVector3 update(const RealVector3& x, const RealVector3& half, RealVector3& v) {
    RealVector3 B, E;
    form_.fields(x, B, E);
    if (settings_.variant != Variant::filtered) {
      const RealVector3 plus = half + (h_ / 2) * E;
      const RealVector3 t = (h_ / 2) * B;
      const RealVector3 s = (2 / (1 + t.squaredNorm())) * t;
      const RealVector3 minus = plus + (plus + plus.cross(t)).cross(s);
      const RealVector3 next = minus + (h_ / 2) * E;
      v = (half + next) / 2;
      return next;
    }
    const Filters f = filters(B);
    const RealVector3 kick = (h_ / 2) * apply(B, 1, f.tanc_half, 0, E);
    const RealVector3 plus = half + kick;
    const RealVector3 drift = h_ * apply(B, 0, 0, f.ups_im, E);
    RealVector3 Bbar = B, minus = plus;
    const int passes = settings_.explicit_point ? 1 : settings_.iterations + 1;
    for (int pass = 0; pass < passes; ++pass) {
      if (pass > 0) {
        RealVector3 Ebar;
        form_.fields(evaluation_point(x, v, B, f), Bbar, Ebar);
      }
      const Filters fbar = pass == 0 ? f : filters(Bbar);  // the first pass turns about B itself
      // exp(-h Bbar^) v_+: the normal part turned by -y about Bbar.
      minus = apply(Bbar, 1, std::cos(fbar.y), -std::sin(fbar.y), plus);
      v = apply(Bbar, 1, fbar.inv_sinc, 0, (minus + plus) / 2) - drift;
    }
    return minus + kick;
  }

  // xbar^n = theta x^n + (1 - theta) x_c^n, x_c^n = x^n + v^n x B^n / |B^n|^2 (HLW (2.3), (2.4)).
  static RealVector3 evaluation_point(const RealVector3& x, const RealVector3& v, const RealVector3& B,
                                      const Filters& f) {
    const Real bb = B.squaredNorm();
    if (bb == 0) return x;
    const RealVector3 centre = x + v.cross(B) / bb;
    return f.theta * x + (1 - f.theta) * centre;
  }

  Filters filters(const RealVector3& B) const {
    Filters f(h_ * B.norm());
    if (f.near_resonance() || !std::isfinite(f.inv_sinc) || !std::isfinite(f.tanc_half))
      throw tsi::ConfigError("time.h", "got h = " + number(h_) + ", where h |B(x)| = " + number(f.y) +
                                           " is a multiple of pi: the filtered Boris's functions Phi1 = y / sin y "
                                           "and Psi = tan(y/2)/(y/2) are infinite there (HLW 2020, (3.2)); expected "
                                           "h |B| away from k pi, or variant \"classical\"");
    return f;
  }

  tsi::ChargedParticleProblem& form_;
  Settings settings_;
  RealVector3 x_ = RealVector3::Zero(), v_ = RealVector3::Zero(), half_ = RealVector3::Zero();
  Vector y_left_;  // the state the last step left
  bool resumable_ = false;
  bool fresh_ = true;  // no step since the binding or reset(): a new trajectory
};

void register_boris(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "boris";
  entry.info.summary =
      "the Boris family for x' = v, v' = v x B(x) + E(x): classical, filtered (Hairer-Lubich-Wang 2020) and "
      "large-step (the initial velocity along B; direct problem of a model with the Lorentz-force form: cpd, "
      "charged-particle-3d)";
  entry.info.params = {
      tsi::string_param("variant", "filtered",
                        "classical (Boris 1970), filtered (Hairer, Lubich, Wang 2020: second order in x and v_par "
                        "for h ~ eps) or large-step (classical from the initial velocity's component along B)")
          .choices({"classical", "filtered", "large-step"}),
      tsi::bool_param("explicit", false,
                      "filtered: evaluate the rotation's field at x^n (HLW's Exp-A, first order) instead of the "
                      "point xbar^n between x^n and the guiding centre (Imp-A, second order)"),
      tsi::integer_param("iterations", 1, "filtered, implicit: fixed-point passes for xbar^n (HLW: one suffices)")
          .range(1, 20),
  };
  entry.traits.order = 2;  // classical for h |B| small; filtered in x and v_par for h ~ eps
  entry.traits.symmetric = false;
  entry.traits.needs_charged_particle_form = true;
  entry.traits.reformulations = {"direct"};
  // Exp-A is first order (HLW, Theorem 3.1's last sentence).
  entry.traits_for = [base = entry.traits](const tsi::Json& params) {
    tsi::StepperTraits traits = base;
    if (params.value("explicit", false)) traits.order = 1;
    return traits;
  };
  entry.create = [](const tsi::Params& p) {
    Settings s;
    const std::string variant = p.string("variant");
    s.variant = variant == "classical" ? Variant::classical
                : variant == "large-step" ? Variant::large_step
                                          : Variant::filtered;
    s.explicit_point = p.boolean("explicit");
    s.iterations = static_cast<int>(p.integer("iterations"));
    if (s.explicit_point && s.variant != Variant::filtered)
      throw tsi::ConfigError("scheme.explicit", "got true with variant \"" + variant +
                                                    "\"; expected it only with variant \"filtered\"");
    return tsi::make_scheme<Boris>(s);
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("boris", register_boris)
