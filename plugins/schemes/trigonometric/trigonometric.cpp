// Trigonometric (Gautschi-type) integrators for x'' = -Omega^2 x + g(x), Omega >= 0 diagonal
// (SPEC.md section 8; Hairer, Lubich, Wanner, Geometric Numerical Integration, XIII.2.2), in
// one-step form with the filters Psi = psi(h Omega), Phi = phi(h Omega):
//   x_{n+1}  = cos(h Omega) x_n + h sinc(h Omega) x'_n + h^2/2 Psi g(Phi x_n)
//   x'_{n+1} = -Omega sin(h Omega) x_n + cos(h Omega) x'_n + h/2 (Psi_0 g(Phi x_n) + Psi_1 g(Phi x_{n+1}))
// with psi = sinc psi_1 and psi_0 = cos psi_1 (sinc(xi) = sin(xi)/xi). The filters:
//   filter            psi(xi)          phi(xi)
//   gautschi          sinc^2(xi/2)     1                            (Gautschi 1961)
//   deuflhard         sinc(xi)         1                            (Deuflhard 1979)
//   garcia-archilla   sinc^2(xi)       sinc(xi)                     (Garcia-Archilla, Sanz-Serna, Skeel 1999)
//   hochbruck-lubich  sinc^2(xi/2)     sinc(xi) (1 + sin^2(xi/2)/3) (Hochbruck, Lubich 1999)
//   hairer-lubich     sinc^2(xi)       1                            (Hairer, Lubich 2000)
// Checked against the public package resting-dove/gautschiIntegrators run outside the project
// (its OneStepGS99 and OneStepF are the garcia-archilla and hairer-lubich rows; it has no other)
// and against an independent implementation of the same formulas (tests/data/rivals/).
// One evaluation of g per step: g(Phi x_{n+1}) is the next step's g(Phi x_n).
#include <array>
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
using tsi::RealVector;
using tsi::Vector;

enum class Filter { gautschi, deuflhard, garcia_archilla, hochbruck_lubich, hairer_lubich };

struct Settings {
  Filter filter = Filter::hairer_lubich;
  std::string name = "hairer-lubich";
};

// A number as the shortest text that reads back to the same double.
std::string number(Real x) {
  char text[32];
  if (x == std::floor(x) && std::abs(x) < 1e15) {  // a whole number as one: "50"
    std::snprintf(text, sizeof text, "%.0f", static_cast<double>(x));
    return text;
  }
  std::snprintf(text, sizeof text, "%.17g", static_cast<double>(x));
  for (int digits = 1; digits <= 17; ++digits) {  // fewer digits where they suffice
    char shorter[32];
    std::snprintf(shorter, sizeof shorter, "%.*g", digits, static_cast<double>(x));
    if (std::strtod(shorter, nullptr) == static_cast<double>(x)) return shorter;
  }
  return text;
}

Real sinc(Real xi) { return xi == 0 ? Real(1) : std::sin(xi) / xi; }

// psi_1 = psi / sinc: for sinc^2(xi/2) (Gautschi, Hochbruck-Lubich) it is tan(xi/2) / (xi/2),
// infinite at xi = odd multiples of pi, where the velocity update is undefined.
Real psi1(Filter f, Real xi) {
  switch (f) {
    case Filter::gautschi:
    case Filter::hochbruck_lubich:
      return xi == 0 ? Real(1) : std::tan(xi / 2) / (xi / 2);
    case Filter::deuflhard:
      return 1;
    case Filter::garcia_archilla:
    case Filter::hairer_lubich:
      return sinc(xi);
  }
  return 1;
}

Real psi(Filter f, Real xi) {
  switch (f) {
    case Filter::gautschi:
    case Filter::hochbruck_lubich: {
      const Real s = sinc(xi / 2);
      return s * s;
    }
    case Filter::deuflhard:
      return sinc(xi);
    case Filter::garcia_archilla:
    case Filter::hairer_lubich: {
      const Real s = sinc(xi);
      return s * s;
    }
  }
  return 1;
}

Real phi(Filter f, Real xi) {
  switch (f) {
    case Filter::garcia_archilla:
      return sinc(xi);
    case Filter::hochbruck_lubich: {
      const Real s = std::sin(xi / 2);
      return sinc(xi) * (1 + s * s / 3);
    }
    default:
      return 1;
  }
}

// The problem's second-order form, or a ConfigError where it has none (the assembler refuses
// such a pairing first: this guards a direct bind).
tsi::SecondOrderProblem& second_order_of(tsi::Problem& problem) {
  tsi::SecondOrderProblem* form = problem.second_order();
  if (!form)
    throw tsi::ConfigError("scheme.name", "got \"trigonometric\" on a problem without the second-order form "
                                          "x'' = -Omega^2 x + g(x); expected the direct reformulation of a model that "
                                          "declares it (fput, henon-heiles, klein-gordon, klein-gordon-complex)");
  return *form;
}

