// detail.c: details (an eye, spots, scales drawn on a part) kept as ink on
// the part: each point bound to the part's mesh where it was drawn, so it
// rides the part's animation and attachment (docs/DESIGN.md, "Details ride
// their part").
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"
#include "sp/curve.h"
#include "sp/embed.h"

static void detail_free(detail* e)
{
    while (e) {
        detail* alt = e->alt;
        free(e->tri);
        free(e);
        e = alt;
    }
}

// Barycentric coordinates of p in the canvas triangle abc (false when it has no area).
static bool bary_of(sp_vec2 p, sp_vec2 a, sp_vec2 b, sp_vec2 c, double w[3])
{
    double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (!(fabs(det) > 1e-12)) return false;
    w[1] = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / det;
    w[2] = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / det;
    w[0] = 1 - w[1] - w[2];
    return isfinite(w[1]) && isfinite(w[2]);
}

// The point of the triangle abc's edges nearest p (p outside it).
static sp_vec2 edge_nearest(sp_vec2 p, sp_vec2 a, sp_vec2 b, sp_vec2 c)
{
    sp_vec2 q[3] = {dragon_segment_nearest(p, a, b), dragon_segment_nearest(p, b, c), dragon_segment_nearest(p, c, a)};
    int k = 0;
    for (int i = 1; i < 3; ++i)
        if (sp_v2_len(sp_v2_sub(p, q[i])) < sp_v2_len(sp_v2_sub(p, q[k]))) k = i;
    return q[k];
}

static sp_vec3 vertex(const double* xyz, uint32_t v)
{
    return (sp_vec3){xyz[3 * (size_t)v], xyz[3 * (size_t)v + 1], xyz[3 * (size_t)v + 2]};
}

// The triangle's normal in the world, turned to the side `flip` says.
static sp_vec3 face_normal(const double* xyz, const uint32_t* tr, double flip)
{
    sp_vec3 a = vertex(xyz, tr[0]);
    sp_vec3 n = sp_v3_cross(sp_v3_sub(vertex(xyz, tr[1]), a), sp_v3_sub(vertex(xyz, tr[2]), a));
    double l = sp_v3_len(n);
    return l > 0 && isfinite(l) ? sp_v3_scale(n, flip / l) : (sp_vec3){0, 0, flip};
}

// The joints that skin the point of triangle tr at barycentric b: its
// corners' influences blended, the four largest kept and renormalised (the
// export's skin takes four). Returns how many.
static int blend_influences(const sp_rig* rig, const uint32_t* tr, const double* b, int joints[4], double weights[4])
{
    int jj[12];
    double ww[12];
    int m = 0;
    for (int c = 0; c < 3; ++c)
        for (int f = 0; f < 4; ++f) {
            int jn = rig->joints4[4 * (size_t)tr[c] + (size_t)f];
            double w = b[c] * rig->weights4[4 * (size_t)tr[c] + (size_t)f];
            if (!(w > 0)) continue;
            int s = 0;
            while (s < m && jj[s] != jn)
                ++s;
            if (s == m) jj[m] = jn, ww[m++] = 0;
            ww[s] += w;
        }
    double sum = 0;
    int k = 0;
    for (; k < 4; ++k) {
        int big = -1;
        for (int s = 0; s < m; ++s)
            if (ww[s] > 0 && (big < 0 || ww[s] > ww[big])) big = s;
        if (big < 0) break;
        joints[k] = jj[big], weights[k] = ww[big], sum += ww[big], ww[big] = 0;
    }
    for (int f = 0; f < k; ++f)
        weights[f] /= sum;
    return k;
}

