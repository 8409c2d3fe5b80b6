/* The machine's peak single-precision rate, measured: every hardware thread
 * runs a loop of independent 256-bit fused multiply-adds (AVX2 + FMA, the
 * widest vectors llvmpipe's code uses on this machine) for about a second;
 * FLOP = threads x iterations x chains x 8 lanes x 2. On a shared machine
 * the wall clock counts other jobs' time too, so the rate is also given per
 * second of the threads' own CPU time (CLOCK_THREAD_CPUTIME_ID) times the
 * hardware threads: the peak of the machine had it to itself.
 * docs/performance.md sets each pass's achieved rate beside this figure.
 *
 *   cc -O2 -mavx2 -mfma -pthread tests/benchmark/fma_peak.c -o /tmp/fma_peak && /tmp/fma_peak [threads]
 */
#include <immintrin.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

enum { kChains = 10, kIterations = 50000000 };

static double Now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

typedef struct {
  float sum;
  double cpu_seconds;
} Result;

static void* Run(void* out) {
  struct timespec t0, t1;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
  __m256 acc[kChains];
  const __m256 a = _mm256_set1_ps(0.999999f), b = _mm256_set1_ps(1e-7f);
  for (int c = 0; c < kChains; ++c) acc[c] = _mm256_set1_ps((float)c);
  for (long i = 0; i < kIterations; ++i)
    for (int c = 0; c < kChains; ++c) acc[c] = _mm256_fmadd_ps(acc[c], a, b);
  float sum = 0.0f, lanes[8];
  for (int c = 0; c < kChains; ++c) {
    _mm256_storeu_ps(lanes, acc[c]);
    for (int l = 0; l < 8; ++l) sum += lanes[l];
  }
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  ((Result*)out)->sum = sum; /* kept, so the loop is not optimized away */
  ((Result*)out)->cpu_seconds = (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec);
  return NULL;
}

int main(int argc, char** argv) {
  if (argc > 1 && atoi(argv[1]) > 256) return 2;
  const int threads = argc > 1 ? atoi(argv[1]) : (int)sysconf(_SC_NPROCESSORS_ONLN);
  pthread_t ids[256];
  Result results[256];
  const double start = Now();
  for (int t = 0; t < threads; ++t) pthread_create(&ids[t], NULL, Run, &results[t]);
  for (int t = 0; t < threads; ++t) pthread_join(ids[t], NULL);
  const double seconds = Now() - start;
  const double flop = (double)threads * kIterations * kChains * 8 * 2;
  double cpu = 0.0;
  for (int t = 0; t < threads; ++t) cpu += results[t].cpu_seconds;
  printf(
      "%d threads: %.1f GFLOP/s by the wall clock (%.3f s); %.1f GFLOP/s per core of CPU time, %.1f GFLOP/s for "
      "%d hardware threads (checksum %g)\n",
      threads, flop / seconds * 1e-9, seconds, flop / cpu * 1e-9, flop / cpu * 1e-9 * sysconf(_SC_NPROCESSORS_ONLN),
      (int)sysconf(_SC_NPROCESSORS_ONLN), (double)results[0].sum);
  return 0;
}
