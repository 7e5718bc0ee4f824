// vlasov-poisson-2d: N charged particles in a periodic box and a uniform strong magnetic field,
// coupled through the electric field they create (SPEC.md section 7; the uniformly accurate
// particle-in-cell method of Chartier, Crouseilles, Lemou, Mehats and Zhao):
//     x_k' = v_k,   v_k' = (1/eps) J v_k + E(x_k),   J v = (v2, -v1),
// E = -grad phi, -lap phi = rho - mean(rho), rho deposited from the particles. In tsi's class
// A = diag(0, J) per particle (e^{A tau} turns v by R(tau) = exp(tau J)) and f = (v, E(x)); the
// state holds (x1, x2, v1, v2) of particle k at entries 4k .. 4k + 3. f_tau on the tau grid
// is one deposition, one Poisson solve and one interpolation per tau point: with v = R(tau) y,
// f_tau(x, y) = (R(tau) y, R(-tau) E(x)).
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>

#include "particles.hpp"
#include "pic_field.hpp"
#include "tsi/error.hpp"
#include "tsi/memory.hpp"
#include "tsi/model.hpp"
#include "tsi/params.hpp"
#include "tsi/plugin.hpp"
#if defined(TSI_WITH_CUDA)
#include "pic_device.hpp"
#include "tsi/device_kernels.hpp"
#include "tsi/spectral_grid.hpp"
#endif

