#pragma once
#include <array>
#include <utility>
#include <map>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include "tsi/context.hpp"
#include "tsi/export.hpp"
#include "tsi/params.hpp"
#include "tsi/types.hpp"

namespace tsi {

class Collective;

namespace detail {
class LeadingDirections;  // a large field's directions before the last, by FftBatch's blocks
}

/// The periodic grid of a pseudo-spectral model in 1, 2 or 3 dimensions: n_1 x .. x n_d points
/// on [0, 2 pi)^d, x = 2 pi (j_1 / n_1, .., j_d / n_d), each n_i even. A field on it is a
/// vector of points() values in C order (the last direction fastest: point (j_1, .., j_d) at
/// (j_1 n_2 + j_2) n_3 + j_3), as NumPy stores an (n_1, .., n_d) array; its Fourier
/// coefficients are stored the same way, index j along direction i holding the wave number
/// j for j < n_i/2 and j - n_i above (FFTW's order; the Nyquist index n_i/2 enters only through
/// m^2, as +-n_i/2). The geometry only: the transforms are GridTransforms.
class TSI_API SpectralGrid {
 public:
  /// `shape`: 1 to 3 even sizes, each at least 2 (a tsi::Error naming the direction otherwise).
  explicit SpectralGrid(std::vector<int> shape);

  int dims() const { return static_cast<int>(shape_.size()); }
  const std::vector<int>& shape() const { return shape_; }
  /// n_1 x .. x n_d.
  Index points() const { return points_; }
  /// The wave number of index j along direction i: j < n_i/2 ? j : j - n_i.
  int wave_number(int direction, int j) const;
  /// |m| along direction i at index j: min(j, n_i - j), 0 .. n_i/2 (the index into a table of
  /// anything that depends on m_i^2, as a phase e^{-i m_i^2 tau}).
  const std::vector<int>& folded(int direction) const { return folded_[static_cast<std::size_t>(direction)]; }
  /// |m|^2 = m_1^2 + .. + m_d^2 at every point, in the coefficients' order (the symbol of -lap).
  const RealVector& laplacian_symbol() const { return laplacian_; }
  /// The largest |m|^2, sum of (n_i/2)^2.
  Real max_laplacian_symbol() const;
  /// The 2/3 rule's mask: 1 where every |m_i| <= n_i / 3, 0 elsewhere.
  RealVector dealias_mask() const;
  /// x_i at index j: 2 pi j / n_i.
  Real coordinate(int direction, int j) const;
  /// Calls point(index, x) for every point in C order, x the point's coordinates (x_1 .. x_d).
  template <class Point>
  void for_each_point(Point&& point) const {
    std::array<int, 3> j{0, 0, 0};
    std::array<Real, 3> x{0.0, 0.0, 0.0};
    for (Index p = 0; p < points_; ++p) {
      for (int i = 0; i < dims(); ++i) x[static_cast<std::size_t>(i)] = coordinate(i, j[static_cast<std::size_t>(i)]);
      point(p, x);
      for (int i = dims() - 1; i >= 0; --i) {  // the next index, the last direction fastest
        if (++j[static_cast<std::size_t>(i)] < shape_[static_cast<std::size_t>(i)]) break;
        j[static_cast<std::size_t>(i)] = 0;
      }
    }
  }
  /// "16", "256 x 256", "64 x 64 x 64".
  std::string describe() const;

  /// Points of the half spectrum of a real field (RealGridTransforms): every wave number of
  /// the leading directions and 0 .. n_d/2 of the last, in C order.
  Index half_points() const { return points_ / shape_.back() * (shape_.back() / 2 + 1); }
  /// Where a full spectrum's coefficient (point p) is in the half spectrum of a real field:
  /// its index there, and whether the coefficient is the conjugate of the one stored (the last
  /// direction's index above n_d/2 holds the coefficient of -m).
  struct HalfIndex {
    Index at;
    bool conjugate;
  };
  std::vector<HalfIndex> full_to_half() const;
  /// For every point of the half spectrum: its index in the full spectrum (m) and that of -m.
  std::vector<std::array<Index, 2>> half_to_full() const;

