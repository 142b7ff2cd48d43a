// part_shapes.c: what of a part a synthetic sketch shows (sp/handdraw.h,
// sp_handdraw_shape): the mesh's silhouette with its decorations, the upper
// or lower side of a closed outline, a single line through a chain-shaped
// skeleton, a piece of the part, and spikes or teeth added along a stretch of
// a curve. These are clean drawings; the hand-drawing model perturbs them
// afterwards.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sp/curve.h"
#include "sp/gltf.h"
#include "sp/handdraw.h"
#include "sp/outline.h"
#include "sp/synth.h"

// Points of a traced silhouette (the abstractions have 150).
#define SIL_POINTS 200

// ---- silhouette -----------------------------------------------------------

// The silhouette of the posed mesh (sp_outline_trace on the skinned
// vertices), or with `keep` (vertex_count flags) of the triangles whose
// three vertices are kept.
static sp_result silhouette(const sp_rig* rig, const sp_camera* cam, const double* p, const unsigned char* keep, sp_sketch* out)
{
    int V = rig->vertex_count, T = rig->triangle_count;
    if (V < 3 || T < 1 || !rig->joints4 || !rig->weights4) return SP_ERR_INVALID;
    double* xyz = malloc(sizeof(double) * 3 * (size_t)V);
    double* w = malloc(sizeof(double) * 4 * (size_t)V);
    unsigned char *skip_v = keep ? malloc((size_t)V) : NULL, *skip_t = keep ? malloc((size_t)T) : NULL;
    sp_vec2* pts = malloc(sizeof(sp_vec2) * (SIL_POINTS + 1));
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    sp_abstraction ab = {0};
    sp_result r = SP_ERR_NO_MEMORY;
    if (!xyz || !w || (keep && (!skip_v || !skip_t)) || !pts || !ev) goto done;
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    for (int i = 0; i < 4 * V; ++i)
        w[i] = rig->weights4[i];
    for (int i = 0; keep && i < V; ++i)
        skip_v[i] = !keep[i];
    for (int t = 0; keep && t < T; ++t) {
        const uint32_t* q = &rig->triangles[3 * t];
        skip_t[t] = !(keep[q[0]] && keep[q[1]] && keep[q[2]]);
    }
    sp_outline_desc od = {.vertex_count = V,
                          .positions = xyz,
                          .influences = 4,
                          .joints = rig->joints4,
                          .weights = w,
                          .triangle_count = T,
                          .triangles = rig->triangles,
                          .skip_vertex = skip_v,
                          .skip_triangle = skip_t,
                          .camera = cam,
                          .points = SIL_POINTS,
                          .keep_largest = true};
    sp_error e = {0};
    if ((r = sp_outline_trace(&od, &ab, NULL, &e)) != SP_OK) goto done;
    for (int i = 0; i < SIL_POINTS; ++i)
        pts[i] = sp_camera_project(cam, (sp_vec3){ab.rest[3 * i], ab.rest[3 * i + 1], ab.rest[3 * i + 2]});
    pts[SIL_POINTS] = pts[0];
    out->canvas_w = cam->width, out->canvas_h = cam->height;
    r = sp_sketch_add_stroke(out, pts, NULL, SIL_POINTS + 1);
done:
    sp_abstraction_free(&ab);
    sp_rig_eval_destroy(ev);
    free(xyz);
    free(w);
    free(skip_v);
    free(skip_t);
    free(pts);
    return r;
}

// ---- a piece: the far end of the part --------------------------------------

