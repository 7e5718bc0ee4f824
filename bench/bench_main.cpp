// What a two-scale step costs, per model at the paper's sizes, against the FFTs it must do:
//   nonlinearity/<model>   one evaluation of f_tau over the whole tau grid (one sweep's work)
//   fft_bound/<model>      the transforms alone that one evaluation needs (back and forth)
//   step/<model>/<scheme>  one step at h = 1/8, eps = 0.01 (counters: fixed-point sweeps and
//                          evaluations of N per step)
//   step_eps/<model>/se1/<eps>  the same at eps = 1 and 1e-6: the cost must not depend on eps
//   nonlinearity_threads/<model>/2  the nonlinearity with FFTW on two threads (large NLS grids)
//   large/<case>/{nonlinearity,fft_bound,se1,eab}  the same at the sizes where the state
//                          dominates: NLS n_x = 8192 x n_tau 64 (complex), the synthetic real
//                          Henon-Heiles ensemble with 2^18 copies x n_tau 16 (the real layout);
//                          2-D NLS 256 x 256 x n_tau 32 and 3-D NLS 64^3 x n_tau 16 (se1 only)
//   tau_threads/<model>_ntau<M>/<T> one SE1 step (h = 1/8, eps = 0.01) with the tau grid split
//                                   over T threads (tsi --threads): Henon-Heiles and the charged
//                                   particle (4 x 64), NLS and Klein-Gordon n_x = 16 ... 1024
//                                   (n_x x 256), 2-D and 3-D NLS at the large sizes: the ratio
//                                   T = 1 / T = 2 per size sets the threshold
// Models and schemes come from the registry, so a new plugin is benchmarked without edits.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <string>

#include "tsi/assembly.hpp"
#include "tsi/fft.hpp"
#include "tsi/spectral_grid.hpp"
#include "tsi/real_fft.hpp"
#include "tsi/phase.hpp"
#include "tsi/plugin_loader.hpp"
#include "tsi/registry.hpp"
#include "tsi/context.hpp"

