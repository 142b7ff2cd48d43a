// match.c: the correspondence step of the ICP: resample the projected
// abstraction curves and the strokes to equal counts and pair their samples,
// ordered (with strokes assigned to curves regardless of drawing order and
// direction) or by closest points in both directions over all strokes.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "solver_internal.h"
#include "sp/curve.h"

// Arc-length resampling of curve c of the projected abstraction, as
// references to its points (so that samples stay linear in the rig's points).
// Unit normal of a resampled stroke at sample k (central difference within
// its stroke), (0, 0) where the stroke has no length there.
// Segment length of the projected abstraction: its coordinates are the
// camera's pixels (at most ~1e13 after the perspective clamp), so squares
// cannot overflow, and libm's hypot, which guards against that, is a visible
// share of a dragon part's solve (BENCHMARKS.md, "Measurements behind the
// solver's constants and stages"). (User strokes keep hypot: they may hold
// anything finite.)
static inline double seg_length(const double* a, const double* b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1];
    return sqrt(dx * dx + dy * dy);
}

static sp_vec2 stroke_normal(const sp_vec2* y, const int* ystroke, int my, int k)
{
    int a = k > 0 && ystroke[k - 1] == ystroke[k] ? k - 1 : k;
    int b = k + 1 < my && ystroke[k + 1] == ystroke[k] ? k + 1 : k;
    sp_vec2 t = sp_v2_sub(y[b], y[a]);
    double len = sqrt(t.x * t.x + t.y * t.y);
    if (!(len > 1e-12)) return (sp_vec2){0, 0};
    return (sp_vec2){-t.y / len, t.x / len};
}

static void resample_refs(const sp_solver* s, const sp_curve* cv, int m, sample_ref* out)
{
    int n = cv->point_count, f = cv->first_point;
    int segs = cv->closed ? n : n - 1;
    double total = 0;
    for (int i = 0; i < segs; ++i) {
        const double* a = s->z2 + 2 * (f + i);
        const double* b = s->z2 + 2 * (f + (i + 1) % n);
        total += seg_length(a, b);
    }
    int seg = 0;
    double acc = 0; // arc length at the start of seg
    for (int k = 0; k < m; ++k) {
        double target = cv->closed ? total * k / m : (m > 1 ? total * k / (m - 1) : 0);
        for (;;) {
            const double* a = s->z2 + 2 * (f + seg);
            const double* b = s->z2 + 2 * (f + (seg + 1) % n);
            double len = seg_length(a, b);
            if (acc + len >= target || seg + 1 >= segs) {
                double t = len > 0 ? (target - acc) / len : 0;
                out[k] = (sample_ref){f + seg, f + (seg + 1) % n, fmin(fmax(t, 0.0), 1.0)};
                break;
            }
            acc += len;
            ++seg;
        }
    }
    if (!cv->closed && m > 1) out[m - 1] = (sample_ref){f + n - 2, f + n - 1, 1.0}; // exact end point
}

static sp_vec2 ref_pos(const sp_solver* s, sample_ref r)
{
    const double* a = s->z2 + 2 * r.a;
    const double* b = s->z2 + 2 * r.b;
    return (sp_vec2){a[0] + r.t * (b[0] - a[0]), a[1] + r.t * (b[1] - a[1])};
}

static double curve_length2d(const sp_solver* s, const sp_curve* cv)
{
    double len = 0;
    int segs = cv->closed ? cv->point_count : cv->point_count - 1;
    for (int i = 0; i < segs; ++i) {
        const double* a = s->z2 + 2 * (cv->first_point + i);
        const double* b = s->z2 + 2 * (cv->first_point + (i + 1) % cv->point_count);
        len += seg_length(a, b);
    }
    return len;
}

// Samples per curve: the caller's fixed count, or about 400 over the whole
// abstraction in proportion to length, 16..160 per curve.
static int samples_for(const sp_solver* s, const sp_curve* cv, double total_len)
{
    if (s->d.samples > 0) return s->d.samples;
    double share = total_len > 0 ? curve_length2d(s, cv) / total_len : 1.0 / s->ab->curve_count;
    int m = (int)lround(400.0 * share);
    return m < 16 ? 16 : (m > 160 ? 160 : m);
}