// The point of a projected mesh (xyz: world, px: canvas) under or nearest
// canvas point p: under it, the front-most triangle's (nearest the viewer,
// +z); else the nearest point of the nearest triangle. Its triangle (-1:
// nothing finite) and barycentric coordinates w.
static int mesh_point_at(const sp_rig* rig, const double* xyz, const sp_vec2* px, sp_vec2 p, double w[3])
{
    int face = -1;
    bool on = false;
    double best = INFINITY; // depth when on, distance when off
    for (int f = 0; f < rig->triangle_count; ++f) {
        const uint32_t* tr = rig->triangles + 3 * (size_t)f;
        sp_vec2 a = px[tr[0]], b = px[tr[1]], c = px[tr[2]];
        double u[3];
        if (!bary_of(p, a, b, c, u)) continue;
        if (u[0] >= 0 && u[1] >= 0 && u[2] >= 0) {
            double z = u[0] * xyz[3 * tr[0] + 2] + u[1] * xyz[3 * tr[1] + 2] + u[2] * xyz[3 * tr[2] + 2];
            if (!on || z > best) on = true, best = z, face = f;
        } else if (!on) {
            double dist = sp_v2_len(sp_v2_sub(p, edge_nearest(p, a, b, c)));
            if (dist < best) best = dist, face = f;
        }
    }
    if (face < 0) return -1;
    const uint32_t* tr = rig->triangles + 3 * (size_t)face;
    sp_vec2 a = px[tr[0]], b = px[tr[1]], c = px[tr[2]];
    if (!bary_of(on ? p : edge_nearest(p, a, b, c), a, b, c, w)) return -1;
    for (int j = 0; j < 3; ++j) // on its edge: rounding must not reach outside
        w[j] = fmin(1, fmax(0, w[j]));
    return face;
}

// The world position of canvas point p at the depth of world point A (the
// pseudo-inverse of the projection's Jacobian at A: exact for the world's
// orthographic camera). False when the projection there is degenerate.
static bool canvas_to_world(const sp_camera* cam, sp_vec3 A, sp_vec2 p, sp_vec3* out)
{
    double J[6];
    sp_camera_jacobian(cam, A, J);
    double g0 = J[0] * J[0] + J[1] * J[1] + J[2] * J[2], g1 = J[0] * J[3] + J[1] * J[4] + J[2] * J[5];
    double g2 = J[3] * J[3] + J[4] * J[4] + J[5] * J[5], det = g0 * g2 - g1 * g1;
    if (!(fabs(det) > 1e-12) || !isfinite(det)) return false;
    sp_vec2 dp = sp_v2_sub(p, sp_camera_project(cam, A));
    double y0 = (g2 * dp.x - g1 * dp.y) / det, y1 = (-g1 * dp.x + g0 * dp.y) / det; // (J J^T)^-1 dp
    *out = (sp_vec3){A.x + J[0] * y0 + J[3] * y1, A.y + J[1] * y0 + J[4] * y1, A.z + J[2] * y0 + J[5] * y1};
    return isfinite(out->x) && isfinite(out->y) && isfinite(out->z);
}

// The vertex whose canvas point (px, n of them) lies nearest p, the one
// nearest the viewer (+z, xyz: world) among those within half a pixel of
// that; -1 when none is finite.
static int vertex_at(const sp_vec2* px, const double* xyz, int n, sp_vec2 p)
{
    double best = dragon_vertex_nearest(px, n, p, INFINITY);
    int front = -1;
    double r = best + 0.5;
    for (int v = 0; isfinite(best) && v < n; ++v) {
        double dx = px[v].x - p.x, dy = px[v].y - p.y;
        if (dx * dx + dy * dy <= r * r && (front < 0 || xyz[3 * v + 2] > xyz[3 * front + 2])) front = v;
    }
    return front;
}

// Canvas point p in the rig's rest space (*rest), carried from world point
// A of part q's mesh as posed (q->ev, q->world_t), which the c joints (with
// weights w) skin: placed in the world at A's depth, then taken back by the
// inverse of their blended skin there. False when nothing carries it.
static bool carry(const sp_dragon* d, const part* q, sp_vec3 A, const int* joints, const double* w, int c, sp_vec2 p,
                  sp_vec3* rest)
{
    sp_mat4 skin = dragon_blended_skin(joints, w, c, sp_rig_eval_skin(q->ev), &q->world_t), inv;
    sp_vec3 W;
    if (c <= 0 || !sp_mat4_inverse(&skin, &inv) || !canvas_to_world(&d->world, A, p, &W)) return false;
    *rest = sp_mat4_point(&inv, W);
    return true;
}

