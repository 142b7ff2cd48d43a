// elephant.c: the paper's Elephant: a quadruped with a trunk, big ears and
// tusks, ~2k vertices, 49 joints, 132 parameters, seen from the side (he
// faces +X; the sketch view looks along -Z), with a stick-figure abstraction
// (a curve per bone chain, ordered) and a looping `walk` clip.
//
// Skeleton: hips (root) -> spine_1 -> spine_2 -> spine_3 -> neck -> head -> jaw, trunk_1..trunk_10,
// ear_<s>_1 -> ear_<s>_2, tusk_<s>; hips -> tail_1..tail_6; spine_3 -> scapula_<s> -> upper_arm ->
// forearm -> front_foot -> front_toes; hips -> hip_<s> -> thigh -> shin -> hind_foot -> hind_toes
// (s = l: the near side, +Z; r: the far side).
//
// Joint frames (gen_rig): local X along the bone in the side view, local Z
// towards the viewer: `rz` bends in the picture (what the stick figure
// shows), `ry` swings out of it (a leg outwards, the trunk sideways, an ear
// flapping), `rx` twists. The near legs stand forward at the front and back
// at the rear and the far legs the other way, so that all four read in the
// side view; the legs' own joints sit in their own planes (z = +-0.3) so
// that bone scales grow a leg along itself.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "characters.h"
#include "gen_mesh.h"
#include "gen_rig.h"
#include "gen_stick.h"

static const double k_pi = 3.14159265358979323846;

enum { NEAR = 0, FAR = 1, TRUNK = 10, TAIL = 6 };

// Palette (sRGB).
static const sp_gen_rgb k_hide = {0.56, 0.55, 0.57}, k_hide_dark = {0.42, 0.41, 0.44}, k_ear_inner = {0.80, 0.60, 0.60};
static const sp_gen_rgb k_ivory = {0.96, 0.93, 0.84}, k_ivory_tip = {0.85, 0.80, 0.68}, k_eye = {0.10, 0.08, 0.07};
static const sp_gen_rgb k_nail = {0.86, 0.83, 0.76}, k_lip = {0.62, 0.50, 0.52}, k_tuft = {0.22, 0.2, 0.2};

static const sp_vec3 k_hips = {-0.72, 1.42, 0}, k_spine[3] = {{-0.32, 1.5, 0}, {0.1, 1.52, 0}, {0.48, 1.48, 0}};
static const sp_vec3 k_neck = {0.78, 1.5, 0}, k_head = {0.98, 1.58, 0}, k_jaw = {1.08, 1.3, 0};
static const sp_vec3 k_head_c = {1.05, 1.58, 0}, k_head_r = {0.38, 0.4, 0.34};
static const double k_leg_z = 0.3;

// A limb's landmarks at stance 0: top pivot, the three bends, the front of
// the pad (toes pivot) and the toe tip.
typedef struct leg_desc {
    sp_vec3 pt[6];
    double radius[5]; ///< at the top, first bend, second bend, wrist/ankle, pad
} leg_desc;

static const leg_desc k_front = {
    .pt = {{0.42, 1.62, 0}, {0.48, 1.12, 0}, {0.45, 0.68, 0}, {0.5, 0.26, 0}, {0.6, 0.06, 0}, {0.68, 0.03, 0}},
    .radius = {0.2, 0.2, 0.155, 0.14, 0.165}};
static const leg_desc k_hind = {
    .pt = {{-0.72, 1.42, 0}, {-0.68, 1.1, 0}, {-0.6, 0.64, 0}, {-0.66, 0.26, 0}, {-0.56, 0.06, 0}, {-0.48, 0.03, 0}},
    .radius = {0.24, 0.23, 0.16, 0.14, 0.165}};

typedef struct elephant {
    sp_gen_rig g;
    sp_gen_mesh m;
    int hips, spine[3], neck, head, jaw, trunk[TRUNK], ear1[2], ear2[2], tusk[2], tail[TAIL];
    int front[2][5], hind[2][5]; ///< girdle, upper, lower, foot, toes
    sp_vec3 front_pt[2][6], hind_pt[2][6];
    sp_gen_path trunk_path, tail_path;
    sp_vec3 trunk_at[TRUNK + 1], tail_at[TAIL + 1]; ///< joint pivots and the tip
} elephant;

static double angle_of(sp_vec3 a, sp_vec3 b)
{
    return atan2(b.y - a.y, b.x - a.x);
}

static sp_vec3 side_z(sp_vec3 p, int side)
{
    return sp_v3(p.x, p.y, side == NEAR ? p.z : -p.z);
}

// ---- colours ---------------------------------------------------------------

