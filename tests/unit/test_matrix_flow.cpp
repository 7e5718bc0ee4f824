// e^{A tau} of the matrix model (tsi/matrix_model.hpp): exact for every tau from A's spectral
// projectors, against Eigen's matrix exponential, for a non-normal real A and a complex A, and
// against Q e^{D tau} Q^T for a 300 x 300 A (frequencies read off its samples); a non-periodic A
// is refused with the deviation measured, also where its entries are large (the check does not
// scale with |A|), a Jordan block, a 1-norm above 1e10; the set-up stops on a stop request;
// model.A is read and checked entry by entry.
#include <doctest/doctest.h>

#include <cmath>
#include <csignal>
#include <numbers>
#include <random>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "tsi/error.hpp"
#include "tsi/matrix_model.hpp"
#include "tsi/stop_request.hpp"

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

// [[0, w], [-w, 0]]: eigenvalues +-i w.
tsi::Matrix rotation(double w) {
  tsi::Matrix A = tsi::Matrix::Zero(2, 2);
  A(0, 1) = w;
  A(1, 0) = -w;
  return A;
}

// The message of the ConfigError that constructing a flow of A throws ("accepted" if none).
std::string refusal(const tsi::Matrix& A) {
  try {
    tsi::PeriodicMatrixFlow flow(A, "model.A");
  } catch (const tsi::ConfigError& e) {
    CHECK(e.field() == "model.A");
    return e.what();
  }
  return "accepted";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Q D Q^T with Q a random orthogonal n x n matrix and D of 2 x 2 blocks turning at frequencies
// 0 .. top (block b at b mod (top + 1)); the last block's frequency is top + detune.
struct Similar {
  Eigen::MatrixXd Q, D;
  tsi::Matrix A() const { return (Q * D * Q.transpose()).cast<tsi::Complex>(); }
  tsi::Matrix exact(double tau) const {  // Q e^{D tau} Q^T
    Eigen::MatrixXd E = Eigen::MatrixXd::Identity(D.rows(), D.cols());
    for (Eigen::Index i = 0; i + 1 < D.rows(); i += 2) {
      const double w = D(i, i + 1), c = std::cos(w * tau), s = std::sin(w * tau);
      E(i, i) = E(i + 1, i + 1) = c;
      E(i, i + 1) = s;
      E(i + 1, i) = -s;
    }
    return (Q * E * Q.transpose()).cast<tsi::Complex>();
  }
};

Similar similar(int n, int top, double detune = 0.0) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd G(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) G(i, j) = normal(random);
  Similar s{Eigen::HouseholderQR<Eigen::MatrixXd>(G).householderQ(), Eigen::MatrixXd::Zero(n, n)};
  for (int b = 0; 2 * b + 1 < n; ++b) {
    const double w = b % (top + 1) + (2 * b + 3 >= n ? top - b % (top + 1) + detune : 0.0);
    s.D(2 * b, 2 * b + 1) = w;
    s.D(2 * b + 1, 2 * b) = -w;
  }
  return s;
}

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

TEST_CASE("matrix flow: apply() turns every column as at() does") {
  const tsi::RealVector taus = (tsi::RealVector(3) << 0.3, -1.7, 40.123).finished();
  tsi::Matrix states(7, 3);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 3; ++j) states(i, j) = tsi::Complex(std::sin(1.0 + i + 2.0 * j), std::cos(3.0 * i - j));
  tsi::Matrix complex_A = tsi::Matrix::Zero(3, 3);
  complex_A(0, 0) = tsi::Complex(0, 2);
  complex_A(1, 1) = tsi::Complex(0, -1);
  complex_A(0, 1) = tsi::Complex(0.5, 0.25);
  for (const tsi::Matrix& A : {non_normal_periodic(), complex_A}) {
    const tsi::PeriodicMatrixFlow flow(A, "model.A");
    tsi::Matrix turned = states.topRows(A.rows());
    flow.apply(taus, turned);
    for (int j = 0; j < 3; ++j)  // a real A turns a complex state's real and imaginary parts alike
      CHECK((turned.col(j) - flow.at(taus(j)) * states.col(j).head(A.rows())).cwiseAbs().maxCoeff() < 1e-13);
  }
}

TEST_CASE("matrix flow: a 300 x 300 A, its frequencies read off its samples, is exact") {
  // Above 256 x 256 no eigenvalues are computed (their Schur iteration cannot be interrupted):
  // the samples are refined until they resolve A. Measured: 1.8e-14 from Q e^{D tau} Q^T.
  const Similar s = similar(300, 20);
  const tsi::PeriodicMatrixFlow flow(s.A(), "model.A");
  CHECK(flow.max_frequency() == 20);
  CHECK(flow.period_deviation() < 1e-12);
  for (const double tau : {0.7, -2.9}) CHECK(max_difference(flow.at(tau), s.exact(tau)) < 1e-12);
}

