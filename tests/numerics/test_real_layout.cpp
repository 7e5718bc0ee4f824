// A real model's two-scale state in the real layout (tau modes 0 .. n_tau/2 of a real U, real
// tau grid, real-to-complex transforms): half the unknowns of the complex layout, and the same
// solution to rounding for every scheme, prepared data of every method and re-preparation.
#include <doctest/doctest.h>

#include <random>
#include <vector>

#include "harness.hpp"
#include "tsi/fft.hpp"
#include "tsi/real_fft.hpp"
#include "tsi/context.hpp"

namespace {

using tsi::Complex;
using tsi::Matrix;
using tsi::RealMatrix;
using tsi::Vector;
using tsi::test::Harness;

RealMatrix random_real(int rows, int cols, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  RealMatrix m(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) m(i, j) = normal(gen);
  return m;
}

}  // namespace

TEST_CASE("real layout: RealFftBatch gives FftBatch's modes 0 .. n/2 and transforms back") {
  for (const auto& [n, rows, parts] : {std::tuple{8, 4, 1}, {64, 4, 2}, {16, 37, 3}, {2, 5, 1}}) {
    CAPTURE(n);
    CAPTURE(rows);
    CAPTURE(parts);
    const RealMatrix values = random_real(rows, n, 7u + static_cast<unsigned>(n * rows));
    tsi::FftBatch complex_fft(n, rows);
    complex_fft.data() = values.cast<Complex>();
    complex_fft.forward();
    const Matrix expected = complex_fft.data().leftCols(n / 2 + 1);

    tsi::RealFftBatch real_fft(n, rows, parts);
    REQUIRE(real_fft.modes() == n / 2 + 1);
    Matrix coefficients(rows, n / 2 + 1);
    for (int p = 0; p < parts; ++p) real_fft.forward_unnormalised(values.data(), coefficients.data(), p);
    coefficients /= static_cast<double>(n);
    CHECK((coefficients - expected).norm() <= 1e-15 * values.norm());

    const Matrix kept = coefficients;
    RealMatrix back(rows, n);
    real_fft.backward(coefficients.data(), back.data());
    CHECK((back - values).norm() <= 1e-14 * values.norm());
    CHECK(coefficients == kept);  // the coefficients are only read
  }
}

TEST_CASE("real layout: a real model's state is half, and its runs are the complex layout's to rounding") {
  auto& h = Harness::instance();
  const int n_tau = 32;
  for (const std::string model_name : {"henon-heiles", "cpd"}) {
    for (const std::string scheme_name : {"se1", "se2", "fd", "me", "eab", "collocation", "composition"}) {
      for (const double eps : {0.5, 1e-3}) {
        CAPTURE(model_name);
        CAPTURE(scheme_name);
        CAPTURE(eps);
        const auto run = [&](bool real_layout, int data_order) {
          tsi::Json config = {{"model", {{"name", model_name}, {"eps", eps}}},
                              {"reformulation", {{"name", "two-scale"}, {"n_tau", n_tau}, {"real_layout", real_layout}}},
                              {"scheme", {{"name", scheme_name}}}};
          if (data_order > 0) config["reformulation"]["initial_data_order"] = data_order;
          tsi::Assembly a = h.assemble(config);
          CHECK(a.reformulation->size() == 4 * (real_layout ? n_tau / 2 + 1 : n_tau));
          return tsi::test::solve(*a.model, *a.reformulation, *a.scheme, 0.5, 8);
        };
        const Vector real = run(true, 0), complex = run(false, 0);
        // Measured: 1e-22 .. 3e-16 for Henon-Heiles but eab at eps = 0.5 (5e-14: its prepared
        // data's trajectory), 9e-14 .. 1.4e-13 for the charged particle at eps = 1e-3 (every
        // scheme alike: rounding times the 1/eps of its physical velocity).
        CHECK((real - complex).norm() <= 2e-13 * complex.norm());
        // Every order of the prepared data. At eps = 0.5 the recursion of orders 4 and above
        // amplifies rounding by up to 1e9 in either layout (measured, complex layout: a one-ulp
        // change of u0 moves order-7 data by 1.2e-7), so there only the closed formulas are
        // compared.
        if (scheme_name == "se1") {
          for (const int order : eps < 0.1 ? std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8} : std::vector<int>{1, 2, 3}) {
            CAPTURE(order);
            const Vector r = run(true, order), c = run(false, order);
            CHECK((r - c).norm() <= 2e-13 * c.norm());
          }
        }
      }
    }
  }
}