// Grey hide, mottled, a little darker along the back.
static sp_gen_rgb hide_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)user;
    double n = 0.6 * sp_gen_noise2(p.x * 9.0 + p.z * 4.0, p.y * 9.0 - p.z * 3.0, 7u) +
               0.4 * sp_gen_noise2(p.x * 3.0 - p.z * 2.0, p.y * 3.0 + p.z * 5.0, 13u);
    sp_gen_rgb c = sp_gen_mix(k_hide, k_hide_dark, 0.35 * sp_gen_smoothstep(0.3, 1.0, cos(a)));
    return sp_gen_shade(c, 0.9 + 0.16 * n);
}

static sp_gen_rgb plain_hide(double u, double a, sp_vec3 p, void* user)
{
    (void)a;
    return hide_color(u, 0.5 * k_pi, p, user);
}

// The trunk: wrinkled rings.
static sp_gen_rgb trunk_color(double u, double a, sp_vec3 p, void* user)
{
    double len = *(const double*)user;
    double ph = u * len / 0.045;
    double groove = sp_gen_smoothstep(0.75, 1.0, ph - floor(ph));
    return sp_gen_shade(plain_hide(u, a, p, NULL), 1.0 - 0.18 * groove);
}

// Feet: toenails along the front of the pad.
static sp_gen_rgb leg_color(double u, double a, sp_vec3 p, void* user)
{
    (void)a, (void)user;
    sp_gen_rgb c = plain_hide(u, a, p, NULL);
    if (p.y < 0.13 && u > 0.9) {
        // Nails: three bumps of colour around the front of the pad.
        double nails = 0.5 + 0.5 * cos(6.0 * atan2(p.z - (p.z > 0 ? k_leg_z : -k_leg_z), 1.0));
        c = sp_gen_mix(c, k_nail, sp_gen_smoothstep(0.3, 0.7, nails) * sp_gen_smoothstep(0.13, 0.08, p.y));
    }
    return c;
}

// An ear: a flat ellipsoid, tall (ax), reaching back and outwards from the
// side of the head over the shoulder (ay), thin (az).
typedef struct ear_ctx {
    sp_vec3 center, ax, ay, az;
} ear_ctx;

static ear_ctx ear_frame(int side)
{
    ear_ctx e = {.center = sp_v3(0.72, 1.42, 0.52), .ax = sp_v3(0, 0.5, 0), .ay = sp_v3(-0.32, 0, 0.16)};
    if (side == FAR) e.center.z = -e.center.z, e.ay.z = -e.ay.z;
    e.az = sp_v3_scale(sp_v3_norm(sp_v3_cross(e.ax, e.ay)), 0.035);
    return e;
}

static sp_gen_rgb ear_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a;
    const ear_ctx* e = user;
    sp_vec3 d = sp_v3_sub(p, e->center);
    // Pink on the side facing the body.
    bool inner = sp_v3_dot(d, e->az) * e->center.z * e->az.z < 0;
    sp_gen_rgb c = plain_hide(u, a, p, NULL);
    double rim = hypot(sp_v3_dot(d, e->ax) / sp_v3_dot(e->ax, e->ax), sp_v3_dot(d, e->ay) / sp_v3_dot(e->ay, e->ay));
    // A darker rim on the outside sets the ear off against the body.
    return inner ? sp_gen_mix(k_ear_inner, c, sp_gen_smoothstep(0.6, 0.95, rim))
                 : sp_gen_shade(c, 1.0 - 0.25 * sp_gen_smoothstep(0.75, 1.0, rim));
}

static sp_gen_rgb flat_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)p;
    return *(const sp_gen_rgb*)user;
}

// ---- profiles --------------------------------------------------------------

typedef struct body_ctx {
    const sp_gen_path* path;
} body_ctx;

static sp_gen_section body_profile(double u, void* user)
{
    const body_ctx* c = user;
    double x = sp_gen_path_at(c->path, u * c->path->length, NULL).x;
    // x -> above, below, half width: a round rump, a deep belly, high
    // shoulders, a short thick neck into the head.
    static const double up[][2] = {{-1.08, 0.3}, {-0.85, 0.44}, {-0.4, 0.46}, {0.15, 0.5}, {0.55, 0.52}, {0.85, 0.36}};
    static const double down[][2] = {{-1.08, 0.34}, {-0.85, 0.5}, {-0.3, 0.64}, {0.2, 0.64}, {0.6, 0.56}, {0.85, 0.36}};
    static const double side[][2] = {{-1.08, 0.32}, {-0.85, 0.48}, {-0.3, 0.6}, {0.2, 0.6}, {0.6, 0.52}, {0.85, 0.34}};
    return (sp_gen_section){sp_gen_interp(up, 6, x), sp_gen_interp(down, 6, x), sp_gen_interp(side, 6, x)};
}

static sp_gen_section trunk_profile(double u, void* user)
{
    (void)user;
    static const double r[][2] = {{0.0, 0.17}, {0.15, 0.15}, {0.5, 0.105}, {0.85, 0.078}, {1.0, 0.072}};
    double k = sp_gen_interp(r, 5, u);
    return (sp_gen_section){k, k, k * 1.05};
}

