// bench/visitors.c: the visitors' drawings through the kiosk pipeline (issue 16).
//   visitors [--half tune|report|fresh] [--db PATH] [--assets DIR] [--data DIR] [--sheet out.png] [--list] [--fit-all]
//            [--on-body [--gap PX] [--part-scale F] [--scenes K]] [--pieces F [--pause MS]] [--json]
// Every drawing of one half of the visitors' set (drawings made neither by nor
// for the project's hand-drawing model: tests/data/visitors/README.md; --data
// defaults to the whole set the build makes from designs.json and the Quick,
// Draw! data, <build>/tests/data/visitors) goes
// through the kiosk pipeline (sp_dragon_add_points) one stroke at a time, on a
// database built by the default recipe (the kiosk's first start): --db PATH is
// used when it exists and created there by that recipe when it does not;
// without --db a fresh one is built in a temporary folder. The canvas is
// 1280 x 800, as the drawings'. Printed per part: the strokes that became the
// right part, that were refused, that became a wrong part, and the right
// part's share among the three guesses (given also for refused strokes); for
// the non-parts the share refused; ms per stroke (classification, and pen-up
// to fitted part). --list prints every drawing's answer; --sheet draws the
// half with the answers (red frame: a refused or wrong part, an accepted
// non-part). --fit-all also fits every category's part to every drawing and
// prints each fit's error (mean error over the stroke's diagonal) beside the
// classifier's scores and nearest distance: the data behind the refusal
// policy and the re-ranking that was tried (BENCHMARKS.md). --on-body also
// draws every leg drawing at a dragon, as a visitor adds legs to a body:
// the half's bodies and heads in turn (forced, so that only the legs are
// measured), the dragon facing right, then left (the legs mirrored with
// it), the legs under the body's front or rear; printed per kind: the
// legs that became their own kind at their own end, and at the other end,
// and of those taken for legs, how many face the way their dragon does.
// It then draws every head, tail and wing drawing touching a dragon's body
// (parts_on_body): printed per kind, those that became their own kind (and
// attached to the body; facing the way the dragon does), a body, another
// part, or were refused, and the farthest an attached part's fitted
// attachment end moved to meet the body's surface; with
// --gap PX drawn that far apart instead (their box PX beyond the body's).
// --part-scale F draws the legs, heads, tails and wings F times their size
// (a visitor's small parts on a large body; the body stays 500 px).
// --scenes K draws each at K dragons a facing (the half's bodies and heads
// in turn): more dragons to measure a placement rule on (default 1).
// --pieces F [--pause MS] instead draws every part drawing through the
// kiosk's UI (sp_kiosk_ui, 1280 x 800 at 96 dpi, a point every 8 ms) in two
// pieces, as a finger that left the glass: broken at F of its points, the
// second piece drawn from where the first ended, MS ms after its pen-up
// (default 120); the UI's FIT jobs run on the pipeline as the kiosk runs
// them (a drawing reaching under the toolbar moved the least that brings
// it onto the canvas). F >= 1 draws it whole through the UI. Printed: the
// drawings that ended as one part, the right one; the right part among
// others; only wrong parts; nothing.
// Tune on --half tune (the default) and --half fresh (drawings made after
// the split by other hands); report --half report.
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "fixtures.h"
#include "sp/clock.h"
#include "sp/dragon.h"
#include "sp/kiosk_ui.h"
#include "sp/partdb.h"
#include "sp/sketch_io.h"
#include "sp/sketch_sheet.h"

#define NOT_A_PART "not_a_part"

typedef struct outcome {
    bool refused;
    char answer[SP_NAME_MAX]; // the part it became ("" when refused)
    bool top1, top3;          // the right category first / among the guesses (refusal aside)
    double ms_classify, ms_total;
    const char* reason;
    double far;              // sp_dragon_result.far_score (NaN: not measured)
    char guess[SP_NAME_MAX]; // the chips' first guess: what a stroke refused as far from every part would have become
} outcome;

static void stroke_box(const sp_stroke* s, sp_vec2* lo, sp_vec2* hi)
{
    sp_sketch one = {.stroke_count = 1, .strokes = (sp_stroke*)s};
    if (!sp_sketch_bounds(&one, lo, hi)) *lo = *hi = (sp_vec2){0, 0};
}

// The stroke moved and scaled so that its box has diagonal `diag` and its
// top centre at `at` (its centre when !top), mirrored left-right on request.
static sp_stroke placed(const sp_stroke* in, double diag, sp_vec2 at, bool top, bool mirror)
{
    sp_stroke o = {.count = in->count, .points = malloc(sizeof(sp_vec2) * (size_t)(in->count + 1))};
    sp_vec2 lo, hi;
    stroke_box(in, &lo, &hi);
    double f = diag / fmax(hypot(hi.x - lo.x, hi.y - lo.y), 1e-9), cx = 0.5 * (lo.x + hi.x);
    double ref_y = top ? lo.y : 0.5 * (lo.y + hi.y);
    for (int i = 0; o.points && i < in->count; ++i)
        o.points[i] = (sp_vec2){at.x + (mirror ? -1 : 1) * f * (in->points[i].x - cx), at.y + f * (in->points[i].y - ref_y)};
    return o;
}

// The half's body and head drawings (sample indices): the --on-body scenes' dragons.
typedef struct scene_set {
    int body[64], head[64], nb, nh;
} scene_set;