static bool grow_pairs(sp_solver* s, int need)
{
    if (need <= s->pair_cap) return true;
    int cap = need + need / 2 + 16;
    pair* p = realloc(s->pairs, sizeof(pair) * (size_t)cap);
    if (!p) return false;
    s->pairs = p;
    s->pair_cap = cap;
    return true;
}

// Drawing-order independence for small stick figures, topology first: when
// there are at most 7 curves and as many strokes (or, in the attempt that
// asks for it, s->partial_topology, fewer but at least 2), every
// one-to-one assignment of the strokes to curves is scored by how many
// joints it breaks (two curves that meet at an end point must get two
// strokes that meet, and the other way round, among the curves that get a
// stroke), then by the ordered shape and length cost. Plain optimal
// assignment on shape cost alone swaps a spine and an arm that happen to
// overlap, and with a limb left undrawn it gave the spine a raised arm; the
// joints do not.
enum { TOPO_MAX = SP_TOPO_MAX };

static bool ends_meet(sp_vec2 a0, sp_vec2 a1, sp_vec2 b0, sp_vec2 b1, double eps)
{
    return sp_v2_len(sp_v2_sub(a0, b0)) < eps || sp_v2_len(sp_v2_sub(a0, b1)) < eps || sp_v2_len(sp_v2_sub(a1, b0)) < eps ||
           sp_v2_len(sp_v2_sub(a1, b1)) < eps;
}

typedef struct topo_search {
    int n, C;                        // strokes, curves (n <= C)
    double cost[TOPO_MAX][TOPO_MAX]; // stroke x curve
    bool sadj[TOPO_MAX][TOPO_MAX], cadj[TOPO_MAX][TOPO_MAX];
    int perm[TOPO_MAX], best[TOPO_MAX];
    bool used[TOPO_MAX];
    int best_breaks;
    double best_cost;
} topo_search;

static void topo_visit(topo_search* t, int s, int breaks, double cost)
{
    if (breaks > t->best_breaks || (breaks == t->best_breaks && cost >= t->best_cost)) return;
    if (s >= t->n || s >= TOPO_MAX) { // n <= TOPO_MAX; the second test tells the compiler so
        t->best_breaks = breaks, t->best_cost = cost;
        memcpy(t->best, t->perm, sizeof t->perm);
        return;
    }
    for (int c = 0; c < t->C; ++c) {
        if (t->used[c]) continue;
        int b = 0;
        for (int q = 0; q < s; ++q) b += t->sadj[s][q] != t->cadj[c][t->perm[q]];
        t->used[c] = true, t->perm[s] = c;
        topo_visit(t, s + 1, breaks + b, cost + t->cost[s][c]);
        t->used[c] = false;
    }
}

// The abstraction's own junctions: which curve ends meet which at the
// default pose (s->rest_meet, 2% of its diagonal there), for the
// directions below. The current pose's would do for a pose near it, not for
// a start with a hand at a foot or on the head (an outside review: chained
// `pose --start` from a squat paired arms by a hand-knee meeting).
void sp__rest_junctions(sp_solver* s, double* scratch)
{
    const int C = s->ab->curve_count;
    s->rest_meet_valid = false;
    if (C < 2 || C > TOPO_MAX) return;
    for (int i = 0; i < s->P; ++i)
        scratch[i] = s->model->params[i].def;
    sp__model_update(s, scratch, false);
    sp__project_abstraction(s);
    double box[4];
    sp__projected_box(s, box);
    double eps = 0.02 * hypot(box[2] - box[0], box[3] - box[1]);
    sp_vec2 ce[TOPO_MAX][2];
    for (int c = 0; c < C; ++c) {
        const sp_curve* cv = &s->ab->curves[c];
        int k0 = cv->first_point, k1 = cv->first_point + cv->point_count - 1;
        ce[c][0] = (sp_vec2){s->z2[2 * k0], s->z2[2 * k0 + 1]}, ce[c][1] = (sp_vec2){s->z2[2 * k1], s->z2[2 * k1 + 1]};
    }
    for (int c = 0; c < C; ++c)
        for (int f = 0; f < 2; ++f) {
            s->rest_meet[c][f] = 0;
            for (int d = 0; d < C; ++d)
                for (int g = 0; g < 2 && d != c; ++g)
                    if (sp_v2_len(sp_v2_sub(ce[c][f], ce[d][g])) < eps) s->rest_meet[c][f] |= (uint16_t)(1u << (2 * d + g));
        }
    s->rest_meet_valid = !s->model->failed && eps > 0;
}

