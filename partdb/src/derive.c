// derive.c: a kiosk part from a rigged glTF made elsewhere (sp/derive.h):
// the part turned to its side view, joint frames in the sketch plane, the
// visitor's parameters, the outline and stick abstractions, the attachment
// point and the clip re-keyed on the new frames.
#include "sp/derive.h"
#include "sp/sketch_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_internal.h"
#include "sp/math.h"
#include "sp/outline.h"

// Parameter bounds (DESIGN.md, "Generated dragon parts"; radians, factors).
#define ROOT_ROT_LIMIT 1.0
#define ROOT_SCALE_MIN 0.5
#define ROOT_SCALE_MAX 2.0
#define JOINT_ROT_LIMIT 0.8
#define JOINT_ROT_LIMIT_MAX 2.0
#define BONE_SCALE_MIN 0.6
#define BONE_SCALE_MAX 1.6
#define FRAME_MARGIN 1.35
// A clip longer than this (seconds) is likely in another unit: said.
#define CLIP_LONG_S 60.0
// A bone shorter than this share of the part's size has no direction of its own.
#define BONE_EPS 1e-4
static const double k_pi = 3.14159265358979323846;
enum { OUTLINE_POINTS = 150, DEPTH_PASSES = 8, CLIP_KEYS_MAX = 2000, CLIP_RATE = 30 };

static const char* const k_derived_names[SP_DERIVED_COUNT] = {"outline", "stick", "parameters", "attach", "clip", "view"};

const char* sp_derived_name(int bit)
{
    return bit >= 0 && bit < SP_DERIVED_COUNT ? k_derived_names[bit] : NULL;
}

bool sp_derive_view_parse(const char* s, sp_derive_view* out)
{
    static const char* const names[] = {"auto", "-z", "+z", "-x", "+x"};
    for (int i = 0; i < 5; ++i)
        if (s && !strcmp(s, names[i])) {
            *out = (sp_derive_view)i;
            return true;
        }
    return false;
}

bool sp_part_needs_derivation(const sp_character* ch)
{
    return ch->derived_abstraction || ch->rig.abstraction_count == 0;
}

sp_camera sp_part_side_camera(sp_vec3 lo, sp_vec3 hi, double margin)
{
    sp_vec3 c = sp_v3_scale(sp_v3_add(lo, hi), 0.5), h = sp_v3_scale(sp_v3_sub(hi, lo), 0.5 * margin);
    return sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, sp_v3_sub(c, h), sp_v3_add(c, h), sp_v3(0, 0, -1), sp_v3(0, 1, 0), 640, 480);
}

// ---- the work ----------------------------------------------------------------

typedef struct djoint {
    int src;       // source joint, -1 for an added root
    int parent;    // derived index, -1 for the root
    sp_vec3 pivot; // rest pivot in the part's space (the view frame)
    double angle;  // in-plane rest angle, radians
    bool moves;    // it or a joint below it moves a vertex
    double limit;  // its rz bound
} djoint;

typedef struct work {
    const sp_character* src;
    const sp_rig* sr;
    sp_mat4 W, Wt; // source world -> part space (a rotation) and back
    sp_mat4* G;    // source world rest transforms (source joints)
    sp_mat4* Ginv;
    sp_mat4* S;       // source skin matrices at rest
    bool* influences; // source joint moves a vertex
    int* to_derived;  // source -> derived joint, -1 when folded
    int count;        // derived joints
    djoint* j;
    sp_mat4* F;    // derived frames at rest (pivot, in-plane angle)
    double* xyz;   // mesh at rest in the part's space
    double extent; // its bounding box diagonal
    // The clip on the derived joints: keys x joints TRS.
    const sp_animation* clip;
    int keys;
    float* times;
    sp_vec3* ct;
    sp_quat* cr;
    sp_vec3* cs;
} work;

static void work_free(work* w)
{
    free(w->G), free(w->Ginv), free(w->S), free(w->influences), free(w->to_derived), free(w->j), free(w->F), free(w->xyz);
    free(w->times), free(w->ct), free(w->cr), free(w->cs);
}

static sp_quat rot_z(double a)
{
    return sp_quat_axis_angle(sp_v3(0, 0, 1), a);
}

// World transforms of a rig's joints from local TRS (parents come first).
static void fk(const sp_rig* r, const sp_vec3* t, const sp_quat* q, const sp_vec3* s, sp_mat4* G)
{
    for (int j = 0; j < r->joint_count; ++j) {
        sp_mat4 L = sp_mat4_trs(t[j], sp_quat_norm(q[j]), s[j]);
        int p = r->joints[j].parent;
        G[j] = p >= 0 ? sp_mat4_mul(&G[p], &L) : L;
    }
}

// The rotation taking the source world to the part's space, where the sketch
// camera looks along -Z with +Y up: its rows are the camera's axes.
static sp_mat4 view_rotation(const sp_character* src, sp_derive_view v)
{
    sp_vec3 xc, yc, zc;
    if (v == SP_DERIVE_VIEW_AUTO) {
        const sp_mat4* V = &src->camera.view;
        sp_vec3 r1 = sp_v3(V->m[1], V->m[5], V->m[9]), r2 = sp_v3(V->m[2], V->m[6], V->m[10]);
        zc = sp_v3_norm(r2);
        yc = sp_v3_norm(sp_v3_sub(r1, sp_v3_scale(zc, sp_v3_dot(r1, zc))));
    } else {
        // zc points from the part towards the camera (against the look direction).
        static const double back[5][3] = {{0, 0, 0}, {0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}};
        zc = sp_v3(back[v][0], back[v][1], back[v][2]);
        yc = sp_v3(0, 1, 0);
    }
    xc = sp_v3_cross(yc, zc);
    sp_mat4 W = sp_mat4_identity();
    const sp_vec3 rows[3] = {xc, yc, zc};
    for (int r = 0; r < 3; ++r) {
        W.m[r] = rows[r].x;
        W.m[4 + r] = rows[r].y;
        W.m[8 + r] = rows[r].z;
    }
    return W;
}

