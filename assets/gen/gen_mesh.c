// gen_mesh.c: the generator's geometry blocks (see gen_mesh.h).
#include "gen_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double k_pi = 3.14159265358979323846;

void* sp_gen_check_alloc(void* p)
{
    if (!p) {
        fprintf(stderr, "sp-assetgen: out of memory\n");
        exit(1);
    }
    return p;
}

void sp_gen_mesh_free(sp_gen_mesh* m)
{
    free(m->pos), free(m->color), free(m->skin), free(m->tris), free(m->deco_vertex), free(m->deco_tri);
    memset(m, 0, sizeof *m);
}

int sp_gen_mesh_vertex(sp_gen_mesh* m, sp_vec3 p, sp_gen_rgb c, const sp_gen_skin* s)
{
    if (m->vertex_count == m->vertex_cap) {
        m->vertex_cap = m->vertex_cap ? 2 * m->vertex_cap : 1024;
        m->pos = sp_gen_check_alloc(realloc(m->pos, sizeof(double) * 3 * (size_t)m->vertex_cap));
        m->color = sp_gen_check_alloc(realloc(m->color, sizeof(sp_gen_rgb) * (size_t)m->vertex_cap));
        m->skin = sp_gen_check_alloc(realloc(m->skin, sizeof(sp_gen_skin) * (size_t)m->vertex_cap));
        m->deco_vertex = sp_gen_check_alloc(realloc(m->deco_vertex, (size_t)m->vertex_cap));
    }
    int i = m->vertex_count++;
    m->deco_vertex[i] = m->decorating;
    m->pos[3 * i] = p.x, m->pos[3 * i + 1] = p.y, m->pos[3 * i + 2] = p.z;
    m->color[i] = c;
    m->skin[i] = *s;
    return i;
}

void sp_gen_mesh_tri(sp_gen_mesh* m, int a, int b, int c)
{
    if (m->tri_count == m->tri_cap) {
        m->tri_cap = m->tri_cap ? 2 * m->tri_cap : 2048;
        m->tris = sp_gen_check_alloc(realloc(m->tris, sizeof(uint32_t) * 3 * (size_t)m->tri_cap));
        m->deco_tri = sp_gen_check_alloc(realloc(m->deco_tri, (size_t)m->tri_cap));
    }
    m->deco_tri[m->tri_count] = m->decorating;
    uint32_t* t = m->tris + 3 * (size_t)m->tri_count++;
    t[0] = (uint32_t)a, t[1] = (uint32_t)b, t[2] = (uint32_t)c;
}

void sp_gen_mesh_mirror_z(sp_gen_mesh* m, int first_vertex, int first_tri)
{
    int v_end = m->vertex_count, t_end = m->tri_count, off = v_end - first_vertex;
    bool was = m->decorating;
    for (int i = first_vertex; i < v_end; ++i) {
        sp_vec3 p = {m->pos[3 * i], m->pos[3 * i + 1], -m->pos[3 * i + 2]};
        sp_gen_skin s = m->skin[i];
        m->decorating = m->deco_vertex[i];
        sp_gen_mesh_vertex(m, p, m->color[i], &s);
    }
    for (int t = first_tri; t < t_end; ++t) {
        const uint32_t* q = m->tris + 3 * (size_t)t;
        int a = (int)q[0], b = (int)q[1], c = (int)q[2];
        m->decorating = m->deco_tri[t];
        sp_gen_mesh_tri(m, a + off, c + off, b + off);
    }
    m->decorating = was;
}

void sp_gen_mesh_shear_z(sp_gen_mesh* m, int first_vertex, double k, double z_offset)
{
    for (int i = first_vertex; i < m->vertex_count; ++i)
        m->pos[3 * i + 2] += m->pos[3 * i + 1] * k + z_offset;
}

// ---- skin ----------------------------------------------------------------

sp_gen_skin sp_gen_skin_lerp(const sp_gen_skin* a, const sp_gen_skin* b, double t)
{
    sp_gen_skin r = {0};
    for (int i = 0; i < a->n; ++i)
        sp_gen_skin_add(&r, a->joint[i], (1.0 - t) * a->w[i]);
    for (int i = 0; i < b->n; ++i)
        sp_gen_skin_add(&r, b->joint[i], t * b->w[i]);
    return r;
}

