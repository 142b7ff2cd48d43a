// Optimal assignment (Kuhn-Munkres) and the stroke-to-curve assignment that
// makes the solver independent of drawing order and direction.
#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "sp/curve.h"

// Shortest augmenting path Hungarian method with potentials, n <= m,
// 1-based work arrays (row/column 0 is the virtual start). O(n^2 m).
// Exact ties pick the lowest column (strict comparisons), so the result is
// a function of the matrix alone.
static void hungarian_nm(const double* a, int n, int m, bool transposed, int* row_of_col, double* work)
{
    double *u = work, *v = u + (n + 1), *minv = v + (m + 1);
    int* p = row_of_col; // m + 1 entries: p[j] = row (1-based) matched to column j, 0 if none
    int* way = (int*)(void*)(minv + (m + 1));
    bool* used = (bool*)(way + (m + 1));
    for (int i = 0; i <= n; ++i)
        u[i] = 0.0;
    for (int j = 0; j <= m; ++j)
        v[j] = 0.0, p[j] = 0, way[j] = 0;
    // a is rows by cols row-major; when transposed, row i of the problem is column i of a.
    int stride = transposed ? n : m;
#define COST(i, j) (transposed ? a[(size_t)(j) * (size_t)stride + (size_t)(i)] : a[(size_t)(i) * (size_t)stride + (size_t)(j)])
    for (int i = 1; i <= n; ++i) {
        p[0] = i;
        int j0 = 0;
        for (int j = 0; j <= m; ++j)
            minv[j] = INFINITY, used[j] = false;
        do {
            used[j0] = true;
            int i0 = p[j0], j1 = 0;
            double delta = INFINITY;
            for (int j = 1; j <= m; ++j) {
                if (used[j]) continue;
                double cur = COST(i0 - 1, j - 1) - u[i0] - v[j];
                if (cur < minv[j]) minv[j] = cur, way[j] = j0;
                if (minv[j] < delta) delta = minv[j], j1 = j;
            }
            assert(j1 > 0);
            for (int j = 0; j <= m; ++j) {
                if (used[j])
                    u[p[j]] += delta, v[j] -= delta;
                else
                    minv[j] -= delta;
            }
            j0 = j1;
        } while (p[j0] != 0);
        do {
            int j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
        } while (j0);
    }
#undef COST
}

sp_result sp_assign_hungarian(const double* cost, int rows, int cols, int* row_to_col, int* col_to_row, double* total)
{
    if (rows < 0 || cols < 0) return SP_ERR_INVALID;
    for (int i = 0; i < rows; ++i)
        row_to_col[i] = -1;
    if (col_to_row)
        for (int j = 0; j < cols; ++j)
            col_to_row[j] = -1;
    if (total) *total = 0.0;
    if (rows == 0 || cols == 0) return SP_OK;
    assert(cost && row_to_col);
    for (size_t k = 0; k < (size_t)rows * (size_t)cols; ++k)
        if (!isfinite(cost[k])) return SP_ERR_INVALID;
    bool transposed = rows > cols;
    int n = transposed ? cols : rows, m = transposed ? rows : cols;
    // Work space: u (n+1), v and minv (m+1 each) doubles, then way (m+1)
    // ints and used (m+1) bools; p separately.
    size_t bytes =
        sizeof(double) * (size_t)(n + 1 + 2 * (m + 1)) + sizeof(int) * (size_t)(m + 1) + sizeof(bool) * (size_t)(m + 1);
    double* work = malloc(bytes);
    int* p = malloc(sizeof(int) * (size_t)(m + 1));
    if (!work || !p) {
        free(work), free(p);
        return SP_ERR_NO_MEMORY;
    }
    hungarian_nm(cost, n, m, transposed, p, work);
    for (int j = 1; j <= m; ++j) {
        if (!p[j]) continue;
        int r = transposed ? j - 1 : p[j] - 1, c = transposed ? p[j] - 1 : j - 1;
        row_to_col[r] = c;
        if (col_to_row) col_to_row[c] = r;
    }
    if (total) {
        double t = 0.0;
        for (int i = 0; i < rows; ++i)
            if (row_to_col[i] >= 0) t += cost[(size_t)i * (size_t)cols + (size_t)row_to_col[i]];
        *total = t;
    }
    free(work), free(p);
    return SP_OK;
}

