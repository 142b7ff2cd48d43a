// solve_cmd.c: the solve-report-write path of the posing commands (see solve_cmd.h).
#include "solve_cmd.h"
#include "stroke_pieces.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "outputs.h"
#include "report.h"
#include "sp/curve.h"
#include "sp/snapshot.h"

// A fit whose mean error is small can still leave one curve far from its
// stroke: a stick figure drawn with no neck line had its arm stroke taken
// by the neck curve, at 1% mean error, with nothing said. A curve farther
// than 4% of the abstraction's size from its stroke on average is named
// (good fits, synthetic targets of four characters solved from rest, stay
// at 3% or under; such misses measured 4.4-12%). The kiosk's fits do
// not pass here: its visitors' strokes are loose by design. Else a curve
// farther than LOOSE_MAX_SHARE from its stroke at one place is named.
#define LOOSE_MAX_SHARE 0.10

static void note_loose_curve(sp_solve_report* rep, const sp_abstraction* ab)
{
    // After a note that strokes were left unused (which says nothing of
    // the fit), not after a best-effort one (which says it all).
    if (strstr(rep->note, "best effort") || !(rep->bbox_diagonal_px > 0)) return;
    int worst = -1;
    for (int i = 0; i < rep->curve_count; ++i)
        if (rep->curves[i].stroke >= 0 && (worst < 0 || rep->curves[i].mean_px > rep->curves[worst].mean_px)) worst = i;
    if (worst < 0) return;
    const sp_curve_report* c = &rep->curves[worst];
    double share = c->mean_px / rep->bbox_diagonal_px;
    size_t at = strlen(rep->note);
    if (share > 0.04 && c->curve >= 0 && c->curve < ab->curve_count) {
        snprintf(rep->note + at, sizeof rep->note - at,
                 "%sloose fit: curve '%s' lies %.1f px (%.1f%% of the abstraction's size) from stroke %d on average: a stroke "
                 "missing or drawn otherwise?",
                 at ? "; " : "", ab->curves[c->curve].name, c->mean_px, 100.0 * share, c->stroke);
        return;
    }
    // One curve (an outline) averages a whole limb missed away: an outline
    // drawn in two pieces fitted with its raised arms down, 5.3 px on
    // average but 57 px (15%) at the arms, with nothing said (an outside
    // review).
    worst = -1;
    for (int i = 0; i < rep->curve_count; ++i)
        if (rep->curves[i].stroke >= 0 && (worst < 0 || rep->curves[i].max_px > rep->curves[worst].max_px)) worst = i;
    c = &rep->curves[worst];
    share = c->max_px / rep->bbox_diagonal_px;
    if (share <= LOOSE_MAX_SHARE || c->curve < 0 || c->curve >= ab->curve_count) return;
    snprintf(rep->note + at, sizeof rep->note - at,
             "%sloose fit: curve '%s' lies up to %.1f px (%.1f%% of the abstraction's size) from stroke %d: a part of the "
             "drawing the fit does not follow",
             at ? "; " : "", ab->curves[c->curve].name, c->max_px, 100.0 * share, c->stroke);
}

// A fit left loose with the root's translation at a bound: the drawing lies
// farther than the character may be moved, which the loose-fit note blamed
// on the strokes (a figure drawn 150 px aside: "a stroke missing?"; an
// outside review).
static void note_placement_bound(sp_solve_report* rep, const sp_param* params, int n, const double* p)
{
    if (!strstr(rep->note, "best effort") && !strstr(rep->note, "loose fit")) return;
    for (int i = 0; i < n && params[i].joint == params[0].joint; ++i) {
        const sp_param* q = &params[i];
        bool place = q->channel >= SP_CH_TX && q->channel <= SP_CH_TZ;
        double span = q->max - q->min, v = p[i];
        if (!place || !(span > 0) || (v > q->min + 1e-6 * span && v < q->max - 1e-6 * span)) continue;
        size_t at = strlen(rep->note);
        snprintf(rep->note + at, sizeof rep->note - at,
                 "; %s stopped at its bound %g: the drawing lies beyond where the character may be moved", q->name,
                 v <= q->min + 1e-6 * span ? q->min : q->max);
        return;
    }
}

