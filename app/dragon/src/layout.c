// layout.c: where a part goes: its zoomed sketch view on the canvas, the
// similarity that places it in the world, and its attachment to a body at
// the point of the body's surface, in the view, nearest to where it was
// drawn (sp/dragon.h, "Attachment").
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"
#include "sp/outline.h"

// Pixels within which two candidate surface points count as equally near
// the attachment end (the near and the far side of a silhouette edge).
#define SAME_DISTANCE_PX 0.5
// Two parts of a kind whose anchors are closer than this fraction of the
// smaller one's stroke (its box's diagonal) are "at the same place": the
// second goes on the body's other side.
#define SAME_PLACE 0.15

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

sp_camera dragon_mirrored_view(const sp_camera* view, double u)
{
    // Turned half round the view's vertical axis (a rotation, not a
    // reflection: the placement stays a similarity), then shifted so that
    // camera x lands at 2u - (what it was).
    sp_mat4 ry = sp_mat4_identity();
    ry.m[0] = ry.m[10] = -1;
    sp_camera c = *view;
    c.view = sp_mat4_mul(&ry, &view->view);
    c.cx = 2 * u - view->cx;
    return c;
}

// Part model space -> world, making the part's view and the world camera agree (sp/dragon.h).
sp_mat4 dragon_placement_of(const sp_dragon* d, const tpl* t, const sp_camera* view)
{
    const sp_camera* w = &d->world;
    double k = view->scale / w->scale;
    sp_mat4 a = sp_mat4_identity();
    a.m[0] = a.m[5] = a.m[10] = k;
    a.m[12] = (view->cx - w->cx) / w->scale;
    a.m[13] = (w->cy - view->cy) / w->scale;
    // The rest centre goes to world depth 0: the depth of the world's origin in its camera.
    a.m[14] = -k * sp_mat4_point(&view->view, t->centre0).z + w->view.m[14];
    // World camera coordinates -> world (its view is a translation).
    sp_mat4 winv;
    sp_mat4_inverse(&w->view, &winv);
    sp_mat4 m = sp_mat4_mul(&a, &view->view);
    m = sp_mat4_mul(&winv, &m);
    return sp_sim3_mat4(sp_sim3_from_mat4(&m));
}

// ---- bodies as seen on the canvas ------------------------------------------------------

// Part q's mesh at its fit moved by m into the world (xyz: vertex_count by
// 3) and seen on the canvas (px). With ring_xyz (point_count by 3 of its
// abstraction), the abstraction too, into ring_xyz and seen in ring.
static void mesh_on_canvas(const sp_dragon* d, const part* q, const sp_mat4* m, double* xyz, sp_vec2* px, double* ring_xyz,
                           sp_vec2* ring)
{
    const sp_rig* rig = &q->t->ch.rig;
    const sp_abstraction* ab = &rig->abstractions[q->t->abstraction];
    sp_rig_eval_update(q->t->ev, q->p_fit, false);
    sp_rig_eval_points(q->t->ev, sp_rig_mesh_points(rig), xyz);
    // Before the move: an abstraction embedded in the mesh reads its model-space vertices.
    if (ring_xyz) sp_rig_eval_abstraction(q->t->ev, ab, xyz, ring_xyz);
    sp_mat4_points(m, xyz, rig->vertex_count);
    for (int v = 0; v < rig->vertex_count; ++v)
        px[v] = sp_camera_project(&d->world, (sp_vec3){xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]});
    if (!ring_xyz) return;
    sp_mat4_points(m, ring_xyz, ab->point_count);
    for (int k = 0; k < ab->point_count; ++k)
        ring[k] = sp_camera_project(&d->world, (sp_vec3){ring_xyz[3 * k], ring_xyz[3 * k + 1], ring_xyz[3 * k + 2]});
}

static bool px_box(const sp_vec2* px, int n, sp_vec2* lo, sp_vec2* hi);

// A body's vertices at its fit, in the world and on the canvas, and the
// area of its surface (kept: a body's fit never changes).
static bool body_prepare(const sp_dragon* d, part* q)
{
    if (q->body_px) return true;
    const sp_rig* rig = &q->t->ch.rig;
    size_t n = (size_t)rig->vertex_count;
    const sp_abstraction* ab = &rig->abstractions[q->t->abstraction];
    bool ring = ab->curve_count == 1 && ab->curves[0].closed && ab->point_count >= 3;
    size_t nr = ring ? (size_t)ab->point_count : 0;
    q->body_xyz = malloc(sizeof(double) * 3 * (n + 1));
    q->body_px = malloc(sizeof(sp_vec2) * (n + 1));
    q->body_tri_box = malloc(sizeof(double) * 4 * ((size_t)rig->triangle_count + 1));
    q->body_ring = ring ? malloc(sizeof(sp_vec2) * nr) : NULL;
    double* ring_xyz = ring ? malloc(sizeof(double) * 3 * nr) : NULL;
    if (!q->body_xyz || !q->body_px || !q->body_tri_box || (ring && (!q->body_ring || !ring_xyz))) {
        free(q->body_xyz), free(q->body_px), free(q->body_tri_box), free(q->body_ring), free(ring_xyz);
        q->body_xyz = NULL, q->body_px = NULL, q->body_tri_box = NULL, q->body_ring = NULL;
        return false;
    }
    mesh_on_canvas(d, q, &q->pub.placement, q->body_xyz, q->body_px, ring_xyz, q->body_ring);
    free(ring_xyz);
    q->body_ring_n = (int)nr;
    sp_vec2 rlo, rhi;
    q->body_ring_size = px_box(q->body_ring, q->body_ring_n, &rlo, &rhi) ? sp_v2_len(sp_v2_sub(rhi, rlo)) : NAN;
    // Boxes kept for nearest_surface, which every part laid out asks of
    // every body near it (a new body lays out them all again).
    for (int f = 0; f < rig->triangle_count; ++f) {
        const uint32_t* tr = rig->triangles + 3 * f;
        sp_vec2 a = q->body_px[tr[0]], b = q->body_px[tr[1]], c = q->body_px[tr[2]];
        double* box = q->body_tri_box + 4 * (size_t)f;
        box[0] = fmin(a.x, fmin(b.x, c.x)), box[1] = fmin(a.y, fmin(b.y, c.y));
        box[2] = fmax(a.x, fmax(b.x, c.x)), box[3] = fmax(a.y, fmax(b.y, c.y));
    }
    if (!px_box(q->body_px, (int)n, &q->body_lo, &q->body_hi)) q->body_lo = q->body_hi = (sp_vec2){NAN, NAN};
    // Its surface: the triangles' area in the world. None (every triangle of
    // zero area, or nothing finite) means there is nothing to hold a part.
    double area = 0;
    for (int f = 0; f < rig->triangle_count; ++f) {
        const uint32_t* tr = rig->triangles + 3 * f;
        const double *a = q->body_xyz + 3 * tr[0], *b = q->body_xyz + 3 * tr[1], *c = q->body_xyz + 3 * tr[2];
        sp_vec3 e1 = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2 = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double fa = 0.5 * sp_v3_len(sp_v3_cross(e1, e2));
        if (isfinite(fa)) area += fa;
    }
    sp_vec3 lo, hi;
    sp_bounds(q->body_xyz, (int)n, &lo, &hi);
    double size = sp_v3_len(sp_v3_sub(hi, lo));
    q->body_has_surface = isfinite(size) && size > 0 && area > 1e-9 * size * size;
    return true;
}

