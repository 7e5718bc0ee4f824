#pragma once
#include <span>

#include "tsi/diagonal.hpp"
#include "tsi/export.hpp"
#include "tsi/types.hpp"

/// The device backend (CUDA, `TSI_WITH_CUDA`): a run's states on a GPU, the schemes unchanged.
///
/// A scheme holds host `Vector`s and combines them through tsi::algebra only. While a
/// `device::Scope` is open on a thread, every algebra function on that thread works on a device
/// copy of each vector instead, found by the vector's host address (OpenMP's and OpenACC's
/// present table): a vector the device has not seen is copied there on first use, and from
/// then on the device copy is the vector's value and the host copy is stale. The two-scale
/// nonlinearity runs there too (the tau transforms by cuFFT, the model's kernels through
/// tsi::DeviceKernels), so a step never leaves the device. Host code that reads a state's
/// entries in the scope opens a `HostView` first (the recorder, every output.every steps).
///
/// Built without CUDA, available() is false and opening a Scope throws tsi::Error.
namespace tsi::device {

/// True when this build has the CUDA backend.
TSI_API bool available();

/// The CUDA devices this process sees (0 without CUDA, a driver or a device).
TSI_API int device_count();

/// The device's name and memory ("NVIDIA H200, 139.8 GiB, 139.2 GiB free"), or why there is none.
TSI_API std::string describe();

/// The backend of the scope open on this thread, or null (then tsi::algebra works on the host).
/// Without CUDA no scope can open: null, inline, so that the algebra's test folds away.
class Backend;
#if defined(TSI_WITH_CUDA)
TSI_API Backend* current() noexcept;
#else
inline Backend* current() noexcept { return nullptr; }
#endif

/// Device memory in use by the scope open on this thread (its vectors), in bytes.
TSI_API double bytes_in_use();

/// A run's steps on the device: opened around tsi::integrate. On closing, the state `y` is
/// copied back to the host (also when the scope closes on an exception) and the device copies
/// of every vector are freed. A vector used in the scope is on the host again only through
/// a HostView or the closing. One scope per thread at a time; a Scope cannot be nested.
class TSI_API Scope {
 public:
  explicit Scope(Vector& y);
  ~Scope();
  Scope(const Scope&) = delete;
  Scope& operator=(const Scope&) = delete;

 private:
  Vector& y_;
  Backend* backend_;
};

/// Host code inside a scope: `v`'s host entries made current (copied back when the device
/// wrote it since), and the device set aside on this thread until the view closes, so that
/// what the host computes from v (read-back, invariants) stays on the host. Nothing when no
/// scope is open.
class TSI_API HostView {
 public:
  explicit HostView(const Vector& v);
  ~HostView();
  HostView(const HostView&) = delete;
  HostView& operator=(const HostView&) = delete;

 private:
  Backend* suspended_;
};

/// The device copy of v for reading (copied there on first use), or null for an empty vector.
TSI_API const Complex* read(const Vector& v);
/// The device copy of v for writing n entries (v resized on the host where it has another
/// size); the device's copy is v's value from here on.
TSI_API Complex* write(Vector& v, Index n);

/// tsi::algebra on the device (the same functions, one kernel each; algebra.hpp calls them
/// while a scope is open).
TSI_API void copy(const Vector& x, Vector& out);
TSI_API void set_zero(Index n, Vector& out);
TSI_API void axpby(Real a, const Vector& x, Real b, const Vector& y, Vector& out);
/// out = start + sum_j d_j . x_j, with each d_j a Diagonal (values(), run()) or, where
/// d_j is null, the real factor scalars[j]. start may be null.
TSI_API void linear_combination(const Vector* start, std::span<const Diagonal* const> d,
                                std::span<const Real> scalars, std::span<const Vector* const> x, Vector& out);
/// The same with per-entry coefficient vectors (the Vector overloads of the algebra).
TSI_API void vector_combination(const Vector* start, std::span<const Vector* const> d,
                                std::span<const Vector* const> x, Vector& out);
TSI_API bool all_finite(const Vector& x);
TSI_API Real inner(const Vector& x, const Vector& y);
TSI_API Real max_norm(const Vector& x);
/// max_i |next_i - x_i|^2 and max_i |next_i|^2 into m[0], m[1].
TSI_API void increment_maxima(const Vector& next, const Vector& x, Real m[2]);

}  // namespace tsi::device