// ---- scalar helpers ------------------------------------------------------

static uint32_t mix32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

double sp_gen_hash2(uint32_t a, uint32_t b)
{
    return (double)mix32(a * 0x9E3779B1u ^ mix32(b + 0x632BE5ABu)) / 4294967296.0;
}

double sp_gen_noise2(double x, double y, uint32_t seed)
{
    double fx = floor(x), fy = floor(y);
    int ix = (int)fx, iy = (int)fy;
    double tx = x - fx, ty = y - fy;
    tx = tx * tx * (3.0 - 2.0 * tx), ty = ty * ty * (3.0 - 2.0 * ty);
    uint32_t s = seed * 0x85EBCA77u;
    double a = sp_gen_hash2((uint32_t)ix + s, (uint32_t)iy), b = sp_gen_hash2((uint32_t)(ix + 1) + s, (uint32_t)iy);
    double c = sp_gen_hash2((uint32_t)ix + s, (uint32_t)(iy + 1)), d = sp_gen_hash2((uint32_t)(ix + 1) + s, (uint32_t)(iy + 1));
    return sp_gen_lerp(sp_gen_lerp(a, b, tx), sp_gen_lerp(c, d, tx), ty);
}

double sp_gen_interp(const double (*keys)[2], int n, double u)
{
    if (u <= keys[0][0]) return keys[0][1];
    if (u >= keys[n - 1][0]) return keys[n - 1][1];
    int i = 0;
    while (i + 2 < n && keys[i + 1][0] <= u)
        ++i;
    double u0 = keys[i][0], u1 = keys[i + 1][0], v0 = keys[i][1], v1 = keys[i + 1][1];
    double h = u1 - u0;
    // Slopes: centred differences inside, one-sided at the ends.
    double m0 = i > 0 ? (v1 - keys[i - 1][1]) / (u1 - keys[i - 1][0]) : (v1 - v0) / h;
    double m1 = i + 2 < n ? (keys[i + 2][1] - v0) / (keys[i + 2][0] - u0) : (v1 - v0) / h;
    double t = (u - u0) / h, t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * v0 + (t3 - 2 * t2 + t) * h * m0 + (-2 * t3 + 3 * t2) * v1 + (t3 - t2) * h * m1;
}

// ---- paths ---------------------------------------------------------------

static void path_measure(sp_gen_path* p)
{
    p->s[0] = 0.0;
    for (int i = 1; i < p->n; ++i)
        p->s[i] = p->s[i - 1] + sp_v3_len(sp_v3_sub(p->p[i], p->p[i - 1]));
    p->length = p->s[p->n - 1];
}

void sp_gen_path_points(sp_gen_path* out, const sp_vec3* pts, int n)
{
    out->n = n;
    out->p = sp_gen_check_alloc(malloc(sizeof(sp_vec3) * (size_t)n));
    out->s = sp_gen_check_alloc(malloc(sizeof(double) * (size_t)n));
    memcpy(out->p, pts, sizeof(sp_vec3) * (size_t)n);
    path_measure(out);
}