// Which way each assigned stroke runs along its curve when the joints tell
// it (topo_rev of the solver): of every way to run the open curves' strokes,
// the ones that keep the most junctions (two stroke ends that meet go to two
// curve ends that meet at rest, s->rest_meet) win; a stroke whose direction
// they do not all agree on, or a closed curve's, is not told (-1). The
// direction with the least squared distance at the current pose pairs an arm
// drawn hanging with one raised from its hand to its shoulder, and a solve
// that starts there folds it (an outside review: pose --start from raised
// arms, 11.4 px); hands drawn touching meet as shoulders do, and only the
// whole figure's junctions tell them apart.
static void topology_directions(const sp_solver* s, const sp_polyline* lines, int n, sp_vec2 (*se)[2], double seps,
                                const int* best, signed char* rev)
{
    for (int i = 0; i < n; ++i)
        rev[best[i]] = -1;
    if (!s->rest_meet_valid) return;
    int meet[TOPO_MAX * TOPO_MAX * 4][4], m = 0; // stroke i end e meets stroke j end g
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            for (int e = 0; e < 2; ++e)
                for (int g = 0; g < 2; ++g)
                    if (sp_v2_len(sp_v2_sub(se[i][e], se[j][g])) < seps)
                        meet[m][0] = i, meet[m][1] = e, meet[m][2] = j, meet[m++][3] = g;
    unsigned closed = 0;
    for (int i = 0; i < n; ++i)
        closed |= (unsigned)lines[best[i]].closed << i;
    int top = 0;
    unsigned top_mask = 0, agree = 0;
    for (unsigned mask = 0; mask < 1u << n; ++mask) {
        if (mask & closed) continue;
        int kept = 0;
        for (int k = 0; k < m; ++k) {
            int i = meet[k][0], j = meet[k][2], f = meet[k][1] ^ (int)(mask >> i & 1), g = meet[k][3] ^ (int)(mask >> j & 1);
            kept += s->rest_meet[best[i]][f] >> (2 * best[j] + g) & 1;
        }
        if (kept > top)
            top = kept, top_mask = mask, agree = ~0u;
        else if (kept == top && top > 0)
            agree &= ~(mask ^ top_mask);
    }
    for (int i = 0; top > 0 && i < n; ++i)
        if (!(closed >> i & 1) && (agree >> i & 1)) rev[best[i]] = (signed char)(top_mask >> i & 1);
}