static sp_gen_section tail_profile(double u, void* user)
{
    (void)user;
    double k = 0.05 - 0.025 * u;
    return (sp_gen_section){k, k, k};
}

static sp_gen_section lip_profile(double u, void* user)
{
    (void)user;
    double k = 0.075 - 0.03 * u;
    return (sp_gen_section){k * 0.8, k * 0.8, k * 1.3};
}

typedef struct leg_ctx {
    const leg_desc* d;
    double s[5], len; ///< arc lengths of pt[0..3] and the pad
} leg_ctx;

static sp_gen_section leg_profile(double u, void* user)
{
    const leg_ctx* c = user;
    const double* R = c->d->radius;
    double k[][2] = {
        {0.0, R[0] * 0.8}, {c->s[0], R[0]}, {c->s[1], R[1]}, {c->s[1] + 0.5 * (c->s[2] - c->s[1]), 0.5 * (R[1] + R[2])},
        {c->s[2], R[2]},   {c->s[3], R[3]}, {c->len, R[4]}};
    for (int i = 0; i < 7; ++i)
        k[i][0] /= c->len;
    double r = sp_gen_interp((const double(*)[2])k, 7, u);
    return (sp_gen_section){r, r, r};
}

// ---- skeleton --------------------------------------------------------------

static sp_vec3 rot_about(sp_vec3 p, sp_vec3 c, double a)
{
    double x = p.x - c.x, y = p.y - c.y;
    return sp_v3(c.x + x * cos(a) - y * sin(a), c.y + x * sin(a) + y * cos(a), p.z);
}

static void build_joints(elephant* e)
{
    sp_gen_rig* g = &e->g;
    e->hips = sp_gen_joint(g, "hips", -1, k_hips, angle_of(k_hips, k_spine[0]));
    static const char* sn[3] = {"spine_1", "spine_2", "spine_3"};
    for (int k = 0; k < 3; ++k)
        e->spine[k] = sp_gen_joint(g, sn[k], k ? e->spine[k - 1] : e->hips, k_spine[k],
                                   angle_of(k_spine[k], k < 2 ? k_spine[k + 1] : k_neck));
    e->neck = sp_gen_joint(g, "neck", e->spine[2], k_neck, angle_of(k_neck, k_head));
    // The trunk hangs from the lower front of the head, curling forward at the tip.
    const sp_vec3 tc[] = {{1.38, 1.22, 0}, {1.47, 0.95, 0}, {1.52, 0.68, 0}, {1.52, 0.42, 0}, {1.51, 0.2, 0}, {1.6, 0.07, 0}};
    sp_gen_path_catmull(&e->trunk_path, tc, 6, 24);
    for (int k = 0; k <= TRUNK; ++k)
        e->trunk_at[k] = sp_gen_path_at(&e->trunk_path, e->trunk_path.length * k / TRUNK, NULL);
    e->head = sp_gen_joint(g, "head", e->neck, k_head, angle_of(k_head, e->trunk_at[0]));
    e->jaw = sp_gen_joint(g, "jaw", e->head, k_jaw, angle_of(k_jaw, sp_v3(1.3, 1.12, 0)));
    char name[64];
    for (int k = 0; k < TRUNK; ++k) {
        snprintf(name, sizeof name, "trunk_%d", k + 1);
        e->trunk[k] =
            sp_gen_joint(g, name, k ? e->trunk[k - 1] : e->head, e->trunk_at[k], angle_of(e->trunk_at[k], e->trunk_at[k + 1]));
    }
    for (int s = 0; s < 2; ++s) {
        const char* sf = s == NEAR ? "l" : "r";
        snprintf(name, sizeof name, "ear_%s_1", sf);
        e->ear1[s] = sp_gen_joint(g, name, e->head, side_z(sp_v3(1.02, 1.5, 0.37), s), k_pi);
        snprintf(name, sizeof name, "ear_%s_2", sf);
        e->ear2[s] = sp_gen_joint(g, name, e->ear1[s], side_z(sp_v3(0.76, 1.45, 0.5), s),
                                  angle_of(sp_v3(0.76, 1.45, 0), sp_v3(0.45, 1.2, 0)));
        snprintf(name, sizeof name, "tusk_%s", sf);
        e->tusk[s] = sp_gen_joint(g, name, e->head, side_z(sp_v3(1.26, 1.2, 0.14), s),
                                  angle_of(sp_v3(1.26, 1.2, 0), sp_v3(1.66, 1.12, 0)));
    }
    const sp_vec3 lc[] = {{-1.1, 1.6, 0}, {-1.18, 1.38, 0}, {-1.21, 1.1, 0}, {-1.19, 0.84, 0}};
    sp_gen_path_catmull(&e->tail_path, lc, 4, 16);
    for (int k = 0; k <= TAIL; ++k)
        e->tail_at[k] = sp_gen_path_at(&e->tail_path, e->tail_path.length * k / TAIL, NULL);
    for (int k = 0; k < TAIL; ++k) {
        snprintf(name, sizeof name, "tail_%d", k + 1);
        e->tail[k] =
            sp_gen_joint(g, name, k ? e->tail[k - 1] : e->hips, e->tail_at[k], angle_of(e->tail_at[k], e->tail_at[k + 1]));
    }
    // Legs: near front forward, far front back; near hind back, far hind forward.
    static const char* fn[5] = {"scapula", "upper_arm", "forearm", "front_foot", "front_toes"};
    static const char* hn[5] = {"hip", "thigh", "shin", "hind_foot", "hind_toes"};
    for (int pair = 0; pair < 2; ++pair)
        for (int s = 0; s < 2; ++s) {
            const leg_desc* d = pair == 0 ? &k_front : &k_hind;
            double stance = (pair == 0 ? 1.0 : -1.0) * (s == NEAR ? 0.1 : -0.1);
            sp_vec3* pt = pair == 0 ? e->front_pt[s] : e->hind_pt[s];
            for (int k = 0; k < 6; ++k) {
                // The girdle pivot stays; the limb turns about its top joint.
                // The girdles pivot on the midline (z = 0), so that both
                // legs of a pair (and the hind legs, the back and the tail)
                // start at one point of the stick figure in every pose.
                pt[k] = k == 0 ? d->pt[0] : rot_about(d->pt[k], d->pt[1], stance);
                pt[k].z = k == 0 ? 0.0 : s == NEAR ? k_leg_z : -k_leg_z;
            }
            int* j = pair == 0 ? e->front[s] : e->hind[s];
            for (int k = 0; k < 5; ++k) {
                snprintf(name, sizeof name, "%s_%s", (pair == 0 ? fn : hn)[k], s == NEAR ? "l" : "r");
                int parent = k ? j[k - 1] : (pair == 0 ? e->spine[2] : e->hips);
                j[k] = sp_gen_joint(g, name, parent, pt[k], angle_of(pt[k], pt[k + 1]));
            }
        }
}

