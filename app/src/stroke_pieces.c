#include "stroke_pieces.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sp/curve.h"

#define PIECES_MAX 64
#define JOIN_GAP_SHARE 0.04
#define JOIN_TURN_MAX (40.0 * M_PI / 180.0)

// The point `along` px from end e of stroke st (0: its first point, 1: its last), walking in.
static sp_vec2 point_in_from(const sp_stroke* st, int e, double along)
{
    int n = st->count, i = e ? n - 1 : 0, step = e ? -1 : 1;
    double walked = 0;
    for (; i + step >= 0 && i + step < n; i += step) {
        double d = sp_v2_len(sp_v2_sub(st->points[i + step], st->points[i]));
        if (walked + d >= along) return st->points[i + step];
        walked += d;
    }
    return st->points[i];
}

// The way the pen goes through end e of st when it leaves the stroke there
// (leaving = true) or comes into it there: from the point `along` in.
static sp_vec2 way_at(const sp_stroke* st, int e, double along, bool leaving)
{
    sp_vec2 end = st->points[e ? st->count - 1 : 0], in = point_in_from(st, e, along);
    sp_vec2 d = leaving ? sp_v2_sub(end, in) : sp_v2_sub(in, end);
    double l = sp_v2_len(d);
    return l > 0 ? sp_v2_scale(d, 1.0 / l) : d;
}

static double angle_between(sp_vec2 a, sp_vec2 b)
{
    double la = sp_v2_len(a), lb = sp_v2_len(b);
    if (!(la > 0) || !(lb > 0)) return M_PI;
    return acos(fmax(-1.0, fmin(1.0, sp_v2_dot(a, b) / (la * lb))));
}

typedef struct join {
    int a, ea, b, eb; // the pen leaves a at its end ea and comes into b at its end eb
    double score;
} join;

static int by_score(const void* x, const void* y)
{
    double p = ((const join*)x)->score, q = ((const join*)y)->score;
    return (p > q) - (p < q);
}

static int root_of(int* up, int i)
{
    while (up[i] != i)
        i = up[i] = up[up[i]];
    return i;
}

// Whether q lies within r of stroke st's line.
static bool near_line(const sp_stroke* st, sp_vec2 q, double r)
{
    for (int j = 0; j + 1 < st->count; ++j)
        if (sp_v2_segment_dist(q, st->points[j], st->points[j + 1]) <= r) return true;
    return st->count == 1 && sp_v2_len(sp_v2_sub(q, st->points[0])) <= r;
}

// Whether a kept stroke other than a and b passes within r of q: a junction
// of the figure (two arms drawn out from the spine), not a pen lifted. A
// stroke that ends there does not pass: arms drawn from where the spine
// was lifted (the usual place, the chest) left its pieces apart, the head
// folded into the chest (a second review).
static bool at_junction(const sp_sketch* sk, const bool* keep, int a, int b, sp_vec2 q, double r)
{
    for (int i = 0; i < sk->stroke_count; ++i) {
        const sp_stroke* st = &sk->strokes[i];
        if (i == a || i == b || !keep[i] || sp_v2_len(sp_v2_sub(q, st->points[0])) <= 2 * r ||
            sp_v2_len(sp_v2_sub(q, st->points[st->count - 1])) <= 2 * r)
            continue;
        if (near_line(st, q, r)) return true;
    }
    return false;
}