// The point of triangle (a, b, c) nearest p, all on the canvas, with its
// barycentric coordinates (Ericson's regions; a degenerate triangle is its
// longest edge).
static sp_vec2 closest_on_triangle(sp_vec2 p, sp_vec2 a, sp_vec2 b, sp_vec2 c, double bary[3])
{
    sp_vec2 ab = sp_v2_sub(b, a), ac = sp_v2_sub(c, a), ap = sp_v2_sub(p, a);
    double area2 = ab.x * ac.y - ab.y * ac.x;
    if (fabs(area2) <= 1e-12 * (sp_v2_dot(ab, ab) + sp_v2_dot(ac, ac))) {
        // No interior: the nearest of the three edges.
        sp_vec2 v[3] = {a, b, c};
        double best = INFINITY;
        sp_vec2 out = a;
        for (int e = 0; e < 3; ++e) {
            sp_vec2 s = v[e], t = v[(e + 1) % 3], st = sp_v2_sub(t, s);
            double len2 = sp_v2_dot(st, st);
            double u = len2 > 0 ? fmin(fmax(sp_v2_dot(sp_v2_sub(p, s), st) / len2, 0.0), 1.0) : 0.0;
            sp_vec2 q = sp_v2_add(s, sp_v2_scale(st, u));
            double dd = sp_v2_len(sp_v2_sub(p, q));
            if (dd < best) {
                best = dd, out = q;
                bary[e] = 1 - u, bary[(e + 1) % 3] = u, bary[(e + 2) % 3] = 0;
            }
        }
        return out;
    }
    double d1 = sp_v2_dot(ab, ap), d2 = sp_v2_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return bary[0] = 1, bary[1] = bary[2] = 0, a;
    sp_vec2 bp = sp_v2_sub(p, b);
    double d3 = sp_v2_dot(ab, bp), d4 = sp_v2_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return bary[1] = 1, bary[0] = bary[2] = 0, b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        bary[0] = 1 - v, bary[1] = v, bary[2] = 0;
        return sp_v2_add(a, sp_v2_scale(ab, v));
    }
    sp_vec2 cp = sp_v2_sub(p, c);
    double d5 = sp_v2_dot(ab, cp), d6 = sp_v2_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return bary[2] = 1, bary[0] = bary[1] = 0, c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        bary[0] = 1 - w, bary[1] = 0, bary[2] = w;
        return sp_v2_add(a, sp_v2_scale(ac, w));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        bary[0] = 0, bary[1] = 1 - w, bary[2] = w;
        return sp_v2_add(b, sp_v2_scale(sp_v2_sub(c, b), w));
    }
    double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
    bary[0] = 1 - v - w, bary[1] = v, bary[2] = w;
    return sp_v2_add(a, sp_v2_add(sp_v2_scale(ab, v), sp_v2_scale(ac, w)));
}

// The body's surface nearest a canvas point, in the view.
typedef struct surface_hit {
    double dist;       // pixels from the query point
    sp_vec2 px;        // the nearest point of the body's projected mesh
    int tri[2];        // [0] the near side (towards the viewer), [1] the far side
    double bary[2][3]; // the surface point's barycentric coordinates in tri
    double z[2];       // its world depth
} surface_hit;

// Distance from p to the box [lo, hi] (0 inside).
static double box_distance(sp_vec2 p, sp_vec2 lo, sp_vec2 hi)
{
    double dx = fmax(fmax(lo.x - p.x, p.x - hi.x), 0.0), dy = fmax(fmax(lo.y - p.y, p.y - hi.y), 0.0);
    return hypot(dx, dy);
}

// Two passes over the body's triangles: the nearest distance, then among
// the points that near (a point inside the silhouette is covered by a front
// and a back triangle; a silhouette edge by the triangles meeting there) the
// nearest to the viewer and the farthest. False when no point of the body
// lies within `within` pixels (INFINITY: anywhere).
static bool nearest_surface(const part* q, sp_vec2 p, double within, surface_hit* h)
{
    const sp_rig* rig = &q->t->ch.rig;
    const sp_vec2* px = q->body_px;
    double best = INFINITY;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) {
            if (!isfinite(best) || !(best <= within)) return false;
            h->dist = best;
            h->tri[0] = h->tri[1] = -1;
            h->z[0] = -INFINITY, h->z[1] = INFINITY;
        }
        double limit = pass == 0 ? INFINITY : best + SAME_DISTANCE_PX;
        for (int f = 0; f < rig->triangle_count; ++f) {
            const uint32_t* tr = rig->triangles + 3 * f;
            const double* box = q->body_tri_box + 4 * (size_t)f;
            double bx = fmax(fmax(box[0] - p.x, p.x - box[2]), 0.0), by = fmax(fmax(box[1] - p.y, p.y - box[3]), 0.0);
            double cut = pass == 0 ? fmin(best, within) : limit;
            if (!(bx * bx + by * by <= cut * cut)) continue; // also skips non-finite corners
            sp_vec2 a = px[tr[0]], b = px[tr[1]], c = px[tr[2]];
            double bary[3];
            sp_vec2 cp = closest_on_triangle(p, a, b, c, bary);
            double dist = sp_v2_len(sp_v2_sub(p, cp));
            if (pass == 0) {
                if (dist < best) best = dist, h->px = cp;
                continue;
            }
            if (!(dist <= limit)) continue;
            double z = 0;
            for (int k = 0; k < 3; ++k)
                z += bary[k] * q->body_xyz[3 * tr[k] + 2];
            for (int side = 0; side < 2; ++side)
                if (side == 0 ? z > h->z[0] : z < h->z[1]) {
                    h->z[side] = z, h->tri[side] = f;
                    memcpy(h->bary[side], bary, sizeof bary);
                }
        }
    }
    return h->tri[0] >= 0;
}

// The point of body q's outline (body_ring) nearest p; *inside: p lies within it.
static sp_vec2 ring_nearest(const part* q, sp_vec2 p, bool* inside)
{
    const sp_vec2* r = q->body_ring;
    int n = q->body_ring_n;
    sp_vec2 best = r[0];
    double bd = INFINITY;
    bool in = false;
    for (int k = 0, j = n - 1; k < n; j = k++) {
        sp_vec2 c = dragon_segment_nearest(p, r[j], r[k]);
        double dd = sp_v2_len(sp_v2_sub(c, p));
        if (dd < bd) bd = dd, best = c;
        if ((r[k].y > p.y) != (r[j].y > p.y) && p.x < r[j].x + (p.y - r[j].y) * (r[k].x - r[j].x) / (r[k].y - r[j].y)) in = !in;
    }
    *inside = in;
    return best;
}