void sp_gen_path_catmull(sp_gen_path* out, const sp_vec3* ctrl, int n, int per_span)
{
    int total = (n - 1) * per_span + 1;
    sp_vec3* pts = sp_gen_check_alloc(malloc(sizeof(sp_vec3) * (size_t)total));
    int k = 0;
    for (int i = 0; i + 1 < n; ++i) {
        sp_vec3 p1 = ctrl[i], p2 = ctrl[i + 1];
        sp_vec3 p0 = i > 0 ? ctrl[i - 1] : sp_v3_sub(sp_v3_scale(p1, 2.0), p2);
        sp_vec3 p3 = i + 2 < n ? ctrl[i + 2] : sp_v3_sub(sp_v3_scale(p2, 2.0), p1);
        // Centripetal parameterisation (alpha = 0.5): no cusps or loops.
        double t0 = 0.0;
        double t1 = t0 + sqrt(fmax(sp_v3_len(sp_v3_sub(p1, p0)), 1e-9));
        double t2 = t1 + sqrt(fmax(sp_v3_len(sp_v3_sub(p2, p1)), 1e-9));
        double t3 = t2 + sqrt(fmax(sp_v3_len(sp_v3_sub(p3, p2)), 1e-9));
        for (int j = 0; j < per_span; ++j) {
            double t = t1 + (t2 - t1) * (double)j / per_span;
            sp_vec3 a1 = sp_v3_add(sp_v3_scale(p0, (t1 - t) / (t1 - t0)), sp_v3_scale(p1, (t - t0) / (t1 - t0)));
            sp_vec3 a2 = sp_v3_add(sp_v3_scale(p1, (t2 - t) / (t2 - t1)), sp_v3_scale(p2, (t - t1) / (t2 - t1)));
            sp_vec3 a3 = sp_v3_add(sp_v3_scale(p2, (t3 - t) / (t3 - t2)), sp_v3_scale(p3, (t - t2) / (t3 - t2)));
            sp_vec3 b1 = sp_v3_add(sp_v3_scale(a1, (t2 - t) / (t2 - t0)), sp_v3_scale(a2, (t - t0) / (t2 - t0)));
            sp_vec3 b2 = sp_v3_add(sp_v3_scale(a2, (t3 - t) / (t3 - t1)), sp_v3_scale(a3, (t - t1) / (t3 - t1)));
            pts[k++] = sp_v3_add(sp_v3_scale(b1, (t2 - t) / (t2 - t1)), sp_v3_scale(b2, (t - t1) / (t2 - t1)));
        }
    }
    pts[k++] = ctrl[n - 1];
    sp_gen_path_points(out, pts, k);
    free(pts);
}

void sp_gen_path_free(sp_gen_path* p)
{
    free(p->p), free(p->s);
    memset(p, 0, sizeof *p);
}

sp_vec3 sp_gen_path_at(const sp_gen_path* p, double s, sp_vec3* tangent)
{
    s = sp_gen_clamp(s, 0.0, p->length);
    // Binary search for the segment holding s.
    int lo = 0, hi = p->n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (p->s[mid] <= s)
            lo = mid;
        else
            hi = mid;
    }
    double len = p->s[hi] - p->s[lo];
    double t = len > 0 ? (s - p->s[lo]) / len : 0.0;
    if (tangent) {
        // Central difference over neighbouring segments for a smooth frame.
        int a = lo > 0 ? lo - 1 : lo, b = hi + 1 < p->n ? hi + 1 : hi;
        sp_vec3 d0 = sp_v3_sub(p->p[hi], p->p[a]), d1 = sp_v3_sub(p->p[b], p->p[lo]);
        *tangent = sp_v3_norm(sp_v3_add(sp_v3_scale(d0, 1.0 - t), sp_v3_scale(d1, t)));
    }
    return sp_v3_add(p->p[lo], sp_v3_scale(sp_v3_sub(p->p[hi], p->p[lo]), t));
}

double sp_gen_path_project(const sp_gen_path* p, sp_vec3 q)
{
    double best = INFINITY, best_s = 0.0;
    for (int i = 0; i + 1 < p->n; ++i) {
        sp_vec3 d = sp_v3_sub(p->p[i + 1], p->p[i]);
        double dd = sp_v3_dot(d, d);
        double t = dd > 0 ? sp_gen_clamp(sp_v3_dot(sp_v3_sub(q, p->p[i]), d) / dd, 0.0, 1.0) : 0.0;
        sp_vec3 c = sp_v3_add(p->p[i], sp_v3_scale(d, t));
        double e = sp_v3_len(sp_v3_sub(q, c));
        if (e < best) best = e, best_s = p->s[i] + t * (p->s[i + 1] - p->s[i]);
    }
    return best_s;
}

sp_vec3 sp_gen_bezier2(sp_vec3 a, sp_vec3 c, sp_vec3 b, double t)
{
    double u = 1.0 - t;
    return sp_v3_add(sp_v3_add(sp_v3_scale(a, u * u), sp_v3_scale(c, 2.0 * u * t)), sp_v3_scale(b, t * t));
}

// ---- chains --------------------------------------------------------------

void sp_gen_chain_add(sp_gen_chain* c, int joint, double station, double blend)
{
    if (c->count >= SP_GEN_CHAIN_MAX) {
        fprintf(stderr, "sp-assetgen: bone chain longer than %d joints\n", SP_GEN_CHAIN_MAX);
        exit(1);
    }
    c->joint[c->count] = joint, c->station[c->count] = station, c->blend[c->count] = blend;
    ++c->count;
}

