// Study tables on synthetic data with known answers: observed orders, drift slopes, and the
// interpolated work to reach an error.
#include <doctest/doctest.h>

#include <fmt/format.h>

#include <cmath>

#include "study_report.hpp"
#include "tsi/convergence.hpp"

namespace {

// A row of the shape study_rows gives every run: each column present, null where not measured.
tsi::Json row(const std::string& id, double eps, double h, double error) {
  tsi::Json r = {{"id", id},        {"label", ""},       {"model", "m"},     {"scheme", "s"},
                 {"reformulation", "two-scale"}, {"eps", eps}, {"h", h}, {"t_end", 1.0},
                 {"n_tau", 64},     {"error", error},    {"varied", tsi::Json::object()}, {"wall_seconds", h},
                 {"status", "completed"}, {"message", ""}};
  for (const char* c : {"order", "error_estimate", "estimate_ratio", "estimate_asymptotic", "err_H", "err_I", "err_m",
                        "drift_H", "drift_I", "drift_m", "sweeps_mean", "rhs_evals", "t_reached"})
    r[c] = nullptr;
  return r;
}

}  // namespace

TEST_CASE("order estimation recovers the order of synthetic power laws") {
  const std::vector<double> h = {0.5, 0.25, 0.125, 0.0625};
  for (double p : {1.0, 2.0, 4.0}) {
    std::vector<double> e;
    for (double x : h) e.push_back(3.0 * std::pow(x, p));
    for (double o : tsi::successive_orders(h, e)) CHECK(o == doctest::Approx(p).epsilon(1e-12));
    CHECK(tsi::least_squares_order(h, e) == doctest::Approx(p).epsilon(1e-12));
  }
  // A perturbed series: the least-squares order lies between the successive ones.
  const std::vector<double> e = {0.25 * 1.1, 0.0625, 0.015625 * 0.9, 0.00390625};
  const auto s = tsi::successive_orders(h, e);
  const double ls = tsi::least_squares_order(h, e);
  CHECK(ls > *std::min_element(s.begin(), s.end()));
  CHECK(ls < *std::max_element(s.begin(), s.end()));
}

TEST_CASE("the convergence summary groups series by eps and takes the max over eps") {
  tsi::Json rows = tsi::Json::array();
  int k = 0;
  for (double eps : {1.0, 0.01})
    for (double h : {0.5, 0.25, 0.125})
      rows.push_back(row(fmt::format("r{}", ++k), eps, h, (eps == 1.0 ? 2.0 : 1.0) * h * h));
  const tsi::Json summary = tsi::app::convergence_summary(rows);
  REQUIRE(summary["series"].size() == 2);
  for (const auto& s : summary["series"]) CHECK(s["least_squares_order"].get<double>() == doctest::Approx(2.0));
  REQUIRE(summary["uniform"].size() == 1);
  CHECK(summary["uniform"][0]["max_error_over_eps"][0].get<double>() == doctest::Approx(0.5));  // 2 * 0.5^2
}

TEST_CASE("each table of a study that varies n_tau gives its own least-squares order") {
  // n_tau has a column of its own, so it is not among the varied paths: the tables are told
  // apart by it, and so must their LS rows be (the coarse grid's flat errors fit at 0, not at
  // the fine grid's 2).
  tsi::Json rows = tsi::Json::array();
  int k = 0;
  for (int n_tau : {16, 64})
    for (double h : {0.5, 0.25, 0.125}) {
      tsi::Json r = row(fmt::format("r{}", ++k), 1.0, h, n_tau == 16 ? 1e-4 : h * h);
      r["n_tau"] = n_tau;
      rows.push_back(r);
    }
  tsi::app::Study study;
  study.kind = "convergence";
  const std::string text = tsi::app::study_text(study, rows);
  INFO(text);
  const size_t coarse = text.find("s (n_tau 16) on m"), fine = text.find("s (n_tau 64) on m");
  REQUIRE(coarse != std::string::npos);
  REQUIRE(fine != std::string::npos);
  REQUIRE(coarse < fine);
  const size_t coarse_fit = text.find("LS order", coarse), fine_fit = text.find("LS order", fine);
  REQUIRE(coarse_fit < fine);
  CHECK(text.substr(coarse_fit, text.find('\n', coarse_fit) - coarse_fit).find("0.00") != std::string::npos);
  CHECK(text.substr(fine_fit, text.find('\n', fine_fit) - fine_fit).find("2.00") != std::string::npos);
}