// A point of the mesh farther than this fraction of the outline's size
// outside it is a spike's or a crest's: no drawing of the body shows it.
#define BEYOND_OUTLINE 0.02

// Where on body q a part goes, given the mesh's point nearest its end (*h):
// a spike or a crest is not where a drawing shows the body (wings on a
// spike's tip hover above the back), so such a point becomes the surface
// at the outline's point nearest it, the spike's foot. h->dist stays the
// distance to the mesh (what the snap measures).
static void onto_outline(const part* q, surface_hit* h)
{
    if (!q->body_ring) return;
    bool in;
    sp_vec2 r = ring_nearest(q, h->px, &in);
    if (in || !(sp_v2_len(sp_v2_sub(r, h->px)) > BEYOND_OUTLINE * q->body_ring_size)) return;
    surface_hit s;
    if (!nearest_surface(q, r, INFINITY, &s)) return;
    s.dist = h->dist;
    *h = s;
}

// ---- attaching -------------------------------------------------------------------------

// The body's socket for this part (its category's, or the one the part
// prefers), nearest the anchor: a hint of the side the part goes on.
static const dsocket* socket_hint(const part* q, const part* p, sp_vec3 anchor, sp_vec3* where)
{
    const dsocket* best = NULL;
    double bd = INFINITY;
    for (int s = 0; s < q->t->socket_count; ++s) {
        const dsocket* so = &q->t->sockets[s];
        if (!socket_accepts(so, p->pub.category, p->t->prefer)) continue;
        sp_vec3 w = fitted_point(q, &q->pub.placement, so->joint, so->local);
        double dd = sp_v3_len(sp_v3_sub(w, anchor));
        if (dd < bd) bd = dd, best = so, *where = w;
    }
    return best;
}

sp_mat4 dragon_blended_skin(const int* joints, const double* w, int n, const sp_mat4* skin, const sp_mat4* world)
{
    sp_mat4 m = {{0}};
    for (int e = 0; e < n; ++e)
        for (int c = 0; c < 16; ++c)
            m.m[c] += w[e] * skin[joints[e]].m[c];
    return sp_mat4_mul(world, &m);
}

sp_mat4 dragon_carrier_matrix(const part* p, const sp_mat4* skin, const sp_mat4* body_world)
{
    return dragon_blended_skin(p->carrier_joint, p->carrier_w, p->carrier_n, skin, body_world);
}

// Attaches part i to body k at the surface point h: moves it there, and
// records the body's joints that skin that point (its carrier).
static void attach(sp_dragon* d, int i, int k, const surface_hit* h, sp_vec3 a)
{
    part* p = d->parts[i];
    part* q = d->parts[k];
    const sp_rig* rig = &q->t->ch.rig;
    // Near or far: the socket says which side the first part of its kind
    // goes on (its depth against the body's middle); a part of the same
    // kind already at the same place sends the next one to the other side.
    sp_vec3 sw = {0, 0, 0};
    const dsocket* so = socket_hint(q, p, a, &sw);
    bool far = false;
    if (so) {
        sp_vec3 lo, hi;
        sp_bounds(q->body_xyz, rig->vertex_count, &lo, &hi);
        far = sw.z < 0.5 * (lo.z + hi.z) - 1e-6 * sp_v3_len(sp_v3_sub(hi, lo));
    }
    sp_vec2 here = h->px;
    for (int j = 0; j < i; ++j) {
        const part* o = d->parts[j];
        double size = fmin(hypot(o->stroke_box[2] - o->stroke_box[0], o->stroke_box[3] - o->stroke_box[1]),
                           hypot(p->stroke_box[2] - p->stroke_box[0], p->stroke_box[3] - p->stroke_box[1]));
        if (o->pub.attached_to == k && !strcmp(o->pub.category, p->pub.category) &&
            sp_v2_len(sp_v2_sub(o->pub.anchor, here)) < SAME_PLACE * size)
            far = !far;
    }
    int side = far ? 1 : 0;
    const uint32_t* tr = rig->triangles + 3 * h->tri[side];
    sp_vec3 s = {0, 0, 0};
    for (int c = 0; c < 3; ++c)
        s = sp_v3_add(s, sp_v3_scale((sp_vec3){q->body_xyz[3 * tr[c]], q->body_xyz[3 * tr[c] + 1], q->body_xyz[3 * tr[c] + 2]},
                                     h->bary[side][c]));
    sp_mat4 move = sp_mat4_translate(sp_v3_sub(s, a));
    p->world_fit = sp_mat4_mul(&move, &p->pub.placement);
    // The carrier: the three corners' skin weights blended by the point's
    // barycentric coordinates.
    p->carrier_n = 0;
    for (int c = 0; c < 3; ++c)
        for (int m = 0; m < 4; ++m) {
            double w = h->bary[side][c] * rig->weights4[4 * tr[c] + m];
            int j = rig->joints4[4 * tr[c] + m];
            if (!(w > 0)) continue;
            int e = 0;
            while (e < p->carrier_n && p->carrier_joint[e] != j)
                ++e;
            if (e == p->carrier_n) { // at most 3 corners x 4 weights = CARRIER_MAX joints
                p->carrier_joint[e] = j, p->carrier_w[e] = 0, ++p->carrier_n;
            }
            p->carrier_w[e] += w;
        }
    double sum = 0;
    int strongest = 0;
    for (int e = 0; e < p->carrier_n; ++e) {
        sum += p->carrier_w[e];
        if (p->carrier_w[e] > p->carrier_w[strongest]) strongest = e;
    }
    for (int e = 0; e < p->carrier_n; ++e)
        p->carrier_w[e] /= sum > 0 ? sum : 1;
    if (p->carrier_n == 0) p->carrier_joint[0] = q->t->attach_joint, p->carrier_w[0] = 1, p->carrier_n = 1;
    sp_rig_eval_update(q->t->ev, q->p_fit, false);
    sp_mat4 m0 = dragon_carrier_matrix(p, sp_rig_eval_skin(q->t->ev), &q->pub.placement);
    sp_mat4_inverse(&m0, &p->carrier0_inv);
    memcpy(p->tri, tr, sizeof p->tri);
    memcpy(p->bary, h->bary[side], sizeof p->bary);
    p->anchor0 = s;
    p->pub.attached_to = k;
    p->pub.far_side = far;
    p->pub.anchor = sp_camera_project(&d->world, s);
    p->pub.carrier_joint = p->carrier_joint[strongest];
    dragon_copy_name(p->pub.socket, sizeof p->pub.socket, so ? so->name : "");
}

