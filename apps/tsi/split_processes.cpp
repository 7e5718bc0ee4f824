#include "split_processes.hpp"

#include <cstdlib>
#include <initializer_list>

#include "tsi/error.hpp"

#ifdef TSI_WITH_MPI
#include <fftw3-mpi.h>
#include <fmt/format.h>
#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "tsi/spectral_grid.hpp"
#endif

namespace tsi::app {

#ifdef TSI_WITH_MPI
namespace {

// The build's Real as MPI sees it (a quad build refuses to split: MPI has no float128).
const MPI_Datatype mpi_real = std::is_same_v<Real, double> ? MPI_DOUBLE : MPI_LONG_DOUBLE;

// FFTW's MPI interface in the build's precision (libfftw3_mpi, libfftw3l_mpi; a quad build
// never splits, and FFTW has no MPI interface in quad).
#if !defined(TSI_PRECISION_QUAD)
#if defined(TSI_PRECISION_LONG_DOUBLE)
#define TSI_FFTW_MPI(name) fftwl_mpi_##name
#define TSI_FFTW_PLAIN(name) fftwl_##name
#else
#define TSI_FFTW_MPI(name) fftw_mpi_##name
#define TSI_FFTW_PLAIN(name) fftw_##name
#endif

// The slab transforms of a split run (Collective::slab_transforms): one FFTW MPI plan each
// way for one field. On the grid, equal blocks of the first direction (grid_slab's rows); in
// Fourier space, equal blocks of the second, transposed (FFTW_MPI_TRANSPOSED_OUT forward,
// FFTW_MPI_TRANSPOSED_IN back): a transform makes one all-to-all instead of the two that
// keeping the first direction's blocks in both spaces takes. The linear flow and the cubic term
// stay local either way. The columns go through the plans one at a time, via FFTW's own buffer,
// which holds the transposes' room too. Planned with FFTW_MEASURE. On 64^3 over 2 ranks a step
// took 0.217 s with estimated plans of the untransposed layout, 0.158 s measured, 0.146 s
// measured and transposed (docs/benchmarks/scaling.md). Measured plans may differ from run to
// run, and so may a split run's last bits (the answer is one rank's to 1e-12).
class MpiSlabTransforms final : public FieldTransforms {
 public:
  MpiSlabTransforms(const SpectralGrid& grid, Index columns, const GridSlab& slab, int processes)
      : points_(slab.points()), columns_(columns) {
    std::vector<ptrdiff_t> n(grid.shape().begin(), grid.shape().end());
    ptrdiff_t local_rows = 0, first_row = 0, local_columns = 0, first_column = 0;
    const auto block = static_cast<ptrdiff_t>(slab.rows), tblock = static_cast<ptrdiff_t>(slab.columns);
    const ptrdiff_t room = TSI_FFTW_MPI(local_size_many_transposed)(grid.dims(), n.data(), 1, block, tblock,
                                                                    MPI_COMM_WORLD, &local_rows, &first_row,
                                                                    &local_columns, &first_column);
    buffer_ = reinterpret_cast<Complex*>(TSI_FFTW_PLAIN(alloc_complex)(static_cast<size_t>(std::max<ptrdiff_t>(room, 1))));
    if (!buffer_) throw Error(fmt::format("--split: cannot allocate the slab transforms' {} values", room));
    auto* data = reinterpret_cast<TSI_FFTW_PLAIN(complex)*>(buffer_);
    plans_[0] = TSI_FFTW_MPI(plan_many_dft)(grid.dims(), n.data(), 1, block, tblock, data, data, MPI_COMM_WORLD,
                                            FFTW_FORWARD, FFTW_MEASURE | FFTW_MPI_TRANSPOSED_OUT);
    // Back from the transposed layout: its input's blocks are the second direction's (FFTW's
    // `block` is the input's first dimension, `tblock` the output's).
    plans_[1] = TSI_FFTW_MPI(plan_many_dft)(grid.dims(), n.data(), 1, tblock, block, data, data, MPI_COMM_WORLD,
                                            FFTW_BACKWARD, FFTW_MEASURE | FFTW_MPI_TRANSPOSED_IN);
    const bool planned = plans_[0] && plans_[1];
    if (!planned || local_rows != block || local_columns != tblock ||
        first_row != static_cast<ptrdiff_t>(slab.first_row) || first_column != static_cast<ptrdiff_t>(slab.first_column)) {
      release();
      throw Error(fmt::format("--split: FFTW could not plan the slab transforms of the grid {} over {} processes "
                              "({}; rows {} from {}, columns {} from {}, expected {} from {} and {} from {})",
                              grid.describe(), processes, planned ? "planned" : "no plan", local_rows, first_row,
                              local_columns, first_column, block, slab.first_row, tblock, slab.first_column));
    }
    data_.resize(points_, columns_);
    data_.setZero();
  }
  ~MpiSlabTransforms() override { release(); }
  MpiSlabTransforms(const MpiSlabTransforms&) = delete;
  MpiSlabTransforms& operator=(const MpiSlabTransforms&) = delete;