// Binds the points to a mesh as shown (hit: the part's mesh in the world
// and on the canvas): each to the front-most triangle under it (nearest the
// viewer, +z), or, off the mesh, to the nearest point of a triangle within
// `near` pixels (not beyond it: a triangle seen edge-on on the canvas would
// fling an extrapolated point far in depth). A flourish's or an edge's
// other points go in the air (flip 0), carried as hit->air says. Returns
// how many were bound (kept in order).
static int bind_points(const sp_dragon* d, const part* q, const detail_hit* hit, const sp_vec2* pts, int m, detail* e)
{
    const sp_rig* rig = &q->t->ch.rig;
    const double* xyz = hit->xyz;
    const sp_vec2* px = hit->px;
    double near = hit->near;
    double* best = malloc(sizeof(double) * 2 * (size_t)m); // per point: depth when on, distance when off
    int* face = malloc(sizeof(int) * (size_t)m);
    bool* on = calloc((size_t)m, sizeof(bool));
    if (!best || !face || !on) {
        free(best), free(face), free(on);
        return 0;
    }
    sp_vec2 lo = pts[0], hi = pts[0];
    for (int i = 0; i < m; ++i) {
        best[2 * i] = -INFINITY, best[2 * i + 1] = near, face[i] = -1;
        lo.x = fmin(lo.x, pts[i].x), lo.y = fmin(lo.y, pts[i].y), hi.x = fmax(hi.x, pts[i].x), hi.y = fmax(hi.y, pts[i].y);
    }
    for (int f = 0; f < rig->triangle_count; ++f) {
        const uint32_t* tr = rig->triangles + 3 * (size_t)f;
        sp_vec2 a = px[tr[0]], b = px[tr[1]], c = px[tr[2]];
        // Only triangles near the stroke's box (most of the mesh is not).
        if (!(fmax(a.x, fmax(b.x, c.x)) >= lo.x - near && fmin(a.x, fmin(b.x, c.x)) <= hi.x + near &&
              fmax(a.y, fmax(b.y, c.y)) >= lo.y - near && fmin(a.y, fmin(b.y, c.y)) <= hi.y + near))
            continue;
        for (int i = 0; i < m; ++i) {
            double w[3];
            if (!bary_of(pts[i], a, b, c, w)) continue;
            if (w[0] >= 0 && w[1] >= 0 && w[2] >= 0) {
                double z = w[0] * xyz[3 * tr[0] + 2] + w[1] * xyz[3 * tr[1] + 2] + w[2] * xyz[3 * tr[2] + 2];
                if (!on[i] || z > best[2 * i]) on[i] = true, best[2 * i] = z, face[i] = f;
            } else if (!on[i]) {
                double dist = sp_v2_len(sp_v2_sub(pts[i], edge_nearest(pts[i], a, b, c)));
                if (dist <= best[2 * i + 1]) best[2 * i + 1] = dist, face[i] = f;
            }
        }
    }
    // A flourish's points in the air are carried together from the mesh's
    // point nearest their middle, so the stroke keeps its shape; an edge's
    // each from the vertex nearest it, so it follows the body's bends.
    sp_vec2 mid = {0, 0};
    int air = 0;
    for (int i = 0; i < m; ++i)
        if (face[i] < 0) mid = sp_v2_add(mid, pts[i]), ++air;
    sp_vec3 A = {0, 0, 0};
    int cj[4] = {0}, cn = 0;
    double cw[4] = {0}, aw[3];
    if (hit->air == DETAIL_AIR_TOGETHER && air > 0) {
        int af = mesh_point_at(rig, xyz, px, sp_v2_scale(mid, 1.0 / air), aw);
        const uint32_t* tr = af >= 0 ? rig->triangles + 3 * (size_t)af : NULL;
        for (int j = 0; tr && j < 3; ++j)
            A = sp_v3_add(A, sp_v3_scale(vertex(xyz, tr[j]), aw[j]));
        cn = tr ? blend_influences(rig, tr, aw, cj, cw) : 0;
    }
    int k = 0;
    for (int i = 0; i < m; ++i) {
        if (face[i] < 0) { // off the mesh and not near it: in the air, or left out of the ink
            if (hit->air == DETAIL_AIR_EACH) {
                int v = vertex_at(px, xyz, rig->vertex_count, pts[i]);
                if (v < 0) continue;
                A = vertex(xyz, (uint32_t)v);
                cn = blend_influences(rig, (const uint32_t[3]){(uint32_t)v, (uint32_t)v, (uint32_t)v}, (const double[3]){1, 0, 0},
                                      cj, cw);
            }
            sp_vec3 r;
            if (!hit->air || !carry(d, q, A, cj, cw, cn, pts[i], &r)) continue;
            memset(e->tri + 3 * k, 0, sizeof(uint32_t) * 3);
            memcpy(e->bary + 3 * k, &(double[3]){r.x, r.y, r.z}, sizeof(double) * 3);
            for (int f = 0; f < 4; ++f)
                e->joint[4 * k + f] = f < cn ? (uint32_t)cj[f] : 0, e->weight[4 * k + f] = f < cn ? cw[f] : 0;
            e->drawn[k] = pts[i];
            e->flip[k++] = 0;
            continue;
        }
        const uint32_t* tr = rig->triangles + 3 * (size_t)face[i];
        sp_vec2 a = px[tr[0]], b = px[tr[1]], c = px[tr[2]], p = on[i] ? pts[i] : edge_nearest(pts[i], a, b, c);
        double w[3];
        if (!bary_of(p, a, b, c, w)) continue;
        for (int j = 0; j < 3; ++j) // on its edge: rounding must not reach outside
            w[j] = fmin(1, fmax(0, w[j]));
        memcpy(e->tri + 3 * k, tr, sizeof(uint32_t) * 3);
        memcpy(e->bary + 3 * k, w, sizeof w);
        e->flip[k] = face_normal(xyz, tr, 1).z >= 0 ? 1 : -1; // the side facing the canvas's viewer
        e->drawn[k++] = pts[i];
    }
    free(best), free(face), free(on);
    return k;
}

