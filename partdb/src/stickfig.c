// stickfig.c: the stick-figure abstraction derived from a skeleton, for
// glTF files without our `sp_abstraction` curves (DESIGN.md).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_internal.h"

typedef struct stick_buf {
    int n, cap;
    double* rest;
    uint16_t* joints;
    float* weights;
} stick_buf;

static bool stick_push(stick_buf* b, const sp_mat4* inv_skin, int joint, sp_vec3 world)
{
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 64;
        double* r = realloc(b->rest, sizeof(double) * 3 * (size_t)cap);
        if (r) b->rest = r;
        uint16_t* j = realloc(b->joints, sizeof(uint16_t) * 4 * (size_t)cap);
        if (j) b->joints = j;
        float* w = realloc(b->weights, sizeof(float) * 4 * (size_t)cap);
        if (w) b->weights = w;
        if (!r || !j || !w) return false;
        b->cap = cap;
    }
    // Why bind space: skinning at the default parameters must give back the
    // world point, x = (G_a IBM_a) x0, like the mesh vertices.
    sp_vec3 x0 = sp_mat4_point(inv_skin, world);
    int i = b->n++;
    b->rest[3 * i] = x0.x, b->rest[3 * i + 1] = x0.y, b->rest[3 * i + 2] = x0.z;
    b->joints[4 * i] = (uint16_t)joint;
    b->joints[4 * i + 1] = b->joints[4 * i + 2] = b->joints[4 * i + 3] = 0;
    b->weights[4 * i] = 1.0f;
    b->weights[4 * i + 1] = b->weights[4 * i + 2] = b->weights[4 * i + 3] = 0.0f;
    return true;
}

// Appends b as one open, ordered curve of `abstraction`; `what` names it in the error.
static sp_result stick_append(sp_rig* rig, const stick_buf* b, const char* abstraction, const char* curve, const char* what,
                              sp_error* err)
{
    if (sp_gltf_append_curve(rig, abstraction, SP_CORR_ORDERED, curve, false, b->n, b->rest, b->joints, b->weights) != SP_OK)
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    return SP_OK;
}

static void stick_free(stick_buf* b)
{
    free(b->rest), free(b->joints), free(b->weights);
}

// How far along the unit direction `dir` from `pivot` the mesh vertices
// that `joint` moves most reach (xyz: the mesh at the default parameters);
// 0 when none lies that way. *share (may be NULL): those vertices' share of the mesh.
static double mesh_reach(const sp_rig* rig, const double* xyz, int joint, sp_vec3 pivot, sp_vec3 dir, double* share)
{
    double far = 0;
    int moved = 0;
    for (int v = 0; xyz && v < rig->vertex_count; ++v) {
        int strongest = 0;
        for (int k = 1; k < 4; ++k)
            if (rig->weights4[4 * v + k] > rig->weights4[4 * v + strongest]) strongest = k;
        if (rig->joints4[4 * v + strongest] != joint) continue;
        sp_vec3 x = {xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]};
        far = fmax(far, sp_v3_dot(sp_v3_sub(x, pivot), dir));
        ++moved;
    }
    if (share) *share = rig->vertex_count > 0 ? (double)moved / rig->vertex_count : 0;
    return far;
}

// A leaf that moves at least this share of the mesh gets a curve of its own
// past its pivot. Smaller ones (a head, hands, feet) do not: with theirs,
// CesiumMan's random poses were fitted within 1% 88 times of 100, where the
// recovery protocol asks 95 (96 without).
#define STICK_TIP_SHARE 0.25

