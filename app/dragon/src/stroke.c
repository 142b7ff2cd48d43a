// stroke.c: the stroke path: a stroke is cleaned, classified, decided on
// (accepted or refused), fitted by every part of the classifier's best
// guesses (the category whose score over its fit's error is best is kept)
// and becomes a part; Redraw, refit, undo and clear.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"
#include "sp/clock.h"
#include "sp/curve.h"
#include "sp/synth.h"

// A stroke that goes over itself for at least this share of its length,
// within this share of its box's diagonal, is taken as drawn once: a child
// goes round a body twice, or back along a head's line, and no drawing the
// classifier knows does (an outside review: such strokes were refused with
// the right part first at 0.97-1.00).
#define RETRACE_SHARE 0.25
#define RETRACE_TOL 0.025
// ... and at least this share of the canvas's diagonal: a finger goes back
// along a small part's line a few pixels off (2 mm on 1280 x 800 at 96
// dpi; legs 4 px off were refused: a second review).
#define RETRACE_MIN_CANVAS 0.005

void sp_dragon_set_stroke_area(sp_dragon* d, double x0, double y0, double x1, double y1)
{
    bool ok = isfinite(x0) && isfinite(y0) && isfinite(x1) && isfinite(y1) && x1 > x0 && y1 > y0;
    d->area[0] = ok ? x0 : 0, d->area[1] = ok ? y0 : 0, d->area[2] = ok ? x1 : 0, d->area[3] = ok ? y1 : 0;
}

// Cleans a stroke: clamps onto the stroke area, drops repeated points, cuts
// off a stretch drawn over the stroke again, resamples very long strokes.
// *out malloc'd. Returns the point count (0 on no memory).
static int clean_stroke(const sp_dragon* d, const sp_vec2* xy, int n, sp_vec2** out)
{
    double W = d->desc.canvas_w, H = d->desc.canvas_h;
    bool area = d->area[2] > d->area[0];
    double x0 = area ? d->area[0] : 0, y0 = area ? d->area[1] : 0, x1 = area ? d->area[2] : W, y1 = area ? d->area[3] : H;
    sp_vec2* tmp = malloc(sizeof(sp_vec2) * (size_t)(n > 0 ? n : 1));
    if (!tmp) return 0;
    sp_vec2 lo = {INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY};
    for (int i = 0; i < n; ++i) {
        tmp[i] = (sp_vec2){fmin(fmax(xy[i].x, x0), x1), fmin(fmax(xy[i].y, y0), y1)};
        lo.x = fmin(lo.x, tmp[i].x), lo.y = fmin(lo.y, tmp[i].y), hi.x = fmax(hi.x, tmp[i].x), hi.y = fmax(hi.y, tmp[i].y);
    }
    int m = sp_curve_clean(tmp, n, 0.0, tmp);
    if (m >= 4)
        m = sp_curve_retrace_start(tmp, m, fmax(RETRACE_MIN_CANVAS * hypot(W, H), RETRACE_TOL * sp_v2_len(sp_v2_sub(hi, lo))),
                                   RETRACE_SHARE);
    if (m > SP_DRAGON_MAX_STROKE_POINTS) {
        sp_vec2* r = malloc(sizeof(sp_vec2) * SP_DRAGON_MAX_STROKE_POINTS);
        if (!r || sp_curve_resample(tmp, m, false, SP_DRAGON_MAX_STROKE_POINTS, r) != SP_OK) {
            free(r);
            free(tmp);
            return 0;
        }
        free(tmp);
        tmp = r;
        m = SP_DRAGON_MAX_STROKE_POINTS;
    }
    *out = tmp;
    return m;
}