// Part q's vertices on the canvas as the visitor sees it (posed at the
// dragon's clock, not at its fit, which a clip's pose moves: a tail's sway
// starts off rest; the parts only, what the caller posed and reads stays as
// it was); malloc'd, NULL when out of memory.
static sp_vec2* shown_px(sp_dragon* d, const part* q)
{
    int nv = q->t->ch.rig.vertex_count;
    dragon_pose_shown(d);
    sp_vec2* px = malloc(sizeof(sp_vec2) * (size_t)(nv > 0 ? nv : 1));
    for (int v = 0; px && v < nv; ++v)
        px[v] = sp_camera_project(&d->world, (sp_vec3){q->xyz[3 * v], q->xyz[3 * v + 1], q->xyz[3 * v + 2]});
    return px;
}

// The points (n canvas points) bound to part q's mesh as shown (hit: its
// tolerance and what becomes of points off it; px: shown_px of q): a detail
// without an id, or NULL when fewer than two points bind or memory runs out.
static detail* bind_detail(sp_dragon* d, const part* q, const detail_hit* hit, const sp_vec2* px, const sp_vec2* pts, int n)
{
    const sp_rig* rig = &q->t->ch.rig;
    if (rig->vertex_count <= 0 || rig->triangle_count <= 0 || n < 2) return NULL;
    // A long stroke is resampled along its length: the ink's shape, not every pen sample.
    int m = n <= SP_DRAGON_DETAIL_POINTS ? n : SP_DRAGON_DETAIL_POINTS;
    detail* e = calloc(1, sizeof *e);
    sp_vec2* rs = m < n ? malloc(sizeof(sp_vec2) * (size_t)m) : NULL;
    size_t mm = (size_t)m;
    // One block: tri (3m uint32, m spare), joint (4m uint32), then bary
    // (3m), flip (m), xyz (3m), normal (3m), drawn (2m), weight (4m) doubles.
    uint32_t* block = malloc(sizeof(uint32_t) * 8 * mm + sizeof(double) * 16 * mm);
    if (!e || (m < n && !rs) || !block || (rs && sp_curve_resample(pts, n, false, m, rs) != SP_OK)) {
        free(e), free(rs), free(block);
        return NULL;
    }
    e->tri = block, e->joint = block + 4 * mm;
    e->bary = (double*)(void*)(block + 8 * mm); // 8m uint32s keep the doubles aligned
    e->flip = e->bary + 3 * mm, e->xyz = e->flip + mm, e->normal = e->xyz + 3 * mm;
    e->drawn = (sp_vec2*)(void*)(e->normal + 3 * mm);
    e->weight = (double*)(void*)(e->drawn + mm);
    // Bound to the part as the visitor sees it, within the tolerance the caller's test used.
    detail_hit shown = *hit;
    shown.xyz = q->xyz, shown.px = (sp_vec2*)px;
    e->n = bind_points(d, q, &shown, rs ? rs : pts, m, e);
    free(rs);
    if (e->n < 2) {
        detail_free(e);
        return NULL;
    }
    e->host = q->pub.id;
    e->t = q->t;
    e->fit0 = q->world_fit;
    e->mirrored = q->pub.mirrored;
    return e;
}