class Trigonometric final : public tsi::Stepper {
 public:
  Trigonometric(tsi::Problem& problem, Real h, const Settings& settings)
      : Stepper(problem, h), form_(second_order_of(problem)) {
    const RealVector& omega = form_.frequencies();
    const Index n = omega.size();
    for (RealVector* c : {&cos_, &sinc_h_, &minus_omega_sin_, &psi_, &phi_, &psi0_, &psi1_}) c->resize(n);
    for (Index i = 0; i < n; ++i) {
      const Real xi = h * omega(i), p1 = psi1(settings.filter, xi);
      // The filter's psi_1 blows up near xi = odd multiples of pi (tan(xi/2)): refused there.
      if (!std::isfinite(p1) || std::abs(p1) > 1e8)
        throw tsi::ConfigError(
            "time.h", "got h = " + number(h) + ", where h omega = " + number(xi) +
                          " is an odd multiple of pi (omega = " + number(omega(i)) + "): the " + settings.name +
                          " filter's psi_1 = tan(xi/2)/(xi/2) is infinite there; expected h omega away from "
                          "(2k+1) pi, or a filter with a finite psi_1 (garcia-archilla, hairer-lubich, deuflhard)");
      cos_(i) = std::cos(xi);
      sinc_h_(i) = h * sinc(xi);
      minus_omega_sin_(i) = -omega(i) * std::sin(xi);
      psi_(i) = psi(settings.filter, xi);
      phi_(i) = phi(settings.filter, xi);
      psi0_(i) = cos_(i) * p1;
      psi1_(i) = p1;
    }
    for (RealVector* w : {&x_, &v_, &x_next_, &filtered_, &g_, &g_next_}) w->setZero(n);
  }

  void reset() override { g_valid_ = false; }

  void step(Real /*t*/, Vector& y) override {
    form_.split(y, x_, v_);
    // g(Phi x_n): the last step's g(Phi x_{n+1}) where y is still that step's result (compared
    // as the state itself: positions read back from it may differ from x_{n+1} by a rounding).
    if (!g_valid_ || y != y_of_g_) {
      filtered_ = phi_.cwiseProduct(x_);
      form_.force(filtered_, g_);
    }
    const Real h2 = 0.5 * h_ * h_;
    x_next_ = cos_.cwiseProduct(x_) + sinc_h_.cwiseProduct(v_) + h2 * psi_.cwiseProduct(g_);
    filtered_ = phi_.cwiseProduct(x_next_);
    form_.force(filtered_, g_next_);
    v_ = minus_omega_sin_.cwiseProduct(x_) + cos_.cwiseProduct(v_) +
         (0.5 * h_) * (psi0_.cwiseProduct(g_) + psi1_.cwiseProduct(g_next_));
    form_.join(x_next_, v_, y);
    g_.swap(g_next_);
    y_of_g_ = y;
    g_valid_ = true;
  }

  double state_vectors() const override { return state_vectors_for(problem_.layout(), {}); }
  // 14 real vectors of n positions (7 coefficients, 7 of work), n <= the state's real entries / 2
  // (positions and velocities): at most 14 n reals = 3.5 vectors of complex entries packed two
  // reals to one.
  static double state_vectors_for(const tsi::ProblemLayout&, const Settings&) { return 3.5; }

 private:
  tsi::SecondOrderProblem& form_;
  RealVector cos_, sinc_h_, minus_omega_sin_, psi_, phi_, psi0_, psi1_;
  RealVector x_, v_, x_next_, filtered_, g_, g_next_;
  Vector y_of_g_;  // the state g_ belongs to
  bool g_valid_ = false;
};

void register_trigonometric(tsi::Registry& registry) {
  tsi::SchemeEntry entry;
  entry.info.name = "trigonometric";
  entry.info.aliases = {"gautschi-type"};
  entry.info.summary =
      "trigonometric (Gautschi-type) integrators for x'' = -Omega^2 x + g(x), one-step form with a filter (direct "
      "problem of a model with the second-order form: fput, Henon-Heiles, Klein-Gordon)";
  entry.info.params = {tsi::string_param("filter", "hairer-lubich",
                                         "the filter functions psi and phi (SPEC.md section 8): gautschi (1961), "
                                         "deuflhard (1979), garcia-archilla (Sanz-Serna, Skeel 1999), hochbruck-lubich "
                                         "(1999), hairer-lubich (2000)")
                           .choices({"gautschi", "deuflhard", "garcia-archilla", "hochbruck-lubich", "hairer-lubich"})};
  entry.traits.order = 2;  // for bounded energy, independently of Omega (not uniformly accurate in general)
  entry.traits.symmetric = true;
  entry.traits.needs_second_order_form = true;
  entry.traits.reformulations = {"direct"};
  entry.create = [](const tsi::Params& p) {
    Settings s;
    s.name = p.string("filter");
    static const std::array<std::pair<const char*, Filter>, 5> names = {
        {{"gautschi", Filter::gautschi},
         {"deuflhard", Filter::deuflhard},
         {"garcia-archilla", Filter::garcia_archilla},
         {"hochbruck-lubich", Filter::hochbruck_lubich},
         {"hairer-lubich", Filter::hairer_lubich}}};
    for (const auto& [name, filter] : names)
      if (s.name == name) s.filter = filter;
    return tsi::make_scheme<Trigonometric>(s);
  };
  registry.add_scheme(std::move(entry));
}

}  // namespace

TSI_PLUGIN("trigonometric", register_trigonometric)
