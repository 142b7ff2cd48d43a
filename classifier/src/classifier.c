// classifier.c: vocabulary, soft-assigned histograms, FLANN k-NN voting,
// rejection, and the model file.
#include "sp/classifier.h"

#include <errno.h>
#include <flann/flann.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cv_adapter.h"
#include "feat.h"
#include "kmeans.h"
#include "model_checksum.h"
#include "picture.h"
#include "shape.h"
#include "sp/math.h"
#include "sp/sketch_io.h"

// The memory describing one drawing takes (about 1.3 MB; feat.h). A classifier
// keeps what its callers' threads used, for their next drawings.
typedef struct clf_work {
    sp_feat_scratch scratch;
    sp_features f;
} clf_work;
enum { WORK_SLOTS = 8 };

struct sp_clf {
    sp_clf_desc desc; // resolved, progress NULL
    int category_count;
    char** categories;
    int words;    // vocabulary size actually used
    float* vocab; // words by 64
    float* vnorm; // words squared norms
    float sigma;  // soft-assignment kernel width (descriptor distance)
    int hist_dim; // words * pyramid_cells(pyramid)
    float* idf;   // words, or NULL
    int train_count;
    float* hists;    // train_count by hist_dim (final, mapped)
    int* labels;     // train_count
    float bandwidth; // voting kernel width (histogram distance)
    float reject;    // reject beyond this nearest distance
    flann_index_t hist_index; // beyond HIST_KDTREE_MIN training drawings; else NULL (knn_shortlist)
    struct FLANNParameters hist_params;
    int16_t* coarse;   // train_count by coarse_stride: the whole-drawing level quantised (knn_shortlist)
    int coarse_stride; // words rounded up to 8
    int shape_count;   // training stroke drawings with a shape descriptor (0: no shape evidence)
    float* shapes;     // shape_count by SP_SHAPE_DIM, standardised by shape_mu / shape_sd
    int* shape_labels; // shape_count
    float shape_mu[SP_SHAPE_DIM], shape_sd[SP_SHAPE_DIM];
    int pic_count;       // training pictures, mirrored ones included (0: no picture evidence)
    float* pics;         // pic_count by SP_PICTURE_DIM
    int* pic_labels;     // pic_count
    float pic_bandwidth; // voting kernel width (picture distance)
    // Idle work memory (work_take, work_give): a cache, so a const sp_clf
    // may fill it; every sp_clf is allocated (calloc: all NULL), never const.
    _Atomic(clf_work*) work[WORK_SLOTS];
};

// An idle clf_work of c's, or a new one (NULL: out of memory).
static clf_work* work_take(const sp_clf* c)
{
    sp_clf* m = (sp_clf*)c;
    for (int i = 0; i < WORK_SLOTS; ++i) {
        clf_work* w = atomic_exchange(&m->work[i], NULL);
        if (w) return w;
    }
    return malloc(sizeof(clf_work));
}

// Keeps w for the next drawing (freed when every slot is taken).
static void work_give(const sp_clf* c, clf_work* w)
{
    sp_clf* m = (sp_clf*)c;
    for (int i = 0; w && i < WORK_SLOTS; ++i) {
        clf_work* none = NULL;
        if (atomic_compare_exchange_strong(&m->work[i], &none, w)) return;
    }
    free(w);
}

sp_clf_desc sp_clf_desc_defaults(const sp_clf_desc* d)
{
    sp_clf_desc r = d ? *d : (sp_clf_desc){0};
    if (r.words <= 0) r.words = 500;
    if (r.vocab_samples <= 0) r.vocab_samples = 50000;
    if (r.kmeans_iterations <= 0) r.kmeans_iterations = 10;
    if (r.soft_neighbours <= 0) r.soft_neighbours = 4;
    if (r.soft_neighbours > 16) r.soft_neighbours = 16;
    if (r.knn <= 0) r.knn = 8;
    if (r.knn > 64) r.knn = 64;
    if (r.pyramid == 0) r.pyramid = 1;
    if (r.pyramid > 2) r.pyramid = 2;
    if (r.tfidf == 0) r.tfidf = 1;
    if (r.hellinger == 0) r.hellinger = 1;
    if (r.mirror == 0) r.mirror = 1;
    if (r.augment <= 0) r.augment = 0;
    if (r.augment > 16) r.augment = 16;
    if (!(r.reject_quantile > 0.0 && r.reject_quantile <= 1.0)) r.reject_quantile = 0.98;
    if (r.seed == 0) r.seed = 1;
    if (r.threads <= 0) r.threads = 2;
    if (!(r.shape_weight > 0.0) || !isfinite(r.shape_weight)) r.shape_weight = -1.0;
    if (r.picture_weight == 0.0) r.picture_weight = SP_CLF_PICTURE_WEIGHT;
    if (!(r.picture_weight > 0.0) || !isfinite(r.picture_weight)) r.picture_weight = -1.0;
    return r;
}

int sp_clf_category_count(const sp_clf* clf)
{
    return clf->category_count;
}
const char* sp_clf_category(const sp_clf* clf, int i)
{
    return i >= 0 && i < clf->category_count ? clf->categories[i] : "?";
}
sp_clf_desc sp_clf_get_desc(const sp_clf* clf)
{
    return clf->desc;
}

void sp_clf_destroy(sp_clf* clf)
{
    if (!clf) return;
    if (clf->hist_index) flann_free_index_float(clf->hist_index, &clf->hist_params);
    for (int i = 0; i < clf->category_count; ++i)
        free(clf->categories[i]);
    free(clf->categories);
    free(clf->vocab);
    free(clf->vnorm);
    free(clf->idf);
    free(clf->hists);
    free(clf->labels);
    free(clf->coarse);
    free(clf->shapes);
    free(clf->shape_labels);
    free(clf->pics);
    free(clf->pic_labels);
    for (int i = 0; i < WORK_SLOTS; ++i)
        free(atomic_load(&clf->work[i]));
    free(clf);
}

// ---------------------------------------------------------------------------
// Indices

// The words' squared norms, for the nearest words by dot products (sp_nearest_words).
static sp_result vocab_norms(sp_clf* c, sp_error* err)
{
    free(c->vnorm);
    if (!(c->vnorm = malloc(sizeof(float) * (size_t)c->words))) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    for (int w = 0; w < c->words; ++w) {
        float s = 0.0f;
        for (int d = 0; d < SP_FEAT_DIM; ++d)
            s += c->vocab[(size_t)w * SP_FEAT_DIM + d] * c->vocab[(size_t)w * SP_FEAT_DIM + d];
        c->vnorm[w] = s;
    }
    return SP_OK;
}

// Coarse histograms for the shortlist: the whole-drawing level (the first
// `words` values; in [0, 1] whatever the mapping) in 14-bit fixed point, so that
// squared differences of two summed in 32 bits cannot overflow. A quickdraw
// fold's 4000 of them take 4 MB, which stays in the cache between queries.
#define COARSE_SCALE 16383.0f
static void quantise_coarse(const sp_clf* c, const float* hist, int16_t* out)
{
    for (int w = 0; w < c->words; ++w) {
        float v = hist[w] * COARSE_SCALE + 0.5f;
        out[w] = (int16_t)(v < 0.0f ? 0.0f : v > COARSE_SCALE ? COARSE_SCALE : v);
    }
    for (int w = c->words; w < c->coarse_stride; ++w)
        out[w] = 0;
}

// Training sets of more histograms than this are searched with FLANN's kd-tree.
#define HIST_KDTREE_MIN 20000

static sp_result build_hist_index(sp_clf* c, sp_error* err)
{
    free(c->coarse);
    c->coarse = NULL;
    if (c->train_count > HIST_KDTREE_MIN) {
        struct FLANNParameters p = DEFAULT_FLANN_PARAMETERS;
        // Why the single kd-tree: FLANN 1.9's randomised trees shuffle with
        // std::random_device, so their (approximate) answers differ from run to run.
        p.algorithm = FLANN_INDEX_KDTREE_SINGLE;
        p.leaf_max_size = 8;
        p.checks = 512;
        p.cores = 1;
        p.log_level = FLANN_LOG_NONE;
        p.random_seed = (long)(c->desc.seed & 0x7fffffff) + 11;
        c->hist_params = p;
        float speedup;
        c->hist_index = flann_build_index_float(c->hists, c->train_count, c->hist_dim, &speedup, &c->hist_params);
        return c->hist_index ? SP_OK : sp_fail(err, SP_ERR_INTERNAL, "FLANN: histogram index build failed");
    }
    // Smaller sets: exact neighbours from the shortlist (knn_shortlist).
    c->coarse_stride = (c->words + 7) / 8 * 8;
    c->coarse = calloc((size_t)c->train_count * c->coarse_stride, sizeof(int16_t));
    if (!c->coarse) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    for (int i = 0; i < c->train_count; ++i)
        quantise_coarse(c, c->hists + (size_t)i * c->hist_dim, c->coarse + (size_t)i * c->coarse_stride);
    return SP_OK;
}