 private:
  std::vector<int> shape_;
  Index points_ = 1;
  std::vector<std::vector<int>> folded_;
  RealVector laplacian_;
};

/// The part of a SpectralGrid that one process of a split run holds (tsi run --split).
///
/// On the grid (physical space): the indices [first_row, first_row + rows) of the first
/// direction, with every index of the others; in C order the contiguous points
/// [first_point(), first_point() + points()). In Fourier space (`transposed`): the indices
/// [first_column, first_column + columns) of the second direction, stored transposed, the second
/// direction slowest, then the first, then the third (FFTW_MPI_TRANSPOSED_OUT's layout: a
/// transform then makes one all-to-all, not two). fourier_point(q) is the whole grid's C-order
/// index of coefficient q held here. One process holds the whole grid, in C order in both spaces.
struct TSI_API GridSlab {
  Index first_row = 0, rows = 0, row_points = 0;  ///< row_points: the points of one index of the first direction
  bool transposed = false;                        ///< Fourier space in the transposed slabs (a split run)
  Index first_column = 0, columns = 0;            ///< the second direction's indices held in Fourier space
  Index n1 = 1, n2 = 1, n3 = 1;                   ///< the grid's shape (1 beyond its dims)
  Index first_point() const { return first_row * row_points; }
  Index points() const { return rows * row_points; }
  /// The whole grid's C-order index of the Fourier coefficient this process holds at q.
  Index fourier_point(Index q) const {
    if (!transposed) return first_point() + q;
    const Index j3 = q % n3, rest = q / n3, j1 = rest % n1, j2 = first_column + rest / n1;
    return (j1 * n2 + j2) * n3 + j3;
  }
};
/// The slab of `grid` this process holds: the whole grid without `split`, else rank r of P holds
/// the rows [r n_1 / P, (r + 1) n_1 / P) on the grid and the columns [r n_2 / P, (r + 1) n_2 / P)
/// in Fourier space. A ConfigError naming `model.dims` for a 1-D grid (FFTW's 1-D MPI transforms
/// change the layout between the spaces), `model.n_x` or `model.n_y` where there are more
/// processes than indices or the size is not a multiple of the processes.
TSI_API GridSlab grid_slab(const SpectralGrid& grid, const Collective* split);
/// `whole` (a value per point of the whole grid's Fourier coefficients, as the Laplacian's
/// symbol) at the coefficients `slab` holds, in their order.
TSI_API RealVector fourier_slab(const RealVector& whole, const GridSlab& slab);
/// Calls point(index, x) for every point of `slab` in C order, index counted from the slab's first
/// point and x the point's coordinates (x_1 .. x_d), as SpectralGrid::for_each_point does.
template <class Point>
void for_each_slab_point(const SpectralGrid& grid, const GridSlab& slab, Point&& point) {
  std::array<Real, 3> x{0.0, 0.0, 0.0};
  for (Index p = 0; p < slab.points(); ++p) {
    Index rest = slab.first_point() + p;  // the global index, its directions from the last
    for (int i = grid.dims() - 1; i >= 0; --i) {
      const int n = grid.shape()[static_cast<std::size_t>(i)];
      x[static_cast<std::size_t>(i)] = grid.coordinate(i, static_cast<int>(rest % n));
      rest /= n;
    }
    point(p, x);
  }
}

/// Transforms of columns() fields on a SpectralGrid (or on this process's slab of it), each way,
/// in place on a points x columns buffer, field j in column j. Sign convention FFTW's: forward
/// is sum_x a(x) e^{-i m.x}, backward sum_m a_m e^{+i m.x}, neither normalised, so
/// backward(forward(a)) = points a. GridTransforms on one process; on the slabs of a split
/// run, Collective::slab_transforms (FFTW's MPI transforms; every process calls them alike).
class TSI_API FieldTransforms {
 public:
  virtual ~FieldTransforms() = default;
  /// points x columns: column j is field j (grid values or Fourier coefficients).
  virtual Eigen::Map<Matrix> data() = 0;
  /// Unnormalised: sum_x a(x) e^{-i m.x}.
  virtual void forward() = 0;
  /// Unnormalised: sum_m a_m e^{+i m.x}.
  virtual void backward() = 0;
  /// Fields it transforms at once.
  virtual Index columns() const = 0;
  /// Work space of data()'s shape (a second grid, as a derivative needs), allocated on first use.
  Matrix& scratch();

 private:
  Matrix scratch_;
};

/// Batched transforms of `columns` fields on a whole SpectralGrid: one d-dimensional FFTW plan
/// each way over the whole batch. Owns its plans and buffer: a model binding its tau grid makes
/// one of its own (no locks between bindings); not synchronised itself.
class TSI_API GridTransforms final : public FieldTransforms {
 public:
  /// `fftw_threads`: FFTW's own threads for the batch (the run's Context::fft).
  GridTransforms(const SpectralGrid& grid, Index columns, ThreadLimit fftw_threads = {});
  ~GridTransforms();
  GridTransforms(const GridTransforms&) = delete;
  GridTransforms& operator=(const GridTransforms&) = delete;

  Eigen::Map<Matrix> data() override { return Eigen::Map<Matrix>(buffer_, points_, columns_); }
  void forward() override;
  void backward() override;
  Index columns() const override { return columns_; }

