#pragma once
// `mpirun -np P tsi run ... --split` for the split-run tests (test_split_mpi.cpp's particles,
// test_split_grid.cpp's spectral grids), and the comparisons of their files with one process's.
#ifdef TSI_TEST_MPIEXEC
#include <cmath>
#include <csignal>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "run_command.hpp"
#include "tsi/npy.hpp"

namespace tsi::test {

inline CommandResult split_run(int ranks, const std::vector<std::string>& args) {
  CommandEnv env = mpirun_env();
  env.send_signal = SIGTERM;  // a guard: the runs take a second; a hung mpirun is stopped
  env.signal_after_seconds = 300.0;
  std::vector<std::string> all = {"-np", std::to_string(ranks), "--oversubscribe", "--allow-run-as-root",
                                  TSI_TEST_RUNNER, "run"};
  all.insert(all.end(), args.begin(), args.end());
  all.push_back("--split");
  CommandResult r = run_command(TSI_TEST_MPIEXEC, all, env);
  // Once in a CI run, mpirun exited 1 within 0.03 s while another test launched mpirun, before
  // any rank had written a word: Open MPI's launcher, not tsi. Such a launch (nothing from tsi on
  // either stream) is tried once more, and said; anything tsi printed is judged as it is.
  // tsi speaks first in "tsi: " (an error) or a line starting "tsi " (a run's header); mpirun's
  // own messages may name the runner's path, which also holds "tsi".
  const bool tsi_spoke = r.err.find("tsi: ") != std::string::npos || r.out.rfind("tsi ", 0) == 0 ||
                         r.out.find("\ntsi ") != std::string::npos;
  if (r.exit_code != 0 && !tsi_spoke) {
    MESSAGE("mpirun failed to launch, tried again: " << r.describe());
    r = run_command(TSI_TEST_MPIEXEC, all, env);
  }
  return r;
}

// The largest difference of two arrays of .npy files, relative to the largest entry of the first.
inline double relative_difference(const fs::path& a, const fs::path& b) {
  const tsi::NpyArray x = tsi::read_npy(a.string()), y = tsi::read_npy(b.string());
  REQUIRE(x.header.shape == y.header.shape);
  return (x.values - y.values).cwiseAbs().maxCoeff() / x.values.cwiseAbs().maxCoeff();
}

// The numbers of invariants.csv's rows after the header.
inline std::vector<std::vector<double>> csv_rows(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace tsi::test
#endif
