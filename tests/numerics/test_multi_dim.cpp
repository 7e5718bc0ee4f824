// NLS and Klein-Gordon on 2-D and 3-D grids (SPEC.md section 7, tsi::SpectralGrid): the
// models' fields, linear flows and variables against the equations computed by naive
// Fourier sums (no FFTW), the fused tau-grid field against its definition, NLS's plane wave
// (an exact solution) met by every second-order two-scale scheme uniformly in eps, and 2-D
// runs from smooth data against rk78 on the filtered problem.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include "harness.hpp"
#include "tsi/convergence.hpp"
#include "tsi/model_capabilities.hpp"
#include "tsi/spectral_grid.hpp"

namespace {

using tsi::Complex;
using tsi::Index;
using tsi::Json;
using tsi::Vector;
using tsi::test::Harness;

// The grid's points and wave numbers in C order, computed here from the shape alone.
struct Grid {
  std::vector<int> shape;
  std::vector<std::array<double, 3>> x;  // coordinates
  std::vector<std::array<int, 3>> m;     // wave numbers (FFT order; Nyquist as -n/2)

  explicit Grid(std::vector<int> s) : shape(std::move(s)) {
    const int n1 = shape[0], n2 = shape.size() > 1 ? shape[1] : 1, n3 = shape.size() > 2 ? shape[2] : 1;
    const auto wave = [](int j, int n) { return j < n / 2 ? j : j - n; };
    for (int a = 0; a < n1; ++a)
      for (int b = 0; b < n2; ++b)
        for (int c = 0; c < n3; ++c) {
          x.push_back({tsi::two_pi * a / n1, tsi::two_pi * b / n2, tsi::two_pi * c / n3});
          m.push_back({wave(a, n1), shape.size() > 1 ? wave(b, n2) : 0, shape.size() > 2 ? wave(c, n3) : 0});
        }
  }
  Index points() const { return static_cast<Index>(x.size()); }
  double volume() const { return std::pow(tsi::two_pi, static_cast<double>(shape.size())); }
  double m2(Index p) const {
    const auto& k = m[static_cast<std::size_t>(p)];
    return k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
  }
  double dot(Index mode, Index point) const {
    const auto& k = m[static_cast<std::size_t>(mode)];
    const auto& y = x[static_cast<std::size_t>(point)];
    return k[0] * y[0] + k[1] * y[1] + k[2] * y[2];
  }
  // Samples (2 pi)^{-d/2} sum_m c_m e^{i m.x} of coefficients c = (2 pi)^{d/2} uhat.
  Vector samples(const Vector& c) const {
    Vector u = Vector::Zero(points());
    for (Index p = 0; p < points(); ++p)
      for (Index q = 0; q < points(); ++q) u(p) += c(q) * std::polar(1.0, dot(q, p));
    return u / std::sqrt(volume());
  }
  // Coefficients (2 pi)^{d/2} / N sum_x u(x) e^{-i m.x} of samples.
  Vector coefficients(const Vector& u) const {
    Vector c = Vector::Zero(points());
    for (Index q = 0; q < points(); ++q)
      for (Index p = 0; p < points(); ++p) c(q) += u(p) * std::polar(1.0, -dot(q, p));
    return c * (std::sqrt(volume()) / static_cast<double>(points()));
  }
};

Json grid_params(const std::vector<int>& shape) {
  Json p = {{"dims", shape.size()}, {"n_x", shape[0]}};
  if (shape.size() > 1) p["n_y"] = shape[1];
  if (shape.size() > 2) p["n_z"] = shape[2];
  return p;
}

// Smooth random coefficients: |c_m| ~ e^{-|m|}, seeded.
Vector random_state(const Grid& g, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Vector c(g.points());
  for (Index p = 0; p < g.points(); ++p) c(p) = Complex(uniform(rng), uniform(rng)) * std::exp(-std::sqrt(g.m2(p)));
  return c;
}

double relative(const Vector& a, const Vector& b) { return (a - b).norm() / b.norm(); }

const std::vector<std::vector<int>> shapes = {{6, 4}, {4, 6, 4}};

TEST_CASE("nls in 2-D and 3-D: variables, field and linear flow are the equation's, by naive Fourier sums") {
  auto& h = Harness::instance();
  for (const auto& shape : shapes) {
    const Grid g(shape);
    auto model = h.model_with("nls", 0.1, grid_params(shape));
    REQUIRE(model->dim() == g.points());
    const Vector c = random_state(g, 7);
    CAPTURE(shape.size());
    // Physical variables: samples of u, and back.
    const Vector u = g.samples(c);
    CHECK(relative(model->to_physical(c), u) < 1e-14);
    CHECK(relative(model->from_physical(u), c) < 1e-14);
    // The field -i |u|^2 u, taken to coefficients.
    Vector cubic(g.points());
    for (Index p = 0; p < g.points(); ++p) cubic(p) = Complex(0.0, -1.0) * std::norm(u(p)) * u(p);
    CHECK(relative(model->nonlinear_field(c), g.coefficients(cubic)) < 1e-13);
    // The linear flow: mode m turns by e^{-i |m|^2 tau} (the Nyquist modes by their +-n/2).
    const double tau = 0.37;
    Vector turned(g.points());
    for (Index p = 0; p < g.points(); ++p) turned(p) = c(p) * std::polar(1.0, -g.m2(p) * tau);
    CHECK(relative(model->linear_flow(tau, c), turned) < 1e-14);
    // Invariants: the mass is ||u||^2, the energy (1/eps) ||grad u||^2 + (1/2) ||u||_4^4.
    const double cell = g.volume() / static_cast<double>(g.points());
    double grad2 = 0.0, quartic = 0.0;
    for (Index p = 0; p < g.points(); ++p) {
      grad2 += g.m2(p) * std::norm(c(p));
      quartic += cell * std::pow(std::norm(u(p)), 2);
    }
    CHECK(model->mass(c) == doctest::Approx(cell * u.squaredNorm()).epsilon(1e-14));
    CHECK(model->energy(c) == doctest::Approx(grad2 / 0.1 + 0.5 * quartic).epsilon(1e-14));
    double largest_m2 = 0.0;  // sum of (n_i / 2)^2
    for (const int n : shape) largest_m2 += 0.25 * n * n;
    CHECK(model->max_linear_frequency() == doctest::Approx(largest_m2));
  }
}

TEST_CASE("nls and klein-gordon in 2-D and 3-D: the fused tau-grid field is e^{-A tau} f(e^{A tau} U)") {
  auto& h = Harness::instance();
  for (const std::string name : {"nls", "klein-gordon"})
    for (const auto& shape : shapes) {
      const Grid g(shape);
      auto model = h.model_with(name, 0.05, grid_params(shape));
      const Index n_tau = 8;
      tsi::RealVector taus(n_tau);
      tsi::Matrix states(g.points(), n_tau), expected(g.points(), n_tau);
      for (Index j = 0; j < n_tau; ++j) {
        taus(j) = tsi::two_pi * static_cast<double>(j) / n_tau;
        states.col(j) = random_state(g, 11 + static_cast<unsigned>(j));
        expected.col(j) = model->linear_flow(-taus(j), model->nonlinear_field(model->linear_flow(taus(j), states.col(j))));
      }
      tsi::Matrix out(g.points(), n_tau);
      model->filtered_field(taus, states, out);
      CAPTURE(name);
      CAPTURE(shape.size());
      CHECK((out - expected).norm() / expected.norm() < 1e-13);
      auto bound = model->bind_tau_grid(taus);
      tsi::Matrix in_place = states;
      bound->evaluate(in_place, in_place);
      CHECK((in_place - expected).norm() / expected.norm() < 1e-13);
    }
}

TEST_CASE("klein-gordon in 2-D and 3-D: a_k and the remainder take |k|^2, z^3 the field, by naive Fourier sums") {
  auto& h = Harness::instance();
  const double eps = 0.05, lambda = 1.0;
  for (const auto& shape : shapes) {
    const Grid g(shape);
    auto model = h.model_with("klein-gordon", eps, grid_params(shape));
    const Vector c = random_state(g, 3);
    // v = backward(a^{-1} c) / (2 pi)^{d/2}, z = Re v; the field i a^{-1} lambda coefficients(z^3).
    Vector scaled(g.points());
    for (Index p = 0; p < g.points(); ++p) scaled(p) = c(p) * std::pow(1.0 + eps * g.m2(p), -0.25);
    const Vector v = g.samples(scaled);
    CHECK(relative(model->to_physical(c), v) < 1e-14);
    Vector z3(g.points());
    for (Index p = 0; p < g.points(); ++p) z3(p) = lambda * std::pow(v(p).real(), 3);
    Vector field = g.coefficients(z3);
    for (Index p = 0; p < g.points(); ++p) field(p) *= Complex(0.0, 1.0) * std::pow(1.0 + eps * g.m2(p), -0.25);
    CHECK(relative(model->nonlinear_field(c), field) < 1e-13);
    const tsi::RealVector& remainder = model->linear_remainder();
    for (Index p = 0; p < g.points(); ++p)
      CHECK(remainder(p) == doctest::Approx((std::sqrt(1.0 + eps * g.m2(p)) - 1.0) / eps).epsilon(1e-12));
  }
}

// The error against the exact plane wave of one run: SCHEME on the two-scale problem,
// n steps to t_end = 1.
double plane_wave_error(const tsi::SchemeEntry& scheme, const Json& model_params, double eps, long n) {
  auto& h = Harness::instance();
  auto model = h.model_with("nls", eps, model_params);
  auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 16}});
  auto stepper = h.scheme(scheme.info.name, Json::object(), "nls");
  const Vector u = tsi::test::solve(*model, *two_scale, *stepper, 1.0, n);
  REQUIRE(model->exact_solution() != nullptr);
  const Vector exact = model->exact_solution()->at(model->to_physical(model->initial_value()), 1.0).x;
  return model->error_norm(u - exact) / model->error_norm(exact);
}