// ---------------------------------------------------------------------------
// Histograms

// Histogram cells of the spatial pyramid: 1x1, then 2x2 (pyramid 1), then 4x4 (pyramid 2).
static int pyramid_levels(int pyramid)
{
    return pyramid > 0 ? 1 + pyramid : 1;
}
static int pyramid_cells(int pyramid)
{
    return pyramid >= 2 ? 21 : pyramid == 1 ? 5 : 1;
}

// Raw soft-assigned word counts of one drawing: level 0 (words) then, with the
// pyramid, the 2x2 cells (4 * words) and the 4x4 cells (16 * words). raw: hist_dim floats.
static sp_result raw_hist(const sp_clf* c, sp_features* f, float* raw, sp_error* err)
{
    const int K = c->words;
    int nn = c->desc.soft_neighbours < K ? c->desc.soft_neighbours : K;
    memset(raw, 0, sizeof(float) * (size_t)c->hist_dim);
    int* idx = malloc(sizeof(int) * (size_t)f->count * nn);
    float* d2 = malloc(sizeof(float) * (size_t)f->count * nn);
    if (!idx || !d2) {
        free(idx);
        free(d2);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    sp_nearest_words(c->vocab, c->vnorm, K, f->desc, f->count, nn, idx, d2);
    const float inv2s2 = 1.0f / (2.0f * c->sigma * c->sigma);
    for (int i = 0; i < f->count; ++i) {
        float w[16], sum = 0.0f;
        const int* id = idx + (size_t)i * nn;
        const float* dd = d2 + (size_t)i * nn;
        // Relative to the nearest word, so that a far-away descriptor still counts once.
        for (int j = 0; j < nn; ++j) {
            w[j] = id[j] >= 0 && id[j] < K ? expf(-(dd[j] - dd[0]) * inv2s2) : 0.0f;
            sum += w[j];
        }
        if (!(sum > 0.0f)) continue;
        int cell = (f->pos[2 * i] >= 0.5f) + 2 * (f->pos[2 * i + 1] >= 0.5f);
        int cx4 = (int)(f->pos[2 * i] * 4.0f), cy4 = (int)(f->pos[2 * i + 1] * 4.0f);
        int cell4 = (cx4 < 0 ? 0 : cx4 > 3 ? 3 : cx4) + 4 * (cy4 < 0 ? 0 : cy4 > 3 ? 3 : cy4);
        for (int j = 0; j < nn; ++j) {
            if (w[j] == 0.0f) continue;
            float v = w[j] / sum;
            raw[id[j]] += v;
            if (c->desc.pyramid > 0) raw[K * (1 + cell) + id[j]] += v;
            if (c->desc.pyramid > 1) raw[K * (5 + cell4) + id[j]] += v;
        }
    }
    free(idx);
    free(d2);
    return SP_OK;
}

// idf weighting, L1 normalisation per pyramid level, Hellinger map.
static void finish_hist(const sp_clf* c, const float* raw, float* out)
{
    const int K = c->words;
    const int levels = pyramid_levels(c->desc.pyramid);
    static const int first_cell[4] = {0, 1, 5, 21};
    for (int l = 0; l < levels; ++l) {
        int b = K * first_cell[l], e = K * first_cell[l + 1];
        double s = 0.0;
        for (int i = b; i < e; ++i) {
            float v = raw[i] * (c->idf ? c->idf[(i - b) % K] : 1.0f);
            out[i] = v;
            s += v;
        }
        float scale = s > 0.0 ? (float)(1.0 / (levels * s)) : 0.0f; // each level weighs the same
        for (int i = b; i < e; ++i) {
            out[i] *= scale;
            if (c->desc.hellinger > 0) out[i] = sqrtf(out[i]);
        }
    }
}

// ---------------------------------------------------------------------------
// Voting

// Floors of the fusion: a category without votes, or without shape neighbours,
// is unlikely, not impossible (the two kinds of evidence disagree on drawings
// of designs the training set lacks; tuned with the shape's weight on the
// visitors' tune half, BENCHMARKS.md "Visitors' drawings").
#define FUSE_VOTE_FLOOR 0.02
#define SHAPE_FLOOR 0.01
#define PICTURE_FLOOR 0.02

static float dist2(const float* a, const float* b, int n, float stop);

// The k rows of `rows` (count by dim) nearest to x: near[] and their squared
// distances best[], nearest first; returns how many (min(k, count)).
static int nearest_rows(const float* rows, int count, int dim, const float* x, int k, int* near, double* best)
{
    int have = 0;
    for (int i = 0; i < count; ++i) {
        double s = dist2(rows + (size_t)i * dim, x, dim, have == k ? (float)best[k - 1] : INFINITY);
        if (have == k && s >= best[k - 1]) continue;
        int j = have < k ? have++ : k - 1;
        for (; j > 0 && best[j - 1] > s; --j)
            best[j] = best[j - 1], near[j] = near[j - 1];
        best[j] = s, near[j] = i;
    }
    return have;
}

// The shape evidence's share per category (`p`, category_count, sums to 1):
// the knn training drawings nearest in (standardised) shape, each weighted by
// how much farther than the nearest one it is. False without shape evidence
// (none in the model, switched off, or the drawing has no shape descriptor).
static bool shape_shares(const sp_clf* c, const sp_sketch* sk, double* p)
{
    if (c->shape_count == 0 || !(c->desc.shape_weight > 0.0) || !sk || sk->stroke_count == 0) return false;
    float x[SP_SHAPE_DIM];
    sp_error e = {0};
    if (sp_shape_describe(sk, x, &e) != SP_OK) return false;
    for (int d = 0; d < SP_SHAPE_DIM; ++d)
        x[d] = (x[d] - c->shape_mu[d]) / c->shape_sd[d];
    int k = c->desc.knn < c->shape_count ? c->desc.knn : c->shape_count, near[64];
    double best[64];
    int have = nearest_rows(c->shapes, c->shape_count, SP_SHAPE_DIM, x, k, near, best);
    double total = 0.0;
    for (int i = 0; i < c->category_count; ++i)
        p[i] = SHAPE_FLOOR;
    for (int j = 0; j < have; ++j)
        p[c->shape_labels[near[j]]] += exp(-(best[j] - best[0]) / (2.0 * (best[0] + 1.0)));
    for (int i = 0; i < c->category_count; ++i)
        total += p[i];
    for (int i = 0; i < c->category_count; ++i)
        p[i] /= total;
    return true;
}

// The picture evidence's share per category (`p`, category_count, sums to 1):
// the knn training pictures nearest, weighted by a kernel of the training
// set's typical nearest distance, as the histogram votes are. False without
// picture evidence.
static bool picture_shares(const sp_clf* c, const sp_sketch* sk, double* p)
{
    if (c->pic_count == 0 || !(c->desc.picture_weight > 0.0) || !sk || sk->stroke_count == 0) return false;
    float x[SP_PICTURE_DIM];
    sp_error e = {0};
    if (sp_picture_describe(sk, false, x, &e) != SP_OK) return false;
    int k = c->desc.knn < c->pic_count ? c->desc.knn : c->pic_count, near[64];
    double best[64];
    int have = nearest_rows(c->pics, c->pic_count, SP_PICTURE_DIM, x, k, near, best);
    const double inv = 1.0 / (2.0 * (double)c->pic_bandwidth * c->pic_bandwidth);
    double total = 0.0;
    for (int i = 0; i < c->category_count; ++i)
        p[i] = 0.0;
    for (int j = 0; j < have; ++j) {
        double w = exp(-(best[j] - best[0]) * inv);
        p[c->pic_labels[near[j]]] += w;
        total += w;
    }
    for (int i = 0; i < c->category_count; ++i)
        p[i] = total > 0.0 ? p[i] / total : 1.0 / c->category_count;
    return true;
}

// The votes of the nn nearest training histograms; with `shape` or `pic`
// (the shape and picture evidence's shares, or NULL) every category's score
// is its vote share (plus the floor) times its shape share raised to
// shape_weight times its picture share (plus its floor) raised to
// picture_weight, renormalised.
static void vote(const sp_clf* c, const int* idx, const float* d2, int nn, const double* shape, const double* pic,
                 sp_clf_answer* a)
{
    memset(a, 0, sizeof *a);
    float* score = calloc((size_t)c->category_count, sizeof(float));
    a->distance = nn > 0 ? sqrtf(fmaxf(d2[0], 0.0f)) : INFINITY;
    a->reject_distance = c->reject;
    a->rejected = !(a->distance <= c->reject);
    if (!score) return;
    const float inv = 1.0f / (2.0f * c->bandwidth * c->bandwidth);
    double total = 0.0;
    for (int j = 0; j < nn; ++j) {
        if (idx[j] < 0 || idx[j] >= c->train_count) continue;
        float w = expf(-(fmaxf(d2[j], 0.0f) - fmaxf(d2[0], 0.0f)) * inv);
        score[c->labels[idx[j]]] += w;
        total += w;
    }
    if ((shape || pic) && total > 0.0) {
        double fused = 0.0;
        for (int k = 0; k < c->category_count; ++k) {
            double f = score[k] / total + FUSE_VOTE_FLOOR;
            if (shape) f *= pow(shape[k], c->desc.shape_weight);
            if (pic) f *= pow(pic[k] + PICTURE_FLOOR, c->desc.picture_weight);
            fused += score[k] = (float)f;
        }
        total = fused;
    }
    for (int r = 0; r < SP_CLF_MAX_RANKED; ++r) {
        int best = -1;
        for (int k = 0; k < c->category_count; ++k)
            if (score[k] > 0.0f && (best < 0 || score[k] > score[best])) best = k;
        if (best < 0) break;
        a->ranked[a->count++] = (sp_clf_rank){best, total > 0 ? (float)(score[best] / total) : 0.0f};
        score[best] = 0.0f;
    }
    free(score);
}

typedef struct bound {
    float d2; // squared distance over the whole-drawing level
    int i;
} bound;

static int cmp_bound(const void* a, const void* b)
{
    const bound *x = a, *y = b;
    if (x->d2 != y->d2) return x->d2 < y->d2 ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

typedef float v4f __attribute__((vector_size(16)));

// Squared L2 distance of n floats; INFINITY as soon as it exceeds stop.
static float dist2(const float* a, const float* b, int n, float stop)
{
    int d = 0;
    float s = 0.0f;
    for (; d + 64 <= n; d += 64) {
        v4f acc[4] = {{0}, {0}, {0}, {0}};
        for (int k = 0; k < 64; k += 16)
            for (int l = 0; l < 4; ++l) {
                v4f x, y;
                memcpy(&x, a + d + k + 4 * l, sizeof x);
                memcpy(&y, b + d + k + 4 * l, sizeof y);
                v4f e = x - y;
                acc[l] += e * e;
            }
        v4f t = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        s += (t[0] + t[1]) + (t[2] + t[3]);
        if (s > stop) return INFINITY; // past the k-th best: not a neighbour
    }
    for (; d < n; ++d)
        s += (a[d] - b[d]) * (a[d] - b[d]);
    return s;
}

// Candidates searched in full: the drawings nearest on the whole-drawing level.
#define SHORTLIST_MIN 256
#define SHORTLIST_PER_NEIGHBOUR 32

// Moves the m smallest bounds (m < n) to the front of b, in no order (quickselect).
static void select_smallest(bound* b, int n, int m)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        bound pivot = b[lo + (hi - lo) / 2];
        int i = lo, j = hi;
        while (i <= j) {
            while (cmp_bound(&b[i], &pivot) < 0)
                ++i;
            while (cmp_bound(&b[j], &pivot) > 0)
                --j;
            if (i <= j) {
                bound t = b[i];
                b[i++] = b[j];
                b[j--] = t;
            }
        }
        if (m - 1 <= j)
            hi = j;
        else if (m - 1 >= i)
            lo = i;
        else
            break;
    }
}