static void rot3(sp_gen_rig* g, int j, const double lim[3][2])
{
    for (int c = 0; c < 3; ++c)
        if (lim[c][1] > lim[c][0]) sp_gen_param(g, j, (sp_channel)(SP_CH_RX + c), lim[c][0], lim[c][1], SP_GROUP_POSE);
}

static void scale(sp_gen_rig* g, int j, double lo, double hi)
{
    sp_gen_param(g, j, SP_CH_S, lo, hi, SP_GROUP_SHAPE);
}

static void build_params(elephant* e)
{
    sp_gen_rig* g = &e->g;
    // Placement: the elephant is redrawn where he stands (moves by about a
    // third of his height), may turn a little out of the picture, and be
    // drawn a little larger or smaller.
    sp_gen_param(g, e->hips, SP_CH_RX, -0.4, 0.4, SP_GROUP_POSE);
    sp_gen_param(g, e->hips, SP_CH_RY, -0.6, 0.6, SP_GROUP_POSE);
    sp_gen_param(g, e->hips, SP_CH_RZ, -0.5, 0.5, SP_GROUP_POSE);
    sp_gen_param(g, e->hips, SP_CH_TX, -0.7, 0.7, SP_GROUP_POSE);
    sp_gen_param(g, e->hips, SP_CH_TY, -0.7, 0.7, SP_GROUP_POSE);
    sp_gen_param(g, e->hips, SP_CH_S, 0.8, 1.25, SP_GROUP_SHAPE);
    // A stiff back (rx rolls, ry turns, rz arches).
    static const double spine[3][2] = {{-0.15, 0.15}, {-0.2, 0.2}, {-0.15, 0.15}};
    for (int k = 0; k < 3; ++k)
        rot3(g, e->spine[k], spine);
    static const double neck[3][2] = {{-0.3, 0.3}, {-0.5, 0.5}, {-0.4, 0.3}};
    rot3(g, e->neck, neck);
    scale(g, e->neck, 0.85, 1.2);
    static const double head[3][2] = {{-0.3, 0.3}, {-0.4, 0.4}, {-0.5, 0.4}};
    rot3(g, e->head, head);
    scale(g, e->head, 0.85, 1.2);
    sp_gen_param(g, e->jaw, SP_CH_RZ, -0.35, 0.02, SP_GROUP_POSE);
    // The trunk curls (rz) and swings sideways (ry) at every joint; its
    // first joint also twists and sets its length.
    for (int k = 0; k < TRUNK; ++k) {
        if (k == 0) sp_gen_param(g, e->trunk[k], SP_CH_RX, -0.4, 0.4, SP_GROUP_POSE);
        sp_gen_param(g, e->trunk[k], SP_CH_RY, k == 0 ? -0.5 : -0.35, k == 0 ? 0.5 : 0.35, SP_GROUP_POSE);
        sp_gen_param(g, e->trunk[k], SP_CH_RZ, k == 0 ? -0.4 : -0.45, k == 0 ? 0.4 : 0.45, SP_GROUP_POSE);
        if (k == 0) scale(g, e->trunk[k], 0.8, 1.25);
    }
    for (int s = 0; s < 2; ++s) {
        // Ears flap outwards (ry < 0 on the near side; the far side mirrors
        // z, so its ry changes sense) and fold (ear_2).
        bool near = s == NEAR;
        double ry_lo = near ? -0.9 : -0.3, ry_hi = near ? 0.3 : 0.9;
        sp_gen_param(g, e->ear1[s], SP_CH_RX, -0.3, 0.3, SP_GROUP_POSE);
        sp_gen_param(g, e->ear1[s], SP_CH_RY, ry_lo, ry_hi, SP_GROUP_POSE);
        sp_gen_param(g, e->ear1[s], SP_CH_RZ, -0.3, 0.3, SP_GROUP_POSE);
        scale(g, e->ear1[s], 0.8, 1.2);
        sp_gen_param(g, e->ear2[s], SP_CH_RY, near ? -0.6 : -0.3, near ? 0.3 : 0.6, SP_GROUP_POSE);
        sp_gen_param(g, e->ear2[s], SP_CH_RZ, -0.3, 0.3, SP_GROUP_POSE);
        sp_gen_param(g, e->tusk[s], SP_CH_RZ, -0.15, 0.15, SP_GROUP_POSE);
        scale(g, e->tusk[s], 0.7, 1.3);
    }
    for (int k = 0; k < TAIL; ++k) {
        if (k == 0) sp_gen_param(g, e->tail[k], SP_CH_RX, -0.3, 0.3, SP_GROUP_POSE);
        sp_gen_param(g, e->tail[k], SP_CH_RY, k == 0 ? -0.6 : -0.5, k == 0 ? 0.6 : 0.5, SP_GROUP_POSE);
        sp_gen_param(g, e->tail[k], SP_CH_RZ, k == 0 ? -0.6 : -0.5, k == 0 ? 0.8 : 0.5, SP_GROUP_POSE);
        if (k == 0) scale(g, e->tail[k], 0.8, 1.3);
    }
    // Legs (X down): rz swings fore (+) and aft in the picture, ry outwards
    // or inwards, rx twists. An elephant's legs are columns: the elbow
    // barely moves, the wrist (front_foot) folds back when the foot lifts,
    // the knee (shin) folds back a little and the hock (hind_foot) forwards.
    for (int pair = 0; pair < 2; ++pair)
        for (int s = 0; s < 2; ++s) {
            const int* j = pair == 0 ? e->front[s] : e->hind[s];
            sp_gen_param(g, j[0], SP_CH_RY, -0.15, 0.15, SP_GROUP_POSE);
            sp_gen_param(g, j[0], SP_CH_RZ, -0.25, 0.25, SP_GROUP_POSE);
            sp_gen_param(g, j[1], SP_CH_RX, -0.3, 0.3, SP_GROUP_POSE);
            sp_gen_param(g, j[1], SP_CH_RY, -0.35, 0.35, SP_GROUP_POSE);
            sp_gen_param(g, j[1], SP_CH_RZ, -0.5, 0.55, SP_GROUP_POSE);
            scale(g, j[1], 0.85, 1.2);
            sp_gen_param(g, j[2], SP_CH_RY, -0.2, 0.2, SP_GROUP_POSE);
            sp_gen_param(g, j[2], SP_CH_RZ, pair == 0 ? -0.2 : -0.7, pair == 0 ? 0.35 : 0.2, SP_GROUP_POSE);
            scale(g, j[2], 0.85, 1.2);
            sp_gen_param(g, j[3], SP_CH_RX, -0.3, 0.3, SP_GROUP_POSE);
            sp_gen_param(g, j[3], SP_CH_RY, -0.3, 0.3, SP_GROUP_POSE);
            sp_gen_param(g, j[3], SP_CH_RZ, pair == 0 ? -0.9 : -0.2, pair == 0 ? 0.2 : 0.6, SP_GROUP_POSE);
            scale(g, j[3], 0.85, 1.2);
            sp_gen_param(g, j[4], SP_CH_RZ, -0.3, 0.3, SP_GROUP_POSE);
        }
}