// The box of n canvas points; false when there are none.
static bool px_box(const sp_vec2* px, int n, sp_vec2* lo, sp_vec2* hi)
{
    if (n <= 0) return false;
    *lo = *hi = px[0];
    for (int v = 1; v < n; ++v)
        lo->x = fmin(lo->x, px[v].x), lo->y = fmin(lo->y, px[v].y), hi->x = fmax(hi->x, px[v].x), hi->y = fmax(hi->y, px[v].y);
    return true;
}

// The body's box on the canvas at its fit (body_prepare'd); false without vertices.
static bool body_box(const part* q, sp_vec2* lo, sp_vec2* hi)
{
    return px_box(q->body_px, q->t->ch.rig.vertex_count, lo, hi);
}

// Whether the boxes [lo, hi] and [a, b] overlap (touching counts).
static bool boxes_overlap(sp_vec2 lo, sp_vec2 hi, sp_vec2 a, sp_vec2 b)
{
    return lo.x <= b.x && a.x <= hi.x && lo.y <= b.y && a.y <= hi.y;
}

// The snap distance on the canvas: a part's attachment end within it of a body attaches.
static double snap_px(const sp_dragon* d)
{
    return d->desc.snap_fraction > 0 ? d->desc.snap_fraction * hypot(d->desc.canvas_w, d->desc.canvas_h) : 0;
}

// Whether the stroke's box [lo, hi] lies on or near a body's box [a, b]:
// within the snap distance, so that a part drawn there would attach.
static bool near_body_box(const sp_dragon* d, sp_vec2 lo, sp_vec2 hi, sp_vec2 a, sp_vec2 b)
{
    double g = snap_px(d);
    return boxes_overlap(lo, hi, (sp_vec2){a.x - g, a.y - g}, (sp_vec2){b.x + g, b.y + g});
}

// Body q's first socket for a part of this category (or preferring it), or NULL.
static const dsocket* kind_socket(const part* q, const char* category, const char* prefer)
{
    for (int s = 0; s < q->t->socket_count; ++s)
        if (socket_accepts(&q->t->sockets[s], category, prefer)) return &q->t->sockets[s];
    return NULL;
}

// Canvas x of body q's socket, less the body's middle.
static double socket_u(const sp_dragon* d, const part* q, const dsocket* so, double mid)
{
    return sp_camera_project(&d->world, fitted_point(q, &q->pub.placement, so->joint, so->local)).x - mid;
}

// Which way the dragon of body k faces: 1 mirrored, 0 as modelled, -1 not
// told. A head or tail drawn at the end of the body other than its socket's
// says the dragon is drawn mirrored; one over the middle says nothing, and
// two that disagree tell nothing. Where it is drawn is its stroke's box, not
// where it hangs: a long neck, a body rising to one end or a spike's foot
// puts the anchor near the middle.
static int body_facing(sp_dragon* d, int k)
{
    part* q = d->parts[k];
    sp_vec2 blo, bhi;
    if (!body_prepare(d, q) || !body_box(q, &blo, &bhi)) return -1;
    double mid = 0.5 * (blo.x + bhi.x), half = 0.5 * (bhi.x - blo.x);
    int mirrored = -1;
    for (int j = 0; j < d->part_n; ++j) {
        const part* o = d->parts[j];
        if (o->pub.attached_to != k || !o->t->lengthwise) continue;
        const dsocket* so = kind_socket(q, o->pub.category, o->t->prefer);
        if (!so) continue;
        double su = socket_u(d, q, so, mid), du = 0.5 * (o->stroke_box[0] + o->stroke_box[2]) - mid;
        if (!(fabs(su) > 0.25 * half && fabs(du) > 0.25 * half)) continue;
        int m = (su > 0) != (du > 0);
        if (mirrored >= 0 && m != mirrored) return -1;
        mirrored = m;
    }
    return mirrored;
}

bool dragon_family_member(sp_dragon* d, int i, char out[SP_NAME_MAX])
{
    const part* p = d->parts[i];
    int k = p->pub.attached_to;
    if (!p->t->family[0] || k < 0) return false;
    part* q = d->parts[k];
    sp_vec2 blo, bhi;
    if (!body_box(q, &blo, &bhi)) return false;
    double mid = 0.5 * (blo.x + bhi.x);
    int mirrored = body_facing(d, k);
    if (mirrored < 0) return false;
    double u = (mirrored ? -1 : 1) * (p->pub.anchor.x - mid);
    // The family's sockets along the body, centred on its middle: the
    // visitor's body is a blob without the model's neck, so with two
    // members the body's middle divides them (BENCHMARKS.md, "Eighth pass").
    enum { MEMBERS_MAX = 16 };
    double su[MEMBERS_MAX], mean = 0;
    int idx[MEMBERS_MAX], members = 0;
    for (int s = 0; s < q->t->socket_count && members < MEMBERS_MAX; ++s) {
        const dsocket* so = &q->t->sockets[s];
        const tpl* kin = dragon_category_first(d, so->name);
        if (!kin || strcmp(kin->family, p->t->family) != 0) continue;
        su[members] = socket_u(d, q, so, mid);
        mean += su[members];
        idx[members++] = s;
    }
    if (members < 2) return false;
    mean /= members;
    const char* best = NULL;
    double bd = INFINITY;
    for (int m = 0; m < members; ++m) {
        double dd = fabs(su[m] - mean - u);
        if (dd < bd) bd = dd, best = q->t->sockets[idx[m]].name;
    }
    if (!best) return false;
    dragon_copy_name(out, SP_NAME_MAX, best);
    return true;
}

// "Clearly smaller" for dragon_drawn_on_body: the stroke's box diagonal
// against the body's. A second body drawn over the first is about as large
// (a bigger dragon); a head, tail or wing drawn on a body is smaller.
#define ON_BODY_SIZE 0.75

bool dragon_on_body(sp_dragon* d, sp_vec2 lo, sp_vec2 hi, int k)
{
    part* q = d->parts[k];
    sp_vec2 a, b;
    if (!q->t->is_torso || !body_prepare(d, q) || !body_box(q, &a, &b)) return false;
    // Near counts as on: a part drawn within the snap distance of a body
    // attaches to it, so a small shape drawn there is meant for that dragon.
    // Its size against the body as drawn too: a fit that took only part of a
    // child's body (a dolphin's outline without its fin) made a wing drawn
    // on its back as large as the fit, and that wing a second body (an
    // outside review).
    double body =
        fmax(hypot(b.x - a.x, b.y - a.y), hypot(q->stroke_box[2] - q->stroke_box[0], q->stroke_box[3] - q->stroke_box[1]));
    return near_body_box(d, lo, hi, a, b) && hypot(hi.x - lo.x, hi.y - lo.y) <= ON_BODY_SIZE * body;
}

bool dragon_drawn_on_body(sp_dragon* d, sp_vec2 lo, sp_vec2 hi, int skip)
{
    for (int k = 0; k < d->part_n; ++k)
        if (k != skip && dragon_on_body(d, lo, hi, k)) return true;
    return false;
}