sp_result sp_gltf_derive_stick(sp_rig* rig, const bool* is_skin, int* flat_bones, sp_error* err)
{
    int J = rig->joint_count;
    if (flat_bones) *flat_bones = 0;
    int* nchild = calloc((size_t)J, sizeof(int));
    int* chain = malloc(sizeof(int) * (size_t)(J + 1));
    double* p = malloc(sizeof(double) * (size_t)(rig->param_count + 1));
    sp_mat4* inv = malloc(sizeof(sp_mat4) * (size_t)J);
    bool* usable = malloc(sizeof(bool) * (size_t)J);
    sp_vec3* pos = malloc(sizeof(sp_vec3) * (size_t)J);
    double* xyz = NULL;
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    stick_buf b = {0};
    sp_result r = SP_OK;
    if (!nchild || !chain || !p || !inv || !usable || !pos || !ev) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
        goto done;
    }
    sp_rig_defaults(rig, p);
    sp_rig_eval_update(ev, p, false);
    const sp_mat4* world = sp_rig_eval_world(ev);
    const sp_mat4* skin = sp_rig_eval_skin(ev);
    // The mesh, for the tips of chains that end at a leaf (NULL: none).
    if (rig->vertex_count > 0 && (xyz = malloc(sizeof(double) * 3 * (size_t)rig->vertex_count)))
        sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    sp_vec3 lo = {0, 0, 0}, hi = {0, 0, 0};
    for (int j = 0; j < J; ++j) {
        // A joint whose skin matrix flattens space has no bind-space place
        // for its bone's points (a singular inverse bind matrix): skipped.
        usable[j] = sp_mat4_inverse_rel(&skin[j], SP_MAT4_FLAT, &inv[j]);
        pos[j] = sp_mat4_translation(&world[j]);
        if (j == 0) lo = hi = pos[j];
        lo = sp_v3(fmin(lo.x, pos[j].x), fmin(lo.y, pos[j].y), fmin(lo.z, pos[j].z));
        hi = sp_v3(fmax(hi.x, pos[j].x), fmax(hi.y, pos[j].y), fmax(hi.z, pos[j].z));
        int pa = rig->joints[j].parent;
        if (pa >= 0 && is_skin[j] && is_skin[pa]) ++nchild[pa];
    }
    // Why relative: bones shorter than a millionth of the skeleton are
    // coincident joints (common at roots) and would give repeated points.
    double eps = 1e-6 * fmax(sp_v3_len(sp_v3_sub(hi, lo)), 1e-12);
    for (int a = 0; a < J; ++a) {
        if (!is_skin[a] || nchild[a] == 0) continue;
        int pa = rig->joints[a].parent;
        bool starts = pa < 0 || !is_skin[pa] || nchild[a] != 1;
        if (!starts) continue;
        for (int c = a + 1; c < J; ++c) {
            if (rig->joints[c].parent != a || !is_skin[c]) continue;
            // The chain a -> c -> ... through single-child joints.
            int len = 0;
            chain[len++] = a;
            int cur = c;
            chain[len++] = cur;
            while (nchild[cur] == 1) {
                int next = -1;
                for (int k = cur + 1; k < J && next < 0; ++k)
                    if (rig->joints[k].parent == cur && is_skin[k]) next = k;
                cur = next;
                chain[len++] = cur;
            }
            b.n = 0;
            int last_u = -1, last_v = -1;
            for (int i = 0; i + 1 < len; ++i) {
                int u = chain[i], v = chain[i + 1];
                sp_vec3 d = sp_v3_sub(pos[v], pos[u]);
                if (!(sp_v3_len(d) > eps)) continue;
                if (!usable[u]) {
                    if (flat_bones) ++*flat_bones;
                    continue;
                }
                for (int k = 0; k < SP_STICK_POINTS_PER_BONE; ++k)
                    if (!stick_push(&b, &inv[u], u, sp_v3_add(pos[u], sp_v3_scale(d, (double)k / SP_STICK_POINTS_PER_BONE)))) {
                        r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
                        goto done;
                    }
                last_u = u, last_v = v;
            }
            if (last_u < 0) continue;
            // A chain that ends at a leaf moving much of the mesh goes on
            // to where that mesh ends: without it that bone had no curve,
            // and the solve posed it at random (RiggedSimple's upper half,
            // an outside review).
            sp_vec3 d = sp_v3_norm(sp_v3_sub(pos[last_v], pos[last_u]));
            double share = 0,
                   tip = nchild[last_v] == 0 && usable[last_v] ? mesh_reach(rig, xyz, last_v, pos[last_v], d, &share) : 0;
            int steps = tip > eps && share >= STICK_TIP_SHARE ? SP_STICK_POINTS_PER_BONE : 0;
            for (int k = 0; k <= steps; ++k) {
                int u = k == 0 ? last_u : last_v;
                sp_vec3 x = sp_v3_add(pos[last_v], sp_v3_scale(d, tip * (double)k / SP_STICK_POINTS_PER_BONE));
                if (!stick_push(&b, &inv[u], u, x)) {
                    r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
                    goto done;
                }
            }
            char name[SP_NAME_MAX];
            snprintf(name, sizeof name, "%.31s-%.31s", rig->joints[chain[0]].name, rig->joints[chain[len - 1]].name);
            if ((r = stick_append(rig, &b, "stick", name, "stick figure", err)) != SP_OK) goto done;
        }
    }