TEST_CASE("nls in 2-D and 3-D: every second-order two-scale scheme meets the exact plane wave at order 2, uniformly in eps") {
  // u = a e^{i k.x} e^{-i (|k|^2/eps + a^2) t}: on the two-scale problem U is constant in tau and
  // turns by e^{-i a^2 t}, which the schemes approximate at their order; the fast phase
  // e^{-i |k|^2 t / eps} is the linear flow's, exact: the errors do not depend on eps or on the
  // grid. a = 1.2, h a^2 <= 0.18: in every scheme's asymptotic range, errors above 1e-4.
  const std::vector<Json> waves = {
      {{"dims", 2}, {"n_x", 8}, {"n_y", 6}, {"initial", "plane-wave"}, {"wave_vector", {2, -1}}, {"amplitude", 1.2}},
      {{"dims", 3}, {"n_x", 4}, {"n_y", 6}, {"n_z", 4}, {"initial", "plane-wave"}, {"wave_vector", {1, 2, -1}},
       {"amplitude", 1.2}}};
  const std::vector<long> steps = {8, 16, 32, 64};
  std::vector<double> hs;
  for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
  for (const auto* scheme : tsi::test::second_order_schemes())
    for (const Json& wave : waves) {
      std::vector<double> largest(steps.size(), 0.0), smallest(steps.size(), HUGE_VAL);
      for (double eps : {1.0, 1e-2, 1e-4, 1e-6}) {
        std::vector<double> errors;
        for (long n : steps) errors.push_back(plane_wave_error(*scheme, wave, eps, n));
        for (std::size_t i = 0; i < steps.size(); ++i) {
          largest[i] = std::max(largest[i], errors[i]);
          smallest[i] = std::min(smallest[i], errors[i]);
        }
        const double order = tsi::least_squares_order(hs, errors);
        CAPTURE(scheme->info.name);
        CAPTURE(wave.dump());
        CAPTURE(eps);
        CAPTURE(errors[0]);
        CAPTURE(errors[3]);
        CHECK(std::abs(order - 2.0) <= 0.15);
      }
      for (std::size_t i = 0; i < steps.size(); ++i) {
        CAPTURE(scheme->info.name);
        CAPTURE(hs[i]);
        CHECK(largest[i] <= 1.5 * smallest[i]);
      }
    }
}

