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

sp_result sp_read_drawing(const char* path, sp_sketch* sk, sp_error* err)
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
    return SP_OK;
}

sp_result sp_read_strokes(const char* path, sp_sketch* sk, sp_error* err)
{
    sp_result r = sp_read_drawing(path, sk, err);
    if (r != SP_OK) return r;
    if (sk->stroke_count == 0) {
        sp_sketch_free(sk);
        return sp_fail(err, SP_ERR_INVALID, "%s: the file has no strokes", path);
    }
    // A one-point stroke is a tap (dot eyes: tablets record one point), left
    // unused by the solve (solve_cmd.c) and said there; a drawing of taps
    // alone has nothing to pose by.
    int lines = 0;
    for (int i = 0; i < sk->stroke_count; ++i)
        lines += sk->strokes[i].count >= 2;
    for (int i = 0; i < sk->stroke_count; ++i)
        if (sk->strokes[i].count < 1 || lines == 0) {
            int n = sk->strokes[i].count;
            sp_sketch_free(sk);
            return sp_fail(err, SP_ERR_INVALID, "%s: stroke %d has %d point%s (%s)", path, i, n, n == 1 ? "" : "s",
                           n < 1 ? "an empty stroke" : "no stroke has 2 or more points");
        }
    // Nothing drawn on the canvas is nothing to pose by: such strokes were
    // solved "best effort", the figure rolled into a ball or flung to a
    // corner with exit 0 (an outside review; `dragon` refuses them too).
    if (!(sk->canvas_w > 0 && sk->canvas_h > 0)) return SP_OK;
    double w = sk->canvas_w, h = sk->canvas_h;
    bool on = false;
    for (int i = 0; i < sk->stroke_count && !on; ++i)
        on = sp_stroke_points_off_canvas(&sk->strokes[i], sk->canvas_w, sk->canvas_h) < sk->strokes[i].count;
    if (!on) {
        sp_fail(err, SP_ERR_INVALID, "%s: every stroke lies off its %gx%g canvas (the first point is at %g, %g)", path, w, h,
                sk->strokes[0].points[0].x, sk->strokes[0].points[0].y);
        sp_sketch_free(sk);
        return SP_ERR_INVALID;
    }
    // A point more than a whole canvas beyond its edge is a pen's glitch or
    // a coordinate slip, not a drawing: one such point flung a crouching
    // figure's leg out, exit 0 (an outside review). Named, refused.
    for (int i = 0; i < sk->stroke_count; ++i)
        for (int k = 0; k < sk->strokes[i].count; ++k) {
            sp_vec2 q = sk->strokes[i].points[k];
            if (q.x >= -w && q.x <= 2 * w && q.y >= -h && q.y <= 2 * h) continue;
            sp_fail(err, SP_ERR_INVALID,
                    "%s: stroke %d, point %d (%g, %g) lies more than a canvas beyond its %gx%g canvas (a glitch of the pen?)",
                    path, i, k, q.x, q.y, w, h);
            sp_sketch_free(sk);
            return SP_ERR_INVALID;
        }
    return SP_OK;
}

// The nearest joint that is an ancestor of both (or one of them); -1: none.
// Parents come before children, so the larger index walks up.
static int common_ancestor(const sp_rig* rig, int a, int b)
{
    while (a != b && a >= 0 && b >= 0)
        if (a > b)
            a = rig->joints[a].parent;
        else
            b = rig->joints[b].parent;
    return a == b ? a : -1;
}

