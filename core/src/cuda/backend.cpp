// The CUDA backend of tsi::device (tsi/device.hpp): the present table of one scope (host
// address -> device copy), the algebra's functions over it, and the host views.
#include <fmt/format.h>

#include <unordered_map>

#include "cuda_check.hpp"
#include "kernels.hpp"
#include "tsi/device.hpp"

namespace tsi::device {

/// A scope's device copies, by host address.
class Backend {
 public:
  Backend() {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess || count == 0)
      throw Error("--device cuda: no CUDA device is visible to this process (" + describe() + ")");
    TSI_CUDA(cudaMalloc(&scratch_, sizeof(double) * 2 * cuda::reduction_blocks));
    TSI_CUDA(cudaMallocHost(&host_scratch_, sizeof(double) * 2 * cuda::reduction_blocks));
  }
  ~Backend() {
    for (auto& [host, copy] : table_) cudaFree(copy.data);
    cudaFree(scratch_);
    cudaFreeHost(host_scratch_);
  }
  Backend(const Backend&) = delete;
  Backend& operator=(const Backend&) = delete;

  const Complex* read(const Vector& v) {
    if (v.size() == 0) return nullptr;
    Copy& c = find(v.data(), v.size(), true);
    return c.data;
  }
  Complex* write(Vector& v, Index n) {
    if (v.size() != n) v.resize(n);  // the host's storage, where the device copy is keyed
    if (n == 0) return nullptr;
    Copy& c = find(v.data(), n, false);
    c.device_newer = true;
    return c.data;
  }
  void to_host(const Vector& v) {
    auto it = table_.find(v.data());
    if (it == table_.end() || !it->second.device_newer || it->second.n != v.size()) return;
    TSI_CUDA(cudaMemcpyAsync(const_cast<Complex*>(v.data()), it->second.data, bytes(v.size()), cudaMemcpyDeviceToHost,
                             cudaStreamPerThread));
    TSI_CUDA(cudaStreamSynchronize(cudaStreamPerThread));
    it->second.device_newer = false;
  }
  double bytes_in_use() const {
    double total = 0;
    for (const auto& [host, copy] : table_) total += static_cast<double>(bytes(copy.n));
    return total;
  }
  double* scratch() { return scratch_; }
  double* host_scratch() { return host_scratch_; }

 private:
  struct Copy {
    Complex* data = nullptr;
    Index n = 0;
    bool device_newer = false;
  };
  static size_t bytes(Index n) { return sizeof(Complex) * static_cast<size_t>(n); }

  // The copy of the host storage at `host` (n entries), made on first sight (copied there when
  // `upload`). A copy of another size belongs to storage the host freed and reused: replaced.
  Copy& find(const Complex* host, Index n, bool upload) {
    auto it = table_.find(host);
    if (it != table_.end() && it->second.n != n) {
      cudaFree(it->second.data);
      table_.erase(it);
      it = table_.end();
    }
    if (it != table_.end()) return it->second;
    Copy c;
    c.n = n;
    size_t free_bytes = 0, total_bytes = 0;
    TSI_CUDA(cudaMemGetInfo(&free_bytes, &total_bytes));
    if (bytes(n) > free_bytes)
      throw Error(fmt::format("--device cuda: a vector of {} values ({:.3g} GiB) does not fit in the device's free "
                              "memory ({:.3g} GiB of {:.3g} GiB; this run holds {:.3g} GiB there already)",
                              n, static_cast<double>(bytes(n)) / 1073741824.0, static_cast<double>(free_bytes) / 1073741824.0,
                              static_cast<double>(total_bytes) / 1073741824.0, bytes_in_use() / 1073741824.0));
    TSI_CUDA(cudaMalloc(&c.data, bytes(n)));
    if (upload)
      TSI_CUDA(cudaMemcpyAsync(c.data, host, bytes(n), cudaMemcpyHostToDevice, cudaStreamPerThread));
    return table_.emplace(host, c).first->second;
  }

  std::unordered_map<const Complex*, Copy> table_;
  double* scratch_ = nullptr;
  double* host_scratch_ = nullptr;
};

namespace {
thread_local Backend* current_backend = nullptr;

Backend& backend() {
  if (!current_backend) throw Error("tsi::device: no device scope is open on this thread");
  return *current_backend;
}
const double* raw(const Complex* p) { return reinterpret_cast<const double*>(p); }
double* raw(Complex* p) { return reinterpret_cast<double*>(p); }

// A combination of `terms` terms from `start` (null: none), its terms to fill.
cuda::Combination started(Backend& be, const Vector* start, size_t terms) {
  if (terms > static_cast<size_t>(cuda::max_terms))
    throw Error(fmt::format("tsi::device: a combination of {} terms (at most {} on the device)", terms,
                            cuda::max_terms));
  cuda::Combination c;
  c.start = start ? raw(be.read(*start)) : nullptr;
  c.count = static_cast<int>(terms);
  return c;
}

}  // namespace

bool available() { return true; }

