#pragma once
// The algebra's kernels over raw device memory (complex values as interleaved doubles): what
// core/src/cuda/backend.cpp calls for tsi::device's functions. No Eigen here: nvcc compiles
// this and kernels.cu alone.
namespace tsi::cuda {

/// One term d . x of a combination: d the complex coefficients (one per run of `run` entries),
/// or, where d is null, the real factor `scalar`.
struct Term {
  const double* d = nullptr;
  double scalar = 0.0;
  long long run = 1;
  const double* x = nullptr;
};

inline constexpr int max_terms = 8;

/// out = start + sum_j terms[j] (start may be null), the terms added in order; out may alias
/// start or any x.
struct Combination {
  const double* start = nullptr;
  int count = 0;
  Term terms[max_terms];
};

void combine(const Combination& c, double* out, long long n);

/// Reductions: `scratch` is device memory for reduction_blocks * 2 doubles, `host` pinned
/// memory for as many.
inline constexpr int reduction_blocks = 1024;
bool all_finite(const double* x, long long n, double* scratch, double* host);
double inner(const double* x, const double* y, long long n, double* scratch, double* host);
/// max |x_i|^2
double max_abs2(const double* x, long long n, double* scratch, double* host);
/// m[0] = max |next_i - x_i|^2, m[1] = max |next_i|^2
void increment_maxima(const double* next, const double* x, long long n, double m[2], double* scratch, double* host);

}  // namespace tsi::cuda
