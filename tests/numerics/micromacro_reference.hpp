#pragma once
// MicroMacro.jl's published CosSin reference solutions (Klein-Gordon with complex z, N = 128,
// T = 0.25): tests/data/rivals/micromacro-cos-sin/donnee_<eps>.txt, one line per grid point,
// Re u, Im u, Re v, Im v.
#include <doctest/doctest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "tsi/types.hpp"

namespace tsi::test {

/// eps and the file name's spelling of it, for every published reference.
inline const std::vector<std::pair<double, std::string>>& micromacro_cases() {
  static const std::vector<std::pair<double, std::string>> cases = {
      {1.0, "1"}, {0.1, "0_1"}, {0.01, "0_01"}, {1e-3, "0_001"}, {1e-4, "0_0001"}, {1e-5, "0_00001"}, {1e-6, "0_000001"}};
  return cases;
}

/// (u, v) on 128 points from a file of one line per point, Re u, Im u, Re v, Im v (the
/// references' layout), at `path` under tests/data/rivals/.
inline Vector read_uv_file(const std::string& path) {
  std::ifstream in(std::string(TSI_TEST_SOURCE_DIR) + "/tests/data/rivals/" + path);
  REQUIRE(in);
  Vector uv(256);
  for (int j = 0; j < 128; ++j) {
    double ur, ui, vr, vi;
    in >> ur >> ui >> vr >> vi;
    REQUIRE(static_cast<bool>(in));
    uv(j) = Complex(ur, ui);
    uv(128 + j) = Complex(vr, vi);
  }
  return uv;
}

/// (u, v) on the 128-point grid from the reference file of `name`.
inline Vector micromacro_reference(const std::string& name) {
  return read_uv_file("micromacro-cos-sin/donnee_" + name + ".txt");
}

}  // namespace tsi::test