sp_gen_skin sp_gen_chain_skin(const sp_gen_chain* c, double s)
{
    // t_k: how much of the weight has passed station k (t_0 = 1).
    double t_prev = 1.0;
    sp_gen_skin r = {0};
    for (int k = 0; k < c->count; ++k) {
        double t_next = 0.0;
        if (k + 1 < c->count) {
            double a = c->station[k + 1];
            double left = a - c->station[k];
            double right = k + 2 < c->count ? c->station[k + 2] - a : INFINITY;
            double b = fmin(c->blend[k + 1], 0.5 * fmin(left, right));
            t_next = b > 0 ? sp_gen_smoothstep(a - b, a + b, s) : (s >= a ? 1.0 : 0.0);
        }
        sp_gen_skin_add(&r, c->joint[k], t_prev - t_next);
        t_prev = t_next;
    }
    return r;
}

// ---- tubes ---------------------------------------------------------------

static sp_vec3 section_point(sp_vec3 c, sp_vec3 N, sp_vec3 B, sp_gen_section sec, double a, double f)
{
    double ca = cos(a), sa = sin(a);
    double h = ca >= 0 ? sec.up : sec.down;
    return sp_v3_add(c, sp_v3_add(sp_v3_scale(N, ca * h * f), sp_v3_scale(B, sa * sec.side * f)));
}

static void section_frame(sp_vec3 T, sp_vec3 side, sp_vec3* N, sp_vec3* B)
{
    sp_vec3 b = sp_v3_sub(side, sp_v3_scale(T, sp_v3_dot(side, T)));
    if (sp_v3_len(b) < 1e-9) b = sp_v3_cross(T, sp_v3(0, 1, 0));
    *B = sp_v3_norm(b);
    *N = sp_v3_norm(sp_v3_cross(*B, T));
}

// Joins ring r0 (first vertex i0) to ring r1 (first vertex i1), `n` vertices each, outward winding.
static void stitch(sp_gen_mesh* m, int i0, int i1, int n)
{
    for (int j = 0; j < n; ++j) {
        int j1 = (j + 1) % n;
        sp_gen_mesh_tri(m, i0 + j, i0 + j1, i1 + j);
        sp_gen_mesh_tri(m, i0 + j1, i1 + j1, i1 + j);
    }
}