// Fills c2s (curve -> stroke) and rev (topology_directions) and returns
// true when the topology search applies.
static bool assign_by_topology(const sp_solver* s, const sp_sketch* sk, const sp_polyline* lines, int C, int* c2s,
                               signed char* rev)
{
    int n = sk->stroke_count;
    if (n > C || n < 2 || C > TOPO_MAX || (n < C && !s->partial_topology)) return false;
    enum { M = 48 };
    topo_search t = {.n = n, .C = C, .best_breaks = 1 << 30, .best_cost = INFINITY};
    sp_vec2 y[M], z[M], se[TOPO_MAX][2], ce[TOPO_MAX][2];
    double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
    for (int i = 0; i < n; ++i) {
        const sp_stroke* st = &sk->strokes[i];
        se[i][0] = st->points[0], se[i][1] = st->points[st->count - 1];
        for (int k = 0; k < st->count; ++k) {
            lo_x = fmin(lo_x, st->points[k].x), hi_x = fmax(hi_x, st->points[k].x);
            lo_y = fmin(lo_y, st->points[k].y), hi_y = fmax(hi_y, st->points[k].y);
        }
    }
    for (int c = 0; c < C; ++c) ce[c][0] = lines[c].points[0], ce[c][1] = lines[c].points[lines[c].count - 1];
    double seps = 0.05 * hypot(hi_x - lo_x, hi_y - lo_y), ceps = 0.02 * s->L;
    bool any = false;
    for (int a = 0; a < C; ++a)
        for (int b = 0; b < C; ++b) {
            t.sadj[a][b] = a != b && a < n && b < n && ends_meet(se[a][0], se[a][1], se[b][0], se[b][1], seps);
            t.cadj[a][b] = a != b && ends_meet(ce[a][0], ce[a][1], ce[b][0], ce[b][1], ceps);
            any |= t.cadj[a][b];
        }
    if (!any) return false;
    for (int i = 0; i < n; ++i) {
        const sp_stroke* st = &sk->strokes[i];
        // Canonical direction, so that a reversed stroke gives the same costs.
        bool flip = st->points[0].x > st->points[st->count - 1].x ||
                    (st->points[0].x == st->points[st->count - 1].x && st->points[0].y > st->points[st->count - 1].y);
        sp_vec2* tmp = malloc(sizeof(sp_vec2) * (size_t)st->count);
        if (!tmp) return false;
        for (int k = 0; k < st->count; ++k) tmp[k] = st->points[flip ? st->count - 1 - k : k];
        for (int c = 0; c < C; ++c) {
            sp_ordered_info info = {0};
            if (sp_curve_resample(tmp, st->count, lines[c].closed, M, y) != SP_OK ||
                sp_curve_resample(lines[c].points, lines[c].count, lines[c].closed, M, z) != SP_OK ||
                sp_corr_ordered(y, z, M, lines[c].closed, NULL, &info) != SP_OK) {
                free(tmp);
                return false;
            }
            double dl = sp_curve_length(tmp, st->count, false) - sp_curve_length(lines[c].points, lines[c].count, false);
            // Plus the squared length difference: projected lengths tell a
            // short neck from an arm that meets it at the same joint.
            t.cost[i][c] = info.cost / M + 4.0 * dl * dl;
        }
        free(tmp);
    }
    topo_visit(&t, 0, 0, 0.0);
    for (int c = 0; c < C; ++c)
        c2s[c] = -1, rev[c] = -1;
    for (int i = 0; i < n; ++i) c2s[t.best[i]] = i;
    topology_directions(s, lines, n, se, seps, t.best, rev);
    return true;
}

// The loop's best shifts at the current projection, for the further
// attempts of sp_solver_solve (icp.c).
int sp__loop_candidates(sp_solver* s, const sp_sketch* sk, sp_ordered_info* out, int k, int* m)
{
    const sp_curve* cv = &s->ab->curves[0];
    *m = samples_for(s, cv, curve_length2d(s, cv));
    sp_vec2* y = malloc(sizeof(sp_vec2) * (size_t)*m);
    sp_vec2* z = malloc(sizeof(sp_vec2) * (size_t)*m);
    sample_ref* refs = malloc(sizeof(sample_ref) * (size_t)*m);
    int n = 0;
    if (y && z && refs && sp_curve_resample(sk->strokes[0].points, sk->strokes[0].count, true, *m, y) == SP_OK) {
        resample_refs(s, cv, *m, refs);
        for (int i = 0; i < *m; ++i) z[i] = ref_pos(s, refs[i]);
        n = sp_corr_ordered_candidates(y, z, *m, out, k);
    }
    free(y), free(z), free(refs);
    return n;
}