static bool scene_drawings(const sp_dataset* ds, scene_set* s)
{
    s->nb = s->nh = 0;
    for (int i = 0; i < ds->count; ++i) {
        const char* label = ds->categories[ds->samples[i].label];
        if (!strcmp(label, "torso") && s->nb < 64) s->body[s->nb++] = i;
        if (!strcmp(label, "head") && s->nh < 64) s->head[s->nh++] = i;
    }
    return s->nb > 0 && s->nh > 0;
}

// Scene m's dragon on a cleared canvas: its body (forced a body, box
// diagonal 500 at the canvas's centre; its box to *lo, *hi) and, with_head,
// its head (forced a head, diagonal 200, centred 20 px inside the body's
// front top corner, at *head_at); facing left mirrors the head. False when
// a stroke fails or is refused. keep: on the canvas as it is, the head
// drawn before the body (the body last, after the parts).
static bool add_dragon(sp_dragon* d, const sp_dataset* ds, const scene_set* s, int m, bool left, bool with_head, bool keep,
                       sp_vec2* lo, sp_vec2* hi, sp_vec2* head_at)
{
    if (!keep) sp_dragon_clear(d);
    sp_dragon_result res;
    sp_error err = {0};
    sp_stroke bs = placed(&ds->samples[s->body[m % s->nb]].sketch.strokes[0], 500, (sp_vec2){640, 400}, false, false);
    *lo = *hi = (sp_vec2){640, 400};
    if (bs.points) stroke_box(&bs, lo, hi);
    *head_at = (sp_vec2){640 + (left ? -1 : 1) * (0.5 * (hi->x - lo->x) - 20), lo->y - 20};
    sp_stroke hs =
        with_head ? placed(&ds->samples[s->head[m % s->nh]].sketch.strokes[0], 200, *head_at, false, left) : (sp_stroke){0};
    bool ok = bs.points && (!with_head || hs.points);
    for (int k = 0; k < 2 && ok; ++k) {
        bool body = (k == 0) != keep;
        if (body)
            ok =
                sp_dragon_add_stroke(d, &bs, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK && !res.rejected;
        else if (with_head)
            ok = sp_dragon_add_stroke(d, &hs, &(sp_dragon_stroke_opts){.category = "head"}, &res, &err) == SP_OK && !res.rejected;
    }
    free(bs.points), free(hs.points);
    return ok;
}

static bool draw_dragon(sp_dragon* d, const sp_dataset* ds, const scene_set* s, int m, bool left, bool with_head, sp_vec2* lo,
                        sp_vec2* hi, sp_vec2* head_at)
{
    return add_dragon(d, ds, s, m, left, with_head, false, lo, hi, head_at);
}

// The part's stroke (classified; its result to *res) added to scene m's
// dragon, already drawn; first: instead drawn on a cleared canvas before the
// same dragon, the body last. False when a stroke fails or is refused (the
// part's refusal is in *res).
static bool add_part(sp_dragon* d, const sp_dataset* ds, const scene_set* s, int m, bool left, bool with_head, bool first,
                     const sp_stroke* part, sp_dragon_result* res)
{
    sp_error err = {0};
    if (!first) return sp_dragon_add_stroke(d, part, NULL, res, &err) == SP_OK;
    sp_vec2 lo, hi, head_at;
    sp_dragon_clear(d);
    return sp_dragon_add_stroke(d, part, NULL, res, &err) == SP_OK &&
           add_dragon(d, ds, s, m, left, with_head, true, &lo, &hi, &head_at);
}

// --on-body: legs drawn at a dragon (a body and a head drawn first), printed
// as a table (or JSON rows). A scene whose body, head or legs stroke fails
// or is refused counts as legs not of their kind.
// `alone`: the drawings' single-stroke outcomes (no body, no rule).
// --part-scale: the on-body parts' size against the bench's own.
static double part_scale = 1;
// --scenes K: each on-body drawing at K dragons (the half's bodies and heads
// in turn) a facing, where one gives few dragons to learn a rule from.
static int scene_rounds = 1;

static void legs_on_body(sp_dragon* d, const sp_dataset* ds, const outcome* alone_out, bool json, const char* half,
                         bool parts_first)
{
    static const char* const kinds[2] = {"front_legs", "hind_legs"};
    scene_set scenes;
    if (!scene_drawings(ds, &scenes)) return;
    int n[2] = {0}, own[2] = {0}, other[2] = {0}, alone[2] = {0}, as_legs[2] = {0}, faced[2] = {0};
    int m = 0;
    for (int i = 0; i < ds->count; ++i) {
        const char* label = ds->categories[ds->samples[i].label];
        int kind = !strcmp(label, kinds[0]) ? 0 : !strcmp(label, kinds[1]) ? 1 : -1;
        if (kind < 0) continue;
        const sp_stroke* legs = &ds->samples[i].sketch.strokes[0];
        sp_dragon_result res;
        // Once a drawing; n counts each drawing once a facing, so both print it twice.
        alone[kind] += !alone_out[i].refused && !strcmp(alone_out[i].answer, label);
        for (int facing = 0; facing < 2; ++facing, ++m)
            for (int e = 0; e < 2 * scene_rounds; ++e) {
                int end = e % 2, sm = m * scene_rounds + e / 2; // 0: the legs' own end, 1: the other; sm: the dragon
                // The legs' top at 60% of the body's height, a quarter of its width from the middle.
                sp_vec2 lo, hi, head_at;
                bool ok = draw_dragon(d, ds, &scenes, sm, facing != 0, true, &lo, &hi, &head_at);
                double dir = facing ? -1 : 1, w = hi.x - lo.x; // dir: the side the head is on
                bool front = (kind == 0) == (end == 0);
                sp_stroke ls =
                    placed(legs, 260 * part_scale, (sp_vec2){640 + dir * (front ? 0.25 : -0.25) * w, lo.y + 0.6 * (hi.y - lo.y)},
                           true, facing != 0);
                ok = ok && ls.points && add_part(d, ds, &scenes, sm, facing != 0, true, parts_first, &ls, &res);
                if (ok && !res.rejected) {
                    const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
                    bool right = !strcmp(p->category, label);
                    if (strstr(p->category, "legs")) as_legs[kind]++, faced[kind] += p->mirrored == (facing != 0);
                    if (end == 0)
                        own[kind] += right;
                    else
                        other[kind] += right;
                }
                if (end == 0) n[kind]++;
                free(ls.points);
            }
    }
    sp_dragon_clear(d);
    if (json) {
        for (int k = 0; k < 2; ++k)
            printf("  {\"case\": \"%s %s on a body%s\", \"n\": %d, \"alone\": %d, \"own_end\": %d, \"other_end\": %d, "
                   "\"as_legs\": %d, \"facing_the_dragon\": %d},\n",
                   half, kinds[k], parts_first ? ", drawn first" : "", n[k], 2 * scene_rounds * alone[k], own[k], other[k],
                   as_legs[k], faced[k]);
        return;
    }
    printf("Legs drawn at a dragon (%s; facing right, then left): became their own kind\n",
           parts_first ? "the legs first, then a head and the body" : "a body and a head first");
    printf("%-12s %6s %22s %22s %22s %22s\n", "legs", "drawn", "alone (no body)", "at their own end", "at the other end",
           "facing their dragon");
    for (int k = 0; k < 2; ++k)
        printf("%-12s %6d %15d of %4d %15d of %4d %15d of %4d %15d of %4d\n", kinds[k], n[k], 2 * scene_rounds * alone[k], n[k],
               own[k], n[k], other[k], n[k], faced[k], as_legs[k]);
}

// The stroke moved by (dx, dy), in place.
static void shifted(sp_stroke* s, double dx, double dy)
{
    for (int i = 0; s->points && i < s->count; ++i)
        s->points[i].x += dx, s->points[i].y += dy;
}

// --on-body: heads, tails and wings drawn touching a dragon's body, as a
// visitor adds them: the half's bodies in turn (forced a body, box diagonal
// 500 at the canvas's centre); for tails and wings also one of its heads
// (forced a head, over the body's front end, as for the legs); the dragon
// facing right, then left (everything mirrored). The part (classified):
// a head centred 20 px inside the body's front top corner; a tail reaching
// out of the rear, its box 30 px into the body's, centred on the body's
// height; wings standing on the body's back, their box 30 px into it.
// Counted per kind: became its own kind (and of those, attached to the
// body), a body (a second dragon), another part, refused. parts_first: the
// part is drawn first, on a clear canvas, then the head and the body, as
// a visitor who starts with the tail.
static void parts_on_body(sp_dragon* d, const sp_dataset* ds, bool json, const char* half, bool parts_first, double gap)
{
    static const char* const kinds[3] = {"head", "tail", "wings"};
    scene_set scenes;
    if (!scene_drawings(ds, &scenes)) return;
    int n[3] = {0}, own[3] = {0}, attached[3] = {0}, body[3] = {0}, other[3] = {0}, refused[3] = {0}, faced[3] = {0};
    double moved[3] = {0}; // the farthest an attached part moved to meet its body, px
    int m = 0;
    for (int i = 0; i < ds->count; ++i) {
        const char* label = ds->categories[ds->samples[i].label];
        int kind = -1;
        for (int k = 0; k < 3; ++k)
            if (!strcmp(label, kinds[k])) kind = k;
        if (kind < 0) continue;
        const sp_stroke* part_s = &ds->samples[i].sketch.strokes[0];
        for (int fr = 0; fr < 2 * scene_rounds; ++fr) {
            int facing = fr / scene_rounds, sm = (m + facing) * scene_rounds + fr % scene_rounds; // sm: the dragon
            sp_dragon_result res;
            sp_vec2 lo, hi, head_at, plo, phi;
            bool ok = draw_dragon(d, ds, &scenes, sm, facing != 0, kind != 0, &lo, &hi, &head_at);
            double dir = facing ? -1 : 1;
            sp_stroke ps = placed(part_s, (kind == 0 ? 200 : 260) * part_scale, kind == 0 ? head_at : (sp_vec2){640, 400}, false,
                                  facing != 0);
            if (ps.points && (kind > 0 || gap > 0)) {
                stroke_box(&ps, &plo, &phi);
                // Into the body's box by 30 px (touching), or `gap` px apart.
                double in = gap > 0 ? -gap : 30;
                if (kind == 2) { // the wings over the body's middle, on (or above) its back
                    shifted(&ps, 640 - 0.5 * (plo.x + phi.x), (lo.y + in) - phi.y);
                } else { // the tail out of the rear end, centred on the body's height; apart, the head beyond the front
                    bool at_right = (kind == 0) == (dir > 0);
                    shifted(&ps, at_right ? (hi.x - in) - plo.x : (lo.x + in) - phi.x,
                            kind == 0 ? 0 : 0.5 * (lo.y + hi.y) - 0.5 * (plo.y + phi.y));
                }
            }
            ok = ok && ps.points && add_part(d, ds, &scenes, sm, facing != 0, kind != 0, parts_first, &ps, &res);
            n[kind]++;
            if (!ok || res.rejected) {
                refused[kind]++;
            } else {
                const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
                bool on = p->attached_to >= 0 && sp_dragon_part_get(d, p->attached_to)->is_torso;
                if (!strcmp(p->category, label)) {
                    own[kind]++, attached[kind] += on, faced[kind] += p->mirrored == (facing != 0);
                    if (on) moved[kind] = fmax(moved[kind], sp_v2_len(sp_v2_sub(p->anchor, p->attach_end)));
                } else if (p->is_torso)
                    body[kind]++;
                else
                    other[kind]++;
            }
            free(ps.points);
        }
        m += 2;
    }
    sp_dragon_clear(d);
    if (json) {
        for (int k = 0; k < 3; ++k)
            printf("  {\"case\": \"%s %s on a body%s\", \"gap_px\": %g, \"n\": %d, \"own\": %d, \"own_attached\": %d, "
                   "\"body\": %d, \"other\": %d, \"refused\": %d, \"own_facing_the_dragon\": %d, \"moved_px_max\": %.0f},\n",
                   half, kinds[k], parts_first ? ", drawn first" : "", gap, n[k], own[k], attached[k], body[k], other[k],
                   refused[k], faced[k], moved[k]);
        return;
    }
    if (gap > 0)
        printf("Heads, tails and wings drawn %g px apart from a dragon's body%s (facing right, then left)\n", gap,
               parts_first ? ", each drawn first, then the head and the body" : "");
    else
        printf("Heads, tails and wings drawn touching a dragon's body%s (facing right, then left)\n",
               parts_first ? ", each drawn first, then the head and the body" : "");
    printf("%-12s %6s %12s %12s %12s %12s %12s %14s %12s\n", "part", "drawn", "own kind", "attached", "a body", "other part",
           "refused", "facing dragon", "moved <= px");
    for (int k = 0; k < 3; ++k)
        printf("%-12s %6d %12d %12d %12d %12d %12d %14d %12.0f\n", kinds[k], n[k], own[k], attached[k], body[k], other[k],
               refused[k], faced[k], moved[k]);
}

static int json_file(const struct dirent* e)
{
    size_t n = strlen(e->d_name);
    return n > 5 && !strcmp(e->d_name + n - 5, ".json");
}

static int by_name(const struct dirent** a, const struct dirent** b)
{
    return strcmp((*a)->d_name, (*b)->d_name);
}

// The file name (without .json) of sample i: sp_dataset_load reads each
// category's files in name order, so its index is its place in that order.
static void sample_name(const char* dir, const sp_dataset* ds, int i, char* out, size_t cap)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, ds->categories[ds->samples[i].label]);
    struct dirent** list = NULL;
    int n = scandir(path, &list, json_file, by_name);
    snprintf(out, cap, "#%d", ds->samples[i].index);
    for (int k = 0; k < n; ++k) {
        if (k == ds->samples[i].index) snprintf(out, cap, "%.*s", (int)strlen(list[k]->d_name) - 5, list[k]->d_name);
        free(list[k]);
    }
    free(list);
}