// Flags the vertices whose strongest joint lies in the subtree of a joint
// whose subtree holds 25-75% of the vertices: the smallest such subtree that
// still holds half of them when there is one (the head without its neck, the
// hand of a wing, the far half of a tail: what a visitor draws as the part),
// else one drawn at random (one leg of a pair). False when no joint qualifies.
static bool piece_vertices(const sp_rig* rig, uint64_t seed, unsigned char* keep)
{
    int J = rig->joint_count, V = rig->vertex_count;
    int* strongest = malloc(sizeof(int) * (size_t)(V > 0 ? V : 1));
    int* count = calloc((size_t)(J > 0 ? J : 1), sizeof(int));
    bool ok = false;
    if (!strongest || !count) goto done;
    for (int v = 0; v < V; ++v) {
        int best = 0;
        for (int k = 1; k < 4; ++k)
            if (rig->weights4[4 * v + k] > rig->weights4[4 * v + best]) best = k;
        strongest[v] = rig->joints4[4 * v + best];
    }
    // count[j]: vertices in j's subtree (children come after parents: sum backwards).
    for (int v = 0; v < V; ++v)
        if (strongest[v] >= 0 && strongest[v] < J) count[strongest[v]]++;
    for (int j = J - 1; j > 0; --j)
        if (rig->joints[j].parent >= 0) count[rig->joints[j].parent] += count[j];
    int cand[256], nc = 0;
    for (int j = 1; j < J && nc < 256; ++j)
        if (count[j] >= V / 4 && count[j] <= 3 * V / 4) cand[nc++] = j;
    if (nc == 0) goto done;
    sp_rng rng = {seed ^ 0x2545F4914F6CDD1Dull};
    int pick = cand[(int)(sp_rng_uniform(&rng) * nc)];
    for (int k = 0, best = V + 1; k < nc; ++k)
        if (count[cand[k]] >= V / 2 && count[cand[k]] < best) best = count[cand[k]], pick = cand[k];
    for (int v = 0; v < V; ++v) {
        int j = strongest[v] < J ? strongest[v] : -1;
        while (j >= 0 && j != pick)
            j = rig->joints[j].parent;
        keep[v] = j == pick;
    }
    ok = true;
done:
    free(strongest);
    free(count);
    return ok;
}

// ---- a single line through the joints -------------------------------------

bool sp_handdraw_shape_available(const sp_rig* rig, sp_handdraw_shape shape)
{
    if (shape == SP_HANDDRAW_SHAPE_PIECE) {
        unsigned char* keep = malloc((size_t)(rig->vertex_count > 0 ? rig->vertex_count : 1));
        bool ok = keep && rig->weights4 && piece_vertices(rig, 1, keep);
        free(keep);
        return ok;
    }
    if (shape != SP_HANDDRAW_SHAPE_LINE) return shape >= 0 && shape < SP_HANDDRAW_SHAPE_COUNT;
    int order[2];
    return sp_rig_line_joints(rig, order, 2) > 0;
}

static sp_result centre_line(const sp_rig* rig, const sp_camera* cam, const double* p, sp_sketch* out)
{
    int* order = malloc(sizeof(int) * ((size_t)rig->joint_count + 1));
    sp_vec2* pts = malloc(sizeof(sp_vec2) * ((size_t)rig->joint_count + 4));
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    sp_result r = SP_OK;
    if (!order || !pts || !ev) {
        r = SP_ERR_NO_MEMORY;
        goto done;
    }
    int no = sp_rig_line_joints(rig, order, rig->joint_count);
    if (no == 0) {
        r = SP_ERR_INVALID;
        goto done;
    }
    sp_rig_eval_update(ev, p, false);
    const sp_mat4* G = sp_rig_eval_world(ev);
    // Joint pivots (the world transforms' translations), each end pushed on
    // by its last bone's length: a leaf joint is where the tip starts.
    int n = 0;
    for (int i = 0; i < no; ++i) {
        const double* m = G[order[i]].m;
        pts[n++] = sp_camera_project(cam, (sp_vec3){m[12], m[13], m[14]});
    }
    if (n >= 2) {
        sp_vec2 e0 = sp_v2_add(pts[0], sp_v2_scale(sp_v2_sub(pts[0], pts[1]), 0.8));
        sp_vec2 e1 = sp_v2_add(pts[n - 1], sp_v2_scale(sp_v2_sub(pts[n - 1], pts[n - 2]), 0.8));
        memmove(pts + 1, pts, sizeof *pts * (size_t)n);
        pts[0] = e0;
        pts[++n] = e1;
        ++n;
    }
    out->canvas_w = cam->width, out->canvas_h = cam->height;
    sp_curve_smooth(pts, n, false, 1, pts);
    r = n >= 2 ? sp_sketch_add_stroke(out, pts, NULL, n) : SP_ERR_INVALID;
done:
    free(order);
    free(pts);
    sp_rig_eval_destroy(ev);
    return r;
}