int sp_gen_tube(sp_gen_mesh* m, const sp_gen_tube_desc* d)
{
    int first = m->vertex_count;
    double s0 = d->s0, s1 = d->s1 > 0 ? d->s1 : d->path->length;
    sp_vec3 side = sp_v3_len(d->side) > 0 ? sp_v3_norm(d->side) : sp_v3(0, 0, 1);
    int R = d->rings, S = d->segments;
    sp_vec3 zoff = sp_v3(0, 0, d->z_offset);

    // One ring: the section at arc length s scaled by f, pushed along T by `push`.
    sp_vec3 T_end[2], C_end[2], N_end[2], B_end[2];
    sp_gen_section sec_end[2];
    sp_gen_skin skin_end[2];
    for (int i = 0; i < R; ++i) {
        double u = (double)i / (R - 1);
        double s = s0 + (s1 - s0) * u;
        sp_vec3 T;
        sp_vec3 c = sp_gen_path_at(d->path, s, &T);
        sp_vec3 N, B;
        section_frame(T, side, &N, &B);
        sp_gen_section sec = d->profile(u, d->user);
        sp_gen_skin sk = d->chain ? sp_gen_chain_skin(d->chain, s) : d->skin;
        if (d->skin_at) sk = d->skin_at(s, &sk, d->user);
        if (i == 0 || i == R - 1) {
            int e = i == 0 ? 0 : 1;
            T_end[e] = T, C_end[e] = c, N_end[e] = N, B_end[e] = B, sec_end[e] = sec, skin_end[e] = sk;
        }
        for (int j = 0; j < S; ++j) {
            double a = 2.0 * k_pi * j / S;
            double f = d->bump ? d->bump(u, a, d->user) : 1.0;
            sp_vec3 p = sp_v3_add(section_point(c, N, B, sec, a, f), zoff);
            sp_gen_rgb col = d->color(u, a, p, d->user);
            sp_gen_mesh_vertex(m, p, col, &sk);
        }
        if (i > 0) stitch(m, first + (i - 1) * S, first + i * S, S);
    }
    // Caps: quarter-circle profile to a pole, skinned like the end ring.
    for (int e = 0; e < 2; ++e) {
        int K = e == 0 ? d->cap0_rings : d->cap1_rings;
        if (K <= 0) continue;
        double len = (e == 0 ? d->cap0_len : d->cap1_len) * (sec_end[e].up + sec_end[e].down + 2.0 * sec_end[e].side) * 0.25;
        sp_vec3 dir = e == 0 ? sp_v3_scale(T_end[e], -1.0) : T_end[e];
        double u = (double)e;
        int prev = e == 0 ? first : first + (R - 1) * S;
        for (int k = 1; k <= K + 1; ++k) {
            double th = 0.5 * k_pi * k / (K + 1);
            sp_vec3 c = sp_v3_add(C_end[e], sp_v3_scale(dir, len * sin(th)));
            if (k == K + 1) {
                sp_vec3 p = sp_v3_add(c, zoff);
                int pole = sp_gen_mesh_vertex(m, p, d->color(u, e == 0 ? k_pi : 0.0, p, d->user), &skin_end[e]);
                for (int j = 0; j < S; ++j) {
                    int j1 = (j + 1) % S;
                    if (e == 0)
                        sp_gen_mesh_tri(m, prev + j1, prev + j, pole);
                    else
                        sp_gen_mesh_tri(m, prev + j, prev + j1, pole);
                }
                break;
            }
            int ring = m->vertex_count;
            for (int j = 0; j < S; ++j) {
                double a = 2.0 * k_pi * j / S;
                double f = (d->bump ? d->bump(u, a, d->user) : 1.0) * cos(th);
                sp_vec3 p = sp_v3_add(section_point(c, N_end[e], B_end[e], sec_end[e], a, f), zoff);
                sp_gen_mesh_vertex(m, p, d->color(u, a, p, d->user), &skin_end[e]);
            }
            if (e == 0)
                stitch(m, ring, prev, S);
            else
                stitch(m, prev, ring, S);
            prev = ring;
        }
    }
    return first;
}

// ---- cones ---------------------------------------------------------------

typedef struct cone_ctx {
    const sp_gen_cone_desc* d;
} cone_ctx;

static sp_gen_section cone_profile(double u, void* user)
{
    const sp_gen_cone_desc* d = ((cone_ctx*)user)->d;
    double r = d->tip_radius + (d->base_radius - d->tip_radius) * pow(1.0 - u, d->taper > 0 ? d->taper : 1.0);
    double f = d->flat > 0 ? d->flat : 1.0;
    return (sp_gen_section){r, r, r * f};
}

static sp_gen_rgb cone_color(double u, double a, sp_vec3 p, void* user)
{
    (void)a, (void)p;
    const sp_gen_cone_desc* d = ((cone_ctx*)user)->d;
    return sp_gen_mix(d->base_color, d->tip_color, sp_gen_smoothstep(0.3, 1.0, u));
}

int sp_gen_cone(sp_gen_mesh* m, const sp_gen_cone_desc* d)
{
    enum { N = 24 };
    sp_vec3 pts[N + 1];
    for (int i = 0; i <= N; ++i)
        pts[i] = sp_gen_bezier2(d->base, d->bend, d->tip, (double)i / N);
    sp_gen_path path;
    sp_gen_path_points(&path, pts, N + 1);
    cone_ctx ctx = {d};
    // Stop short of the tip by the tip radius so the rounded cap ends there.
    double s1 = path.length - d->tip_radius;
    if (s1 < 0.5 * path.length) s1 = 0.5 * path.length;
    int first = sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                                   .s1 = s1,
                                                   .rings = d->rings,
                                                   .segments = d->segments,
                                                   .side = d->side,
                                                   .profile = cone_profile,
                                                   .color = cone_color,
                                                   .user = &ctx,
                                                   .skin = d->skin,
                                                   .cap1_rings = 2,
                                                   .cap1_len = 1.0});
    sp_gen_path_free(&path);
    return first;
}

// ---- ellipsoids ----------------------------------------------------------

