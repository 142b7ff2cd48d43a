// animate.c: each part's clip as offsets on its fitted parameters, and the
// whole dragon posed at a time (attached parts carried by their bodies).
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"
#include "sp/synth.h"

// The clip's parameters at clip time tc (into out), from the joints' local TRS.
static void clip_params(tpl* t, double tc, double* out)
{
    const sp_rig* rig = &t->ch.rig;
    for (int j = 0; j < rig->joint_count; ++j)
        t->tr[j] = rig->joints[j].rest_t, t->rot[j] = rig->joints[j].rest_r, t->sc[j] = rig->joints[j].rest_s;
    sp_animation_sample(t->clip, tc, t->tr, t->rot, t->sc);
    sp_rig_defaults(rig, out);
    for (int j = 0; j < rig->joint_count; ++j)
        if (rig->joints[j].param_count > 0) sp_rig_params_from_trs(rig, j, t->tr[j], t->rot[j], t->sc[j], out);
}

// Part p's parameters at dragon time t (see dragon.h: clip offsets on the fit).
static void animated_params(const sp_dragon* d, part* p, double t, double* out)
{
    tpl* tp = p->t;
    const sp_rig* rig = &tp->ch.rig;
    memcpy(out, p->p_fit, sizeof(double) * (size_t)rig->param_count);
    if (!tp->clip || !(d->period > 0)) return;
    double n = fmax(1.0, round(d->period / tp->clip_len));
    double per = d->period / n;
    double ph = fmod(t, per);
    if (ph < 0) ph += per;
    if (!(ph == ph)) ph = 0;
    double tc = tp->clip_start + ph / per * tp->clip_len;
    clip_params(tp, tc, tp->scratch_p);
    for (int k = 0; k < rig->param_count; ++k) {
        if (sp_channel_is_scale(rig->params[k].channel))
            out[k] *= tp->clip0[k] > 0 ? tp->scratch_p[k] / tp->clip0[k] : 1.0;
        else
            out[k] += tp->scratch_p[k] - tp->clip0[k];
    }
    sp_rig_clamp(rig, out);
}

// The world transform of part p at its current p_t (bodies must be posed
// first): an attached part follows its anchor, the body's skinned surface
// point, and turns and scales with its carrier (the blended skin matrix
// there, relative to the body's fit, as its nearest similarity).
static sp_mat4 part_world_at(const sp_dragon* d, const part* p)
{
    if (p->pub.attached_to < 0) return p->world_fit;
    const part* q = d->parts[p->pub.attached_to];
    const sp_rig* rig = &q->t->ch.rig;
    int rows[3] = {(int)p->tri[0], (int)p->tri[1], (int)p->tri[2]};
    double x[9];
    sp_rig_eval_rows(q->ev, sp_rig_mesh_points(rig), rows, 3, x);
    sp_vec3 s = {0, 0, 0};
    for (int c = 0; c < 3; ++c)
        s = sp_v3_add(s, sp_v3_scale((sp_vec3){x[3 * c], x[3 * c + 1], x[3 * c + 2]}, p->bary[c]));
    s = sp_mat4_point(&q->world_t, s);
    sp_mat4 m = dragon_carrier_matrix(p, sp_rig_eval_skin(q->ev), &q->world_t);
    sp_mat4 rel = sp_mat4_mul(&m, &p->carrier0_inv);
    sp_sim3 r = sp_sim3_from_mat4(&rel);
    // Pinned at the anchor: anchor0 goes exactly to where the surface point is now.
    r.t = sp_v3_sub(s, sp_v3_scale(sp_quat_rotate(r.r, p->anchor0), r.s));
    sp_mat4 f = sp_sim3_mat4(r);
    return sp_mat4_mul(&f, &p->world_fit);
}

void dragon_pose_parts(sp_dragon* d, double t)
{
    if (!isfinite(t)) t = 0;
    // Pass 0: parts that carry others (torsos) and free parts; pass 1: attached parts.
    for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < d->part_n; ++i) {
            part* p = d->parts[i];
            if ((p->pub.attached_to >= 0) != (pass == 1)) continue;
            const sp_rig* rig = &p->t->ch.rig;
            animated_params(d, p, t, p->p_t);
            sp_rig_eval_update(p->ev, p->p_t, false);
            sp_rig_eval_points(p->ev, sp_rig_mesh_points(rig), p->xyz);
            sp_rig_eval_abstraction(p->ev, &rig->abstractions[p->t->abstraction], p->xyz, p->outline);
            p->world_t = part_world_at(d, p);
        }
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        sp_mat4_points(&p->world_t, p->xyz, p->t->ch.rig.vertex_count);
        sp_mat4_points(&p->world_t, p->outline, p->t->ch.rig.abstractions[p->t->abstraction].point_count);
    }
}

void dragon_pose_shown(sp_dragon* d)
{
    // Posed means posed at shown_t with nothing changed since (a change,
    // the export and the report unpose).
    if (!d->posed) dragon_pose_parts(d, d->shown_t);
}

void dragon_pose(sp_dragon* d, double t)
{
    dragon_pose_parts(d, t);
    dragon_details_pose(d);
    d->posed = true;
}

sp_result sp_dragon_pose_at(sp_dragon* d, double t, sp_error* err)
{
    (void)err;
    d->shown_t = isfinite(t) ? t : 0;
    dragon_pose(d, d->shown_t);
    return SP_OK;
}

const double* sp_dragon_part_xyz(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? d->parts[i]->xyz : NULL;
}

const double* sp_dragon_part_outline(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? d->parts[i]->outline : NULL;
}

int sp_dragon_part_fitted_outline(const sp_dragon* d, int i, sp_vec2* xy)
{
    if (i < 0 || i >= d->part_n) return 0;
    const part* p = d->parts[i];
    const sp_rig* rig = &p->t->ch.rig;
    const sp_abstraction* ab = &rig->abstractions[p->t->abstraction];
    if (!xy) return ab->point_count;
    // In the part's own zoomed view, at the fit: exactly what the solver matched.
    double* tmp = malloc(sizeof(double) * 2 * ((size_t)ab->point_count + 1));
    if (!tmp || sp_abstraction_project(rig, p->t->abstraction, &p->pub.view, p->p_fit, tmp) != SP_OK) {
        free(tmp);
        return 0;
    }
    for (int k = 0; k < ab->point_count; ++k)
        xy[k] = (sp_vec2){tmp[2 * k], tmp[2 * k + 1]};
    free(tmp);
    return ab->point_count;
}

const double* sp_dragon_part_params(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? d->parts[i]->p_t : NULL;
}

const sp_mat4* sp_dragon_part_transform(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? &d->parts[i]->world_t : NULL;
}

bool sp_dragon_bounds(const sp_dragon* d, sp_vec3* lo, sp_vec3* hi)
{
    bool any = false;
    for (int i = 0; d->posed && i < d->part_n; ++i) {
        const part* p = d->parts[i];
        int n = p->t->ch.rig.vertex_count;
        if (n <= 0) continue;
        sp_vec3 a, b;
        sp_bounds(p->xyz, n, &a, &b);
        if (!any) *lo = a, *hi = b;
        lo->x = fmin(lo->x, a.x), lo->y = fmin(lo->y, a.y), lo->z = fmin(lo->z, a.z);
        hi->x = fmax(hi->x, b.x), hi->y = fmax(hi->y, b.y), hi->z = fmax(hi->z, b.z);
        any = true;
    }
    return any;
}