// ---- partial outlines and added spikes --------------------------------------

// The upper (top) or lower side of a closed curve: the run between its
// leftmost and rightmost points that lies above (below) the other.
static sp_result half_side(const sp_sketch* closed_sk, bool top, sp_sketch* out)
{
    const sp_stroke* s = &closed_sk->strokes[0];
    int n = s->count - 1; // the last point repeats the first
    if (n < 8) return SP_ERR_INVALID;
    int il = 0, ir = 0;
    for (int i = 1; i < n; ++i) {
        if (s->points[i].x < s->points[il].x) il = i;
        if (s->points[i].x > s->points[ir].x) ir = i;
    }
    // Two runs: il -> ir and ir -> il (cyclic); the top one has the smaller mean y.
    sp_vec2* run[2];
    int len[2];
    double mean[2];
    for (int k = 0; k < 2; ++k) {
        int from = k == 0 ? il : ir, to = k == 0 ? ir : il;
        len[k] = (to - from + n) % n + 1;
        run[k] = malloc(sizeof(sp_vec2) * (size_t)len[k]);
        mean[k] = 0;
        for (int i = 0; run[k] && i < len[k]; ++i) {
            run[k][i] = s->points[(from + i) % n];
            mean[k] += run[k][i].y / len[k];
        }
    }
    sp_result r = SP_ERR_NO_MEMORY;
    if (run[0] && run[1]) {
        int pick = (mean[0] < mean[1]) == top ? 0 : 1;
        out->canvas_w = closed_sk->canvas_w, out->canvas_h = closed_sk->canvas_h;
        r = len[pick] >= 3 ? sp_sketch_add_stroke(out, run[pick], NULL, len[pick]) : SP_ERR_INVALID;
    }
    free(run[0]);
    free(run[1]);
    return r;
}