// ---------------------------------------------------------------------------

// Reading a stroke backwards gives the same polyline; pick the direction
// whose first differing end point is lexicographically smaller, so a stroke
// and its reverse resample to bit-identical samples.
static bool canonical_flip(const sp_vec2* p, int n)
{
    for (int i = 0, k = n - 1; i < k; ++i, --k) {
        if (p[i].x != p[k].x) return p[k].x < p[i].x;
        if (p[i].y != p[k].y) return p[k].y < p[i].y;
    }
    return false;
}

// A cost-matrix row with its stroke index, sorted by content then index.
typedef struct row_key {
    const double* row;
    int cols, index;
} row_key;

static int cmp_rows(const void* pa, const void* pb)
{
    const row_key *a = pa, *b = pb;
    for (int j = 0; j < a->cols; ++j) {
        if (a->row[j] < b->row[j]) return -1;
        if (a->row[j] > b->row[j]) return 1;
    }
    return (a->index > b->index) - (a->index < b->index);
}

static sp_result pair_cost(const sp_vec2* ys, const sp_vec2* zs, int m, bool closed, sp_correspondence kind, sp_corr_pair* pairs,
                           sp_ordered_info* info)
{
    if (kind == SP_CORR_CLOSEST) {
        double c = 0.0;
        sp_result r = sp_corr_closest(ys, m, zs, m, pairs, &c);
        *info = (sp_ordered_info){false, 0, c / (2.0 * m)};
        return r;
    }
    sp_result r = sp_corr_ordered(ys, zs, m, closed, NULL, info);
    info->cost /= m;
    return r;
}