// Fewer strokes than curves: each stroke goes to the curve it matches best,
// which need not be the one meant (one raised arm drawn alone was taken by
// the spine and folded the figure, 0.25 px, "converged", nothing said). The
// curves left without a stroke, and where the strokes went, are named
// (after a best-effort note: they often explain it).
static void note_unmatched_curves(sp_solve_report* rep, const sp_abstraction* ab)
{
    // Three names of each at most (a curve's name is up to 63 bytes), after
    // the best-effort or loose-fit note that may come first.
    char left[220] = "", took[260] = "";
    int n_left = 0, n_took = 0;
    for (int i = 0; i < rep->curve_count; ++i) {
        const sp_curve_report* c = &rep->curves[i];
        if (c->curve < 0 || c->curve >= ab->curve_count) continue;
        size_t at = c->stroke < 0 ? strlen(left) : strlen(took);
        if (c->stroke < 0 && ++n_left <= 3)
            snprintf(left + at, sizeof left - at, "%s'%s'", at ? ", " : "", ab->curves[c->curve].name);
        else if (c->stroke >= 0 && ++n_took <= 3)
            snprintf(took + at, sizeof took - at, "%sstroke %d '%s'", at ? ", " : "", c->stroke, ab->curves[c->curve].name);
    }
    if (n_left == 0) return;
    size_t at = strlen(rep->note);
    snprintf(rep->note + at, sizeof rep->note - at, "%s%d curve%s without a stroke (%s%s); the strokes took: %s%s",
             at ? "; " : "", n_left, n_left == 1 ? "" : "s", left, n_left > 3 ? ", ..." : "", took, n_took > 3 ? ", ..." : "");
}

static bool solve_picked(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                         double* p, sp_solve_report* rep, sp_error* err);

// ---- strokes left out before a solve

enum { STROKE_KEPT = -1, STROKE_DOT = -2, STROKE_LEFT_OUT = -3 }; // else: the stroke it traces over

static void stroke_box(const sp_stroke* st, double box[4])
{
    box[0] = box[1] = INFINITY, box[2] = box[3] = -INFINITY;
    for (int j = 0; j < st->count; ++j) {
        box[0] = fmin(box[0], st->points[j].x), box[1] = fmin(box[1], st->points[j].y);
        box[2] = fmax(box[2], st->points[j].x), box[3] = fmax(box[3], st->points[j].y);
    }
}

// Whether stroke b traces over stroke a: 90% of 32 points along b lie within
// tol of a (a's polyline at up to 256 of its points).
static bool traces_over(const sp_stroke* b, const sp_stroke* a, double tol)
{
    int na = a->count < 256 ? a->count : 256, near = 0;
    for (int k = 0; k < 32; ++k) {
        sp_vec2 q = b->points[(int)((long)k * (b->count - 1) / 31)];
        double d = INFINITY;
        for (int i = 1; i < na && d > tol; ++i)
            d = fmin(d, sp_v2_segment_dist(q, a->points[(int)((long)(i - 1) * (a->count - 1) / (na - 1))],
                                           a->points[(int)((long)i * (a->count - 1) / (na - 1))]));
        near += d <= tol;
    }
    return near >= 29;
}

// The dots (pen taps: dot eyes) of sk, which are no curve: why[i]
// STROKE_DOT, else STROKE_KEPT; the number kept returned.
static int mark_dots(const sp_sketch* sk, int* why)
{
    int kept = 0;
    for (int i = 0; i < sk->stroke_count; ++i) {
        why[i] = sk->strokes[i].count >= 2 && sp_curve_length(sk->strokes[i].points, sk->strokes[i].count, false) > 0
                     ? STROKE_KEPT
                     : STROKE_DOT;
        kept += why[i] == STROKE_KEPT;
    }
    return kept;
}