// ---- mesh ------------------------------------------------------------------

// Side s's ear (a thin flap behind the eye, flapping about its front
// edge), tusk and eye.
static void build_ear_side(elephant* e, int s)
{
    sp_gen_mesh* m = &e->m;
    ear_ctx ec = ear_frame(s);
    int ef = sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = ec.center,
                                                          .ax = ec.ax,
                                                          .ay = ec.ay,
                                                          .az = ec.az,
                                                          .rings = 8,
                                                          .segments = 14,
                                                          .color = ear_color,
                                                          .user = &ec,
                                                          .skin = sp_gen_skin_one(e->ear1[s])});
    sp_gen_skin outer = sp_gen_skin_one(e->ear2[s]);
    sp_vec3 back_dir = sp_v3_norm(ec.ay);
    for (int v = ef; v < m->vertex_count; ++v) {
        // The lower half droops backwards into a lobe.
        sp_vec3 p = {m->pos[3 * v], m->pos[3 * v + 1], m->pos[3 * v + 2]};
        double up = sp_v3_dot(sp_v3_sub(p, ec.center), ec.ax) / sp_v3_dot(ec.ax, ec.ax);
        p = sp_v3_add(p, sp_v3_scale(back_dir, 0.12 * fmax(0.0, -up) * fmax(0.0, -up)));
        m->pos[3 * v] = p.x, m->pos[3 * v + 1] = p.y, m->pos[3 * v + 2] = p.z;
        // How far back from the front edge (where ear_1 holds it).
        sp_vec3 d = sp_v3_sub(sp_v3(m->pos[3 * v], m->pos[3 * v + 1], m->pos[3 * v + 2]), ec.center);
        double back = 1.0 + sp_v3_dot(d, ec.ay) / sp_v3_dot(ec.ay, ec.ay); // 0 at the front edge, 2 at the back
        m->skin[v] = sp_gen_skin_lerp(&m->skin[v], &outer, sp_gen_smoothstep(0.4, 1.2, back));
    }
    // Tusks and eyes.
    sp_vec3 base = side_z(sp_v3(1.26, 1.2, 0.14), s);
    sp_gen_cone(m, &(sp_gen_cone_desc){.base = base,
                                       .bend = side_z(sp_v3(1.5, 1.0, 0.17), s),
                                       .tip = side_z(sp_v3(1.68, 1.12, 0.2), s),
                                       .base_radius = 0.05,
                                       .tip_radius = 0.012,
                                       .taper = 0.8,
                                       .flat = 1.0,
                                       .rings = 6,
                                       .segments = 8,
                                       .base_color = k_ivory,
                                       .tip_color = k_ivory_tip,
                                       .skin = sp_gen_skin_one(e->tusk[s])});
    double ex = 1.24, ey = 1.64;
    double ez = k_head_r.z * sqrt(1.0 - pow((ex - k_head_c.x) / k_head_r.x, 2) - pow((ey - k_head_c.y) / k_head_r.y, 2)) - 0.008;
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = side_z(sp_v3(ex, ey, ez), s),
                                                 .ax = {0.035, 0, 0},
                                                 .ay = {0, 0.026, 0},
                                                 .az = {0, 0, 0.02},
                                                 .rings = 4,
                                                 .segments = 6,
                                                 .color = flat_color,
                                                 .user = (void*)&k_eye,
                                                 .skin = sp_gen_skin_one(e->head)});
}