static sp_result new_part(sp_dragon* d, tpl* t, const double* p, const sp_solve_report* rep, const sp_camera* view, bool mirrored,
                          const sp_vec2* xy, int n, float confidence, part** out, sp_error* err)
{
    const sp_rig* rig = &t->ch.rig;
    part* q = calloc(1, sizeof *q);
    if (!q) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    size_t P = (size_t)rig->param_count + 1;
    q->p_fit = malloc(sizeof(double) * P);
    q->p_t = malloc(sizeof(double) * P);
    q->xyz = malloc(sizeof(double) * 3 * ((size_t)rig->vertex_count + 1));
    q->outline = malloc(sizeof(double) * 3 * ((size_t)rig->abstractions[t->abstraction].point_count + 1));
    q->stroke = malloc(sizeof(sp_vec2) * (size_t)(n > 0 ? n : 1));
    sp_rig_eval_create(rig, &q->ev, NULL);
    if (!q->p_fit || !q->p_t || !q->xyz || !q->outline || !q->stroke || !q->ev) {
        q->t = NULL;
        dragon_part_free(q);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    memcpy(q->p_fit, p, sizeof(double) * (size_t)rig->param_count);
    memcpy(q->stroke, xy, sizeof(sp_vec2) * (size_t)n);
    q->stroke_n = n;
    q->stroke_box[0] = q->stroke_box[2] = xy[0].x, q->stroke_box[1] = q->stroke_box[3] = xy[0].y;
    for (int i = 1; i < n; ++i) {
        q->stroke_box[0] = fmin(q->stroke_box[0], xy[i].x), q->stroke_box[1] = fmin(q->stroke_box[1], xy[i].y);
        q->stroke_box[2] = fmax(q->stroke_box[2], xy[i].x), q->stroke_box[3] = fmax(q->stroke_box[3], xy[i].y);
    }
    q->t = t;
    ++t->refs;
    sp_dragon_part* pub = &q->pub;
    pub->id = d->next_id++;
    dragon_copy_name(pub->name, sizeof pub->name, t->name);
    dragon_copy_name(pub->category, sizeof pub->category, t->category);
    pub->confidence = confidence;
    pub->character = &t->ch;
    pub->abstraction = t->abstraction;
    pub->params = q->p_fit;
    pub->report = *rep;
    pub->view = *view;
    pub->mirrored = mirrored;
    pub->placement = dragon_placement_of(d, t, view);
    pub->is_torso = t->is_torso;
    pub->attached_to = -1;
    pub->carrier_joint = -1;
    pub->anchor = (sp_vec2){NAN, NAN};
    pub->stroke_points = n;
    pub->stroke_xy = q->stroke;
    *out = q;
    return SP_OK;
}

// One fitted candidate: a part of the category in one facing.
typedef struct fit_choice {
    tpl* t;
    bool mirrored;
    double score; // mean error over the stroke's diagonal (of the better facing when kept by place: fit_variants)
    double* p;    // malloc'd, rig.param_count
    sp_solve_report rep;
    sp_camera view; // the view it was fitted in (turned when mirrored)
} fit_choice;

// Whether a fit can become a part: every number finite (a solver that
// produced NaN from a broken rig must not put it on the canvas).
static bool fit_is_finite(const sp_dragon* d, const tpl* t, const double* p, const sp_solve_report* rep, const sp_camera* view)
{
    for (int k = 0; k < t->ch.rig.param_count; ++k)
        if (!isfinite(p[k])) return false;
    sp_mat4 m = dragon_placement_of(d, t, view);
    for (int k = 0; k < 16; ++k)
        if (!isfinite(m.m[k])) return false;
    return isfinite(rep->mean_error_px) && isfinite(rep->max_error_px);
}

// Fits the stroke (its box [lo, hi]) with template t in one facing: the
// mirrored facing fits the stroke mirrored left-right about its box's centre.
static bool fit_one(sp_dragon* d, tpl* t, const sp_sketch* sk, sp_vec2 lo, sp_vec2 hi, bool mirrored, fit_choice* out,
                    int* not_finite)
{
    const sp_rig* rig = &t->ch.rig;
    int n = sk->strokes[0].count;
    double u = 0.5 * (lo.x + hi.x);
    sp_vec2* flipped = mirrored ? malloc(sizeof(sp_vec2) * (size_t)n) : NULL;
    double* p = malloc(sizeof(double) * ((size_t)rig->param_count + 1));
    if (!p || (mirrored && !flipped)) {
        free(p), free(flipped);
        return false;
    }
    sp_sketch msk = *sk;
    sp_stroke ms = {.count = n, .points = flipped};
    if (mirrored) {
        for (int i = 0; i < n; ++i)
            flipped[i] = (sp_vec2){2 * u - sk->strokes[0].points[i].x, sk->strokes[0].points[i].y};
        msk.strokes = &ms;
    }
    memcpy(p, t->ch.pose, sizeof(double) * (size_t)rig->param_count);
    t->solver_cam = dragon_zoomed_view(t, lo, hi);
    sp_solve_report rep;
    sp_error serr = {0};
    bool ok = sp_solver_solve(t->solver, &msk, p, p, &rep, &serr) == SP_OK;
    free(flipped);
    // Legs fitted by one leg's line: the other leg stands beside it, on
    // every fit (a part turned or re-fitted later, too: an outside review).
    if (ok && t->twins) dragon_limb_follow(t, p);
    if (ok && d->fit_hook) d->fit_hook(p, rig->param_count);
    sp_camera view = mirrored ? dragon_mirrored_view(&t->solver_cam, u) : t->solver_cam;
    if (ok && !fit_is_finite(d, t, p, &rep, &view)) ok = false, ++*not_finite;
    if (!ok) {
        free(p);
        return false;
    }
    double score = rep.mean_error_px / fmax(rep.bbox_diagonal_px, 1.0);
    *out = (fit_choice){t, mirrored, score, p, rep, view};
    return true;
}

// A fit in the hinted facing worse than this (mean error over the stroke's
// diagonal; good fits of hand-drawn parts are 0.1-0.3%) also tries the other.
#define OTHER_FACING_SCORE 0.004

// Wings (a part that neither reaches sideways, nor is a body, nor has kin
// told apart by place) face the way their dragon does unless the other
// facing fits clearly better: a child's wing leaning forward, drawn at the
// shoulders, fitted leaning back shrank across the neck and was kept as ink
// on the head (an outside review). Legs keep their dragon's facing (toes).
static bool faces_freely(const tpl* t)
{
    return !t->lengthwise && !t->is_torso && !t->family[0];
}

// How much better the other facing must fit: a head's or a tail's (no
// facing told, or a poor fit in the told one), and a wing's against its
// dragon's facing (the review's wing: 0.49; the visitors' tune half's wings
// at a dragon, 0.59 and more, keep their dragon's facing).
#define OTHER_FACING_GAIN 0.8
#define WING_FACING_GAIN 0.55

// Fits every candidate part. A part that reaches sideways (a head, a tail)
// is fitted in the facing the bodies' sockets hint at and, when there is no
// hint or that fit is poor, in the other too: the hinted one is kept unless
// the other fits clearly better, and always when the stroke comes out of
// the end of the body that hints. The best candidate goes to *best.
static bool fit_variants(sp_dragon* d, tpl** cands, int nc, const sp_sketch* sk, sp_vec2 lo, sp_vec2 hi, fit_choice* best,
                         int* not_finite)
{
    bool any = false;
    for (int c = 0; c < nc; ++c) {
        tpl* t = cands[c];
        bool out_of_end = false;
        // A part that reaches sideways faces away from the body it comes
        // out of; legs and wings face the way their dragon does.
        int hint = t->lengthwise ? dragon_facing_hint(d, t, lo, hi, &out_of_end) : t->is_torso ? 1 : dragon_facing_at(d, lo, hi);
        fit_choice a, b;
        bool got = fit_one(d, t, sk, lo, hi, hint < 0, &a, not_finite);
        bool other = (t->lengthwise || (faces_freely(t) && hint != 0)) && (hint == 0 || !got || a.score > OTHER_FACING_SCORE);
        if (other && fit_one(d, t, sk, lo, hi, !(hint < 0), &b, not_finite)) {
            if (got && out_of_end) {
                // Drawn out of a body's end, the part's root is at the body
                // whichever facing fits better (a visitor's tail ending in a
                // spade or a flame fits reversed): the hinted facing is the
                // part, and the better facing's error is the category's
                // evidence for the ranking and the refusal.
                a.score = fmin(a.score, b.score);
                free(b.p);
            } else if (!got || b.score < (t->lengthwise ? OTHER_FACING_GAIN : WING_FACING_GAIN) * a.score) {
                if (got) free(a.p);
                a = b, got = true;
            } else {
                free(b.p);
            }
        }
        if (!got) continue;
        if (!any || a.score < best->score) {
            if (any) free(best->p);
            *best = a, any = true;
        } else {
            free(a.p);
        }
    }
    return any;
}

// How far apart fit f's curves and the stroke are, both ways: the mean of
// the stroke's points' mean distance to the curves and the curves' points'
// mean distance to the stroke, over `diag` (the stroke's box diagonal). The
// solver's error goes one way only, so an outline along one side of a line
// drawing scores as well as a line on it. INFINITY when it cannot be measured.
static double two_way_gap(const fit_choice* f, const sp_stroke* st, double diag)
{
    const sp_rig* rig = &f->t->ch.rig;
    const sp_abstraction* ab = &rig->abstractions[f->t->abstraction];
    int m = ab->point_count, n = st->count;
    double* xy = malloc(sizeof(double) * 2 * (size_t)m);
    sp_vec2* c = malloc(sizeof(sp_vec2) * (size_t)m);
    int* next = malloc(sizeof(int) * (size_t)(m > n ? m : n));
    double* dist = malloc(sizeof(double) * (size_t)(m > n ? m : n));
    double gap = INFINITY;
    if (!xy || !c || !next || !dist || sp_abstraction_project(rig, f->t->abstraction, &f->view, f->p, xy) != SP_OK) goto done;
    for (int i = 0; i < m; ++i)
        c[i] = (sp_vec2){xy[2 * i], xy[2 * i + 1]}, next[i] = i + 1;
    for (int k = 0; k < ab->curve_count; ++k) {
        const sp_curve* cv = &ab->curves[k];
        next[cv->first_point + cv->point_count - 1] = cv->closed ? cv->first_point : -1;
    }
    double to_curve = 0, to_stroke = 0;
    if (sp_polyline_distances(c, next, m, st->points, n, dist) != SP_OK) goto done;
    for (int i = 0; i < n; ++i)
        to_curve += dist[i];
    for (int i = 0; i < n; ++i)
        next[i] = i + 1 < n ? i + 1 : -1;
    if (sp_polyline_distances(st->points, next, n, c, m, dist) != SP_OK) goto done;
    for (int i = 0; i < m; ++i)
        to_stroke += dist[i];
    gap = 0.5 * (to_curve / n + to_stroke / m) / fmax(diag, 1.0);
done:
    free(xy), free(c), free(next), free(dist);
    return gap;
}

// A stroke drawn as one open line (not a loop: sp_stroke_is_loop) may be a
// tail or a pair of legs drawn as a line, which the part's outline can only
// take folded or shrunk: the kept fit f is fitted again with the part's
// lines (tpl.line, tpl.limb) in the same facing, and the line fit lying
// nearest the stroke both ways (two_way_gap) replaces it when nearer than
// f. The outline's score stays f's evidence (the ranking and the refusal
// are measured on outlines).
static void prefer_line(sp_dragon* d, const sp_sketch* sk, sp_vec2 lo, sp_vec2 hi, fit_choice* f)
{
    if (sp_stroke_is_loop(&sk->strokes[0])) return;
    double diag = sp_v2_len(sp_v2_sub(hi, lo)), best = INFINITY;
    tpl* lines[2] = {f->t->line, f->t->limb};
    for (int k = 0; k < 2; ++k) {
        fit_choice l;
        int not_finite = 0;
        if (!lines[k] || !fit_one(d, lines[k], sk, lo, hi, f->mirrored, &l, &not_finite)) continue;
        if (best == INFINITY) best = two_way_gap(f, &sk->strokes[0], diag);
        double gl = two_way_gap(&l, &sk->strokes[0], diag);
        if (gl < best) {
            best = gl;
            l.score = f->score;
            free(f->p);
            *f = l;
        } else {
            free(l.p);
        }
    }
}

// Fits every part of `category` (each variant and facing) to the stroke: the
// best fit goes to *best. *any_part: the category has a part to fit.
static bool fit_category(sp_dragon* d, const char* category, const sp_sketch* sk, sp_vec2 lo, sp_vec2 hi, fit_choice* best,
                         int* not_finite, bool* any_part)
{
    tpl* cands[16];
    int cap = d->desc.max_variants < 16 ? d->desc.max_variants : 16;
    sp_error lerr = {0};
    int nc = dragon_category_templates(d, category, cands, cap, &lerr);
    *any_part = *any_part || nc > 0;
    return nc > 0 && fit_variants(d, cands, nc, sk, lo, hi, best, not_finite);
}

// A fit error (mean error over the stroke's diagonal) below this counts as
// this: an exact fit must not outweigh every vote.
#define RERANK_FIT_FLOOR 1e-4
// Guesses scoring under this share of the first's are not fitted: such a
// guess would need a fit five times better to win, which none of the
// visitors' tune half came near (the lowest winner scored 0.29 of the
// first), and skipping them saves two of three extra fits.
#define RERANK_MIN_SHARE 0.2

// Puts `chosen` first in out->guesses, guesses 0..g-1 moving up one (over
// slot g: chosen's own place, or the last slot for a guess not among them).
static void guess_to_front(sp_dragon_result* out, int g, sp_dragon_guess chosen)
{
    memmove(&out->guesses[1], &out->guesses[0], sizeof chosen * (size_t)g);
    out->guesses[0] = chosen;
}

// Whether the category's parts are bodies (its first part is).
static bool category_is_body(sp_dragon* d, const char* category)
{
    const tpl* t = dragon_category_first(d, category);
    return t && t->is_torso;
}

// How well a part can take the drawn shape is evidence the classifier lacks:
// fits the stroke with each of the classifier's best guesses (out->guesses,
// at most SP_DRAGON_GUESSES, those scoring at least RERANK_MIN_SHARE of the
// first) and keeps the category whose score over its fit's error is highest
// (BENCHMARKS.md, "Visitors' drawings", sixth pass). no_body: the stroke is
// drawn on a body (dragon_drawn_on_body), so the guesses that are bodies are
// passed over (and the shares count from the first other guess) unless no
// other guess has a part that fits. The kept
// category moves to the front of out->guesses; category and *confidence
// become its name and score.
static bool rerank_by_fit(sp_dragon* d, const sp_sketch* sk, sp_vec2 lo, sp_vec2 hi, bool no_body, sp_dragon_result* out,
                          char category[SP_NAME_MAX], float* confidence, fit_choice* best, int* not_finite, bool* any_part)
{
    int kept = -1;
    double kept_rank = 0.0;
    // Pass 1, only when drawn on a body and no other guess fitted: the body
    // guesses, their shares counted from the first guess as without the rule.
    for (int pass = 0; pass < (no_body ? 2 : 1) && kept < 0; ++pass) {
        int first = -1; // pass 1: the first guess with a part, body or not
        for (int g = 0; pass == 1 && first < 0 && g < out->guess_count; ++g)
            if (dragon_category_first(d, out->guesses[g].category)) first = g;
        for (int g = 0; g < out->guess_count; ++g) {
            fit_choice f;
            if (no_body && category_is_body(d, out->guesses[g].category) != (pass == 1)) continue;
            // A guess with no part (one removed until the next db train) is
            // not the first the others' shares count from: it left the stroke
            // with no part at all, the kiosk saying it was not ready.
            if (!dragon_category_first(d, out->guesses[g].category)) continue;
            if (first < 0) first = g;
            if (g > first && out->guesses[g].confidence < RERANK_MIN_SHARE * out->guesses[first].confidence) continue;
            if (!fit_category(d, out->guesses[g].category, sk, lo, hi, &f, not_finite, any_part)) continue;
            double rank = out->guesses[g].confidence / fmax(f.score, RERANK_FIT_FLOOR);
            if (kept >= 0 && rank <= kept_rank) {
                free(f.p);
                continue;
            }
            if (kept >= 0) free(best->p);
            *best = f, kept = g, kept_rank = rank;
        }
    }
    if (kept < 0) return false;
    sp_dragon_guess chosen = out->guesses[kept];
    guess_to_front(out, kept, chosen);
    dragon_copy_name(category, SP_NAME_MAX, chosen.category);
    *confidence = chosen.confidence;
    return true;
}

// The family of a category's parts ("" for none or no part).
static const char* category_family(sp_dragon* d, const char* category)
{
    const tpl* t = dragon_category_first(d, category);
    return t ? t->family : "";
}

static bool among_guesses(const sp_dragon_result* out, const char* category)
{
    for (int g = 0; g < out->guess_count; ++g)
        if (!strcmp(out->guesses[g].category, category)) return true;
    return false;
}

static void fill_guesses(const sp_clf* clf, const sp_clf_answer* a, sp_dragon_result* out)
{
    out->guess_count = 0;
    for (int i = 0; i < a->count && out->guess_count < SP_DRAGON_GUESSES; ++i) {
        sp_dragon_guess* g = &out->guesses[out->guess_count++];
        dragon_copy_name(g->category, sizeof g->category, sp_clf_category(clf, a->ranked[i].category));
        g->confidence = a->ranked[i].score;
    }
}

// Front and hind legs are one family, told apart by where they are drawn
// (layout.c), and each other's commonest confusion: when the first of the
// final guesses (the part, or a refused stroke's best guess) has kin the
// guesses lack, the best-ranked of them in the classifier's answer `a`
// takes the last slot, so a stroke taken for legs offers both kinds.
static void offer_kin(sp_dragon* d, const sp_clf_answer* a, sp_dragon_result* out)
{
    if (!d->clf || out->guess_count < 2) return;
    char family[SP_NAME_MAX];
    dragon_copy_name(family, sizeof family, category_family(d, out->guesses[0].category));
    if (!family[0]) return;
    for (int i = 0; i < a->count; ++i) {
        const char* kin = sp_clf_category(d->clf, a->ranked[i].category);
        if (among_guesses(out, kin) || strcmp(category_family(d, kin), family) != 0) continue;
        sp_dragon_guess* last = &out->guesses[out->guess_count - 1];
        dragon_copy_name(last->category, sizeof last->category, kin);
        last->confidence = a->ranked[i].score;
        return;
    }
}

static sp_result reject(sp_dragon_result* out, sp_dragon_reject why, double t0)
{
    out->rejected = true;
    out->reason = why;
    out->part = -1;
    out->ms_total = sp_now_ms() - t0;
    return SP_OK;
}

// A stroke nearer than this to its mirror image (mirror_gap) counts as
// symmetric, and each unit nearer adds MIRROR_WEIGHT to its distance from
// every part. On the tune half of tests/data/visitors no part taken for a
// head, tail or wing came under 0.08, and every weight from 4 to 50 gave
// the same answers (BENCHMARKS.md, "Visitors' drawings", eleventh pass).
#define MIRROR_GAP_SYMMETRIC 0.08
#define MIRROR_WEIGHT 7.0

// A stroke turned by a k-th of a turn (k = 3..8) that lands within this of
// itself, nearer than TURN_GAP_RATIO times where an arbitrary turn lands it,
// has the symmetry of a regular polygon or a star (dragon_turns_onto_itself).
// TURN_GAP_ROUND keeps circles out: an arbitrary turn lands a round stroke
// on itself too, and a round body is a part. No training drawing of a part
// (714 single strokes) and no tune drawing of a part meets all three; every
// value within +-0.01 of the gap and from 0.75 to 0.9 of the ratio refuses
// the same tune drawings (BENCHMARKS.md, "Visitors' drawings", twelfth pass).
#define TURN_GAP_SYMMETRIC 0.10
#define TURN_GAP_RATIO 0.85
#define TURN_GAP_ROUND 0.09

enum { SHAPE_POINTS = 96 };

// The stroke resampled to SHAPE_POINTS points about their centroid, over
// their RMS radius, so that gaps between it and its images are in units of
// its size. False when that cannot be measured (a stroke of one point).
static bool shape_points(const sp_vec2* pts, int n, sp_vec2 r[SHAPE_POINTS])
{
    if (sp_curve_resample(pts, n, false, SHAPE_POINTS, r) != SP_OK) return false;
    sp_vec2 c = {0, 0};
    for (int i = 0; i < SHAPE_POINTS; ++i)
        c = sp_v2_add(c, r[i]);
    c = sp_v2_scale(c, 1.0 / SHAPE_POINTS);
    double rms = 0;
    for (int i = 0; i < SHAPE_POINTS; ++i) {
        r[i] = sp_v2_sub(r[i], c);
        rms += sp_v2_dot(r[i], r[i]);
    }
    rms = sqrt(rms / SHAPE_POINTS);
    if (!(rms > 0)) return false;
    for (int i = 0; i < SHAPE_POINTS; ++i)
        r[i] = sp_v2_scale(r[i], 1.0 / rms);
    return true;
}

// The mean distance from the points r, each mapped by the 2x2 matrix m (row
// major), to the nearest of the unmapped points.
static double mapped_gap(const sp_vec2 r[SHAPE_POINTS], const double m[4])
{
    double sum = 0;
    for (int i = 0; i < SHAPE_POINTS; ++i) {
        sp_vec2 t = {m[0] * r[i].x + m[1] * r[i].y, m[2] * r[i].x + m[3] * r[i].y};
        double best = INFINITY;
        for (int j = 0; j < SHAPE_POINTS; ++j)
            best = fmin(best, sp_v2_dot(sp_v2_sub(t, r[j]), sp_v2_sub(t, r[j])));
        sum += sqrt(best);
    }
    return sum / SHAPE_POINTS;
}

// How far a stroke is from being its own mirror image about the upright line
// through its centroid: the mean distance from each of its points to the
// mirrored stroke and back, over its RMS radius (0: symmetric). 1 (far from
// symmetric) when it cannot be measured.
double dragon_mirror_gap(const sp_vec2* pts, int n)
{
    sp_vec2 r[SHAPE_POINTS];
    if (!shape_points(pts, n, r)) return 1.0;
    // A mirror is its own inverse, so the distance from the stroke to its
    // image and from the image to the stroke are the same sum.
    return mapped_gap(r, (const double[4]){-1, 0, 0, 1});
}

// The same gap for the stroke turned by `angle`: the mean of the way there
// (turned by angle) and back (turned by -angle).
static double turn_gap(const sp_vec2 r[SHAPE_POINTS], double angle)
{
    double c = cos(angle), s = sin(angle);
    return 0.5 * (mapped_gap(r, (const double[4]){c, -s, s, c}) + mapped_gap(r, (const double[4]){c, s, -s, c}));
}

// Whether the stroke has the symmetry of a regular polygon or a star (a
// triangle, a square, a house, a sun): no dragon part a visitor draws does.
bool dragon_turns_onto_itself(const sp_vec2* pts, int n)
{
    sp_vec2 r[SHAPE_POINTS];
    if (!shape_points(pts, n, r)) return false;
    double symmetric = INFINITY;
    for (int k = 3; k <= 8; ++k)
        symmetric = fmin(symmetric, turn_gap(r, 2 * M_PI / k));
    if (symmetric >= TURN_GAP_SYMMETRIC) return false;
    // An arbitrary turn: the median over turns of 5, 15, ... 175 degrees
    // (a turn by -a lands as far as one by a).
    enum { TURNS = 18 };
    double arbitrary[TURNS];
    for (int i = 0; i < TURNS; ++i)
        arbitrary[i] = turn_gap(r, (5.0 + 10.0 * i) * M_PI / 180.0);
    qsort(arbitrary, TURNS, sizeof arbitrary[0], sp_cmp_double);
    double typical = 0.5 * (arbitrary[TURNS / 2 - 1] + arbitrary[TURNS / 2]);
    return typical >= TURN_GAP_ROUND && symmetric < TURN_GAP_RATIO * typical;
}

// The kiosk's refusal policy (docs/DESIGN.md, "Refusal policy"): a stroke
// that looks anything like a part becomes the best guess; refused are only
// what is clearly not a part, in two halves. Before the fit
// (refused_before_fit): scribbles, and regular polygons or stars. After it
// (far_score above SP_DRAGON_FAR_LIMIT): strokes far from every part. Taps
// and tiny strokes never get here. Constants tuned on the tune half and the
// fresh set of tests/data/visitors (BENCHMARKS.md, "Visitors' drawings").

// The scribble test's ink is measured over points at least this fraction
// of the canvas diagonal apart (3.8 px at 1280 x 800): a slow, shaky hand
// (a point every pixel, 1 px of touch noise) doubled its stroke's length
// and was refused, its first guess right (BENCHMARKS.md, "Thirty-sixth pass").
#define INK_STEP 0.0025

// Length of the stroke over points at least `step` apart (sp_curve_clean).
static double ink_length(const sp_vec2* pts, int n, double step)
{
    sp_vec2* k = malloc(sizeof(sp_vec2) * (size_t)n);
    if (!k) return sp_curve_length(pts, n, false);
    double len = sp_curve_length(k, sp_curve_clean(pts, n, step, k), false);
    free(k);
    return len;
}

// A scribble (far more ink than its size, or crossing itself over and over)
// or a shape with a polygon's or a star's symmetry, unless the best guess's
// part has it too (`polygonal`: a curator's star). `diag`: the canvas's diagonal.
static bool refused_before_fit(const sp_vec2* pts, int n, double diag, bool polygonal)
{
    enum { M = 64 };
    sp_vec2 r[M], lo = pts[0], hi = pts[0];
    for (int i = 1; i < n; ++i)
        lo.x = fmin(lo.x, pts[i].x), lo.y = fmin(lo.y, pts[i].y), hi.x = fmax(hi.x, pts[i].x), hi.y = fmax(hi.y, pts[i].y);
    if (ink_length(pts, n, INK_STEP * diag) > 6.0 * sp_v2_len(sp_v2_sub(hi, lo))) return true;
    if (sp_curve_resample(pts, n, false, M, r) != SP_OK) return false;
#define CROSS(a, b) ((a).x * (b).y - (a).y * (b).x)
    int crossings = 0;
    for (int i = 0; i + 1 < M; ++i)
        for (int j = i + 2; j + 1 < M; ++j) {
            sp_vec2 p = r[i], q = r[i + 1], u = r[j], v = r[j + 1];
            double d1 = CROSS(sp_v2_sub(q, p), sp_v2_sub(u, p)), d2 = CROSS(sp_v2_sub(q, p), sp_v2_sub(v, p));
            double d3 = CROSS(sp_v2_sub(v, u), sp_v2_sub(p, u)), d4 = CROSS(sp_v2_sub(v, u), sp_v2_sub(q, u));
            crossings += d1 * d2 < 0 && d3 * d4 < 0;
        }
#undef CROSS
    return crossings > 12 || (!polygonal && dragon_turns_onto_itself(pts, n));
}

// Whether part t is drawn in profile, where a symmetric drawing is
// suspect: not a body, not legs, and not its own mirror image (a curator's
// part seen from the front: a person's outline is symmetric).
static bool in_profile(const tpl* t)
{
    return !t->is_torso && !t->family[0] && t->own_mirror_gap >= MIRROR_GAP_SYMMETRIC;
}

// How far from every part (refused above SP_DRAGON_FAR_LIMIT): `near`, the
// classifier's nearest-drawing distance in units of the model's calibrated
// reject distance, weighed together with how badly the best guess's part
// takes the stroke (`fit`: the fit's mean error over the stroke's diagonal)
// and, when that part is drawn in profile (`profile`), how nearly the stroke
// is its own mirror image.
static double far_score(const sp_vec2* pts, int n, double near, double fit, bool profile)
{
    // A part drawn in profile (a head, a tail, a wing) is seldom its own
    // mirror image about an upright line; much else a visitor draws is (a
    // tree, a sun). Bodies and leg pairs are left out: a visitor's
    // oval or humped body and a neat pair of legs are symmetric too.
    double sym = profile ? fmax(0.0, MIRROR_GAP_SYMMETRIC - dragon_mirror_gap(pts, n)) : 0.0;
    return near + 6.0 * fit + MIRROR_WEIGHT * sym;
}

// far_score with the best guess's part fitted in the other facing, when it
// fits that clearly better (error under 0.55 times, as a wing's other
// facing must; INFINITY otherwise): which way a part faces is where it
// goes, not whether it is one. Legs keep their dragon's facing (their
// toes), and an L-shaped leg whose foot points back fitted it at twice the
// error or more (0.41-0.45 times in the other facing) and was refused, its
// mirror image accepted (an outside review: Quick, Draw! feet 10 and 17,
// the classifier 86-94% sure). The tune half's spiral, taken for legs,
// fits the other facing at 0.65 times and stays refused. Fitted only for a
// stroke about to be refused; a stroke it keeps takes that fit (*best).
#define REFUSAL_FACING_GAIN 0.55
// Only for a stroke the classifier is this sure of (its first guess's
// score): the review's feet were 0.86-0.94; a Quick, Draw! hammer at 0.67,
// taken for legs the same way, was kept as a crumpled leg (the kiosk review
// of the change).
#define REFUSAL_FACING_SURE 0.8
static double other_facing_far(sp_dragon* d, const sp_sketch* sk, sp_vec2 lo, sp_vec2 hi, fit_choice* best, const sp_vec2* pts,
                               int n, double near)
{
    fit_choice o;
    int not_finite = 0;
    if (!fit_one(d, best->t, sk, lo, hi, !best->mirrored, &o, &not_finite)) return INFINITY;
    double far = o.score < REFUSAL_FACING_GAIN * best->score ? far_score(pts, n, near, o.score, in_profile(best->t)) : INFINITY;
    // Kept for the stroke it keeps: folded into its dragon's facing, a foot
    // pointing back lay 60 px from the foot drawn (the review again).
    if (far <= SP_DRAGON_FAR_LIMIT) {
        free(best->p);
        *best = o;
    } else {
        free(o.p);
    }
    return far;
}

// Whether the classifier's best guess is a part with a polygon's or a star's
// symmetry itself (a curator's star: its own outline was refused).
static bool top_is_polygonal(sp_dragon* d, const sp_clf_answer* a)
{
    const tpl* t = a->count > 0 ? dragon_category_first(d, sp_clf_category(d->clf, a->ranked[0].category)) : NULL;
    return t && t->own_polygonal;
}

// The stroke path's decision: the classifier's answer becomes a category
// (accepted) or a refusal. Classifies also when the category is forced, so
// the chips still show the classifier's guesses (out->guesses); a forced
// category is taken as is; otherwise the top guess, unless the stroke is
// refused before the fit (refused_before_fit) or the top guess scores under
// min_confidence (the policy's other half waits for the fit: *near, the
// classifier's nearest distance in units of its reject distance). Sets
// out->ms_classify. Returns SP_DRAGON_ACCEPTED with category and *confidence
// filled, or why the stroke is refused.
static sp_dragon_reject classify_and_decide(sp_dragon* d, const sp_sketch* sk, const char* forced, sp_dragon_result* out,
                                            char category[SP_NAME_MAX], float* confidence, double* near, sp_clf_answer* a)
{
    *confidence = 1.0f;
    *near = 0.0;
    a->count = 0;
    if (forced) dragon_copy_name(category, SP_NAME_MAX, forced);
    if (!d->clf) return forced ? SP_DRAGON_ACCEPTED : SP_DRAGON_NO_MODEL;
    sp_error cerr = {0};
    double tc = sp_now_ms();
    sp_result r = sp_clf_classify(d->clf, sk, NULL, a, &cerr);
    if (r == SP_OK)
        fill_guesses(d->clf, a, out);
    else
        a->count = 0; // a failed classification leaves no answer to offer kin from
    if (r != SP_OK && !forced) return SP_DRAGON_UNRECOGNISED;
    out->ms_classify = sp_now_ms() - tc;
    if (forced) return SP_DRAGON_ACCEPTED;
    if (isfinite(a->reject_distance) && a->reject_distance > 0) *near = a->distance / a->reject_distance;
    if (a->count == 0 || a->ranked[0].score < d->desc.min_confidence ||
        refused_before_fit(sk->strokes[0].points, sk->strokes[0].count, hypot(sk->canvas_w, sk->canvas_h),
                           top_is_polygonal(d, a)))
        return SP_DRAGON_UNRECOGNISED;
    dragon_copy_name(category, SP_NAME_MAX, sp_clf_category(d->clf, a->ranked[0].category));
    *confidence = a->ranked[0].score;
    return SP_DRAGON_ACCEPTED;
}

// The box of part p's stroke on the canvas.
static void stroke_box_of(const part* p, sp_vec2* lo, sp_vec2* hi)
{
    *lo = (sp_vec2){p->stroke_box[0], p->stroke_box[1]}, *hi = (sp_vec2){p->stroke_box[2], p->stroke_box[3]};
}

// Part p's own copy of its cleaned stroke as a sketch (s holds the stroke).
static sp_sketch part_sketch(const sp_dragon* d, const part* p, sp_stroke* s)
{
    *s = (sp_stroke){.count = p->stroke_n, .points = p->stroke};
    return (sp_sketch){.canvas_w = d->desc.canvas_w, .canvas_h = d->desc.canvas_h, .stroke_count = 1, .strokes = s};
}

// Part i of a family (front or hind legs), attached to a body, fitted as the
// family's member for the place it was drawn (dragon_family_member): what it
// looks like decided the family, where it is decides which one. False when
// it is that member already, the place does not tell, or the member has no
// part that fits.
static bool fit_family_member(sp_dragon* d, int i, char member[SP_NAME_MAX], fit_choice* f)
{
    part* old = d->parts[i];
    if (!dragon_family_member(d, i, member) || !strcmp(member, old->pub.category)) return false;
    sp_stroke st;
    sp_sketch sk = part_sketch(d, old, &st);
    sp_vec2 lo, hi;
    stroke_box_of(old, &lo, &hi);
    int not_finite = 0;
    bool any_part = false;
    if (!fit_category(d, member, &sk, lo, hi, f, &not_finite, &any_part)) return false;
    prefer_line(d, &sk, lo, hi, f);
    return true;
}

// A classified part of a family drawn at a body becomes the family's member
// for the place it was drawn (fit_family_member). The last part is
// re-fitted as that member, which goes first in out->guesses, so the chips
// offer the other back. The classifier keeps its answer when the member has
// no part that fits.
static sp_result take_family_member(sp_dragon* d, sp_dragon_result* out, sp_error* err)
{
    int i = d->part_n - 1;
    part* old = d->parts[i];
    char member[SP_NAME_MAX];
    fit_choice f;
    if (!fit_family_member(d, i, member, &f)) return SP_OK;
    int g = 0;
    while (g < out->guess_count && strcmp(out->guesses[g].category, member))
        ++g;
    sp_dragon_guess chosen = {.confidence = 0.0f};
    if (g < out->guess_count) {
        chosen = out->guesses[g];
    } else {
        dragon_copy_name(chosen.category, sizeof chosen.category, member);
        g = out->guess_count < SP_DRAGON_GUESSES ? out->guess_count++ : SP_DRAGON_GUESSES - 1;
    }
    part* q = NULL;
    sp_result r = new_part(d, f.t, f.p, &f.rep, &f.view, f.mirrored, old->stroke, old->stroke_n, chosen.confidence, &q, err);
    free(f.p);
    if (r != SP_OK) return r;
    guess_to_front(out, g, chosen);
    dragon_part_free(old);
    d->parts[i] = q;
    dragon_relayout(d);
    return SP_OK;
}

// q, a new fit of part i, takes its place as the part it was (its id, a
// chip's choice), keeping it to give back when part `by` goes.
static void take_place(sp_dragon* d, int i, part* q, uint64_t by)
{
    part* old = d->parts[i];
    q->pub.id = old->pub.id;
    q->chosen = old->chosen;
    q->before = old, q->before_by = by;
    d->parts[i] = q;
}

// Part i becomes fit f (which it frees), keeping its id (the kiosk keys its
// chips and its kept stroke by id) and its stroke; the part it was is kept
// for the body with id `by` to give back (give_back_fits). False when out of
// memory: the part stays as it was.
static bool replace_before_body(sp_dragon* d, int i, fit_choice* f, float confidence, uint64_t by)
{
    part *old = d->parts[i], *q = NULL;
    sp_error lerr = {0};
    sp_result r = new_part(d, f->t, f->p, &f->rep, &f->view, f->mirrored, old->stroke, old->stroke_n, confidence, &q, &lerr);
    free(f->p);
    if (r != SP_OK) return false;
    take_place(d, i, q, by);
    return true;
}

// Part i leaves d->parts while the others decide without it (as a body its
// own fit would hint its own facing): their attachments follow the
// renumbering, and one to part i is none meanwhile; `saved` (part_n ints)
// keeps them for part_return.
static void part_lift(sp_dragon* d, int i, int* saved)
{
    for (int k = 0; k < d->part_n; ++k) {
        int a = saved[k] = d->parts[k]->pub.attached_to;
        d->parts[k]->pub.attached_to = a == i ? -1 : a > i ? a - 1 : a;
    }
    memmove(&d->parts[i], &d->parts[i + 1], sizeof(part*) * (size_t)(d->part_n - i - 1));
    --d->part_n;
}

static void part_return(sp_dragon* d, int i, part* p, const int* saved)
{
    memmove(&d->parts[i + 1], &d->parts[i], sizeof(part*) * (size_t)(d->part_n - i));
    d->parts[i] = p;
    ++d->part_n;
    for (int k = 0; k < d->part_n; ++k)
        d->parts[k]->pub.attached_to = saved[k];
}

// An earlier body that carries a part, at least this fraction of the new
// body's size (stroke box diagonals), stays a body.
#define SAME_SIZE_BODY 0.75

// Part i, taken by the classifier for a body when it was drawn alone, lies
// on the body just drawn (dragon_on_body): decided again as if drawn after
// that body (the on-body rule of rerank_by_fit), so the tail a visitor
// started with becomes a tail of this dragon instead of a second one. A
// body a chip chose stays, and so does one that carries two parts or more
// (a small dragon with a bigger body drawn round it: its body became a head
// smeared over the new one's flank; one part may hang on a wing or tail
// drawn first and taken for a body), or one part and is about as large.
// The new part takes the old one's place and id; false (nothing changed)
// when no other guess has a part that fits.
static bool decide_again_on_body(sp_dragon* d, int i, int body)
{
    part* old = d->parts[i];
    sp_vec2 lo, hi;
    stroke_box_of(old, &lo, &hi);
    if (!old->t->is_torso || old->chosen || !d->clf || !dragon_on_body(d, lo, hi, body)) return false;
    // A body that carries a part and is about as large as the new one, as
    // drawn, is a body: an arch drawn over a dragon's back made its body a
    // pair of legs and dropped its head, and a body drawn again a little
    // larger round the first made that one a head as large as the body (an
    // outside review). A tail or head drawn first and taken for a body is
    // clearly smaller (confidence does not tell: misread ones score 0.99
    // too; nor does lying inside the new body's box: such a tail may; second
    // and third reviews).
    const double* nbox = d->parts[body]->stroke_box;
    double old_size = hypot(hi.x - lo.x, hi.y - lo.y), new_size = hypot(nbox[2] - nbox[0], nbox[3] - nbox[1]);
    if (old->carried >= 2 || (old->carried >= 1 && old_size >= SAME_SIZE_BODY * new_size)) return false;
    sp_stroke st;
    sp_sketch sk = part_sketch(d, old, &st);
    sp_dragon_result res = {.part = -1};
    char category[SP_NAME_MAX] = "";
    float confidence = 1.0f;
    double near = 0.0;
    sp_clf_answer a;
    if (classify_and_decide(d, &sk, NULL, &res, category, &confidence, &near, &a) != SP_DRAGON_ACCEPTED) return false;
    int* saved = malloc(sizeof *saved * (size_t)d->part_n);
    if (!saved) return false;
    part_lift(d, i, saved);
    fit_choice f;
    int not_finite = 0;
    bool any_part = false, fitted = rerank_by_fit(d, &sk, lo, hi, true, &res, category, &confidence, &f, &not_finite, &any_part);
    part_return(d, i, old, saved);
    free(saved);
    if (!fitted) return false;
    if (f.t->is_torso) {
        free(f.p);
        return false;
    }
    prefer_line(d, &sk, lo, hi, &f);
    return replace_before_body(d, i, &f, confidence, d->parts[body]->pub.id);
}

// Part i (legs, wings) fitted again facing the way its dragon faces
// (dragon_facing_at), when it faces the other way. False when it faces that
// way already, the dragon does not tell, or the fit fails.
static bool turn_to_dragon(sp_dragon* d, int i, fit_choice* f)
{
    part* old = d->parts[i];
    sp_vec2 lo, hi;
    stroke_box_of(old, &lo, &hi);
    int hint = dragon_facing_at(d, lo, hi);
    if (hint == 0 || (hint < 0) == old->pub.mirrored) return false;
    sp_stroke st;
    sp_sketch sk = part_sketch(d, old, &st);
    int not_finite = 0;
    if (!fit_one(d, old->t, &sk, lo, hi, hint < 0, f, &not_finite)) return false;
    double own = old->pub.report.mean_error_px / fmax(old->pub.report.bbox_diagonal_px, 1.0);
    if (faces_freely(old->t) && own < WING_FACING_GAIN * f->score) { // its own facing fits far better
        free(f->p);
        return false;
    }
    prefer_line(d, &sk, lo, hi, f);
    return true;
}

// Free parts whose strokes come within the snap distance of body's surface
// reach it as the part just drawn does (layout.c, layout_part): fitted
// again with the attachment end where the stroke comes nearest the body.
// When the body comes (part `by`), every part drawn before it: a head drawn
// first hung beside its dragon where, drawn second, it attached
// (BENCHMARKS.md, "Thirty-fifth pass"); only_refitted: only those part `by`
// fitted again (parts_by_place: legs made the other kind or turned lost
// their reach). The former fit is kept for Undo (give_back_fits).
static bool parts_reach_body(sp_dragon* d, int body, uint64_t by, bool only_refitted)
{
    bool changed = false;
    for (int i = 0; i < d->part_n; ++i) {
        part *old = d->parts[i], *q = NULL;
        sp_vec2 target;
        bool own = old->before && old->before_by == by; // fitted again by part `by` (turned): reaches in place
        if (i == body || old->pub.id == by || old->t->is_torso || old->pub.attached_to >= 0 || (only_refitted && !own) ||
            dragon_reach_target(d, i, body, old->pub.attach_end, &target) != body)
            continue;
        if (own) {
            if (dragon_fit_reaching(d, old, target)) old->layout_key = 0, changed = true;
            continue;
        }
        sp_error lerr = {0};
        if (new_part(d, old->t, old->p_fit, &old->pub.report, &old->pub.view, old->pub.mirrored, old->stroke, old->stroke_n,
                     old->pub.confidence, &q, &lerr) != SP_OK)
            continue;
        if (!dragon_fit_reaching(d, q, target)) {
            dragon_part_free(q);
            continue;
        }
        take_place(d, i, q, by);
        changed = true;
    }
    return changed;
}

// Legs and wings attached to body `body` follow its dragon, as when drawn
// after the part with id `by` (a body just drawn, or a head or tail that
// just told its facing): legs take their kind from where they are on it
// (take_family_member; a chip's choice stands), and legs and wings face
// the way the dragon does (turn_to_dragon).
static void parts_by_place(sp_dragon* d, int body, uint64_t by)
{
    bool changed = false;
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        sp_vec2 lo, hi;
        stroke_box_of(p, &lo, &hi);
        // Free but drawn on the body: a part fitted facing the wrong way
        // may hold its attachment end away from the body.
        bool at_body = p->pub.attached_to == body || (p->pub.attached_to < 0 && dragon_on_body(d, lo, hi, body));
        if (p->pub.id == by || !at_body || p->t->is_torso || p->t->lengthwise) continue;
        char member[SP_NAME_MAX];
        fit_choice f;
        if ((!p->chosen && fit_family_member(d, i, member, &f)) || turn_to_dragon(d, i, &f))
            changed |= replace_before_body(d, i, &f, p->pub.confidence, by);
    }
    if (!changed) return;
    dragon_relayout(d);
    // Fitted again from their strokes alone, parts that had reached the body may hang free.
    if (parts_reach_body(d, body, by, true)) dragon_relayout(d);
}