int sp_gen_ellipsoid(sp_gen_mesh* m, const sp_gen_ellipsoid_desc* d)
{
    int first = m->vertex_count;
    int R = d->rings, S = d->segments;
    // Poles at center -+ ax; rings in between.
    sp_vec3 p0 = sp_v3_sub(d->center, d->ax);
    int pole0 = sp_gen_mesh_vertex(m, p0, d->color(0.0, 0.0, p0, d->user), &d->skin);
    int prev = -1;
    for (int i = 1; i < R; ++i) {
        double th = k_pi * i / R;
        double u = (double)i / R;
        int ring = m->vertex_count;
        for (int j = 0; j < S; ++j) {
            double a = 2.0 * k_pi * j / S;
            sp_vec3 p =
                sp_v3_add(d->center, sp_v3_add(sp_v3_scale(d->ax, -cos(th)), sp_v3_add(sp_v3_scale(d->ay, sin(th) * cos(a)),
                                                                                       sp_v3_scale(d->az, sin(th) * sin(a)))));
            sp_gen_mesh_vertex(m, p, d->color(u, a, p, d->user), &d->skin);
        }
        if (prev < 0) {
            for (int j = 0; j < S; ++j)
                sp_gen_mesh_tri(m, pole0, ring + (j + 1) % S, ring + j);
        } else {
            stitch(m, prev, ring, S);
        }
        prev = ring;
    }
    sp_vec3 p1 = sp_v3_add(d->center, d->ax);
    int pole1 = sp_gen_mesh_vertex(m, p1, d->color(1.0, 0.0, p1, d->user), &d->skin);
    for (int j = 0; j < S; ++j)
        sp_gen_mesh_tri(m, prev + j, prev + (j + 1) % S, pole1);
    return first;
}

// ---- membranes -----------------------------------------------------------

void sp_gen_curve_push(sp_gen_curve* c, sp_vec3 p, const sp_gen_skin* skin)
{
    c->p = sp_gen_check_alloc(realloc(c->p, sizeof(sp_vec3) * (size_t)(c->n + 1)));
    c->skin = sp_gen_check_alloc(realloc(c->skin, sizeof(sp_gen_skin) * (size_t)(c->n + 1)));
    c->p[c->n] = p;
    c->skin[c->n] = *skin;
    ++c->n;
}

void sp_gen_curve_finish(sp_gen_curve* c)
{
    c->s = sp_gen_check_alloc(realloc(c->s, sizeof(double) * (size_t)c->n));
    c->s[0] = 0.0;
    for (int i = 1; i < c->n; ++i)
        c->s[i] = c->s[i - 1] + sp_v3_len(sp_v3_sub(c->p[i], c->p[i - 1]));
    double L = c->s[c->n - 1];
    for (int i = 1; i < c->n; ++i)
        c->s[i] = L > 0 ? c->s[i] / L : (double)i / (c->n - 1);
}

void sp_gen_curve_free(sp_gen_curve* c)
{
    free(c->p), free(c->skin), free(c->s);
    memset(c, 0, sizeof *c);
}

sp_vec3 sp_gen_curve_at(const sp_gen_curve* c, double t, sp_gen_skin* skin)
{
    t = sp_gen_clamp(t, 0.0, 1.0);
    int i = 0;
    while (i + 2 < c->n && c->s[i + 1] < t)
        ++i;
    double len = c->s[i + 1] - c->s[i];
    double f = len > 0 ? sp_gen_clamp((t - c->s[i]) / len, 0.0, 1.0) : 0.0;
    if (skin) *skin = sp_gen_skin_lerp(&c->skin[i], &c->skin[i + 1], f);
    return sp_v3_add(c->p[i], sp_v3_scale(sp_v3_sub(c->p[i + 1], c->p[i]), f));
}