namespace {

struct Case {
  std::string model;
  tsi::Json model_params;
  int n_tau;
};

tsi::Registry& registry() {
  static tsi::Registry r;
  static const bool loaded = [] {
    tsi::register_core(r);
    tsi::PluginLoader loader(r);
    loader.load_directory(TSI_BENCH_PLUGIN_DIR);
    loader.load_directory(TSI_BENCH_MODEL_DIR);  // the synthetic models of the scale cases
    return true;
  }();
  (void)loaded;
  return r;
}

std::shared_ptr<const tsi::Model> make_model(const Case& c, double eps, const tsi::Context& context = {}) {
  const auto& e = registry().model(c.model);
  tsi::Json params = c.model_params;
  params["eps"] = eps;
  return e.create(tsi::Params(tsi::resolve_params(e.info.params, params, "model"), context));
}

std::unique_ptr<tsi::Reformulation> two_scale(std::shared_ptr<const tsi::Model> model, const Case& c, int order,
                                              const tsi::Context& context = {}) {
  const auto& e = registry().reformulation("two-scale");
  return e.create(std::move(model),
                  tsi::Params(tsi::resolve_params(e.info.params, {{"n_tau", c.n_tau}, {"initial_data_order", order}},
                                                  "bench"),
                              context));
}

void nonlinearity_in(benchmark::State& state, const Case& c, const tsi::Context& context) {
  auto model = make_model(c, 0.01, context);
  auto problem = two_scale(model, c, 2, context);
  const tsi::Vector y = problem->prepare(model->initial_value());
  tsi::Vector out(y.size());
  for (auto _ : state) {
    problem->nonlinear(0.0, y, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["unknowns"] = static_cast<double>(y.size());
}

void nonlinearity(benchmark::State& state, Case c) { nonlinearity_in(state, c, {}); }

// The same with FFTW splitting each large batch over `threads` threads (Context::fft).
void nonlinearity_threads(benchmark::State& state, Case c, int threads) {
  tsi::Context context;
  context.fft.threads = threads;
  nonlinearity_in(state, c, context);
}

void fft_bound(benchmark::State& state, Case c) {
  auto model = make_model(c, 0.01);
  if (!model->is_complex() && !model->has_linear_remainder() && model->dim() > 4) {
    // A large real model: the real layout's transforms, tau modes 0 .. n_tau/2.
    const int rows = static_cast<int>(model->dim());
    tsi::RealFftBatch tau(c.n_tau, rows);
    tsi::RealMatrix values = tsi::RealMatrix::Random(rows, c.n_tau);
    tsi::Matrix coefficients(rows, c.n_tau / 2 + 1);
    for (auto _ : state) {
      tau.forward_unnormalised(values.data(), coefficients.data());
      tau.backward(coefficients.data(), values.data());
      benchmark::DoNotOptimize(values.data());
    }
    return;
  }
  // The model's own transforms (NLS: in space) happen inside its field; count the tau ones
  // here, and the spatial ones by a batch of n_tau fields on the model's grid (its physical
  // shape: 1, 2 or 3 directions) when the model is a field (complex, dim > 4).
  tsi::FftBatch tau(c.n_tau, static_cast<int>(model->dim()));
  tau.data().setRandom();
  std::unique_ptr<tsi::GridTransforms> x;
  if (model->is_complex() && model->dim() > 4) {
    std::vector<int> shape;
    for (const tsi::Index n : model->physical_shape()) shape.push_back(static_cast<int>(n));
    x = std::make_unique<tsi::GridTransforms>(tsi::SpectralGrid(shape), c.n_tau);
    x->data().setRandom();
  }
  for (auto _ : state) {
    tau.backward();
    tau.forward();
    if (x) {
      x->backward();
      x->forward();
    }
    benchmark::DoNotOptimize(tau.data().data());
  }
}

void step_in(benchmark::State& state, const Case& c, const tsi::Json& scheme, double eps, const tsi::Context& context) {
  // The runner's assembler: every default completed as `tsi run` completes it (SE2's nodes).
  tsi::AssemblyOptions options;
  options.context = context;
  tsi::Json model_section = c.model_params;
  model_section["name"] = c.model;
  model_section["eps"] = eps;
  tsi::Assembly a = tsi::assemble_config({{"model", model_section},
                                          {"reformulation", {{"name", "two-scale"}, {"n_tau", c.n_tau}}},
                                          {"scheme", scheme}},
                                         registry(), options);
  tsi::Reformulation* problem = a.reformulation.get();
  const double h = 0.125;
  tsi::Stepper* stepper = &a.bind(h);
  const tsi::Vector y0 = problem->prepare(a.u0);
  tsi::Vector y = y0;
  long n = 0;
  for (auto _ : state) {
    stepper->step(tsi::step_time(n++, h), y);
    if (n == 64) {  // stay on a bounded trajectory
      state.PauseTiming();
      y = y0, n = 0;
      stepper->reset();
      state.ResumeTiming();
    }
  }
  const auto stats = stepper->stats();
  state.counters["sweeps"] = stats.solves ? stats.iterations_mean() : 0.0;
  // Evaluations of N per step (SE2: one per quadrature node and sweep): the FFT work a step must do.
  state.counters["evaluations"] = static_cast<double>(problem->evaluations()) / static_cast<double>(state.iterations());
}

void step(benchmark::State& state, Case c, tsi::Json scheme, double eps) { step_in(state, c, scheme, eps, {}); }

// One step with the tau grid on `threads` threads from the first size (threshold 1).
void step_tau_threads(benchmark::State& state, Case c, int threads) {
  tsi::Context context;
  context.tau_grid = {threads, 1};
  step_in(state, c, tsi::Json{{"name", "se1"}}, 0.01, context);
}

std::vector<Case> paper_cases() {
  std::vector<Case> cases;
  for (const auto* m : registry().models()) {
    const std::string& name = m->info.name;
    if (name == "henon-heiles" || name == "cpd") cases.push_back({name, tsi::Json::object(), 64});
    if (name == "nls")
      for (int n_x : {16, 64, 256}) cases.push_back({name, {{"n_x", n_x}}, 256});
  }
  return cases;
}

std::string label(const Case& c) {
  if (c.model_params.value("dims", 1) > 1) {
    const int n = c.model_params["n_x"].get<int>();
    return c.model + "_" + std::to_string(c.model_params["dims"].get<int>()) + "d_" + std::to_string(n) + "^" +
           std::to_string(c.model_params["dims"].get<int>());
  }
  if (c.model_params.contains("copies")) return c.model + "_" + c.model_params["copies"].dump();
  return c.model_params.contains("n_x") ? c.model + "_nx" + c.model_params["n_x"].dump() : c.model;
}

}  // namespace

int main(int argc, char** argv) {
  for (const Case& c : paper_cases()) {
    benchmark::RegisterBenchmark(("nonlinearity/" + label(c)).c_str(), nonlinearity, c);
    benchmark::RegisterBenchmark(("fft_bound/" + label(c)).c_str(), fft_bound, c);
    if (c.model_params.value("n_x", 16) != 16)  // large enough for FFTW's threads
      benchmark::RegisterBenchmark(("nonlinearity_threads/" + label(c) + "/2").c_str(), nonlinearity_threads, c, 2)
          ->UseRealTime();
    if (c.model_params.value("n_x", 16) != 16) continue;  // steps at the paper's sizes only
    for (const auto* s : registry().schemes()) {
      const auto& r = s->traits.reformulations;
      if (std::find(r.begin(), r.end(), "two-scale") != r.end())
        benchmark::RegisterBenchmark(("step/" + label(c) + "/" + s->info.name).c_str(), step, c,
                                     tsi::Json{{"name", s->info.name}}, 0.01);
    }
    // The charged particle's SE2 with the 2 nodes that were given to it before the assembler
    // completed its 6: what the right quadrature costs.
    if (c.model == "cpd")
      benchmark::RegisterBenchmark("step/cpd/se2/2-nodes", step, c,
                                   tsi::Json{{"name", "se2"}, {"quadrature_nodes", 2}}, 0.01);
    for (double eps : {1.0, 1e-6})
      benchmark::RegisterBenchmark(("step_eps/" + label(c) + "/se1/" + (eps == 1.0 ? "1" : "1e-6")).c_str(), step, c,
                                   tsi::Json{{"name", "se1"}}, eps);
  }
  for (const Case& c : {Case{"nls", {{"n_x", 8192}}, 64}, Case{"henon-heiles-ensemble", {{"copies", 262144}}, 16}}) {
    const std::string prefix = "large/" + label(c) + "_ntau" + std::to_string(c.n_tau) + "/";
    benchmark::RegisterBenchmark((prefix + "nonlinearity").c_str(), nonlinearity, c);
    benchmark::RegisterBenchmark((prefix + "fft_bound").c_str(), fft_bound, c);
    for (const char* scheme : {"se1", "eab"})
      benchmark::RegisterBenchmark((prefix + scheme).c_str(), step, c, tsi::Json{{"name", scheme}}, 0.01);
  }
  for (const Case& c : {Case{"nls", {{"dims", 2}, {"n_x", 256}}, 32}, Case{"nls", {{"dims", 3}, {"n_x", 64}}, 16}}) {
    const std::string prefix = "large/" + label(c) + "_ntau" + std::to_string(c.n_tau) + "/";
    benchmark::RegisterBenchmark((prefix + "nonlinearity").c_str(), nonlinearity, c);
    benchmark::RegisterBenchmark((prefix + "fft_bound").c_str(), fft_bound, c);
    benchmark::RegisterBenchmark((prefix + "se1").c_str(), step, c, tsi::Json{{"name", "se1"}}, 0.01);
    benchmark::RegisterBenchmark((prefix + "nonlinearity_fft_threads/2").c_str(), nonlinearity_threads, c, 2)
        ->UseRealTime();
  }
  std::vector<Case> threaded = {{"henon-heiles", tsi::Json::object(), 64}, {"cpd", tsi::Json::object(), 64},
                                 {"nls", {{"n_x", 16}}, 32}, {"nls", {{"n_x", 16}}, 64}};
  for (const char* model : {"nls", "klein-gordon"})
    for (int n_x : {16, 32, 64, 128, 256, 512, 1024}) threaded.push_back({model, {{"n_x", n_x}}, 256});
  threaded.push_back({"nls", {{"dims", 2}, {"n_x", 256}}, 32});
  threaded.push_back({"nls", {{"dims", 3}, {"n_x", 64}}, 16});
  for (const Case& c : threaded)
    for (int threads : {1, 2})
      benchmark::RegisterBenchmark(
          ("tau_threads/" + label(c) + "_ntau" + std::to_string(c.n_tau) + "/" + std::to_string(threads)).c_str(),
          step_tau_threads, c, threads)
          ->UseRealTime();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