// The joints a draw-over may move (`free`, by joint): those that carry the
// curves embedded in the mesh, the limb above them and everything below.
// - Carriers: a joint with at least SP_DRAWOVER_CARRIER_SHARE of the skin
//   (the triangle's vertices' weights blended by the point's barycentric
//   coordinates) at a tenth of a curve's points or more: one point on the
//   chest where a stroke starts did not make the chest twist for an arm. A
//   joint moving more than SP_DRAWOVER_LIMB_SHARE of the mesh (a trunk)
//   counts only the points where no joint under it has that share.
// - The limb above: each carrier's ancestors up to, not including, the
//   first that moves more than SP_DRAWOVER_LIMB_SHARE of the mesh (its skin
//   and its descendants': a chest carries the head and both arms): a hand,
//   a finger or a tail's tip redrawn moves its arm or its tail.
// - Below: the joints under a carrier hold their own part still (W_dist):
//   without them a redrawn neck swung the head, 6.2% of the size.
static bool curve_carriers(const sp_rig* rig, const sp_abstraction* emb, double share, bool* free_j)
{
    int J = rig->joint_count;
    double* w = calloc((size_t)J + 1, sizeof(double));
    int* hits = calloc(2 * ((size_t)J + 1), sizeof(int));
    int* own = hits + J + 1;                               // hits where no joint under it has the share too
    bool* under = calloc((size_t)J + 1, sizeof(bool));     // at the point: a joint under it has the share
    double* moves = calloc((size_t)J + 1, sizeof(double)); // share of the mesh's skin at or under the joint
    if (!w || !hits || !under || !moves) {
        free(w), free(hits), free(under), free(moves);
        return false;
    }
    for (size_t v = 0; v < (size_t)rig->vertex_count; ++v)
        for (int k = 0; k < 4; ++k)
            moves[rig->joints4[4 * v + k]] += rig->weights4[4 * v + k] / rig->vertex_count;
    for (int j = J - 1; j > 0; --j) // children come after their parents (sp_rig_finalize)
        if (rig->joints[j].parent >= 0) moves[rig->joints[j].parent] += moves[j];
    // Curve by curve: a tenth of each curve's own points (with several
    // curves drawn over, a tenth of them all left a spine's short curve
    // without carriers, and the chest bent into an S; an outside review).
    for (int c = 0; c < emb->curve_count; ++c) {
        const sp_curve* cv = &emb->curves[c];
        for (int i = cv->first_point; i < cv->first_point + cv->point_count; ++i) {
            for (int t = 0; t < 3; ++t) {
                uint32_t v = emb->tri_vertices[3 * i + t];
                for (int k = 0; k < 4 && v < (uint32_t)rig->vertex_count; ++k)
                    w[rig->joints4[4 * (size_t)v + k]] += emb->bary[3 * i + t] * rig->weights4[4 * (size_t)v + k];
            }
            for (int j = 0; j < J; ++j)
                for (int a = w[j] >= share ? rig->joints[j].parent : -1; a >= 0 && !under[a]; a = rig->joints[a].parent)
                    under[a] = true;
            for (int j = 0; j < J; ++j) {
                hits[j] += w[j] >= share;
                own[j] += w[j] >= share && !under[j];
                w[j] = 0, under[j] = false;
            }
        }
        for (int j = 0; j < J; ++j) {
            // A trunk joint (moving more than the limb share) counts only where
            // the curve is on its own skin: RiggedFigure's upper arm is skinned to
            // its spine at the shoulder, and a draw-over of the arm freed the
            // chest, the head and the other arm (an outside review).
            int h = moves[j] > SP_DRAWOVER_LIMB_SHARE ? own[j] : hits[j];
            hits[j] = own[j] = 0;
            if (10 * h < cv->point_count || h == 0) continue;
            free_j[j] = true;
            for (int a = rig->joints[j].parent; a >= 0 && moves[a] <= SP_DRAWOVER_LIMB_SHARE; a = rig->joints[a].parent)
                free_j[a] = true;
        }
    }
    for (int j = 0; j < J; ++j)
        free_j[j] |= rig->joints[j].parent >= 0 && free_j[rig->joints[j].parent];
    free(w), free(hits), free(under), free(moves);
    return true;
}

// How many of joint j's children have parameters at or under them.
static int branches_with_params(const sp_rig* rig, int j)
{
    int n = 0;
    for (int c = 0; c < rig->joint_count; ++c) {
        if (rig->joints[c].parent != j) continue;
        bool any = false;
        for (int k = c; k < rig->joint_count && !any; ++k) { // children come after their parents
            int a = k;
            while (a > c)
                a = rig->joints[a].parent;
            any = a == c && rig->joints[k].param_count > 0;
        }
        n += any;
    }
    return n;
}