namespace {

using tsi::Real;
using tsi::Index;
using tsi::MatrixRef;
using tsi::Vector;
using tsi::pic::Field;
using tsi::pic::Geometry;
using tsi::pic::ParticleLayout;

static_assert(std::endian::native == std::endian::little, "the peer's raw particle files are little-endian");

// A complex column read as doubles: the real part of entry 4k + c at 8k + 2c.
constexpr ParticleLayout complex_layout{8, 2};
constexpr ParticleLayout real_layout{4, 1};

// f_tau at one phase (cos, sin) for the particles of one column, given E at them:
// (R(tau) y, R(-tau) E) per particle (E is computed before, so out may be the column itself).
template <class Write>
void filtered_column(const Real* e, Index particles, const Real* u, ParticleLayout layout, Real c, Real s,
                     Write&& write) {
  const Index ps = layout.particle_stride, cs = layout.component_stride;
  for (Index k = 0; k < particles; ++k) {
    const Real* p = u + k * ps;
    const Real y1 = p[2 * cs], y2 = p[3 * cs], e1 = e[2 * k], e2 = e[2 * k + 1];
    write(k, 0, c * y1 + s * y2);
    write(k, 1, -s * y1 + c * y2);
    write(k, 2, c * e1 - s * e2);
    write(k, 3, s * e1 + c * e2);
  }
}

// Which field a tau column's particles feel: the field of that column's own positions (the
// two-scale problem of the equation as written: one deposition and solve per tau point), or
// the field of the positions on the diagonal, U(t, t/eps), the particles' actual positions at
// t, frozen along tau (the UA-PIC codes': one deposition and solve per evaluation).
enum class TauField { per_tau, diagonal };

class VlasovPoisson2d final : public tsi::Model,
                              public tsi::FusedTauGrid,
                              public tsi::PhysicalVariables
#if defined(TSI_WITH_CUDA)
    , public tsi::DeviceKernels
#endif
{
 public:
  VlasovPoisson2d(Real eps, Geometry geometry, TauField tau_field, tsi::RealVector particles,
                  const tsi::Collective* collective)
      : Model(eps), g_(geometry), tau_field_(tau_field), u0_(std::move(particles)), collective_(collective) {}

  const tsi::FusedTauGrid* fused_tau_grid() const override { return this; }
  const tsi::PhysicalVariables* physical_variables() const override { return this; }

  Index dim() const override { return 4 * g_.particles; }
  bool is_complex() const override { return false; }

  void linear_flow(const tsi::RealVector& taus, MatrixRef u) const override {
    for (Index j = 0; j < u.cols(); ++j) {
      const Real c = std::cos(taus(j)), s = std::sin(taus(j));
      for (Index k = 0; k < g_.particles; ++k) {
        const Real v1 = u(4 * k + 2, j).real(), v2 = u(4 * k + 3, j).real();
        u(4 * k + 2, j) = c * v1 + s * v2;
        u(4 * k + 3, j) = -s * v1 + c * v2;
      }
    }
  }

  void nonlinear_field(tsi::ConstMatrixRef u, MatrixRef out) const override {
    const std::lock_guard<std::mutex> lock(mutex_);
    Field& field = shared_field();
    // f = f_0 = (v, E(x)): the filtered column at tau = 0, where R(0) = I.
    for (Index j = 0; j < u.cols(); ++j) {
      const Real* column = reinterpret_cast<const Real*>(u.col(j).data());
      filtered_column(field.at_particles(column, complex_layout), g_.particles, column, complex_layout, 1.0, 0.0,
                      [&](Index k, int c, Real value) { out(4 * k + c, j) = value; });
    }
  }

  void apply_A(const Vector& u, Vector& out) const override {
    out.resize(u.size());
    for (Index k = 0; k < g_.particles; ++k) {
      out(4 * k) = out(4 * k + 1) = 0.0;
      out(4 * k + 2) = u(4 * k + 3);
      out(4 * k + 3) = -u(4 * k + 2);
    }
  }

  Vector initial_value() const override { return u0_.cast<tsi::Complex>(); }

  /// f_tau bound to a tau grid: its own field (buffers and transforms) and rotation tables.
  class GridField final : public tsi::TauGridField {
   public:
    GridField(const Geometry& g, TauField tau_field, const tsi::RealVector& taus, const tsi::Collective* collective)
        : g_(g), tau_field_(tau_field), field_(g, collective), cos_(taus.array().cos()), sin_(taus.array().sin()) {}
    void evaluate(MatrixRef u, MatrixRef out) override {
      for (Index j = 0; j < u.cols(); ++j) {
        const Real* column = reinterpret_cast<const Real*>(u.col(j).data());
        filtered_column(e_at(column, complex_layout), g_.particles, column, complex_layout, cos_(j), sin_(j),
                        [&](Index k, int c, Real value) { out(4 * k + c, j) = value; });
      }
    }
    bool evaluates_real() const override { return true; }
    bool in_place() const override { return true; }  // E is computed from every position first
    void evaluate_real(tsi::RealMatrixRef u, tsi::RealMatrixRef out) override {
      for (Index j = 0; j < u.cols(); ++j) {
        Real* o = out.col(j).data();
        filtered_column(e_at(u.col(j).data(), real_layout), g_.particles, u.col(j).data(), real_layout, cos_(j),
                        sin_(j), [o](Index k, int c, Real value) { o[4 * k + c] = value; });
      }
    }
    bool needs_diagonal() const override { return tau_field_ == TauField::diagonal; }
    void set_diagonal(const Vector& diagonal) override {
      diagonal_ = &diagonal;
      diagonal_solved_ = false;
    }
    // The diagonal's field is frozen along tau: each particle's f is then its own, 4 rows.
    Index independent_row_group() const override { return tau_field_ == TauField::diagonal ? 4 : 0; }
    void prepare_rows() override {
      solve_diagonal();
      field_.prepare_interpolation();
    }
    void evaluate_rows_real(tsi::RealMatrixRef values, Index) const override {
      constexpr Index chunk = 64;  // particles per interpolation: E for them on the stack
      Real e[2 * chunk];
      const Index particles = values.rows() / 4;
      for (Index k0 = 0; k0 < particles; k0 += chunk) {
        const Index m = std::min(chunk, particles - k0);
        // Where every column holds the same positions (the grid constant in tau that re-preparation
        // evaluates: e^{tau A} turns v alone), E is the same at every tau: interpolated once.
        const bool one_field = same_positions(values, 4 * k0, m);
        for (Index j = 0; j < values.cols(); ++j) {
          Real* u = values.col(j).data() + 4 * k0;
          if (j == 0 || !one_field) field_.interpolate_into(u, real_layout, m, e);
          filtered_column(e, m, u, real_layout, cos_(j), sin_(j), [u](Index k, int c, Real v) { u[4 * k + c] = v; });
        }
      }
    }

   private:
    // True when the m particles from row r0 on have bit for bit the positions of column 0 in
    // every column (a grid that varies in tau differs at its first particle: one comparison).
    static bool same_positions(tsi::RealMatrixRef values, Index r0, Index m) {
      for (Index j = 1; j < values.cols(); ++j)
        for (Index k = 0; k < m; ++k)
          for (Index c = 0; c < 2; ++c)
            if (std::bit_cast<std::uint64_t>(values(r0 + 4 * k + c, j)) !=
                std::bit_cast<std::uint64_t>(values(r0 + 4 * k + c, 0)))
              return false;
      return true;
    }
    void solve_diagonal() {
      if (!diagonal_) throw tsi::Error("vlasov-poisson-2d: the diagonal field was evaluated without the diagonal");
      if (!diagonal_solved_) {
        field_.solve(reinterpret_cast<const Real*>(diagonal_->data()), complex_layout);
        diagonal_solved_ = true;
      }
    }
    // E at the particles of one column: from their own field, or from the diagonal's.
    const Real* e_at(const Real* column, ParticleLayout layout) {
      if (tau_field_ == TauField::per_tau) return field_.at_particles(column, layout);
      solve_diagonal();
      return field_.interpolate(column, layout);
    }

    Geometry g_;
    TauField tau_field_;
    Field field_;
    tsi::RealVector cos_, sin_;
    const Vector* diagonal_ = nullptr;
    bool diagonal_solved_ = false;
  };
  std::unique_ptr<tsi::TauGridField> bind_tau_grid(const tsi::RealVector& taus) const override {
    return std::make_unique<GridField>(g_, tau_field_, taus, collective_);
  }

#if defined(TSI_WITH_CUDA)
  // f_tau on the device (pic_device.cu): each column's deposition, solve and interpolation, with
  // the host Field's wave numbers and weights.
  class DeviceField final : public tsi::DeviceTauGridField {
   public:
    explicit DeviceField(std::unique_ptr<pic_device::Kernels> kernels) : kernels_(std::move(kernels)) {}
    void evaluate(tsi::Complex* grid, Real scale) override { kernels_->evaluate(grid, scale); }

   private:
    std::unique_ptr<pic_device::Kernels> kernels_;
  };
  std::unique_ptr<tsi::DeviceTauGridField> bind_device_tau_grid(const tsi::RealVector& taus) const override {
    if (tau_field_ != TauField::per_tau)
      throw tsi::ConfigError("model.tau_field", "got \"diagonal\" with --device cuda; expected \"per-tau\"");
    if (collective_) throw tsi::Error("--device cuda: a split run's particles stay on the CPU");
    pic_device::Setup s;
    s.n_x = g_.n_x;
    s.n_y = g_.n_y;
    s.width = g_.shape == tsi::pic::Shape::cic ? 2 : 6;
    s.offset = g_.shape == tsi::pic::Shape::cic ? 0 : 2;
    s.particles = g_.particles;
    s.inverse_dx = 1.0 / g_.dx();
    s.inverse_dy = 1.0 / g_.dy();
    s.weight = g_.weight();
    s.inverse_cell = 1.0 / (g_.dx() * g_.dy());
    const tsi::SpectralGrid grid({g_.n_y, g_.n_x});  // as Field's: (n_y, n_x), x halved
    const Index half_x = g_.n_x / 2 + 1, half = half_x * g_.n_y;
    for (Index p = 0; p < half; ++p) {
      const int jy = static_cast<int>(p / half_x), ix = static_cast<int>(p % half_x);
      const Real k1 = g_.k_x * ix, k2 = g_.k_y * grid.wave_number(0, jy), k_squared = k1 * k1 + k2 * k2;
      s.k1.push_back(k1);
      s.k2.push_back(k2);
      s.inverse_k2.push_back(k_squared > 0.0 ? 1.0 / k_squared : 0.0);
    }
    const tsi::RealVector c = taus.array().cos(), sn = taus.array().sin();  // GridField's
    s.cos_tau.assign(c.data(), c.data() + c.size());
    s.sin_tau.assign(sn.data(), sn.data() + sn.size());
    return std::make_unique<DeviceField>(pic_device::make_kernels(s));
  }
#endif
  // Split over processes, the field's reductions must come in one order: one thread calls them.
  bool independent_tau_grid_bindings() const override { return !collective_; }
  /// The filtered problem's f_tau, phases per call: through the model's one field (a binding
  /// per call would plan its transforms every time).
  void filtered_field(const tsi::RealVector& taus, MatrixRef u, MatrixRef out) const override {
    const std::lock_guard<std::mutex> lock(mutex_);
    Field& field = shared_field();
    for (Index j = 0; j < u.cols(); ++j) {
      const Real* column = reinterpret_cast<const Real*>(u.col(j).data());
      filtered_column(field.at_particles(column, complex_layout), g_.particles, column, complex_layout,
                      std::cos(taus(j)), std::sin(taus(j)), [&](Index k, int c, Real value) { out(4 * k + c, j) = value; });
    }
  }

  // The physical variables are the model's; the state is an N x 4 array in files.
  Index physical_dim() const override { return dim(); }
  Vector from_physical(const Vector& x) const override { return x; }
  Vector to_physical(const Vector& u) const override { return u; }
  std::vector<Index> physical_shape() const override {
    return {g_.all_particles > 0 ? g_.all_particles : g_.particles, 4};  // the whole plasma's
  }
  Real error_norm(const Vector& x) const override {
    Real squares = x.squaredNorm();
    if (collective_) collective_->sum(&squares, 1);
    return std::sqrt(squares);
  }
  const tsi::Collective* processes() const override { return collective_; }
  // The state files keep positions in the box (a run carries them out unwrapped, and a file
  // farther out than a box length would be refused by check_positions).
  void canonicalize_physical(Vector& x) const override {
    const Real lengths[2] = {g_.length_x(), g_.length_y()};
    for (Index k = 0; k < x.size() / 4; ++k)
      for (int c = 0; c < 2; ++c) {
        Real p = x(4 * k + c).real();
        if (p >= 0.0 && p < lengths[c]) continue;
        p -= lengths[c] * std::floor(p / lengths[c]);
        x(4 * k + c) = p < lengths[c] ? p : 0.0;  // a rounding up to L is the box's 0
      }
  }

  std::vector<tsi::ModelInvariant> invariants() const override {
    const Geometry g = g_;
    const tsi::Collective* collective = collective_;  // sums over the processes of a split run
    const auto kinetic = [g, collective](const Vector& u) {
      Real sum = 0.0;
      for (Index k = 0; k < g.particles; ++k) sum += std::norm(u(4 * k + 2)) + std::norm(u(4 * k + 3));
      if (collective) collective->sum(&sum, 1);
      return 0.5 * g.weight() * sum;
    };
    return {
        {"W", "total energy: sum w |v|^2 / 2 + (1/2) int |E|^2 (conserved by the flow, by PIC up to grid heating)",
         [this, kinetic](const Vector& u) {
           const std::lock_guard<std::mutex> lock(mutex_);
           return kinetic(u) + field_of(u).field_energy();
         }},
        {"P", "|total momentum| |sum w v| (P turns with the field: R(t/eps) P(0))",
         [g, collective](const Vector& u) {
           Real p[2] = {0.0, 0.0};
           for (Index k = 0; k < g.particles; ++k) {
             p[0] += u(4 * k + 2).real();
             p[1] += u(4 * k + 3).real();
           }
           if (collective) collective->sum(p, 2);
           return g.weight() * std::hypot(p[0], p[1]);
         }},
        {"Q", "total charge int rho (|box|: the deposition loses nothing)",
         [this](const Vector& u) {
           const std::lock_guard<std::mutex> lock(mutex_);
           return field_of(u).charge();
         }},
        {"W_E", "electric energy (1/2) int |E|^2 (exchanged with the kinetic energy: Landau damping, instabilities)",
         [this](const Vector& u) {
           const std::lock_guard<std::mutex> lock(mutex_);
           return field_of(u).field_energy();
         },
         false}};
  }

 private:
  // The field of the calls that are not a tau-grid binding's (the filtered and direct
  // problems, the invariants), made once; callers hold mutex_.
  Field& shared_field() const {
    if (!field_) field_ = std::make_unique<Field>(g_, collective_);
    return *field_;
  }
  // The shared field solved for the positions of a model state (callers hold mutex_).
  Field& field_of(const Vector& u) const {
    Field& field = shared_field();
    field.solve(reinterpret_cast<const Real*>(u.data()), complex_layout);
    return field;
  }

  Geometry g_;
  TauField tau_field_;
  tsi::RealVector u0_;
  const tsi::Collective* collective_;  // the processes a split run's particles lie on, or null
  mutable std::mutex mutex_;
  mutable std::unique_ptr<Field> field_;
};

bool positive_even(const tsi::Json& v, long max) { return v.get<long>() >= 2 && v.get<long>() <= max && v.get<long>() % 2 == 0; }

void register_vlasov_poisson(tsi::Registry& registry) {
  tsi::ModelEntry entry;
  entry.info.name = "vlasov-poisson-2d";
  entry.info.aliases = {"pic"};
  entry.info.summary =
      "particle-in-cell Vlasov-Poisson plasma in a uniform strong magnetic field: N particles (x, v) in a periodic "
      "box, E from their charge on an n_x x n_y grid, dim 4 N";
  entry.info.params = {
      tsi::integer_or_string_param("particles", 256,
                                   "the number of particles to sample, or a file of particles: .npy (N x 4 float64: "
                                   "x1 x2 v1 v2) or the UA-PIC peer's raw layout (4 little-endian float64 each)")
          .check(
              [](const tsi::Json& v) {
                if (v.is_string()) return !v.get<std::string>().empty();
                return v.get<double>() >= 1 && v.get<double>() <= Real(1L << 28);
              },
              "a number of particles from 1 to 2^28, or a file name"),
      tsi::integer_param("n_x", 16, "grid points along x1 (even)")
          .check([](const tsi::Json& v) { return positive_even(v, 1L << 14); }, "an even integer from 2 to 16384"),
      tsi::integer_param("n_y", 16, "grid points along x2 (even)")
          .check([](const tsi::Json& v) { return positive_even(v, 1L << 14); }, "an even integer from 2 to 16384"),
      tsi::number_param("k_x", 0.5, "the box is [0, 2 pi / k_x) along x1").range(1e-6, 1e6),
      tsi::number_param("k_y", 1.0, "the box is [0, 2 pi / k_y) along x2").range(1e-6, 1e6),
      tsi::string_param("shape", "m6",
                        "the shape function of deposition and interpolation: m6 (quintic spline, 6 x 6 nodes, the "
                        "peer's) or cic (cloud in cell, 2 x 2)")
          .choices({"m6", "cic"}),
      tsi::string_param("distribution", "landau",
                        "sampled particles: landau (density 1 + alpha cos(k_x x1), Maxwellian v) or peer (1 + sin(x2) "
                        "+ alpha cos(k_x x1), two streams at v1 = +-2)")
          .choices({"landau", "peer"}),
      tsi::number_param("alpha", 0.05, "the density's perturbation").range(0.0, 1.0),
      tsi::integer_param("seed", 1, "the sampling's seed")
          .check([](const tsi::Json& v) { return v.get<long>() >= 0; }, "a non-negative integer"),
      tsi::string_param("tau_field", "per-tau",
                        "the field a two-scale tau column feels: per-tau (the field of the column's own positions, "
                        "a deposition and Poisson solve per tau point) or diagonal (the field of the particles' "
                        "positions at t, U(t, t/eps), frozen along tau: one solve per evaluation, the UA-PIC codes')")
          .choices({"per-tau", "diagonal"})};
  entry.default_n_tau = 16;
  entry.nonlinearity_degree = 0;  // E(x) is not a polynomial
  // A small plasma on a coarse grid: the orders of every scheme in seconds. The tau grid must
  // resolve E along a gyration (radius eps |v|) against the cell: n_tau = 16 does at eps = 0.1
  // on 8 x 8 cells, not on 16 x 16 (eab's error at h = 1/32 falls 3.4x when n_tau doubles).
  entry.verification = {{0.1, 0.01}, {4, 8, 16, 32}, {{"particles", 64}, {"n_x", 8}, {"n_y", 8}}};
  entry.create = [](const tsi::Params& p) {
    Geometry g;
    g.n_x = static_cast<int>(p.integer("n_x"));
    g.n_y = static_cast<int>(p.integer("n_y"));
    g.k_x = p.number("k_x");
    g.k_y = p.number("k_y");
    g.shape = p.string("shape") == "cic" ? tsi::pic::Shape::cic : tsi::pic::Shape::m6;
    // The particles come from model.particles alone, where their file is checked (shape, finite
    // values, positions, energies); model.u0 would replace them unchecked.
    if (p.has("u0")) {
      const tsi::Json& u0 = p.raw().at("u0");
      throw tsi::ConfigError(
          "model.u0",
          (u0.is_string() ? "got the file \"" + u0.get<std::string>() + "\""
                          : "got " + std::to_string(u0.is_array() ? u0.size() : 1) + " values") +
              ": vlasov-poisson-2d takes its initial particles from model.particles, not model.u0: give them there "
              "as a .npy file of shape (N, 4), x1 x2 v1 v2 per particle (a run's state.npy is one), "
              "and leave model.u0 out");
    }
    tsi::RealVector particles;
    const tsi::Json& given = p.raw().at("particles");
    if (given.is_string()) {
      particles = tsi::pic::read_particles(given.get<std::string>());
      g.particles = particles.size() / 4;
      tsi::pic::check_positions(particles, g, given.get<std::string>());
      tsi::pic::check_energies(particles, g, given.get<std::string>());
    } else {
      g.particles = static_cast<Index>(given.get<double>());
      // Sampled before the run sizes its state (n_tau such sets, checked next): refused here
      // when the particles alone do not fit, before they are allocated and sampled.
      tsi::check_allocation("model.particles", 32.0 * static_cast<double>(g.particles),
                            std::to_string(g.particles) +
                                " particles (x1 x2 v1 v2 in float64, sampled before the run's state of n_tau such sets)");
      const auto distribution =
          p.string("distribution") == "peer" ? tsi::pic::Distribution::peer : tsi::pic::Distribution::landau;
      particles = tsi::pic::sample_particles(g, distribution, p.number("alpha"), static_cast<std::uint64_t>(p.integer("seed")));
    }
    g.threads = p.context().tau_grid.threads;
    const TauField tau_field = p.string("tau_field") == "diagonal" ? TauField::diagonal : TauField::per_tau;
    // Split over processes (tsi run --split), this one keeps its contiguous block of particles.
    const tsi::Collective* collective = p.context().collective;
    if (collective) {
      const tsi::Share share = tsi::share_of(g.particles, collective->rank(), collective->size());
      if (g.particles < collective->size())  // refused by every process alike
        throw tsi::ConfigError("model.particles",
                               std::to_string(g.particles) + " particles cannot be split over " +
                                   std::to_string(collective->size()) +
                                   " processes; expected at least one particle per process");
      particles = tsi::RealVector(particles.segment(4 * share.first, 4 * share.count));
      g.all_particles = g.particles;
      g.particles = share.count;
    }
    return std::make_unique<VlasovPoisson2d>(p.number("eps"), g, tau_field, std::move(particles), collective);
  };
  registry.add_model(std::move(entry));
}

}  // namespace

TSI_PLUGIN("vlasov-poisson-2d", register_vlasov_poisson)