// Squared distance of two coarse histograms (n a multiple of 8).
static int64_t coarse_dist2(const int16_t* a, const int16_t* b, int n)
{
#ifdef __SSE2__
    __m128i acc = _mm_setzero_si128();
    for (int d = 0; d < n; d += 8) {
        __m128i e = _mm_sub_epi16(_mm_loadu_si128((const __m128i*)(a + d)), _mm_loadu_si128((const __m128i*)(b + d)));
        __m128i sq = _mm_madd_epi16(e, e); // 4 sums of two squares (< 2^29 each)
        acc = _mm_add_epi64(acc, _mm_unpacklo_epi32(sq, _mm_setzero_si128()));
        acc = _mm_add_epi64(acc, _mm_unpackhi_epi32(sq, _mm_setzero_si128()));
    }
    int64_t lanes[2];
    _mm_storeu_si128((__m128i*)lanes, acc);
    return lanes[0] + lanes[1];
#else
    int64_t s = 0;
    for (int d = 0; d < n; ++d)
        s += (int32_t)(a[d] - b[d]) * (int32_t)(a[d] - b[d]);
    return s;
#endif
}

// The k nearest training histograms. Why not FLANN's linear search: it reads
// every training histogram whole (quickdraw fold: 4000 x 2500 floats, 40 MB;
// about half the time of a classification). The distance over the first
// pyramid level (the whole drawing, a fifth of the data) ranks the true
// neighbours early: on quickdraw fold 0 the 8 true neighbours of 480 of 500
// test drawings were among the first 64 by that distance, and of all 500 among
// the first 256. So candidates are shortlisted on that level (quantised, 4 MB:
// cache-resident) and only the SHORTLIST_MIN (or 32 per neighbour) nearest get
// full distances, each giving up once past the k-th best. Ties: the lower
// index. Large sets (> HIST_KDTREE_MIN) use FLANN's kd-tree instead.
static sp_result knn_shortlist(const sp_clf* c, const float* q, int nn, int* idx, float* d2, sp_error* err)
{
    const int n = c->train_count, dim = c->hist_dim, cs = c->coarse_stride;
    bound* b = malloc(sizeof(bound) * (size_t)n);
    int16_t* qc = malloc(sizeof(int16_t) * (size_t)cs);
    if (!b || !qc) {
        free(b);
        free(qc);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    quantise_coarse(c, q, qc);
    for (int i = 0; i < n; ++i)
        b[i] = (bound){(float)coarse_dist2(qc, c->coarse + (size_t)i * cs, cs), i};
    int m = nn * SHORTLIST_PER_NEIGHBOUR > SHORTLIST_MIN ? nn * SHORTLIST_PER_NEIGHBOUR : SHORTLIST_MIN;
    if (m < n)
        select_smallest(b, n, m);
    else
        m = n;
    qsort(b, (size_t)m, sizeof(bound), cmp_bound); // nearest first: the k-th best tightens early
    int have = 0;
    for (int j = 0; j < m; ++j) {
        float worst = have == nn ? d2[nn - 1] : INFINITY;
        int i = b[j].i;
        float d = dist2(q, c->hists + (size_t)i * dim, dim, worst);
        if (!(d < worst) && !(d == worst && have == nn && i < idx[nn - 1])) continue;
        int k = have < nn ? have++ : nn - 1;
        while (k > 0 && (d2[k - 1] > d || (d2[k - 1] == d && idx[k - 1] > i))) {
            d2[k] = d2[k - 1];
            idx[k] = idx[k - 1];
            --k;
        }
        d2[k] = d;
        idx[k] = i;
    }
    free(b);
    free(qc);
    return SP_OK;
}

static sp_result classify_hist(const sp_clf* c, float* hist, const double* shape, const double* pic, sp_clf_answer* out,
                               sp_error* err)
{
    int nn = c->desc.knn < c->train_count ? c->desc.knn : c->train_count;
    int idx[64];
    float d2[64];
    if (!c->hist_index) {
        sp_result rc = knn_shortlist(c, hist, nn, idx, d2, err);
        if (rc != SP_OK) return rc;
    } else {
        struct FLANNParameters p = c->hist_params;
        if (flann_find_nearest_neighbors_index_float(c->hist_index, hist, 1, idx, d2, nn, &p) < 0)
            return sp_fail(err, SP_ERR_INTERNAL, "FLANN: histogram search failed");
    }
    vote(c, idx, d2, nn, shape, pic, out);
    return SP_OK;
}

sp_result sp_clf_classify(const sp_clf* c, const sp_sketch* sketch, const sp_raster* raster, sp_clf_answer* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    clf_work* w = work_take(c);
    sp_features* f = w ? &w->f : NULL;
    float* raw = malloc(sizeof(float) * (size_t)c->hist_dim * 2);
    double* shape = malloc(sizeof(double) * (size_t)c->category_count * 2);
    sp_result rc = (!w || !raw || !shape) ? sp_fail(err, SP_ERR_NO_MEMORY, "out of memory") : SP_OK;
    if (rc == SP_OK) rc = sp_feat_extract(sketch, raster, &w->scratch, f, err);
    if (rc == SP_OK) rc = raw_hist(c, f, raw, err);
    if (rc == SP_OK) {
        finish_hist(c, raw, raw + c->hist_dim);
        double* pic = shape + c->category_count;
        bool strokes = sketch && sketch->stroke_count > 0;
        bool shaped = strokes && shape_shares(c, sketch, shape), pictured = strokes && picture_shares(c, sketch, pic);
        rc = classify_hist(c, raw + c->hist_dim, shaped ? shape : NULL, pictured ? pic : NULL, out, err);
    }
    work_give(c, w);
    free(raw);
    free(shape);
    return rc;
}

// ---------------------------------------------------------------------------
// Training

// Training drawings described for the vocabulary sample, and leave-one-out
// queries for the voting bandwidth and reject threshold, at most (larger sets
// are sampled; below these sizes every drawing is used, as before).
#define PASS1_MAX_JOBS 4000
#define LOO_MAX_QUERIES 2000

typedef struct job {
    int sample;  // index into the dataset
    int variant; // 0 original, 1 mirrored, 2.. jittered
} job;

typedef struct train_ctx {
    const sp_dataset* data;
    sp_clf* clf;
    const job* jobs;
    int job_count;
    int per_job;       // pass 1: descriptors kept per drawing
    int stride;        // pass 1 describes every stride-th job only
    float* sample;     // pass 1: (job_count / stride, rounded up) * per_job * 64
    int* sample_n;     // kept per job
    float* raw;        // pass 2: job_count * hist_dim
    sp_result* status; // per job
    sp_error* errs;    // per job
    int pass;
    atomic_int done;
    pthread_mutex_t lock;
} train_ctx;

// The drawing a job trains on: the sample itself, mirrored, or a jittered copy.
static sp_result job_drawing(const train_ctx* t, const job* j, sp_sketch* sk, sp_raster* r, bool* owned)
{
    const sp_sample* s = &t->data->samples[j->sample];
    *owned = false;
    if (j->variant == 0) {
        *sk = s->sketch;
        *r = s->raster;
        return SP_OK;
    }
    *owned = true;
    memset(r, 0, sizeof *r);
    memset(sk, 0, sizeof *sk);
    if (s->sketch.stroke_count == 0) { // raster: only mirroring
        size_t n = (size_t)s->raster.w * s->raster.h;
        r->pixels = malloc(n ? n : 1);
        if (!r->pixels) return SP_ERR_NO_MEMORY;
        r->w = s->raster.w;
        r->h = s->raster.h;
        for (int y = 0; y < r->h; ++y)
            for (int x = 0; x < r->w; ++x)
                r->pixels[(size_t)y * r->w + x] = s->raster.pixels[(size_t)y * r->w + (r->w - 1 - x)];
        return SP_OK;
    }
    if (j->variant >= 2 && t->clf->desc.augment_fn) {
        sp_result rc = t->clf->desc.augment_fn(t->clf->desc.augment_user, &s->sketch, j->sample, j->variant - 2, sk);
        if (rc != SP_OK) sp_sketch_free(sk);
        return rc;
    }
    if (sp_sketch_clone(&s->sketch, sk) != SP_OK) return SP_ERR_NO_MEMORY;
    double m[4] = {-1, 0, 0, 1}; // mirror
    if (j->variant >= 2) {
        uint64_t rng = t->clf->desc.seed * 0x9e3779b97f4a7c15ull ^ ((uint64_t)j->sample << 20) ^ (uint64_t)j->variant;
        clf_rng_next(&rng);
        double ang = (clf_rng_uniform(&rng) * 2 - 1) * 12.0 * M_PI / 180.0;
        double sx = 0.85 + 0.3 * clf_rng_uniform(&rng), sy = 0.85 + 0.3 * clf_rng_uniform(&rng);
        double sh = (clf_rng_uniform(&rng) * 2 - 1) * 0.1;
        double flip = (t->clf->desc.mirror > 0 && clf_rng_uniform(&rng) < 0.5) ? -1.0 : 1.0;
        double cs = cos(ang), sn = sin(ang);
        // R * Shear * S * Flip
        double a = sx * flip, b = sh * sy, d = sy;
        m[0] = cs * a;
        m[1] = cs * b - sn * d;
        m[2] = sn * a;
        m[3] = sn * b + cs * d;
    }
    for (int i = 0; i < sk->stroke_count; ++i)
        for (int k = 0; k < sk->strokes[i].count; ++k) {
            sp_vec2 p = sk->strokes[i].points[k];
            sk->strokes[i].points[k] = (sp_vec2){m[0] * p.x + m[1] * p.y, m[2] * p.x + m[3] * p.y};
        }
    return SP_OK;
}

static int train_job(void* user, int k)
{
    train_ctx* t = user;
    const int i = t->pass == 1 ? k * t->stride : k; // the job; pass 1 keeps its sample at k
    const job* j = &t->jobs[i];
    sp_sketch sk;
    sp_raster r;
    bool owned;
    sp_result rc = job_drawing(t, j, &sk, &r, &owned);
    if (rc != SP_OK) // an augmented copy that could not be made is skipped like a bad drawing
        rc = sp_fail(&t->errs[i], rc, "augmented copy %d: %s", j->variant - 1, sp_result_name(rc));
    clf_work* w = rc == SP_OK ? work_take(t->clf) : NULL;
    sp_features* f = w ? &w->f : NULL;
    if (rc == SP_OK && !w) rc = sp_fail(&t->errs[i], SP_ERR_NO_MEMORY, "out of memory");
    if (rc == SP_OK) rc = sp_feat_extract(&sk, &r, &w->scratch, f, &t->errs[i]);
    if (rc == SP_OK && t->pass == 1) {
        // A seeded partial shuffle picks this drawing's share of the vocabulary sample.
        uint64_t rng = t->clf->desc.seed ^ ((uint64_t)(i + 1) * 0xd1b54a32d192ed03ull);
        int keep = f->count < t->per_job ? f->count : t->per_job;
        int order[SP_FEAT_MAX];
        for (int k = 0; k < f->count; ++k)
            order[k] = k;
        for (int k = 0; k < keep; ++k) {
            int o = k + (int)(clf_rng_next(&rng) % (uint64_t)(f->count - k));
            int tmp = order[k];
            order[k] = order[o];
            order[o] = tmp;
            memcpy(t->sample + ((size_t)i / (size_t)t->stride * t->per_job + k) * SP_FEAT_DIM,
                   f->desc + (size_t)order[k] * SP_FEAT_DIM, sizeof(float) * SP_FEAT_DIM);
        }
        t->sample_n[i] = keep;
    } else if (rc == SP_OK) {
        rc = raw_hist(t->clf, f, t->raw + (size_t)i * t->clf->hist_dim, &t->errs[i]);
    }
    work_give(t->clf, w);
    if (owned) {
        sp_sketch_free(&sk);
        sp_raster_free(&r);
    }
    t->status[i] = rc;
    int done = atomic_fetch_add(&t->done, 1) + 1;
    if (t->clf->desc.progress) {
        pthread_mutex_lock(&t->lock);
        t->clf->desc.progress(t->clf->desc.progress_user, t->pass == 1 ? "descriptors" : "histograms", done,
                              t->pass == 1 ? (t->job_count + t->stride - 1) / t->stride : t->job_count);
        pthread_mutex_unlock(&t->lock);
    }
    // Bad drawings (empty, NaN) are skipped; running out of memory or a library failure stops training.
    return rc == SP_ERR_NO_MEMORY || rc == SP_ERR_INTERNAL ? (int)rc : 0;
}

typedef struct loo_ctx {
    const sp_clf* c;
    const int* src;
    const int* queries; // histogram indices asked about
    int query_count;
    const float* norms; // squared norm of every training histogram
    float* out;         // per training histogram: distance to the nearest other drawing, -1 if not asked
} loo_ctx;

#define LOO_BLOCK 128

// One block of leave-one-out queries: exact distances to every training
// histogram from dot products (OpenCV's gemm; FLANN's linear search is far
// slower on tens of thousands of histograms: BENCHMARKS.md, "Classifier
// training"), the nearest that is another drawing.
static int loo_block(void* user, int b)
{
    loo_ctx* l = user;
    const sp_clf* c = l->c;
    const int n = c->train_count, dim = c->hist_dim;
    int first = b * LOO_BLOCK, m = l->query_count - first < LOO_BLOCK ? l->query_count - first : LOO_BLOCK;
    float* q = calloc((size_t)m * dim, sizeof(float));
    float* dots = malloc(sizeof(float) * (size_t)m * n);
    sp_error e = {0};
    int rc = !q || !dots ? SP_ERR_NO_MEMORY : 0;
    for (int k = 0; !rc && k < m; ++k)
        memcpy(q + (size_t)k * dim, c->hists + (size_t)l->queries[first + k] * dim, sizeof(float) * (size_t)dim);
    // n by m (the small block is the transposed operand: transposing all
    // training histograms for every block cost more than the products).
    if (!rc) rc = (int)sp_cv_dot_rows(c->hists, n, q, m, dim, dots, &e);
    float best[LOO_BLOCK];
    for (int k = 0; k < m; ++k)
        best[k] = INFINITY;
    for (int j = 0; !rc && j < n; ++j) {
        const float* row = dots + (size_t)j * m;
        for (int k = 0; k < m; ++k) {
            int i = l->queries[first + k];
            if (l->src[j] != l->src[i]) best[k] = fminf(best[k], l->norms[i] + l->norms[j] - 2.0f * row[k]);
        }
    }
    for (int k = 0; !rc && k < m; ++k)
        l->out[l->queries[first + k]] = isfinite(best[k]) ? sqrtf(fmaxf(best[k], 0.0f)) : -1.0f;
    free(q);
    free(dots);
    return rc;
}

// The shape descriptors of the training stroke drawings (originals: the
// descriptor is mirror-invariant), standardised per value over them.
static sp_result train_shapes(sp_clf* c, const sp_dataset* data, const unsigned char* use, sp_error* err)
{
    for (int d = 0; d < SP_SHAPE_DIM; ++d)
        c->shape_sd[d] = 1.0f;
    if (!(c->desc.shape_weight > 0.0)) return SP_OK;
    c->shapes = malloc(sizeof(float) * SP_SHAPE_DIM * (size_t)(data->count ? data->count : 1));
    c->shape_labels = malloc(sizeof(int) * (size_t)(data->count ? data->count : 1));
    if (!c->shapes || !c->shape_labels) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while training");
    int n = 0;
    for (int i = 0; i < data->count; ++i) {
        const sp_sample* s = &data->samples[i];
        if ((use && !use[i]) || s->label < 0 || s->label >= data->category_count || s->sketch.stroke_count == 0) continue;
        sp_error e = {0};
        if (sp_shape_describe(&s->sketch, c->shapes + (size_t)n * SP_SHAPE_DIM, &e) != SP_OK) continue;
        c->shape_labels[n++] = s->label;
    }
    if (n == 0) return SP_OK; // raster drawings only: the votes alone rank
    double mu[SP_SHAPE_DIM] = {0}, var[SP_SHAPE_DIM] = {0};
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < SP_SHAPE_DIM; ++d)
            mu[d] += c->shapes[(size_t)i * SP_SHAPE_DIM + d] / n;
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < SP_SHAPE_DIM; ++d) {
            double v = c->shapes[(size_t)i * SP_SHAPE_DIM + d] - mu[d];
            var[d] += v * v / n;
        }
    for (int d = 0; d < SP_SHAPE_DIM; ++d) {
        c->shape_mu[d] = (float)mu[d];
        c->shape_sd[d] = (float)fmax(sqrt(var[d]), 1e-3); // a value all drawings share weighs nothing, not infinitely much
    }
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < SP_SHAPE_DIM; ++d) {
            float* v = &c->shapes[(size_t)i * SP_SHAPE_DIM + d];
            *v = (*v - c->shape_mu[d]) / c->shape_sd[d];
        }
    c->shape_count = n;
    return SP_OK;
}

