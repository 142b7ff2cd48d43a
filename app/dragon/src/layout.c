// layout.c: where a part goes: its zoomed sketch view on the canvas, the
// similarity that places it in the world, and its attachment to a body.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dragon_internal.h"

// World point of a joint-local offset of part p at its fitted pose.
static sp_vec3 fitted_point(const part* p, const sp_mat4* model_to_world, int joint, sp_vec3 local)
{
    tpl* t = p->t;
    sp_rig_eval_update(t->ev, p->p_fit, false);
    sp_vec3 m = sp_mat4_point(&sp_rig_eval_world(t->ev)[joint], local);
    return sp_mat4_point(model_to_world, m);
}

static bool socket_accepts(const dsocket* s, const char* category, const char* prefer)
{
    if (prefer[0] && !strcmp(s->name, prefer)) return true;
    if (!strcmp(s->name, category)) return true; // sockets named after what they take (assets/)
    if (!s->accepts[0]) return false;
    char key[SP_NAME_MAX + 2];
    snprintf(key, sizeof key, ",%s,", category);
    return strstr(s->accepts, key) != NULL;
}

// The part's sketch view zoomed and panned so its rest abstraction covers the stroke's box.
sp_camera dragon_zoomed_view(const tpl* t, sp_vec2 lo, sp_vec2 hi)
{
    sp_camera c = t->base;
    double ds = sp_v2_len(sp_v2_sub(hi, lo)), dr = sp_v2_len(sp_v2_sub(t->rest_hi, t->rest_lo));
    double f = ds / dr;
    sp_vec2 cs = sp_v2_scale(sp_v2_add(lo, hi), 0.5), cr = sp_v2_scale(sp_v2_add(t->rest_lo, t->rest_hi), 0.5);
    c.scale = t->base.scale * f;
    c.cx = cs.x - f * (cr.x - t->base.cx);
    c.cy = cs.y - f * (cr.y - t->base.cy);
    return c;
}

// Part model space -> world, making the part's view and the world camera agree (dragon.h).
sp_mat4 dragon_placement_of(const sp_dragon* d, const tpl* t, const sp_camera* view)
{
    const sp_camera* w = &d->world;
    double k = view->scale / w->scale;
    sp_mat4 a = sp_mat4_identity();
    a.m[0] = a.m[5] = a.m[10] = k;
    a.m[12] = (view->cx - w->cx) / w->scale;
    a.m[13] = (w->cy - view->cy) / w->scale;
    a.m[14] = -k * t->depth0;
    // World camera coordinates -> world (its view is a translation).
    sp_mat4 winv;
    sp_mat4_inverse(&w->view, &winv);
    sp_mat4 m = sp_mat4_mul(&a, &view->view);
    m = sp_mat4_mul(&winv, &m);
    return sp_sim3_mat4(sp_sim3_from_mat4(&m));
}

// Recomputes every attachment and the loop period (after any change).
void dragon_relayout(sp_dragon* d)
{
    double diag = hypot(d->desc.canvas_w, d->desc.canvas_h);
    d->period = 0;
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        p->world_fit = p->pub.placement;
        p->pub.attached_to = -1;
        p->pub.socket[0] = 0;
        p->pub.socket_joint = -1;
        if (p->t->clip) d->period = fmax(d->period, p->t->clip_len);
    }
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        if (p->t->is_torso) continue;
        sp_vec3 a = fitted_point(p, &p->pub.placement, p->t->attach_joint, p->t->attach_local);
        sp_vec2 a2 = sp_camera_project(&d->world, a);
        // Two rounds: sockets that want this part (by category or name), then any socket.
        for (int round = 0; round < 2 && p->pub.attached_to < 0; ++round) {
            double best = INFINITY;
            int bk = -1, bs = -1;
            sp_vec3 bpos = {0, 0, 0};
            for (int k = 0; k < d->part_n; ++k) {
                const part* q = d->parts[k];
                if (k == i || !q->t->is_torso) continue;
                for (int s = 0; s < q->t->socket_count; ++s) {
                    const dsocket* so = &q->t->sockets[s];
                    if (round == 0 && !socket_accepts(so, p->pub.category, p->t->prefer)) continue;
                    sp_vec3 w = fitted_point(q, &q->pub.placement, so->joint, so->local);
                    double dist = sp_v2_len(sp_v2_sub(sp_camera_project(&d->world, w), a2));
                    if (dist < best) best = dist, bk = k, bs = s, bpos = w;
                }
                if (q->t->socket_count == 0 && round == 1) {
                    // A torso without declared sockets: its root joint is the socket.
                    sp_vec3 w = fitted_point(q, &q->pub.placement, q->t->attach_joint, (sp_vec3){0, 0, 0});
                    double dist = sp_v2_len(sp_v2_sub(sp_camera_project(&d->world, w), a2));
                    if (dist < best) best = dist, bk = k, bs = -1, bpos = w;
                }
            }
            if (bk < 0) continue;
            const part* q = d->parts[bk];
            int joint = bs >= 0 ? q->t->sockets[bs].joint : q->t->attach_joint;
            sp_vec3 delta = sp_v3_sub(bpos, a);
            bool snap = d->desc.snap_fraction > 0 && best <= d->desc.snap_fraction * diag;
            if (!snap) delta.x = delta.y = 0;
            sp_mat4 tr = sp_mat4_translate(delta);
            p->world_fit = sp_mat4_mul(&tr, &p->pub.placement);
            sp_rig_eval_update(q->t->ev, q->p_fit, false);
            sp_mat4 f0 = sp_mat4_mul(&q->pub.placement, &sp_rig_eval_world(q->t->ev)[joint]);
            p->socket0 = sp_sim3_from_mat4(&f0);
            p->pub.attached_to = bk;
            p->pub.socket_joint = joint;
            dragon_copy_name(p->pub.socket, sizeof p->pub.socket,
                             bs >= 0 ? q->t->sockets[bs].name : q->t->ch.rig.joints[joint].name);
        }
    }
    d->posed = false;
}