int sp_gen_membrane(sp_gen_mesh* m, const sp_gen_membrane_desc* d)
{
    int first = m->vertex_count;
    int ns = d->ns, nt = d->nt;
    sp_vec3 P00 = sp_gen_curve_at(d->inner, 0, NULL), P01 = sp_gen_curve_at(d->inner, 1, NULL);
    sp_vec3 P10 = sp_gen_curve_at(d->outer, 0, NULL), P11 = sp_gen_curve_at(d->outer, 1, NULL);
    for (int layer = 0; layer < 2; ++layer) {
        double z = layer == 0 ? 0.5 * d->thickness : -0.5 * d->thickness;
        for (int i = 0; i < ns; ++i) {
            double s = (double)i / (ns - 1);
            sp_gen_skin k0, k1;
            sp_vec3 e0 = sp_gen_curve_at(d->side0, s, &k0), e1 = sp_gen_curve_at(d->side1, s, &k1);
            for (int j = 0; j < nt; ++j) {
                double t = (double)j / (nt - 1);
                sp_vec3 c0 = sp_gen_curve_at(d->inner, t, NULL), c1 = sp_gen_curve_at(d->outer, t, NULL);
                sp_vec3 p = sp_v3_add(sp_v3_scale(c0, 1.0 - s), sp_v3_scale(c1, s));
                p = sp_v3_add(p, sp_v3_add(sp_v3_scale(e0, 1.0 - t), sp_v3_scale(e1, t)));
                sp_vec3 bl = sp_v3_add(sp_v3_add(sp_v3_scale(P00, (1 - s) * (1 - t)), sp_v3_scale(P01, (1 - s) * t)),
                                       sp_v3_add(sp_v3_scale(P10, s * (1 - t)), sp_v3_scale(P11, s * t)));
                p = sp_v3_sub(p, bl);
                p.z += z;
                sp_gen_skin sk = sp_gen_skin_lerp(&k0, &k1, t);
                if (d->skin) sk = d->skin(sp_v3(p.x, p.y, p.z - z), &sk, d->user);
                sp_gen_mesh_vertex(m, p, d->color(s, t, p, d->user), &sk);
            }
        }
    }
    // Which way is "front" depends on the handedness of (s, t): decide from
    // the patch's own orientation so that layer 0 faces +Z.
    sp_vec3 a = sp_v3_sub(sp_gen_curve_at(d->outer, 0.5, NULL), sp_gen_curve_at(d->inner, 0.5, NULL));
    sp_vec3 b = sp_v3_sub(sp_gen_curve_at(d->side1, 0.5, NULL), sp_gen_curve_at(d->side0, 0.5, NULL));
    bool st_ccw = sp_v3_cross(a, b).z > 0; // s then t turns counter-clockwise seen from +Z
    int L = ns * nt;
    for (int layer = 0; layer < 2; ++layer) {
        bool flip = (layer == 0) != st_ccw;
        int o = first + layer * L;
        for (int i = 0; i + 1 < ns; ++i)
            for (int j = 0; j + 1 < nt; ++j) {
                int v00 = o + i * nt + j, v10 = v00 + nt, v01 = v00 + 1, v11 = v10 + 1;
                if (!flip) {
                    sp_gen_mesh_tri(m, v00, v10, v11);
                    sp_gen_mesh_tri(m, v00, v11, v01);
                } else {
                    sp_gen_mesh_tri(m, v00, v11, v10);
                    sp_gen_mesh_tri(m, v00, v01, v11);
                }
            }
    }
    // Rim: walk the boundary of the grid and join the layers.
    int perim = 2 * (ns - 1) + 2 * (nt - 1);
    int* loop = sp_gen_check_alloc(malloc(sizeof(int) * (size_t)perim));
    int k = 0;
    for (int j = 0; j < nt - 1; ++j)
        loop[k++] = j; // s = 0, t up
    for (int i = 0; i < ns - 1; ++i)
        loop[k++] = i * nt + (nt - 1); // t = 1, s up
    for (int j = nt - 1; j > 0; --j)
        loop[k++] = (ns - 1) * nt + j; // s = 1, t down
    for (int i = ns - 1; i > 0; --i)
        loop[k++] = i * nt; // t = 0, s down
    for (int q = 0; q < perim; ++q) {
        int a0 = first + loop[q], a1 = first + loop[(q + 1) % perim];
        int b0 = a0 + L, b1 = a1 + L;
        // The loop runs (t up, s up, t down, s down): clockwise in (s, t), so
        // clockwise seen from +Z when st_ccw; outward is then to its left.
        if (!st_ccw) {
            sp_gen_mesh_tri(m, a0, b0, a1);
            sp_gen_mesh_tri(m, a1, b0, b1);
        } else {
            sp_gen_mesh_tri(m, a0, a1, b0);
            sp_gen_mesh_tri(m, a1, b1, b0);
        }
    }
    free(loop);
    return first;
}