// Runs pass 1 or 2 of training over `count` jobs (see train_job). Only running
// out of memory or a library failure stops it: the first job that did names its drawing.
static sp_result train_pass(train_ctx* t, int pass, int count, sp_error* err)
{
    t->pass = pass;
    atomic_store(&t->done, 0);
    int bad = sp_parallel_for(count, t->clf->desc.threads, train_job, t);
    if (!bad) return SP_OK;
    for (int i = 0; i < t->job_count; ++i)
        if (t->status[i] == (sp_result)bad)
            return sp_fail(err, (sp_result)bad, "training drawing %d: %s", t->jobs[i].sample, t->errs[i].text);
    return sp_fail(err, (sp_result)bad, "training: %s", sp_result_name((sp_result)bad));
}

// Leave-one-out queries for the picture evidence's bandwidth at most: the
// median nearest distance of a few hundred drawings is as good as of all.
#define PICTURE_LOO_MAX 512

typedef struct picture_loo_ctx {
    const sp_clf* c;
    const int* src;     // per picture: its drawing
    int count;          // pictures
    const int* queries; // pictures asked about
    double* near;       // per query: distance to the nearest picture of another drawing (-1: none)
} picture_loo_ctx;

static int picture_loo_one(void* user, int q)
{
    const picture_loo_ctx* k = user;
    const int i = k->queries[q];
    const float* x = k->c->pics + (size_t)i * SP_PICTURE_DIM;
    double best = INFINITY;
    for (int j = 0; j < k->count; ++j) {
        if (k->src[j] == k->src[i]) continue;
        double s2 = dist2(k->c->pics + (size_t)j * SP_PICTURE_DIM, x, SP_PICTURE_DIM, (float)best);
        if (s2 < best) best = s2;
    }
    k->near[q] = isfinite(best) ? sqrt(best) : -1.0;
    return 0;
}