static int find(char** names, int n, const char* s)
{
    for (int i = 0; i < n; ++i)
        if (!strcmp(names[i], s)) return i;
    return -1;
}

// The database built in a temporary folder (no --db), removed.
static void remove_tmp_db(const char* dir, const char* db)
{
    if (!db[0]) return;
    sp_fixture_remove_db(db);
    rmdir(dir);
}

static int fail_tmp(const char* dir, const char* db)
{
    remove_tmp_db(dir, db);
    return 1;
}

// Runs the UI's queued jobs on the pipeline as the kiosk does (run_fit):
// a FIT that continues the last stroke takes back what that made first.
static void run_ui_jobs(sp_kiosk_ui* ui, sp_dragon* d)
{
    sp_kiosk_job j;
    static sp_vec2 xy[SP_KIOSK_STROKE_MAX];
    while (sp_kiosk_ui_next_job(ui, &j)) {
        if (j.kind != SP_KJOB_FIT) continue;
        for (int i = 0; i < j.stroke->count; ++i)
            xy[i] = (sp_vec2){j.stroke->xy[2 * i], j.stroke->xy[2 * i + 1]};
        if (j.undo_first) sp_dragon_undo(d);
        sp_dragon_result res;
        sp_error err = {0};
        sp_result r = sp_dragon_add_points(d, xy, j.stroke->count,
                                           &(sp_dragon_stroke_opts){.category = j.category[0] ? j.category : NULL,
                                                                    .replace_last = j.replace,
                                                                    .replace_detail = j.replace_detail},
                                           &res, &err);
        bool ok = r == SP_OK && !res.rejected && res.part >= 0;
        sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = ok,
                                                        .kept = r == SP_OK && res.reason == SP_DRAGON_DETAIL && res.detail >= 0,
                                                        .category = ok ? sp_dragon_part_get(d, res.part)->category : NULL,
                                                        .part_count = sp_dragon_part_count(d)});
    }
}