// The strokes resampled for closest points, msum samples in all shared by
// length (at least 8 a stroke), into s->ypoly with each sample's stroke.
static sp_result resample_strokes(sp_solver* s, const sp_sketch* sk, int msum, sp_error* err)
{
    s->ypoly_valid = false;
    double slen_total = 0;
    double* slen = malloc(sizeof(double) * (size_t)sk->stroke_count);
    int* scount = malloc(sizeof(int) * (size_t)sk->stroke_count);
    if (!slen || !scount) {
        free(slen), free(scount);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while matching strokes");
    }
    for (int i = 0; i < sk->stroke_count; ++i) slen_total += slen[i] = sp_curve_length(sk->strokes[i].points, sk->strokes[i].count, false);
    int my = 0;
    for (int i = 0; i < sk->stroke_count; ++i) {
        double share = slen_total > 0 ? slen[i] / slen_total : 0;
        scount[i] = (int)lround(msum * share);
        if (scount[i] < 8) scount[i] = 8;
        my += scount[i];
    }
    sp_result res = SP_OK;
    if (my > s->ypoly_cap) {
        sp_vec2* yp = realloc(s->ypoly, sizeof(sp_vec2) * (size_t)my);
        if (yp) s->ypoly = yp;
        int* ys = realloc(s->ypoly_stroke, sizeof(int) * (size_t)my);
        if (ys) s->ypoly_stroke = ys;
        if (!yp || !ys) res = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while matching strokes");
        else s->ypoly_cap = my;
    }
    for (int i = 0, at = 0; res == SP_OK && i < sk->stroke_count; ++i) {
        res = sp_curve_resample(sk->strokes[i].points, sk->strokes[i].count, false, scount[i], s->ypoly + at);
        if (res != SP_OK) sp_fail(err, res, "stroke %d cannot be resampled", i);
        for (int k = 0; k < scount[i]; ++k) s->ypoly_stroke[at + k] = i;
        at += scount[i];
    }
    free(slen), free(scount);
    s->ypoly_count = res == SP_OK ? my : 0;
    s->ypoly_total = msum;
    s->ypoly_valid = res == SP_OK;
    return res;
}

// The curves' sample counts (samples_for) over the whole abstraction: their
// total and the largest.
static void sample_counts(const sp_solver* s, double total_len, int* msum, int* mmax)
{
    *mmax = 1, *msum = 0;
    for (int c = 0; c < s->ab->curve_count; ++c) {
        int m = samples_for(s, &s->ab->curves[c], total_len);
        *mmax = m > *mmax ? m : *mmax;
        *msum += m;
    }
}

// Which stroke each curve gets (c2s, curve -> stroke or -1): the last
// assignment when `keep` asks for it, else by topology when that applies,
// else by shape (sp_assign_strokes). Sets rep->unused_strokes.
static sp_result assign_curves(sp_solver* s, const sp_sketch* sk, const sp_polyline* lines, bool keep, int* c2s,
                               sp_solve_report* rep, sp_error* err)
{
    const int C = s->ab->curve_count;
    rep->unused_strokes = 0;
    if (keep && s->c2s_valid) {
        memcpy(c2s, s->c2s, sizeof(int) * (size_t)C);
        for (int c = 0; c < C; ++c)
            rep->unused_strokes -= c2s[c] >= 0;
        rep->unused_strokes += sk->stroke_count;
    } else if (sk->stroke_count == 1 && s->one_stroke_curve >= 0 && s->one_stroke_curve < C) { // icp.c tries each
        for (int c = 0; c < C && c < SP_REPORT_CURVES; ++c)
            c2s[c] = c == s->one_stroke_curve ? 0 : -1, s->topo_rev[c] = -1;
    } else if (!assign_by_topology(s, sk, lines, C, c2s, s->topo_rev)) { // C <= TOPO_MAX when it applies
        for (int c = 0; c < C && c < SP_REPORT_CURVES; ++c)
            s->topo_rev[c] = -1;
        sp_stroke_match* sm = malloc(sizeof(sp_stroke_match) * (size_t)sk->stroke_count);
        if (!sm) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while matching strokes");
        sp_result res =
            sp_assign_strokes(sk->strokes, sk->stroke_count, lines, C, &(sp_assign_desc){.samples = 64}, sm, c2s, err);
        for (int i = 0; res == SP_OK && i < sk->stroke_count; ++i)
            rep->unused_strokes += sm[i].curve < 0;
        free(sm);
        if (res != SP_OK) return res;
    }
    if (C <= SP_REPORT_CURVES) {
        memcpy(s->c2s, c2s, sizeof(int) * (size_t)C);
        s->c2s_valid = true;
    }
    return SP_OK;
}

