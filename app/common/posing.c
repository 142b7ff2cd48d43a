#include "posing.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/sketch_io.h"

int sp_pick_abstraction(const sp_abstraction* abs, int count, const char* rig_path, const char* name, sp_error* err)
{
    if (count == 0) {
        sp_fail(err, SP_ERR_INVALID, "%s: the rig has no sketch abstraction", rig_path);
        return -1;
    }
    if (!name) return 0;
    for (int a = 0; a < count; ++a)
        if (!strcmp(abs[a].name, name)) return a;
    char list[256] = "";
    for (int i = 0; i < count; ++i) {
        size_t n = strlen(list);
        snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", abs[i].name);
    }
    sp_fail(err, SP_ERR_INVALID, "%s: no abstraction '%s' (it has: %s)", rig_path, name, list);
    return -1;
}

sp_result sp_read_strokes(const char* path, sp_sketch* sk, sp_error* err)
{
    // An animator's drawing from a vector editor: one stroke per subpath,
    // its viewBox the canvas.
    bool svg = sp_path_ext_is(path, "svg");
    sp_result r = svg ? sp_sketch_read_svg(path, sk, err) : sp_sketch_read_json(path, sk, err);
    if (r != SP_OK) return r;
    if (svg && !(sk->canvas_w > 0 && sk->canvas_h > 0)) {
        sp_sketch_free(sk);
        return sp_fail(
            err, SP_ERR_INVALID,
            "%s: the SVG has no usable viewBox, so its canvas is unknown (viewBox=\"X Y W H\", W and H in (0, 1000000))", path);
    }
    if (sk->stroke_count == 0) {
        sp_sketch_free(sk);
        return sp_fail(err, SP_ERR_INVALID, "%s: the file has no strokes", path);
    }
    for (int i = 0; i < sk->stroke_count; ++i)
        if (sk->strokes[i].count < 2) {
            int n = sk->strokes[i].count;
            sp_sketch_free(sk);
            return sp_fail(err, SP_ERR_INVALID, "%s: stroke %d has %d point%s (at least 2 are needed)", path, i, n, n == 1 ? "" : "s");
        }
    return SP_OK;
}

bool* sp_drawover_active(const sp_rig* rig)
{
    bool* on = malloc(sizeof(bool) * (size_t)(rig->param_count + 1));
    if (!on) return NULL;
    for (int q = 0; q < rig->param_count; ++q)
        on[q] = !sp_rig_param_shifts(rig, q);
    return on;
}

// A weight as the solver takes it (0: its default; < 0: off) times f.
static double scaled(double typed, double def, double f)
{
    return typed < 0 ? typed : (typed == 0 ? def : typed) * f;
}

double sp_drawover_scale_weights(sp_solve_desc* d, const sp_rig* rig, const double* xyz, const sp_camera* cam,
                                 const sp_sketch* on)
{
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int v = 0; v < rig->vertex_count; ++v) {
        sp_vec2 q = sp_camera_project(cam, (sp_vec3){xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]});
        lx = fmin(lx, q.x), hx = fmax(hx, q.x), ly = fmin(ly, q.y), hy = fmax(hy, q.y);
    }
    sp_vec2 lo, hi;
    double mesh = hypot(hx - lx, hy - ly), drawn = sp_sketch_bounds(on, &lo, &hi) ? sp_v2_len(sp_v2_sub(hi, lo)) : 0;
    double f = drawn > 0 && isfinite(mesh) ? (mesh / drawn) * (mesh / drawn) : 1;
    f = fmin(fmax(f, 1), 1e4);
    d->lambda_pose = scaled(d->lambda_pose, SP_LAMBDA_POSE, f);
    d->lambda_plane = scaled(d->lambda_plane, SP_LAMBDA_PLANE, f);
    d->lambda_dist = scaled(d->lambda_dist, SP_LAMBDA_DIST, f);
    return f;
}