// Points i0..i1 of s moved by `by`, as a finger's down, moves and up from time t; returns the pen-up time.
static double finger(sp_kiosk_ui* ui, const sp_stroke* s, sp_vec2 by, int i0, int i1, double t)
{
    for (int i = i0; i <= i1; ++i, t += 8) {
        sp_kiosk_event_type ty = i == i0 ? SP_KEV_DOWN : i == i1 ? SP_KEV_UP : SP_KEV_MOVE;
        sp_kiosk_ui_event(ui, &(sp_kiosk_event){ty, t, (float)(s->points[i].x + by.x), (float)(s->points[i].y + by.y), 0});
    }
    return t - 8;
}

// The least move that brings the stroke's box into the UI's canvas (the
// window without the toolbar): a visitor draws where the canvas is.
static sp_vec2 onto_canvas(const sp_kiosk_ui* ui, const sp_stroke* s)
{
    sp_vec2 lo, hi, by = {0, 0};
    stroke_box(s, &lo, &hi);
    const sp_kiosk_rect* c = &ui->canvas;
    double m = 2, x1 = c->x + c->w - m, y1 = c->y + c->h - m;
    if (hi.x > x1) by.x = x1 - hi.x;
    if (lo.x + by.x < c->x + m) by.x = c->x + m - lo.x;
    if (hi.y > y1) by.y = y1 - hi.y;
    if (lo.y + by.y < c->y + m) by.y = c->y + m - lo.y;
    return by;
}