// A stroke at most this fraction of a part's size (box diagonals on the
// canvas) lying on that part is a detail of it: an eye on a head, spots on
// a body. Larger, it is a part drawn over another: the visitors' parts
// drawn on a body at 0.3 of the on-body bench's size (legs, tails and wings
// 78 px against a body of 500) stay parts; smaller, some lie on the body's
// stubs and spikes and become details (BENCHMARKS.md, "Sixteenth pass").
#define DETAIL_SIZE 0.12
// The share of the stroke's points that must lie on the part.
#define DETAIL_ON 0.9
// How near the part's mesh a point counts as on it: the smaller of these
// fractions of the part's box diagonal and the stroke's (a child's eye on a
// thin snout runs over its edge; a small part drawn at a body's edge
// reaches beyond it).
#define DETAIL_NEAR 0.04
#define DETAIL_NEAR_OWN 0.3
// The stroke's points tested (evenly by index), enough to tell on from off.
#define DETAIL_SAMPLES 32

// A part's projected mesh (px: its vertices on the canvas) rasterised over
// the window of w x h pixels whose corner is o (sp_raster_triangle: a cell
// is covered when its centre lies in a triangle). One pass over the
// triangles serves all of a stroke's points.
static void cover(const sp_rig* rig, const sp_vec2* px, sp_vec2 o, int w, int h, unsigned char* cells)
{
    for (int f = 0; f < rig->triangle_count; ++f) {
        const uint32_t* tr = rig->triangles + 3 * f;
        double c[3][2];
        for (int k = 0; k < 3; ++k)
            c[k][0] = px[tr[k]].x - o.x, c[k][1] = px[tr[k]].y - o.y;
        sp_raster_triangle(cells, w, h, c[0], c[1], c[2]);
    }
}

// Whether a covered cell's centre lies within r pixels of canvas point p.
static bool covered_near(const unsigned char* cells, int w, int h, sp_vec2 o, sp_vec2 p, double r)
{
    double cx = p.x - o.x - 0.5, cy = p.y - o.y - 0.5;
    int x0 = (int)fmax(0, ceil(cx - r)), x1 = (int)fmin(w - 1, floor(cx + r));
    int y0 = (int)fmax(0, ceil(cy - r)), y1 = (int)fmin(h - 1, floor(cy + r));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            if (cells[(size_t)y * w + x] && (x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r) return true;
    return false;
}

void dragon_detail_hit_free(detail_hit* hit)
{
    free(hit->xyz), free(hit->px);
    hit->xyz = NULL, hit->px = NULL;
}

// Part k's mesh as shown (posed by dragon_pose_shown at d->shown_t: a
// clip's pose there is not the fit), in the world and on the canvas (*xyz,
// *px: malloc'd, vertex_count each), and its box there [a, b], when its
// stroke's box, grown as below, overlaps the stroke's box [lo, hi]. 0: not
// near it (or no mesh); -1: out of memory.
static int part_near_stroke(sp_dragon* d, int k, sp_vec2 lo, sp_vec2 hi, double** xyz, sp_vec2** px, sp_vec2* a, sp_vec2* b)
{
    const part* q = d->parts[k];
    // Its stroke's box first (cheap): a part is shown about where it was
    // drawn (its fit reaching a little beyond the stroke, its horns and
    // spikes too), moved at most by the snap distance when it attaches.
    double qd = hypot(q->stroke_box[2] - q->stroke_box[0], q->stroke_box[3] - q->stroke_box[1]), g = snap_px(d) + 0.25 * qd;
    sp_vec2 qlo = {q->stroke_box[0] - g, q->stroke_box[1] - g}, qhi = {q->stroke_box[2] + g, q->stroke_box[3] + g};
    const sp_rig* rig = &q->t->ch.rig;
    int nv = rig->vertex_count;
    *xyz = NULL, *px = NULL;
    if (!boxes_overlap(lo, hi, qlo, qhi) || nv <= 0 || rig->triangle_count <= 0) return 0;
    *xyz = malloc(sizeof(double) * 3 * (size_t)nv);
    *px = malloc(sizeof(sp_vec2) * (size_t)nv);
    if (!*xyz || !*px) {
        free(*xyz), free(*px);
        *xyz = NULL, *px = NULL;
        return -1;
    }
    memcpy(*xyz, q->xyz, sizeof(double) * 3 * (size_t)nv);
    for (int v = 0; v < nv; ++v)
        (*px)[v] = sp_camera_project(&d->world, (sp_vec3){q->xyz[3 * v], q->xyz[3 * v + 1], q->xyz[3 * v + 2]});
    px_box(*px, nv, a, b);
    return 1;
}

// A speck (a stroke too small to become a part) needs only this share of
// its points on a part: a spot drawn at a thin tail's edge lies half off it.
#define SPECK_ON 0.5

// dragon_detail_of with `on`, the share of points that must lie on the
// part, `size`, the stroke's largest size (box diagonals, a fraction of the
// part's mesh on the canvas), and what becomes of the points off it.
static int detail_with(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, double on, double size,
                       double near_part, detail_air air, detail_hit* hit)
{
    double diag = hypot(hi.x - lo.x, hi.y - lo.y);
    dragon_pose_shown(d);                      // for part_near_stroke
    for (int k = d->part_n - 1; k >= 0; --k) { // the part drawn last lies on top
        part* q = d->parts[k];
        double qd = hypot(q->stroke_box[2] - q->stroke_box[0], q->stroke_box[3] - q->stroke_box[1]);
        if (k == skip || n < 2 || !(diag <= 2 * size * qd)) continue;
        const sp_rig* rig = &q->t->ch.rig;
        double* xyz;
        sp_vec2 *px, a, b;
        int got = part_near_stroke(d, k, lo, hi, &xyz, &px, &a, &b);
        if (got < 0) return -1; // out of memory: not a detail, the stroke goes on as a part
        if (got == 0) continue;
        int m = n < DETAIL_SAMPLES ? n : DETAIL_SAMPLES, off = 0;
        double near = fmin(near_part * hypot(b.x - a.x, b.y - a.y), DETAIL_NEAR_OWN * diag);
        bool detail = diag <= size * hypot(b.x - a.x, b.y - a.y) && boxes_overlap(lo, hi, a, b);
        // The window: the stroke's box grown by `near` (and a cell); none for
        // a mesh that is not finite or a window beyond reason.
        sp_vec2 o = {floor(lo.x - near - 1), floor(lo.y - near - 1)};
        double wd = ceil(hi.x + near + 1 - o.x) + 1, hd = ceil(hi.y + near + 1 - o.y) + 1;
        detail = detail && isfinite(near) && wd * hd <= 4e6;
        int w = detail ? (int)wd : 0, h = detail ? (int)hd : 0;
        unsigned char* cells = detail ? calloc((size_t)w * (size_t)h, 1) : NULL;
        detail = detail && cells;
        if (detail) cover(rig, px, o, w, h, cells);
        for (int s = 0; detail && s < m; ++s) { // stops once too many points are off
            // Half a cell's diagonal more: a point in a covered cell is on the mesh.
            off += !covered_near(cells, w, h, o, pts[(size_t)s * (size_t)(n - 1) / (size_t)(m - 1)], near + 0.71);
            detail = off <= (1 - on) * m;
        }
        free(cells);
        if (detail && hit) {
            *hit = (detail_hit){.part = k, .xyz = xyz, .px = px, .near = near + 0.71, .air = air};
            return k;
        }
        free(xyz), free(px);
        if (detail) return k;
    }
    return -1;
}

int dragon_detail_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit)
{
    return detail_with(d, pts, n, lo, hi, skip, DETAIL_ON, DETAIL_SIZE, DETAIL_NEAR, DETAIL_AIR_NONE, hit);
}