// The pictures of the training stroke drawings (and, with `mirror`, of them
// mirrored), and the voting bandwidth: the median distance from a drawing to
// the nearest picture of another drawing.
static sp_result train_pictures(sp_clf* c, const sp_dataset* data, const unsigned char* use, sp_error* err)
{
    if (!(c->desc.picture_weight > 0.0)) return SP_OK;
    const int per = c->desc.mirror > 0 ? 2 : 1;
    size_t cap = (size_t)(data->count ? data->count : 1) * per;
    c->pics = malloc(sizeof(float) * SP_PICTURE_DIM * cap);
    c->pic_labels = malloc(sizeof(int) * cap);
    int* src = malloc(sizeof(int) * cap);
    int* queries = malloc(sizeof(int) * cap);
    double* near = malloc(sizeof(double) * cap);
    if (!c->pics || !c->pic_labels || !src || !queries || !near) {
        free(src), free(queries), free(near);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while training");
    }
    int n = 0;
    for (int i = 0; i < data->count; ++i) {
        const sp_sample* s = &data->samples[i];
        if ((use && !use[i]) || s->label < 0 || s->label >= data->category_count || s->sketch.stroke_count == 0) continue;
        for (int m = 0; m < per; ++m) {
            sp_error e = {0};
            if (sp_picture_describe(&s->sketch, m == 1, c->pics + (size_t)n * SP_PICTURE_DIM, &e) != SP_OK) break;
            c->pic_labels[n] = s->label;
            src[n++] = i;
        }
    }
    // Every stride-th original drawing asks for its nearest picture of another drawing.
    int originals = 0, nq = 0, q = 0;
    for (int i = 0; i < n; ++i)
        originals += i == 0 || src[i] != src[i - 1];
    int stride = (originals + PICTURE_LOO_MAX - 1) / PICTURE_LOO_MAX;
    for (int i = 0; i < n; ++i)
        if ((i == 0 || src[i] != src[i - 1]) && q++ % (stride > 0 ? stride : 1) == 0) queries[nq++] = i;
    picture_loo_ctx k = {c, src, n, queries, near};
    sp_parallel_for(nq, c->desc.threads, picture_loo_one, &k);
    int m = 0;
    for (int i = 0; i < nq; ++i)
        if (near[i] >= 0.0) near[m++] = near[i];
    if (m > 0) {
        qsort(near, (size_t)m, sizeof(double), sp_cmp_double);
        c->pic_bandwidth = (float)fmax(near[m / 2], 1e-4);
    } else {
        c->pic_bandwidth = 1.0f;
    }
    free(src), free(queries), free(near);
    c->pic_count = n;
    return SP_OK;
}

// Soft-assignment width: the median distance of a descriptor to its nearest word.
static sp_result soft_width(sp_clf* c, const float* sample, int total)
{
    int* idx = malloc(sizeof(int) * (size_t)total);
    float* d2 = malloc(sizeof(float) * (size_t)total);
    if (!idx || !d2) {
        free(idx);
        free(d2);
        return SP_ERR_NO_MEMORY;
    }
    sp_nearest_words(c->vocab, c->vnorm, c->words, sample, total, 1, idx, d2);
    qsort(d2, (size_t)total, sizeof(float), sp_cmp_float);
    c->sigma = sqrtf(fmaxf(d2[total / 2], 0.0f));
    if (!(c->sigma > 1e-3f)) c->sigma = 1e-3f;
    free(idx);
    free(d2);
    return SP_OK;
}