done:
    sp_rig_eval_destroy(ev);
    free(nchild), free(chain), free(p), free(inv), free(usable), free(pos), free(xyz);
    stick_free(&b);
    return r;
}

// ---- the line through a chain-shaped skeleton -----------------------------

// Leaves of the skeleton (joints without children); returns their count (up to cap).
static int leaves(const sp_rig* rig, int* out, int cap)
{
    int n = 0;
    for (int j = 0; j < rig->joint_count; ++j) {
        bool leaf = true;
        for (int c = j + 1; c < rig->joint_count && leaf; ++c)
            leaf = rig->joints[c].parent != j;
        if (leaf) {
            if (n < cap) out[n] = j;
            ++n;
        }
    }
    return n;
}

// Chain from joint j up to the root (j first); returns its length.
static int chain_up(const sp_rig* rig, int j, int* out)
{
    int n = 0;
    for (; j >= 0 && n < rig->joint_count; j = rig->joints[j].parent)
        out[n++] = j;
    return n;
}

int sp_rig_line_joints(const sp_rig* rig, int* order, int cap)
{
    int lv[2];
    int nl = leaves(rig, lv, 2);
    if (!(nl == 1 || nl == 2) || rig->joint_count < 3) return 0;
    int* a = malloc(sizeof(int) * (size_t)rig->joint_count * 2);
    if (!a) return 0;
    int* b = a + rig->joint_count;
    int na = chain_up(rig, lv[0], a), nb = nl == 2 ? chain_up(rig, lv[1], b) : 0;
    // Leaf A up to the lowest common ancestor, then down to leaf B (one leaf: up to the root).
    int lca = na - 1;
    if (nl == 2)
        for (int i = 0; i < na; ++i) {
            bool shared = false;
            for (int k = 0; k < nb && !shared; ++k)
                shared = b[k] == a[i];
            if (shared) {
                lca = i;
                break;
            }
        }
    int no = 0;
    for (int i = 0; i <= lca && no < cap; ++i)
        order[no++] = a[i];
    if (nl == 2) {
        int k = 0;
        while (k < nb && b[k] != a[lca])
            ++k;
        for (int i = k - 1; i >= 0 && no < cap; --i)
            order[no++] = b[i];
    }
    free(a);
    return no;
}

// Points along the whole line, spread by length (the outline has 150).
enum { LINE_POINTS = 96 };

// The end of the line beyond joint `joint` at `pivot`, coming from `from`:
// as far along that way as the vertices `joint` moves most reach (xyz: the
// mesh at the default parameters; NULL, or none reaching on: 0.8 of the
// last bone, as the training's line shape).
static sp_vec3 pushed_end(const sp_rig* rig, const double* xyz, int joint, sp_vec3 pivot, sp_vec3 from)
{
    sp_vec3 d = sp_v3_sub(pivot, from);
    double len = sp_v3_len(d), reach = 0.8 * len;
    if (!(len > 0)) return pivot;
    d = sp_v3_scale(d, 1.0 / len);
    double far = mesh_reach(rig, xyz, joint, pivot, d, NULL);
    return sp_v3_add(pivot, sp_v3_scale(d, far > 0 ? far : reach));
}