TEST_CASE("nls and klein-gordon in 2-D: SE1 against rk78 on the filtered problem, uniformly second order") {
  // The default data (the products of the 1-D profiles) on an 8 x 8 grid to T = 1, each model
  // with its default n_tau (NLS 256: f_tau has tau frequencies up to 2 max |m|^2 = 64 here;
  // Klein-Gordon 32), eps from 1 to 1/256 (NLS: the filtered reference's steps grow as 1/eps) or
  // to 1e-6 (Klein-Gordon), and from the step where h max A_k < 1 (Klein-Gordon's remainder reaches
  // |k|^2 / 2 = 16). The reference's own accuracy from a tighter rk78 run: 1e-9 at most, far
  // below the errors measured. Measured (h = 1/8 .. 1/64 for NLS, 1/16 .. 1/128 for
  // Klein-Gordon): NLS 5.3e-4 .. 8.3e-6 at eps = 1 and within 1.1x of it at 1/16 and 1/256;
  // Klein-Gordon 4.1e-4 .. 6.4e-6 at eps = 1e-4 and 1e-6 (within 2%), 3.8e-5 .. 5.9e-7 at eps = 1,
  // and at eps = 1/16 3.2e-4 .. 3.1e-6 (order 2.22: h = 1/16 is still pre-asymptotic there).
  auto& h = Harness::instance();
  const Json params = {{"dims", 2}, {"n_x", 8}};
  for (const std::string name : {"nls", "klein-gordon"}) {
    const std::vector<long> steps =
        name == "nls" ? std::vector<long>{8, 16, 32, 64} : std::vector<long>{16, 32, 64, 128};
    std::vector<double> hs;
    for (long n : steps) hs.push_back(1.0 / static_cast<double>(n));
    std::vector<double> largest(steps.size(), 0.0), limit;
    const std::vector<double> epsilons =
        name == "nls" ? std::vector<double>{1.0, 1.0 / 16, 1.0 / 256} : std::vector<double>{1.0, 1.0 / 16, 1e-4, 1e-6};
    for (double eps : epsilons) {
      auto model = h.model_with(name, eps, params);
      auto filtered = h.reformulation("filtered", model);
      const Vector reference = tsi::test::solve(*model, *filtered, *h.scheme("rk78", {{"tol", 1e-13}}), 1.0, 1);
      const Vector tighter = tsi::test::solve(*model, *filtered, *h.scheme("rk78", {{"tol", 1e-14}}), 1.0, 1);
      const double norm = model->error_norm(reference);
      CAPTURE(name);
      CAPTURE(eps);
      CHECK(model->error_norm(tighter - reference) / norm < 1e-9);
      std::vector<double> errors;
      for (long n : steps) {
        auto two_scale = h.reformulation("two-scale", model, {{"n_tau", name == "nls" ? 256 : 32}});
        const Vector u = tsi::test::solve(*model, *two_scale, *h.scheme("se1", Json::object(), name), 1.0, n);
        errors.push_back(model->error_norm(u - reference) / norm);
      }
      for (std::size_t i = 0; i < steps.size(); ++i) {
        largest[i] = std::max(largest[i], errors[i]);
      }
      CAPTURE(errors[0]);
      CAPTURE(errors[3]);
      CHECK(errors[3] > 1e-7);  // far above the reference's accuracy
      CHECK(std::abs(tsi::least_squares_order(hs, errors) - 2.0) <= 0.3);
      limit = errors;  // the smallest eps last
    }
    for (std::size_t i = 0; i < steps.size(); ++i) {
      // Uniform in eps: no eps has an error above twice the one at the smallest eps.
      CAPTURE(name);
      CAPTURE(hs[i]);
      CAPTURE(largest[i]);
      CAPTURE(limit[i]);
      CHECK(largest[i] <= 2.0 * limit[i]);
    }
  }
}