// With more kept strokes than the abstraction's `curves`, the strokes that
// trace over a longer kept one (a line gone over twice, as sketchy drawing
// does), shortest first, while strokes are over: why[j] = the stroke it
// traces over. The number kept returned. Drawn within 2.5% of the
// drawing's size (at least 2 px): a wobbly retrace strays 6 px. Only up to
// RETRACE_MAX_STROKES strokes (more is hatching, and the pairs' test grows
// with their square).
#define RETRACE_MAX_STROKES 64
static int mark_retraces(const sp_sketch* sk, int curves, int kept, int* why)
{
    int n = sk->stroke_count;
    if (kept <= curves || n > RETRACE_MAX_STROKES) return kept;
    double len[RETRACE_MAX_STROKES], box[4 * RETRACE_MAX_STROKES];
    double all[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < n; ++i) {
        len[i] = why[i] == STROKE_KEPT ? sp_curve_length(sk->strokes[i].points, sk->strokes[i].count, false) : 0;
        stroke_box(&sk->strokes[i], box + 4 * i);
        for (int c = 0; c < 2; ++c)
            all[c] = fmin(all[c], box[4 * i + c]), all[2 + c] = fmax(all[2 + c], box[4 * i + 2 + c]);
    }
    const double tol = fmax(2.0, 0.025 * hypot(all[2] - all[0], all[3] - all[1]));
    bool over[RETRACE_MAX_STROKES][RETRACE_MAX_STROKES]; // [j][i]: j traces over i
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double *bj = box + 4 * j, *bi = box + 4 * i;
            over[j][i] = i != j && why[i] == STROKE_KEPT && why[j] == STROKE_KEPT && len[i] >= len[j] && bj[0] >= bi[0] - tol &&
                         bj[1] >= bi[1] - tol && bj[2] <= bi[2] + tol && bj[3] <= bi[3] + tol &&
                         traces_over(&sk->strokes[j], &sk->strokes[i], tol);
        }
    while (kept > curves) {
        int drop = -1, onto = -1;
        for (int j = 0; j < n; ++j) {
            if (why[j] != STROKE_KEPT || (drop >= 0 && len[j] >= len[drop])) continue;
            for (int i = 0; i < n; ++i)
                if (over[j][i] && why[i] == STROKE_KEPT) {
                    drop = j;
                    break;
                }
        }
        if (drop < 0) break;
        for (int i = 0; i < n; ++i) // named: the longest kept stroke it traces over
            if (over[drop][i] && why[i] == STROKE_KEPT && (onto < 0 || len[i] > len[onto])) onto = i;
        why[drop] = onto, --kept;
    }
    return kept;
}

// The solver's note that strokes were left unused counted them, of the strokes
// it was given: replaced by one that names them, the strokes left out before
// the solve (`why`) with theirs.
static void note_unused_strokes(sp_solve_report* rep, const int* why, const int* used, int n)
{
    const char* solver_said = "stroke(s) more than the abstraction's";
    const char* at = strstr(rep->note, solver_said);
    if (at) { // "N stroke(s) more than ... were left unused" starts the note (match.c)
        const char* end = strchr(at, ';');
        memmove(rep->note, end ? end + 2 : at + strlen(at), strlen(end ? end + 2 : at + strlen(at)) + 1);
    }
    char list[160] = "";
    int count = 0, cut = 0;
    size_t w = 0;
    for (int i = 0; i < n; ++i) {
        if (why[i] == STROKE_KEPT && used[i]) continue;
        ++count;
        char one[48];
        int k = snprintf(one, sizeof one, "%s%d%s", w ? ", " : "", i,
                         why[i] == STROKE_DOT        ? " (a dot)"
                         : why[i] == STROKE_LEFT_OUT ? " (the rest fit better without it)"
                                                     : "");
        if (why[i] >= 0) k = snprintf(one, sizeof one, "%s%d (traced over stroke %d)", w ? ", " : "", i, why[i]);
        if (cut || w + (size_t)k + 6 >= sizeof list) { // room for ", ..."
            ++cut;
            continue;
        }
        memcpy(list + w, one, (size_t)k + 1);
        w += (size_t)k;
    }
    if (cut) snprintf(list + w, sizeof list - w, ", ...");
    rep->unused_strokes = count;
    if (count == 0) return;
    char rest[sizeof rep->note];
    snprintf(rest, sizeof rest, "%s", rep->note);
    int said = snprintf(rep->note, sizeof rep->note, "%d stroke%s left unused: %s%s%s", count, count == 1 ? "" : "s", list,
                        rest[0] ? "; " : "", rest);
    if (said >= (int)sizeof rep->note) memcpy(rep->note + sizeof rep->note - 4, "...", 4); // a long note says it was cut
}

