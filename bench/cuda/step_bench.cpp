// tsi_cuda_bench: a two-scale NLS step on the device against the cuFFT bound and the CPU
// (TSI_WITH_CUDA; scripts/device-check.sh runs it).
//
//   tsi_cuda_bench [--n 1024] [--n-tau 32] [--steps 5] [--cpu-steps 1] [--threads T] [--json FILE]
//                  [--pic-particles N]
//   (--steps 0: the CPU's steps only, on a machine without a GPU)
//
// For SE1 and eab on the 2-D NLS of n x n points (eps = 0.1, the paper's data): the median
// time of a step on the device, and of the four batched transforms one evaluation of N makes
// (tau inverse, spatial inverse, spatial forward, tau forward) timed alone with the same plans:
// the cuFFT bound of a step is that times the step's evaluations of N. Then the same steps on
// the CPU (T threads), the relative difference of the states after two steps, and the device
// memory the run held. With --pic-particles N, the same for the particle-in-cell plasma of N
// particles (vlasov-poisson-2d, per-tau field, 64 x 64 grid, n_tau 16).
#include <cuda_runtime.h>
#include <cufft.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "tsi/algebra.hpp"
#include "tsi/assembly.hpp"
#include "tsi/device.hpp"
#include "tsi/error.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"

namespace {

using namespace tsi;
using Clock = std::chrono::steady_clock;

void check(cudaError_t s, const char* what) {
  if (s != cudaSuccess) throw Error(std::string(what) + ": " + cudaGetErrorString(s));
}
void check(cufftResult s, const char* what) {
  if (s != CUFFT_SUCCESS) throw Error(std::string(what) + ": cuFFT error " + std::to_string(static_cast<int>(s)));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct TransformTimes {
  double all = 0, tau = 0, space = 0;  // the four; the tau pair; the spatial pair (median seconds)
};

// The four transforms of one evaluation of N, alone: median seconds over `reps`, and of each pair.
TransformTimes transform_bound(int n, int n_tau, int reps) {
  const long long dim = static_cast<long long>(n) * n, size = dim * n_tau;
  cufftDoubleComplex* data = nullptr;
  check(cudaMalloc(&data, sizeof(cufftDoubleComplex) * static_cast<size_t>(size)), "cudaMalloc");
  {
    std::vector<cufftDoubleComplex> host(static_cast<size_t>(size));
    std::mt19937_64 g(7);
    std::normal_distribution<double> d;
    for (auto& z : host) z = {d(g), d(g)};  // random data: zeros can run faster
    check(cudaMemcpy(data, host.data(), sizeof(cufftDoubleComplex) * host.size(), cudaMemcpyHostToDevice), "upload");
  }
  cufftHandle tau = 0, space = 0;
  size_t work = 0;
  long long nt[1] = {n_tau}, ns[2] = {n, n};
  check(cufftCreate(&tau), "cufftCreate");
  check(cufftMakePlanMany64(tau, 1, nt, nt, dim, 1, nt, dim, 1, CUFFT_Z2Z, dim, &work), "tau plan");
  check(cufftCreate(&space), "cufftCreate");
  check(cufftMakePlanMany64(space, 2, ns, nullptr, 1, dim, nullptr, 1, dim, CUFFT_Z2Z, n_tau, &work), "space plan");
  cudaEvent_t a, b;
  check(cudaEventCreate(&a), "event");
  check(cudaEventCreate(&b), "event");
  const auto timed = [&](bool with_tau, bool with_space) {
    std::vector<double> times;
    for (int r = 0; r < reps + 2; ++r) {  // two warm-ups
      check(cudaEventRecord(a), "record");
      if (with_tau) check(cufftExecZ2Z(tau, data, data, CUFFT_INVERSE), "tau inverse");
      if (with_space) check(cufftExecZ2Z(space, data, data, CUFFT_INVERSE), "space inverse");
      if (with_space) check(cufftExecZ2Z(space, data, data, CUFFT_FORWARD), "space forward");
      if (with_tau) check(cufftExecZ2Z(tau, data, data, CUFFT_FORWARD), "tau forward");
      check(cudaEventRecord(b), "record");
      check(cudaEventSynchronize(b), "sync");
      float ms = 0;
      check(cudaEventElapsedTime(&ms, a, b), "elapsed");
      if (r >= 2) times.push_back(ms * 1e-3);
    }
    return median(times);
  };
  TransformTimes t;
  t.all = timed(true, true);
  t.tau = timed(true, false);
  t.space = timed(false, true);
  cufftDestroy(tau);
  cufftDestroy(space);
  cudaFree(data);
  return t;
}

struct Measured {
  double step = 0, evaluations_per_step = 0, difference = 0, device_bytes = 0, state_bytes = 0, cpu_step = 0;
  double nonlinear = 0, pass = 0;  // one evaluation of N; one algebra pass over three vectors
  long sweeps = 0;
};

Json nls_config(const std::string& scheme, int n, int n_tau) {
  return {{"model", {{"name", "nls"}, {"eps", 0.1}, {"dims", 2}, {"n_x", n}, {"n_y", n}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", n_tau}, {"initial_data_order", 2}}},
          {"scheme", {{"name", scheme}}}};
}

// The particle-in-cell plasma of the UA-PIC peer's data (SPEC.md section 7) at 2^20 particles
// on a 64 x 64 grid, each tau column with its own field (per-tau), the complex layout.
Json pic_config(const std::string& scheme, long particles, int n_tau) {
  return {{"model", {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}, {"particles", particles}, {"distribution", "peer"},
                     {"alpha", 0.5}, {"n_x", 64}, {"n_y", 64}, {"shape", "m6"}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", n_tau}, {"initial_data_order", 2}, {"real_layout", false}}},
          {"scheme", {{"name", scheme}}}};
}

Measured measure(Registry& registry, const Json& config, int steps, int cpu_steps, int threads) {
  AssemblyOptions options;
  options.context = Context::with_threads(threads, threads);
  Assembly a = assemble_config(config, registry, options);
  const double h = 0.01;
  const Vector y0 = a.reformulation->prepare(a.u0);
  Measured m;
  m.state_bytes = static_cast<double>(y0.size()) * sizeof(Complex);
  Vector after_two;
  if (steps > 0) {  // the device: two steps (eab's start-up, SE1's first guess), then `steps` timed
    size_t free0 = 0, free1 = 0, total = 0;
    check(cudaMemGetInfo(&free0, &total), "cudaMemGetInfo");
    Vector y = y0;
    Stepper& stepper = a.bind(h);
    stepper.reset();
    device::Scope scope(y);
    stepper.step(0, y);
    stepper.step(h, y);
    {
      device::HostView host(y);
      after_two = y;
    }
    std::vector<double> times;
    const long e0 = a.reformulation->evaluations();
    for (int k = 0; k < steps; ++k) {
      check(cudaDeviceSynchronize(), "sync");
      const auto t0 = Clock::now();
      stepper.step((k + 2) * h, y);
      check(cudaDeviceSynchronize(), "sync");
      times.push_back(seconds_since(t0));
    }
    m.evaluations_per_step = static_cast<double>(a.reformulation->evaluations() - e0) / steps;
    m.step = median(times);
    check(cudaMemGetInfo(&free1, &total), "cudaMemGetInfo");
    m.device_bytes = static_cast<double>(free0 - free1);
    // Where a step's time goes: one evaluation of N alone, and one pass of the algebra over
    // three vectors of the state's size (out = x + d . y, the implicit stage's sweep).
    Vector n_out = a.reformulation->new_state(), pass_out = a.reformulation->new_state();
    std::vector<double> n_times, pass_times;
    for (int k = 0; k < 7; ++k) {
      check(cudaDeviceSynchronize(), "sync");
      auto t0 = Clock::now();
      a.reformulation->nonlinear(0.0, y, n_out);
      check(cudaDeviceSynchronize(), "sync");
      if (k >= 2) n_times.push_back(seconds_since(t0));
      t0 = Clock::now();
      algebra::diagonal_multiply_add(y, a.reformulation->linear_multipliers(), n_out, pass_out);
      check(cudaDeviceSynchronize(), "sync");
      if (k >= 2) pass_times.push_back(seconds_since(t0));
    }
    m.nonlinear = median(n_times);
    m.pass = median(pass_times);
  }
  if (cpu_steps > 0) {  // the CPU: the same two steps (compared), then cpu_steps timed
    Vector y = y0;
    Stepper& stepper = a.bind(h);
    stepper.reset();
    stepper.step(0, y);
    stepper.step(h, y);
    if (after_two.size()) m.difference = (after_two - y).norm() / y.norm();
    std::vector<double> times;
    for (int k = 0; k < cpu_steps; ++k) {
      const auto t0 = Clock::now();
      stepper.step((k + 2) * h, y);
      times.push_back(seconds_since(t0));
    }
    m.cpu_step = median(times);
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  int n = 1024, n_tau = 32, steps = 5, cpu_steps = 1;
  long pic_particles = 0;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::string json_file;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--n") n = std::stoi(value);
    else if (flag == "--n-tau") n_tau = std::stoi(value);
    else if (flag == "--steps") steps = std::stoi(value);
    else if (flag == "--cpu-steps") cpu_steps = std::stoi(value);
    else if (flag == "--threads") threads = std::stoi(value);
    else if (flag == "--json") json_file = value;
    else if (flag == "--pic-particles") pic_particles = std::stol(value);
    else {
      std::fprintf(stderr, "tsi_cuda_bench: unknown flag %s\n", flag.c_str());
      return 2;
    }
  }
  try {
    Registry registry;
    PluginLoader loader(registry);
    register_core(registry);
    const char* dir = std::getenv("TSI_PLUGIN_DIR");
    loader.load_directory(dir ? dir : TSI_BENCH_PLUGIN_DIR);
    fmt::print("device: {}\n", steps > 0 ? device::describe() : "none (--steps 0: the CPU only)");
    const TransformTimes t = steps > 0 ? transform_bound(n, n_tau, 20) : TransformTimes{};
    const double bound = t.all;
    fmt::print("2-D NLS {} x {}, n_tau = {}: the four transforms of one evaluation of N take {:.3f} ms (the tau "
               "pair {:.3f} ms, the spatial pair {:.3f} ms; medians of 20)\n",
               n, n, n_tau, bound * 1e3, t.tau * 1e3, t.space * 1e3);
    Json out = {{"device", steps > 0 ? device::describe() : "none"}, {"n", n}, {"n_tau", n_tau},
                {"transforms_seconds", bound}, {"tau_transforms_seconds", t.tau},
                {"spatial_transforms_seconds", t.space}, {"cpu_threads", threads}, {"schemes", Json::object()}};
    fmt::print("{:<6} {:>10} {:>8} {:>12} {:>8} {:>12} {:>10} {:>12} {:>10}\n", "scheme", "step ms", "N/step",
               "bound ms", "x bound", "CPU step s", "CPU/GPU", "rel. diff", "GPU GiB");
    for (const std::string scheme : {"se1", "eab"}) {
      const Measured m = measure(registry, nls_config(scheme, n, n_tau), steps, cpu_steps, threads);
      const double step_bound = bound * m.evaluations_per_step;
      fmt::print("{:<6} {:>10.3f} {:>8.2f} {:>12.3f} {:>8.2f} {:>12.3f} {:>10.1f} {:>12.2e} {:>10.2f}\n", scheme,
                 m.step * 1e3, m.evaluations_per_step, step_bound * 1e3, step_bound > 0 ? m.step / step_bound : 0.0,
                 m.cpu_step, m.cpu_step > 0 && m.step > 0 ? m.cpu_step / m.step : 0.0, m.difference, m.device_bytes / 1073741824.0);
      out["schemes"][scheme] = {{"step_seconds", m.step},
                                {"evaluations_per_step", m.evaluations_per_step},
                                {"bound_seconds", step_bound},
                                {"cpu_step_seconds", m.cpu_step},
                                {"relative_difference_after_two_steps", m.difference},
                                {"nonlinear_seconds", m.nonlinear},
                                {"three_vector_pass_seconds", m.pass},
                                {"device_bytes", m.device_bytes},
                                {"state_bytes", m.state_bytes}};
    }
    if (pic_particles > 0) {
      fmt::print("particle-in-cell, {} particles, 64 x 64 grid, M6, n_tau = 16, per-tau field:\n", pic_particles);
      fmt::print("{:<6} {:>10} {:>8} {:>12} {:>10} {:>12} {:>10}\n", "scheme", "step ms", "N/step", "CPU step s",
                 "CPU/GPU", "rel. diff", "GPU GiB");
      for (const std::string scheme : {"se1", "eab"}) {
        const Measured m = measure(registry, pic_config(scheme, pic_particles, 16), steps, cpu_steps, threads);
        fmt::print("{:<6} {:>10.3f} {:>8.2f} {:>12.3f} {:>10.1f} {:>12.2e} {:>10.2f}\n", scheme, m.step * 1e3,
                   m.evaluations_per_step, m.cpu_step, m.cpu_step > 0 && m.step > 0 ? m.cpu_step / m.step : 0.0,
                   m.difference, m.device_bytes / 1073741824.0);
        out["pic"][scheme] = {{"particles", pic_particles},
                              {"step_seconds", m.step},
                              {"evaluations_per_step", m.evaluations_per_step},
                              {"cpu_step_seconds", m.cpu_step},
                              {"relative_difference_after_two_steps", m.difference},
                              {"nonlinear_seconds", m.nonlinear},
                              {"device_bytes", m.device_bytes},
                              {"state_bytes", m.state_bytes}};
      }
    }
    for (const auto& [name, r] : out["schemes"].items())
      fmt::print("{}: one evaluation of N {:.3f} ms, one pass over three vectors {:.3f} ms ({:.2f} TB/s)\n", name,
                 r["nonlinear_seconds"].get<double>() * 1e3, r["three_vector_pass_seconds"].get<double>() * 1e3,
                 r["three_vector_pass_seconds"].get<double>() > 0
                     ? 3 * r["state_bytes"].get<double>() / r["three_vector_pass_seconds"].get<double>() / 1e12
                     : 0.0);
    if (!json_file.empty()) {
      std::FILE* f = std::fopen(json_file.c_str(), "w");
      if (!f) throw Error("cannot write " + json_file);
      std::fputs((out.dump(2) + "\n").c_str(), f);
      std::fclose(f);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tsi_cuda_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
