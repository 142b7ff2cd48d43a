// kmeans.c: k-means++ seeding and Lloyd iterations; nearest centres through FLANN.
#include "kmeans.h"

#include "cv_adapter.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

typedef struct pf_ctx {
    int n;
    atomic_int next;
    atomic_int failed;
    int (*fn)(void*, int);
    void* user;
} pf_ctx;

static void* pf_worker(void* arg)
{
    pf_ctx* c = arg;
    for (;;) {
        if (atomic_load(&c->failed)) break;
        int i = atomic_fetch_add(&c->next, 1);
        if (i >= c->n) break;
        int r = c->fn(c->user, i);
        if (r) {
            int zero = 0;
            atomic_compare_exchange_strong(&c->failed, &zero, r);
        }
    }
    return NULL;
}

int sp_parallel_for(int n, int threads, int (*fn)(void* user, int i), void* user)
{
    pf_ctx c = {.n = n, .fn = fn, .user = user};
    atomic_init(&c.next, 0);
    atomic_init(&c.failed, 0);
    if (threads < 1) threads = 1;
    if (threads > 64) threads = 64;
    if (threads > n) threads = n > 0 ? n : 1;
    pthread_t tid[64];
    int started = 0;
    for (int t = 1; t < threads; ++t)
        if (pthread_create(&tid[started], NULL, pf_worker, &c) == 0) ++started;
    pf_worker(&c); // the caller works too; fewer threads than asked is still correct
    for (int t = 0; t < started; ++t)
        pthread_join(tid[t], NULL);
    return atomic_load(&c.failed);
}

static float dist2(const float* a, const float* b, int dim)
{
    float s = 0.0f;
    for (int i = 0; i < dim; ++i) {
        float d = a[i] - b[i];
        s += d * d;
    }
    return s;
}

typedef struct seed_ctx {
    const float* data;
    int n, dim;
    const float* center;
    float* mind;
} seed_ctx;

enum { CHUNK = 4096 };

static int seed_update(void* user, int chunk)
{
    seed_ctx* c = user;
    int b = chunk * CHUNK, e = b + CHUNK < c->n ? b + CHUNK : c->n;
    for (int i = b; i < e; ++i) {
        float d = dist2(c->data + (size_t)i * c->dim, c->center, c->dim);
        if (d < c->mind[i]) c->mind[i] = d;
    }
    return 0;
}

typedef struct assign_ctx {
    const float* centers;
    const float* cnorm;
    int k;
    const float* data;
    int n;
    int* label;
    float* dist;
} assign_ctx;

static int assign_chunk(void* user, int chunk)
{
    assign_ctx* c = user;
    int b = chunk * CHUNK, e = b + CHUNK < c->n ? b + CHUNK : c->n;
    sp_nearest_words(c->centers, c->cnorm, c->k, c->data + (size_t)b * 64, e - b, 1, c->label + b, c->dist + b);
    return 0;
}