int device_count() {
  int count = 0;
  return cudaGetDeviceCount(&count) == cudaSuccess ? count : 0;
}

std::string describe() {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) return std::string("no CUDA device: ") + cudaGetErrorString(status);
  if (count == 0) return "no CUDA device";
  int id = 0;
  cudaDeviceProp p{};
  if (cudaGetDevice(&id) != cudaSuccess || cudaGetDeviceProperties(&p, id) != cudaSuccess) return "a CUDA device";
  size_t free_bytes = 0, total_bytes = 0;
  cudaMemGetInfo(&free_bytes, &total_bytes);
  return fmt::format("{} (compute capability {}.{}, {} multiprocessors), {:.1f} GiB, {:.1f} GiB free", p.name, p.major,
                     p.minor, p.multiProcessorCount, static_cast<double>(total_bytes) / 1073741824.0,
                     static_cast<double>(free_bytes) / 1073741824.0);
}

Backend* current() noexcept { return current_backend; }

double bytes_in_use() { return current_backend ? current_backend->bytes_in_use() : 0.0; }

Scope::Scope(Vector& y) : y_(y), backend_(nullptr) {
  if (current_backend) throw Error("tsi::device::Scope: a device scope is already open on this thread");
  backend_ = new Backend();
  current_backend = backend_;
}

Scope::~Scope() {
  try {
    backend_->to_host(y_);
  } catch (...) {  // the state stays as the host last had it; the error was the step's to report
  }
  current_backend = nullptr;
  delete backend_;
}

HostView::HostView(const Vector& v) : suspended_(current_backend) {
  if (suspended_) suspended_->to_host(v);
  current_backend = nullptr;
}

HostView::~HostView() { current_backend = suspended_; }

const Complex* read(const Vector& v) { return backend().read(v); }
Complex* write(Vector& v, Index n) { return backend().write(v, n); }

void copy(const Vector& x, Vector& out) {
  if (&x == &out) return;
  Backend& b = backend();
  const Complex* from = b.read(x);
  Complex* to = b.write(out, x.size());
  if (x.size())
    TSI_CUDA(cudaMemcpyAsync(to, from, sizeof(Complex) * static_cast<size_t>(x.size()), cudaMemcpyDeviceToDevice,
                             cudaStreamPerThread));
}

void set_zero(Index n, Vector& out) {
  Complex* to = backend().write(out, n);
  if (n) TSI_CUDA(cudaMemsetAsync(to, 0, sizeof(Complex) * static_cast<size_t>(n), cudaStreamPerThread));
}

void axpby(Real a, const Vector& x, Real b, const Vector& y, Vector& out) {
  Backend& be = backend();
  cuda::Combination c;
  c.count = 2;
  c.terms[0] = {nullptr, a, 1, raw(be.read(x))};
  c.terms[1] = {nullptr, b, 1, raw(be.read(y))};
  cuda::combine(c, raw(be.write(out, x.size())), x.size());
}

void linear_combination(const Vector* start, std::span<const Diagonal* const> d, std::span<const Real> scalars,
                        std::span<const Vector* const> x, Vector& out) {
  Backend& be = backend();
  const Index n = start ? start->size() : x.front()->size();
  cuda::Combination c = started(be, start, x.size());
  for (size_t j = 0; j < x.size(); ++j) {
    cuda::Term& t = c.terms[j];
    t.x = raw(be.read(*x[j]));
    if (j < d.size() && d[j]) {
      t.d = raw(be.read(d[j]->values()));
      t.run = d[j]->run();
    } else {
      t.scalar = scalars[j];
    }
  }
  cuda::combine(c, raw(be.write(out, n)), n);
}

void vector_combination(const Vector* start, std::span<const Vector* const> d, std::span<const Vector* const> x,
                        Vector& out) {
  Backend& be = backend();
  const Index n = start ? start->size() : x.front()->size();
  cuda::Combination c = started(be, start, x.size());
  for (size_t j = 0; j < x.size(); ++j) c.terms[j] = {raw(be.read(*d[j])), 0.0, 1, raw(be.read(*x[j]))};
  cuda::combine(c, raw(be.write(out, n)), n);
}

bool all_finite(const Vector& x) {
  Backend& be = backend();
  return cuda::all_finite(raw(be.read(x)), x.size(), be.scratch(), be.host_scratch());
}

Real inner(const Vector& x, const Vector& y) {
  Backend& be = backend();
  return cuda::inner(raw(be.read(x)), raw(be.read(y)), x.size(), be.scratch(), be.host_scratch());
}

Real max_norm(const Vector& x) {
  Backend& be = backend();
  return std::sqrt(cuda::max_abs2(raw(be.read(x)), x.size(), be.scratch(), be.host_scratch()));
}

void increment_maxima(const Vector& next, const Vector& x, Real m[2]) {
  Backend& be = backend();
  cuda::increment_maxima(raw(be.read(next)), raw(be.read(x)), next.size(), m, be.scratch(), be.host_scratch());
}

}  // namespace tsi::device