// The solve of sk's strokes that why[] keeps (all of them when it keeps
// none: the solver says why), its report's strokes numbered as in sk;
// used[i]: stroke i took a curve (closest pairs: every stroke kept does).
static bool solve_kept(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const int* why,
                       const double* start, double* p, sp_solve_report* rep, int* used, sp_error* err)
{
    int n = sk->stroke_count, kept = 0;
    for (int i = 0; i < n; ++i)
        kept += why[i] == STROKE_KEPT;
    sp_sketch picked = *sk;
    sp_stroke* some = kept > 0 && kept < n ? malloc(sizeof *some * (size_t)kept) : NULL;
    int* orig = malloc(sizeof(int) * (size_t)(n + 1));
    if (!orig || (kept > 0 && kept < n && !some)) {
        free(some), free(orig);
        sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        fprintf(stderr, "%s: %s: %s\n", s->cmd, strokes, err->text);
        return false;
    }
    for (int i = 0, k = 0; i < n; ++i)
        if (!some || why[i] == STROKE_KEPT) {
            if (some) some[k] = sk->strokes[i];
            orig[k++] = i;
        }
    if (some) picked.strokes = some, picked.stroke_count = kept;
    bool ok = solve_picked(s, cam, &picked, strokes, start, p, rep, err);
    const sp_abstraction* ab = &sp_rig_handle_abstractions(s->rig)[s->abstraction];
    for (int i = 0; i < n; ++i)
        used[i] = ab->correspondence == SP_CORR_CLOSEST && why[i] == STROKE_KEPT;
    for (int i = 0; ok && i < rep->curve_count; ++i)
        if (rep->curves[i].stroke >= 0 && rep->curves[i].stroke < picked.stroke_count)
            used[rep->curves[i].stroke = orig[rep->curves[i].stroke]] = 1;
    free(some), free(orig);
    return ok;
}

// A solve of some of the strokes: which it kept (why: n), which took a
// curve (used: n), the pose (p: P) and its report.
typedef struct kept_fit {
    int *why, *used;
    double* p;
    sp_solve_report* rep;
} kept_fit;

// A fit without some strokes is taken when its mean error is at least 1%
// lower (not the same fit again, named as if it were better).
#define BETTER_FIT 0.99

// Solves the strokes that cand->why keeps into *cand, from `start` as the
// first solve was (`aliased`: the start and the result one buffer, as
// `pose` and `drawover` give them, which the solver's later attempts then
// start from: a drawing with a stroke left out is solved as that drawing
// would be; a second review found the same strokes at 21.8 px one way and
// 1.1 the other); taken into *best when it fits better.
static void solve_if_better(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                            bool aliased, const kept_fit* cand, kept_fit* best)
{
    sp_error err = {0};
    int n = sk->stroke_count, P = sp_rig_handle_param_count(s->rig);
    if (start && aliased) memcpy(cand->p, start, sizeof(double) * (size_t)P);
    if (!solve_kept(s, cam, sk, strokes, cand->why, start && aliased ? cand->p : start, cand->p, cand->rep, cand->used, &err) ||
        !(cand->rep->mean_error_px < BETTER_FIT * best->rep->mean_error_px))
        return;
    memcpy(best->p, cand->p, sizeof(double) * (size_t)P);
    *best->rep = *cand->rep;
    memcpy(best->why, cand->why, sizeof(int) * (size_t)n);
    memcpy(best->used, cand->used, sizeof(int) * (size_t)n);
}