int dragon_detail_keep(sp_dragon* d, const detail_hit* hit, const sp_vec2* pts, int n)
{
    int k = hit->part;
    if (k < 0 || k >= d->part_n || !hit->xyz || !hit->px || n < 2 || d->detail_n >= SP_DRAGON_MAX_DETAILS) return -1;
    if (!d->details && !(d->details = calloc(SP_DRAGON_MAX_DETAILS, sizeof(detail*)))) return -1;
    sp_vec2* px = shown_px(d, d->parts[k]);
    detail* e = px ? bind_detail(d, d->parts[k], hit, px, pts, n) : NULL;
    free(px);
    if (!e) return -1;
    e->id = d->next_id++;
    d->details[d->detail_n] = e;
    return d->detail_n++;
}

// Canvas point x moved by the world transform m (the canvas is the world's front view).
static sp_vec2 moved_px(const sp_dragon* d, const sp_mat4* m, sp_vec2 x)
{
    sp_vec3 o, dir;
    sp_camera_ray(&d->world, x, &o, &dir);
    return sp_camera_project(&d->world, sp_mat4_point(m, o));
}

// The transform from where detail e was drawn to where part q (which shows
// it) is laid out now; false when q has not moved since.
static bool ink_moved(const detail* e, const part* q, sp_mat4* m)
{
    sp_mat4 inv;
    if (!memcmp(&q->world_fit, &e->fit0, sizeof *m) || !sp_mat4_inverse(&e->fit0, &inv)) return false;
    *m = sp_mat4_mul(&q->world_fit, &inv);
    return true;
}

static bool binds(const detail* e, const part* q)
{
    return e->t == q->t && e->mirrored == q->pub.mirrored;
}

// Ink (n canvas points) whose middle the part's mesh as shown does not
// cover is moved, whole, until it does, at the mesh's point nearest it: a
// spot drawn on a leg's foot, whose new fit put the foot elsewhere, hung in
// the air 50 px beside it (a second review).
static void onto_mesh(const part* q, const sp_vec2* px, sp_vec2* at, int n)
{
    const sp_rig* rig = &q->t->ch.rig;
    sp_vec2 mid = {0, 0};
    for (int j = 0; j < n; ++j)
        mid = sp_v2_add(mid, at[j]);
    mid = sp_v2_scale(mid, 1.0 / n);
    double w[3];
    int f = mesh_point_at(rig, q->xyz, px, mid, w);
    if (f >= 0) {
        const uint32_t* tr = rig->triangles + 3 * (size_t)f;
        sp_vec2 m = {0, 0};
        for (int c = 0; c < 3; ++c)
            m = sp_v2_add(m, sp_v2_scale(px[tr[c]], w[c]));
        sp_vec2 by = sp_v2_sub(m, mid);
        if (sp_v2_len(by) > 0.5)
            for (int j = 0; j < n; ++j)
                at[j] = sp_v2_add(at[j], by);
    }
}

// Ink bound anew to another fit of its part snaps onto that mesh within
// this share of its own size (the detail test's own-size tolerance).
#define DETAIL_FOLLOW_NEAR 0.3

// Bindings kept of one detail: the part decided again, then turned, then
// given back; a longer chain loses its oldest.
enum { DETAIL_BINDINGS = 4 };