TEST_CASE("the convergence summary never fits an order across a failed run") {
  tsi::Json rows = tsi::Json::array();
  int k = 0;
  for (double h : {0.5, 0.25, 0.125, 0.0625}) rows.push_back(row(fmt::format("r{}", ++k), 1.0, h, h * h));
  rows[1]["error"] = nullptr;  // h = 1/4 blew up
  rows[1]["status"] = "blow-up";
  const tsi::Json summary = tsi::app::convergence_summary(rows);
  REQUIRE(summary["series"].size() == 1);
  const tsi::Json& s = summary["series"][0];
  CHECK(s["h"].size() == 4);  // the failed run stays in the series
  CHECK(s["error"][1].is_null());
  CHECK(s["least_squares_order"].is_null());  // 2.0 over the survivors would hide the blow-up
  CHECK(s["failed_runs"] == 1);
  CHECK(s["successive_orders"][0].is_null());
  CHECK(s["successive_orders"][2].get<double>() == doctest::Approx(2.0));
}

TEST_CASE("drift slope is the least-squares slope over the chosen window") {
  std::string csv = "t,H,I,m,err_H,err_I,err_m,tau_roughness\n";
  for (int i = 0; i <= 100; ++i) {
    const double t = i;
    csv += fmt::format("{},0,0,0,{},5,0,0\n", t, 1e-3 * t + (i % 2 ? 1e-4 : -1e-4));
  }
  CHECK(tsi::app::drift_slope(csv, "err_H", 10.0) == doctest::Approx(1e-3).epsilon(1e-2));
  CHECK(tsi::app::drift_slope(csv, "err_I", 10.0) == doctest::Approx(0.0));
  CHECK(std::isnan(tsi::app::drift_slope(csv, "nosuch", 10.0)));
}

TEST_CASE("work to reach an error interpolates between the bracketing runs") {
  tsi::Json rows = tsi::Json::array();
  // error = h^2, wall = h: at error 1e-4, h = 1e-2 exactly.
  for (double h : {0.1, 0.03, 0.003}) rows.push_back(row("r", 1.0, h, h * h));
  const tsi::Json w = tsi::app::work_at_error(rows, {1e-4, 1e-12});
  REQUIRE(w.size() == 1);
  CHECK(w[0]["seconds"][0].get<double>() == doctest::Approx(1e-2).epsilon(1e-9));
  CHECK(w[0]["how"][0] == "interpolated");
  CHECK(w[0]["seconds"][1].is_null());  // no run reaches it
  CHECK(w[0]["how"][1].is_null());
}

TEST_CASE("work to reach an error every run beats is the cheapest run's, marked as a bound") {
  tsi::Json rows = tsi::Json::array();
  // Errors 1e-9 .. 1e-11 (all below 1e-6); wall (= h here) 3e-3, 1e-3 (the cheapest), 2e-3.
  rows.push_back(row("r", 1.0, 3e-3, 1e-9));
  rows.push_back(row("r", 1.0, 1e-3, 1e-10));
  rows.push_back(row("r", 1.0, 2e-3, 1e-11));
  const tsi::Json w = tsi::app::work_at_error(rows, {1e-6});
  REQUIRE(w.size() == 1);
  CHECK(w[0]["seconds"][0].get<double>() == 1e-3);
  CHECK(w[0]["how"][0] == "at_most");
}

TEST_CASE("the max over eps is unknown, not the survivors' maximum, when a run at that h failed") {
  tsi::Json rows = tsi::Json::array();
  int k = 0;
  for (double eps : {1.0, 0.01})
    for (double h : {0.5, 0.25}) rows.push_back(row(fmt::format("r{}", ++k), eps, h, h * h));
  rows[2]["error"] = nullptr;  // eps = 0.01, h = 1/2 blew up
  rows[2]["status"] = "blow-up";
  const tsi::Json summary = tsi::app::convergence_summary(rows);
  REQUIRE(summary["uniform"].size() == 1);
  const tsi::Json& u = summary["uniform"][0];
  CHECK(u["h"][0].get<double>() == 0.5);
  CHECK(u["max_error_over_eps"][0].is_null());  // 0.25 from eps = 1 alone would hide the blow-up
  CHECK(u["max_error_over_eps"][1].get<double>() == doctest::Approx(0.0625));
}