// The tail with a dark tuft.
static void build_tail(elephant* e)
{
    sp_gen_mesh* m = &e->m;
    sp_gen_chain lch = {0};
    for (int k = 0; k < TAIL; ++k)
        sp_gen_chain_add(&lch, e->tail[k], e->tail_path.length * k / TAIL, k == 0 ? 0.0 : 0.03);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &e->tail_path,
                                       .rings = 12,
                                       .segments = 6,
                                       .profile = tail_profile,
                                       .color = plain_hide,
                                       .chain = &lch,
                                       .cap0_rings = 1,
                                       .cap0_len = 0.5});
    sp_vec3 tt = e->tail_at[TAIL], tdir;
    sp_gen_path_at(&e->tail_path, e->tail_path.length, &tdir);
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = sp_v3_add(tt, sp_v3_scale(tdir, 0.02)),
                                                 .ax = sp_v3_scale(tdir, 0.08),
                                                 .ay = sp_v3_scale(sp_v3(-tdir.y, tdir.x, 0), 0.04),
                                                 .az = {0, 0, 0.04},
                                                 .rings = 5,
                                                 .segments = 6,
                                                 .color = flat_color,
                                                 .user = (void*)&k_tuft,
                                                 .skin = sp_gen_skin_one(e->tail[TAIL - 1])});
}