static void details_follow(sp_dragon* d, int k, const part* before)
{
    const part* q = d->parts[k];
    sp_vec2* px = NULL; // shown_px of q, once a detail is bound anew
    for (int i = 0; i < d->detail_n; ++i) {
        const part* was = before;
        detail* e = d->details[i];
        if (e->host != q->pub.id || binds(e, q)) continue;
        // A binding to this fit kept from before (the part given back): first again.
        detail *prev = e, *b = e->alt;
        while (b && !binds(b, q))
            prev = b, b = b->alt;
        if (b) {
            prev->alt = b->alt, b->alt = e;
            d->details[i] = b;
            continue;
        }
        // Else bound anew where it shows on the fit it was bound to, as if
        // drawn there now (an eye drawn in a head taken for a body, which
        // the body drawn next made a head, was hidden for good); that fit
        // may lie further back (decided again, then turned, in one stroke).
        while (was && !binds(e, was))
            was = was->before;
        if (!was) continue;
        sp_vec2* at = malloc(sizeof(sp_vec2) * (size_t)e->n);
        if (!px) px = shown_px(d, q);
        if (!at || !px) {
            free(at);
            continue;
        }
        sp_mat4 m;
        bool moved = ink_moved(e, was, &m);
        for (int j = 0; j < e->n; ++j)
            at[j] = moved ? moved_px(d, &m, e->drawn[j]) : e->drawn[j];
        onto_mesh(q, px, at, e->n);
        sp_vec2 lo = at[0], hi = at[0];
        for (int j = 1; j < e->n; ++j)
            lo.x = fmin(lo.x, at[j].x), lo.y = fmin(lo.y, at[j].y), hi.x = fmax(hi.x, at[j].x), hi.y = fmax(hi.y, at[j].y);
        // Its points off the new mesh go with it in the air (a flourish's
        // way): ink the visitor drew is not dropped.
        detail_hit hit = {
            .part = k, .near = DETAIL_FOLLOW_NEAR * hypot(hi.x - lo.x, hi.y - lo.y) + 1.0, .air = DETAIL_AIR_TOGETHER};
        detail* nb = bind_detail(d, q, &hit, px, at, e->n);
        free(at);
        if (!nb) continue;
        nb->id = e->id;
        nb->alt = e;
        d->details[i] = nb;
        int depth = 0;
        for (detail* c = nb; c; c = c->alt)
            if (++depth == DETAIL_BINDINGS && c->alt) {
                detail_free(c->alt);
                c->alt = NULL;
            }
    }
    free(px);
}

static const part* host_of(const sp_dragon* d, const detail* e, int* index)
{
    for (int k = 0; k < d->part_n; ++k)
        if (d->parts[k]->pub.id == e->host) {
            *index = k;
            return d->parts[k];
        }
    *index = -1;
    return NULL;
}

double dragon_ink_distance(const sp_dragon* d, uint64_t host, sp_vec2 p)
{
    double best = INFINITY;
    for (int i = 0; i < d->detail_n; ++i) {
        const detail* e = d->details[i];
        int k;
        const part* q = e->host == host ? host_of(d, e, &k) : NULL;
        if (!q || !binds(e, q)) continue; // not shown
        // Its part laid out again since (attached elsewhere, or freed): the
        // ink is shown where the part's move takes it, not where it was drawn.
        sp_mat4 m = {{0}};
        bool moved = ink_moved(e, q, &m);
        sp_vec2 a = moved ? moved_px(d, &m, e->drawn[0]) : e->drawn[0];
        for (int j = 0; j + 1 < e->n; ++j) {
            sp_vec2 b = moved ? moved_px(d, &m, e->drawn[j + 1]) : e->drawn[j + 1];
            best = fmin(best, sp_v2_len(sp_v2_sub(p, dragon_segment_nearest(p, a, b))));
            a = b;
        }
    }
    return best;
}

void dragon_details_pose(sp_dragon* d)
{
    for (int i = 0; i < d->detail_n; ++i) {
        detail* e = d->details[i];
        int k;
        const part* q = host_of(d, e, &k);
        e->shown = q && q->t == e->t && q->pub.mirrored == e->mirrored;
        for (int j = 0; e->shown && j < e->n; ++j) {
            if (e->flip[j] == 0) { // in the air: its joints carry it; no surface under it, so no normal
                int jn[4] = {(int)e->joint[4 * j], (int)e->joint[4 * j + 1], (int)e->joint[4 * j + 2], (int)e->joint[4 * j + 3]};
                sp_mat4 m = dragon_blended_skin(jn, e->weight + 4 * j, 4, sp_rig_eval_skin(q->ev), &q->world_t);
                sp_vec3 r = sp_mat4_point(&m, (sp_vec3){e->bary[3 * j], e->bary[3 * j + 1], e->bary[3 * j + 2]});
                memcpy(e->xyz + 3 * j, &(double[3]){r.x, r.y, r.z}, sizeof(double) * 3);
                memset(e->normal + 3 * j, 0, sizeof(double) * 3);
                continue;
            }
            const uint32_t* tr = e->tri + 3 * j;
            sp_vec3 s = {0, 0, 0};
            for (int c = 0; c < 3; ++c)
                s = sp_v3_add(s, sp_v3_scale(vertex(q->xyz, tr[c]), e->bary[3 * j + c]));
            sp_vec3 nrm = face_normal(q->xyz, tr, e->flip[j]);
            memcpy(e->xyz + 3 * j, &(double[3]){s.x, s.y, s.z}, sizeof(double) * 3);
            memcpy(e->normal + 3 * j, &(double[3]){nrm.x, nrm.y, nrm.z}, sizeof(double) * 3);
        }
    }
}