sp_result sp_kmeans(const float* data, int n, int dim, int k, uint64_t seed, int iterations, int threads, float* centers,
                    sp_error* err)
{
    if (dim != 64) return sp_fail(err, SP_ERR_INVALID, "k-means: descriptors must be 64-D");
    if (k < 1 || n < k) return sp_fail(err, SP_ERR_INVALID, "k-means: %d clusters from %d points", k, n);
    float* mind = malloc(sizeof(float) * (size_t)n);
    int* label = malloc(sizeof(int) * (size_t)n);
    int* prev = malloc(sizeof(int) * (size_t)n);
    float* dist = malloc(sizeof(float) * (size_t)n);
    double* acc = malloc(sizeof(double) * (size_t)k * dim);
    int* cnt = malloc(sizeof(int) * (size_t)k);
    sp_result rc = SP_OK;
    if (!mind || !label || !prev || !dist || !acc || !cnt) {
        rc = sp_fail(err, SP_ERR_NO_MEMORY, "k-means: out of memory");
        goto done;
    }
    uint64_t rng = seed;
    int nchunks = (n + CHUNK - 1) / CHUNK;
    // k-means++ seeding: each new centre drawn with probability ~ squared distance.
    int first = (int)(clf_rng_next(&rng) % (uint64_t)n);
    memcpy(centers, data + (size_t)first * dim, sizeof(float) * (size_t)dim);
    for (int i = 0; i < n; ++i)
        mind[i] = 3.4e38f;
    for (int j = 1; j <= k; ++j) {
        seed_ctx sc = {data, n, dim, centers + (size_t)(j - 1) * dim, mind};
        sp_parallel_for(nchunks, threads, seed_update, &sc);
        if (j == k) break;
        double total = 0.0;
        for (int i = 0; i < n; ++i)
            total += mind[i];
        int pick = 0;
        if (total > 0.0) {
            double r = clf_rng_uniform(&rng) * total, c = 0.0;
            pick = n - 1;
            for (int i = 0; i < n; ++i) {
                c += mind[i];
                if (c > r) {
                    pick = i;
                    break;
                }
            }
        } else {
            pick = (int)(clf_rng_next(&rng) % (uint64_t)n); // all points coincide with centres
        }
        memcpy(centers + (size_t)j * dim, data + (size_t)pick * dim, sizeof(float) * (size_t)dim);
    }
    for (int i = 0; i < n; ++i)
        prev[i] = -1;
    for (int it = 0; it < iterations; ++it) {
        float* cnorm = (float*)cnt; // reuse: sizeof(int) == sizeof(float), refilled below
        for (int c = 0; c < k; ++c) {
            float s = 0.0f;
            for (int d = 0; d < dim; ++d)
                s += centers[(size_t)c * dim + d] * centers[(size_t)c * dim + d];
            cnorm[c] = s;
        }
        assign_ctx ac = {centers, cnorm, k, data, n, label, dist};
        sp_parallel_for(nchunks, threads, assign_chunk, &ac);
        int changed = 0;
        for (int i = 0; i < n; ++i)
            changed += label[i] != prev[i];
        memcpy(prev, label, sizeof(int) * (size_t)n);
        memset(acc, 0, sizeof(double) * (size_t)k * dim);
        memset(cnt, 0, sizeof(int) * (size_t)k);
        for (int i = 0; i < n; ++i) {
            int l = label[i];
            if (l < 0 || l >= k) continue;
            ++cnt[l];
            const float* x = data + (size_t)i * dim;
            double* a = acc + (size_t)l * dim;
            for (int d = 0; d < dim; ++d)
                a[d] += x[d];
        }
        for (int c = 0; c < k; ++c) {
            if (cnt[c] == 0) {
                // Empty cluster: move it to the point worst served by its centre.
                int far = 0;
                for (int i = 1; i < n; ++i)
                    if (dist[i] > dist[far]) far = i;
                memcpy(centers + (size_t)c * dim, data + (size_t)far * dim, sizeof(float) * (size_t)dim);
                dist[far] = 0.0f;
                continue;
            }
            for (int d = 0; d < dim; ++d)
                centers[(size_t)c * dim + d] = (float)(acc[(size_t)c * dim + d] / cnt[c]);
        }
        if (changed == 0) break;
    }
done:
    free(mind);
    free(label);
    free(prev);
    free(dist);
    free(acc);
    free(cnt);
    return rc;
}

typedef float v4f __attribute__((vector_size(16)));
typedef int v4si __attribute__((vector_size(16)));

// Keeps the nn smallest (d, w) in bd/bi, sorted; exact ties keep the lower index.
static inline void keep_nearest(float d, int w, int nn, int* bi, float* bd)
{
    if (d >= bd[nn - 1]) return;
    int j = nn - 1;
    while (j > 0 && bd[j - 1] > d) {
        bd[j] = bd[j - 1];
        bi[j] = bi[j - 1];
        --j;
    }
    bd[j] = d;
    bi[j] = w;
}

