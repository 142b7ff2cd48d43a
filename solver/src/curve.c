// Polylines: arc-length resampling, cleaning, smoothing, and the paper's
// two correspondence procedures (ordered and closest point).
#include "sp/curve.h"

#include <assert.h>
#include <flann/flann.h>
#include <stdlib.h>
#include <string.h>

static inline double dist2(sp_vec2 a, sp_vec2 b)
{
    double dx = a.x - b.x, dy = a.y - b.y;
    return dx * dx + dy * dy;
}

bool sp_curve_is_valid(const sp_vec2* pts, int n)
{
    if (n < 1 || !pts) return false;
    for (int i = 0; i < n; ++i)
        if (!sp_v2_is_valid(pts[i])) return false;
    return true;
}

static inline double seg_len(const sp_vec2* pts, int n, int j)
{
    int k = j + 1 == n ? 0 : j + 1;
    return hypot(pts[k].x - pts[j].x, pts[k].y - pts[j].y);
}

double sp_curve_length(const sp_vec2* pts, int n, bool closed)
{
    if (n <= 1) return 0.0;
    int nseg = closed ? n : n - 1;
    double L = 0.0;
    for (int j = 0; j < nseg; ++j)
        L += seg_len(pts, n, j);
    return L;
}

sp_result sp_curve_resample(const sp_vec2* pts, int n, bool closed, int m, sp_vec2* out)
{
    if (n < 1 || m < 1) return SP_ERR_INVALID;
    assert(pts && out);
    if (!sp_curve_is_valid(pts, n)) return SP_ERR_INVALID;
    double L = sp_curve_length(pts, n, closed);
    if (!isfinite(L)) return SP_ERR_INVALID;
    if (!(L > 0.0) || m == 1) {
        // Zero length (one point or all equal): m copies of the first point.
        for (int k = 0; k < m; ++k)
            out[k] = pts[0];
        return SP_OK;
    }
    int nseg = closed ? n : n - 1;
    double denom = closed ? (double)m : (double)(m - 1);
    // One walk along the segments. s0 accumulates the same terms in the same
    // order as sp_curve_length, so the last segment ends exactly at L and
    // every target (<= L) lies on a segment.
    int j = 0;
    double s0 = 0.0, lj = seg_len(pts, n, 0);
    for (int k = 0; k < m; ++k) {
        // Multiply rather than accumulate a step, so that error does not grow with k.
        double target = L * ((double)k / denom);
        while (j < nseg - 1 && s0 + lj < target) {
            s0 += lj;
            ++j;
            lj = seg_len(pts, n, j);
        }
        double t = lj > 0.0 ? (target - s0) / lj : 0.0;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
        sp_vec2 a = pts[j], b = pts[j + 1 == n ? 0 : j + 1];
        out[k] = (sp_vec2){a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
    }
    if (!closed) out[m - 1] = pts[n - 1];
    return SP_OK;
}

int sp_curve_clean(const sp_vec2* pts, int n, double min_step, sp_vec2* out)
{
    if (n <= 0) return 0;
    assert(pts && out);
    // fmax also maps a NaN step to 0 (exact duplicates only).
    double step2 = fmax(min_step, 0.0);
    step2 *= step2;
    // In place is safe: we only ever write at k <= i after reading pts[i].
    int k = 0;
    out[k++] = pts[0];
    for (int i = 1; i < n; ++i) {
        sp_vec2 p = pts[i];
        double d2 = dist2(p, out[k - 1]);
        bool keep = step2 > 0.0 ? d2 >= step2 : d2 > 0.0;
        if (keep)
            out[k++] = p;
        else if (i == n - 1 && d2 > 0.0) {
            // The end of a stroke matters more than the point before it.
            if (k > 1)
                out[k - 1] = p;
            else
                out[k++] = p;
        }
    }
    return k;
}

void sp_curve_smooth(const sp_vec2* pts, int n, bool closed, int iterations, sp_vec2* out)
{
    if (n <= 0) return;
    assert(pts && out);
    if (out != pts) memmove(out, pts, sizeof(sp_vec2) * (size_t)n);
    if (n < 3) return;
    for (int it = 0; it < iterations; ++it) {
        if (closed) {
            sp_vec2 first = out[0], prev = out[n - 1];
            for (int i = 0; i < n; ++i) {
                sp_vec2 cur = out[i], next = i == n - 1 ? first : out[i + 1];
                out[i] = (sp_vec2){0.25 * prev.x + 0.5 * cur.x + 0.25 * next.x, 0.25 * prev.y + 0.5 * cur.y + 0.25 * next.y};
                prev = cur;
            }
        } else {
            sp_vec2 prev = out[0];
            for (int i = 1; i < n - 1; ++i) {
                sp_vec2 cur = out[i], next = out[i + 1];
                out[i] = (sp_vec2){0.25 * prev.x + 0.5 * cur.x + 0.25 * next.x, 0.25 * prev.y + 0.5 * cur.y + 0.25 * next.y};
                prev = cur;
            }
        }
    }
}

static double seg_dist2(sp_vec2 x, sp_vec2 a, sp_vec2 b);

// A stretch that goes over the stroke before it is at least this share of
// the length it goes over.
#define RETRACE_MIN_LENGTH 0.7
// What leads to the second pass is the pen's way back when the stroke
// turns where it ends by more than about 60 degrees (the cosine): a loop's
// next turn runs on.
#define CONNECTOR_TURN 0.5

static double turn_sign(sp_vec2 a, sp_vec2 b, sp_vec2 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Whether the polyline p[0..n-1] crosses itself (two segments that are not
// neighbours cross properly). O(n^2).
static bool crosses_itself(const sp_vec2* p, int n)
{
    for (int i = 0; i + 1 < n; ++i)
        for (int j = i + 2; j + 1 < n; ++j) {
            double d1 = turn_sign(p[i], p[i + 1], p[j]), d2 = turn_sign(p[i], p[i + 1], p[j + 1]);
            double d3 = turn_sign(p[j], p[j + 1], p[i]), d4 = turn_sign(p[j], p[j + 1], p[i + 1]);
            if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
        }
    return false;
}

int sp_curve_retrace_start(const sp_vec2* pts, int n, double tol, double min_share)
{
    enum { M = 64 }; // samples along the stroke: a stretch's share is counted in 64ths
    if (n < 4 || !(tol > 0) || !sp_curve_is_valid(pts, n)) return n;
    double len = sp_curve_length(pts, n, false);
    sp_vec2 r[M];
    double* arc = malloc(sizeof(double) * (size_t)n); // the stroke's length up to each point
    if (!arc || !(len > 0) || sp_curve_resample(pts, n, false, M, r) != SP_OK) {
        free(arc);
        return n;
    }
    arc[0] = 0;
    for (int k = 1; k < n; ++k)
        arc[k] = arc[k - 1] + sp_v2_len(sp_v2_sub(pts[k], pts[k - 1]));
    double step = len / (M - 1), own = fmax(2.0 * tol, step);
    // first[i]: where along the stroke the first of its segments within tol
    // of sample i ends (INFINITY: none), against the stroke as drawn, not
    // its samples (a claw's tip lies off a 64th's chord of an outline); a
    // sample's own stretch of the stroke does not count (a turn back comes
    // within tol of itself there without going over anything).
    double first[M];
    int first_seg[M]; // that segment's index
    for (int i = 0; i < M; ++i) {
        first[i] = INFINITY, first_seg[i] = -1;
        for (int k = 0; k + 1 < n && arc[k + 1] <= i * step - own; ++k)
            if (seg_dist2(r[i], pts[k], pts[k + 1]) < tol * tol) {
                first[i] = arc[k + 1], first_seg[i] = k;
                break;
            }
    }
    free(arc);
    int last = M - (int)ceil(fmax(0.0, min_share) * (M - 1)); // the stretch's earliest start
    for (int c = 1; c <= last && c < M; ++c) {
        // Over the stroke up to c, not over itself: shading drawn back and
        // forth goes over its last pass only, and is not drawn once.
        double at = c * step;
        if (!(first[c] <= at)) continue;
        int count = 0;
        for (int i = c; i < M; ++i)
            count += first[i] <= at;
        if (count < 0.9 * (M - c)) continue;
        // Going over the stroke follows it along, in order: a scribble's
        // points each lie near some of the scribble before them too, here
        // and there (it was cut, and the rest of it taken for a part).
        int jumps = 0, pairs = 0;
        for (int i = c; i + 1 < M; ++i)
            if (first[i] <= at && first[i + 1] <= at) ++pairs, jumps += fabs(first[i + 1] - first[i]) > 3.0 * step + 2.0 * tol;
        if (jumps > 1 + 0.1 * pairs) continue;
        // Going over a stretch follows it about its length: a line drawn
        // straight back through a zigzag (closing it into a shape) comes
        // within tol of all of it in half its length.
        bool covered[M] = {false};
        int n_covered = 0;
        for (int j = 0; j < c; ++j) {
            for (int i = c; i < M && !covered[j]; ++i)
                covered[j] = seg_dist2(r[i], r[j], r[j + 1]) < tol * tol;
            n_covered += covered[j];
        }
        if (M - 1 - c < RETRACE_MIN_LENGTH * n_covered) continue;
        // What leads from the first pass to the second without being gone
        // over (a line back to where the first began, then the doodle
        // again) is cut too: kept, it closed the doodle into a part. Told
        // by the samples before the second pass's own neighbourhood that
        // it does not go near.
        bool near[M] = {false};
        for (int j = 0; j < c; ++j)
            for (int i = c; i + 1 < M && !near[j]; ++i)
                near[j] = seg_dist2(r[j], r[i], r[i + 1]) < tol * tol;
        int keep = c, j = c - (int)ceil(own / step) - 1;
        if (j > 0 && !near[j]) {
            keep = j;
            while (keep > c / 2 && keep > 1 && !near[keep - 1])
                --keep;
            // The pen back to where the stroke began turns there to go over
            // it again; the rest of a loop gone round one and a half times
            // runs on into its second turn, one simple ring up to there (its
            // ends aside: they meet), and was cut to half a ring (a second
            // review). A test of straightness instead kept a curved way
            // back, and a tail or a spring drawn twice became wings (a
            // third); the spring's coils cross.
            int k = c + 2 < M ? 2 : M - 1 - c;
            sp_vec2 in = sp_v2_sub(r[c], r[c - 2 < keep ? keep : c - 2]), out = sp_v2_sub(r[c + k], r[c]);
            if (k > 0 && sp_v2_dot(in, out) > CONNECTOR_TURN * sp_v2_len(in) * sp_v2_len(out) && !crosses_itself(r + 1, c - 1))
                keep = c;
        }
        if (keep == c && first_seg[c] >= 0) {
            // A loop comes within tol of where it began a tol short of
            // closing: cut where it comes nearest to the point it passes
            // (an eye 6 px across gone round three times was kept as four
            // fifths of a ring; an outside review), on the segment it
            // passes, not at its end (one long straight side drawn twice
            // was kept whole; a second review).
            sp_vec2 a = pts[first_seg[c]], b = pts[first_seg[c] + 1], ab = sp_v2_sub(b, a);
            double t = sp_v2_dot(ab, ab) > 0 ? fmin(1.0, fmax(0.0, sp_v2_dot(sp_v2_sub(r[c], a), ab) / sp_v2_dot(ab, ab))) : 0.0;
            sp_vec2 at0 = sp_v2_add(a, sp_v2_scale(ab, t));
            while (keep + 1 < M && sp_v2_len(sp_v2_sub(r[keep + 1], at0)) < sp_v2_len(sp_v2_sub(r[keep], at0)))
                ++keep;
        }
        // The input points up to that length (a long segment that crosses
        // it, a jump back to where the stroke began, is left out whole).
        at = keep * step;
        double s = 0.0;
        for (int k = 1; k < n; ++k) {
            s += sp_v2_len(sp_v2_sub(pts[k], pts[k - 1]));
            if (s > at + 1e-9 * len) return k >= 2 ? k : 2;
        }
        return n;
    }
    return n;
}

// Cost of one ordered candidate; stops early once it cannot beat `best`
// (a tie keeps the earlier candidate, so stopping at equality is exact).
static double ordered_cost(const sp_vec2* y, const sp_vec2* z, int m, bool reversed, int shift, double best)
{
    double c = 0.0;
    for (int i = 0; i < m; ++i) {
        int j = reversed ? shift - i : shift + i;
        if (j < 0)
            j += m;
        else if (j >= m)
            j -= m;
        c += dist2(y[i], z[j]);
        if (c >= best) return INFINITY;
    }
    return c;
}

void sp_corr_ordered_match(const sp_ordered_info* c, int m, int* match)
{
    for (int i = 0; i < m; ++i) {
        int j = (c->reversed ? c->shift - i : c->shift + i) % m;
        match[i] = j < 0 ? j + m : j;
    }
}

int sp_corr_ordered_candidates(const sp_vec2* y, const sp_vec2* z, int m, sp_ordered_info* out, int k)
{
    if (m < 3 || k < 1 || !sp_curve_is_valid(y, m) || !sp_curve_is_valid(z, m)) return 0;
    double* cost = malloc(sizeof(double) * 2 * (size_t)m);
    if (!cost) return 0;
    for (int rev = 0; rev < 2; ++rev)
        for (int s = 0; s < m; ++s) cost[rev * m + s] = ordered_cost(y, z, m, rev, s, INFINITY);
    int n = 0, sep = m / 20 > 1 ? m / 20 : 1;
    while (n < k) {
        // The cheapest local minimum not near one already taken.
        int bi = -1;
        for (int i = 0; i < 2 * m; ++i) {
            int rev = i / m, s = i % m;
            double c = cost[i];
            if (!isfinite(c) || c > cost[rev * m + (s + 1) % m] || c > cost[rev * m + (s + m - 1) % m]) continue;
            bool near = false;
            for (int t = 0; t < n && !near; ++t) {
                int d = abs(out[t].shift - s);
                near = out[t].reversed == (rev != 0) && (d < sep || m - d < sep);
            }
            if (!near && (bi < 0 || c < cost[bi])) bi = i;
        }
        if (bi < 0) break;
        out[n++] = (sp_ordered_info){bi >= m, bi % m, cost[bi]};
    }
    free(cost);
    return n;
}

sp_result sp_corr_ordered(const sp_vec2* y, const sp_vec2* z, int m, bool closed, int* match, sp_ordered_info* info)
{
    if (m < 1) return SP_ERR_INVALID;
    assert(y && z);
    if (!sp_curve_is_valid(y, m) || !sp_curve_is_valid(z, m)) return SP_ERR_INVALID;
    sp_ordered_info best = {false, 0, INFINITY};
    // Open curves: the reversed candidate is "shift m-1, reversed".
    int shifts = closed ? m : 1;
    for (int rev = 0; rev < 2; ++rev)
        for (int s = 0; s < shifts; ++s) {
            int shift = closed ? s : (rev ? m - 1 : 0);
            double c = ordered_cost(y, z, m, rev, shift, best.cost);
            if (c < best.cost) best = (sp_ordered_info){rev != 0, shift, c};
        }
    if (!isfinite(best.cost)) {
        // Only when every candidate overflowed; recompute the first one in full.
        best = (sp_ordered_info){false, 0, ordered_cost(y, z, m, false, 0, INFINITY)};
        if (isnan(best.cost)) return SP_ERR_INVALID;
    }
    if (match) sp_corr_ordered_match(&best, m, match);
    if (!closed) best.shift = 0;
    if (info) *info = best;
    return SP_OK;
}

typedef struct x_index {
    double x;
    int i;
} x_index;

static inline bool x_less(x_index a, x_index b) { return a.x < b.x || (a.x == b.x && a.i < b.i); }

// Sorts by (x, i), a total order, so the result is the one qsort gives; an
// inlined quicksort with insertion sort below 16 entries is much faster than
// qsort on the few hundred samples of a closest-point round, where sorting
// weighs in the matching's cost (BENCHMARKS.md, "Measurements behind the
// solver's constants and stages").
static void sort_x_index(x_index* a, int n)
{
    while (n > 16) {
        // Median of three as the pivot; Hoare partition.
        x_index lo = a[0], mid = a[n / 2], hi = a[n - 1], pv;
        if (x_less(mid, lo)) pv = lo, lo = mid, mid = pv;
        if (x_less(hi, mid)) mid = x_less(hi, lo) ? lo : hi;
        pv = mid;
        int i = -1, j = n;
        for (;;) {
            do ++i;
            while (x_less(a[i], pv));
            do --j;
            while (x_less(pv, a[j]));
            if (i >= j) break;
            x_index t = a[i];
            a[i] = a[j], a[j] = t;
        }
        // Recurse into the smaller side, loop on the larger (stack depth log n).
        int left = j + 1;
        if (left < n - left) {
            sort_x_index(a, left);
            a += left, n -= left;
        } else {
            sort_x_index(a + left, n - left);
            n = left;
        }
    }
    for (int i = 1; i < n; ++i) {
        x_index t = a[i];
        int j = i - 1;
        while (j >= 0 && x_less(t, a[j])) a[j + 1] = a[j], --j;
        a[j + 1] = t;
    }
}

// For each query point, the index of its closest data point (lowest index on
// ties). The data sorted along their longer extent (x or y), each query
// searches outwards from its own coordinate and stops where that gap alone
// exceeds the best distance: exact, and a fraction of the all-pairs scan on
// curves of a few hundred samples (BENCHMARKS.md, "Measurements behind the
// solver's constants and stages", "Closest points' sweep"). Each search
// starts from the previous query's answer and sorted position: consecutive
// queries are neighbours along a curve, so the bound is tight from the start
// and no binary search is needed (the cost had been unpredictable branches).
// Still exact: a point that beats or ties the start lies within the start's
// distance, so inside the swept band.
static void closest_brute(const sp_vec2* q, int nq, const sp_vec2* d, int nd, int* idx)
{
    x_index* xs = malloc(sizeof(x_index) * (size_t)nd);
    if (!xs) { // all pairs, no scratch needed
        for (int i = 0; i < nq; ++i) {
            int bj = 0;
            double bd = dist2(q[i], d[0]);
            for (int j = 1; j < nd; ++j) {
                double dd = dist2(q[i], d[j]);
                if (dd < bd) bd = dd, bj = j;
            }
            idx[i] = bj;
        }
        return;
    }
    double lx = INFINITY, hx = -INFINITY, ly = INFINITY, hy = -INFINITY;
    for (int j = 0; j < nd; ++j) lx = fmin(lx, d[j].x), hx = fmax(hx, d[j].x), ly = fmin(ly, d[j].y), hy = fmax(hy, d[j].y);
    const bool along_y = hy - ly > hx - lx;
    for (int j = 0; j < nd; ++j) xs[j] = (x_index){along_y ? d[j].y : d[j].x, j};
    sort_x_index(xs, nd);
    int bj = 0, lo = 0; // the previous query's answer and sorted position
    for (int i = 0; i < nq; ++i) {
        const sp_vec2 p = q[i];
        const double px = along_y ? p.y : p.x;
        // lo: the first sorted entry with key >= px, walked from the last one's.
        while (lo > 0 && xs[lo - 1].x >= px) --lo;
        while (lo < nd && xs[lo].x < px) ++lo;
        double bd = dist2(p, d[bj]);
        for (int k = lo; k < nd; ++k) {
            double dx = xs[k].x - px;
            if (dx * dx > bd) break;
            double dd = dist2(p, d[xs[k].i]);
            if (dd < bd || (dd == bd && xs[k].i < bj)) bd = dd, bj = xs[k].i;
        }
        for (int k = lo - 1; k >= 0; --k) {
            double dx = px - xs[k].x;
            if (dx * dx > bd) break;
            double dd = dist2(p, d[xs[k].i]);
            if (dd < bd || (dd == bd && xs[k].i < bj)) bd = dd, bj = xs[k].i;
        }
        idx[i] = bj;
    }
    free(xs);
}

// Squared distance of x to segment ab.
static double seg_dist2(sp_vec2 x, sp_vec2 a, sp_vec2 b)
{
    sp_vec2 ab = sp_v2_sub(b, a), ax = sp_v2_sub(x, a);
    double l2 = sp_v2_dot(ab, ab);
    double t = l2 > 0 ? fmin(1.0, fmax(0.0, sp_v2_dot(ax, ab) / l2)) : 0.0;
    sp_vec2 d = sp_v2_sub(ax, (sp_vec2){t * ab.x, t * ab.y});
    return sp_v2_dot(d, d);
}

// Squared distance of x to the segments at point v (or to v alone).
static double point_segments_dist2(const sp_vec2* p, const int* next, const int* prev, int v, sp_vec2 x)
{
    if (next[v] < 0 && prev[v] < 0) return dist2(x, p[v]);
    double b = INFINITY;
    if (next[v] >= 0) b = fmin(b, seg_dist2(x, p[v], p[next[v]]));
    if (prev[v] >= 0) b = fmin(b, seg_dist2(x, p[prev[v]], p[v]));
    return b;
}

sp_result sp_polyline_distances(const sp_vec2* p, const int* next, int n, const sp_vec2* q, int nq, double* out)
{
    if (n < 1) return SP_ERR_INVALID;
    for (int v = 0; v < n; ++v)
        if (next[v] < -1 || next[v] >= n) return SP_ERR_INVALID;
    int* prev = malloc(sizeof(int) * (size_t)n);
    x_index* xs = malloc(sizeof(x_index) * (size_t)n);
    if (!prev || !xs) { // every segment for every query, no scratch needed
        free(prev), free(xs);
        for (int i = 0; i < nq; ++i) {
            double b = INFINITY;
            for (int v = 0; v < n; ++v) b = fmin(b, next[v] >= 0 ? seg_dist2(q[i], p[v], p[next[v]]) : dist2(q[i], p[v]));
            out[i] = sqrt(b);
        }
        return SP_OK;
    }
    for (int v = 0; v < n; ++v) prev[v] = -1;
    double half = 0; // half the longest segment
    for (int v = 0; v < n; ++v)
        if (next[v] >= 0) {
            prev[next[v]] = v;
            half = fmax(half, 0.5 * sqrt(dist2(p[v], p[next[v]])));
        }
    for (int v = 0; v < n; ++v) xs[v] = (x_index){p[v].x, v};
    sort_x_index(xs, n);
    // A segment within b of x has an endpoint within b + half of it, so
    // points beyond that x gap cannot hold a closer segment.
    for (int i = 0; i < nq; ++i) {
        const sp_vec2 x = q[i];
        int lo = 0, hi = n;
        while (lo < hi) {
            int mid = (lo + hi) / 2;
            if (xs[mid].x < x.x) lo = mid + 1;
            else hi = mid;
        }
        double bd = INFINITY, reach = INFINITY;
        for (int k = lo; k < n && xs[k].x - x.x <= reach; ++k) {
            double d = point_segments_dist2(p, next, prev, xs[k].i, x);
            if (d < bd) bd = d, reach = sqrt(bd) + half;
        }
        for (int k = lo - 1; k >= 0 && x.x - xs[k].x <= reach; --k) {
            double d = point_segments_dist2(p, next, prev, xs[k].i, x);
            if (d < bd) bd = d, reach = sqrt(bd) + half;
        }
        out[i] = sqrt(bd);
    }
    free(prev), free(xs);
    return SP_OK;
}

// The same through an exact single k-d tree (eps 0, unlimited checks).
static sp_result closest_kdtree(const sp_vec2* q, int nq, const sp_vec2* d, int nd, int* idx)
{
    struct FLANNParameters prm = DEFAULT_FLANN_PARAMETERS;
    prm.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    prm.checks = FLANN_CHECKS_UNLIMITED;
    prm.eps = 0.0f;
    prm.leaf_max_size = 10;
    prm.cores = 1;
    prm.log_level = FLANN_LOG_NONE;
    prm.random_seed = 1;
    double* dists = malloc(sizeof(double) * (size_t)nq);
    if (!dists) return SP_ERR_NO_MEMORY;
    float speedup = 0.0f;
    // sp_vec2 arrays are n by 2 doubles; FLANN's C API takes non-const
    // pointers but does not write through them.
    flann_index_t index = flann_build_index_double((double*)(void*)d, nd, 2, &speedup, &prm);
    if (!index) {
        free(dists);
        return SP_ERR_INTERNAL;
    }
    int rc = flann_find_nearest_neighbors_index_double(index, (double*)(void*)q, nq, idx, dists, 1, &prm);
    flann_free_index_double(index, &prm);
    free(dists);
    if (rc != 0) return SP_ERR_INTERNAL;
    for (int i = 0; i < nq; ++i)
        if (idx[i] < 0 || idx[i] >= nd) return SP_ERR_INTERNAL;
    return SP_OK;
}

sp_result sp_corr_closest(const sp_vec2* y, int my, const sp_vec2* z, int mz, sp_corr_pair* pairs, double* cost)
{
    if (my < 1 || mz < 1) return SP_ERR_INVALID;
    assert(y && z && pairs);
    if (!sp_curve_is_valid(y, my) || !sp_curve_is_valid(z, mz)) return SP_ERR_INVALID;
    // One scratch index array serves both directions and both methods.
    int* idx = malloc(sizeof(int) * (size_t)(my > mz ? my : mz));
    if (!idx) return SP_ERR_NO_MEMORY;
    bool brute = (double)my * (double)mz <= (double)SP_CORR_BRUTE_MAX;
    sp_result r = SP_OK;
    if (brute)
        closest_brute(y, my, z, mz, idx);
    else
        r = closest_kdtree(y, my, z, mz, idx);
    if (r == SP_OK) {
        for (int i = 0; i < my; ++i)
            pairs[i] = (sp_corr_pair){i, idx[i]};
        if (brute)
            closest_brute(z, mz, y, my, idx);
        else
            r = closest_kdtree(z, mz, y, my, idx);
    }
    if (r == SP_OK) {
        for (int j = 0; j < mz; ++j)
            pairs[my + j] = (sp_corr_pair){idx[j], j};
        if (cost) {
            double c = 0.0;
            for (int k = 0; k < my + mz; ++k)
                c += dist2(y[pairs[k].y], z[pairs[k].z]);
            *cost = c;
        }
    }
    free(idx);
    return r;
}