// Parts drawn before a body, when the body comes (the last part), as if
// drawn after it:
// - a part the classifier took for a body that lies on it is decided again
//   (decide_again_on_body);
// - a head or a tail on it takes the facing it would have been fitted in
//   after the body (fit_variants: the facing the body hints at, kept when
//   it comes out of the body's end), so that its root rides the body;
// - legs attached to it become the legs of their end, and legs and wings
//   face the way its dragon does (parts_by_place);
// - a part drawn a little apart reaches it (parts_reach_body).
// Each keeps its id and its stroke; its former fit is kept for Undo or a
// Redraw of the body (give_back_fits).
static void parts_meet_body(sp_dragon* d)
{
    int body = d->part_n - 1;
    uint64_t by = d->parts[body]->pub.id;
    bool changed = false;
    for (int i = 0; i < body; ++i)
        changed |= decide_again_on_body(d, i, body);
    if (changed) dragon_relayout(d);
    changed = false;
    for (int i = 0; i < body; ++i) {
        part* old = d->parts[i];
        if ((old->before && old->before_by == by) || old->t->is_torso || !old->t->lengthwise) continue;
        sp_vec2 lo, hi;
        stroke_box_of(old, &lo, &hi);
        bool others = old->pub.attached_to >= 0 && old->pub.attached_to != body;
        if (others || !dragon_on_body(d, lo, hi, body)) continue; // another dragon's part
        sp_stroke st;
        sp_sketch sk = part_sketch(d, old, &st);
        fit_choice f;
        int not_finite = 0;
        tpl* t = old->t;
        if (!fit_variants(d, &t, 1, &sk, lo, hi, &f, &not_finite)) continue;
        if (f.mirrored == old->pub.mirrored) {
            free(f.p);
            continue;
        }
        prefer_line(d, &sk, lo, hi, &f);
        changed |= replace_before_body(d, i, &f, old->pub.confidence, by);
    }
    if (changed) dragon_relayout(d);
    if (parts_reach_body(d, body, by, false)) dragon_relayout(d);
    parts_by_place(d, body, by);
}