TEST_CASE("nls in 1-D and 3-D: the physical shape is the grid's (u_final.npy's)") {
  auto& h = Harness::instance();
  auto model = h.model_with("nls", 0.1, grid_params({8, 6, 4}));
  const std::vector<Index> expected = {8, 6, 4};
  CHECK(model->physical_shape() == expected);
  CHECK(h.model("nls", 0.1)->physical_shape() == std::vector<Index>{16});
}

}  // namespace

namespace {

TEST_CASE("nls with dealias: the field lives in the 2/3 band, the run stays there and conserves H") {
  // The field is the masked one (against the undealiased model), u0 is masked, and rk78 on the
  // direct problem keeps the modes outside the band at zero and H to its tolerance: the
  // dealiased system is Hamiltonian on the band.
  auto& h = Harness::instance();
  const std::vector<int> shape = {12, 12};
  Json params = grid_params(shape);
  auto plain = h.model_with("nls", 0.1, params);
  params["dealias"] = true;
  auto model = h.model_with("nls", 0.1, params);
  const tsi::RealVector mask = tsi::SpectralGrid(shape).dealias_mask();
  CHECK(mask.sum() == 81.0);  // |m_i| <= 4 of 12: 9 x 9
  const Vector c = random_state(Grid(shape), 5);
  const Vector field = model->nonlinear_field(c);
  CHECK((field - plain->nonlinear_field(c).cwiseProduct(mask.cast<Complex>())).norm() <= 1e-15 * field.norm());
  CHECK(!model->has_exact_nonlinear_flow());
  const Vector u0 = model->initial_value();
  CHECK(u0.cwiseProduct((1.0 - mask.array()).matrix().cast<Complex>()).norm() == 0.0);
  auto direct = h.reformulation("direct", model);
  Vector y = direct->prepare(u0);
  const double h0 = model->energy(u0);
  tsi::integrate(*h.scheme("rk78", {{"tol", 1e-13}})->bind(*direct, 0.5), y, 2, {});
  const Vector u = direct->read_back(y, 1.0);
  CHECK(u.cwiseProduct((1.0 - mask.array()).matrix().cast<Complex>()).norm() < 1e-14 * u.norm());
  CHECK(std::abs(model->energy(u) - h0) < 1e-10 * std::abs(h0));
  CHECK((u - u0).norm() > 0.1 * u0.norm());  // it moved
}

}  // namespace