// Colouring in is drawn over a part up to its whole size: a stroke refused
// as a scribble (or not recognised) that lies on one part as a detail does.
#define COLOURING_SIZE 1.0
// A stroke the classifier took for a part is colouring in only when it lies
// within the part's mesh, a point off it by at most this fraction of the
// part's size: short legs drawn as teeth under a belly reach over its edge.
#define COLOURING_NEAR_RECOGNISED 0.01

int dragon_colouring_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, bool recognised,
                        detail_hit* hit)
{
    // A closed shape drawn on a part is a part drawn there (as for spikes along the back).
    if (n < 2 || sp_stroke_is_loop(&(sp_stroke){.count = n, .points = (sp_vec2*)pts})) return -1;
    return detail_with(d, pts, n, lo, hi, skip, DETAIL_ON, COLOURING_SIZE, recognised ? COLOURING_NEAR_RECOGNISED : DETAIL_NEAR,
                       DETAIL_AIR_NONE, hit);
}

int dragon_speck_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit)
{
    if (!(hypot(hi.x - lo.x, hi.y - lo.y) < SP_DRAGON_PART_MIN * hypot(d->desc.canvas_w, d->desc.canvas_h))) return -1;
    int k = detail_with(d, pts, n, lo, hi, skip, SPECK_ON, DETAIL_SIZE, DETAIL_NEAR, DETAIL_AIR_TOGETHER, hit);
    // Bound where drawn: its points off the mesh ride in the air rather
    // than onto the mesh's edge, which would squash a spot drawn half off.
    if (k >= 0 && hit) hit->near = 0.71;
    return k;
}

// A flourish (fire from a mouth, a spade at a tail's tip, a crown on a
// head) is at most this multiple of its part's size on the canvas (box
// diagonals; a child's fire is often larger than the head): larger, it is
// a part of its own drawn there.
#define FLOURISH_SIZE 1.5
// How near its part's projected mesh (or the ink drawn out of it) a
// flourish must come (a fraction of the part's box diagonal: a child's fire
// starts a little off the snout).
#define FLOURISH_TOUCH 0.08
// The share of its points off the part: a stroke mostly over a part is
// drawn over it, not out of it.
#define FLOURISH_OUT 0.3
// Touching only the part's stroke (the part as drawn, where its fit does not
// reach), a flourish is at most this multiple of the part's size: a crown
// on a drawn head is; legs drawn against it are not (a part of their own).
#define FLOURISH_DRAWN_SIZE 0.75

double dragon_vertex_nearest(const sp_vec2* px, int n, sp_vec2 p, double limit)
{
    double best = limit * limit;
    for (int v = 0; v < n; ++v) {
        double dx = px[v].x - p.x, dy = px[v].y - p.y, d2 = dx * dx + dy * dy;
        if (d2 < best) best = d2;
    }
    return sqrt(best);
}

int dragon_flourish_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit)
{
    if (n < 2) return -1;
    double diag = hypot(hi.x - lo.x, hi.y - lo.y);
    for (int k = 0; k < d->part_n; ++k) // the bodies' meshes, for the distances below
        if (k != skip && d->parts[k]->t->is_torso) body_prepare(d, d->parts[k]);
    dragon_pose_shown(d); // for part_near_stroke
    int m = n < DETAIL_SAMPLES ? n : DETAIL_SAMPLES;
    for (int k = d->part_n - 1; k >= 0; --k) { // the part drawn last lies on top
        part* q = d->parts[k];
        // Only a part of a dragon (attached to its body): a part floating free is not one to draw out of.
        if (k == skip || q->pub.attached_to < 0) continue;
        double* xyz;
        sp_vec2 *px, a, b;
        int got = part_near_stroke(d, k, lo, hi, &xyz, &px, &a, &b);
        if (got < 0) return -1; // out of memory: not a flourish, the stroke goes on as a part
        if (got == 0) continue;
        int nv = q->t->ch.rig.vertex_count;
        double pd = hypot(b.x - a.x, b.y - a.y), touch = FLOURISH_TOUCH * pd, nearest = INFINITY, drawn = INFINITY;
        // Its mesh at its fit too, where its stroke was drawn: a clip's pose
        // moves it from there, and a stroke drawn out of either is drawn out of it.
        double* fxyz = malloc(sizeof(double) * 3 * (size_t)nv);
        sp_vec2* fpx = malloc(sizeof(sp_vec2) * (size_t)nv);
        bool fitted = fxyz && fpx;
        if (fitted) mesh_on_canvas(d, q, &q->world_fit, fxyz, fpx, NULL, NULL);
        free(fxyz);
        bool flourish = fitted && diag <= FLOURISH_SIZE * pd && isfinite(pd);
        int out = 0;
        // Every point nearer the part than any body: out of the part, not
        // reaching for the body (a part drawn there would attach to it).
        // Distances to the meshes' projected vertices, not their triangles:
        // those are a few pixels across, and a head has some 30,000.
        for (int s = 0; flourish && s < m; ++s) {
            sp_vec2 x = pts[(size_t)s * (size_t)(n - 1) / (size_t)(m - 1)];
            double dm = fmin(dragon_vertex_nearest(px, nv, x, INFINITY), dragon_vertex_nearest(fpx, nv, x, INFINITY));
            double dp = fmin(dm, dragon_ink_distance(d, q->pub.id, x));
            for (int j = 0; flourish && j < d->part_n; ++j) {
                const part* o = d->parts[j];
                if (j != skip && o->t->is_torso && o->body_px)
                    flourish = !(dragon_vertex_nearest(o->body_px, o->t->ch.rig.vertex_count, x, dp) < dp);
            }
            nearest = fmin(nearest, dp);
            drawn = fmin(drawn, dragon_vertex_nearest(q->stroke, q->stroke_n, x, drawn));
            out += dm > touch;
        }
        free(fpx);
        // Touching the part as drawn counts too, for a stroke clearly smaller
        // than the part: a visitor draws a crown on the head they drew,
        // where the fit may not reach; one about as large is a part of its own.
        bool touches = nearest <= touch || (drawn <= touch && diag <= FLOURISH_DRAWN_SIZE * pd);
        if (flourish && touches && out >= FLOURISH_OUT * m) {
            if (hit) {
                // Only points on the mesh are bound to it; the rest ride it in the air.
                *hit = (detail_hit){.part = k, .xyz = xyz, .px = px, .near = 0.71, .air = DETAIL_AIR_TOGETHER};
                return k;
            }
            free(xyz), free(px);
            return k;
        }
        free(xyz), free(px);
    }
    return -1;
}