// Gives back the fits that the part with this id changed when it came (parts_meet_body, parts_by_place).
static void give_back_fits(sp_dragon* d, uint64_t by)
{
    for (int i = 0; i < d->part_n; ++i)
        while (d->parts[i]->before && d->parts[i]->before_by == by) { // decided again, then turned or made the other legs
            part* q = d->parts[i];
            d->parts[i] = q->before;
            q->before = NULL;
            dragon_part_free(q);
        }
}

// Below this confidence, a stroke taken for a part may be colouring in.
#define COLOURING_UNSURE 0.85

// Whether a classified stroke (accepted or not recognised) is drawn on a
// part (not part `skip`) as its detail, its spikes, a speck or colouring in
// (layout.c); *hit says where.
static bool drawn_on_part(sp_dragon* d, sp_dragon_reject why, float confidence, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi,
                          int skip, detail_hit* hit)
{
    if (why != SP_DRAGON_ACCEPTED && why != SP_DRAGON_UNRECOGNISED) return false;
    // Colouring in of a stroke taken for a part only when the classifier is
    // unsure: a wing drawn flat on the flank (0.9-1.0 wings) is a wing (a
    // third review: 10 of 30 visitors' wings became ink); stripes, a spiral
    // and a zigzag scored 0.42-0.8.
    bool colouring = why == SP_DRAGON_UNRECOGNISED || confidence < COLOURING_UNSURE;
    return dragon_detail_of(d, pts, n, lo, hi, skip, hit) >= 0 || dragon_edge_of(d, pts, n, lo, hi, skip, hit) >= 0 ||
           dragon_speck_of(d, pts, n, lo, hi, skip, hit) >= 0 ||
           (colouring && dragon_colouring_of(d, pts, n, lo, hi, skip, why == SP_DRAGON_ACCEPTED, hit) >= 0);
}

