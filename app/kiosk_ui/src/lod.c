// lod.c: vertex clustering on a cubic grid (see lod.h), with a binary search
// on the cell size for a triangle budget.
#include "sp/kiosk_lod.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

enum { KEY_BITS = 21 }; // cluster and cell indices are packed three to a 64-bit key
#define KEY_MASK ((1ull << KEY_BITS) - 1)
#define EMPTY UINT64_MAX

typedef struct table {
    uint64_t* keys;
    int* vals;
    size_t cap; // power of two
} table;

static bool table_init(table* t, size_t n)
{
    t->cap = 16;
    while (t->cap < 2 * n)
        t->cap *= 2;
    t->keys = malloc(sizeof *t->keys * t->cap);
    t->vals = malloc(sizeof *t->vals * t->cap);
    if (!t->keys || !t->vals) return false;
    memset(t->keys, 0xFF, sizeof *t->keys * t->cap);
    return true;
}

static void table_clear(table* t)
{
    memset(t->keys, 0xFF, sizeof *t->keys * t->cap);
}

static void table_free(table* t)
{
    free(t->keys);
    free(t->vals);
}

// The value stored under key, or inserts `val` and returns -1.
static int table_get_or_put(table* t, uint64_t key, int val)
{
    uint64_t h = key * 0x9E3779B97F4A7C15ull;
    size_t i = (size_t)(h >> 20) & (t->cap - 1);
    for (;; i = (i + 1) & (t->cap - 1)) {
        if (t->keys[i] == EMPTY) {
            t->keys[i] = key, t->vals[i] = val;
            return -1;
        }
        if (t->keys[i] == key) return t->vals[i];
    }
}

static int cluster_grid(const double* xyz, int nv, const double lo[3], double cell, table* t, int* cluster)
{
    table_clear(t);
    double inv = 1.0 / cell;
    int n = 0;
    for (int v = 0; v < nv; ++v) {
        uint64_t key = 0;
        for (int c = 0; c < 3; ++c)
            key = (key << KEY_BITS) | ((uint64_t)(int64_t)floor((xyz[3 * v + c] - lo[c]) * inv) & KEY_MASK);
        int got = table_get_or_put(t, key, n);
        cluster[v] = got >= 0 ? got : n++;
    }
    return n;
}

// Maps the triangles to clusters, dropping degenerate ones and duplicates
// (either winding: a thin sheet's two faces collapse onto one). Writes them
// to out (may be NULL to count).
static int map_triangles(const uint32_t* tris, int nt, const int* cluster, table* t, uint32_t* out)
{
    table_clear(t);
    int m = 0;
    for (int i = 0; i < nt; ++i) {
        uint32_t a = (uint32_t)cluster[tris[3 * i]], b = (uint32_t)cluster[tris[3 * i + 1]],
                 c = (uint32_t)cluster[tris[3 * i + 2]];
        if (a == b || b == c || a == c) continue;
        uint32_t s[3] = {a, b, c}, tmp;
        if (s[0] > s[1]) tmp = s[0], s[0] = s[1], s[1] = tmp;
        if (s[1] > s[2]) tmp = s[1], s[1] = s[2], s[2] = tmp;
        if (s[0] > s[1]) tmp = s[0], s[0] = s[1], s[1] = tmp;
        uint64_t key = ((uint64_t)s[0] << (2 * KEY_BITS)) | ((uint64_t)s[1] << KEY_BITS) | s[2];
        if (table_get_or_put(t, key, m) >= 0) continue;
        if (out) out[3 * m] = a, out[3 * m + 1] = b, out[3 * m + 2] = c;
        ++m;
    }
    return m;
}

void sp_lod_free(sp_lod* lod)
{
    if (!lod) return;
    free(lod->cluster);
    free(lod->inv_size);
    free(lod->tris);
    free(lod->colors);
    memset(lod, 0, sizeof *lod);
}

sp_result sp_lod_build(const double* xyz, int nv, const uint32_t* tris, int nt, const float* colors, int max_tris, sp_lod* out)
{
    memset(out, 0, sizeof *out);
    if (nv <= 0 || nt <= 0 || (size_t)nv > KEY_MASK) return SP_ERR_INVALID;
    for (int i = 0; i < 3 * nt; ++i)
        if (tris[i] >= (uint32_t)nv) return SP_ERR_INVALID;
    for (int i = 0; i < 3 * nv; ++i)
        if (!isfinite(xyz[i])) return SP_ERR_INVALID;
    out->vertex_count = nv;
    out->cluster = malloc(sizeof(int) * (size_t)nv);
    table t = {0}, tt = {0};
    if (!out->cluster || !table_init(&t, (size_t)nv) || !table_init(&tt, (size_t)nt)) goto oom;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c)
            lo[c] = fmin(lo[c], xyz[3 * v + c]), hi[c] = fmax(hi[c], xyz[3 * v + c]);
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!isfinite(diag)) {
        table_free(&t), table_free(&tt);
        sp_lod_free(out);
        return SP_ERR_INVALID;
    }
    int nc;
    if (nt <= max_tris || !(diag > 0)) {
        for (int v = 0; v < nv; ++v)
            out->cluster[v] = v;
        nc = nv;
    } else {
        // The finest grid within the budget: more triangles with smaller cells
        // (nearly monotonic), so bisect the cell size on a log scale.
        double a = diag / 4000, b = diag / 4;
        for (int it = 0; it < 14; ++it) {
            double mid = sqrt(a * b);
            cluster_grid(xyz, nv, lo, mid, &t, out->cluster);
            if (map_triangles(tris, nt, out->cluster, &tt, NULL) > max_tris)
                a = mid;
            else
                b = mid;
        }
        nc = cluster_grid(xyz, nv, lo, b, &t, out->cluster);
    }
    out->cluster_count = nc;
    out->inv_size = calloc((size_t)nc, sizeof(float));
    out->tris = malloc(sizeof(uint32_t) * 3 * (size_t)nt);
    if (colors) out->colors = calloc((size_t)nc * 4, sizeof(float));
    if (!out->inv_size || !out->tris || (colors && !out->colors)) goto oom;
    out->tri_count = map_triangles(tris, nt, out->cluster, &tt, out->tris);
    for (int v = 0; v < nv; ++v) {
        out->inv_size[out->cluster[v]] += 1.0f;
        for (int c = 0; colors && c < 4; ++c)
            out->colors[4 * out->cluster[v] + c] += colors[4 * v + c];
    }
    for (int k = 0; k < nc; ++k) {
        for (int c = 0; colors && c < 4; ++c)
            out->colors[4 * k + c] /= out->inv_size[k];
        out->inv_size[k] = 1.0f / out->inv_size[k];
    }
    table_free(&t);
    table_free(&tt);
    return SP_OK;
oom:
    table_free(&t);
    table_free(&tt);
    sp_lod_free(out);
    return SP_ERR_NO_MEMORY;
}

void sp_lod_positions(const sp_lod* lod, const double* xyz, double* out)
{
    memset(out, 0, sizeof(double) * 3 * (size_t)lod->cluster_count);
    for (int v = 0; v < lod->vertex_count; ++v) {
        double* o = out + 3 * lod->cluster[v];
        o[0] += xyz[3 * v], o[1] += xyz[3 * v + 1], o[2] += xyz[3 * v + 2];
    }
    for (int k = 0; k < lod->cluster_count; ++k)
        for (int c = 0; c < 3; ++c)
            out[3 * k + c] *= lod->inv_size[k];
}