// --pieces: each part drawing in two pieces through the UI (see the top).
static void in_pieces(sp_dragon* d, const sp_dataset* ds, double frac, double pause, bool json, const char* half)
{
    int none = find(ds->categories, ds->category_count, NOT_A_PART);
    int n = 0, one_right = 0, among = 0, wrong = 0, nothing = 0, joined = 0;
    for (int i = 0; i < ds->count; ++i) {
        if (ds->samples[i].label == none) continue;
        const char* label = ds->categories[ds->samples[i].label];
        const sp_stroke* s = &ds->samples[i].sketch.strokes[0];
        if (s->count < 4) continue;
        sp_kiosk_ui* ui = NULL;
        if (sp_kiosk_ui_create(NULL, &ui, NULL) != SP_OK) return;
        sp_kiosk_ui_resize(ui, 1280, 800, 96.0 / 25.4);
        // A tap leaves the attract screen.
        sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_DOWN, 0, 640, 400, 0});
        sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_UP, 50, 640, 400, 0});
        int k = frac >= 1 ? s->count - 1 : (int)(frac * (s->count - 1));
        k = k < 1 ? 1 : k;
        sp_vec2 by = onto_canvas(ui, s);
        double up = finger(ui, s, by, 0, k, 1000);
        run_ui_jobs(ui, d);
        if (k < s->count - 1) {
            finger(ui, s, by, k, s->count - 1, up + pause);
            run_ui_jobs(ui, d);
        }
        int parts = sp_dragon_part_count(d), right = 0;
        for (int p = 0; p < parts; ++p)
            right += !strcmp(sp_dragon_part_get(d, p)->category, label);
        ++n;
        one_right += parts == 1 && right == 1;
        among += right > 0 && parts > 1;
        wrong += parts > 0 && right == 0;
        nothing += parts == 0;
        joined += ui->joined;
        sp_kiosk_ui_destroy(ui);
        sp_dragon_clear(d);
    }
    if (json)
        printf("[\n  {\"case\": \"%s parts in two pieces\", \"frac\": %g, \"pause_ms\": %g, \"n\": %d, \"one_right\": %d, "
               "\"right_among_others\": %d, \"wrong\": %d, \"nothing\": %d, \"joined\": %d}\n]\n",
               half, frac, pause, n, one_right, among, wrong, nothing, joined);
    else
        printf("%s half, %d part drawings %s: one part, the right one %d; the right part among others %d; only wrong parts "
               "%d; nothing %d (pieces joined: %d)\n",
               half, n, frac >= 1 ? "drawn whole through the UI" : "in two pieces", one_right, among, wrong, nothing, joined);
}

// "1.2,1.23,1.26" -> limits; 0 when malformed (a value not a positive number, more than cap).
static int parse_limits(const char* text, double* limits, int cap)
{
    int n = 0;
    for (const char* p = text; *p;) {
        char* end;
        double v = strtod(p, &end);
        if (end == p || !(v > 0) || !isfinite(v) || n == cap || (*end && (*end != ',' || !end[1]))) return 0;
        limits[n++] = v;
        p = *end ? end + 1 : end;
    }
    return n;
}

// What the half would give with the far-from-every-part limit at `limit`
// instead of SP_DRAGON_FAR_LIMIT: each stroke's far score decides it anew
// (a stroke refused for another reason, or before its fit, stays refused;
// one accepted only past the limit becomes its chips' first guess).
static void at_limit(const sp_dataset* ds, const outcome* out, int none, double limit, int* right, int* refused, int* non)
{
    *right = *refused = *non = 0;
    for (int i = 0; i < ds->count; ++i) {
        const outcome* o = &out[i];
        bool ref = isfinite(o->far) ? o->far > limit : o->refused;
        const char* answer = o->refused ? o->guess : o->answer;
        if (ds->samples[i].label == none)
            *non += ref;
        else {
            *refused += ref;
            *right += !ref && !strcmp(answer, ds->categories[ds->samples[i].label]);
        }
    }
}