// A stroke (classified, not a Redraw) drawn out of a part of the dragon,
// away from its body, is a flourish of that part (docs/DESIGN.md,
// "Flourishes ride their part"): kept as ink on it (out->detail, -1 when
// the dragon holds no more), like a detail, and refused as one.
static bool kept_as_flourish(sp_dragon* d, const sp_dragon_stroke_opts* o, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi,
                             sp_dragon_result* out)
{
    detail_hit hit = {0};
    if (o->category || o->replace_last || !d->clf || dragon_flourish_of(d, pts, n, lo, hi, -1, &hit) < 0) return false;
    out->detail = dragon_detail_keep(d, &hit, pts, n);
    dragon_detail_hit_free(&hit);
    return true;
}

// A stroke its fit refused, kept as ink all the same when it is colouring
// in on a part or a flourish of one (a wavy line along a belly faded; an
// outside review): out->detail.
static bool kept_as_ink_after_fit(sp_dragon* d, const sp_dragon_stroke_opts* o, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi,
                                  sp_dragon_result* out)
{
    detail_hit ink = {0};
    bool coloured = !o->category && dragon_colouring_of(d, pts, n, lo, hi, o->replace_last ? d->part_n - 1 : -1, true, &ink) >= 0;
    if (coloured) out->detail = dragon_detail_keep(d, &ink, pts, n);
    dragon_detail_hit_free(&ink);
    return coloured || kept_as_flourish(d, o, pts, n, lo, hi, out);
}

