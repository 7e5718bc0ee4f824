// e^{A tau} of the matrix model (tsi/matrix_model.hpp): exact for every tau from A's spectral
// projectors, against Eigen's matrix exponential, for a non-normal real A and a complex A;
// a non-periodic A is refused with the deviation measured; model.A is read and checked entry
// by entry.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "tsi/error.hpp"
#include "tsi/matrix_model.hpp"

namespace {

// S diag-block(frequencies) S^{-1}: a real A with eigenvalues 0, +-i, +-2i, +-3i, not normal.
tsi::Matrix non_normal_periodic() {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(7, 7);
  for (int k = 1; k <= 3; ++k) {
    D(2 * k - 1, 2 * k) = k;
    D(2 * k, 2 * k - 1) = -k;
  }
  Eigen::MatrixXd S(7, 7);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) S(i, j) = (i == j ? 2.0 : 0.0) + 0.3 * std::sin(1.0 + i + 3.0 * j);
  return (S * D * S.inverse()).cast<tsi::Complex>();
}

double max_difference(const tsi::Matrix& a, const tsi::Matrix& b) { return (a - b).cwiseAbs().maxCoeff(); }

}  // namespace

TEST_CASE("matrix flow: e^{A tau} from the projectors equals the matrix exponential") {
  SUBCASE("real, non-normal, frequencies 0 to 3") {
    const tsi::Matrix A = non_normal_periodic();
    const tsi::PeriodicMatrixFlow flow(A, "model.A");
    CHECK(flow.max_frequency() == 3);
    CHECK(flow.period_deviation() < 1e-12);
    for (const double tau : {0.0, 0.3, -1.7, 2.0 * std::numbers::pi, 40.123}) {
      const tsi::Matrix E = flow.at(tau);
      CHECK(E.imag().isZero(0.0));  // a real A gives a real flow, exactly
      CHECK(max_difference(E, (tsi::Complex(tau) * A).exp()) < 1e-11);
    }
  }
  SUBCASE("complex") {
    tsi::Matrix A = tsi::Matrix::Zero(3, 3);
    A(0, 0) = tsi::Complex(0, 2);
    A(1, 1) = tsi::Complex(0, -1);
    A(0, 1) = tsi::Complex(0.5, 0.25);  // upper triangular, distinct eigenvalues: diagonalisable
    const tsi::PeriodicMatrixFlow flow(A, "model.A");
    CHECK(flow.max_frequency() == 2);
    for (const double tau : {0.7, -3.1})
      CHECK(max_difference(flow.at(tau), (tsi::Complex(tau) * A).exp()) < 1e-12);
  }
}

TEST_CASE("matrix flow: a non-periodic A is refused with what was measured") {
  tsi::Matrix A = tsi::Matrix::Zero(2, 2);
  A(0, 1) = 1.1;
  A(1, 0) = -1.1;
  try {
    tsi::PeriodicMatrixFlow flow(A, "model.A");
    FAIL("accepted");
  } catch (const tsi::ConfigError& e) {
    const std::string what = e.what();
    CHECK(e.field() == "model.A");
    CHECK(what.find("differs from the identity by 0.588") != std::string::npos);
    CHECK(what.find("0+1.1i") != std::string::npos);
  }
  // A Jordan block (not diagonalisable) is not periodic either.
  tsi::Matrix J = tsi::Matrix::Zero(2, 2);
  J(0, 1) = 1e-3;
  CHECK_THROWS_AS(tsi::PeriodicMatrixFlow(J, "model.A"), tsi::ConfigError);
}

TEST_CASE("matrix flow: model.A is read entry by entry") {
  bool complex_entries = true;
  const tsi::Matrix A = tsi::matrix_from_json(tsi::Json::parse("[[0, 1], [-1, 0.5]]"), "model.A", complex_entries);
  CHECK_FALSE(complex_entries);
  CHECK(A(1, 1) == tsi::Complex(0.5, 0.0));
  const tsi::Matrix C = tsi::matrix_from_json(tsi::Json::parse("[[[0, 2], 0], [0, [0, -1]]]"), "model.A", complex_entries);
  CHECK(complex_entries);
  CHECK(C(0, 0) == tsi::Complex(0.0, 2.0));
  const auto field_of = [](const char* text) {
    bool c = false;
    try {
      tsi::matrix_from_json(tsi::Json::parse(text), "model.A", c);
    } catch (const tsi::ConfigError& e) {
      return e.field();
    }
    return std::string("accepted");
  };
  CHECK(field_of("[]") == "model.A");
  CHECK(field_of("[[1, 2], [3]]") == "model.A[1]");
  CHECK(field_of("[[1, 2], [3, \"x\"]]") == "model.A[1][1]");
  CHECK(field_of("[[1, 2], [3, null]]") == "model.A[1][1]");
  CHECK(field_of("[[1, [2]], [3, 4]]") == "model.A[0][1]");
  CHECK(field_of("{\"a\": 1}") == "model.A");
  CHECK(field_of("[[18446744073709551615]]") == "accepted");  // a uint64 is a finite double
}