// A stroke along a body's back (spikes, a mane) lies within this fraction
// of the body's size on the canvas (its box's diagonal) of the body's mesh
// everywhere, off it only beside its upper half: the parts visitors draw
// at a body reach farther out of it, legs downwards (BENCHMARKS.md,
// "Nineteenth pass").
#define EDGE_BAND 0.06
// At least this share of its points lie off the mesh (by more than
// EDGE_OFF of the body's size: the vertices inside it are a few pixels
// apart); mostly on it, it is drawn on the body (a detail or a part).
#define EDGE_OUT 0.3
#define EDGE_OFF 0.01
// Or it lies wholly above the body's middle, its box's height at most this
// fraction of its width: low teeth drawn on a body whose own spikes are in
// its mesh lie on that mesh (a review: teeth 15-20 px high along the back
// became a pair of legs standing on it).
#define EDGE_FLAT 0.5
// It runs along the body for at least this fraction of the body's size
// (box diagonals): a small part drawn flat on the back is compact (the
// on-body bench's wings at 0.3 of their size, 78 px against a body of 500).
#define EDGE_MIN 0.25

int dragon_edge_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit)
{
    // A line along the back, not a loop: a closed shape on the body's edge is a part drawn there.
    if (n < 2 || sp_stroke_is_loop(&(sp_stroke){.count = n, .points = (sp_vec2*)pts})) return -1;
    double diag = hypot(hi.x - lo.x, hi.y - lo.y);
    int m = n < DETAIL_SAMPLES ? n : DETAIL_SAMPLES;
    for (int k = d->part_n - 1; k >= 0; --k) { // the body drawn last lies on top
        part* q = d->parts[k];
        sp_vec2 a, b;
        if (k == skip || !q->t->is_torso || !body_prepare(d, q) || !body_box(q, &a, &b)) continue;
        int nv = q->t->ch.rig.vertex_count;
        double bd = hypot(b.x - a.x, b.y - a.y), band = EDGE_BAND * bd;
        if (!(diag <= ON_BODY_SIZE * bd && diag >= EDGE_MIN * bd) ||
            !boxes_overlap(lo, hi, (sp_vec2){a.x - band, a.y - band}, (sp_vec2){b.x + band, b.y + band}))
            continue;
        bool along = true;
        int out = 0;
        for (int s = 0; along && s < m; ++s) {
            sp_vec2 x = pts[(size_t)s * (size_t)(n - 1) / (size_t)(m - 1)];
            double dist = dragon_vertex_nearest(q->body_px, nv, x, INFINITY);
            bool off = dist > EDGE_OFF * bd;
            // Off the mesh only on the body's upper half, its back: legs drawn short under a body reach down.
            along = dist <= band && (!off || x.y < 0.5 * (a.y + b.y));
            out += off;
        }
        bool flat_top = hi.y - lo.y <= EDGE_FLAT * (hi.x - lo.x) && hi.y < 0.5 * (a.y + b.y);
        if (!along || (out < EDGE_OUT * m && !flat_top)) continue;
        if (hit) { // the body's mesh at its fit (a body is shown where it was fitted), the hit's own copy
            double* xyz = malloc(sizeof(double) * 3 * (size_t)nv);
            sp_vec2* px = malloc(sizeof(sp_vec2) * (size_t)nv);
            if (!xyz || !px) {
                free(xyz), free(px);
                return -1; // out of memory: not an edge, the stroke goes on as a part
            }
            memcpy(xyz, q->body_xyz, sizeof(double) * 3 * (size_t)nv);
            memcpy(px, q->body_px, sizeof(sp_vec2) * (size_t)nv);
            *hit = (detail_hit){.part = k, .xyz = xyz, .px = px, .near = 0.71, .air = DETAIL_AIR_EACH};
        }
        return k;
    }
    return -1;
}

// A socket farther than this from the body's middle (in half-lengths of the
// body on the canvas) is at an end: a head's or a tail's, not the wings' or
// the legs' (the shipped torso fitted to the visitors' tune bodies puts its
// head socket at 0.7-0.95 on 9 of 11, its tail socket at 0.8-0.96).
#define END_SOCKET 0.6

// The body whose box on the canvas ([blo, bhi]) is nearest canvas point c, or -1.
static int nearest_body(sp_dragon* d, sp_vec2 c, sp_vec2* blo, sp_vec2* bhi)
{
    int body = -1;
    double bd = INFINITY;
    for (int k = 0; k < d->part_n; ++k) {
        part* q = d->parts[k];
        sp_vec2 a, b;
        if (!q->t->is_torso || !body_prepare(d, q) || !body_box(q, &a, &b)) continue;
        double dist = box_distance(c, a, b);
        if (dist < bd) bd = dist, body = k, *blo = a, *bhi = b;
    }
    return body;
}

int dragon_facing_hint(sp_dragon* d, const tpl* t, sp_vec2 lo, sp_vec2 hi, bool* out_of_end)
{
    *out_of_end = false;
    sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
    sp_vec2 blo = {0, 0}, bhi = {0, 0};
    int k = nearest_body(d, c, &blo, &bhi);
    if (k < 0) return 0;
    const part* body = d->parts[k];
    double mid = 0.5 * (blo.x + bhi.x), half = 0.5 * (bhi.x - blo.x);
    double side = c.x - mid;
    if (!(fabs(side) > 0.25 * half)) return 0; // over the body's middle: no side to face away from
    // The side a part of its kind takes facing as modelled: its socket's,
    // else the way it reaches.
    int natural = t->outward;
    bool at_end = false;
    const dsocket* so = kind_socket(body, t->category, t->prefer);
    if (so) {
        double su = socket_u(d, body, so, mid);
        if (fabs(su) > 0.25 * half) natural = su > 0 ? 1 : -1;
        at_end = fabs(su) > END_SOCKET * half;
    }
    *out_of_end = at_end && near_body_box(d, lo, hi, blo, bhi) && (side > 0 ? hi.x > bhi.x : lo.x < blo.x);
    return (side > 0 ? 1 : -1) == natural ? 1 : -1;
}