void dragon_details_follow_parts(sp_dragon* d)
{
    for (int k = 0; k < d->part_n; ++k)
        details_follow(d, k, d->parts[k]->before);
}

int dragon_detail_skinned(const sp_dragon* d, int i, double* rest, uint16_t* joints, float* weights)
{
    if (i < 0 || i >= d->detail_n) return -1;
    const detail* e = d->details[i];
    int k;
    const part* q = host_of(d, e, &k);
    if (!q || q->t != e->t || q->pub.mirrored != e->mirrored) return -1;
    const sp_rig* rig = &q->t->ch.rig;
    for (int j = 0; j < e->n; ++j) {
        const uint32_t* tr = e->tri + 3 * j;
        const double* b = e->bary + 3 * j;
        int jn[4];
        double w[4];
        int c = 4;
        if (e->flip[j] == 0) { // in the air: its rest position and the joints that carry it
            memcpy(rest + 3 * j, b, sizeof(double) * 3);
            for (int f = 0; f < 4; ++f)
                jn[f] = (int)e->joint[4 * j + f], w[f] = e->weight[4 * j + f];
        } else {
            for (int a = 0; a < 3; ++a)
                rest[3 * j + a] = b[0] * rig->rest[3 * (size_t)tr[0] + (size_t)a] +
                                  b[1] * rig->rest[3 * (size_t)tr[1] + (size_t)a] +
                                  b[2] * rig->rest[3 * (size_t)tr[2] + (size_t)a];
            c = blend_influences(rig, tr, b, jn, w);
        }
        for (int f = 0; f < 4; ++f) {
            joints[4 * j + f] = f < c ? (uint16_t)jn[f] : 0;
            weights[4 * j + f] = f < c ? (float)w[f] : (float)(c == 0 && f == 0);
        }
    }
    return k;
}

void dragon_details_prune(sp_dragon* d)
{
    int kept = 0;
    for (int i = 0; i < d->detail_n; ++i) {
        int k;
        if (host_of(d, d->details[i], &k))
            d->details[kept++] = d->details[i];
        else
            detail_free(d->details[i]);
    }
    d->detail_n = kept;
}

uint64_t dragon_detail_last_change(const sp_dragon* d)
{
    if (d->detail_n == 0) return 0;
    uint64_t id = d->details[d->detail_n - 1]->id;
    return d->part_n == 0 || id > d->parts[d->part_n - 1]->pub.id ? id : 0;
}

void dragon_detail_pop(sp_dragon* d)
{
    if (d->detail_n > 0) detail_free(d->details[--d->detail_n]);
}

void dragon_detail_remove(sp_dragon* d, uint64_t id)
{
    int kept = 0;
    for (int i = 0; i < d->detail_n; ++i) {
        if (d->details[i]->id == id)
            detail_free(d->details[i]);
        else
            d->details[kept++] = d->details[i];
    }
    d->detail_n = kept;
}

void dragon_details_clear(sp_dragon* d)
{
    while (d->detail_n > 0)
        dragon_detail_pop(d);
    free(d->details);
    d->details = NULL;
}

int sp_dragon_detail_count(const sp_dragon* d)
{
    return d->detail_n;
}

bool sp_dragon_detail_get(const sp_dragon* d, int i, sp_dragon_detail* out)
{
    if (i < 0 || i >= d->detail_n) return false;
    const detail* e = d->details[i];
    int k;
    host_of(d, e, &k);
    bool shown = d->posed && e->shown;
    *out = (sp_dragon_detail){
        .id = e->id, .part = k, .point_count = e->n, .xyz = shown ? e->xyz : NULL, .normal = shown ? e->normal : NULL};
    return true;
}