 private:
  void execute(int direction);
  Index points_, columns_;
  Complex* buffer_ = nullptr;
  std::unique_ptr<detail::LeadingDirections> leading_;  // a large multi-dimensional field: by direction
  void* plans_[2] = {nullptr, nullptr};                  // forward, backward
};

/// The transforms of `columns` fields on this process's part of `grid`: GridTransforms without
/// `split`, else the split run's slab transforms (grid_slab's slabs).
TSI_API std::unique_ptr<FieldTransforms> make_field_transforms(const SpectralGrid& grid, Index columns,
                                                               ThreadLimit fftw_threads, const Collective* split);

/// Real-to-complex transforms of `columns` real fields on a SpectralGrid: field j's values
/// (column j of points x columns) to its half spectrum (column j of half_points() x columns,
/// SpectralGrid::half_points' order) and back, FFTW's r2c and c2r, unnormalised as
/// GridTransforms: half the work and memory of complex transforms, for fields that are real on
/// the grid (Klein-Gordon's z). backward() reads the half spectrum as Hermitian (the imaginary
/// parts of self-conjugate modes are ignored) and overwrites it. Large multi-dimensional fields
/// go by direction as GridTransforms' do.
class TSI_API RealGridTransforms {
 public:
  RealGridTransforms(const SpectralGrid& grid, Index columns, ThreadLimit fftw_threads = {});
  ~RealGridTransforms();
  RealGridTransforms(const RealGridTransforms&) = delete;
  RealGridTransforms& operator=(const RealGridTransforms&) = delete;

  /// points x columns real values.
  Eigen::Map<RealMatrix> values() { return Eigen::Map<RealMatrix>(values_, points_, columns_); }
  /// half_points x columns coefficients.
  Eigen::Map<Matrix> spectrum() { return Eigen::Map<Matrix>(spectrum_, half_points_, columns_); }
  /// values -> spectrum (the values are kept).
  void forward();
  /// spectrum -> values (the spectrum is overwritten).
  void backward();
  /// A second set of values of the same shape (a derivative's z), allocated on first use.
  RealMatrix& scratch();
  Index columns() const { return columns_; }

 private:
  Index points_, half_points_, columns_;
  int n_last_;
  Real* values_ = nullptr;
  Complex* spectrum_ = nullptr;
  std::unique_ptr<detail::LeadingDirections> leading_;  // a large multi-dimensional field: by direction
  void* plans_[2] = {nullptr, nullptr};                  // r2c, c2r
  RealMatrix scratch_;
};

/// FieldTransforms for every batch size a model meets, planned on first use and kept: a run sees
/// two or three sizes (1 and n_tau, or a slice of n_tau), so nothing is planned inside a step
/// after the first call. With `split`, a split run's slab transforms (make_field_transforms).
/// Not synchronised: the model serialises its calls (the buffers are shared work space).
class TSI_API GridTransformsPool {
 public:
  GridTransformsPool(const SpectralGrid& grid, ThreadLimit fftw_threads = {}, const Collective* split = nullptr)
      : grid_(grid), fftw_threads_(fftw_threads), split_(split) {}
  FieldTransforms& get(Index columns);
  ThreadLimit fftw_threads() const { return fftw_threads_; }
  const Collective* split() const { return split_; }

 private:
  const SpectralGrid& grid_;
  ThreadLimit fftw_threads_;
  const Collective* split_;
  std::map<Index, std::unique_ptr<FieldTransforms>> batches_;
};

/// The parameters of a model on a SpectralGrid: `dims` (1, 2 or 3, default 1) and the points
/// per direction `n_x`, `n_y`, `n_z` (even, 2 .. 2^20; n_y and n_z default to n_x). `what`
/// says what a value on the grid is, for the documentation ("samples of u").
TSI_API ParamSchema spectral_grid_params(const std::string& what);
/// A plane wave a e^{i k.x} on a SpectralGrid, the data a model offers as `initial: "plane-wave"`.
struct TSI_API PlaneWave {
  Real amplitude = 1.0;
  std::array<int, 3> wave_vector{1, 0, 0};  ///< k, zero beyond the grid's dims
  /// |k|^2.
  Real k2() const;
  /// a e^{i k.x} at x.
  Complex at(const std::array<Real, 3>& x) const;
};
/// The parameters of a model's initial data on a SpectralGrid: `initial` (`default_name`,
/// described by `default_doc`, or "plane-wave"), `wave_vector` and `amplitude` (the plane wave's).
TSI_API ParamSchema initial_data_params(const std::string& default_name, const std::string& default_doc);
/// The plane wave a model's resolved parameters ask for, or none for the default data: a
/// ConfigError naming `model.wave_vector[i]` for a k_i that is no integer or not below n_i / 2
/// in magnitude, `model.wave_vector` for the wrong count, and either key where the data are not
/// the plane wave. Default k = (1, 0, 0), a = 1.
TSI_API std::optional<PlaneWave> plane_wave(const Params& params, const std::vector<int>& shape);

/// The grid's shape from a model's resolved parameters: a ConfigError naming `model.n_y` or
/// `model.n_z` where one is given beyond `dims`, or where the grid has more than 2^31 - 1 points.
TSI_API std::vector<int> spectral_grid_shape(const Params& params);

}  // namespace tsi
