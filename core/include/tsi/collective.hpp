#pragma once
#include <algorithm>
#include <memory>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

class FieldTransforms;
class SpectralGrid;

/// The processes one run is split over (a particle-in-cell run's particles over MPI ranks,
/// `mpirun -np P tsi run --split`): every process holds its part of the state, and these
/// reductions, which every process calls in the same order, make the few global numbers a run
/// decides on (the field's density, a fixed-point increment, an invariant) the same on all of
/// them. The core holds only this interface; the runner implements it over MPI.
class TSI_API Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// values[i] = the sum of values[i] over the processes (in place, the same result on all).
  virtual void sum(Real* values, Index n) const = 0;
  /// values[i] = the largest values[i] over the processes (in place).
  virtual void max(Real* values, Index n) const = 0;
  /// The processes' `local` vectors one after the other, in rank order, on rank 0 (an empty
  /// vector elsewhere).
  virtual RealVector gather(const RealVector& local) const = 0;
  /// Transforms of `columns` complex fields on `grid`, its first direction split over the
  /// processes in grid_slab's slabs: each process's buffer holds its slab, in both spaces (the
  /// transposes between are the transforms' own). Every process makes and executes them alike,
  /// in the same order. A Collective without them (the default) throws tsi::Error.
  virtual std::unique_ptr<FieldTransforms> slab_transforms(const SpectralGrid& grid, Index columns) const;
  /// Stops every process with exit code `code`: a failure on one of them, which the others,
  /// waiting in a reduction, would never learn of.
  [[noreturn]] virtual void abort(int code) const = 0;

  /// The sum of one number over the processes.
  Real sum(Real value) const {
    sum(&value, 1);
    return value;
  }
  /// True when `flag` holds on every process.
  bool all(bool flag) const {
    Real v = flag ? 0 : 1;
    max(&v, 1);
    return v == 0.0;
  }
};

/// The part of `count` items (particles) that process `rank` of `size` holds: [first, first + count).
struct Share {
  Index first = 0, count = 0;
};
/// Contiguous blocks in rank order, the first count % size of them one item longer.
inline Share share_of(Index count, int rank, int size) {
  const Index base = count / size, extra = count % size;
  return {rank * base + std::min<Index>(rank, extra), base + (rank < extra ? 1 : 0)};
}

}  // namespace tsi
