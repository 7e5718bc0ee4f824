#pragma once
#include "tsi/types.hpp"

namespace tsi {

/// Chebyshev-Lobatto points x_0 < ... < x_{m-1} on [-1, 1] (m odd, so that the middle one is
/// 0) with the matrices that differentiate their interpolating polynomial at the points and
/// integrate it from 0 to each point. The prepared data's averaged trajectory lives on them.
struct SigmaNodes {
  explicit SigmaNodes(int m);

  RealVector x;
  RealMatrix differentiate;  ///< (D v)_i = p'(x_i), p the interpolant of the values v
  RealMatrix integrate;      ///< (S v)_i = int_0^{x_i} p
  int center;                     ///< the index of x = 0
};

}  // namespace tsi
