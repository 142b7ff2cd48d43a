/// kmeans.h (private): seeded k-means++ (exact nearest centres), nearest words, a parallel for.
#ifndef SP_CLF_KMEANS_H
#define SP_CLF_KMEANS_H

#include <stdint.h>

#include "sp/result.h"

/// splitmix64: tiny, seedable, the same on every platform.
static inline uint64_t clf_rng_next(uint64_t* s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
/// Uniform in [0, 1).
static inline double clf_rng_uniform(uint64_t* s)
{
    return (double)(clf_rng_next(s) >> 11) * (1.0 / 9007199254740992.0);
}

/// Clusters `n` rows of `dim` (= 64) floats into `k` centres (k <= n). Deterministic for a
/// given seed whatever `threads` is. centers: k by dim.
sp_result sp_kmeans(const float* data, int n, int dim, int k, uint64_t seed, int iterations, int threads, float* centers,
                    sp_error* err);

/// Runs fn(user, i) for i in [0, n) on `threads` threads (work stealing by counter).
/// Stops handing out work once any call returns non-zero; returns the first non-zero.
int sp_parallel_for(int n, int threads, int (*fn)(void* user, int i), void* user);

#endif

/// Exact `nn` nearest rows of `words` (K by 64, squared norms in `wnorm`) for each of `n`
/// 64-D rows of `x`; idx/d2: n by nn, nearest first, squared distances.
/// Why not FLANN here: exact distances from dot products (OpenCV's gemm; a
/// vectorised scan when that fails) are faster than FLANN 1.9's linear or
/// kd-tree search for a drawing's descriptors against the vocabulary, and
/// deterministic (BENCHMARKS.md, "Quick, Draw! 100 categories").
void sp_nearest_words(const float* words, const float* wnorm, int K, const float* x, int n, int nn, int* idx, float* d2);