// Leave-one-out nearest distances (another drawing, not a variant of the same one)
// give the voting bandwidth (median) and the reject threshold (quantile).
static sp_result calibrate_distances(sp_clf* c, const int* src, int n, sp_error* err)
{
    float* loo = malloc(sizeof(float) * (size_t)n);
    int* queries = malloc(sizeof(int) * (size_t)n);
    float* norms = malloc(sizeof(float) * (size_t)n);
    if (!loo || !queries || !norms) {
        free(loo);
        free(queries);
        free(norms);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while training");
    }
    // Why a sample: exact leave-one-out over n drawings costs n^2 histogram
    // distances (20000 drawings: minutes); a few thousand queries give the
    // median and the reject quantile just as well (a quickdraw 5-fold
    // training set, 2000 drawings, is still done exactly).
    int originals = 0;
    for (int i = 0; i < n; ++i)
        originals += i == 0 || src[i] != src[i - 1];
    int stride = (originals + LOO_MAX_QUERIES - 1) / LOO_MAX_QUERIES, nq = 0;
    for (int i = 0; i < n; ++i) {
        loo[i] = -1.0f;
        double s2 = 0.0;
        for (int d = 0; d < c->hist_dim; ++d)
            s2 += (double)c->hists[(size_t)i * c->hist_dim + d] * c->hists[(size_t)i * c->hist_dim + d];
        norms[i] = (float)s2;
        if (i > 0 && src[i] == src[i - 1]) continue; // one query per original drawing, not its variants
        uint64_t h = (uint64_t)src[i] ^ ((uint64_t)c->desc.seed << 32);
        if (stride > 1 && clf_rng_next(&h) % (uint64_t)stride != 0) continue;
        queries[nq++] = i;
    }
    loo_ctx lc = {c, src, queries, nq, norms, loo};
    int bad = sp_parallel_for((nq + LOO_BLOCK - 1) / LOO_BLOCK, c->desc.threads, loo_block, &lc);
    free(queries);
    free(norms);
    if (bad) {
        free(loo);
        return sp_fail(err, (sp_result)bad, "leave-one-out distances: %s", sp_result_name((sp_result)bad));
    }
    int m = 0;
    for (int i = 0; i < n; ++i)
        if (loo[i] >= 0.0f) loo[m++] = loo[i];
    if (m > 0) {
        qsort(loo, (size_t)m, sizeof(float), sp_cmp_float);
        c->bandwidth = fmaxf(loo[m / 2], 1e-4f);
        int qi = (int)ceil(c->desc.reject_quantile * m) - 1;
        if (qi < 0) qi = 0;
        if (qi >= m) qi = m - 1;
        c->reject = c->desc.reject_quantile >= 1.0 ? INFINITY : loo[qi];
    } else {
        c->bandwidth = 1.0f;
        c->reject = INFINITY;
    }
    free(loo);
    return SP_OK;
}

sp_result sp_clf_train(const sp_dataset* data, const unsigned char* use, const sp_clf_desc* desc, sp_clf** out, sp_error* err)
{
    *out = NULL;
    sp_clf* c = calloc(1, sizeof *c);
    train_ctx t = {.data = data, .clf = c};
    atomic_init(&t.done, 0);
    job* jobs = NULL;
    sp_result rc = SP_OK;
    float* sample = NULL;
    int* src = NULL;
    if (!c) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    c->desc = sp_clf_desc_defaults(desc);
    pthread_mutex_init(&t.lock, NULL);
    c->categories = calloc((size_t)(data->category_count ? data->category_count : 1), sizeof(char*));
    if (!c->categories) goto oom;
    for (int i = 0; i < data->category_count; ++i) {
        if (!(c->categories[i] = strdup(data->categories[i]))) goto oom;
        c->category_count = i + 1;
    }
    int per_sample = 1 + (c->desc.mirror > 0) + c->desc.augment;
    jobs = malloc(sizeof(job) * (size_t)(data->count ? data->count : 1) * per_sample);
    if (!jobs) goto oom;
    int nj = 0;
    for (int i = 0; i < data->count; ++i) {
        const sp_sample* s = &data->samples[i];
        if ((use && !use[i]) || s->label < 0 || s->label >= data->category_count) continue;
        jobs[nj++] = (job){i, 0};
        if (c->desc.mirror > 0) jobs[nj++] = (job){i, 1};
        if (s->sketch.stroke_count > 0)
            for (int a = 0; a < c->desc.augment; ++a)
                jobs[nj++] = (job){i, 2 + a};
    }
    if (nj == 0) {
        rc = sp_fail(err, SP_ERR_INVALID, "no training drawings");
        goto fail;
    }
    t.jobs = jobs;
    t.job_count = nj;
    // Why a stride: the vocabulary needs vocab_samples descriptors, which a few
    // thousand drawings give; describing every drawing of a large set twice
    // (here and for the histograms) doubled the training time for nothing.
    t.stride = (nj + PASS1_MAX_JOBS - 1) / PASS1_MAX_JOBS;
    const int n1 = (nj + t.stride - 1) / t.stride;
    t.per_job = (c->desc.vocab_samples + n1 - 1) / n1;
    if (t.per_job > SP_FEAT_MAX) t.per_job = SP_FEAT_MAX;
    t.sample = malloc(sizeof(float) * (size_t)n1 * t.per_job * SP_FEAT_DIM);
    t.sample_n = calloc((size_t)nj, sizeof(int));
    t.status = calloc((size_t)nj, sizeof(sp_result));
    t.errs = calloc((size_t)nj, sizeof(sp_error));
    if (!t.sample || !t.sample_n || !t.status || !t.errs) goto oom;

    // Pass 1: a sample of descriptors for the vocabulary.
    if ((rc = train_pass(&t, 1, n1, err)) != SP_OK) goto fail;
    int total = 0;
    for (int i = 0; i < nj; ++i)
        total += t.status[i] == SP_OK ? t.sample_n[i] : 0;
    if (total == 0) {
        rc = sp_fail(err, SP_ERR_INVALID, "no training drawing has any ink (first problem: %s)", t.errs[0].text);
        goto fail;
    }
    sample = malloc(sizeof(float) * (size_t)total * SP_FEAT_DIM);
    if (!sample) goto oom;
    int at = 0;
    for (int k = 0; k < n1; ++k) {
        int i = k * t.stride;
        if (t.status[i] != SP_OK) continue;
        memcpy(sample + (size_t)at * SP_FEAT_DIM, t.sample + (size_t)k * t.per_job * SP_FEAT_DIM,
               sizeof(float) * SP_FEAT_DIM * (size_t)t.sample_n[i]);
        at += t.sample_n[i];
    }
    free(t.sample);
    t.sample = NULL;

    c->words = c->desc.words < total ? c->desc.words : total;
    c->vocab = malloc(sizeof(float) * (size_t)c->words * SP_FEAT_DIM);
    if (!c->vocab) goto oom;
    if (c->desc.progress) c->desc.progress(c->desc.progress_user, "vocabulary", 0, 1);
    rc = sp_kmeans(sample, total, SP_FEAT_DIM, c->words, c->desc.seed, c->desc.kmeans_iterations, c->desc.threads, c->vocab, err);
    if (rc != SP_OK) goto fail;
    if ((rc = vocab_norms(c, err)) != SP_OK) goto fail;
    if ((rc = soft_width(c, sample, total)) != SP_OK) goto oom;
    if (c->desc.progress) c->desc.progress(c->desc.progress_user, "vocabulary", 1, 1);
    free(sample);
    sample = NULL;

    // Pass 2: histograms.
    c->hist_dim = c->words * pyramid_cells(c->desc.pyramid);
    t.raw = malloc(sizeof(float) * (size_t)nj * c->hist_dim);
    if (!t.raw) goto oom;
    if ((rc = train_pass(&t, 2, nj, err)) != SP_OK) goto fail;
    int n = 0;
    for (int i = 0; i < nj; ++i)
        n += t.status[i] == SP_OK;
    if (c->desc.tfidf > 0) {
        c->idf = calloc((size_t)c->words, sizeof(float));
        if (!c->idf) goto oom;
        for (int i = 0; i < nj; ++i) {
            if (t.status[i] != SP_OK) continue;
            const float* r = t.raw + (size_t)i * c->hist_dim;
            for (int w = 0; w < c->words; ++w)
                c->idf[w] += r[w] > 0.5f;
        }
        for (int w = 0; w < c->words; ++w)
            c->idf[w] = fmaxf(logf((float)n / (1.0f + c->idf[w])), 0.05f);
    }
    c->hists = malloc(sizeof(float) * (size_t)n * c->hist_dim);
    c->labels = malloc(sizeof(int) * (size_t)n);
    src = malloc(sizeof(int) * (size_t)n);
    if (!c->hists || !c->labels || !src) goto oom;
    int k = 0;
    for (int i = 0; i < nj; ++i) {
        if (t.status[i] != SP_OK) continue;
        finish_hist(c, t.raw + (size_t)i * c->hist_dim, c->hists + (size_t)k * c->hist_dim);
        c->labels[k] = data->samples[jobs[i].sample].label;
        src[k++] = jobs[i].sample;
    }
    c->train_count = n;
    if ((rc = build_hist_index(c, err)) != SP_OK) goto fail;
    if ((rc = train_shapes(c, data, use, err)) != SP_OK) goto fail;
    if ((rc = train_pictures(c, data, use, err)) != SP_OK) goto fail;

    if ((rc = calibrate_distances(c, src, n, err)) != SP_OK) goto fail;
    c->desc.progress = NULL;
    c->desc.progress_user = NULL;
    c->desc.augment_fn = NULL;
    c->desc.augment_user = NULL;
    *out = c;
    c = NULL;
    goto fail; // shared cleanup
oom:
    rc = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while training");
fail:
    pthread_mutex_destroy(&t.lock);
    free(jobs);
    free(t.sample);
    free(t.sample_n);
    free(t.status);
    free(t.errs);
    free(t.raw);
    free(sample);
    free(src);
    sp_clf_destroy(c);
    return rc;
}