// Ordered pairs: strokes assigned to curves, each pair of stroke and curve
// resampled to the curve's count and paired in order (direction detected,
// best cyclic shift for closed curves, or how->loop_shift held).
static sp_result ordered_pairs(sp_solver* s, const sp_sketch* sk, const sp_pairing* how, double total_len, sp_solve_report* rep,
                               sp_error* err)
{
    const sp_abstraction* ab = s->ab;
    const int C = ab->curve_count;
    int mmax, msum;
    sample_counts(s, total_len, &msum, &mmax);
    sp_polyline* lines = malloc(sizeof(sp_polyline) * (size_t)C);
    sp_vec2* pts = malloc(sizeof(sp_vec2) * (size_t)ab->point_count);
    int* c2s = malloc(sizeof(int) * (size_t)C);
    sp_vec2* y = malloc(sizeof(sp_vec2) * (size_t)mmax);
    sp_vec2* z = malloc(sizeof(sp_vec2) * (size_t)mmax);
    sample_ref* refs = malloc(sizeof(sample_ref) * (size_t)mmax);
    int* match = malloc(sizeof(int) * (size_t)mmax);
    sp_result res = SP_OK;
    if (!lines || !pts || !c2s || !y || !z || !refs || !match || !grow_pairs(s, msum)) {
        res = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while matching strokes");
        goto done;
    }
    for (int i = 0; i < ab->point_count; ++i)
        pts[i] = (sp_vec2){s->z2[2 * i], s->z2[2 * i + 1]};
    for (int c = 0; c < C; ++c)
        lines[c] = (sp_polyline){pts + ab->curves[c].first_point, ab->curves[c].point_count, ab->curves[c].closed};
    res = assign_curves(s, sk, lines, how->keep_assignment, c2s, rep, err);
    for (int c = 0; res == SP_OK && c < C; ++c) {
        int st = c2s[c];
        if (st < 0) continue;
        const sp_curve* cv = &ab->curves[c];
        int m = samples_for(s, cv, total_len);
        res = sp_curve_resample(sk->strokes[st].points, sk->strokes[st].count, cv->closed, m, y);
        if (res != SP_OK) {
            sp_fail(err, res, "stroke %d cannot be resampled", st);
            break;
        }
        resample_refs(s, cv, m, refs);
        for (int k = 0; k < m; ++k)
            z[k] = ref_pos(s, refs[k]);
        sp_ordered_info info;
        if (how->loop_shift && cv->closed && C == 1) {
            info = *how->loop_shift;
            sp_corr_ordered_match(&info, m, match);
        } else if (s->d.ordered_by_ends && !cv->closed) {
            bool held = c < SP_REPORT_CURVES && s->end_stroke[c] == st;
            sp_vec2 y0 = y[0], y1 = y[m - 1], z0 = z[0], z1 = z[m - 1];
            bool rev = held ? s->end_rev[c]
                            : hypot(y0.x - z0.x, y0.y - z0.y) + hypot(y1.x - z1.x, y1.y - z1.y) >
                                  hypot(y0.x - z1.x, y0.y - z1.y) + hypot(y1.x - z0.x, y1.y - z0.y);
            if (c < SP_REPORT_CURVES) s->end_stroke[c] = st, s->end_rev[c] = rev;
            info = (sp_ordered_info){rev, rev ? m - 1 : 0, 0};
            sp_corr_ordered_match(&info, m, match);
            info.shift = 0;
        } else if (c < SP_REPORT_CURVES && s->topo_rev[c] >= 0) {
            info = (sp_ordered_info){s->topo_rev[c] != 0, s->topo_rev[c] ? m - 1 : 0, 0};
            sp_corr_ordered_match(&info, m, match);
            info.shift = 0;
        } else {
            res = sp_corr_ordered(y, z, m, cv->closed, match, &info);
        }
        if (res != SP_OK) {
            sp_fail(err, res, "stroke %d: no ordered correspondence", st);
            break;
        }
        for (int k = 0; k < m; ++k)
            s->pairs[s->pair_count++] = (pair){.y = y[k], .s = refs[match[k]], .curve = c}; // ordered: no normal
        if (c < SP_REPORT_CURVES) rep->curves[c].stroke = st, rep->curves[c].reversed = info.reversed;
    }
    if (res == SP_OK && rep->unused_strokes > 0)
        snprintf(rep->note, sizeof rep->note, "%d stroke(s) more than the abstraction's %d curve(s) were left unused",
                 rep->unused_strokes, C);
done:
    free(lines), free(pts), free(c2s), free(y), free(z), free(refs), free(match);
    return res;
}

