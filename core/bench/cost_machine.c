/*
 * cost_machine.c — what one core of this machine can do, for the cost model
 * of `make bench-cost` (docs/benchmarks.md, "Cost model").
 *
 *   cost_machine [REPEATS]
 *
 * Each figure is the best of REPEATS (default 15) timed runs, and the
 * median is printed too: on a shared VM a run can only be slowed down by
 * the neighbours, never sped up, so the best run is the machine's.  Run it
 * pinned to one core (taskset).  Lines of key=value:
 *
 *   machine clock_ghz=          a chain of dependent integer adds, register
 *                               to register (1 cycle each on every x86-64
 *                               since the P6), adds/s;
 *                               5 x REPEATS runs of 8 ms
 *   machine fma256 gflops=      AVX2 FMA, 12 independent accumulators of 4
 *                               doubles (2 flops per lane): the peak of
 *                               vector code; flops_per_cycle = gflops/clock
 *   machine scalar gflops=      scalar multiply then add (the build's
 *                               -ffp-contract=off, no -march: what the
 *                               core's compiled loops can issue), 12 chains
 *   machine sqrt cycles=        cycles per scalar sqrt, independent operands
 *   machine div cycles=         cycles per scalar division, independent
 *   machine sqrt256, div256     the same with AVX2, cycles per element
 *   machine triad level= bytes= gbs=   a[i] = b[i] + s c[i] over three arrays
 *                               of `bytes` in all; 24 bytes per element
 *                               counted (STREAM's convention: the
 *                               write-allocate read of a[] is not)
 *   machine triad256 level=...  the same with AVX2 loads and stores
 *
 * Compiled with -O2 -fno-tree-vectorize, so that the scalar and triad
 * loops are the plain loops written here (the triad's loads and stores are
 * then 8 bytes wide, as in the pair loop).
 */
#include <immintrin.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#define MAX_REPEATS 101
static int repeats = 15;

/* best (largest) and median of the rates in v[0..n) */
static void best_median(double *v, int n, double *best, double *median)
{
    qsort(v, (size_t)n, sizeof v[0], cmp_double);
    *best = v[n - 1];
    *median = v[n / 2];
}

/* 100 dependent adds per iteration: the loop's own add and branch run beside them. */
static double clock_ghz(double *median)
{
    double rate[MAX_REPEATS];
    /* short runs (8 ms), many: on a shared core some fall between preemptions */
    const long iters = 200000;
    const int runs = 5 * repeats < MAX_REPEATS ? 5 * repeats : MAX_REPEATS;
    for (int r = 0; r < runs; r++) {
        uint64_t x = 0, one = 1;
        const double t0 = now();
        for (long k = 0; k < iters; k++) {
            /* register + register: newer Intel cores (seen on a Xeon of
             * model 167, 2026-11-27) fold chains of add-immediate at
             * renaming and ran this chain at "24 GHz" with $1 */
#define A4 "add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\t"
#define A20 A4 A4 A4 A4 A4
            __asm__ volatile(A20 A20 A20 A20 A20 : "+r"(x) : "r"(one));
        }
        const double t = now() - t0;
        rate[r] = (double)iters * 100 / t / 1e9;
        if (x != (uint64_t)iters * 100)
            return -1;
    }
    double best;
    best_median(rate, runs, &best, median);
    return best;
}

/* Twelve named accumulators (an array of them stayed in memory), updated
 * by OP and kept live by an empty asm. */
#define ACC12(T, init) T a0 = init(1), a1 = init(2), a2 = init(3), a3 = init(4), a4 = init(5), \
    a5 = init(6), a6 = init(7), a7 = init(8), a8 = init(9), a9 = init(10), a10 = init(11), \
    a11 = init(12)
#define EACH12(OP) OP(a0); OP(a1); OP(a2); OP(a3); OP(a4); OP(a5); OP(a6); OP(a7); OP(a8); \
    OP(a9); OP(a10); OP(a11)
#define KEEP12 __asm__ volatile("" : "+x"(a0), "+x"(a1), "+x"(a2), "+x"(a3), "+x"(a4), "+x"(a5), \
                                "+x"(a6), "+x"(a7), "+x"(a8), "+x"(a9), "+x"(a10), "+x"(a11))