// ---------------------------------------------------------------------------
// Reject threshold calibration on held-out drawings

typedef struct calib_ctx {
    const sp_clf* c;
    const sp_dataset* data;
    const unsigned char* use;
    float* dist; // per sample, -1 when skipped or not drawable
} calib_ctx;

static int calib_one(void* user, int i)
{
    calib_ctx* k = user;
    k->dist[i] = -1.0f;
    if (k->use && !k->use[i]) return 0;
    const sp_sample* s = &k->data->samples[i];
    sp_clf_answer a;
    sp_error e = {0};
    sp_result r = sp_clf_classify(k->c, &s->sketch, &s->raster, &a, &e);
    if (r == SP_OK) k->dist[i] = a.distance;
    return r == SP_ERR_NO_MEMORY || r == SP_ERR_INTERNAL ? (int)r : 0; // a bad drawing is only skipped
}

float sp_clf_reject_distance(const sp_clf* clf)
{
    return clf->reject;
}

sp_result sp_clf_calibrate_reject(sp_clf* c, const sp_dataset* held_out, const unsigned char* use, double quantile, double margin,
                                  float* distances, int* count, sp_error* err)
{
    if (count) *count = 0;
    if (!(quantile > 0.0 && quantile <= 1.0))
        return sp_fail(err, SP_ERR_INVALID, "calibration quantile %g is not in (0, 1]", quantile);
    if (margin == 0.0) margin = 1.0;
    if (!(margin >= 1.0 && isfinite(margin))) return sp_fail(err, SP_ERR_INVALID, "calibration margin %g is not >= 1", margin);
    float* d = malloc(sizeof(float) * (size_t)(held_out->count > 0 ? held_out->count : 1));
    if (!d) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    calib_ctx k = {c, held_out, use, d};
    int bad = sp_parallel_for(held_out->count, c->desc.threads, calib_one, &k);
    if (bad) {
        free(d);
        return sp_fail(err, (sp_result)bad, "calibration: %s", sp_result_name((sp_result)bad));
    }
    int m = 0;
    for (int i = 0; i < held_out->count; ++i)
        if (d[i] >= 0.0f && isfinite(d[i])) d[m++] = d[i];
    if (m == 0) {
        free(d);
        return sp_fail(err, SP_ERR_INVALID, "calibration: no usable held-out drawing");
    }
    qsort(d, (size_t)m, sizeof(float), sp_cmp_float);
    int qi = (int)ceil(quantile * m) - 1;
    if (qi < 0) qi = 0;
    if (qi >= m) qi = m - 1;
    c->reject = (float)(d[qi] * margin);
    if (distances) memcpy(distances, d, sizeof(float) * (size_t)m);
    if (count) *count = m;
    free(d);
    return SP_OK;
}

// ---------------------------------------------------------------------------
// Model file: "SPCLFMDL", u32 version, u32 byte-order mark, u64 payload bytes,
// payload, u64 FNV-1a of the payload. Host byte order (the mark refuses others).

static const char k_magic[8] = {'S', 'P', 'C', 'L', 'F', 'M', 'D', 'L'};
#define SP_CLF_BOM 0x01020304u

typedef struct wbuf {
    unsigned char* p;
    size_t n, cap;
    bool oom;
} wbuf;

static void put(wbuf* b, const void* v, size_t n)
{
    if (b->oom || n == 0) return; // n == 0: v may be NULL (a model without shape evidence)
    if (b->n + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->n + n)
            cap *= 2;
        unsigned char* g = realloc(b->p, cap);
        if (!g) {
            b->oom = true;
            return;
        }
        b->p = g;
        b->cap = cap;
    }
    memcpy(b->p + b->n, v, n);
    b->n += n;
}
static void put_i32(wbuf* b, int32_t v)
{
    put(b, &v, 4);
}
static void put_f32(wbuf* b, float v)
{
    put(b, &v, 4);
}
static void put_f64(wbuf* b, double v)
{
    put(b, &v, 8);
}

sp_result sp_clf_to_bytes(const sp_clf* c, void** bytes, size_t* size, sp_error* err)
{
    *bytes = NULL, *size = 0;
    wbuf b = {0};
    const size_t head = 24; // magic, version, byte order, body length: filled in once the body is known
    put(&b, (const unsigned char[24]){0}, head);
    const sp_clf_desc* d = &c->desc;
    int32_t ints[] = {d->words, d->vocab_samples, d->kmeans_iterations, d->soft_neighbours, d->knn, d->pyramid,
                      d->tfidf, d->hellinger, d->mirror, d->augment, (int32_t)d->seed,
                      0 /* threads: the model does not depend on them */};
    put_i32(&b, (int32_t)(sizeof ints / sizeof ints[0]));
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; ++i)
        put_i32(&b, ints[i]);
    put_f64(&b, d->reject_quantile);
    put_i32(&b, c->category_count);
    for (int i = 0; i < c->category_count; ++i) {
        int32_t l = (int32_t)strlen(c->categories[i]);
        put_i32(&b, l);
        put(&b, c->categories[i], (size_t)l);
    }
    put_i32(&b, c->words);
    put_i32(&b, SP_FEAT_DIM);
    put(&b, c->vocab, sizeof(float) * (size_t)c->words * SP_FEAT_DIM);
    put_f32(&b, c->sigma);
    put_i32(&b, c->hist_dim);
    put_i32(&b, c->idf != NULL);
    if (c->idf) put(&b, c->idf, sizeof(float) * (size_t)c->words);
    put_i32(&b, c->train_count);
    put(&b, c->hists, sizeof(float) * (size_t)c->train_count * c->hist_dim);
    put(&b, c->labels, sizeof(int32_t) * (size_t)c->train_count);
    put_f32(&b, c->bandwidth);
    put_f32(&b, c->reject);
    put_f64(&b, d->shape_weight);
    put_i32(&b, c->shape_count);
    put_i32(&b, SP_SHAPE_DIM);
    put(&b, c->shape_mu, sizeof c->shape_mu);
    put(&b, c->shape_sd, sizeof c->shape_sd);
    put(&b, c->shapes, sizeof(float) * (size_t)c->shape_count * SP_SHAPE_DIM);
    put(&b, c->shape_labels, sizeof(int32_t) * (size_t)c->shape_count);
    put_f64(&b, d->picture_weight);
    put_i32(&b, c->pic_count);
    put_i32(&b, SP_PICTURE_DIM);
    put_f32(&b, c->pic_bandwidth);
    put(&b, c->pics, sizeof(float) * (size_t)c->pic_count * SP_PICTURE_DIM);
    put(&b, c->pic_labels, sizeof(int32_t) * (size_t)c->pic_count);
    uint32_t version = SP_CLF_FILE_VERSION, bom = SP_CLF_BOM;
    uint64_t len = b.n - head, sum = b.oom ? 0 : sp_clf_checksum(b.p + head, len);
    put(&b, &sum, 8);
    if (b.oom) {
        free(b.p);
        return sp_fail(err, SP_ERR_NO_MEMORY, "classifier model: out of memory");
    }
    memcpy(b.p, k_magic, 8);
    memcpy(b.p + 8, &version, 4);
    memcpy(b.p + 12, &bom, 4);
    memcpy(b.p + 16, &len, 8);
    *bytes = b.p, *size = b.n;
    return SP_OK;
}

sp_result sp_clf_save(const sp_clf* c, const char* path, sp_error* err)
{
    void* bytes;
    size_t size;
    sp_result r = sp_clf_to_bytes(c, &bytes, &size, err);
    if (r == SP_OK) r = sp_file_write(path, bytes, size, err); // whole: a model file is never left half replaced
    free(bytes);
    return r;
}

typedef struct rbuf {
    const unsigned char* p;
    size_t n, at;
    bool bad;
} rbuf;

static void get(rbuf* b, void* v, size_t n)
{
    if (b->bad || n > b->n - b->at) {
        b->bad = true;
        memset(v, 0, n);
        return;
    }
    memcpy(v, b->p + b->at, n);
    b->at += n;
}
static int32_t get_i32(rbuf* b)
{
    int32_t v;
    get(b, &v, 4);
    return v;
}
static float get_f32(rbuf* b)
{
    float v;
    get(b, &v, 4);
    return v;
}

static bool all_finite(const float* v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) return false;
    return true;
}