// More kept strokes than curves: solved again with the strokes the fit
// left unused left out from the start, with the shortest strokes left out,
// and with one or two over, with each way of leaving them out (at most
// LEAVE_OUT_MAX solves); the best fit is kept.
// Why: the solver assigns strokes to curves against the start pose, where
// a raised arm lies on the rest spine, so a head drawn as a circle, a
// ground line or an arm in two pieces took the spine's or another arm's
// curve and the figure folded (an outside review: 8-30 px mean, where the
// same drawing without the extra stroke fitted at 0.9 px); stray lines
// settle unused, but only after they pulled the pose while the assignment
// was made; grass tufts drawn under the feet are the shortest strokes.
#define LEAVE_OUT_MAX 36
static void try_leaving_out(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                            bool aliased, bool every_way, const kept_fit* cand, kept_fit* best)
{
    const sp_abstraction* ab = &sp_rig_handle_abstractions(s->rig)[s->abstraction];
    int n = sk->stroke_count, kept = 0;
    for (int i = 0; i < n; ++i)
        kept += best->why[i] == STROKE_KEPT;
    int surplus = kept - ab->curve_count;
    if (ab->correspondence != SP_CORR_ORDERED || surplus < 1) return;
    int* was = malloc(sizeof(int) * (size_t)n); // why before any is left out
    double* len = malloc(sizeof(double) * (size_t)n);
    if (!was || !len) {
        free(was), free(len);
        return;
    }
    memcpy(was, best->why, sizeof(int) * (size_t)n);
    memcpy(cand->why, was, sizeof(int) * (size_t)n);
    int unused = 0;
    for (int i = 0; i < n; ++i)
        if (was[i] == STROKE_KEPT && !best->used[i]) cand->why[i] = STROKE_LEFT_OUT, ++unused;
    if (unused == surplus) solve_if_better(s, cam, sk, strokes, start, aliased, cand, best);
    // The `surplus` shortest strokes.
    for (int i = 0; i < n; ++i)
        len[i] = was[i] == STROKE_KEPT ? sp_curve_length(sk->strokes[i].points, sk->strokes[i].count, false) : INFINITY;
    memcpy(cand->why, was, sizeof(int) * (size_t)n);
    for (int k = 0; k < surplus; ++k) {
        int shortest = -1;
        for (int i = 0; i < n; ++i)
            if (cand->why[i] == STROKE_KEPT && (shortest < 0 || len[i] < len[shortest])) shortest = i;
        cand->why[shortest] = STROKE_LEFT_OUT;
    }
    solve_if_better(s, cam, sk, strokes, start, aliased, cand, best);
    // Every way, all compared, whatever the fit: two strays took an arm's
    // curve at 2.2 px, 0.5% of the drawing's size, under any threshold that
    // good fits pass (a second review).
    long ways = surplus == 1 ? kept : (long)kept * (kept - 1) / 2;
    for (int a = 0; every_way && surplus <= 2 && ways <= LEAVE_OUT_MAX && a < n; ++a)
        for (int b = surplus == 2 ? a + 1 : a; b < (surplus == 2 ? n : a + 1); ++b) {
            if (was[a] != STROKE_KEPT || was[b] != STROKE_KEPT) continue;
            memcpy(cand->why, was, sizeof(int) * (size_t)n);
            cand->why[a] = cand->why[b] = STROKE_LEFT_OUT;
            solve_if_better(s, cam, sk, strokes, start, aliased, cand, best);
        }
    free(was), free(len);
}

// The fit of sk's strokes as they are drawn, into *best (why, used, p,
// rep: sized for sk): the dots and retraces left out, then strokes left out
// when the rest fits better (start0: the caller's start copied, or NULL;
// every_way: try_leaving_out's search of every way too).
static bool fit_strokes(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                        const double* start0, bool every_way, kept_fit* best)
{
    const sp_abstraction* ab = &sp_rig_handle_abstractions(s->rig)[s->abstraction];
    int n = sk->stroke_count, P = sp_rig_handle_param_count(s->rig);
    int* why2 = malloc(sizeof(int) * (size_t)(2 * n + 1));
    double* alt = malloc(sizeof(double) * (size_t)(P + 1));
    sp_solve_report* rep2 = malloc(sizeof *rep2);
    if (!why2 || !alt || !rep2) {
        free(why2), free(alt), free(rep2);
        fprintf(stderr, "%s: %s: out of memory\n", s->cmd, strokes);
        return false;
    }
    sp_error err = {0};
    int kept = mark_dots(sk, best->why);
    memcpy(why2, best->why, sizeof(int) * (size_t)n);
    bool retraces = mark_retraces(sk, ab->curve_count, kept, why2) < kept;
    bool ok = solve_kept(s, cam, sk, strokes, best->why, start, best->p, best->rep, best->used, &err);
    kept_fit cand = {why2, why2 + n, alt, rep2};
    // Without the retraces, kept when that fits better: two legs drawn
    // together, or a line of action beside the spine, look like a retrace
    // too, and left out broke a figure that fitted (a second review).
    if (ok && retraces) solve_if_better(s, cam, sk, strokes, start0, start == best->p, &cand, best);
    if (ok) try_leaving_out(s, cam, sk, strokes, start0, start == best->p, every_way, &cand, best);
    free(why2), free(alt), free(rep2);
    return ok;
}