static void build_body(elephant* e)
{
    sp_gen_mesh* m = &e->m;
    const sp_vec3 bc[] = {{-1.08, 1.45, 0}, {-0.72, 1.42, 0}, {-0.3, 1.46, 0}, {0.1, 1.48, 0}, {0.5, 1.47, 0}, {0.86, 1.52, 0}};
    sp_gen_path path;
    sp_gen_path_catmull(&path, bc, 6, 16);
    sp_gen_chain ch = {0};
    sp_gen_chain_add(&ch, e->hips, 0.0, 0.0);
    for (int k = 0; k < 3; ++k)
        sp_gen_chain_add(&ch, e->spine[k], sp_gen_path_project(&path, k_spine[k]), 0.15);
    sp_gen_chain_add(&ch, e->neck, sp_gen_path_project(&path, k_neck), 0.1);
    body_ctx bx = {&path};
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                       .rings = 22,
                                       .segments = 18,
                                       .profile = body_profile,
                                       .color = hide_color,
                                       .user = &bx,
                                       .chain = &ch,
                                       .cap0_rings = 3,
                                       .cap0_len = 0.7,
                                       .cap1_rings = 2,
                                       .cap1_len = 0.6});
    sp_gen_path_free(&path);

    // The head: a big dome; its back follows the neck part of the way.
    int first = sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = k_head_c,
                                                             .ax = {0, k_head_r.y, 0},
                                                             .ay = {0, 0, k_head_r.z},
                                                             .az = {k_head_r.x, 0, 0},
                                                             .rings = 12,
                                                             .segments = 18,
                                                             .color = hide_color,
                                                             .skin = sp_gen_skin_one(e->head)});
    sp_gen_skin nk = sp_gen_skin_one(e->neck);
    for (int v = first; v < m->vertex_count; ++v)
        m->skin[v] = sp_gen_skin_lerp(&m->skin[v], &nk, 0.5 * sp_gen_smoothstep(0.92, 0.7, m->pos[3 * v]));
    // The lower lip, on the jaw.
    const sp_vec3 jc[] = {{1.0, 1.32, 0}, {1.15, 1.24, 0}, {1.3, 1.14, 0}};
    sp_gen_path jp;
    sp_gen_path_catmull(&jp, jc, 3, 8);
    sp_gen_chain jch = {0};
    sp_gen_chain_add(&jch, e->head, 0.0, 0.0);
    sp_gen_chain_add(&jch, e->jaw, sp_gen_path_project(&jp, k_jaw), 0.05);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &jp,
                                       .rings = 6,
                                       .segments = 8,
                                       .profile = lip_profile,
                                       .color = flat_color,
                                       .user = (void*)&k_lip,
                                       .chain = &jch,
                                       .cap1_rings = 1,
                                       .cap1_len = 0.8});
    sp_gen_path_free(&jp);
    // The trunk, from inside the head.
    sp_vec3 tc[TRUNK + 2];
    tc[0] = sp_v3(1.22, 1.42, 0);
    for (int k = 0; k <= TRUNK; ++k)
        tc[k + 1] = e->trunk_at[k];
    sp_gen_path tp;
    sp_gen_path_catmull(&tp, tc, TRUNK + 2, 6);
    sp_gen_chain tch = {0};
    sp_gen_chain_add(&tch, e->head, 0.0, 0.0);
    for (int k = 0; k < TRUNK; ++k)
        sp_gen_chain_add(&tch, e->trunk[k], sp_gen_path_project(&tp, e->trunk_at[k]), k == 0 ? 0.08 : 0.05);
    double tl = tp.length;
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &tp,
                                       .s1 = tl - 0.03,
                                       .rings = 26,
                                       .segments = 10,
                                       .profile = trunk_profile,
                                       .color = trunk_color,
                                       .user = &tl,
                                       .chain = &tch,
                                       .cap1_rings = 2,
                                       .cap1_len = 0.4});
    sp_gen_path_free(&tp);
    for (int s = 0; s < 2; ++s)
        build_ear_side(e, s);
    build_tail(e);
}

static void build_leg(elephant* e, int pair, int s)
{
    sp_gen_mesh* m = &e->m;
    const leg_desc* d = pair == 0 ? &k_front : &k_hind;
    const sp_vec3* pt = pair == 0 ? e->front_pt[s] : e->hind_pt[s];
    const int* j = pair == 0 ? e->front[s] : e->hind[s];
    // From inside the body down to the pad (the last point is the pad's
    // bottom, under the ankle).
    sp_vec3 bottom = sp_v3(pt[3].x + 0.03, 0.1, pt[3].z);
    sp_vec3 top = sp_v3(pt[0].x, pt[0].y, pt[1].z); // the girdle pivot is on the midline; the limb in its plane
    sp_vec3 ctrl[6] = {sp_v3_add(top, sp_v3(0, 0.12, 0)), top, pt[1], pt[2], pt[3], bottom};
    sp_gen_path path;
    sp_gen_path_catmull(&path, ctrl, 6, 14);
    leg_ctx lc = {.d = d, .len = path.length};
    for (int k = 0; k < 4; ++k)
        lc.s[k] = sp_gen_path_project(&path, ctrl[k + 1]);
    lc.s[4] = path.length;
    sp_gen_chain ch = {0};
    sp_gen_chain_add(&ch, j[0], 0.0, 0.0);
    sp_gen_chain_add(&ch, j[1], lc.s[1], 0.16);
    sp_gen_chain_add(&ch, j[2], lc.s[2], 0.13);
    sp_gen_chain_add(&ch, j[3], lc.s[3], 0.08);
    sp_gen_chain_add(&ch, j[4], path.length - 0.02, 0.02);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                       .rings = 13,
                                       .segments = 12,
                                       .profile = leg_profile,
                                       .color = leg_color,
                                       .user = &lc,
                                       .chain = &ch,
                                       .cap1_rings = 2,
                                       .cap1_len = 0.3});
    sp_gen_path_free(&path);
}