// Every join of two kept strokes' ends within the gap and the turn, and
// away from the other strokes, scored (gap and turn, each as a share of its
// limit).
static int candidate_joins(const sp_sketch* sk, const bool* keep, double tol, join* out)
{
    int n = sk->stroke_count, m = 0;
    for (int a = 0; a < n; ++a)
        for (int b = a + 1; b < n; ++b) {
            if (!keep[a] || !keep[b]) continue;
            const sp_stroke *sa = &sk->strokes[a], *sb = &sk->strokes[b];
            double la = sp_curve_length(sa->points, sa->count, false), lb = sp_curve_length(sb->points, sb->count, false);
            for (int ea = 0; ea < 2; ++ea)
                for (int eb = 0; eb < 2; ++eb) {
                    sp_vec2 pa = sa->points[ea ? sa->count - 1 : 0], pb = sb->points[eb ? sb->count - 1 : 0];
                    sp_vec2 gap = sp_v2_sub(pb, pa);
                    double g = sp_v2_len(gap);
                    if (g > tol) continue;
                    sp_vec2 out_a = way_at(sa, ea, fmin(0.2 * la, 2 * tol), true);
                    sp_vec2 in_b = way_at(sb, eb, fmin(0.2 * lb, 2 * tol), false);
                    double turn = angle_between(out_a, in_b);
                    // Across a gap the pen goes on the way it went (a gap
                    // beside the line is another stroke's start); put down
                    // back on the line, it goes on over it (the usual way
                    // of lifting the pen: refused, the pieces of a leg
                    // overlapping 5 px were left apart; an outside review).
                    bool on = g <= 0.25 * tol || angle_between(out_a, gap) <= 1.5 * JOIN_TURN_MAX ||
                              near_line(sa, pb, fmax(2.0, 0.25 * tol));
                    double turn_far = angle_between(way_at(sa, ea, fmin(0.4 * la, 2 * tol), true),
                                                    way_at(sb, eb, fmin(0.4 * lb, 2 * tol), false));
                    // Either way of measuring within the limit: a drag of
                    // 1.5 px back at the lift of a 20 px piece read as 40.3
                    // degrees, and the arm was left out (a third review).
                    if (fmin(turn, turn_far) > JOIN_TURN_MAX || !on) continue;
                    // Two arms drawn out from the spine's side meet in a
                    // straight line there, as a line's pieces do.
                    if (at_junction(sk, keep, a, b, sp_v2_scale(sp_v2_add(pa, pb), 0.5), fmax(3.0, tol / 3))) continue;
                    // Ranked by the way the two pieces go over more of
                    // their length: where three or more ends meet (the
                    // spine lifted where the arms start), the arms' first
                    // few pixels ran straight across the chest as the
                    // spine's pieces did, and took the join.
                    out[m++] = (join){a, ea, b, eb, g / tol + fmax(turn, turn_far) / JOIN_TURN_MAX};
                }
        }
    qsort(out, (size_t)m, sizeof *out, by_score);
    return m;
}

// After join j: where it meets, three or more kept strokes' ends within a
// third of the gap limit make a junction of ends, which takes no other join
// (link -2).
static void close_junction(const sp_sketch* sk, const bool* keep, const join* j, double tol, int (*link)[2])
{
    const sp_stroke *sa = &sk->strokes[j->a], *sb = &sk->strokes[j->b];
    sp_vec2 q = sp_v2_scale(sp_v2_add(sa->points[j->ea ? sa->count - 1 : 0], sb->points[j->eb ? sb->count - 1 : 0]), 0.5);
    double r = fmax(3.0, tol / 3);
    int ends = 0;
    for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < sk->stroke_count; ++i)
            for (int e = 0; keep[i] && e < 2; ++e) {
                const sp_stroke* st = &sk->strokes[i];
                if (sp_v2_len(sp_v2_sub(st->points[e ? st->count - 1 : 0], q)) > r) continue;
                if (pass == 0)
                    ++ends;
                else if (ends >= 3 && link[i][e] == -1)
                    link[i][e] = -2;
            }
}