// How many parts each body carries before a part comes (a body laid out
// with it may take their parts to itself): decide_again_on_body.
static void count_carried(sp_dragon* d)
{
    for (int k = 0; k < d->part_n; ++k)
        d->parts[k]->carried = 0;
    for (int k = 0; k < d->part_n; ++k) {
        int b = d->parts[k]->pub.attached_to;
        if (b >= 0 && b < d->part_n) ++d->parts[b]->carried;
    }
}

// The new part q in the last one's place (replace_last) or after it; q is
// freed when there is no room.
static sp_result put_part(sp_dragon* d, part* q, bool replace_last, sp_error* err)
{
    if (replace_last && d->part_n > 0) {
        give_back_fits(d, d->parts[d->part_n - 1]->pub.id);
        dragon_part_free(d->parts[d->part_n - 1]);
        d->parts[d->part_n - 1] = q;
        dragon_details_prune(d); // the replaced part's ink goes with it
        return SP_OK;
    }
    if (d->part_n == d->part_cap) {
        int cap2 = d->part_cap ? 2 * d->part_cap : 8;
        part** np = realloc(d->parts, sizeof(part*) * (size_t)cap2);
        if (!np) {
            dragon_part_free(q);
            return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        }
        d->parts = np, d->part_cap = cap2;
    }
    d->parts[d->part_n++] = q;
    return SP_OK;
}