bool dragon_claims_socket(sp_dragon* d, const tpl* t, sp_vec2 lo, sp_vec2 hi)
{
    sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5), blo = {0, 0}, bhi = {0, 0};
    int k = nearest_body(d, c, &blo, &bhi);
    const dsocket* so = k >= 0 ? kind_socket(d->parts[k], t->category, t->prefer) : NULL;
    if (!so) return false;
    for (int i = 0; i < d->part_n; ++i)
        if (d->parts[i]->pub.attached_to == k && !strcmp(d->parts[i]->pub.category, t->category)) return false;
    double mid = 0.5 * (blo.x + bhi.x), half = 0.5 * (bhi.x - blo.x), side = c.x - mid;
    // The socket's end as the dragon faces (its heads and tails may say it
    // is drawn mirrored); when nothing tells, either end.
    int facing = body_facing(d, k);
    double su = socket_u(d, d->parts[k], so, mid) * (facing == 1 ? -1 : 1);
    return fabs(su) > END_SOCKET * half && (facing < 0 || su * side > 0) && near_body_box(d, lo, hi, blo, bhi) &&
           (side > 0 ? hi.x > bhi.x : lo.x < blo.x);
}

int dragon_facing_at(sp_dragon* d, sp_vec2 lo, sp_vec2 hi)
{
    sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
    int body = -1;
    double bd = INFINITY;
    for (int k = 0; k < d->part_n; ++k) {
        part* q = d->parts[k];
        sp_vec2 a, b;
        if (!q->t->is_torso || !body_prepare(d, q) || !body_box(q, &a, &b) || !near_body_box(d, lo, hi, a, b)) continue;
        double dist = box_distance(c, a, b);
        if (dist < bd) bd = dist, body = k;
    }
    int m = body >= 0 ? body_facing(d, body) : -1;
    return m < 0 ? 0 : m ? -1 : 1;
}

// A key for the set of bodies a layout was made against (their ids in order).
static uint64_t bodies_key(const sp_dragon* d)
{
    uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < d->part_n; ++i)
        if (d->parts[i]->t->is_torso) h = (h ^ d->parts[i]->pub.id) * 1099511628211ull;
    return h;
}

// The body nearest canvas point a2 whose surface lies within `snap` of it,
// and that surface point in *best; -1 for none.
static int nearest_body_surface(sp_dragon* d, int i, sp_vec2 a2, double snap, surface_hit* best)
{
    int bk = -1;
    best->dist = INFINITY;
    for (int k = 0; k < d->part_n; ++k) {
        part* q = d->parts[k];
        if (k == i || !q->t->is_torso || !body_prepare(d, q)) continue;
        // Only a body nearer than the snap distance and than the nearest
        // so far can hold the part: the others' triangles need no look.
        double within = fmin(snap, best->dist);
        if (box_distance(a2, q->body_lo, q->body_hi) > within) continue;
        surface_hit h;
        if (nearest_surface(q, a2, within, &h) && h.dist < best->dist) *best = h, bk = k;
    }
    if (bk >= 0) onto_outline(d->parts[bk], best);
    return bk;
}

// The stroke's points tried for where it comes nearest a body (evenly by index).
#define REACH_SAMPLES 48

int dragon_reach_target(sp_dragon* d, int i, int only, sp_vec2 a2, sp_vec2* target)
{
    const part* p = d->parts[i];
    sp_vec2 lo = {p->stroke_box[0], p->stroke_box[1]}, hi = {p->stroke_box[2], p->stroke_box[3]};
    double snap = snap_px(d), dist[REACH_SAMPLES];
    sp_vec2 at[REACH_SAMPLES], from[REACH_SAMPLES];
    int body[REACH_SAMPLES], m = 0;
    double bd = INFINITY;
    for (int k = 0; k < d->part_n; ++k) {
        part* q = d->parts[k];
        if (k == i || (only >= 0 && k != only) || !dragon_on_body(d, lo, hi, k) || !q->body_has_surface) continue;
        for (int s = 0; s < REACH_SAMPLES && m < REACH_SAMPLES; ++s) {
            sp_vec2 pt = p->stroke[(int)((long)s * (p->stroke_n - 1) / (REACH_SAMPLES - 1))];
            surface_hit h;
            if (box_distance(pt, q->body_lo, q->body_hi) > snap || !nearest_surface(q, pt, snap, &h)) continue;
            onto_outline(q, &h);
            dist[m] = h.dist, at[m] = h.px, from[m] = pt, body[m++] = k;
            bd = fmin(bd, h.dist);
        }
    }
    int best = -1;
    for (int j = 0; j < m; ++j)
        if (dist[j] <= bd + SAME_DISTANCE_PX + 0.02 * snap &&
            (best < 0 || sp_v2_len(sp_v2_sub(from[j], a2)) < sp_v2_len(sp_v2_sub(from[best], a2))))
            best = j;
    if (best < 0) return -1;
    *target = at[best];
    return body[best];
}

// Lays part i out against the bodies: attached at the nearest body's
// surface when its attachment end is within the snap distance of one, else
// free where it was drawn.
static void layout_part(sp_dragon* d, int i)
{
    part* p = d->parts[i];
    p->world_fit = p->pub.placement;
    p->pub.attached_to = -1;
    p->pub.far_side = false;
    p->pub.socket[0] = 0;
    p->pub.carrier_joint = -1;
    p->pub.anchor = (sp_vec2){NAN, NAN};
    p->note = SP_DRAGON_NOTE_NONE;
    sp_vec3 a = fitted_point(p, &p->pub.placement, p->t->attach_joint, p->t->attach_local);
    sp_vec2 a2 = sp_camera_project(&d->world, a);
    p->pub.attach_end = a2;
    if (p->t->is_torso) return;
    double snap = snap_px(d);
    surface_hit best;
    int bk = nearest_body_surface(d, i, a2, snap, &best);
    // The part just drawn near a body, its attachment end fitted farther
    // from it: fitted again with that end held where the stroke comes
    // nearest the body (reach.c). Only the newest part, at its first layout:
    // an earlier part's fit stays what its own stroke made it (a body drawn
    // after it makes it reach: stroke.c, parts_meet_body).
    sp_vec2 target;
    if (bk < 0 && p->layout_key == 0 && i == d->part_n - 1 && dragon_reach_target(d, i, -1, a2, &target) >= 0 &&
        dragon_fit_reaching(d, p, target)) {
        a = fitted_point(p, &p->pub.placement, p->t->attach_joint, p->t->attach_local);
        p->pub.attach_end = a2 = sp_camera_project(&d->world, a);
        bk = nearest_body_surface(d, i, a2, snap, &best);
    }
    if (bk < 0) return; // far from every body: free, where it was drawn
    if (!d->parts[bk]->body_has_surface) {
        p->note = SP_DRAGON_NOTE_NO_SURFACE; // drawn at a body that cannot hold it: free
        return;
    }
    attach(d, i, bk, &best, a);
}

void dragon_relayout(sp_dragon* d)
{
    uint64_t key = bodies_key(d);
    d->period = 0;
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        if (p->t->clip) d->period = fmax(d->period, p->t->clip_len);
        // A part keeps its layout while the bodies stay the same (parts
        // drawn before it do not change it; those after it cannot).
        if (p->layout_key != key) layout_part(d, i);
        p->layout_key = key;
    }
    d->posed = false;
}
