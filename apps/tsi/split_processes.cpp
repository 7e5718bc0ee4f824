#include "split_processes.hpp"

#include <cstdlib>
#include <initializer_list>

#include "tsi/error.hpp"

#ifdef TSI_WITH_MPI
#include <mpi.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>
#endif

namespace tsi::app {

#ifdef TSI_WITH_MPI
namespace {

// The build's Real as MPI sees it (a quad build refuses to split: MPI has no float128).
const MPI_Datatype mpi_real = std::is_same_v<Real, double> ? MPI_DOUBLE : MPI_LONG_DOUBLE;

class MpiWorld final : public Collective {
 public:
  MpiWorld() {
    int provided = 0;  // the reductions come from the thread that called MPI_Init (tsi's main)
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiWorld() override { MPI_Finalize(); }

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