// The length of the strokes a fit leaves out or unused, dots and retraces
// aside (those are meant to be).
static double ink_left_out(const sp_sketch* sk, const int* why, const int* used)
{
    double ink = 0;
    for (int i = 0; i < sk->stroke_count; ++i)
        if (why[i] == STROKE_LEFT_OUT || (why[i] == STROKE_KEPT && !used[i]))
            ink += sp_curve_length(sk->strokes[i].points, sk->strokes[i].count, false);
    return ink;
}

// A fit of the drawing with lines drawn in pieces joined is taken when it
// leaves less ink out and fits no more than this much worse (its limbs are
// whole, so it has more to fit): the arm in two pieces fitted at 0.80 px
// with its forearm left out and the arm ending at the head, at 0.84 whole.
#define JOINED_WORSE 1.3
#define JOINED_WORSE_PX 0.3
// ... or, in a draw-over (its strokes redraw the curves drawn over, no
// strays), when it fits within this share of its size all the same: half a
// line left out fits at nearly nothing (an arm redrawn in two pieces kept
// half, 0.19 px, where whole it fits at 0.63; a third review). Not in a
// redraw: a ground line drawn on from a kicking foot was joined to the leg.
#define JOINED_GOOD 0.005

// The fit of the lines joined (lines, line_of, flip: sp_pieces_join) into
// *best's terms (sk's strokes): a stroke joined takes its line's why and
// used, a line traced over is its first stroke, and the report's curves
// name a line's first stroke; said in the note.
static void take_joined(const sp_sketch* sk, const sp_sketch* lines, const int* line_of, const bool* flip, const kept_fit* j,
                        int P, kept_fit* best)
{
    int n = sk->stroke_count, m = lines->stroke_count;
    int first[64 + 1];
    for (int k = 0; k < m; ++k)
        first[k] = -1;
    for (int i = 0; i < n; ++i)
        if (first[line_of[i]] < 0) first[line_of[i]] = i;
    for (int i = 0; i < n; ++i) {
        int w = j->why[line_of[i]];
        best->why[i] = w >= 0 ? first[w] : w;
        best->used[i] = j->used[line_of[i]];
    }
    *best->rep = *j->rep;
    for (int c = 0; c < best->rep->curve_count; ++c) {
        sp_curve_report* cr = &best->rep->curves[c];
        if (cr->stroke < 0 || cr->stroke >= m) continue;
        cr->stroke = first[cr->stroke];
        cr->reversed ^= flip[cr->stroke]; // the stroke named, not its line (a third review)
    }
    memcpy(best->p, j->p, sizeof(double) * (size_t)P);
    // The lines a curve took (one left out is named among the unused).
    char said[200] = "";
    size_t w = 0;
    int groups = 0, cut = 0;
    for (int k = 0; k < m; ++k) {
        int members = 0;
        for (int i = first[k]; i < n; ++i)
            members += line_of[i] == k;
        if (members < 2 || j->why[k] != STROKE_KEPT || !j->used[k]) continue;
        ++groups;
        if (cut || w + 4 * (size_t)members + 8 >= sizeof said) { // room for ", ..."
            ++cut;
            continue;
        }
        for (int i = first[k]; i < n; ++i)
            if (line_of[i] == k)
                w += (size_t)snprintf(said + w, sizeof said - w, "%s%d", i == first[k] ? (w ? ", " : "") : "+", i);
    }
    if (cut) snprintf(said + w, sizeof said - w, "%s...", w ? ", " : "");
    size_t at = strlen(best->rep->note);
    if (groups > 0)
        snprintf(best->rep->note + at, sizeof best->rep->note - at, "%sstrokes %s taken as one line%s (drawn in pieces)",
                 at ? "; " : "", said, groups > 1 ? " each" : "");
}

