// embed.c: projecting a drawn curve onto the mesh (draw-over posing, eq. 2).
#include "sp/embed.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/curve.h"

void sp_camera_ray(const sp_camera* cam, sp_vec2 px, sp_vec3* origin, sp_vec3* dir)
{
    sp_mat4 inv;
    sp_mat4_inverse(&cam->view, &inv);
    double x = (px.x - cam->cx), y = (cam->cy - px.y);
    if (cam->kind == SP_CAMERA_ORTHOGRAPHIC) {
        sp_vec3 c = {x / cam->scale, y / cam->scale, -cam->znear};
        *origin = sp_mat4_point(&inv, c);
        *dir = sp_v3_norm(sp_mat4_dir(&inv, (sp_vec3){0, 0, -1}));
    } else {
        *origin = sp_mat4_translation(&inv);
        *dir = sp_v3_norm(sp_mat4_dir(&inv, (sp_vec3){x / cam->scale, y / cam->scale, -1}));
    }
}

// Moller-Trumbore: distance along the ray and barycentrics, or false.
static bool ray_triangle(sp_vec3 o, sp_vec3 d, sp_vec3 a, sp_vec3 b, sp_vec3 c, double* t, double* u, double* v)
{
    sp_vec3 e1 = sp_v3_sub(b, a), e2 = sp_v3_sub(c, a);
    sp_vec3 p = sp_v3_cross(d, e2);
    double det = sp_v3_dot(e1, p);
    if (fabs(det) < 1e-18) return false;
    double inv = 1.0 / det;
    sp_vec3 s = sp_v3_sub(o, a);
    *u = sp_v3_dot(s, p) * inv;
    if (*u < 0 || *u > 1) return false;
    sp_vec3 q = sp_v3_cross(s, e1);
    *v = sp_v3_dot(d, q) * inv;
    if (*v < 0 || *u + *v > 1) return false;
    *t = sp_v3_dot(e2, q) * inv;
    return *t >= 0;
}

static sp_vec3 vtx(const double* xyz, uint32_t i) { return (sp_vec3){xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }

sp_result sp_embed_curve(const sp_rig* rig, const double* xyz, const sp_camera* cam, const sp_vec2* px, int n, int samples,
                         const char* name, sp_abstraction* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (samples < 2) samples = 2;
    if (n < 2 || !sp_curve_is_valid(px, n)) return sp_fail(err, SP_ERR_INVALID, "the draw-over stroke needs 2 or more finite points");
    if (rig->triangle_count <= 0) return sp_fail(err, SP_ERR_INVALID, "the rig has no triangles to draw over");
    sp_vec2* s = malloc(sizeof(sp_vec2) * (size_t)samples);
    out->curves = calloc(1, sizeof(sp_curve));
    out->tri_vertices = malloc(sizeof(uint32_t) * 3 * (size_t)samples);
    out->bary = malloc(sizeof(double) * 3 * (size_t)samples);
    if (!s || !out->curves || !out->tri_vertices || !out->bary) {
        free(s);
        sp_abstraction_free(out);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while embedding the curve");
    }
    sp_curve_resample(px, n, false, samples, s);
    double diag = hypot(cam->width, cam->height), snap = 0.04 * diag;
    int hits = 0;
    for (int k = 0; k < samples; ++k) {
        sp_vec3 o, d;
        sp_camera_ray(cam, s[k], &o, &d);
        double best = DBL_MAX, bu = 0, bv = 0;
        int bt = -1;
        for (int t = 0; t < rig->triangle_count; ++t) {
            const uint32_t* tr = rig->triangles + 3 * t;
            double dist, u, v;
            if (ray_triangle(o, d, vtx(xyz, tr[0]), vtx(xyz, tr[1]), vtx(xyz, tr[2]), &dist, &u, &v) && dist < best)
                best = dist, bt = t, bu = u, bv = v;
        }
        uint32_t* tv = out->tri_vertices + 3 * k;
        double* b = out->bary + 3 * k;
        if (bt >= 0) {
            memcpy(tv, rig->triangles + 3 * bt, sizeof(uint32_t) * 3);
            b[0] = 1.0 - bu - bv, b[1] = bu, b[2] = bv;
            ++hits;
            continue;
        }
        // Missed: the nearest vertex in the image, if close enough.
        double bd = DBL_MAX;
        uint32_t bi = 0;
        for (int i = 0; i < rig->vertex_count; ++i) {
            sp_vec2 q = sp_camera_project(cam, vtx(xyz, (uint32_t)i));
            double dd = sp_v2_len(sp_v2_sub(q, s[k]));
            if (dd < bd) bd = dd, bi = (uint32_t)i;
        }
        tv[0] = tv[1] = tv[2] = bi;
        b[0] = 1.0, b[1] = b[2] = 0.0;
        if (bd <= snap) ++hits;
    }
    free(s);
    if (hits * 2 < samples) {
        sp_abstraction_free(out);
        return sp_fail(err, SP_ERR_INVALID, "the draw-over stroke is not on the character (%d of %d samples land on it)", hits, samples);
    }
    snprintf(out->name, sizeof out->name, "%s", name ? name : "drawover");
    snprintf(out->curves[0].name, sizeof out->curves[0].name, "%s", out->name);
    out->correspondence = SP_CORR_ORDERED;
    out->curve_count = 1;
    out->curves[0].point_count = samples;
    out->point_count = samples;
    return SP_OK;
}

int sp_rig_add_abstraction(sp_rig* rig, const sp_abstraction* a)
{
    sp_abstraction* grown = realloc(rig->abstractions, sizeof(sp_abstraction) * (size_t)(rig->abstraction_count + 1));
    if (!grown) return -1;
    rig->abstractions = grown;
    sp_abstraction* d = &rig->abstractions[rig->abstraction_count];
    *d = *a;
    size_t np = (size_t)a->point_count;
    d->curves = malloc(sizeof(sp_curve) * (size_t)a->curve_count);
    d->rest = a->rest ? malloc(sizeof(double) * 3 * np) : NULL;
    d->joints = a->joints ? malloc(sizeof(uint16_t) * 4 * np) : NULL;
    d->weights = a->weights ? malloc(sizeof(float) * 4 * np) : NULL;
    d->tri_vertices = a->tri_vertices ? malloc(sizeof(uint32_t) * 3 * np) : NULL;
    d->bary = a->bary ? malloc(sizeof(double) * 3 * np) : NULL;
    if (!d->curves || (a->rest && !d->rest) || (a->joints && !d->joints) || (a->weights && !d->weights) ||
        (a->tri_vertices && !d->tri_vertices) || (a->bary && !d->bary)) {
        sp_abstraction_free(d);
        return -1;
    }
    memcpy(d->curves, a->curves, sizeof(sp_curve) * (size_t)a->curve_count);
    if (a->rest) memcpy(d->rest, a->rest, sizeof(double) * 3 * np);
    if (a->joints) memcpy(d->joints, a->joints, sizeof(uint16_t) * 4 * np);
    if (a->weights) memcpy(d->weights, a->weights, sizeof(float) * 4 * np);
    if (a->tri_vertices) memcpy(d->tri_vertices, a->tri_vertices, sizeof(uint32_t) * 3 * np);
    if (a->bary) memcpy(d->bary, a->bary, sizeof(double) * 3 * np);
    return rig->abstraction_count++;
}