namespace {

TEST_CASE("klein-gordon in 2-D and 3-D: at lambda = 0 the plane wave is exact, and every two-scale scheme meets it") {
  // v = a e^{i k.x} e^{i omega_k t}, omega_k = sqrt(1 + eps |k|^2) / eps: the linear part (1/eps and
  // the remainder A_k = |k|^2 / (1 + sqrt(1 + eps |k|^2)), integrated exactly by the schemes) alone.
  // The error is the rounding of the phases, which grow as 1/eps (the exact value's accuracy).
  auto& h = Harness::instance();
  const std::vector<Json> waves = {
      {{"dims", 2}, {"n_x", 8}, {"n_y", 6}, {"initial", "plane-wave"}, {"wave_vector", {3, -2}}, {"lambda", 0.0}},
      {{"dims", 3}, {"n_x", 4}, {"n_y", 6}, {"n_z", 8}, {"initial", "plane-wave"}, {"wave_vector", {1, 2, -3}},
       {"amplitude", 0.7}, {"lambda", 0.0}}};
  for (const Json& wave : waves)
    for (double eps : {1.0, 1e-3, 1e-6})
      for (const auto* scheme : tsi::test::two_scale_schemes()) {
        auto model = h.model_with("klein-gordon", eps, wave);
        REQUIRE(model->exact_solution() != nullptr);
        auto two_scale = h.reformulation("two-scale", model, {{"n_tau", 8}});
        const Vector u =
            tsi::test::solve(*model, *two_scale, *h.scheme(scheme->info.name, Json::object(), "klein-gordon"), 1.0, 8);
        const auto exact = model->exact_solution()->at(model->to_physical(model->initial_value()), 1.0);
        CAPTURE(wave.dump());
        CAPTURE(eps);
        CAPTURE(scheme->info.name);
        CHECK(model->error_norm(u - exact.x) / model->error_norm(exact.x) < 1e-13 + 100.0 * exact.accuracy);
      }
  // With lambda != 0 there is no exact solution to declare.
  Json cubic = waves[0];
  cubic["lambda"] = 1.0;
  CHECK(h.model_with("klein-gordon", 0.1, cubic)->exact_solution() == nullptr);
}

}  // namespace