TEST_CASE("matrix flow: the period test does not scale with |A|") {
  // Frequency 999999 + 5e-4: e^(2 pi A) - I is 3.1e-3, which the former test (1e-9 max(1, 2 pi
  // |A|) = 6.3e-3) passed; the flow then turned at 999999: after t/eps = 1e4, 5 radians off.
  const std::string detuned = refusal(rotation(999999 + 5e-4));
  CHECK(contains(detuned, "e^(2 pi A) differs from the identity by 0.00314"));
  CHECK(contains(detuned, "sum_k i k P_k over A's spectral projectors P_k"));
  CHECK(contains(detuned, "0+999999i"));
  // Frequency 1 + 1e-12, far below what the former test saw (6.3e-12 against 6.3e-9).
  CHECK(contains(refusal(rotation(1 + 1e-12)), "misses A by 3.1"));
  // The same on 300 x 300, where no eigenvalue is computed: the multiplicities of the
  // frequencies (the DFT of the traces of the samples) are not integers.
  CHECK(contains(refusal(similar(300, 20, 1e-9).A()), "the multiplicities of A's frequencies"));
  // The largest frequency taken, exactly: the flow is cos and sin of 1e6 tau to their rounding.
  const tsi::PeriodicMatrixFlow fast(rotation(1e6), "model.A");
  CHECK(fast.max_frequency() == 1000000);
  const tsi::Matrix E = fast.at(0.3);
  CHECK(std::abs(E(0, 0) - std::cos(3e5)) < 1e-9);
  CHECK(std::abs(E(0, 1) - std::sin(3e5)) < 1e-9);
  CHECK(contains(refusal(rotation(1e6 + 1)), "frequencies up to 1e6 are taken"));
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
  // A Jordan block (not diagonalisable) is not periodic either, its eigenvalues 0 though.
  tsi::Matrix J = tsi::Matrix::Zero(2, 2);
  J(0, 1) = 1e-3;
  CHECK_THROWS_AS(tsi::PeriodicMatrixFlow(J, "model.A"), tsi::ConfigError);
  J(0, 1) = 1;
  const std::string jordan = refusal(J);
  CHECK(contains(jordan, "e^(2 pi A) differs from the identity by 6.28"));
  CHECK(contains(jordan, "misses A by 1"));
  CHECK(contains(jordan, "or A is not diagonalisable (a Jordan block such as [[0, 1], [0, 0]]"));
}

TEST_CASE("matrix flow: entries too large or too small, 1 x 1, eigenvalues off the axis") {
  // Periodic (eigenvalues +-i) but a 1-norm of 1e11: rounding reaches 2e-5 in the eigenvalues.
  tsi::Matrix huge = tsi::Matrix::Zero(2, 2);
  huge(0, 1) = 1e11;
  huge(1, 0) = -1e-11;
  CHECK(contains(refusal(huge), "has the 1-norm 1e+11 (its largest column sum of |a_ij|), expected at most 1e+10"));
  // Eigenvalues +-i with eigenvectors far from orthogonal: e^(A tau) = [[cos, a sin], [-sin/a, cos]].
  // At a = 100 the flow is exact to rounding; at a = 1e5 the rounding of the samples (a^2 times
  // more) exceeds 1e-6 |A|: no test could tell a periodic A from another.
  huge(0, 1) = 100;
  huge(1, 0) = -0.01;
  const tsi::PeriodicMatrixFlow skewed(huge, "model.A");
  CHECK(std::abs(skewed.at(1.0)(0, 1) - 100 * std::sin(1.0)) < 1e-11);  // measured 1.1e-12 of 84
  huge(0, 1) = 1e5;
  huge(1, 0) = -1e-5;
  CHECK(contains(refusal(huge), "has e^(A tau) with entries up to 1e+05 (its eigenvectors that far from orthogonal)"));
  // Frequency 1e-9: not an integer, however small.
  CHECK(contains(refusal(rotation(1e-9)), "misses A by 1e-09"));
  // 1 x 1: 0 and 3i turn; 0.5 and 0.001 + i do not.
  tsi::Matrix one(1, 1);
  one(0, 0) = 0;
  CHECK(max_difference(tsi::PeriodicMatrixFlow(one, "model.A").at(2.0), tsi::Matrix::Ones(1, 1)) == 0);
  one(0, 0) = tsi::Complex(0, 3);
  const tsi::PeriodicMatrixFlow three(one, "model.A");
  CHECK(three.max_frequency() == 3);
  CHECK(std::abs(three.at(0.4)(0, 0) - std::polar(1.0, 1.2)) < 1e-15);
  one(0, 0) = 0.5;
  CHECK(contains(refusal(one), "A's eigenvalue 0.5+0i is 0.5 from i k with k = 0"));
  one(0, 0) = tsi::Complex(1e-3, 1);
  CHECK(contains(refusal(one), "A's eigenvalue 0.001+1i is 0.001 from i k with k = 1"));
}

TEST_CASE("matrix flow: the set-up stops on a stop request") {
  tsi::request_stop(SIGINT);
  try {
    tsi::PeriodicMatrixFlow flow(non_normal_periodic(), "model.A");
    FAIL("not stopped");
  } catch (const tsi::Interrupted& e) {
    CHECK(e.signal() == SIGINT);
    CHECK(contains(e.what(), "interrupted by signal 2 while setting up model.A's flow"));
  }
  tsi::clear_stop_request();
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