TEST_CASE("real layout: re-preparation and the tau monitors read the real layout as the complex one") {
  auto& h = Harness::instance();
  const auto build = [&](bool real_layout) {
    return h.assemble({{"model", {{"name", "cpd"}, {"eps", 1.0}}},
                       {"reformulation", {{"name", "two-scale"}, {"n_tau", 32}, {"real_layout", real_layout},
                                          {"reprepare", "auto"}, {"reprepare_min_gap", 2},
                                          {"reprepare_defect", 1e-12}, {"reprepare_defect_floor", 1e-9}}},
                       {"scheme", {{"name", "se1"}}}});
  };
  tsi::Assembly real = build(true), complex = build(false);
  Vector yr = real.reformulation->prepare(real.u0), yc = complex.reformulation->prepare(complex.u0);
  const double hstep = 0.05;
  auto& sr = real.bind(hstep);
  auto& sc = complex.bind(hstep);
  long repreparations = 0;
  for (long n = 1; n <= 40; ++n) {
    const double t = tsi::step_time(n, hstep);
    sr.step(tsi::step_time(n - 1, hstep), yr);
    sc.step(tsi::step_time(n - 1, hstep), yc);
    const bool a = real.reformulation->repreparation()->after_step(n, t, yr),
               b = complex.reformulation->repreparation()->after_step(n, t, yc);
    REQUIRE(a == b);
    if (a) {
      ++repreparations;
      sr.reset();
      sc.reset();
    }
    CHECK(real.reformulation->two_scale_diagnostics()->tau_spread(yr) == doctest::Approx(complex.reformulation->two_scale_diagnostics()->tau_spread(yc)).epsilon(1e-10));
    CHECK(real.reformulation->two_scale_diagnostics()->tau_roughness(yr) ==
          doctest::Approx(complex.reformulation->two_scale_diagnostics()->tau_roughness(yc)).epsilon(1e-8));
    const Vector ur = real.reformulation->read_back(yr, t), uc = complex.reformulation->read_back(yc, t);
    CHECK((ur - uc).norm() <= 1e-12 * uc.norm());
    CHECK(ur.imag().norm() == 0.0);  // a real U reads back real
  }
  CHECK(repreparations > 0);  // the rule fired: the comparison covers re-preparation
}

TEST_CASE("real layout: on two tau-grid threads the field is the one-thread field") {
  if (!tsi::tau_grid_threads_available()) return;
  auto& h = Harness::instance();
  const auto field = [&](int threads) {
    std::unique_ptr<tsi::Reformulation> r;
    auto model = h.model("henon-heiles", 0.01);
    {
      const tsi::test::ContextSetting setting(tsi::test::ContextSetting::tau_grid(threads, 1));
      r = h.reformulation("two-scale", model, {{"n_tau", 64}});
    }
    REQUIRE(r->two_scale_diagnostics()->threads() == threads);
    const Vector y = r->prepare(model->initial_value()) * 3.0;
    Vector out;
    r->nonlinear(0.0, y, out);
    return out;
  };
  const Vector one = field(1), two = field(2);
  CHECK((one - two).norm() <= 1e-15 * one.norm());
}

TEST_CASE("real layout: a real model's filtered and direct states hold two values to an entry, with the same numbers") {
  // Henon-Heiles and the charged particle (4 values: 2 entries) and the matrix model with the
  // non-autonomous linear field (4 values and t: 3 entries, the last one half used).
  auto& h = Harness::instance();
  const tsi::Json models[] = {{{"name", "henon-heiles"}, {"eps", 0.1}},
                              {{"name", "cpd"}, {"eps", 0.1}},
                              {{"name", "matrix"}, {"eps", 0.15}, {"f", "linear"}}};
  for (const tsi::Json& model : models) {
    for (const auto& [reformulation, scheme] : {std::pair{"filtered", "rk78"}, {"filtered", "se1"}, {"filtered", "eab"},
                                                {"direct", "rk78"}, {"direct", "strang"}}) {
      CAPTURE(model.dump());
      CAPTURE(reformulation);
      CAPTURE(scheme);
      const auto run = [&](bool real_layout) -> Vector {
        tsi::Json config = {{"model", model},
                            {"reformulation", {{"name", reformulation}, {"real_layout", real_layout}}},
                            {"scheme", {{"name", scheme}}}};
        if (std::string(scheme) == "rk78") config["scheme"]["tol"] = 1e-12;
        if (std::string(scheme) == "strang" && model["name"] != "cpd") return {};  // the one with exact flows
        tsi::Assembly a = h.assemble(config);
        const tsi::Index d = a.model->dim();
        CHECK(a.reformulation->size() == (real_layout ? (d + 1) / 2 : d));
        // The state is the model's values two to an entry, and reads back as them.
        const Vector y0 = a.reformulation->prepare(a.u0);
        if (real_layout && std::string(reformulation) == "filtered") {
          for (tsi::Index i = 0; i < d; ++i)
            CHECK(a.u0(i).real() == (i % 2 == 0 ? y0(i / 2).real() : y0(i / 2).imag()));
          // (e^{A 0} from the matrix model's spectral projectors: the identity to rounding)
          CHECK((a.reformulation->read_back(y0, 0.0) - a.u0).norm() <= 1e-15 * a.u0.norm());
        }
        return tsi::test::solve(*a.model, *a.reformulation, *a.scheme, 0.5, 8);
      };
      const Vector packed = run(true), unpacked = run(false);
      if (unpacked.size() == 0) continue;  // no exact flows for Strang
      const double difference = (packed - unpacked).norm() / unpacked.norm();
      CAPTURE(difference);
      // The same arithmetic on the same doubles.
      CHECK(difference == 0.0);
    }
  }
}