static sp_mat4 transpose3(const sp_mat4* a)
{
    sp_mat4 t = sp_mat4_identity();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            t.m[4 * c + r] = a->m[4 * r + c];
    return t;
}

// Source joints moving vertices, the derived joints (everything at or below
// a moving joint, in source order), their pivots and in-plane angles.
static sp_result build_joints(work* w, sp_derive_info* info, sp_error* err)
{
    const sp_rig* sr = w->sr;
    int SJ = sr->joint_count;
    for (int i = 0; i < sr->vertex_count; ++i)
        for (int k = 0; k < 4; ++k)
            if (sr->weights4[4 * i + k] > 0) w->influences[sr->joints4[4 * i + k]] = true;
    bool* kept = calloc((size_t)SJ, sizeof(bool));
    if (!kept) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    int tops = 0, count = 0;
    for (int j = 0; j < SJ; ++j) {
        int p = sr->joints[j].parent;
        kept[j] = w->influences[j] || (p >= 0 && kept[p]);
        if (kept[j]) ++count;
        if (kept[j] && !(p >= 0 && kept[p])) ++tops;
    }
    info->joints_folded = SJ - count;
    info->root_added = tops > 1;
    w->count = count + (tops > 1);
    w->j = calloc((size_t)w->count, sizeof(djoint));
    w->F = malloc(sizeof(sp_mat4) * (size_t)w->count);
    if (!w->j || !w->F) {
        free(kept);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    int n = 0;
    if (tops > 1) w->j[n++] = (djoint){.src = -1, .parent = -1};
    for (int j = 0; j < SJ; ++j) {
        w->to_derived[j] = -1;
        if (!kept[j]) continue;
        int p = sr->joints[j].parent;
        int dp = p >= 0 && kept[p] ? w->to_derived[p] : (tops > 1 ? 0 : -1);
        w->to_derived[j] = n;
        w->j[n++] = (djoint){.src = j, .parent = dp, .pivot = sp_mat4_point(&w->W, sp_mat4_translation(&w->G[j]))};
    }
    free(kept);
    // A joint moves the mesh when it or one below it has weights.
    for (int d = w->count - 1; d >= 0; --d) {
        djoint* q = &w->j[d];
        if (q->src >= 0 && w->influences[q->src]) q->moves = true;
        if (q->moves && q->parent >= 0) w->j[q->parent].moves = true;
    }
    if (tops > 1) {
        sp_vec3 c = {0, 0, 0};
        for (int d = 1; d < w->count; ++d)
            if (w->j[d].parent == 0) c = sp_v3_add(c, w->j[d].pivot);
        w->j[0].pivot = sp_v3_scale(c, 1.0 / tops);
    }
    // In-plane angles: towards the children, else towards the vertices the
    // joint moves (a leaf), else the parent's.
    double eps = BONE_EPS * w->extent;
    for (int d = 0; d < w->count; ++d) {
        djoint* q = &w->j[d];
        sp_vec3 c = {0, 0, 0};
        int kids = 0;
        for (int e = d + 1; e < w->count; ++e)
            if (w->j[e].parent == d) c = sp_v3_add(c, w->j[e].pivot), ++kids;
        sp_vec3 dir = kids ? sp_v3_sub(sp_v3_scale(c, 1.0 / kids), q->pivot) : sp_v3(0, 0, 0);
        if (!(hypot(dir.x, dir.y) > eps) && q->src >= 0) {
            double sw = 0;
            sp_vec3 m = {0, 0, 0};
            for (int i = 0; i < sr->vertex_count; ++i)
                for (int k = 0; k < 4; ++k)
                    if (sr->joints4[4 * i + k] == q->src && sr->weights4[4 * i + k] > 0) {
                        double wt = sr->weights4[4 * i + k];
                        m = sp_v3_add(m, sp_v3_scale(sp_v3(w->xyz[3 * i], w->xyz[3 * i + 1], w->xyz[3 * i + 2]), wt));
                        sw += wt;
                    }
            dir = sw > 0 ? sp_v3_sub(sp_v3_scale(m, 1.0 / sw), q->pivot) : sp_v3(0, 0, 0);
        }
        if (hypot(dir.x, dir.y) > eps)
            q->angle = atan2(dir.y, dir.x);
        else
            q->angle = q->parent >= 0 ? w->j[q->parent].angle : 0.0;
        q->limit = JOINT_ROT_LIMIT;
        w->F[d] = sp_mat4_trs(q->pivot, rot_z(q->angle), sp_v3(1, 1, 1));
    }
    return SP_OK;
}

// The first animation with keys, re-keyed on the derived frames: at each key
// time the source skeleton's motion M_j(t) = G_j(t) G_j^-1 (in the part's
// space) carries each derived frame, F_j(t) = M_j(t) F_j, and the local TRS
// is F_parent(t)^-1 F_j(t). Widens the joints' rz bounds to what it does.
static sp_result convert_clip(work* w, sp_error* err)
{
    const sp_rig* sr = w->sr;
    double start, end;
    w->clip = sp_rig_first_clip(sr, &start, &end);
    if (!w->clip) return SP_OK;
    const sp_animation* an = w->clip;
    // Key times: every channel's, plus a steady rate where keys are not linear.
    size_t nt = 0;
    bool uniform = false;
    float t0 = INFINITY, t1 = -INFINITY;
    for (int c = 0; c < an->channel_count; ++c) {
        nt += (size_t)an->channels[c].key_count;
        uniform |= an->channels[c].interp != SP_INTERP_LINEAR;
        if (an->channels[c].key_count > 0) {
            t0 = fminf(t0, an->channels[c].times[0]);
            t1 = fmaxf(t1, an->channels[c].times[an->channels[c].key_count - 1]);
        }
    }
    size_t steady = uniform ? (size_t)ceil((double)(t1 - t0) * CLIP_RATE) + 1 : 0;
    float* t = malloc(sizeof(float) * (nt + steady + 1));
    if (!t) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    size_t m = 0;
    for (int c = 0; c < an->channel_count; ++c)
        for (int k = 0; k < an->channels[c].key_count; ++k)
            t[m++] = an->channels[c].times[k];
    for (size_t k = 0; k < steady; ++k)
        t[m++] = fminf(t1, t0 + (float)k / CLIP_RATE);
    qsort(t, m, sizeof(float), sp_cmp_float);
    size_t u = 0;
    for (size_t k = 0; k < m; ++k)
        if (u == 0 || t[k] - t[u - 1] > 1e-6f) t[u++] = t[k];
    if (u > CLIP_KEYS_MAX) { // evenly thinned, the ends kept
        for (size_t k = 0; k < CLIP_KEYS_MAX; ++k)
            t[k] = t[(size_t)llround((double)k * (double)(u - 1) / (CLIP_KEYS_MAX - 1))];
        u = CLIP_KEYS_MAX;
    }
    w->keys = (int)u;
    w->times = t;
    int SJ = sr->joint_count, DJ = w->count;
    size_t cells = u * (size_t)DJ;
    w->ct = malloc(sizeof(sp_vec3) * cells);
    w->cr = malloc(sizeof(sp_quat) * cells);
    w->cs = malloc(sizeof(sp_vec3) * cells);
    sp_vec3* tr = calloc((size_t)SJ, sizeof(sp_vec3));
    sp_quat* rot = calloc((size_t)SJ, sizeof(sp_quat));
    sp_vec3* sc = calloc((size_t)SJ, sizeof(sp_vec3));
    sp_mat4* Gt = malloc(sizeof(sp_mat4) * (size_t)SJ);
    sp_mat4* Ft = malloc(sizeof(sp_mat4) * (size_t)DJ);
    if (!w->ct || !w->cr || !w->cs || !tr || !rot || !sc || !Gt || !Ft) {
        free(tr), free(rot), free(sc), free(Gt), free(Ft);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    for (size_t k = 0; k < u; ++k) {
        for (int j = 0; j < SJ; ++j)
            tr[j] = sr->joints[j].rest_t, rot[j] = sr->joints[j].rest_r, sc[j] = sr->joints[j].rest_s;
        sp_animation_sample(an, t[k], tr, rot, sc);
        fk(sr, tr, rot, sc, Gt);
        for (int d = 0; d < DJ; ++d) {
            const djoint* q = &w->j[d];
            if (q->src < 0) {
                Ft[d] = w->F[d];
            } else {
                sp_mat4 M = sp_mat4_mul(&w->W, &Gt[q->src]);
                M = sp_mat4_mul(&M, &w->Ginv[q->src]);
                M = sp_mat4_mul(&M, &w->Wt);
                Ft[d] = sp_mat4_mul(&M, &w->F[d]);
            }
            sp_mat4 L = Ft[d];
            if (q->parent >= 0) {
                sp_mat4 inv;
                sp_mat4_inverse(&Ft[q->parent], &inv);
                L = sp_mat4_mul(&inv, &Ft[d]);
            }
            size_t at = k * (size_t)DJ + (size_t)d;
            sp_gltf_decompose(&L, &w->ct[at], &w->cr[at], &w->cs[at]);
            // Keep neighbouring keys on the same side of the quaternion sphere.
            if (k > 0) {
                sp_quat p = w->cr[at - (size_t)DJ], *c = &w->cr[at];
                if (p.x * c->x + p.y * c->y + p.z * c->z + p.w * c->w < 0) *c = (sp_quat){-c->x, -c->y, -c->z, -c->w};
            }
            // The in-plane part of the turn from rest (the twist about the
            // frame's Z), which the kiosk reads back as an rz offset.
            double rest_angle = q->parent < 0 ? q->angle : q->angle - w->j[q->parent].angle;
            sp_quat rel = sp_quat_mul(sp_quat_conj(rot_z(rest_angle)), w->cr[at]);
            double twist = fabs(2.0 * atan2(rel.z, rel.w));
            if (twist > k_pi) twist = 2.0 * k_pi - twist;
            w->j[d].limit = fmax(w->j[d].limit, fmin(JOINT_ROT_LIMIT_MAX, 1.1 * twist));
        }
    }
    free(tr), free(rot), free(sc), free(Gt), free(Ft);
    return SP_OK;
}

// Channels of the re-keyed clip on the joints it moves.
static sp_result add_clip(const work* w, sp_rig* R, sp_derive_info* info, sp_error* err)
{
    int DJ = w->count, K = w->keys;
    R->animations = calloc(1, sizeof(sp_animation));
    if (!R->animations) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    R->animation_count = 1;
    sp_animation* an = &R->animations[0];
    snprintf(an->name, sizeof an->name, "%s", w->clip->name);
    an->duration_s = w->times[K - 1];
    an->channels = calloc(3 * (size_t)DJ, sizeof(sp_anim_channel));
    if (!an->channels) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    double tol_t = 1e-6 * w->extent;
    for (int d = 0; d < DJ; ++d) {
        const sp_joint* jt = &R->joints[d];
        for (int path = 0; path < 3; ++path) {
            bool moves = false;
            for (int k = 0; k < K && !moves; ++k) {
                size_t at = (size_t)k * (size_t)DJ + (size_t)d;
                if (path == SP_ANIM_TRANSLATION)
                    moves = sp_v3_len(sp_v3_sub(w->ct[at], jt->rest_t)) > tol_t;
                else if (path == SP_ANIM_SCALE)
                    moves = sp_v3_len(sp_v3_sub(w->cs[at], jt->rest_s)) > 1e-6;
                else {
                    sp_quat a = w->cr[at], b = jt->rest_r;
                    moves = 1.0 - fabs(a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w) > 1e-10;
                }
            }
            if (!moves) continue;
            int comps = path == SP_ANIM_ROTATION ? 4 : 3;
            sp_anim_channel* c = &an->channels[an->channel_count];
            c->joint = d;
            c->path = (sp_anim_path)path;
            c->interp = SP_INTERP_LINEAR;
            c->times = malloc(sizeof(float) * (size_t)K);
            c->values = malloc(sizeof(float) * (size_t)comps * (size_t)K);
            ++an->channel_count; // counted now so that sp_rig_free releases it on failure
            if (!c->times || !c->values) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
            c->key_count = K;
            for (int k = 0; k < K; ++k) {
                size_t at = (size_t)k * (size_t)DJ + (size_t)d;
                float* v = c->values + (size_t)comps * (size_t)k;
                c->times[k] = w->times[k];
                if (path == SP_ANIM_TRANSLATION)
                    v[0] = (float)w->ct[at].x, v[1] = (float)w->ct[at].y, v[2] = (float)w->ct[at].z;
                else if (path == SP_ANIM_SCALE)
                    v[0] = (float)w->cs[at].x, v[1] = (float)w->cs[at].y, v[2] = (float)w->cs[at].z;
                else
                    v[0] = (float)w->cr[at].x, v[1] = (float)w->cr[at].y, v[2] = (float)w->cr[at].z, v[3] = (float)w->cr[at].w;
            }
        }
    }
    snprintf(info->clip, sizeof info->clip, "%s", an->name);
    info->clip_keys = K;
    info->clip_channels = an->channel_count;
    return SP_OK;
}

// The derived joints, skinning and parameters (root reach set later, from the camera).
static sp_result build_rig(const work* w, sp_rig* R, sp_error* err)
{
    const sp_rig* sr = w->sr;
    int DJ = w->count;
    R->joints = calloc((size_t)DJ, sizeof(sp_joint));
    size_t nv = (size_t)sr->vertex_count;
    R->rest = malloc(sizeof(double) * 3 * nv);
    R->joints4 = malloc(sizeof(uint16_t) * 4 * nv);
    R->weights4 = malloc(sizeof(float) * 4 * nv);
    R->triangles = malloc(sizeof(uint32_t) * 3 * (size_t)sr->triangle_count + 1);
    if (!R->joints || !R->rest || !R->joints4 || !R->weights4 || !R->triangles)
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    R->joint_count = DJ;
    for (int d = 0; d < DJ; ++d) {
        const djoint* q = &w->j[d];
        sp_joint* jt = &R->joints[d];
        if (q->src >= 0) {
            snprintf(jt->name, sizeof jt->name, "%s", sr->joints[q->src].name);
        } else {
            snprintf(jt->name, sizeof jt->name, "sp_root");
            for (int k = 1; sp_rig_find_joint(sr, jt->name) >= 0; ++k)
                snprintf(jt->name, sizeof jt->name, "sp_root_%d", k);
        }
        jt->parent = q->parent;
        if (q->parent >= 0) {
            const djoint* p = &w->j[q->parent];
            jt->rest_t = sp_quat_rotate(rot_z(-p->angle), sp_v3_sub(q->pivot, p->pivot));
            jt->rest_r = rot_z(q->angle - p->angle);
        } else {
            jt->rest_t = q->pivot;
            jt->rest_r = rot_z(q->angle);
        }
        jt->rest_s = sp_v3(1, 1, 1);
        // The skin matrix at rest stays the source's (in the part's space):
        // F_j IBM'_j = W S_j, so every vertex deforms as in the file.
        sp_mat4 finv;
        sp_mat4_inverse(&w->F[d], &finv);
        if (q->src >= 0) {
            sp_mat4 ws = sp_mat4_mul(&w->W, &w->S[q->src]);
            jt->inverse_bind = sp_mat4_mul(&finv, &ws);
        } else {
            jt->inverse_bind = finv;
        }
    }
    R->vertex_count = sr->vertex_count;
    memcpy(R->rest, sr->rest, sizeof(double) * 3 * nv);
    memcpy(R->weights4, sr->weights4, sizeof(float) * 4 * nv);
    for (size_t i = 0; i < 4 * nv; ++i)
        R->joints4[i] = sr->weights4[i] > 0 ? (uint16_t)w->to_derived[sr->joints4[i]] : 0;
    R->triangle_count = sr->triangle_count;
    memcpy(R->triangles, sr->triangles, sizeof(uint32_t) * 3 * (size_t)sr->triangle_count);

    // Bone scales: D joints with a scale on one chain from the root may each
    // change by a factor within [0.6, 1.6]^(1/D), so that no bone, with the
    // joints above it, leaves 0.6..1.6 of its length.
    int* up = calloc((size_t)DJ, sizeof(int));
    int* down = calloc((size_t)DJ, sizeof(int));
    if (!up || !down) {
        free(up), free(down);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    for (int d = 0; d < DJ; ++d) {
        int scaled = w->j[d].parent >= 0 && w->j[d].moves;
        up[d] = scaled + (w->j[d].parent >= 0 ? up[w->j[d].parent] : 0);
    }
    for (int d = DJ - 1; d >= 0; --d) {
        int scaled = w->j[d].parent >= 0 && w->j[d].moves, pa = w->j[d].parent;
        down[d] += scaled;
        if (pa >= 0 && down[d] > down[pa]) down[pa] = down[d];
    }
    sp_result r = SP_OK;
    for (int d = 0; d < DJ && r == SP_OK; ++d) {
        const djoint* q = &w->j[d];
        int ok = 0;
        if (q->parent < 0) {
            double lim = fmax(ROOT_ROT_LIMIT, q->limit > JOINT_ROT_LIMIT ? q->limit : 0.0);
            ok |= sp_rig_add_param(R, d, SP_CH_RZ, -lim, lim, SP_GROUP_POSE) < 0;
            ok |= sp_rig_add_param(R, d, SP_CH_TX, -1, 1, SP_GROUP_POSE) < 0;
            ok |= sp_rig_add_param(R, d, SP_CH_TY, -1, 1, SP_GROUP_POSE) < 0;
            ok |= sp_rig_add_param(R, d, SP_CH_S, ROOT_SCALE_MIN, ROOT_SCALE_MAX, SP_GROUP_SHAPE) < 0;
        } else if (q->moves) {
            double depth = up[d] + down[d] - 1;
            ok |= sp_rig_add_param(R, d, SP_CH_RZ, -q->limit, q->limit, SP_GROUP_POSE) < 0;
            ok |= sp_rig_add_param(R, d, SP_CH_S, pow(BONE_SCALE_MIN, 1.0 / depth), pow(BONE_SCALE_MAX, 1.0 / depth),
                                   SP_GROUP_SHAPE) < 0;
        }
        if (ok) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    free(up), free(down);
    return r;
}

// The traced outline (world points at rest) moved to bind space: x0 = A^-1 x
// with A the point's blended skin matrix at rest, as the mesh's vertices are.
static sp_result add_outline(sp_rig* R, const double* xyz, const sp_mat4* skin, const sp_camera* cam, int points,
                             sp_derive_info* info, sp_character* warn_to, sp_error* err)
{
    size_t nv = (size_t)R->vertex_count;
    double* wd = malloc(sizeof(double) * 4 * nv);
    if (!wd) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    for (size_t i = 0; i < 4 * nv; ++i)
        wd[i] = R->weights4[i];
    sp_outline_desc od = {.vertex_count = R->vertex_count,
                          .positions = xyz,
                          .influences = 4,
                          .joints = R->joints4,
                          .weights = wd,
                          .triangle_count = R->triangle_count,
                          .triangles = R->triangles,
                          .camera = cam,
                          .points = points,
                          .depth_passes = DEPTH_PASSES,
                          .surface = true,
                          .keep_largest = true};
    sp_abstraction ab;
    sp_outline_info oi;
    sp_result r = sp_outline_trace(&od, &ab, &oi, err);
    free(wd);
    if (r != SP_OK) return r;
    info->outline_regions = oi.regions;
    info->outline_dropped = oi.dropped_share;
    if (oi.dropped_share > 0.005)
        sp_character_warn(
            warn_to, "the side silhouette is in %d pieces: the outline follows the largest (%.1f%% of the silhouette left out)",
            oi.regions, 100.0 * oi.dropped_share);
    for (int i = 0; i < ab.point_count; ++i) {
        sp_mat4 A = {{0}};
        for (int k = 0; k < 4; ++k) {
            double wk = ab.weights[4 * i + k];
            if (!(wk > 0)) continue;
            for (int e = 0; e < 16; ++e)
                A.m[e] += wk * skin[ab.joints[4 * i + k]].m[e];
        }
        sp_mat4 inv;
        if (!sp_mat4_inverse_rel(&A, SP_MAT4_FLAT, &inv)) {
            sp_abstraction_free(&ab);
            return sp_fail(err, SP_ERR_INVALID, "the skin collapses at outline point %d (a singular blend of joint matrices)", i);
        }
        sp_vec3 x0 = sp_mat4_point(&inv, sp_v3(ab.rest[3 * i], ab.rest[3 * i + 1], ab.rest[3 * i + 2]));
        ab.rest[3 * i] = x0.x, ab.rest[3 * i + 1] = x0.y, ab.rest[3 * i + 2] = x0.z;
    }
    r = sp_gltf_append_curve(R, "outline", SP_CORR_CLOSEST, "outline", true, ab.point_count, ab.rest, ab.joints, ab.weights) ==
                SP_OK
            ? SP_OK
            : sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sp_abstraction_free(&ab);
    return r;
}

// sp_part: the source's (sockets turned into the part's space), with the
// category, the abstraction and the attachment point.
static sp_result derived_part(const work* w, const sp_rig* R, const char* category, const char* abstraction, int attach,
                              sp_part* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (w->src->has_part && sp_part_copy(&w->src->part, out, err) != SP_OK) return SP_ERR_NO_MEMORY;
    for (int i = 0; i < out->socket_count; ++i)
        if (out->sockets[i].has_position) out->sockets[i].position = sp_mat4_point(&w->W, out->sockets[i].position);
    snprintf(out->category, sizeof out->category, "%s", category ? category : "");
    snprintf(out->abstraction, sizeof out->abstraction, "%s", abstraction);
    free(out->attach.extra);
    out->has_attach = true;
    out->attach = (sp_part_attach){.has_position = true, .position = w->j[attach].pivot};
    snprintf(out->attach.socket, sizeof out->attach.socket, "%s", category ? category : "");
    snprintf(out->attach.joint, sizeof out->attach.joint, "%s", R->joints[attach].name);
    return SP_OK;
}

// Whether some triangle has an area above rounding, relative to the mesh's
// size: a mesh of flattened triangles has no silhouette in any view.
static bool has_area(const sp_rig* r)
{
    sp_vec3 lo, hi;
    sp_bounds(r->rest, r->vertex_count, &lo, &hi);
    double ext = fmax(hi.x - lo.x, fmax(hi.y - lo.y, hi.z - lo.z));
    if (!(ext > 0) || !isfinite(ext)) return false;
    double tiny = 1e-12 * ext * ext;
    for (int t = 0; t < r->triangle_count; ++t) {
        const uint32_t* q = r->triangles + 3 * (size_t)t;
        if (q[0] >= (uint32_t)r->vertex_count || q[1] >= (uint32_t)r->vertex_count || q[2] >= (uint32_t)r->vertex_count)
            return true; // the tracer names the bad index
        const double *a = r->rest + 3 * (size_t)q[0], *b = r->rest + 3 * (size_t)q[1], *c = r->rest + 3 * (size_t)q[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n0 = u[1] * v[2] - u[2] * v[1], n1 = u[2] * v[0] - u[0] * v[2], n2 = u[0] * v[1] - u[1] * v[0];
        if (sqrt(n0 * n0 + n1 * n1 + n2 * n2) > tiny) return true;
    }
    return false;
}

// What a derived part is refused for before any work: several skins, no
// skinned mesh or no surface, an abstraction other than outline or stick,
// a category the part database would refuse (after the work).
static sp_result check_source(const sp_character* src, const sp_derive_desc* d, const char** abstraction, const char** category,
                              sp_error* err)
{
    const sp_rig* sr = &src->rig;
    if (src->mesh_skins > 1)
        return sp_fail(err, SP_ERR_UNSUPPORTED,
                       "the file has %d skins; a part is one skinned mesh (join the meshes under one armature first)",
                       src->mesh_skins);
    if (sr->joint_count == 0 || sr->vertex_count == 0 || !sr->weights4)
        return sp_fail(err, SP_ERR_UNSUPPORTED, "the file has no skinned mesh");
    if (sr->triangle_count == 0)
        return sp_fail(err, SP_ERR_INVALID, "the skinned mesh has no triangles to trace an outline from");
    if (!has_area(sr))
        return sp_fail(err, SP_ERR_INVALID,
                       "the skinned mesh's %d triangles all have no area (corners in one place or in a line): no surface "
                       "to trace an outline from",
                       sr->triangle_count);
    *abstraction = d->abstraction ? d->abstraction : "outline";
    if (strcmp(*abstraction, "outline") != 0 && strcmp(*abstraction, "stick") != 0)
        return sp_fail(err, SP_ERR_INVALID, "abstraction '%s': a derived part's sketches show its outline or its stick figure",
                       *abstraction);
    const char* c = d->category ? d->category : src->part.category[0] ? src->part.category : NULL;
    *category = c;
    // Refused here, as the part database would refuse it later (after the work).
    char shown[128]; // escaped: a category from the file may hold newlines and escape codes
    if (c && !sp_part_name_is_plain(c))
        return sp_fail(err, SP_ERR_INVALID,
                       "category '%s': not a plain name ([A-Za-z0-9_.-], 1 to %d characters, not starting with '.'), as the "
                       "part database takes it",
                       sp_text_printable(c, shown, sizeof shown), SP_NAME_MAX - 1);
    return SP_OK;
}

// The source at rest (node TRS; tr, rot, sc: scratch of a joint each): its
// joints' world and skin matrices, its mesh in the part's space and extent.
static sp_result source_at_rest(work* w, sp_vec3* tr, sp_quat* rot, sp_vec3* sc, sp_error* err)
{
    const sp_rig* sr = w->sr;
    int SJ = sr->joint_count;
    size_t nv = (size_t)sr->vertex_count;
    for (int j = 0; j < SJ; ++j)
        tr[j] = sr->joints[j].rest_t, rot[j] = sr->joints[j].rest_r, sc[j] = sr->joints[j].rest_s;
    fk(sr, tr, rot, sc, w->G);
    for (int j = 0; j < SJ; ++j) {
        if (!sp_mat4_inverse_rel(&w->G[j], SP_MAT4_FLAT, &w->Ginv[j]))
            return sp_fail(err, SP_ERR_INVALID, "joint '%s' has a singular rest transform (a zero or vanishing scale)",
                           sr->joints[j].name);
        w->S[j] = sp_mat4_mul(&w->G[j], &sr->joints[j].inverse_bind);
    }
    sp_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < nv; ++i) {
        sp_vec3 x0 = sp_v3(sr->rest[3 * i], sr->rest[3 * i + 1], sr->rest[3 * i + 2]), x = {0, 0, 0};
        for (int k = 0; k < 4; ++k) {
            double wk = sr->weights4[4 * i + (size_t)k];
            if (wk > 0) x = sp_v3_add(x, sp_v3_scale(sp_mat4_point(&w->S[sr->joints4[4 * i + (size_t)k]], x0), wk));
        }
        x = sp_mat4_point(&w->W, x);
        w->xyz[3 * i] = x.x, w->xyz[3 * i + 1] = x.y, w->xyz[3 * i + 2] = x.z;
        lo = sp_v3(fmin(lo.x, x.x), fmin(lo.y, x.y), fmin(lo.z, x.z));
        hi = sp_v3(fmax(hi.x, x.x), fmax(hi.y, x.y), fmax(hi.z, x.z));
    }
    w->extent = sp_v3_len(sp_v3_sub(hi, lo));
    if (!(w->extent > 0) || !isfinite(w->extent)) return sp_fail(err, SP_ERR_INVALID, "the mesh at rest has no extent");
    return SP_OK;
}

// A part attached by a root three or more limbs branch from (a figure's
// hips: legs and spine) hangs from the body there: a figure drawn standing
// on a dragon's back sank into it to the waist (an outside curator review).
// Said, naming the lowest joint, which such a figure stands on; the attach
// point is the curator's choice (a pair of legs hangs by its hips). ev
// holds the rest pose.
static void warn_attach_between_limbs(const sp_rig* R, const sp_rig_eval* ev, const bool* is_skin, sp_character* notes)
{
    int limbs = 0, lowest = -1;
    const sp_mat4* world = sp_rig_eval_world(ev);
    for (int c = 1; c < R->joint_count; ++c) {
        if (!is_skin[c]) continue;
        if (R->joints[c].parent == 0) ++limbs;
        if (lowest < 0 || sp_mat4_translation(&world[c]).y < sp_mat4_translation(&world[lowest]).y) lowest = c;
    }
    if (limbs >= 3 && lowest > 0) // a pair of legs (two) rightly hangs by its hips
        sp_character_warn(notes,
                          "it attaches by its root '%s', where %d limbs branch: on a body it hangs from there (a figure standing "
                          "on a dragon sinks in to the waist); to stand on its lowest joint give --attach-joint %s",
                          R->joints[0].name, limbs, R->joints[lowest].name);
}

// The derived joint a part attaches by, named by its source joint.
static sp_result attach_joint_of(const work* w, const char* name, int* attach, sp_error* err)
{
    int sj = sp_rig_find_joint(w->sr, name);
    if (sj < 0) return sp_fail(err, SP_ERR_INVALID, "--attach-joint: no joint named '%s'", name);
    if (w->to_derived[sj] < 0)
        return sp_fail(err, SP_ERR_INVALID, "--attach-joint: joint '%s' is above the skin (it moves no vertex)", name);
    *attach = w->to_derived[sj];
    return SP_OK;
}

bool sp_part_curves_warning(const sp_rig* rig, int a, char* line, size_t cap)
{
    if (a < 0 || a >= rig->abstraction_count || rig->abstractions[a].curve_count <= 1) return false;
    snprintf(line, cap,
             "its '%s' abstraction has %d curves; the kiosk fits one stroke per part, so visitors cannot draw it in the kiosk "
             "(it suits `sketchpose pose`; the kiosk's parts use `outline`)",
             rig->abstractions[a].name, rig->abstractions[a].curve_count);
    return true;
}

// What the part's clip (w->clip, or none) says of the file's animations.
static void warn_clip(sp_character* out, const sp_rig* sr, const work* w)
{
    // A clip in the wrong unit (ms or frames read as seconds) is said either
    // way: 0.2 ms of keys was "no animation", 2000 s passed silently and
    // hardly moved in the kiosk (an outside review).
    int channels = 0;
    for (int a = 0; a < sr->animation_count; ++a)
        channels += sr->animations[a].channel_count;
    // Channels on nodes outside the skeleton were dropped at the load (said
    // then): a clip of those alone was sent to look at its key times.
    if (!w->clip && sr->animation_count > 0 && channels == 0)
        sp_character_warn(out, "the file's animations move no joint of the skin (their channels are on other nodes): the "
                               "part has no clip");
    else if (!w->clip && sr->animation_count > 0)
        sp_character_warn(out, "the file's animations have no keys more than 1 ms apart: the part has no clip (are its key "
                               "times in seconds?)");
    else if (!w->clip)
        sp_character_warn(out, "no animation with keys: the part has no clip (it holds its fitted pose in the kiosk)");
    else if (w->times[w->keys - 1] - w->times[0] > CLIP_LONG_S)
        sp_character_warn(out,
                          "clip '%s' lasts %.0f s: the kiosk loops it, so the part hardly moves (are its key times in "
                          "seconds, not frames or ms?)",
                          w->clip->name, (double)(w->times[w->keys - 1] - w->times[0]));
}

sp_result sp_part_derive(const sp_character* src, const sp_derive_desc* desc, sp_character* out, sp_derive_info* info_out,
                         sp_error* err)
{
    memset(out, 0, sizeof *out);
    sp_derive_desc d = desc ? *desc : (sp_derive_desc){0};
    sp_derive_info info_tmp;
    sp_derive_info* info = info_out ? info_out : &info_tmp;
    memset(info, 0, sizeof *info);
    const sp_rig* sr = &src->rig;
    const char *abstraction = NULL, *category = NULL;
    sp_result r = check_source(src, &d, &abstraction, &category, err);
    if (r != SP_OK) return r;

    work w = {0};
    w.src = src;
    w.sr = sr;
    w.W = view_rotation(src, d.view);
    w.Wt = transpose3(&w.W);
    int SJ = sr->joint_count;
    size_t nv = (size_t)sr->vertex_count;
    w.G = malloc(sizeof(sp_mat4) * (size_t)SJ);
    w.Ginv = malloc(sizeof(sp_mat4) * (size_t)SJ);
    w.S = malloc(sizeof(sp_mat4) * (size_t)SJ);
    w.influences = calloc((size_t)SJ, sizeof(bool));
    w.to_derived = malloc(sizeof(int) * (size_t)SJ);
    w.xyz = malloc(sizeof(double) * 3 * nv);
    sp_vec3 *tr = NULL, *sc = NULL;
    sp_quat* rot = NULL;
    tr = calloc((size_t)SJ, sizeof(sp_vec3));
    rot = calloc((size_t)SJ, sizeof(sp_quat));
    sc = calloc((size_t)SJ, sizeof(sp_vec3));
    sp_rig R = {0};
    sp_rig_eval* ev = NULL;
    double* p = NULL;
    bool* is_skin = NULL;
    sp_part part = {0};
    if (!w.G || !w.Ginv || !w.S || !w.influences || !w.to_derived || !w.xyz || !tr || !rot || !sc) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    if ((r = source_at_rest(&w, tr, rot, sc, err)) != SP_OK) goto done;
    if ((r = build_joints(&w, info, err)) != SP_OK || (r = convert_clip(&w, err)) != SP_OK ||
        (r = build_rig(&w, &R, err)) != SP_OK)
        goto done;
    int attach = 0;
    if (d.attach_joint && (r = attach_joint_of(&w, d.attach_joint, &attach, err)) != SP_OK) goto done;
    if (w.clip && (r = add_clip(&w, &R, info, err)) != SP_OK) goto done;
    const char* what = "the derived part";
    if ((r = sp_rig_finalize(&R, what, NULL, err)) != SP_OK) goto done;

    // The side view of the rest pose, the root's reach, the abstractions.
    sp_rig_eval_create(&R, &ev, NULL);
    p = malloc(sizeof(double) * (size_t)(R.param_count + 1));
    is_skin = malloc(sizeof(bool) * (size_t)R.joint_count);
    if (!ev || !p || !is_skin) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    sp_rig_defaults(&R, p);
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(&R), w.xyz);
    sp_vec3 lo, hi;
    sp_bounds(w.xyz, R.vertex_count, &lo, &hi);
    sp_camera cam = sp_part_side_camera(lo, hi, FRAME_MARGIN);
    double reach = 0.5 * fmax(cam.width, cam.height) / cam.scale;
    // A part whose moves our own readers refuse is no part (a model in
    // micrometres was written, then refused by inspect: an outside review).
    if (!(reach <= SP_GLTF_MOVE_MAX)) {
        r = sp_fail(err, SP_ERR_INVALID,
                    "the model is %.3g units across: its placement would move it by up to %.3g, over the %.0e a part's moves may "
                    "span; scale it down (a model in micrometres to metres)",
                    fmax(hi.x - lo.x, fmax(hi.y - lo.y, hi.z - lo.z)), reach, SP_GLTF_MOVE_MAX);
        goto done;
    }
    for (int q = 0; q < R.param_count; ++q)
        if (R.joints[R.params[q].joint].parent < 0 && (R.params[q].channel == SP_CH_TX || R.params[q].channel == SP_CH_TY))
            R.params[q].min = -reach, R.params[q].max = reach;
    // Warnings go on the new character; collect them in a scratch one first.
    sp_character notes = {0};
    r = add_outline(&R, w.xyz, sp_rig_eval_skin(ev), &cam, d.outline_points > 0 ? d.outline_points : OUTLINE_POINTS, info, &notes,
                    err);
    if (r != SP_OK) {
        sp_character_free(&notes);
        goto done;
    }
    for (int j = 0; j < R.joint_count; ++j)
        is_skin[j] = w.j[j].src >= 0;
    int flat = 0;
    if ((r = sp_gltf_derive_stick(&R, is_skin, &flat, err)) != SP_OK || (r = sp_rig_finalize(&R, what, NULL, err)) != SP_OK) {
        sp_character_free(&notes);
        goto done;
    }
    if (flat > 0)
        sp_character_warn(&notes,
                          "the stick figure leaves out %d bone%s whose skin flattens the mesh (a singular inverse bind matrix)",
                          flat, flat == 1 ? "" : "s");
    if (!d.attach_joint) warn_attach_between_limbs(&R, ev, is_skin, &notes);
    bool stick = sp_rig_find_abstraction(&R, "stick") >= 0;
    if (!strcmp(abstraction, "stick") && !stick) {
        sp_character_free(&notes);
        r = sp_fail(err, SP_ERR_INVALID, "abstraction 'stick': the skeleton has no bones to draw a stick figure of");
        goto done;
    }
    if ((r = derived_part(&w, &R, category, abstraction, attach, &part, err)) != SP_OK) {
        sp_character_free(&notes);
        goto done;
    }
    info->derived = SP_DERIVED_OUTLINE | (stick ? SP_DERIVED_STICK : 0) | SP_DERIVED_PARAMETERS | SP_DERIVED_ATTACH |
                    (w.clip ? SP_DERIVED_CLIP : 0) | SP_DERIVED_VIEW;
    snprintf(info->root, sizeof info->root, "%s", R.joints[0].name);
    snprintf(info->attach_joint, sizeof info->attach_joint, "%s", R.joints[attach].name);
    if ((r = sp_character_from_rig(&R, out, err)) != SP_OK) {
        sp_character_free(&notes);
        goto done;
    }
    if (src->colors) memcpy(out->colors, src->colors, sizeof(float) * 4 * nv);
    out->camera = cam;
    out->has_camera = true;
    out->has_part = true;
    out->part = part;
    memset(&part, 0, sizeof part);
    for (int i = 0; i < src->warning_count; ++i)
        sp_character_warn(out, "%s", src->warnings[i]);
    for (int i = 0; i < notes.warning_count; ++i)
        sp_character_warn(out, "%s", notes.warnings[i]);
    sp_character_free(&notes);
    if (!src->derived_dofs) sp_character_warn(out, "the file's own sp_dofs were replaced by the derived parameters");
    if (sr->animation_count > 1)
        sp_character_warn(out, "only the clip '%s' is kept; %d other animations were left out", w.clip ? w.clip->name : "",
                          sr->animation_count - 1);
    warn_clip(out, sr, &w);
    // The kiosk fits one stroke per part: a figure of several curves cannot
    // be drawn there (an outside review's stick figure became six parts).
    char line[320];
    if (sp_part_curves_warning(&out->rig, sp_rig_find_abstraction(&out->rig, abstraction), line, sizeof line))
        sp_character_warn(out, "%s", line);
done:
    sp_part_free(&part);
    free(is_skin);
    free(p);
    sp_rig_eval_destroy(ev);
    sp_rig_free(&R);
    free(tr), free(rot), free(sc);
    work_free(&w);
    if (r != SP_OK) sp_character_free(out);
    return r;
}