// The fit of `lines` (sk's strokes joined, line_of: sp_pieces_join) in the
// buffers given (why: 4 n ints, pj: P), with or without the search of every
// way to leave strokes out (every_way), taken into *best by JOINED_WORSE
// (after_joined: best is another joined fit, which only a better one beats).
static bool fit_joined(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const sp_sketch* lines,
                       const int* line_of, const bool* flip, const double* start0, bool aliased, bool after_joined,
                       bool every_way, int* why, double* pj, sp_solve_report* rj, kept_fit* best)
{
    int n = sk->stroke_count, m = lines->stroke_count, P = sp_rig_handle_param_count(s->rig);
    if (start0) memcpy(pj, start0, sizeof(double) * (size_t)P);
    kept_fit j = {why, why + m, pj, rj};
    if (!fit_strokes(s, cam, lines, strokes, start0 && aliased ? pj : start0, start0, every_way, &j)) return false;
    int *why_n = why + 2 * n, *used_n = why_n + n; // j's in sk's strokes, to count the ink left out
    for (int i = 0; i < n; ++i) // (a retrace is not ink left out: counted so, it kept an arm's pieces apart; a third review)
        why_n[i] = j.why[line_of[i]], used_n[i] = j.used[line_of[i]];
    double was = best->rep->mean_error_px, ink = ink_left_out(sk, why_n, used_n),
           ink_was = ink_left_out(sk, best->why, best->used);
    // After a fit of other joins was taken, only a better one (as solve_if_better).
    bool better = after_joined
                      ? ink <= ink_was && rj->mean_error_px < BETTER_FIT * was
                      : ink < ink_was && (rj->mean_error_px <= fmax(JOINED_WORSE * was, was + JOINED_WORSE_PX) ||
                                          (s->desc.ordered_by_ends && rj->mean_error_px <= JOINED_GOOD * rj->bbox_diagonal_px));
    if (!better) return false;
    take_joined(sk, lines, line_of, flip, &j, P, best);
    return true;
}

// More strokes than curves, some left out: lines drawn in pieces, end to
// end (stroke_pieces.h), joined and the drawing fitted again (fit_joined). Why: the solver gives a curve one stroke, so a limb
// drawn in two pieces kept one and fitted short, the other left out as a stray at a good-looking error (a foot at knee height,
// 0.96 px; a head folded into the chest, 0.58 px; an outside review), and a drawing of five lines in ten pieces fell apart (18
// px).
static void try_pieces_joined(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes,
                              const double* start0, bool aliased, kept_fit* best)
{
    const sp_abstraction* ab = &sp_rig_handle_abstractions(s->rig)[s->abstraction];
    int n = sk->stroke_count, P = sp_rig_handle_param_count(s->rig), kept = 0;
    if (ab->correspondence != SP_CORR_ORDERED || n > 64 || !(ink_left_out(sk, best->why, best->used) > 0)) return;
    bool keep[64];
    for (int i = 0; i < n; ++i)
        kept += keep[i] = best->why[i] != STROKE_DOT;
    int* why = malloc(sizeof(int) * (size_t)(4 * n + 1));
    double* pj = malloc(sizeof(double) * (size_t)(P + 1));
    sp_solve_report* rj = malloc(sizeof *rj);
    // The joins closest first, and again without the first or the second
    // candidate, the best fit kept (with one stroke over, the spine going
    // straight on into a leg took the only join, and the leg's own two
    // pieces were never tried; a second review).
    bool taken = false;
    for (int skip = -1; why && pj && rj && skip < 2; ++skip) {
        int next[64], line_of[64];
        bool flip[64];
        sp_sketch lines;
        if (sp_pieces_find(sk, keep, kept - ab->curve_count, skip, next, flip) == 0) break;
        if (!sp_pieces_join(sk, next, flip, &lines, line_of)) break;
        // The first with the search of every way to leave strokes out
        // (without it, a spine lifted at the chest and a leg in pieces kept
        // the foot at knee height; a third review), the others without (an
        // animation's keys in pieces took 2-2.6 s).
        taken |= fit_joined(s, cam, sk, strokes, &lines, line_of, flip, start0, aliased, taken, skip < 0, why, pj, rj, best);
        sp_sketch_free(&lines);
    }
    free(why), free(pj), free(rj);
}

