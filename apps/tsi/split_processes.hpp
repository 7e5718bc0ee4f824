#pragma once
// `mpirun -np P tsi run CONFIG --split`: one run whose state is split over the MPI ranks (a
// particle-in-cell run's particles), each rank holding its share; the field's density, the
// fixed-point tests, the invariants and the error norms are reduced over the ranks
// (tsi::Collective), and rank 0 writes the files.
#include <memory>

#include "tsi/collective.hpp"

namespace tsi::app {

/// MPI initialised and the ranks of MPI_COMM_WORLD as a run's Collective (its destruction
/// finalises MPI); a ConfigError naming --split when this tsi was built without MPI.
std::unique_ptr<Collective> start_split_processes();

/// The number of processes an MPI launcher started this one among (Open MPI's, MPICH's or
/// Intel MPI's environment; 0 when not launched by one), without initialising MPI.
int launched_processes();
/// This process's rank among them (0 when not launched by one).
int launched_rank();

}  // namespace tsi::app
