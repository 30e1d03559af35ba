#pragma once
// The host's streaming bandwidth for the benchmarks (bench, bench_fem), measured in their run.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <memory>

namespace smpm::benchmarks {

// STREAM-like triad bandwidth (GB/s, 24 bytes per element) on `threads` threads: best of five.
inline double triad_gbs(int threads) {
  const std::size_t n = std::size_t(1) << 26;  // 3 x 512 MiB
  std::unique_ptr<double[]> a(new double[n]), b(new double[n]), c(new double[n]);
  const long N = static_cast<long>(n);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long i = 0; i < N; ++i) {  // first touch by the threads that use the pages
    a[i] = 0;
    b[i] = 1.0 + i % 7;
    c[i] = 2.0 - i % 5;
  }
  double best = 1e30;
  const double s = 0.5;
  for (int r = 0; r < 5; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    double* A = a.get();
    const double* B = b.get();
    const double* C = c.get();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < N; ++i) A[i] = B[i] + s * C[i];
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  volatile double sink = a[n / 3];  // the result is used
  (void)sink;
  return 24.0 * static_cast<double>(n) / best / 1e9;
}

}  // namespace smpm::benchmarks