  Eigen::Map<Matrix> data() override { return Eigen::Map<Matrix>(data_.data(), points_, columns_); }
  void forward() override { execute(0); }
  void backward() override { execute(1); }
  Index columns() const override { return columns_; }

 private:
  void execute(int direction) {
    for (Index j = 0; j < columns_; ++j) {
      std::copy_n(data_.col(j).data(), points_, buffer_);
      TSI_FFTW_PLAIN(execute)(static_cast<TSI_FFTW_PLAIN(plan)>(plans_[direction]));
      std::copy_n(buffer_, points_, data_.col(j).data());
    }
  }
  void release() {
    for (void*& plan : plans_)
      if (plan) TSI_FFTW_PLAIN(destroy_plan)(static_cast<TSI_FFTW_PLAIN(plan)>(plan)), plan = nullptr;
    if (buffer_) TSI_FFTW_PLAIN(free)(buffer_), buffer_ = nullptr;
  }

  Index points_, columns_;
  Complex* buffer_ = nullptr;
  void* plans_[2] = {nullptr, nullptr};  // forward, backward
  Matrix data_;
};
#endif  // !TSI_PRECISION_QUAD

class MpiWorld final : public Collective {
 public:
  MpiWorld() {
    int provided = 0;  // the reductions come from the thread that called MPI_Init (tsi's main)
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
#if !defined(TSI_PRECISION_QUAD)
    TSI_FFTW_MPI(init)();
#endif
  }
  ~MpiWorld() override {
#if !defined(TSI_PRECISION_QUAD)
    TSI_FFTW_MPI(cleanup)();
#endif
    MPI_Finalize();
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void sum(Real* values, Index n) const override { reduce(values, n, MPI_SUM); }
  void max(Real* values, Index n) const override { reduce(values, n, MPI_MAX); }
  RealVector gather(const RealVector& local) const override {
    std::vector<int> counts(static_cast<size_t>(size_)), offsets(static_cast<size_t>(size_));
    const int count = checked_count(local.size());
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    Index total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[static_cast<size_t>(r)] = checked_count(total);
      total += counts[static_cast<size_t>(r)];
    }
    RealVector all(rank_ == 0 ? total : 0);
    MPI_Gatherv(local.data(), count, mpi_real, all.data(), counts.data(), offsets.data(), mpi_real, 0,
                MPI_COMM_WORLD);
    return all;
  }
#if !defined(TSI_PRECISION_QUAD)
  std::unique_ptr<FieldTransforms> slab_transforms(const SpectralGrid& grid, Index columns) const override {
    return std::make_unique<MpiSlabTransforms>(grid, columns, grid_slab(grid, this), size_);
  }
#endif
  [[noreturn]] void abort(int code) const override {
    std::fflush(stdout);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, code);
    std::abort();  // MPI_Abort does not return
  }

 private:
  // MPI counts are ints: a state of more than 2^31 - 1 values per call is refused, not truncated.
  static int checked_count(Index n) {
    if (n < 0 || n > INT_MAX)
      throw Error("--split: " + std::to_string(n) + " values in one MPI call, more than MPI's int counts hold");
    return static_cast<int>(n);
  }
  static void reduce(Real* values, Index n, MPI_Op op) {
    MPI_Allreduce(MPI_IN_PLACE, values, checked_count(n), mpi_real, op, MPI_COMM_WORLD);
  }
  int rank_ = 0, size_ = 1;
};

}  // namespace

std::unique_ptr<Collective> start_split_processes() {
  if (std::numeric_limits<Real>::digits > 64)
    throw ConfigError("--split", "this tsi is a quad build (TSI_PRECISION=quad), and MPI reduces no quadruple "
                                 "precision; split runs need a double or long-double build");
  return std::make_unique<MpiWorld>();
}
#else
std::unique_ptr<Collective> start_split_processes() {
  throw ConfigError("--split", "this tsi was built without MPI; install libopenmpi-dev and openmpi-bin and "
                               "rebuild (cmake finds MPI by itself) to split a run over ranks");
}
#endif

namespace {
int environment_number(std::initializer_list<const char*> names) {
  for (const char* name : names) {
    const char* value = std::getenv(name);
    if (value && std::atoi(value) >= 0) return std::atoi(value);
  }
  return 0;
}
}  // namespace

int launched_processes() { return environment_number({"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"}); }
int launched_rank() { return environment_number({"OMPI_COMM_WORLD_RANK", "PMI_RANK", "MPI_LOCALRANKID"}); }

}  // namespace tsi::app
