// reach.c: a part drawn a little apart from a body, fitted again so that
// its attachment end meets the body (docs/DESIGN.md, "Which strokes join a
// dragon"). The solver matches outlines, not where a neck begins: a round
// head fits with its neck's end anywhere inside the drawing, often on the
// side away from the body. Held at the body, the rest of the pose takes
// the drawing as before.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"

// The solver moving what the part's own solver moves but the root's
// translation: made on first use (most templates never reach).
static bool pinned_solver(const sp_dragon* d, tpl* t, int tx, int ty)
{
    if (t->pinned) return true;
    const sp_rig* rig = &t->ch.rig;
    t->pinned_active = malloc(sizeof(bool) * ((size_t)rig->param_count + 1));
    if (!t->pinned_active) return false;
    for (int k = 0; k < rig->param_count; ++k)
        t->pinned_active[k] = (t->active ? t->active[k] : true) && k != tx && k != ty;
    sp_solve_desc sd = d->desc.solve;
    sd.active = t->pinned_active;
    sp_error err = {0};
    if (sp_solver_create(rig, t->abstraction, &t->solver_cam, &sd, &t->pinned, &err) != SP_OK) {
        free(t->pinned_active);
        t->pinned_active = NULL;
        return false;
    }
    return true;
}

// The attachment end at parameters p, in the solver's view (t->solver_cam).
static sp_vec2 end_in_view(tpl* t, const double* p)
{
    sp_rig_eval_update(t->ev, p, false);
    return sp_camera_project(&t->solver_cam, sp_mat4_point(&sp_rig_eval_world(t->ev)[t->attach_joint], t->attach_local));
}

// Sets the root's translation (params tx, ty) so that the attachment end
// lies at `target` in the solver's view: Newton steps on the 2x2 system
// (the translation moves the end almost linearly). False when the bounds
// keep the end from getting there.
static bool place_end(tpl* t, double* p, int tx, int ty, sp_vec2 target)
{
    const sp_param* par = t->ch.rig.params;
    for (int it = 0; it < 4; ++it) {
        sp_vec2 e = end_in_view(t, p);
        sp_vec2 r = sp_v2_sub(target, e);
        if (sp_v2_len(r) < 0.25) return true;
        double h[2] = {1e-4 * (par[tx].max - par[tx].min), 1e-4 * (par[ty].max - par[ty].min)};
        sp_vec2 col[2];
        int idx[2] = {tx, ty};
        for (int c = 0; c < 2; ++c) {
            double keep = p[idx[c]];
            p[idx[c]] = keep + h[c];
            col[c] = sp_v2_scale(sp_v2_sub(end_in_view(t, p), e), 1.0 / h[c]);
            p[idx[c]] = keep;
        }
        double det = col[0].x * col[1].y - col[1].x * col[0].y;
        if (!(fabs(det) > 1e-12)) return false;
        double dx = (r.x * col[1].y - col[1].x * r.y) / det, dy = (col[0].x * r.y - r.x * col[0].y) / det;
        p[tx] = fmin(fmax(p[tx] + dx, par[tx].min), par[tx].max);
        p[ty] = fmin(fmax(p[ty] + dy, par[ty].min), par[ty].max);
    }
    return sp_v2_len(sp_v2_sub(target, end_in_view(t, p))) < 0.25;
}

// The reaching fit is kept when its error (mean over the stroke's box
// diagonal, as the fit's score) is at most this many times the free fit's,
// or under REACH_FIT_OK: a neck bent to the body still has to look like the
// drawing.
#define REACH_FIT_WORSE 1.5
#define REACH_FIT_OK 0.01

bool dragon_fit_reaching(sp_dragon* d, part* p, sp_vec2 target)
{
    tpl* t = p->t;
    const sp_rig* rig = &t->ch.rig;
    int tx = -1, ty = -1;
    for (int k = 0; k < rig->param_count; ++k)
        if (rig->params[k].joint == t->attach_joint && rig->joints[t->attach_joint].parent < 0) {
            if (rig->params[k].channel == SP_CH_TX) tx = k;
            if (rig->params[k].channel == SP_CH_TY) ty = k;
        }
    // Only a root that carries the attachment end can hold it in place.
    if (tx < 0 || ty < 0 || p->stroke_n < 2 || !pinned_solver(d, t, tx, ty)) return false;
    sp_vec2 lo = {p->stroke_box[0], p->stroke_box[1]}, hi = {p->stroke_box[2], p->stroke_box[3]};
    double u = 0.5 * (lo.x + hi.x);
    int n = p->stroke_n;
    sp_vec2* pts = malloc(sizeof(sp_vec2) * (size_t)n);
    double* q = malloc(sizeof(double) * ((size_t)rig->param_count + 1));
    bool kept = false;
    if (!pts || !q) goto done;
    // The fit's own frame: a mirrored part was fitted to its stroke mirrored
    // about the box's centre (stroke.c, fit_one).
    for (int i = 0; i < n; ++i)
        pts[i] = p->pub.mirrored ? (sp_vec2){2 * u - p->stroke[i].x, p->stroke[i].y} : p->stroke[i];
    if (p->pub.mirrored) target.x = 2 * u - target.x;
    t->solver_cam = dragon_zoomed_view(t, lo, hi);
    memcpy(q, p->p_fit, sizeof(double) * (size_t)rig->param_count);
    if (!place_end(t, q, tx, ty, target)) goto done;
    sp_sketch sk = {.canvas_w = d->desc.canvas_w,
                    .canvas_h = d->desc.canvas_h,
                    .stroke_count = 1,
                    .strokes = &(sp_stroke){.count = n, .points = pts}};
    sp_solve_report rep;
    sp_error err = {0};
    if (sp_solver_solve(t->pinned, &sk, q, q, &rep, &err) != SP_OK) goto done;
    if (t->twins) dragon_limb_follow(t, q); // as every fit of legs by one leg's line
    for (int k = 0; k < rig->param_count; ++k)
        if (!isfinite(q[k])) goto done;
    double before = p->pub.report.mean_error_px / fmax(p->pub.report.bbox_diagonal_px, 1.0);
    double after = rep.mean_error_px / fmax(rep.bbox_diagonal_px, 1.0);
    if (!isfinite(after) || !(after <= fmax(REACH_FIT_WORSE * before, REACH_FIT_OK))) goto done;
    if (!(sp_v2_len(sp_v2_sub(target, end_in_view(t, q))) < 1.0)) goto done;
    memcpy(p->p_fit, q, sizeof(double) * (size_t)rig->param_count);
    p->pub.report = rep;
    kept = true;
done:
    free(pts);
    free(q);
    return kept;
}