// Closest points, both ways, over all strokes and all curves at once: the
// strokes get as many samples in all as the curves, by length. They do not
// move during a solve, so their samples are kept (s->ypoly) and made again
// only for a new solve or another total count.
static sp_result closest_pairs(sp_solver* s, const sp_sketch* sk, double total_len, sp_solve_report* rep, sp_error* err)
{
    const sp_abstraction* ab = s->ab;
    const int C = ab->curve_count;
    int mmax, msum;
    sample_counts(s, total_len, &msum, &mmax);
    sp_result res = SP_OK;
    if (!s->ypoly_valid || s->ypoly_total != msum) {
        res = resample_strokes(s, sk, msum, err);
        if (res != SP_OK) return res;
    }
    const sp_vec2* y = s->ypoly;
    const int* ystroke = s->ypoly_stroke;
    const int my = s->ypoly_count;
    sp_vec2* z = malloc(sizeof(sp_vec2) * (size_t)msum);
    sample_ref* refs = malloc(sizeof(sample_ref) * (size_t)msum);
    int* zcurve = malloc(sizeof(int) * (size_t)msum);
    sp_corr_pair* cp = malloc(sizeof(sp_corr_pair) * (size_t)(my + msum));
    int* votes = calloc((size_t)C * (size_t)sk->stroke_count, sizeof(int));
    if (!z || !refs || !zcurve || !cp || !votes || !grow_pairs(s, my + msum)) {
        res = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while matching strokes");
        goto done;
    }
    int at = 0;
    for (int c = 0; c < C; ++c) {
        int m = samples_for(s, &ab->curves[c], total_len);
        resample_refs(s, &ab->curves[c], m, refs + at);
        for (int k = 0; k < m; ++k)
            z[at + k] = ref_pos(s, refs[at + k]), zcurve[at + k] = c;
        at += m;
    }
    res = sp_corr_closest(y, my, z, msum, cp, NULL);
    if (res != SP_OK) {
        sp_fail(err, res, "closest-point correspondences failed");
        goto done;
    }
    for (int i = 0; i < my + msum; ++i) {
        int c = zcurve[cp[i].z];
        s->pairs[s->pair_count++] = (pair){y[cp[i].y], refs[cp[i].z], c, stroke_normal(y, ystroke, my, cp[i].y), i >= my};
        votes[c * sk->stroke_count + ystroke[cp[i].y]]++;
    }
    for (int c = 0; c < rep->curve_count; ++c) {
        int best = -1, bv = 0;
        for (int i = 0; i < sk->stroke_count; ++i)
            if (votes[c * sk->stroke_count + i] > bv) bv = votes[c * sk->stroke_count + i], best = i;
        rep->curves[c].stroke = best;
    }
done:
    free(z), free(refs), free(zcurve), free(cp), free(votes);
    return res;
}

sp_result sp__build_pairs(sp_solver* s, const sp_sketch* sk, const sp_pairing* how, sp_solve_report* rep, sp_error* err)
{
    const sp_abstraction* ab = s->ab;
    const int C = ab->curve_count;
    s->pair_count = 0;
    rep->curve_count = C < SP_REPORT_CURVES ? C : SP_REPORT_CURVES;
    for (int c = 0; c < rep->curve_count; ++c)
        rep->curves[c] = (sp_curve_report){c, -1, false, 0, 0};
    double total_len = 0;
    for (int c = 0; c < C; ++c)
        total_len += curve_length2d(s, &ab->curves[c]);
    return how->mode == SP_CORR_ORDERED ? ordered_pairs(s, sk, how, total_len, rep, err)
                                        : closest_pairs(s, sk, total_len, rep, err);
}