bool sp_solve_cmd_solve(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                        double* p, sp_solve_report* rep, cJSON** report)
{
    *report = NULL;
    const sp_abstraction* ab = &sp_rig_handle_abstractions(s->rig)[s->abstraction];
    int n = sk->stroke_count, P = sp_rig_handle_param_count(s->rig);
    int* why = malloc(sizeof(int) * (size_t)(2 * n + 1));
    double* start0 = malloc(sizeof(double) * (size_t)(P + 1)); // p may be start
    if (!why || !start0) {
        free(why), free(start0);
        fprintf(stderr, "%s: %s: out of memory\n", s->cmd, strokes);
        return false;
    }
    if (start) memcpy(start0, start, sizeof(double) * (size_t)P);
    kept_fit best = {why, why + n, p, rep};
    bool ok = fit_strokes(s, cam, sk, strokes, start, start ? start0 : NULL, true, &best);
    if (ok) try_pieces_joined(s, cam, sk, strokes, start ? start0 : NULL, start == p, &best);
    if (ok) {
        note_unused_strokes(rep, why, best.used, n);
        note_loose_curve(rep, ab);
        note_placement_bound(rep, sp_rig_handle_params(s->rig), P, p);
        note_unmatched_curves(rep, ab);
        size_t len = strlen(rep->note);
        if (len + 1 >= sizeof rep->note) memcpy(rep->note + sizeof rep->note - 4, "...", 4); // a note cut says so
        *report = sp_report_json(rep, ab, sp_rig_handle_params(s->rig), P, p);
    }
    free(why), free(start0);
    return ok;
}

// The solve of the strokes kept.
static bool solve_picked(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                         double* p, sp_solve_report* rep, sp_error* err)
{
    if (!s->solver || cam->width != s->cam.width || cam->height != s->cam.height) {
        sp_solver_destroy(s->solver);
        s->cam = *cam;
        if (sp_rig_handle_solver(s->rig, s->abstraction, &s->cam, &s->desc, &s->solver, err) != SP_OK) {
            fprintf(stderr, "%s: %s\n", s->cmd, err->text);
            return false;
        }
    }
    if (sp_solver_solve(s->solver, sk, start, p, rep, err) != SP_OK) {
        fprintf(stderr, "%s: %s: %s\n", s->cmd, strokes, err->text);
        return false;
    }
    return true;
}

// --out and --render of the rig at p, to the names staged for them.
static sp_result write_posed(const sp_solve_cmd* s, const double* p, const sp_solve_outputs* o, const char* out,
                             const char* render, sp_error* err)
{
    sp_rig_posed v;
    sp_result r = sp_rig_handle_posed(s->rig, s->abstraction, p, &s->cam, &v, err);
    if (r == SP_OK && out) r = sp_rig_posed_save(&v, out, err);
    if (r == SP_OK && render) {
        sp_snapshot_desc d = {.character = v.character,
                              .params = v.params,
                              .camera = &s->cam,
                              .abstraction = v.abstraction,
                              .strokes = o->strokes,
                              .ghost = o->ghost};
        // The picture is the strokes' canvas, which can be too large for GL: say which output failed.
        sp_error e = {0};
        if ((r = sp_snapshot_png(&d, render, &e)) != SP_OK && err) {
            if (strstr(e.text, render))
                *err = e;
            else
                sp_fail(err, r, "%s: %s", render, e.text);
        }
    }
    sp_rig_posed_free(&v);
    return r;
}

bool sp_solve_cmd_write(const sp_solve_cmd* s, const cJSON* report, const double* p, const sp_solve_outputs* o)
{
    sp_error err = {0};
    sp_outputs staged = {0};
    const char *rep = NULL, *out = NULL, *render = NULL;
    sp_result r = sp_outputs_stage(&staged, o->report, &rep, &err);
    if (r == SP_OK) r = sp_outputs_stage(&staged, o->out, &out, &err);
    if (r == SP_OK) r = sp_outputs_stage(&staged, o->render, &render, &err);
    if (r == SP_OK && rep) r = sp_json_write_file(rep, report, &err);
    if (r == SP_OK && (out || render)) r = write_posed(s, p, o, out, render, &err);
    if (r == SP_OK) r = sp_outputs_commit(&staged, &err);
    if (r != SP_OK) {
        sp_outputs_undo(&staged, &err);
        fprintf(stderr, "%s: %s\n", s->cmd, err.text);
        return false;
    }
    if (!sp_cli_stdout_taken((const char* const[]){o->report, o->out, o->render}, 3)) sp_json_print(report);
    if (o->note && o->note[0]) fprintf(stderr, "%s: %s\n", s->cmd, o->note);
    if (o->out) sp_rig_handle_warn_textures(s->cmd, s->rig, o->out);
    return true;
}

double sp_solve_cmd_lambda(double typed)
{
    return isnan(typed) ? 0 : typed > 0 ? typed : -1;
}

void sp_solve_cmd_end(sp_solve_cmd* s)
{
    sp_solver_destroy(s->solver);
    s->solver = NULL;
}