// The same through dot products in blocks of rows (OpenCV's gemm); false when
// the scratch or the adapter fails (the caller falls back to the scan).
static bool nearest_words_gemm(const float* words, const float* wnorm, int K, const float* x, int n, int nn, int* idx, float* d2)
{
    int rows = (1 << 20) / (K > 0 ? K : 1); // about 4 MB of scratch
    if (rows < 1) rows = 1;
    if (rows > 256) rows = 256;
    float* dots = malloc(sizeof(float) * (size_t)rows * (size_t)K);
    if (!dots) return false;
    for (int b = 0; b < n; b += rows) {
        int m = n - b < rows ? n - b : rows;
        sp_error e = {0};
        if (sp_cv_dot_rows(x + (size_t)b * 64, m, words, K, 64, dots, &e) != SP_OK) {
            free(dots);
            return false;
        }
        for (int i = 0; i < m; ++i) {
            const float* q = x + (size_t)(b + i) * 64;
            float qn = 0.0f;
            for (int d = 0; d < 64; ++d)
                qn += q[d] * q[d];
            int* bi = idx + (size_t)(b + i) * nn;
            float* bd = d2 + (size_t)(b + i) * nn;
            for (int j = 0; j < nn; ++j) {
                bi[j] = -1;
                bd[j] = 3.4e38f;
            }
            // Why four words at a time: one vector comparison rules out all four
            // in almost every step (a word-by-word insertion scan took as long
            // as the products).
            const float* row = dots + (size_t)i * K;
            float worst = bd[nn - 1];
            const v4f qv = {qn, qn, qn, qn};
            v4f wv = {worst, worst, worst, worst};
            int w = 0;
            for (; w + 4 <= K; w += 4) {
                v4f r, wn;
                memcpy(&r, row + w, sizeof r);
                memcpy(&wn, wnorm + w, sizeof wn);
                v4f d = qv + wn - (r + r);
                v4si lt = d < wv;
                if (!(lt[0] | lt[1] | lt[2] | lt[3])) continue;
                for (int l = 0; l < 4; ++l)
                    if (d[l] < worst) {
                        keep_nearest(d[l] < 0.0f ? 0.0f : d[l], w + l, nn, bi, bd);
                        worst = bd[nn - 1];
                    }
                wv = (v4f){worst, worst, worst, worst};
            }
            for (; w < K; ++w) {
                float d = qn + wnorm[w] - 2.0f * row[w];
                if (d < worst) {
                    keep_nearest(d < 0.0f ? 0.0f : d, w, nn, bi, bd);
                    worst = bd[nn - 1];
                }
            }
        }
    }
    free(dots);
    return true;
}

void sp_nearest_words(const float* words, const float* wnorm, int K, const float* x, int n, int nn, int* idx, float* d2)
{
    if (n > 0 && nearest_words_gemm(words, wnorm, K, x, n, nn, idx, d2)) return;
    for (int i = 0; i < n; ++i) {
        const float* q = x + (size_t)i * 64;
        v4f qv[16];
        float qn = 0.0f;
        for (int k = 0; k < 16; ++k) {
            memcpy(&qv[k], q + 4 * k, sizeof(v4f));
            for (int j = 0; j < 4; ++j)
                qn += q[4 * k + j] * q[4 * k + j];
        }
        int* bi = idx + (size_t)i * nn;
        float* bd = d2 + (size_t)i * nn;
        for (int j = 0; j < nn; ++j) {
            bi[j] = -1;
            bd[j] = 3.4e38f;
        }
        for (int w = 0; w < K; ++w) {
            const float* c = words + (size_t)w * 64;
            v4f a0 = {0}, a1 = {0}, a2 = {0}, a3 = {0}, cv[4];
            for (int k = 0; k < 16; k += 4) {
                memcpy(cv, c + 4 * k, sizeof cv);
                a0 += qv[k] * cv[0];
                a1 += qv[k + 1] * cv[1];
                a2 += qv[k + 2] * cv[2];
                a3 += qv[k + 3] * cv[3];
            }
            v4f s = a0 + a1 + a2 + a3;
            float d = qn + wnorm[w] - 2.0f * (s[0] + s[1] + s[2] + s[3]);
            keep_nearest(d < 0.0f ? 0.0f : d, w, nn, bi, bd);
        }
    }
}
