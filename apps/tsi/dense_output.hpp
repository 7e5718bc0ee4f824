#pragma once
#include <map>
#include <vector>

#include "tsi/model.hpp"
#include "tsi/reformulation.hpp"

namespace tsi::app {

/// u at requested times between the steps (output.times): the problem's state U (two-scale:
/// U(t, tau), smooth in t uniformly in eps) interpolated in t by the polynomial of degree p
/// through p + 1 consecutive steps around the time (p the scheme's order: the interpolation's
/// error O(h^(p+1)) stays below the scheme's O(h^p)), then read back at tau = t/eps as at a step
/// (Reformulation::read_back). A step's state is kept only while a pending time's stencil needs
/// it; a time is evaluated as soon as its stencil's last step is computed. A step costs O(1)
/// besides the evaluations, however many times are asked.
class DenseOutput {
 public:
  /// `times` in [0, t_end] (any order; the values come back in the same order), steps of size
  /// h, n_steps of them.
  DenseOutput(std::vector<double> times, int degree, double h, long n_steps, const Model& model,
              Reformulation& reformulation);

  /// After step n (n = 0: the initial state), with the problem's state y.
  void observe(long n, const Vector& y);
  /// The run stopped (at its end, a blow-up or an interrupt) after the last step observed:
  /// the times it reached are evaluated with the steps of their stencil that were computed
  /// (a lower degree); the others stay unset. An interrupt (tsi::stop_requested) stops the
  /// evaluations within one of them, here and in observe: the times left stay unset.
  void finish();

  const std::vector<double>& times() const { return times_; }
  /// u(times[k]) in physical variables; empty where the run did not reach the time.
  const std::vector<Vector>& values() const { return values_; }
  int degree() const { return degree_; }

 private:
  struct Pending {
    std::size_t index;  // in times_
    long first, last;   // the stencil's steps
  };
  void evaluate(const Pending& p, long last_available);

  std::vector<double> times_;
  int degree_;
  double h_;
  const Model& model_;
  Reformulation& reformulation_;
  // By the stencil's last step (and so by its first: both grow with the time); the ones from
  // next_ on are still to be evaluated.
  std::vector<Pending> pending_;
  std::size_t next_ = 0;
  std::map<long, Vector> states_;  // the steps a pending stencil needs
  std::vector<Vector> values_;
  long last_observed_ = -1;
};

}  // namespace tsi::app