int sp_pieces_find(const sp_sketch* sk, const bool* keep, int most, int skip, int* next, bool* flip)
{
    int n = sk->stroke_count;
    for (int i = 0; i < n; ++i)
        next[i] = -1, flip[i] = false;
    if (n < 2 || n > PIECES_MAX || most < 1) return 0;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < n; ++i)
        for (int j = 0; keep[i] && j < sk->strokes[i].count; ++j) {
            sp_vec2 q = sk->strokes[i].points[j];
            lo[0] = fmin(lo[0], q.x), lo[1] = fmin(lo[1], q.y), hi[0] = fmax(hi[0], q.x), hi[1] = fmax(hi[1], q.y);
        }
    double tol = fmax(3.0, JOIN_GAP_SHARE * hypot(hi[0] - lo[0], hi[1] - lo[1]));
    join* cand = malloc(sizeof *cand * (size_t)(2 * n * n + 1));
    int link[PIECES_MAX][2], up[PIECES_MAX]; // link[i][e]: the stroke joined at end e of i (-1: none, -2: none allowed)
    if (!cand || !(tol < INFINITY)) {
        free(cand);
        return 0;
    }
    for (int i = 0; i < n; ++i)
        link[i][0] = link[i][1] = -1, up[i] = i;
    int m = candidate_joins(sk, keep, tol, cand), joins = 0;
    if (skip >= m) m = 0; // nothing else to try
    for (int k = 0; k < m && joins < most; ++k) {
        const join* j = &cand[k];
        if (k == skip) continue;
        int ra = root_of(up, j->a), rb = root_of(up, j->b);
        if (link[j->a][j->ea] != -1 || link[j->b][j->eb] != -1 || ra == rb) continue; // an end taken, or a loop
        link[j->a][j->ea] = j->b, link[j->b][j->eb] = j->a, up[ra] = rb, ++joins;
        // Where three or more ends meet (the spine lifted where the arms
        // start) one join is made: the arms' pieces were joined across the
        // chest too, and every line in three pieces fell apart (15.7 px).
        close_junction(sk, keep, j, tol, link);
    }
    free(cand);
    // Each line walked from a stroke with one end free, which it starts from.
    bool seen[PIECES_MAX] = {false};
    for (int h = 0; h < n; ++h) {
        if (seen[h] || (link[h][0] < 0) == (link[h][1] < 0)) continue;
        int at = h, in_end = link[h][0] < 0 ? 0 : 1; // the end the line comes into `at` by
        while (at >= 0) {
            seen[at] = true;
            flip[at] = in_end == 1; // it starts where its end 1 is: reversed
            int to = link[at][1 - in_end] >= 0 ? link[at][1 - in_end] : -1; // -2: an end left free at a junction
            next[at] = to;
            if (to >= 0) in_end = link[to][0] == at ? 0 : 1; // two strokes share one join at most
            at = to;
        }
    }
    return joins;
}

bool sp_pieces_join(const sp_sketch* sk, const int* next, const bool* flip, sp_sketch* lines, int* line_of)
{
    int n = sk->stroke_count;
    memset(lines, 0, sizeof *lines);
    lines->canvas_w = sk->canvas_w, lines->canvas_h = sk->canvas_h;
    bool* inner = calloc((size_t)n + 1, sizeof *inner); // comes after another on its line
    size_t total = 0;
    for (int i = 0; i < n; ++i)
        total += (size_t)sk->strokes[i].count;
    sp_vec2* pts = malloc(sizeof *pts * (total + 1));
    bool ok = inner && pts;
    for (int i = 0; ok && i < n; ++i)
        if (next[i] >= 0) inner[next[i]] = true;
    for (int i = 0; ok && i < n; ++i) {
        if (inner[i]) continue;
        int count = 0;
        for (int at = i; at >= 0; at = next[at]) {
            const sp_stroke* st = &sk->strokes[at];
            // A piece put down back over the last one: the points behind
            // where the line got to go (the line doubled back there).
            int from = 0;
            if (count >= 2) {
                sp_vec2 end = pts[count - 1], way = sp_v2_sub(end, pts[count > 4 ? count - 4 : 0]);
                while (from < st->count - 2 &&
                       sp_v2_dot(sp_v2_sub(st->points[flip[at] ? st->count - 1 - from : from], end), way) < 0)
                    ++from;
            }
            for (int j = from; j < st->count; ++j)
                pts[count + j - from] = st->points[flip[at] ? st->count - 1 - j : j];
            count += st->count - from;
            line_of[at] = lines->stroke_count;
        }
        ok = sp_sketch_add_stroke(lines, pts, NULL, count) == SP_OK;
    }
    free(inner), free(pts);
    if (!ok) sp_sketch_free(lines);
    return ok;
}