__attribute__((target("avx2,fma"))) static double fma256_gflops(double *median)
{
    double rate[MAX_REPEATS];
    const long iters = 5000000;
    for (int r = 0; r < repeats; r++) {
        const __m256d m = _mm256_set1_pd(0.999999), c = _mm256_set1_pd(1e-7);
#define SET(q) _mm256_set1_pd(1.0 + q)
        ACC12(__m256d, SET);
#define FMA(v) v = _mm256_fmadd_pd(v, m, c)
        const double t0 = now();
        for (long k = 0; k < iters; k++) {
            EACH12(FMA);
            KEEP12;
        }
        const double t = now() - t0;
        double sink[4], s = 0;
#define SUM(v) (_mm256_storeu_pd(sink, v), s += sink[0])
        EACH12(SUM);
        if (s != s)
            return -1;
        rate[r] = (double)iters * 12 * 4 * 2 / t / 1e9;
    }
    double best;
    best_median(rate, repeats, &best, median);
    return best;
}

static double scalar_gflops(double *median)
{
    double rate[MAX_REPEATS];
    const long iters = 10000000;
    for (int r = 0; r < repeats; r++) {
        const double m = 0.999999, c = 1e-7;
#define ONE(q) (1.0 + q)
        ACC12(double, ONE);
#define MULADD(v) v = v * m + c
        const double t0 = now();
        for (long k = 0; k < iters; k++) {
            EACH12(MULADD);
            KEEP12;
        }
        const double t = now() - t0;
        double s = 0;
#define ADD(v) s += v
        EACH12(ADD);
        if (s != s)
            return -1;
        rate[r] = (double)iters * 12 * 2 / t / 1e9;
    }
    double best;
    best_median(rate, repeats, &best, median);
    return best;
}

/* Nanoseconds per sqrt (op 0) or division (op 1) over an L1-resident array
 * of independent operands. */
#define OPS_N 2048
static double op_ns(int op, double *median)
{
    static double in[OPS_N], den[OPS_N], out[OPS_N];
    double rate[MAX_REPEATS];
    for (int i = 0; i < OPS_N; i++)
        in[i] = 1.0 + (double)i / OPS_N, den[i] = 1.5 + (double)(OPS_N - i) / OPS_N;
    const int sweeps = 2000;
    for (int r = 0; r < repeats; r++) {
        const double t0 = now();
        for (int k = 0; k < sweeps; k++) {
            if (op == 0)
                for (int i = 0; i < OPS_N; i++) {
                    /* in a register first: sqrtsd from memory would merge
                     * into its destination and chain the iterations */
                    double v = in[i];
                    __asm__("" : "+x"(v));
                    out[i] = __builtin_sqrt(v);
                }
            else
                for (int i = 0; i < OPS_N; i++)
                    out[i] = in[i] / den[i];
            __asm__ volatile("" ::: "memory");
        }
        const double t = now() - t0;
        rate[r] = (double)sweeps * OPS_N / t; /* ops per second */
    }
    double best;
    best_median(rate, repeats, &best, median);
    if (out[OPS_N / 2] != out[OPS_N / 2])
        return -1;
    *median = 1e9 / *median;
    return 1e9 / best;
}

/* The same with AVX2 (4 doubles a vector): nanoseconds per element. */
__attribute__((target("avx2"))) static double op256_ns(int op, double *median)
{
    static double in[OPS_N] __attribute__((aligned(32))), den[OPS_N] __attribute__((aligned(32))),
        out[OPS_N] __attribute__((aligned(32)));
    double rate[MAX_REPEATS];
    for (int i = 0; i < OPS_N; i++)
        in[i] = 1.0 + (double)i / OPS_N, den[i] = 1.5 + (double)(OPS_N - i) / OPS_N;
    const int sweeps = 2000;
    for (int r = 0; r < repeats; r++) {
        const double t0 = now();
        for (int k = 0; k < sweeps; k++) {
            if (op == 0)
                for (int i = 0; i < OPS_N; i += 4)
                    _mm256_store_pd(out + i, _mm256_sqrt_pd(_mm256_load_pd(in + i)));
            else
                for (int i = 0; i < OPS_N; i += 4)
                    _mm256_store_pd(out + i,
                                    _mm256_div_pd(_mm256_load_pd(in + i), _mm256_load_pd(den + i)));
            __asm__ volatile("" ::: "memory");
        }
        const double t = now() - t0;
        rate[r] = (double)sweeps * OPS_N / t;
    }
    double best;
    best_median(rate, repeats, &best, median);
    if (out[OPS_N / 2] != out[OPS_N / 2])
        return -1;
    *median = 1e9 / *median;
    return 1e9 / best;
}