sp_result sp_dragon_add_points(sp_dragon* d, const sp_vec2* xy, int count, const sp_dragon_stroke_opts* opts,
                               sp_dragon_result* out, sp_error* err)
{
    double t0 = sp_now_ms();
    memset(out, 0, sizeof *out);
    out->part = out->detail = -1;
    out->far_score = NAN;
    d->part_error[0] = '\0';
    sp_dragon_stroke_opts o = opts ? *opts : (sp_dragon_stroke_opts){0};
    // A chip for a detail: the part takes the detail's place when the detail is the last change.
    uint64_t drop_detail = o.replace_detail ? dragon_detail_last_change(d) : 0;
    if (count < 0 || (count > 0 && !xy)) return sp_fail(err, SP_ERR_INVALID, "stroke: %d points", count);
    if (count > 0 && !sp_curve_is_valid(xy, count))
        return sp_fail(err, SP_ERR_INVALID, "stroke: a coordinate is not a finite number");
    sp_error rerr = {0};
    sp_dragon_reload_if_changed(d, NULL, &rerr); // a failed poll keeps the current model: the kiosk goes on
    if (count < 2) return reject(out, SP_DRAGON_TOO_SHORT, t0);
    if (!(o.replace_last && d->part_n > 0) && d->part_n >= d->desc.max_parts) return reject(out, SP_DRAGON_FULL, t0);
    sp_vec2* pts = NULL;
    int n = clean_stroke(d, xy, count, &pts);
    if (n == 0) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sp_vec2 lo = pts[0], hi = pts[0];
    for (int i = 1; i < n; ++i)
        lo.x = fmin(lo.x, pts[i].x), lo.y = fmin(lo.y, pts[i].y), hi.x = fmax(hi.x, pts[i].x), hi.y = fmax(hi.y, pts[i].y);
    if (n < 2 || sp_v2_len(sp_v2_sub(hi, lo)) < 0.01 * hypot(d->desc.canvas_w, d->desc.canvas_h)) {
        free(pts);
        return reject(out, SP_DRAGON_TOO_SHORT, t0);
    }
    sp_sketch sk = {.canvas_w = d->desc.canvas_w,
                    .canvas_h = d->desc.canvas_h,
                    .stroke_count = 1,
                    .strokes = &(sp_stroke){.count = n, .points = pts}};
    char category[SP_NAME_MAX] = "";
    float confidence = 1.0f;
    double near = 0.0;
    sp_clf_answer a;
    sp_dragon_reject why = classify_and_decide(d, &sk, o.category, out, category, &confidence, &near, &a);
    // A small stroke drawn on a part is a detail of it (an eye, spots,
    // shading), one drawn along a body's edge too (spikes on its back), and
    // a speck half on a part (a spot at a thin tail's edge): a tiny or thin
    // part there is not what was meant. So is an open stroke on a part, at
    // any size: colouring in (reviews: a scribble faded, stripes became legs).
    // It is kept as ink on the part; its guesses stay (a chip makes it a part).
    detail_hit hit = {0};
    if (!o.category && drawn_on_part(d, why, confidence, pts, n, lo, hi, o.replace_last ? d->part_n - 1 : -1, &hit))
        why = SP_DRAGON_DETAIL;
    bool flourish = why == SP_DRAGON_UNRECOGNISED && kept_as_flourish(d, &o, pts, n, lo, hi, out);
    if (flourish) why = SP_DRAGON_DETAIL;
    if (why != SP_DRAGON_ACCEPTED) {
        if (why == SP_DRAGON_DETAIL && !flourish) out->detail = dragon_detail_keep(d, &hit, pts, n);
        dragon_detail_hit_free(&hit);
        free(pts);
        offer_kin(d, &a, out);
        return reject(out, why, t0);
    }
    // A part this small on the canvas is a speck nobody meant (a review: a
    // 20 px head became a body the size of a pea, wings of 25-45 px barely
    // showed): "a bit bigger please". Details on a part were taken above,
    // and a part chosen by a chip stands.
    if (!o.category && sp_v2_len(sp_v2_sub(hi, lo)) < SP_DRAGON_PART_MIN * hypot(d->desc.canvas_w, d->desc.canvas_h)) {
        free(pts);
        return reject(out, SP_DRAGON_TOO_SHORT, t0);
    }
    // Fit every variant of the category (and facing); keep the one that
    // matches best. A classified stroke is fitted with each of the
    // classifier's best guesses (rerank_by_fit).
    double tf = sp_now_ms();
    fit_choice best;
    int not_finite = 0;
    bool any_part = false;
    bool fitted;
    if (!o.category && d->clf) {
        // A stroke drawn on a body is a part of that dragon: a body guess is
        // taken only when no other guess has a part that fits.
        bool on_body = dragon_drawn_on_body(d, lo, hi, o.replace_last ? d->part_n - 1 : -1);
        fitted = rerank_by_fit(d, &sk, lo, hi, on_body, out, category, &confidence, &best, &not_finite, &any_part);
    } else {
        fitted = fit_category(d, category, &sk, lo, hi, &best, &not_finite, &any_part);
    }
    out->ms_fit = sp_now_ms() - tf;
    offer_kin(d, &a, out);
    if (!any_part) {
        free(pts);
        return reject(out, SP_DRAGON_NO_PART, t0);
    }
    if (!fitted) {
        free(pts);
        if (not_finite > 0) out->note = SP_DRAGON_NOTE_NOT_FINITE;
        return reject(out, SP_DRAGON_FIT_FAILED, t0);
    }
    if (!o.category && d->clf) out->far_score = far_score(pts, n, near, best.score, in_profile(best.t));
    if (out->far_score > SP_DRAGON_FAR_LIMIT && a.count > 0 && a.ranked[0].score >= REFUSAL_FACING_SURE)
        out->far_score = fmin(out->far_score, other_facing_far(d, &sk, lo, hi, &best, pts, n, near));
    if (out->far_score > SP_DRAGON_FAR_LIMIT) {
        bool ink = kept_as_ink_after_fit(d, &o, pts, n, lo, hi, out);
        free(pts);
        free(best.p);
        return reject(out, ink ? SP_DRAGON_DETAIL : SP_DRAGON_UNRECOGNISED, t0);
    }
    prefer_line(d, &sk, lo, hi, &best);
    part* q = NULL;
    sp_result r = new_part(d, best.t, best.p, &best.rep, &best.view, best.mirrored, pts, n, confidence, &q, err);
    free(best.p);
    if (r != SP_OK) {
        free(pts);
        return r;
    }
    q->chosen = o.category != NULL;
    count_carried(d);
    if ((r = put_part(d, q, o.replace_last, err)) != SP_OK) {
        free(pts);
        return r;
    }
    dragon_relayout(d);
    // A part that would float free, drawn out of a part of the dragon away
    // from its body, is a flourish of that part (fire from the mouth taken
    // for tails, a flame for a head, a puff of smoke for a body): kept as
    // ink on it instead, its guesses offered as a detail's.
    if (q->pub.attached_to < 0 && !o.category && d->clf && !o.replace_last && !dragon_claims_socket(d, q->t, lo, hi)) {
        // Tested without the part; only a body changes the others' layout
        // (it may have taken parts to itself), so only a body is laid out again.
        --d->part_n;
        if (q->t->is_torso) dragon_relayout(d);
        if (kept_as_flourish(d, &o, pts, n, lo, hi, out)) {
            dragon_part_free(q);
            free(pts);
            dragon_relayout(d); // the loop's period without it
            return reject(out, SP_DRAGON_DETAIL, t0);
        }
        d->parts[d->part_n++] = q;
        if (q->t->is_torso) dragon_relayout(d);
    }
    free(pts);
    if (q->t->is_torso) parts_meet_body(d);
    if (!o.category && d->clf) {
        r = take_family_member(d, out, err);
        if (r != SP_OK) return r;
    }
    // A head or tail tells the facing of the body it hangs on: the legs
    // already there take their kind from where they are, and legs and
    // wings turn to face the way it does.
    const part* last = d->parts[d->part_n - 1];
    if (last->t->lengthwise && last->pub.attached_to >= 0) parts_by_place(d, last->pub.attached_to, last->pub.id);
    dragon_details_follow_parts(d); // parts fitted again, laid out where they end
    if (drop_detail) dragon_detail_remove(d, drop_detail);
    out->part = d->part_n - 1;
    out->rejected = false;
    out->reason = SP_DRAGON_ACCEPTED;
    out->note = d->parts[out->part]->note;
    out->ms_total = sp_now_ms() - t0;
    return SP_OK;
}

