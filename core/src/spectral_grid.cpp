#include "tsi/spectral_grid.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "fftw_planner.hpp"
#include "fftw_precision.hpp"
#include "tsi/collective.hpp"
#include "tsi/error.hpp"
#include "tsi/fft.hpp"
#include "tsi/memory.hpp"
#include "tsi/phase.hpp"

namespace tsi {

namespace detail {

// A large multi-dimensional field (from 4096 points) goes one direction at a time: the last
// (contiguous) by its own plan, the others here, through FftBatch's blocks of a few rows at a
// time (in cache): FFTW_ESTIMATE's plan for a whole 256 x 256 field walks it once per strided
// transform, 2.9 ms against 0.2 ms. Small fields and every 1-D grid: one batched plan. On one
// thread: FFTW's threads would split the strided plans (no blocks), slower here than one thread
// (125 ms against 62 at 256 x 256 x 32); a run's threads split its tau grid.
class LeadingDirections {
 public:
  static constexpr Index min_points = 4096;
  static bool used_for(const SpectralGrid& grid) { return grid.dims() > 1 && grid.points() >= min_points; }

  // The directions before the last of a field whose last direction holds `last_width` values
  // (n_d complex values, or n_d/2 + 1 of a real field's half spectrum).
  LeadingDirections(const std::vector<int>& shape, int last_width) {
    const std::size_t last = shape.size() - 1;
    points_ = last_width;
    for (std::size_t i = 0; i < last; ++i) points_ *= shape[i];
    for (std::size_t i = 0; i < last; ++i) {  // direction i: n_i points, stride and count the rest
      int inner = last_width;
      for (std::size_t k = i + 1; k < last; ++k) inner *= shape[k];
      batches_.push_back(std::make_unique<FftBatch>(shape[i], inner));
      slabs_.push_back(static_cast<Index>(shape[i]) * inner);  // the field is points / slab such slabs
    }
  }

  // The field at `field` along every leading direction, innermost first: forward (0) or backward (1).
  void transform(Complex* field, int direction) {
    for (std::size_t i = batches_.size(); i-- > 0;)
      for (Index at = 0; at < points_; at += slabs_[i]) batches_[i]->transform(field + at, field + at, direction);
  }