sp_result sp_assign_strokes(const sp_stroke* strokes, int stroke_count, const sp_polyline* curves, int curve_count,
                            const sp_assign_desc* desc, sp_stroke_match* out, int* curve_to_stroke, sp_error* err)
{
    if (stroke_count < 0 || curve_count < 0) return sp_fail(err, SP_ERR_INVALID, "assign: negative stroke or curve count");
    assert((stroke_count == 0 || (strokes && out)) && (curve_count == 0 || curves));
    int m = desc && desc->samples > 0 ? desc->samples : 64;
    sp_correspondence kind = desc ? desc->match : SP_CORR_ORDERED;
    int S = stroke_count, C = curve_count;
    for (int s = 0; s < S; ++s) {
        if (strokes[s].count < 1) return sp_fail(err, SP_ERR_INVALID, "stroke %d has no points", s);
        if (!sp_curve_is_valid(strokes[s].points, strokes[s].count))
            return sp_fail(err, SP_ERR_INVALID, "stroke %d has a non-finite coordinate", s);
    }
    bool any_closed = false;
    for (int c = 0; c < C; ++c) {
        if (curves[c].count < 1) return sp_fail(err, SP_ERR_INVALID, "curve %d has no points", c);
        if (!sp_curve_is_valid(curves[c].points, curves[c].count))
            return sp_fail(err, SP_ERR_INVALID, "curve %d has a non-finite coordinate", c);
        any_closed |= curves[c].closed;
    }
    for (int s = 0; s < S; ++s)
        out[s] = (sp_stroke_match){-1, false, 0, 0.0};
    if (curve_to_stroke)
        for (int c = 0; c < C; ++c)
            curve_to_stroke[c] = -1;
    if (S == 0 || C == 0) return SP_OK;

    int max_n = 0;
    for (int s = 0; s < S; ++s)
        max_n = strokes[s].count > max_n ? strokes[s].count : max_n;
    size_t sm = (size_t)S * (size_t)m, SC = (size_t)S * (size_t)C;
    sp_vec2* ys_open = malloc(sizeof(sp_vec2) * sm);
    sp_vec2* ys_closed = any_closed ? malloc(sizeof(sp_vec2) * sm) : NULL;
    sp_vec2* zs = malloc(sizeof(sp_vec2) * (size_t)C * (size_t)m);
    sp_vec2* flipped = malloc(sizeof(sp_vec2) * (size_t)max_n);
    sp_corr_pair* pairs = malloc(sizeof(sp_corr_pair) * 2 * (size_t)m);
    double* cost = malloc(sizeof(double) * SC);
    double* sorted = calloc(SC, sizeof(double)); // calloc: GCC cannot see the copy below fill it
    row_key* keys = malloc(sizeof(row_key) * (size_t)S);
    int* row_to_col = malloc(sizeof(int) * (size_t)S);
    sp_result r = SP_OK;
    if (!ys_open || (any_closed && !ys_closed) || !zs || !flipped || !pairs || !cost || !sorted || !keys || !row_to_col) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "assign: out of memory for %d strokes and %d curves", S, C);
        goto done;
    }

    // Resample once: strokes in canonical direction (open, and closed if any
    // curve is closed), curves as they are.
    for (int s = 0; s < S && r == SP_OK; ++s) {
        const sp_vec2* p = strokes[s].points;
        int n = strokes[s].count;
        if (canonical_flip(p, n)) {
            for (int i = 0; i < n; ++i)
                flipped[i] = p[n - 1 - i];
            p = flipped;
        }
        r = sp_curve_resample(p, n, false, m, ys_open + (size_t)s * m);
        if (r == SP_OK && any_closed) r = sp_curve_resample(p, n, true, m, ys_closed + (size_t)s * m);
        if (r != SP_OK) r = sp_fail(err, r, "stroke %d: length overflows", s);
    }
    for (int c = 0; c < C && r == SP_OK; ++c) {
        r = sp_curve_resample(curves[c].points, curves[c].count, curves[c].closed, m, zs + (size_t)c * m);
        if (r != SP_OK) r = sp_fail(err, r, "curve %d: length overflows", c);
    }
    if (r != SP_OK) goto done;

    for (int s = 0; s < S; ++s)
        for (int c = 0; c < C; ++c) {
            const sp_vec2* ys = (curves[c].closed ? ys_closed : ys_open) + (size_t)s * m;
            sp_ordered_info info;
            r = pair_cost(ys, zs + (size_t)c * m, m, curves[c].closed, kind, pairs, &info);
            if (r != SP_OK) {
                r = sp_fail(err, r, "stroke %d vs curve %d: %s", s, c, sp_result_name(r));
                goto done;
            }
            // Huge coordinates can overflow the cost; cap it so that sums of
            // potentials inside the Hungarian method stay finite.
            cost[(size_t)s * C + c] = isfinite(info.cost) && info.cost < 1e290 ? info.cost : 1e290;
        }

    // Sort rows by content so the assignment sees the same matrix whatever
    // the order the strokes came in; identical rows keep their input order.
    for (int s = 0; s < S; ++s)
        keys[s] = (row_key){cost + (size_t)s * C, C, s};
    qsort(keys, (size_t)S, sizeof(row_key), cmp_rows);
    for (int k = 0; k < S; ++k)
        memcpy(sorted + (size_t)k * C, keys[k].row, sizeof(double) * (size_t)C);
    r = sp_assign_hungarian(sorted, S, C, row_to_col, NULL, NULL);
    if (r != SP_OK) {
        r = sp_fail(err, r, "assign: %s", sp_result_name(r));
        goto done;
    }

    // Report direction and shift against each stroke as drawn (not its
    // canonical direction), from its own resampling.
    for (int k = 0; k < S && r == SP_OK; ++k) {
        int s = keys[k].index, c = row_to_col[k];
        if (c < 0) continue;
        if (curve_to_stroke) curve_to_stroke[c] = s;
        sp_vec2* ys = ys_open + (size_t)s * m; // scratch: its cost row is no longer needed
        r = sp_curve_resample(strokes[s].points, strokes[s].count, curves[c].closed, m, ys);
        sp_ordered_info info = {false, 0, 0.0};
        if (r == SP_OK) r = pair_cost(ys, zs + (size_t)c * m, m, curves[c].closed, kind, pairs, &info);
        if (r != SP_OK) r = sp_fail(err, r, "stroke %d vs curve %d: %s", s, c, sp_result_name(r));
        out[s] = (sp_stroke_match){c, info.reversed, info.shift, info.cost};
    }

done:
    free(ys_open), free(ys_closed), free(zs), free(flipped), free(pairs);
    free(cost), free(sorted), free(keys), free(row_to_col);
    return r;
}