// One section of training rows (count by dim floats) and their labels, as
// the histograms, shape values and pictures are stored: allocated, read and
// checked (finite values, labels among the categories). SP_ERR_PARSE when
// the section is inconsistent (the buffer's size already checked by the caller).
static sp_result get_rows(rbuf* b, int count, int dim, int categories, float** rows, int** labels)
{
    *rows = malloc(sizeof(float) * (size_t)dim * (size_t)(count ? count : 1));
    *labels = malloc(sizeof(int) * (size_t)(count ? count : 1));
    if (!*rows || !*labels) return SP_ERR_NO_MEMORY;
    get(b, *rows, sizeof(float) * (size_t)dim * (size_t)count);
    get(b, *labels, sizeof(int32_t) * (size_t)count);
    for (int i = 0; i < count; ++i)
        if ((*labels)[i] < 0 || (*labels)[i] >= categories) return SP_ERR_PARSE;
    return b->bad || !all_finite(*rows, (size_t)dim * (size_t)count) ? SP_ERR_PARSE : SP_OK;
}

sp_result sp_clf_from_bytes(const void* bytes, size_t size, const char* what, sp_clf** out, sp_error* err)
{
    *out = NULL;
    const unsigned char* hdr = bytes;
    if (size < 8 || memcmp(hdr, k_magic, 8) != 0)
        return sp_fail(err, SP_ERR_PARSE, "%s: not a sketchpose classifier model", what);
    if (size < 24) return sp_fail(err, SP_ERR_PARSE, "%s: model file truncated (header)", what);
    uint32_t version, bom;
    uint64_t len;
    memcpy(&version, hdr + 8, 4);
    memcpy(&bom, hdr + 12, 4);
    memcpy(&len, hdr + 16, 8);
    if (bom != SP_CLF_BOM) return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: model written on a machine of other byte order", what);
    if (version < 1 || version > SP_CLF_FILE_VERSION)
        return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: model format version %u, this build reads versions 1 to %d (retrain)", what,
                       version, SP_CLF_FILE_VERSION);
    if (len > (uint64_t)1 << 32)
        return sp_fail(err, SP_ERR_PARSE, "%s: model header claims %llu bytes (corrupt)", what, (unsigned long long)len);
    if (size - 24 < len + 8)
        return sp_fail(err, SP_ERR_PARSE, "%s: model file truncated (%zu of %llu bytes)", what, size,
                       (unsigned long long)len + 32);
    const unsigned char* p = hdr + 24;
    uint64_t sum;
    memcpy(&sum, p + len, 8);
    if (size - 24 != len + 8 || sum != sp_clf_checksum(p, (size_t)len))
        return sp_fail(err, SP_ERR_PARSE, "%s: model file corrupt (checksum mismatch)", what);
    rbuf b = {p, (size_t)len, 0, false};
    sp_clf* c = calloc(1, sizeof *c);
    sp_result rc = SP_OK;
    if (!c) goto oom;
    int32_t ni = get_i32(&b);
    int32_t ints[12] = {0};
    if (ni != 12) goto corrupt;
    for (int i = 0; i < 12; ++i)
        ints[i] = get_i32(&b);
    // The order sp_clf_save writes them in.
    sp_clf_desc d = {.words = ints[0],
                     .vocab_samples = ints[1],
                     .kmeans_iterations = ints[2],
                     .soft_neighbours = ints[3],
                     .knn = ints[4],
                     .pyramid = ints[5],
                     .tfidf = ints[6],
                     .hellinger = ints[7],
                     .mirror = ints[8],
                     .augment = ints[9],
                     .seed = (uint32_t)ints[10],
                     .threads = ints[11]};
    get(&b, &d.reject_quantile, 8);
    c->desc = sp_clf_desc_defaults(&d);
    int32_t nc = get_i32(&b);
    if (b.bad || nc < 1 || nc > 100000) goto corrupt;
    c->categories = calloc((size_t)nc, sizeof(char*));
    if (!c->categories) goto oom;
    for (int i = 0; i < nc; ++i) {
        int32_t l = get_i32(&b);
        if (b.bad || l < 0 || (size_t)l > b.n - b.at) goto corrupt;
        if (!(c->categories[i] = malloc((size_t)l + 1))) goto oom;
        c->category_count = i + 1;
        get(&b, c->categories[i], (size_t)l);
        c->categories[i][l] = '\0';
    }
    c->words = get_i32(&b);
    if (b.bad || c->words < 1 || c->words > 100000 || get_i32(&b) != SP_FEAT_DIM) goto corrupt;
    if ((size_t)c->words * SP_FEAT_DIM * 4 > b.n - b.at) goto corrupt;
    if (!(c->vocab = malloc(sizeof(float) * (size_t)c->words * SP_FEAT_DIM))) goto oom;
    get(&b, c->vocab, sizeof(float) * (size_t)c->words * SP_FEAT_DIM);
    c->sigma = get_f32(&b);
    c->hist_dim = get_i32(&b);
    if (b.bad || c->hist_dim != c->words * pyramid_cells(c->desc.pyramid) || !(c->sigma > 0) || !isfinite(c->sigma)) goto corrupt;
    if (get_i32(&b)) {
        if ((size_t)c->words * 4 > b.n - b.at) goto corrupt;
        if (!(c->idf = malloc(sizeof(float) * (size_t)c->words))) goto oom;
        get(&b, c->idf, sizeof(float) * (size_t)c->words);
    }
    c->train_count = get_i32(&b);
    if (b.bad || c->train_count < 1 || (size_t)c->train_count * ((size_t)c->hist_dim + 1) * 4 > b.n - b.at) goto corrupt;
    if ((rc = get_rows(&b, c->train_count, c->hist_dim, c->category_count, &c->hists, &c->labels)) != SP_OK) goto bad_rows;
    c->bandwidth = get_f32(&b);
    c->reject = get_f32(&b);
    c->desc.shape_weight = -1.0; // version 1: no shape evidence
    if (version >= 2) {
        get(&b, &c->desc.shape_weight, 8);
        c->shape_count = get_i32(&b);
        if (b.bad || get_i32(&b) != SP_SHAPE_DIM || c->shape_count < 0 || !isfinite(c->desc.shape_weight) ||
            (size_t)c->shape_count * (SP_SHAPE_DIM + 1) * 4 + 2 * sizeof c->shape_mu > b.n - b.at)
            goto corrupt;
        get(&b, c->shape_mu, sizeof c->shape_mu);
        get(&b, c->shape_sd, sizeof c->shape_sd);
        if ((rc = get_rows(&b, c->shape_count, SP_SHAPE_DIM, c->category_count, &c->shapes, &c->shape_labels)) != SP_OK)
            goto bad_rows;
        for (int d = 0; d < SP_SHAPE_DIM; ++d)
            if (!(c->shape_sd[d] > 0)) goto corrupt;
        if (!all_finite(c->shape_mu, SP_SHAPE_DIM) || !all_finite(c->shape_sd, SP_SHAPE_DIM)) goto corrupt;
    }
    c->desc.picture_weight = -1.0; // versions 1 and 2: no picture evidence
    if (version >= 3) {
        get(&b, &c->desc.picture_weight, 8);
        c->pic_count = get_i32(&b);
        if (b.bad || get_i32(&b) != SP_PICTURE_DIM || c->pic_count < 0 || !isfinite(c->desc.picture_weight) ||
            (size_t)c->pic_count * (SP_PICTURE_DIM + 1) * 4 + 4 > b.n - b.at)
            goto corrupt;
        c->pic_bandwidth = get_f32(&b);
        if ((rc = get_rows(&b, c->pic_count, SP_PICTURE_DIM, c->category_count, &c->pics, &c->pic_labels)) != SP_OK)
            goto bad_rows;
        if (c->pic_count > 0 && !(c->pic_bandwidth > 0 && isfinite(c->pic_bandwidth))) goto corrupt;
    }
    if (b.bad || b.at != b.n || !(c->bandwidth > 0) || isnan(c->reject)) goto corrupt;
    if (!all_finite(c->vocab, (size_t)c->words * SP_FEAT_DIM) || (c->idf && !all_finite(c->idf, (size_t)c->words))) goto corrupt;
    if ((rc = vocab_norms(c, err)) != SP_OK || (rc = build_hist_index(c, err)) != SP_OK) {
        sp_clf_destroy(c);
        return rc;
    }
    *out = c;
    return SP_OK;
bad_rows:
    if (rc == SP_ERR_NO_MEMORY) goto oom;
corrupt:
    sp_clf_destroy(c);
    return sp_fail(err, SP_ERR_PARSE, "%s: model file corrupt (inconsistent contents)", what);
oom:
    sp_clf_destroy(c);
    return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
}

sp_result sp_clf_load(const char* path, sp_clf** out, sp_error* err)
{
    *out = NULL;
    void* data;
    size_t size;
    // At most the largest body the header can claim, and the header and checksum.
    sp_result r = sp_file_read(path, ((size_t)1 << 32) + 32, &data, &size, err);
    if (r != SP_OK) return r;
    r = sp_clf_from_bytes(data, size, path, out, err);
    free(data);
    return r;
}