 private:
  Index points_ = 1;
  std::vector<std::unique_ptr<FftBatch>> batches_;
  std::vector<Index> slabs_;
};

}  // namespace detail

SpectralGrid::SpectralGrid(std::vector<int> shape) : shape_(std::move(shape)) {
  if (shape_.empty() || shape_.size() > 3)
    throw Error(fmt::format("SpectralGrid: {} directions given, expected 1, 2 or 3", shape_.size()));
  for (std::size_t i = 0; i < shape_.size(); ++i) {
    const int n = shape_[i];
    if (n < 2 || n % 2 != 0)
      throw Error(fmt::format("SpectralGrid: direction {} has {} points, expected an even number of at least 2", i + 1, n));
    if (points_ > std::numeric_limits<int>::max() / n)  // FFTW's plans count points in int
      throw Error(fmt::format("SpectralGrid: {} points exceed 2^31 - 1", describe()));
    points_ *= n;
    std::vector<int> folded(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) folded[static_cast<std::size_t>(j)] = std::min(j, n - j);
    folded_.push_back(std::move(folded));
  }
  laplacian_.resize(points_);
  // C order: the index of the last direction runs fastest.
  Index p = 0;
  const int n1 = shape_[0], n2 = dims() > 1 ? shape_[1] : 1, n3 = dims() > 2 ? shape_[2] : 1;
  for (int a = 0; a < n1; ++a)
    for (int b = 0; b < n2; ++b)
      for (int c = 0; c < n3; ++c, ++p) {
        const Real m1 = folded_[0][static_cast<std::size_t>(a)];
        const Real m2 = dims() > 1 ? folded_[1][static_cast<std::size_t>(b)] : 0.0;
        const Real m3 = dims() > 2 ? folded_[2][static_cast<std::size_t>(c)] : 0.0;
        laplacian_(p) = m1 * m1 + m2 * m2 + m3 * m3;
      }
}

int SpectralGrid::wave_number(int direction, int j) const {
  const int n = shape_[static_cast<std::size_t>(direction)];
  return 2 * j < n ? j : j - n;
}

Real SpectralGrid::max_laplacian_symbol() const {
  Real sum = 0;
  for (const int n : shape_) sum += 0.25 * n * n;
  return sum;
}

RealVector SpectralGrid::dealias_mask() const {
  RealVector mask(points_);
  Index p = 0;
  const int n1 = shape_[0], n2 = dims() > 1 ? shape_[1] : 1, n3 = dims() > 2 ? shape_[2] : 1;
  const auto kept = [&](int direction, int j) {
    return 3 * folded_[static_cast<std::size_t>(direction)][static_cast<std::size_t>(j)] <=
           shape_[static_cast<std::size_t>(direction)];
  };
  for (int a = 0; a < n1; ++a)
    for (int b = 0; b < n2; ++b)
      for (int c = 0; c < n3; ++c, ++p)
        mask(p) = kept(0, a) && (dims() < 2 || kept(1, b)) && (dims() < 3 || kept(2, c)) ? 1.0 : 0.0;
  return mask;
}

Real SpectralGrid::coordinate(int direction, int j) const {
  return two_pi * static_cast<Real>(j) / shape_[static_cast<std::size_t>(direction)];
}

std::string SpectralGrid::describe() const {
  std::string text;
  for (std::size_t i = 0; i < shape_.size(); ++i) text += (i ? " x " : "") + std::to_string(shape_[i]);
  return text;
}

std::vector<SpectralGrid::HalfIndex> SpectralGrid::full_to_half() const {
  const int n_last = shape_.back(), half = n_last / 2 + 1;
  std::vector<HalfIndex> map(static_cast<std::size_t>(points_));
  std::array<int, 3> j{0, 0, 0};
  const std::size_t last = shape_.size() - 1;
  for (Index p = 0; p < points_; ++p) {
    // The row of the leading directions' indices, of m or of -m.
    Index row = 0, mirrored_row = 0;
    for (std::size_t i = 0; i < last; ++i) {
      row = row * shape_[i] + j[i];
      mirrored_row = mirrored_row * shape_[i] + (shape_[i] - j[i]) % shape_[i];
    }
    const int jl = j[last];
    map[static_cast<std::size_t>(p)] = 2 * jl <= n_last ? HalfIndex{row * half + jl, false}
                                                        : HalfIndex{mirrored_row * half + (n_last - jl), true};
    for (std::size_t i = shape_.size(); i-- > 0;) {  // the next index, the last direction fastest
      if (++j[i] < shape_[i]) break;
      j[i] = 0;
    }
  }
  return map;
}

std::vector<std::array<Index, 2>> SpectralGrid::half_to_full() const {
  const int n_last = shape_.back(), half = n_last / 2 + 1;
  std::vector<std::array<Index, 2>> map;
  map.reserve(static_cast<std::size_t>(half_points()));
  const std::size_t last = shape_.size() - 1;
  std::array<int, 3> j{0, 0, 0};
  for (Index q = 0; q < half_points(); ++q) {
    Index full = 0, mirrored = 0;
    for (std::size_t i = 0; i <= last; ++i) {
      full = full * shape_[i] + j[i];
      mirrored = mirrored * shape_[i] + (shape_[i] - j[i]) % shape_[i];
    }
    map.push_back({full, mirrored});
    for (std::size_t i = shape_.size(); i-- > 0;) {  // the next index; the last one runs to n/2
      if (++j[i] < (i == last ? half : shape_[i])) break;
      j[i] = 0;
    }
  }
  return map;
}

GridTransforms::GridTransforms(const SpectralGrid& grid, Index columns, ThreadLimit fftw_threads)
    : points_(grid.points()), columns_(columns) {
  if (columns <= 0 || columns > std::numeric_limits<int>::max())
    throw Error(fmt::format("GridTransforms: {} columns, expected 1 to 2^31 - 1", columns));
  const auto values = static_cast<std::size_t>(points_) * static_cast<std::size_t>(columns_);
  const std::vector<int>& shape = grid.shape();
  if (detail::LeadingDirections::used_for(grid))  // by direction; the last one by the plans below
    leading_ = std::make_unique<detail::LeadingDirections>(shape, shape.back());
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  buffer_ = reinterpret_cast<Complex*>(TSI_FFTW(alloc_complex)(values));
  if (!buffer_)
    throw Error(fmt::format("GridTransforms: cannot allocate {} x {} complex values ({:.3g} GB)", grid.describe(),
                            columns, static_cast<double>(sizeof(Complex)) * static_cast<double>(values) / 1e9));
  if (detail::fftw_threads_ready())
    TSI_FFTW(plan_with_nthreads)(leading_ ? 1 : fftw_threads.for_size(static_cast<Index>(values)));
  auto* data = reinterpret_cast<TSI_FFTW(complex)*>(buffer_);
  const int signs[2] = {FFTW_FORWARD, FFTW_BACKWARD};
  for (int d = 0; d < 2; ++d) {
    if (leading_) {  // the last direction of one field: points / n_last rows of n_last
      const int n_last = shape.back();
      plans_[d] = TSI_FFTW(plan_many_dft)(1, &n_last, static_cast<int>(points_ / n_last), data, nullptr, 1, n_last, data,
                                     nullptr, 1, n_last, signs[d], FFTW_ESTIMATE);
    } else {
      const int dist = static_cast<int>(points_);  // checked against int by SpectralGrid
      plans_[d] = TSI_FFTW(plan_many_dft)(grid.dims(), shape.data(), static_cast<int>(columns_), data, nullptr, 1, dist,
                                     data, nullptr, 1, dist, signs[d], FFTW_ESTIMATE);
    }
  }
  if (detail::fftw_threads_ready()) TSI_FFTW(plan_with_nthreads)(1);
  if (!plans_[0] || !plans_[1]) {
    for (void* plan : plans_)
      if (plan) TSI_FFTW(destroy_plan)(static_cast<TSI_FFTW(plan)>(plan));
    TSI_FFTW(free)(buffer_);
    throw Error(fmt::format("GridTransforms: FFTW could not plan {} x {} transforms", grid.describe(), columns));
  }
  std::fill(buffer_, buffer_ + values, Complex(0.0));
}

GridTransforms::~GridTransforms() {
  leading_.reset();  // before the lock: FftBatch takes it itself
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  for (void* plan : plans_)
    if (plan) TSI_FFTW(destroy_plan)(static_cast<TSI_FFTW(plan)>(plan));
  TSI_FFTW(free)(buffer_);
}

void GridTransforms::execute(int direction) {
  auto* plan = static_cast<TSI_FFTW(plan)>(plans_[direction]);
  if (!leading_) return TSI_FFTW(execute)(plan);
  // Every column has the buffer's alignment (points_ even, 16-byte complex values).
  for (Index j = 0; j < columns_; ++j) {
    Complex* field = buffer_ + j * points_;
    TSI_FFTW(execute_dft)(plan, reinterpret_cast<TSI_FFTW(complex)*>(field), reinterpret_cast<TSI_FFTW(complex)*>(field));
    leading_->transform(field, direction);
  }
}

void GridTransforms::forward() { execute(0); }
void GridTransforms::backward() { execute(1); }

Matrix& FieldTransforms::scratch() {
  if (scratch_.size() == 0) scratch_.resize(data().rows(), columns());
  return scratch_;
}

GridSlab grid_slab(const SpectralGrid& grid, const Collective* split) {
  const Index rows = grid.shape().front();
  GridSlab slab{0, rows, grid.points() / rows};
  if (!split) return slab;
  const int processes = split->size();
  if (grid.dims() == 1)
    throw ConfigError("model.dims", fmt::format("got 1 with --split over {} processes; expected 2 or 3: a grid is "
                                                "split in slabs of its first direction, and a 1-D grid has no "
                                                "second direction to keep whole",
                                                processes));
  if (rows < processes)
    throw ConfigError("model.n_x", fmt::format("got {} with --split over {} processes; expected at least one slab "
                                               "(an index of the first direction) per process: n_x >= {}, or at "
                                               "most {} processes",
                                               rows, processes, processes, rows));
  if (rows % processes != 0)
    throw ConfigError("model.n_x", fmt::format("got {} with --split over {} processes; expected a multiple of {}: "
                                               "the slabs are equal (n_x / processes indices of the first "
                                               "direction each)",
                                               rows, processes, processes));
  const Index columns = grid.shape()[1];
  if (columns < processes || columns % processes != 0)
    throw ConfigError("model.n_y", fmt::format("got {} with --split over {} processes; expected a multiple of {}: "
                                               "in Fourier space each process holds n_y / processes indices of "
                                               "the second direction",
                                               columns, processes, processes));
  slab.rows = rows / processes;
  slab.first_row = slab.rows * split->rank();
  slab.transposed = true;
  slab.columns = columns / processes;
  slab.first_column = slab.columns * split->rank();
  slab.n1 = rows;
  slab.n2 = columns;
  slab.n3 = grid.dims() == 3 ? grid.shape()[2] : 1;
  return slab;
}

RealVector fourier_slab(const RealVector& whole, const GridSlab& slab) {
  RealVector mine(slab.points());
  for (Index q = 0; q < slab.points(); ++q) mine(q) = whole(slab.fourier_point(q));
  return mine;
}

std::unique_ptr<FieldTransforms> Collective::slab_transforms(const SpectralGrid& grid, Index /*columns*/) const {
  throw Error(fmt::format("the processes of this split run have no slab transforms for the grid {} (a Collective "
                          "without FFTW's MPI transforms)",
                          grid.describe()));
}

std::unique_ptr<FieldTransforms> make_field_transforms(const SpectralGrid& grid, Index columns,
                                                       ThreadLimit fftw_threads, const Collective* split) {
  if (split) return split->slab_transforms(grid, columns);
  return std::make_unique<GridTransforms>(grid, columns, fftw_threads);
}

RealGridTransforms::RealGridTransforms(const SpectralGrid& grid, Index columns, ThreadLimit fftw_threads)
    : points_(grid.points()), half_points_(grid.half_points()), columns_(columns), n_last_(grid.shape().back()) {
  if (columns <= 0 || columns > std::numeric_limits<int>::max())
    throw Error(fmt::format("RealGridTransforms: {} columns, expected 1 to 2^31 - 1", columns));
  const std::vector<int>& shape = grid.shape();
  const int half = n_last_ / 2 + 1;
  if (detail::LeadingDirections::used_for(grid))  // the half spectrum's, complex; the last by the plans below
    leading_ = std::make_unique<detail::LeadingDirections>(shape, half);
  const auto n_values = static_cast<std::size_t>(points_) * static_cast<std::size_t>(columns_);
  const auto n_coefficients = static_cast<std::size_t>(half_points_) * static_cast<std::size_t>(columns_);
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  values_ = detail::tsi_real(TSI_FFTW(alloc_real)(n_values));
  spectrum_ = reinterpret_cast<Complex*>(TSI_FFTW(alloc_complex)(n_coefficients));
  const auto release = [this] {
    for (void* plan : plans_)
      if (plan) TSI_FFTW(destroy_plan)(static_cast<TSI_FFTW(plan)>(plan));
    if (values_) TSI_FFTW(free)(values_);
    if (spectrum_) TSI_FFTW(free)(spectrum_);
  };
  if (!values_ || !spectrum_) {
    release();
    throw Error(fmt::format("RealGridTransforms: cannot allocate {} x {} real values ({:.3g} GB)", grid.describe(),
                            columns, static_cast<double>(sizeof(Complex)) * static_cast<double>(n_values) / 1e9));
  }
  if (detail::fftw_threads_ready())
    TSI_FFTW(plan_with_nthreads)(leading_ ? 1 : fftw_threads.for_size(static_cast<Index>(n_values)));
  auto* out = reinterpret_cast<TSI_FFTW(complex)*>(spectrum_);
  if (leading_) {  // the last direction of one field: its rows
    const int rows = static_cast<int>(points_ / n_last_);
    plans_[0] = TSI_FFTW(plan_many_dft_r2c)(1, &n_last_, rows, detail::fftw_real(values_), nullptr, 1, n_last_, out, nullptr, 1, half,
                                       FFTW_ESTIMATE);
    plans_[1] = TSI_FFTW(plan_many_dft_c2r)(1, &n_last_, rows, out, nullptr, 1, half, detail::fftw_real(values_), nullptr, 1, n_last_,
                                       FFTW_ESTIMATE);
  } else {
    const int dist_values = static_cast<int>(points_), dist_spectrum = static_cast<int>(half_points_);
    plans_[0] = TSI_FFTW(plan_many_dft_r2c)(grid.dims(), shape.data(), static_cast<int>(columns_), detail::fftw_real(values_), nullptr, 1,
                                       dist_values, out, nullptr, 1, dist_spectrum, FFTW_ESTIMATE);
    plans_[1] = TSI_FFTW(plan_many_dft_c2r)(grid.dims(), shape.data(), static_cast<int>(columns_), out, nullptr, 1,
                                       dist_spectrum, detail::fftw_real(values_), nullptr, 1, dist_values, FFTW_ESTIMATE);
  }
  if (detail::fftw_threads_ready()) TSI_FFTW(plan_with_nthreads)(1);
  if (!plans_[0] || !plans_[1]) {
    release();
    throw Error(fmt::format("RealGridTransforms: FFTW could not plan {} x {} transforms", grid.describe(), columns));
  }
  std::fill(values_, values_ + n_values, Real(0));
  std::fill(spectrum_, spectrum_ + n_coefficients, Complex(0.0));
}

RealGridTransforms::~RealGridTransforms() {
  leading_.reset();  // before the lock: FftBatch takes it itself
  std::lock_guard<std::mutex> lock(detail::fftw_planner_mutex());
  for (void* plan : plans_)
    if (plan) TSI_FFTW(destroy_plan)(static_cast<TSI_FFTW(plan)>(plan));
  TSI_FFTW(free)(values_);
  TSI_FFTW(free)(spectrum_);
}

void RealGridTransforms::forward() {
  auto* plan = static_cast<TSI_FFTW(plan)>(plans_[0]);
  if (!leading_) return TSI_FFTW(execute)(plan);
  for (Index j = 0; j < columns_; ++j) {
    Complex* field = spectrum_ + j * half_points_;
    // Columns keep the buffers' alignment: points_ even (doubles) and 16-byte complex values.
    TSI_FFTW(execute_dft_r2c)(plan, detail::fftw_real(values_ + j * points_), reinterpret_cast<TSI_FFTW(complex)*>(field));
    leading_->transform(field, 0);
  }
}

void RealGridTransforms::backward() {
  auto* plan = static_cast<TSI_FFTW(plan)>(plans_[1]);
  if (!leading_) return TSI_FFTW(execute)(plan);
  for (Index j = 0; j < columns_; ++j) {
    Complex* field = spectrum_ + j * half_points_;
    leading_->transform(field, 1);
    TSI_FFTW(execute_dft_c2r)(plan, reinterpret_cast<TSI_FFTW(complex)*>(field), detail::fftw_real(values_ + j * points_));
  }
}

RealMatrix& RealGridTransforms::scratch() {
  if (scratch_.size() == 0) scratch_.resize(points_, columns_);
  return scratch_;
}

FieldTransforms& GridTransformsPool::get(Index columns) {
  auto it = batches_.find(columns);
  if (it == batches_.end())
    it = batches_.emplace(columns, make_field_transforms(grid_, columns, fftw_threads_, split_)).first;
  return *it->second;
}

namespace {
bool even_size(const Json& v) {
  const long n = v.get<long>();
  return n >= 2 && n <= (1L << 20) && n % 2 == 0;
}
}  // namespace

ParamSchema spectral_grid_params(const std::string& what) {
  const std::string even = "an even integer in [2, 1048576]";
  return {
      integer_param("dims", 1, "dimension of the grid: 1, 2 or 3 (the torus [0, 2 pi)^dims)")
          .check([](const Json& v) { return v.get<long>() >= 1 && v.get<long>() <= 3; }, "1, 2 or 3"),
      integer_param("n_x", 16, "Fourier modes (grid points) in x; u0 is given as " + what + " on the grid")
          .check(even_size, even),
      integer_param("n_y", nullptr, "grid points in y (dims >= 2); default n_x").check(even_size, even),
      integer_param("n_z", nullptr, "grid points in z (dims = 3); default n_x").check(even_size, even)};
}

Real PlaneWave::k2() const {
  Real sum = 0;
  for (const int k : wave_vector) sum += static_cast<Real>(k) * k;
  return sum;
}

Complex PlaneWave::at(const std::array<Real, 3>& x) const {
  Real phase = 0;
  for (std::size_t i = 0; i < 3; ++i) phase += wave_vector[i] * x[i];
  return std::polar(amplitude, phase);
}

ParamSchema initial_data_params(const std::string& default_name, const std::string& default_doc) {
  return {string_param("initial", default_name,
                       "initial data: \"" + default_name + "\" (" + default_doc +
                           ") or \"plane-wave\" (amplitude e^{i k.x})")
              .choices({default_name, "plane-wave"}),
          array_param("wave_vector", "the plane wave's k, one integer per direction with |k_i| < n_i/2; default (1, 0, 0)"),
          number_param("amplitude", nullptr, "the plane wave's amplitude a; default 1")
              .check([](const Json& v) { return std::isfinite(v.get<double>()); }, "a finite number")};
}

std::optional<PlaneWave> plane_wave(const Params& p, const std::vector<int>& shape) {
  if (p.string("initial") != "plane-wave") {
    for (const char* key : {"wave_vector", "amplitude"})
      if (p.has(key))
        throw ConfigError(std::string("model.") + key, "is given, but model.initial is \"" + p.string("initial") +
                                                           "\" (it belongs to \"plane-wave\")");
    return std::nullopt;
  }
  PlaneWave wave;
  if (p.has("amplitude")) wave.amplitude = p.number("amplitude");
  if (!p.has("wave_vector")) return wave;
  const Json& k = p.raw().at("wave_vector");
  const std::size_t dims = shape.size();
  if (k.size() != dims)
    throw ConfigError("model.wave_vector",
                      fmt::format("got {}, expected {} integers (one per direction, dims = {})", k.dump(), dims, dims));
  wave.wave_vector = {0, 0, 0};
  for (std::size_t i = 0; i < dims; ++i) {
    const Json& v = k.at(i);
    const int n = shape[i];
    // Resolved on the grid: |k_i| < n_i / 2 (the Nyquist mode has no sign).
    if (!v.is_number_integer() || std::abs(v.get<long>()) >= n / 2)
      throw ConfigError(fmt::format("model.wave_vector[{}]", i),
                        fmt::format("got {}, expected an integer of magnitude below n/2 = {}", v.dump(), n / 2));
    wave.wave_vector[i] = static_cast<int>(v.get<long>());
  }
  return wave;
}

std::vector<int> spectral_grid_shape(const Params& params) {
  const int dims = static_cast<int>(params.integer("dims"));
  const int n_x = static_cast<int>(params.integer("n_x"));
  const char* names[3] = {"n_x", "n_y", "n_z"};
  std::vector<int> shape = {n_x};
  Index points = n_x;
  for (int i = 1; i < 3; ++i) {
    const bool given = params.has(names[i]);
    if (i >= dims) {
      if (given)
        throw ConfigError(std::string("model.") + names[i],
                          fmt::format("got {}, but dims = {}: the grid has no direction {}", params.integer(names[i]),
                                      dims, names[i] + 2));
      continue;
    }
    const int n = given ? static_cast<int>(params.integer(names[i])) : n_x;
    if (points > std::numeric_limits<int>::max() / n)
      throw ConfigError(std::string("model.") + names[i],
                        fmt::format("got {}{}: the grid would have more than 2^31 - 1 points", n,
                                    given ? "" : " (the default, n_x)"));
    points *= n;
    shape.push_back(n);
  }
  // The model holds u0 and a work grid of these points before the run sizes its state (whose
  // footprint is checked next): refused here, before either is allocated.
  check_allocation("model.n_x",
                   32.0 * static_cast<double>(points),
                   fmt::format("a grid of {} = {} points (the model's u0 and a work grid of complex values, before the "
                               "run's state of n_tau such grids)",
                               fmt::join(shape, " x "), points));
  return shape;
}

}  // namespace tsi