/* Triad over three arrays of `bytes` bytes in all: GB/s, 24 bytes per
 * element; vector = 1: AVX2 loads and stores of 4 doubles, 2 per iteration
 * (the scalar loop is bound by its own instructions from the caches). */
__attribute__((target("avx2"))) static void triad_avx2(double *restrict a, const double *restrict b,
                                                      const double *restrict c, size_t n, double s)
{
    const __m256d sv = _mm256_set1_pd(s);
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        _mm256_storeu_pd(a + i, _mm256_add_pd(_mm256_loadu_pd(b + i),
                                              _mm256_mul_pd(sv, _mm256_loadu_pd(c + i))));
        _mm256_storeu_pd(a + i + 4, _mm256_add_pd(_mm256_loadu_pd(b + i + 4),
                                                  _mm256_mul_pd(sv, _mm256_loadu_pd(c + i + 4))));
    }
    for (; i < n; i++)
        a[i] = b[i] + s * c[i];
}

static double triad_gbs(size_t bytes, int vector, double *median)
{
    const size_t n = bytes / 24;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
    double rate[MAX_REPEATS];
    if (!a || !b || !c)
        return -1;
    for (size_t i = 0; i < n; i++)
        a[i] = 0, b[i] = 1.0 + (double)i, c[i] = 2.0;
    /* at least ~0.05 s a run */
    const long sweeps = (long)(2e8 / (double)bytes) + 1;
    const double s = 0.5;
    for (int r = 0; r < repeats; r++) {
        const double t0 = now();
        for (long k = 0; k < sweeps; k++) {
            if (vector)
                triad_avx2(a, b, c, n, s);
            else
                for (size_t i = 0; i < n; i++)
                    a[i] = b[i] + s * c[i];
            __asm__ volatile("" ::: "memory");
        }
        const double t = now() - t0;
        rate[r] = (double)sweeps * (double)n * 24 / t / 1e9;
    }
    double best;
    best_median(rate, repeats, &best, median);
    if (a[n / 2] != b[n / 2] + s * c[n / 2])
        best = -1;
    free(a), free(b), free(c);
    return best;
}

int main(int argc, char **argv)
{
    if (argc > 1)
        repeats = atoi(argv[1]);
    if (repeats < 1 || repeats > MAX_REPEATS) {
        fprintf(stderr, "usage: cost_machine [REPEATS (1..%d)]\n", MAX_REPEATS);
        return 2;
    }
    double med, best;
    const double ghz = clock_ghz(&med);
    printf("machine clock_ghz=%.4f median=%.4f repeats=%d\n", ghz, med, repeats);
    fflush(stdout);
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        best = fma256_gflops(&med);
        printf("machine fma256 gflops=%.3f median=%.3f flops_per_cycle=%.2f\n", best, med,
               best / ghz);
    } else {
        printf("machine fma256 gflops=nan median=nan flops_per_cycle=nan (no AVX2/FMA)\n");
    }
    best = scalar_gflops(&med);
    printf("machine scalar gflops=%.3f median=%.3f flops_per_cycle=%.2f\n", best, med, best / ghz);
    best = op_ns(0, &med);
    printf("machine sqrt ns=%.3f median=%.3f cycles=%.2f\n", best, med, best * ghz);
    best = op_ns(1, &med);
    printf("machine div ns=%.3f median=%.3f cycles=%.2f\n", best, med, best * ghz);
    if (__builtin_cpu_supports("avx2")) {
        best = op256_ns(0, &med);
        printf("machine sqrt256 ns=%.3f median=%.3f cycles=%.2f (per element)\n", best, med,
               best * ghz);
        best = op256_ns(1, &med);
        printf("machine div256 ns=%.3f median=%.3f cycles=%.2f (per element)\n", best, med,
               best * ghz);
    }
    fflush(stdout);
    static const struct {
        const char *level;
        size_t bytes;
    } sizes[] = {{"L1", 24u << 10}, {"L2", 768u << 10}, {"L3", 12u << 20}, {"memory", 768u << 20}};
    const int avx2 = __builtin_cpu_supports("avx2") != 0;
    for (int vector = 0; vector <= avx2; vector++)
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
            best = triad_gbs(sizes[k].bytes, vector, &med);
            printf("machine %s level=%s bytes=%zu gbs=%.3f median=%.3f bytes_per_cycle=%.3f\n",
                   vector ? "triad256" : "triad", sizes[k].level, sizes[k].bytes, best, med,
                   best / ghz);
            fflush(stdout);
        }
    return 0;
}