sp_result sp_dragon_add_stroke(sp_dragon* d, const sp_stroke* stroke, const sp_dragon_stroke_opts* opts, sp_dragon_result* out,
                               sp_error* err)
{
    return sp_dragon_add_points(d, stroke ? stroke->points : NULL, stroke ? stroke->count : 0, opts, out, err);
}

sp_result sp_dragon_refit_last(sp_dragon* d, const char* category, sp_dragon_result* out, sp_error* err)
{
    if (d->part_n == 0) {
        memset(out, 0, sizeof *out);
        out->detail = -1;
        out->far_score = NAN;
        return reject(out, SP_DRAGON_NOTHING_TO_REFIT, sp_now_ms());
    }
    part* last = d->parts[d->part_n - 1];
    // A copy: the part (and its stroke) is freed when replaced.
    int n = last->stroke_n;
    sp_vec2* xy = malloc(sizeof(sp_vec2) * (size_t)n);
    if (!xy) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    memcpy(xy, last->stroke, sizeof(sp_vec2) * (size_t)n);
    sp_result r = sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = category, .replace_last = true}, out, err);
    free(xy);
    return r;
}

bool sp_dragon_undo(sp_dragon* d)
{
    // A detail always comes after its part, so taking back the last change never leaves ink without its part.
    if (dragon_detail_last_change(d)) {
        dragon_detail_pop(d);
        return true;
    }
    if (d->part_n == 0) return false;
    part* last = d->parts[--d->part_n];
    give_back_fits(d, last->pub.id);
    dragon_part_free(last);
    dragon_relayout(d);
    dragon_details_follow_parts(d);
    return true;
}

void sp_dragon_clear(sp_dragon* d)
{
    dragon_details_clear(d);
    while (d->part_n > 0)
        dragon_part_free(d->parts[--d->part_n]);
    dragon_relayout(d);
}