// Appends abstraction `name` (one open curve of the same name) through the
// pivots of the joints the rig's line reaches in `order` (n of them, read by
// joints_of), each end pushed on to the end of the mesh there.
static sp_result add_path(sp_rig* rig, int (*joints_of)(const sp_rig*, int, int*, int), int arg, const char* name, bool* added,
                          sp_error* err)
{
    *added = false;
    int J = rig->joint_count;
    if (sp_rig_find_abstraction(rig, name) >= 0) return SP_OK;
    int* order = malloc(sizeof(int) * (size_t)(J + 1));
    double* p = malloc(sizeof(double) * (size_t)(rig->param_count + 1));
    sp_vec3* at = malloc(sizeof(sp_vec3) * (size_t)(J + 3)); // the path's points: the two pushed ends added
    int* bone = malloc(sizeof(int) * (size_t)(J + 3));       // the joint moving the segment from at[i] to at[i + 1]
    double* xyz = NULL;
    sp_rig_eval* ev = NULL;
    sp_rig_eval_create(rig, &ev, NULL);
    stick_buf b = {0};
    sp_result r = SP_OK;
    if (!order || !p || !at || !bone || !ev) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
        goto done;
    }
    int n = joints_of(rig, arg, order, J);
    if (n < 2) goto done;
    sp_rig_defaults(rig, p);
    sp_rig_eval_update(ev, p, false);
    const sp_mat4* world = sp_rig_eval_world(ev);
    const sp_mat4* skin = sp_rig_eval_skin(ev);
    // Joint pivots, each end pushed on to the end of the mesh there (a
    // visitor's line ends where the drawn part does: a tail's spade, the
    // toes' claws).
    for (int i = 0; i < n; ++i)
        at[i + 1] = sp_mat4_translation(&world[order[i]]);
    if (rig->vertex_count > 0 && (xyz = malloc(sizeof(double) * 3 * (size_t)rig->vertex_count)))
        sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    at[0] = pushed_end(rig, xyz, order[0], at[1], at[2]);
    at[n + 1] = pushed_end(rig, xyz, order[n - 1], at[n], at[n - 1]);
    // A segment is the bone of the parent of its two joints; a pushed end is its joint's.
    bone[0] = order[0], bone[n] = order[n - 1];
    for (int i = 1; i < n; ++i) {
        int u = order[i - 1], v = order[i];
        bone[i] = rig->joints[u].parent == v ? v : u;
    }
    double total = 0;
    for (int i = 0; i <= n; ++i)
        total += sp_v3_len(sp_v3_sub(at[i + 1], at[i]));
    if (!(total > 0) || !isfinite(total)) goto done;
    for (int i = 0; i <= n; ++i) {
        sp_vec3 d = sp_v3_sub(at[i + 1], at[i]);
        int k = (int)ceil(LINE_POINTS * sp_v3_len(d) / total);
        sp_mat4 inv;
        if (!sp_mat4_inverse_rel(&skin[bone[i]], SP_MAT4_FLAT, &inv)) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: joint %s has a singular skin matrix", name, rig->joints[bone[i]].name);
            goto done;
        }
        for (int s = 0; s < k || (i == n && s == k); ++s)
            if (!stick_push(&b, &inv, bone[i], sp_v3_add(at[i], sp_v3_scale(d, k > 0 ? (double)s / k : 0.0)))) {
                r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
                goto done;
            }
    }
    if (b.n >= 2 && (r = stick_append(rig, &b, name, name, name, err)) == SP_OK) *added = true;
done:
    sp_rig_eval_destroy(ev);
    free(order), free(p), free(at), free(bone), free(xyz);
    stick_free(&b);
    return r;
}

static int line_joints(const sp_rig* rig, int unused, int* order, int cap)
{
    (void)unused;
    return sp_rig_line_joints(rig, order, cap);
}

sp_result sp_rig_add_line(sp_rig* rig, bool* added, sp_error* err)
{
    return add_path(rig, line_joints, 0, "line", added, err);
}

// The chain from `leaf` up to the joint the skeleton's two leaves share
// (that joint last); 0 unless the skeleton is a line of two leaves and
// `leaf` is one of them.
static int limb_joints(const sp_rig* rig, int leaf, int* order, int cap)
{
    int lv[2];
    if (leaves(rig, lv, 2) != 2 || (leaf != lv[0] && leaf != lv[1]) || cap < 1) return 0;
    int n = sp_rig_line_joints(rig, order, cap);
    if (n < 3 || n > cap) return 0;
    // The line runs leaf A .. shared .. leaf B (turned to start at `leaf`):
    // up from the leaf while each next joint is the one before's parent.
    if (order[0] != leaf)
        for (int i = 0, k = n - 1; i < k; ++i, --k) {
            int t = order[i];
            order[i] = order[k], order[k] = t;
        }
    int m = 1;
    while (m < n && rig->joints[order[m - 1]].parent == order[m])
        ++m;
    return m >= 2 ? m : 0;
}

sp_result sp_rig_add_limb(sp_rig* rig, int leaf, bool* added, sp_error* err)
{
    return add_path(rig, limb_joints, leaf, "limb", added, err);
}