bool* sp_drawover_active(const sp_rig* rig, const sp_abstraction* emb)
{
    bool* on = malloc(sizeof(bool) * (size_t)(rig->param_count + 1));
    bool* carrier = calloc((size_t)rig->joint_count + 1, sizeof(bool));
    if (!on || !carrier || (emb && emb->tri_vertices && !curve_carriers(rig, emb, SP_DRAWOVER_CARRIER_SHARE, carrier))) {
        free(on), free(carrier);
        return NULL;
    }
    // The placement joint: the first with parameters, when it translates the
    // whole character (its rotation and scale then turn and grow it all);
    // and the body's root under it, the nearest common ancestor of every
    // other joint with parameters (hips, pelvis: a loader's derived
    // placement only translates, and the hips' turn is the whole figure's).
    bool placement = false;
    for (int q = 0; q < rig->param_count; ++q)
        placement |= sp_rig_param_shifts(rig, q);
    int place = rig->param_count > 0 ? rig->params[0].joint : -1, body = -2;
    for (int j = 0; placement && j < rig->joint_count; ++j)
        if (j != place && rig->joints[j].param_count > 0) body = body == -2 ? j : common_ancestor(rig, body, j);
    // Only a body's root where limbs branch (hips: legs and spine) is held;
    // on a single chain (SimpleSkin, RiggedSimple) it is the chain's first
    // bend, and holding it left SimpleSkin nothing to move (an outside review).
    if (body >= 0 && branches_with_params(rig, body) < 2) body = -2;
    for (int q = 0; q < rig->param_count; ++q)
        on[q] = !(placement && (rig->params[q].joint == place || rig->params[q].joint == body)) &&
                (!emb || !emb->tri_vertices || carrier[rig->params[q].joint]);
    free(carrier);
    return on;
}

void sp_drawover_note_held(const sp_rig* rig, const bool* active, char* note, size_t cap)
{
    if (!strstr(note, "best effort") && !strstr(note, "loose fit")) return;
    bool* moves = calloc((size_t)rig->joint_count + 1, sizeof(bool));
    if (!moves) return;
    for (int q = 0; q < rig->param_count; ++q)
        moves[rig->params[q].joint] |= active[q];
    // The joints that move whose parents do not: where each moving limb starts.
    char from[160] = "";
    int n = 0;
    for (int j = 0; j < rig->joint_count; ++j) {
        int pa = rig->joints[j].parent;
        if (!moves[j] || (pa >= 0 && moves[pa]) || ++n > 3) continue;
        size_t at = strlen(from);
        snprintf(from + at, sizeof from - at, "%s'%s'", at ? ", " : "", rig->joints[j].name);
    }
    free(moves);
    size_t at = strlen(note);
    if (n == 0)
        snprintf(note + at, cap - at,
                 "; no joint under the drawn curves may move (draw-over holds the placement and the body's root)");
    else
        snprintf(note + at, cap - at,
                 "; draw-over moves only the joints under the drawn curves, from %s%s down, never the placement or the body's "
                 "root (draw over more to move more)",
                 from, n > 3 ? ", ..." : "");
}

// A weight as the solver takes it (0: its default; < 0: off) times f.
static double scaled(double typed, double def, double f)
{
    return typed < 0 ? typed : (typed == 0 ? def : typed) * f;
}

// The canvas box's diagonal of n points (world, by 3).
static double projected_diagonal(const double* xyz, int n, const sp_camera* cam)
{
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int v = 0; v < n; ++v) {
        sp_vec2 q = sp_camera_project(cam, (sp_vec3){xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]});
        lx = fmin(lx, q.x), hx = fmax(hx, q.x), ly = fmin(ly, q.y), hy = fmax(hy, q.y);
    }
    return n > 0 ? hypot(hx - lx, hy - ly) : 0;
}

double sp_drawover_scale_weights(sp_solve_desc* d, const sp_rig* rig, const double* xyz, const sp_camera* cam,
                                 const sp_abstraction* emb)
{
    enum { MAX_FACTOR = 10000 };
    double mesh = projected_diagonal(xyz, rig->vertex_count, cam), f = MAX_FACTOR;
    double* pts = emb->tri_vertices && emb->bary ? malloc(sizeof(double) * 3 * (size_t)(emb->point_count + 1)) : NULL;
    if (pts) {
        for (int i = 0; i < emb->point_count; ++i)
            for (int c = 0; c < 3; ++c) {
                const uint32_t* t = &emb->tri_vertices[3 * i];
                const double* b = &emb->bary[3 * i];
                pts[3 * i + c] = b[0] * xyz[3 * t[0] + c] + b[1] * xyz[3 * t[1] + c] + b[2] * xyz[3 * t[2] + c];
            }
        double drawn = projected_diagonal(pts, emb->point_count, cam);
        if (drawn > 1e-9 && isfinite(mesh)) f = (mesh / drawn) * (mesh / drawn);
        free(pts);
    } else if (!emb->tri_vertices) {
        f = 1; // not a curve on the mesh: its size is the character's own
    }
    f = fmin(fmax(f, 1), MAX_FACTOR);
    d->lambda_pose = scaled(d->lambda_pose, SP_LAMBDA_POSE, f);
    d->lambda_plane = scaled(d->lambda_plane, SP_LAMBDA_PLANE, f);
    d->lambda_dist = scaled(d->lambda_dist, SP_LAMBDA_DIST, f);
    return f;
}