static sp_abstraction build_stick(const elephant* e)
{
    sp_abstraction st;
    sp_gen_stick_begin(&st);
    const sp_gen_rig* g = &e->g;
    // The back from the hips to the head, ending where the trunk starts.
    int spine[6] = {e->hips, e->spine[0], e->spine[1], e->spine[2], e->neck, e->head};
    sp_gen_stick_curve(&st, g, "spine", spine, 6, e->trunk_at[0], 20);
    sp_gen_stick_curve(&st, g, "trunk", e->trunk, TRUNK, e->trunk_at[TRUNK], 20);
    int tail[TAIL + 1] = {e->hips};
    for (int k = 0; k < TAIL; ++k)
        tail[k + 1] = e->tail[k];
    sp_gen_stick_curve(&st, g, "tail", tail, TAIL + 1, e->tail_at[TAIL], 12);
    static const char* names[2][2] = {{"front_leg_l", "front_leg_r"}, {"hind_leg_l", "hind_leg_r"}};
    for (int pair = 0; pair < 2; ++pair)
        for (int s = 0; s < 2; ++s) {
            const int* j = pair == 0 ? e->front[s] : e->hind[s];
            const sp_vec3* pt = pair == 0 ? e->front_pt[s] : e->hind_pt[s];
            sp_gen_stick_curve(&st, g, names[pair][s], j, 5, pt[5], 12);
        }
    return st;
}

// `walk`: the diagonal pairs swing together (near front with far hind),
// lifting their feet on the forward swing; the head bobs, the trunk and
// the tail sway. The loop starts and ends at rest.
static void build_clip(elephant* e)
{
    enum { KEYS = 33 };
    sp_gen_rig* g = &e->g;
    sp_gen_clip_begin(g, "walk", 1.6, KEYS);
    for (int pair = 0; pair < 2; ++pair)
        for (int s = 0; s < 2; ++s) {
            const int* j = pair == 0 ? e->front[s] : e->hind[s];
            double ph0 = (pair == 0) == (s == NEAR) ? 0.0 : k_pi;
            double a[3][KEYS];
            for (int q = 0; q < KEYS; ++q) {
                double ph = 2.0 * k_pi * q / (KEYS - 1) + ph0;
                double lift = fmax(0.0, sin(ph + 0.5 * k_pi)); // the forward swing
                a[0][q] = 0.22 * sin(ph);
                a[1][q] = (pair == 0 ? 0.15 : -0.3) * lift * lift;
                a[2][q] = (pair == 0 ? -0.5 : 0.3) * lift * lift;
            }
            for (int k = 0; k < 3; ++k)
                sp_gen_clip_rz(g, j[k + 1], a[k]);
        }
    double head[KEYS], trunk[KEYS], tail[KEYS];
    for (int q = 0; q < KEYS; ++q) {
        double ph = 2.0 * k_pi * q / (KEYS - 1);
        head[q] = 0.05 * sin(2.0 * ph);
        trunk[q] = 0.08 * sin(ph + 0.8);
        tail[q] = 0.15 * sin(ph + 1.6);
    }
    sp_gen_clip_rz(g, e->head, head);
    for (int k = 2; k < TRUNK; k += 2)
        sp_gen_clip_rz(g, e->trunk[k], trunk);
    sp_gen_clip_rz(g, e->tail[0], tail);
    sp_gen_clip_rz(g, e->tail[3], tail);
}

sp_result sp_character_elephant(const char* path, sp_error* err)
{
    elephant e;
    memset(&e, 0, sizeof e);
    sp_gen_rig_init(&e.g);
    build_joints(&e);
    build_params(&e);
    build_body(&e);
    for (int pair = 0; pair < 2; ++pair)
        for (int s = 0; s < 2; ++s)
            build_leg(&e, pair, s);
    sp_abstraction stick = build_stick(&e);
    build_clip(&e);
    sp_result r = sp_gen_save(
        &e.g, &e.m, &(sp_gen_save_desc){.name = "elephant", .abstractions = &stick, .abstraction_count = 1, .no_outline = true},
        path, err);
    sp_abstraction_free(&stick);
    sp_gen_path_free(&e.trunk_path);
    sp_gen_path_free(&e.tail_path);
    sp_gen_mesh_free(&e.m);
    sp_gen_rig_free(&e.g);
    return r;
}
