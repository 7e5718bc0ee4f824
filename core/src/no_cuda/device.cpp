// tsi::device in a build without CUDA (TSI_WITH_CUDA=OFF): no scope can open (current() is
// null, inline in device.hpp), so the algebra never calls the functions below (each throws if
// it were).
#include "tsi/device.hpp"
#include "tsi/error.hpp"

namespace tsi::device {

class Backend {};

namespace {
[[noreturn]] void unavailable() {
  throw Error("--device cuda: this build of tsi has no CUDA backend (configure with -DTSI_WITH_CUDA=ON on a machine "
              "with the CUDA toolkit; docs/how-to/gpu.md)");
}
}  // namespace

bool available() { return false; }
int device_count() { return 0; }
std::string describe() { return "this build has no CUDA backend"; }
double bytes_in_use() { return 0.0; }

// (the members are read here so that compilers see them used: this build never opens a scope)
Scope::Scope(Vector& y) : y_(y), backend_(nullptr) { unavailable(); }
Scope::~Scope() { (void)y_, (void)backend_; }
HostView::HostView(const Vector&) : suspended_(nullptr) {}
HostView::~HostView() { (void)suspended_; }

const Complex* read(const Vector&) { unavailable(); }
Complex* write(Vector&, Index) { unavailable(); }
void copy(const Vector&, Vector&) { unavailable(); }
void set_zero(Index, Vector&) { unavailable(); }
void axpby(Real, const Vector&, Real, const Vector&, Vector&) { unavailable(); }
void linear_combination(const Vector*, std::span<const Diagonal* const>, std::span<const Real>,
                        std::span<const Vector* const>, Vector&) {
  unavailable();
}
void vector_combination(const Vector*, std::span<const Vector* const>, std::span<const Vector* const>, Vector&) {
  unavailable();
}
bool all_finite(const Vector&) { unavailable(); }
Real inner(const Vector&, const Vector&) { unavailable(); }
Real max_norm(const Vector&) { unavailable(); }
void increment_maxima(const Vector&, const Vector&, Real*) { unavailable(); }

}  // namespace tsi::device

#include "../reformulations/device_tau_grid.hpp"

namespace tsi {

std::unique_ptr<DeviceTauGrid> make_device_tau_grid(const Model&, const RealVector&, Index, int) {
  throw Error("--device cuda: this build of tsi has no CUDA backend");
}

}  // namespace tsi