// Replaces a stretch of the (single-stroke) curve by a row of spikes or
// teeth standing outward: a detail the visitor adds that the part lacks.
static sp_result add_spikes(sp_sketch* sk, sp_rng* rng)
{
    sp_stroke* s = &sk->strokes[0];
    bool closed = s->count >= 4 && sp_v2_len(sp_v2_sub(s->points[0], s->points[s->count - 1])) < 1e-9;
    int n = closed ? s->count - 1 : s->count;
    if (n < 8) return SP_OK;
    double L = sp_curve_length(s->points, n, closed);
    enum { M = 240 };
    sp_vec2 dense[M];
    sp_result r = sp_curve_resample(s->points, n, closed, M, dense);
    if (r != SP_OK) return r;
    // Outward: for a closed curve the side away from the enclosed area (by the
    // signed area); for an open one, a random side.
    double area = 0;
    for (int i = 0; i < M; ++i)
        area += dense[i].x * dense[(i + 1) % M].y - dense[(i + 1) % M].x * dense[i].y;
    double side = closed ? (area > 0 ? -1.0 : 1.0) : (sp_rng_uniform(rng) < 0.5 ? -1.0 : 1.0);
    int run = (int)(M * sp_rng_range(rng, 0.12, 0.35));
    int start = closed ? (int)(sp_rng_uniform(rng) * M) : (int)(sp_rng_uniform(rng) * (M - run - 1));
    int teeth = 3 + (int)(sp_rng_uniform(rng) * 6);
    double height = sp_rng_range(rng, 0.025, 0.07) * L / (closed ? 2.5 : 1.5);
    sp_vec2* outp = malloc(sizeof(sp_vec2) * (M + 1)); // at most one point per sample, and the closing one
    if (!outp) return SP_ERR_NO_MEMORY;
    int k = 0;
    for (int i = 0; i < M; ++i) {
        int j = (start + i) % M;
        if (!closed) j = i;
        bool in_run = closed ? i < run : (j >= start && j < start + run);
        int pos = closed ? i : j - start;
        if (!in_run || pos == 0) {
            outp[k++] = dense[j];
            continue;
        }
        // Inside the run: only the teeth's corners (a base point, then a tip).
        int step = run / teeth;
        if (step < 2) step = 2;
        if (pos % step == 0)
            outp[k++] = dense[j];
        else if (pos % step == step / 2) {
            sp_vec2 t = sp_v2_sub(dense[(j + 1) % M], dense[(j - 1 + M) % M]);
            double tl = sp_v2_len(t);
            if (tl > 0) outp[k++] = sp_v2_add(dense[j], sp_v2_scale((sp_vec2){t.y / tl, -t.x / tl}, side * height));
        }
    }
    if (closed) outp[k++] = outp[0];
    sp_sketch spiky = {.canvas_w = sk->canvas_w, .canvas_h = sk->canvas_h};
    r = sp_sketch_add_stroke(&spiky, outp, NULL, k);
    free(outp);
    if (r == SP_OK) {
        sp_sketch_free(sk);
        *sk = spiky;
    }
    return r;
}

sp_result sp_handdraw_clean_shape(const sp_rig* rig, int abstraction, const sp_camera* cam, const double* p,
                                  sp_handdraw_shape shape, bool details, double spikes, uint64_t seed, sp_sketch* out)
{
    memset(out, 0, sizeof *out);
    sp_result r;
    const sp_abstraction* ab = abstraction >= 0 && abstraction < rig->abstraction_count ? &rig->abstractions[abstraction] : NULL;
    bool one_loop = ab && ab->curve_count == 1 && ab->curves[0].closed;
    switch (shape) {
    case SP_HANDDRAW_SHAPE_LINE:
        r = centre_line(rig, cam, p, out);
        break;
    case SP_HANDDRAW_SHAPE_PIECE: {
        unsigned char* keep = malloc((size_t)(rig->vertex_count > 0 ? rig->vertex_count : 1));
        r = !keep                                              ? SP_ERR_NO_MEMORY
            : rig->weights4 && piece_vertices(rig, seed, keep) ? silhouette(rig, cam, p, keep, out)
                                                               : SP_ERR_INVALID;
        free(keep);
        break;
    }
    case SP_HANDDRAW_SHAPE_OUTLINE:
    case SP_HANDDRAW_SHAPE_TOP:
    case SP_HANDDRAW_SHAPE_UNDERSIDE:
        // Partial outlines need one closed curve: the silhouette when the abstraction is not one.
        if (details || (shape != SP_HANDDRAW_SHAPE_OUTLINE && !one_loop))
            r = silhouette(rig, cam, p, NULL, out);
        else
            r = sp_synth_sketch(rig, abstraction, cam, p, out);
        if (r == SP_OK && shape != SP_HANDDRAW_SHAPE_OUTLINE) {
            sp_sketch half = {0};
            r = half_side(out, shape == SP_HANDDRAW_SHAPE_TOP, &half);
            sp_sketch_free(out);
            *out = half;
        }
        break;
    default:
        r = SP_ERR_INVALID;
    }
    sp_rng rng = {seed ^ 0x5851F42D4C957F2Dull};
    if (r == SP_OK && out->stroke_count == 1 && spikes > 0 && sp_rng_uniform(&rng) < spikes) r = add_spikes(out, &rng);
    if (r != SP_OK) sp_sketch_free(out);
    return r;
}