int main(int argc, char** argv)
{
    const char *half = "tune", *db_path = NULL, *assets = SP_SOURCE_DIR "/assets", *data = SP_BINARY_DIR "/tests/data/visitors",
               *sheet = NULL;
    bool json = sp_bench_json_flag(argc, argv), list = false, fit_all = false, on_body = false;
    double gap = 0, pieces = 0, pause = 120, limits[32];
    int n_limits = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--half") && i + 1 < argc)
            half = argv[++i];
        else if (!strcmp(argv[i], "--db") && i + 1 < argc)
            db_path = argv[++i];
        else if (!strcmp(argv[i], "--assets") && i + 1 < argc)
            assets = argv[++i];
        else if (!strcmp(argv[i], "--data") && i + 1 < argc)
            data = argv[++i];
        else if (!strcmp(argv[i], "--sheet") && i + 1 < argc)
            sheet = argv[++i];
        else if (!strcmp(argv[i], "--list"))
            list = true;
        else if (!strcmp(argv[i], "--fit-all"))
            fit_all = true;
        else if (!strcmp(argv[i], "--on-body"))
            on_body = true;
        else if (!strcmp(argv[i], "--gap") && i + 1 < argc)
            gap = atof(argv[++i]);
        else if (!strcmp(argv[i], "--part-scale") && i + 1 < argc && atof(argv[i + 1]) > 0)
            part_scale = atof(argv[++i]);
        else if (!strcmp(argv[i], "--scenes") && i + 1 < argc && atoi(argv[i + 1]) >= 1 && atoi(argv[i + 1]) <= 64)
            scene_rounds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--pieces") && i + 1 < argc && atof(argv[i + 1]) > 0)
            pieces = atof(argv[++i]);
        else if (!strcmp(argv[i], "--pause") && i + 1 < argc && atof(argv[i + 1]) >= 0)
            pause = atof(argv[++i]);
        else if (!strcmp(argv[i], "--limits") && i + 1 < argc && (n_limits = parse_limits(argv[i + 1], limits, 32)) > 0)
            ++i;
        else if (strcmp(argv[i], "--json") != 0) {
            fprintf(stderr,
                    "usage: visitors [--half tune|report|fresh] [--db PATH] [--assets DIR] [--data DIR] [--sheet out.png] "
                    "[--list] [--fit-all] [--limits L,L...] [--on-body [--gap PX] [--part-scale F] [--scenes K]] [--pieces F "
                    "[--pause MS]] "
                    "[--json]\n");
            return 2;
        }
    }
    if (strcmp(half, "tune") != 0 && strcmp(half, "report") != 0 && strcmp(half, "fresh") != 0) {
        fprintf(stderr, "visitors: --half is tune, report or fresh\n");
        return 2;
    }
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/%s", data, half);
    sp_dataset ds = {0};
    sp_error err = {0};
    if (sp_dataset_load(dir, &ds, &err) != SP_OK) {
        fprintf(stderr, "visitors: %s\n", err.text);
        return 1;
    }
    char tmp[] = "/tmp/sp-visitors-XXXXXX", tmp_db[64] = "";
    if (!db_path) {
        if (!mkdtemp(tmp)) {
            fprintf(stderr, "visitors: cannot create a temporary folder\n");
            return 1;
        }
        snprintf(tmp_db, sizeof tmp_db, "%s/default.db", tmp);
        db_path = tmp_db;
    }
    double t_build = 0;
    if (access(db_path, F_OK) != 0) {
        double t0 = sp_now_ms();
        if (sp_db_create_default(db_path, assets, NULL, &err) != SP_OK) {
            fprintf(stderr, "visitors: %s\n", err.text);
            return fail_tmp(tmp, tmp_db);
        }
        t_build = sp_now_ms() - t0;
        fprintf(stderr, "visitors: built %s by the default recipe in %.1f s\n", db_path, t_build / 1000);
    }
    sp_dragon* d;
    sp_dragon_create(&(sp_dragon_desc){.db_path = db_path, .assets_dir = assets, .canvas_w = 1280, .canvas_h = 800}, &d, &err);
    if (!d || sp_dragon_preload(d, &err) != SP_OK) {
        fprintf(stderr, "visitors: %s\n", err.text);
        return fail_tmp(tmp, tmp_db);
    }
    if (pieces > 0) {
        if (pieces < 1 && !json) printf("Broken at %g of its points, drawn on %g ms after\n", pieces, pause);
        in_pieces(d, &ds, pieces, pause, json, half);
        sp_dragon_destroy(d);
        sp_dataset_free(&ds);
        remove_tmp_db(tmp, tmp_db);
        return 0;
    }
    outcome* out = calloc((size_t)ds.count + 1, sizeof *out);
    double* ms_c = malloc(sizeof(double) * ((size_t)ds.count + 1));
    double* ms_t = malloc(sizeof(double) * ((size_t)ds.count + 1));
    int n_ms = 0;
    for (int i = 0; i < ds.count; ++i) {
        const sp_sketch* s = &ds.samples[i].sketch;
        const char* label = ds.categories[ds.samples[i].label];
        sp_dragon_result res;
        if (s->stroke_count != 1) {
            fprintf(stderr, "visitors: drawing %d of %s has %d strokes (one expected)\n", i, label, s->stroke_count);
            return fail_tmp(tmp, tmp_db);
        }
        if (sp_dragon_add_stroke(d, &s->strokes[0], NULL, &res, &err) != SP_OK) {
            fprintf(stderr, "visitors: %s drawing %d: %s\n", label, i, err.text);
            return fail_tmp(tmp, tmp_db);
        }
        outcome* o = &out[i];
        o->refused = res.rejected;
        o->reason = sp_dragon_reject_name(res.reason);
        if (!res.rejected) snprintf(o->answer, sizeof o->answer, "%s", sp_dragon_part_get(d, res.part)->category);
        o->far = res.far_score;
        if (res.guess_count > 0) snprintf(o->guess, sizeof o->guess, "%s", res.guesses[0].category);
        if (isfinite(o->far) && o->refused != (o->far > SP_DRAGON_FAR_LIMIT)) {
            fprintf(stderr, "visitors: %s drawing %d: far score %.4f, yet %s\n", label, i, o->far,
                    o->refused ? "refused" : "accepted");
            return fail_tmp(tmp, tmp_db);
        }
        for (int k = 0; k < res.guess_count; ++k)
            o->top3 |= !strcmp(res.guesses[k].category, label);
        o->top1 = !strcmp(o->guess, label); // "" when there were no guesses
        o->ms_classify = res.ms_classify;
        o->ms_total = res.ms_total;
        // Every stroke that reached the classifier counts for the timing (taps stop before it).
        if (res.ms_classify > 0) {
            ms_c[n_ms] = res.ms_classify;
            ms_t[n_ms++] = res.ms_total;
        }
        sp_dragon_clear(d);
        if (fit_all) { // diagnostic: every category forced, the fit's error relative to the stroke's size
            const sp_clf* clf = sp_dragon_model(d);
            char name[256];
            sample_name(dir, &ds, i, name, sizeof name);
            printf("%-11s %-34s", label, name);
            double best = 1e9;
            int bc = -1;
            for (int c = 0; clf && c < sp_clf_category_count(clf); ++c) {
                sp_dragon_result fr;
                sp_dragon_add_stroke(d, &s->strokes[0], &(sp_dragon_stroke_opts){.category = sp_clf_category(clf, c)}, &fr, &err);
                double e = fr.part >= 0 ? sp_dragon_part_get(d, fr.part)->report.mean_error_px /
                                              sp_dragon_part_get(d, fr.part)->report.bbox_diagonal_px
                                        : 9;
                printf(" %s=%.3f", sp_clf_category(clf, c), e);
                if (e < best) best = e, bc = c;
                sp_dragon_clear(d);
            }
            printf("  best=%s guess=%s", bc >= 0 ? sp_clf_category(clf, bc) : "-",
                   res.guess_count ? res.guesses[0].category : "-");
            sp_sketch one = {.canvas_w = 1280, .canvas_h = 800, .stroke_count = 1, .strokes = &s->strokes[0]};
            sp_clf_answer a;
            if (clf && sp_clf_classify(clf, &one, NULL, &a, &err) == SP_OK) {
                printf(" dist=%.4f rej=%.4f clf:", a.distance, a.reject_distance);
                for (int k = 0; k < a.count; ++k)
                    printf(" %s=%.3f", sp_clf_category(clf, a.ranked[k].category), a.ranked[k].score);
            }
            printf("\n");
        }
    }
    // Per part.
    char** cats = ds.categories;
    int nc = ds.category_count;
    int *n = calloc((size_t)nc, sizeof(int)), *right = calloc((size_t)nc, sizeof(int)),
        *refused = calloc((size_t)nc, sizeof(int)), *wrong = calloc((size_t)nc, sizeof(int)),
        *top3 = calloc((size_t)nc, sizeof(int)), *top1 = calloc((size_t)nc, sizeof(int));
    for (int i = 0; i < ds.count; ++i) {
        int c = ds.samples[i].label;
        n[c]++;
        refused[c] += out[i].refused;
        right[c] += !out[i].refused && !strcmp(out[i].answer, cats[c]);
        wrong[c] += !out[i].refused && strcmp(out[i].answer, cats[c]) != 0;
        top3[c] += out[i].top3;
        top1[c] += out[i].top1;
    }
    int none = find(cats, nc, NOT_A_PART);
    int pn = 0, pr = 0, pref = 0, pw = 0, p3 = 0, p1 = 0;
    for (int c = 0; c < nc; ++c)
        if (c != none) pn += n[c], pr += right[c], pref += refused[c], pw += wrong[c], p3 += top3[c], p1 += top1[c];
    double mc = 0, mc90 = 0, mt = 0, mt90 = 0;
    if (n_ms > 0) {
        sp_bench_stats(ms_c, n_ms, &mc, &mc90);
        sp_bench_stats(ms_t, n_ms, &mt, &mt90);
    }
    if (list)
        for (int i = 0; i < ds.count; ++i) {
            const char* label = cats[ds.samples[i].label];
            bool ok = strcmp(label, NOT_A_PART) ? !out[i].refused && !strcmp(out[i].answer, label) : out[i].refused;
            char name[256];
            sample_name(dir, &ds, i, name, sizeof name);
            fprintf(json ? stderr : stdout, "%-4s %-11s %-34s -> %-12s (%s)%s\n", ok ? "ok" : "MISS", label, name,
                    out[i].refused ? "refused" : out[i].answer, out[i].reason, out[i].top3 ? "" : " not in top 3");
        }
    if (json) {
        printf("[\n");
        if (on_body) {
            for (int first = 0; first < 2; ++first) {
                legs_on_body(d, &ds, out, true, half, first);
                parts_on_body(d, &ds, true, half, first, gap);
            }
        }
        for (int c = 0; c < nc; ++c) {
            if (c == none) continue;
            printf("  {\"case\": \"%s %s\", \"n\": %d, \"right\": %d, \"refused\": %d, \"wrong\": %d, \"top1\": %d, \"top3\": "
                   "%d},\n",
                   half, cats[c], n[c], right[c], refused[c], wrong[c], top1[c], top3[c]);
        }
        printf(
            "  {\"case\": \"%s parts\", \"n\": %d, \"right\": %d, \"refused\": %d, \"wrong\": %d, \"top1\": %d, \"top3\": %d},\n",
            half, pn, pr, pref, pw, p1, p3);
        if (none >= 0) printf("  {\"case\": \"%s not a part\", \"n\": %d, \"refused\": %d},\n", half, n[none], refused[none]);
        for (int k = 0; k < n_limits; ++k) {
            int r, f, nr;
            at_limit(&ds, out, none, limits[k], &r, &f, &nr);
            printf("  {\"case\": \"%s far limit %g\", \"right\": %d, \"refused\": %d, \"non_parts_refused\": %d},\n", half,
                   limits[k], r, f, nr);
        }
        printf("  {\"case\": \"%s classify\", \"ms_median\": %.3f, \"ms_p90\": %.3f, \"runs\": %d, \"target_ms\": 10},\n", half,
               mc, mc90, n_ms);
        printf("  {\"case\": \"%s pen-up to part\", \"ms_median\": %.3f, \"ms_p90\": %.3f, \"runs\": %d, \"target_ms\": 50}",
               half, mt, mt90, n_ms);
        if (t_build > 0)
            printf(",\n  {\"case\": \"first build of the default database\", \"ms_median\": %.0f, \"runs\": 1, \"target_ms\": "
                   "120000}",
                   t_build);
        printf("\n]\n");
    } else {
        printf("Visitors' drawings, %s %s (%s), database %s\n", half, strcmp(half, "fresh") ? "half" : "set", dir, db_path);
        printf("%-12s %4s %14s %14s %14s %14s %14s\n", "part", "n", "right part", "refused", "wrong part", "top 3",
               "first guess");
#define PCT(a, b) ((b) > 0 ? 100.0 * (a) / (b) : 0.0)
        for (int c = 0; c < nc; ++c) {
            if (c == none) continue;
            printf("%-12s %4d %6d (%4.0f%%) %6d (%4.0f%%) %6d (%4.0f%%) %6d (%4.0f%%) %6d (%4.0f%%)\n", cats[c], n[c], right[c],
                   PCT(right[c], n[c]), refused[c], PCT(refused[c], n[c]), wrong[c], PCT(wrong[c], n[c]), top3[c],
                   PCT(top3[c], n[c]), top1[c], PCT(top1[c], n[c]));
        }
        printf("%-12s %4d %6d (%4.1f%%) %6d (%4.1f%%) %6d (%4.1f%%) %6d (%4.1f%%) %6d (%4.1f%%)\n", "all parts", pn, pr,
               PCT(pr, pn), pref, PCT(pref, pn), pw, PCT(pw, pn), p3, PCT(p3, pn), p1, PCT(p1, pn));
        printf("%-12s %4s %14s %14s %14s %14s %14s\n", "targets", "", ">= 85%", "<= 5%", "", ">= 97%", "(refusal aside)");
        if (none >= 0)
            printf("%-12s %4d refused %d (%.1f%%)   target: >= 50%%\n", "not a part", n[none], refused[none],
                   PCT(refused[none], n[none]));
        printf("ms per stroke (%d strokes that reached the classifier): classification %.2f median, %.2f p90 (target 10); pen-up "
               "to part %.2f "
               "median, %.2f p90 (target 50)\n",
               n_ms, mc, mc90, mt, mt90);
        if (n_limits > 0)
            printf("far-from-every-part limit (the kiosk's %g): right parts / parts refused / non-parts refused\n",
                   SP_DRAGON_FAR_LIMIT);
        for (int k = 0; k < n_limits; ++k) {
            int r, f, nr;
            at_limit(&ds, out, none, limits[k], &r, &f, &nr);
            printf("  %-8g %4d / %d / %d\n", limits[k], r, f, nr);
        }
#undef PCT
        if (on_body && part_scale != 1) printf("Parts drawn at a dragon at %g times the size below\n", part_scale);
        if (on_body) {
            for (int first = 0; first < 2; ++first) {
                legs_on_body(d, &ds, out, false, half, first);
                parts_on_body(d, &ds, false, half, first, gap);
            }
        }
    }
    if (sheet) {
        sp_sheet_item* items = calloc((size_t)ds.count, sizeof *items);
        char(*notes)[96] = calloc((size_t)ds.count, sizeof *notes);
        char(*labels)[96] = calloc((size_t)ds.count, sizeof *labels);
        for (int i = 0; i < ds.count; ++i) {
            const char* label = cats[ds.samples[i].label];
            bool part = strcmp(label, NOT_A_PART) != 0;
            sample_name(dir, &ds, i, labels[i], sizeof labels[i]);
            snprintf(notes[i], sizeof notes[i], "-> %s", out[i].refused ? "refused" : out[i].answer);
            items[i] = (sp_sheet_item){.sketch = &ds.samples[i].sketch,
                                       .label = labels[i],
                                       .note = notes[i],
                                       .highlight = part ? out[i].refused || strcmp(out[i].answer, label) != 0 : !out[i].refused};
        }
        char title[256];
        snprintf(title, sizeof title, "%s half: red = a part refused or taken for another, or a doodle taken for a part", half);
        if (sp_sheet_write_png(items, ds.count, &(sp_sheet_desc){.cols = 10, .cell = 170, .title = title}, sheet, &err) != SP_OK)
            fprintf(stderr, "visitors: %s\n", err.text);
        free(items);
        free(notes);
        free(labels);
    }
    free(n);
    free(right);
    free(refused);
    free(wrong);
    free(top3);
    free(top1);
    free(out);
    free(ms_c);
    free(ms_t);
    sp_dragon_destroy(d);
    sp_dataset_free(&ds);
    remove_tmp_db(tmp, tmp_db);
    return 0;
}
