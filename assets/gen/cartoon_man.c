// cartoon_man.c: the paper's Cartoon Man: a friendly humanoid with a big
// head, big hands and big shoes, ~2.2k vertices, 33 joints, 91 parameters,
// seen from the front (he faces +Z; the sketch view looks along -Z), with a
// stick figure (a curve per bone chain, ordered) and an outline (closed,
// closest) abstraction, and a looping `wave` clip.
//
// Skeleton: root -> pelvis -> spine_1 -> spine_2 -> chest -> neck -> head -> brow_l|r;
// chest -> clavicle_<s> -> upper_arm -> forearm -> hand -> fingers_1 -> fingers_2, hand -> thumb_1 -> thumb_2;
// pelvis -> thigh_<s> -> shin -> foot -> toes (s = l at +X, r at -X: his left is the viewer's right).
//
// Joint frames (gen_rig): local X along the bone in the picture plane, local
// Z towards the viewer, so `rz` bends in the picture (what a stick figure
// shows), `ry` swings forwards or backwards (foreshortening) and `rx` twists.
// The rest pose is a relaxed A-pose whose elbows sit a little behind and
// knees a little in front of the picture plane: a flexion then moves the
// picture at first order, so the solver sees which way a limb bends.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "characters.h"
#include "gen_mesh.h"
#include "gen_rig.h"
#include "gen_stick.h"

static const double k_pi = 3.14159265358979323846;

// Palette (sRGB).
static const sp_gen_rgb k_skin = {0.98, 0.78, 0.62}, k_blush = {0.97, 0.58, 0.52}, k_nose = {0.97, 0.66, 0.55};
static const sp_gen_rgb k_hair = {0.36, 0.20, 0.10}, k_brow = {0.24, 0.13, 0.06}, k_mouth = {0.55, 0.12, 0.14};
static const sp_gen_rgb k_eye = {0.98, 0.98, 0.96}, k_pupil = {0.06, 0.05, 0.05};
static const sp_gen_rgb k_shirt = {0.86, 0.25, 0.20}, k_trousers = {0.22, 0.33, 0.58};
static const sp_gen_rgb k_belt = {0.24, 0.14, 0.08}, k_buckle = {0.96, 0.78, 0.26};
static const sp_gen_rgb k_shoe = {0.42, 0.23, 0.12}, k_sole = {0.16, 0.11, 0.08};

// ---- the figure's landmarks (rest space, his left side; the right mirrors x) ----

static const sp_vec3 k_pelvis = {0, 0.92, 0};
static const double k_spine_y[5] = {1.00, 1.08, 1.16, 1.27, 1.335}; // spine_1, spine_2, chest, neck, head pivots
static const double k_spine_z[5] = {-0.015, -0.025, -0.015, -0.01, 0.0};
static const sp_vec3 k_head_c = {0, 1.52, 0.01};
static const sp_vec3 k_head_r = {0.205, 0.235, 0.2};
enum { LEFT = 0, RIGHT = 1 };

typedef struct arm_pts {
    sp_vec3 clav, shoulder, elbow, wrist, knuckles, fingers_2, tip; ///< pivots and the fingertip
    sp_vec3 dir, out;                                               ///< hand direction; outward across the palm
    sp_vec3 thumb_1, thumb_2, thumb_tip, thumb_dir;
} arm_pts;

typedef struct leg_pts {
    sp_vec3 hip, knee, ankle, ball, sole, heel, toe;
} leg_pts;

static sp_vec3 mirror(sp_vec3 p, int side)
{
    return side == LEFT ? p : sp_v3(-p.x, p.y, p.z);
}

static sp_vec3 polar(sp_vec3 from, double len, double deg, double z)
{
    double a = deg * k_pi / 180.0;
    return sp_v3(from.x + len * cos(a), from.y + len * sin(a), z);
}

static arm_pts arm_points(int side)
{
    arm_pts a;
    a.clav = sp_v3(0.0, 1.235, -0.01);
    a.shoulder = sp_v3(0.2, 1.205, -0.01);
    a.elbow = polar(a.shoulder, 0.27, -58.0, -0.035);
    a.wrist = polar(a.elbow, 0.25, -62.0, 0.0);
    a.dir = sp_v3(cos(-64.0 * k_pi / 180.0), sin(-64.0 * k_pi / 180.0), 0);
    a.out = sp_v3(-a.dir.y, a.dir.x, 0); // away from the body, in the palm's plane
    a.knuckles = sp_v3_add(a.wrist, sp_v3_scale(a.dir, 0.11));
    a.fingers_2 = sp_v3_add(a.knuckles, sp_v3_scale(a.dir, 0.06));
    a.tip = sp_v3_add(a.fingers_2, sp_v3_scale(a.dir, 0.068));
    a.thumb_dir = sp_v3_norm(sp_v3_add(sp_v3_scale(a.dir, 0.7), sp_v3_scale(a.out, 0.7)));
    a.thumb_1 = sp_v3_add(a.wrist, sp_v3_add(sp_v3_scale(a.dir, 0.045), sp_v3_scale(a.out, 0.042)));
    a.thumb_2 = sp_v3_add(a.thumb_1, sp_v3_scale(a.thumb_dir, 0.05));
    a.thumb_tip = sp_v3_add(a.thumb_2, sp_v3_scale(a.thumb_dir, 0.045));
    sp_vec3* p[] = {&a.clav, &a.shoulder, &a.elbow,   &a.wrist,   &a.knuckles,  &a.fingers_2, &a.tip,
                    &a.dir,  &a.out,      &a.thumb_1, &a.thumb_2, &a.thumb_tip, &a.thumb_dir};
    for (size_t k = 0; k < sizeof p / sizeof p[0]; ++k)
        *p[k] = mirror(*p[k], side);
    return a;
}

static leg_pts leg_points(int side)
{
    // Short cartoon legs: the soles are at y = 0.14.
    leg_pts l = {.hip = {0.095, 0.86, 0},
                 .knee = {0.11, 0.555, 0.03},
                 .ankle = {0.12, 0.25, 0},
                 .ball = {0.125, 0.175, 0.14},
                 .sole = {0.12, 0.16, 0.06},
                 .heel = {0.125, 0.207, -0.075},
                 .toe = {0.125, 0.205, 0.235}};
    sp_vec3* p[] = {&l.hip, &l.knee, &l.ankle, &l.ball, &l.sole, &l.heel, &l.toe};
    for (size_t k = 0; k < sizeof p / sizeof p[0]; ++k)
        *p[k] = mirror(*p[k], side);
    return l;
}

// The in-plane direction of a bone (the joint's rest angle).
static double angle_of(sp_vec3 a, sp_vec3 b)
{
    return atan2(b.y - a.y, b.x - a.x);
}

// Depth of the face (the head ellipsoid's front) at (x, y).
static double face_z(double x, double y)
{
    double u = x / k_head_r.x, v = (y - k_head_c.y) / k_head_r.y;
    return k_head_c.z + k_head_r.z * sqrt(fmax(0.0, 1.0 - u * u - v * v));
}

static sp_vec3 eye_center(int side)
{
    return mirror(sp_v3(0.072, 1.575, face_z(0.072, 1.575) - 0.022), side);
}

// ---- colours ---------------------------------------------------------------

static sp_gen_rgb torso_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)user;
    // Trousers up to the belt, a red shirt with a rounded collar, a bare neck.
    if (p.y < 0.865) return k_trousers;
    if (p.y < 0.9) return p.z > 0.08 && fabs(p.x) < 0.032 ? k_buckle : k_belt;
    // The shirt covers the shoulders up to the neck; a round collar.
    double r = hypot(p.x, p.z / 0.9);
    if (p.y < 1.23 || (r > 0.075 && p.y < 1.3)) {
        // A button placket down the front.
        double placket = p.z > 0.1 && fabs(p.x) < 0.012 ? 0.85 : 1.0;
        return sp_gen_shade(k_shirt, placket);
    }
    return k_skin;
}

static sp_gen_rgb head_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)user;
    double nx = p.x / k_head_r.x, ny = (p.y - k_head_c.y) / k_head_r.y, nz = (p.z - k_head_c.z) / k_head_r.z;
    // Hair over the crown and down the back, a fringe lower at the sides.
    double h = ny + 0.75 * fmax(0.0, -nz) + 0.2 * fabs(nx);
    sp_gen_rgb c = sp_gen_mix(k_skin, k_hair, sp_gen_smoothstep(0.36, 0.46, h));
    // Rosy cheeks.
    double cheek = hypot(fabs(p.x) - 0.12, p.y - 1.46);
    if (nz > 0) c = sp_gen_mix(c, k_blush, 0.6 * (1.0 - sp_gen_smoothstep(0.02, 0.05, cheek)));
    return c;
}

static sp_gen_rgb flat_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)p;
    return *(const sp_gen_rgb*)user;
}

static sp_gen_rgb brow_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)p, (void)user;
    return k_brow;
}

static sp_gen_rgb mouth_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)p, (void)user;
    return k_mouth;
}

static sp_gen_rgb eye_color(double u, double a, sp_vec3 p, void* user)
{
    (void)a, (void)p, (void)user;
    return u > 0.8 ? k_pupil : k_eye;
}

static sp_gen_rgb shoe_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)p, (void)user;
    return cos(a) < -0.55 ? k_sole : k_shoe;
}

// ---- pieces ------------------------------------------------------------------

// Interpolates keys given as arc lengths (converted to the tube's u).
static double keyed(double (*k)[2], int n, double len, double u)
{
    double kk[16][2];
    for (int i = 0; i < n; ++i)
        kk[i][0] = k[i][0] / len, kk[i][1] = k[i][1];
    return sp_gen_interp((const double(*)[2])kk, n, u);
}

typedef struct torso_ctx {
    double y0, y1;
} torso_ctx;

static sp_gen_section torso_profile(double u, void* user)
{
    const torso_ctx* c = user;
    double y = c->y0 + u * (c->y1 - c->y0);
    // y -> half width, front depth, back depth: hips, a waist, a round
    // belly, a broad chest, sloping shoulders (the arms' tubes make the
    // shoulders' top), a neck.
    static const double w[][2] = {{0.745, 0.12}, {0.80, 0.165}, {0.88, 0.175}, {0.98, 0.165}, {1.06, 0.17},
                                  {1.14, 0.185}, {1.20, 0.185}, {1.245, 0.14}, {1.28, 0.068}, {1.36, 0.062}};
    static const double f[][2] = {{0.745, 0.09}, {0.80, 0.11},  {0.88, 0.115}, {0.98, 0.125}, {1.06, 0.13},
                                  {1.14, 0.12},  {1.20, 0.105}, {1.245, 0.08}, {1.28, 0.06},  {1.36, 0.058}};
    static const double b[][2] = {{0.745, 0.10}, {0.80, 0.12}, {0.88, 0.125}, {0.98, 0.11}, {1.06, 0.105},
                                  {1.14, 0.105}, {1.20, 0.1},  {1.245, 0.08}, {1.28, 0.06}, {1.36, 0.058}};
    return (sp_gen_section){sp_gen_interp(f, 10, y), sp_gen_interp(b, 10, y), sp_gen_interp(w, 10, y)};
}

typedef struct limb_ctx {
    double s[6]; ///< arc lengths of landmarks along the path
    double len;
    int kind; ///< 0 arm, 1 leg
} limb_ctx;

static sp_gen_section arm_profile(double u, void* user)
{
    const limb_ctx* c = user;
    double sS = c->s[1], sE = c->s[2], sW = c->s[3];
    double sleeve = sS + 0.62 * (sE - sS);
    double k[][2] = {{0.0, 0.05},
                     {sS, 0.072},
                     {sS + 0.4 * (sE - sS), 0.066},
                     {sleeve - 0.004, 0.067},
                     {sleeve + 0.012, 0.05},
                     {sE, 0.046},
                     {sE + 0.4 * (sW - sE), 0.049},
                     {sW, 0.04},
                     {c->len, 0.038}};
    double r = keyed(k, 9, c->len, u);
    return (sp_gen_section){r, r, r};
}

static sp_gen_rgb arm_color(double u, double a, sp_vec3 p, void* user)
{
    (void)a, (void)p;
    const limb_ctx* c = user;
    double s = u * c->len, sleeve = c->s[1] + 0.62 * (c->s[2] - c->s[1]);
    return s < sleeve + 0.004 ? k_shirt : k_skin;
}

static sp_gen_section leg_profile(double u, void* user)
{
    const limb_ctx* c = user;
    double sH = c->s[1], sK = c->s[2], sA = c->s[3];
    double k[][2] = {
        {0.0, 0.08},        {sH, 0.095},    {sH + 0.45 * (sK - sH), 0.086}, {sK, 0.068}, {sK + 0.35 * (sA - sK), 0.067},
        {sA - 0.05, 0.064}, {c->len, 0.066}};
    double r = keyed(k, 7, c->len, u);
    return (sp_gen_section){r, r, r};
}

static sp_gen_rgb leg_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)user;
    // A darker turn-up above the shoe.
    return p.y < 0.28 ? sp_gen_shade(k_trousers, 0.8) : k_trousers;
}

typedef struct hand_ctx {
    double sK, sF, len;
} hand_ctx;

static sp_gen_section hand_profile(double u, void* user)
{
    const hand_ctx* c = user;
    double wk[][2] = {{0.0, 0.046}, {0.4 * c->sK, 0.066}, {c->sK, 0.064}, {c->sF, 0.056}, {c->len, 0.05}};
    double tk[][2] = {{0.0, 0.028}, {0.5 * c->sK, 0.028}, {c->sK, 0.023}, {c->len, 0.02}};
    double w = keyed(wk, 5, c->len, u), t = keyed(tk, 4, c->len, u);
    return (sp_gen_section){t, t, w};
}

static sp_gen_section thumb_profile(double u, void* user)
{
    (void)user;
    double r = 0.025 - 0.004 * u;
    return (sp_gen_section){r, r, r * 0.92};
}

static sp_gen_section shoe_profile(double u, void* user)
{
    (void)user;
    // A big rounded toe box and a lower heel.
    static const double up[][2] = {{0.0, 0.06}, {0.35, 0.075}, {0.7, 0.072}, {1.0, 0.066}};
    static const double side[][2] = {{0.0, 0.066}, {0.4, 0.074}, {0.75, 0.094}, {1.0, 0.09}};
    return (sp_gen_section){sp_gen_interp(up, 4, u), 0.055, sp_gen_interp(side, 4, u)};
}

static sp_gen_section small_profile(double u, void* user)
{
    const double* r = user; // {up/down, side}
    double f = 0.75 + 0.25 * sin(k_pi * u);
    return (sp_gen_section){r[0] * f, r[0] * f, r[1] * f};
}

typedef struct man {
    sp_gen_rig g;
    sp_gen_mesh m;
    int root, pelvis, spine[5]; ///< spine_1, spine_2, chest, neck, head
    int brow[2], eye[2], clav[2], upper[2], fore[2], hand[2], fing1[2], fing2[2], thumb1[2], thumb2[2];
    int thigh[2], shin[2], foot[2], toes[2];
} man;

static void build_joints(man* w)
{
    sp_gen_rig* g = &w->g;
    w->root = sp_gen_joint(g, "root", -1, k_pelvis, 0.5 * k_pi);
    w->pelvis = sp_gen_joint(g, "pelvis", w->root, k_pelvis, 0.5 * k_pi);
    static const char* names[5] = {"spine_1", "spine_2", "chest", "neck", "head"};
    for (int k = 0; k < 5; ++k)
        w->spine[k] =
            sp_gen_joint(g, names[k], k ? w->spine[k - 1] : w->pelvis, sp_v3(0, k_spine_y[k], k_spine_z[k]), 0.5 * k_pi);
    int head = w->spine[4], chest = w->spine[2];
    for (int s = 0; s < 2; ++s)
        w->brow[s] = sp_gen_joint(g, s == LEFT ? "brow_l" : "brow_r", head, mirror(sp_v3(0.072, 1.66, 0.19), s), 0.5 * k_pi);
    for (int s = 0; s < 2; ++s)
        w->eye[s] = sp_gen_joint(g, s == LEFT ? "eye_l" : "eye_r", head, eye_center(s), 0.5 * k_pi);
    for (int s = 0; s < 2; ++s) {
        const char* sf = s == LEFT ? "l" : "r";
        arm_pts a = arm_points(s);
        char name[64];
#define JOINT(var, nm, parent, at, to)                                                                                           \
    snprintf(name, sizeof name, "%s_%s", nm, sf);                                                                                \
    var[s] = sp_gen_joint(g, name, parent, at, angle_of(at, to))
        JOINT(w->clav, "clavicle", chest, a.clav, a.shoulder);
        JOINT(w->upper, "upper_arm", w->clav[s], a.shoulder, a.elbow);
        JOINT(w->fore, "forearm", w->upper[s], a.elbow, a.wrist);
        JOINT(w->hand, "hand", w->fore[s], a.wrist, a.knuckles);
        JOINT(w->fing1, "fingers_1", w->hand[s], a.knuckles, a.fingers_2);
        JOINT(w->fing2, "fingers_2", w->fing1[s], a.fingers_2, a.tip);
        JOINT(w->thumb1, "thumb_1", w->hand[s], a.thumb_1, a.thumb_2);
        JOINT(w->thumb2, "thumb_2", w->thumb1[s], a.thumb_2, a.thumb_tip);
    }
    for (int s = 0; s < 2; ++s) {
        const char* sf = s == LEFT ? "l" : "r";
        leg_pts l = leg_points(s);
        char name[64];
        JOINT(w->thigh, "thigh", w->pelvis, l.hip, l.knee);
        JOINT(w->shin, "shin", w->thigh[s], l.knee, l.ankle);
#undef JOINT
        // Foot and toes keep the shin's frame (X down): `ry` pitches the
        // toes up and down, `rx` turns them in and out.
        snprintf(name, sizeof name, "foot_%s", sf);
        w->foot[s] = sp_gen_joint(g, name, w->shin[s], l.ankle, -0.5 * k_pi);
        snprintf(name, sizeof name, "toes_%s", sf);
        w->toes[s] = sp_gen_joint(g, name, w->foot[s], l.ball, -0.5 * k_pi);
    }
}

// Limits are written for his left side; the right side mirrors the
// channels that change sign under x -> -x (rx, rz; ry keeps its sense).
static void param_lr(sp_gen_rig* g, const int* j, sp_channel ch, double lo, double hi)
{
    sp_gen_param(g, j[LEFT], ch, lo, hi, SP_GROUP_POSE);
    if (ch == SP_CH_RX || ch == SP_CH_RZ)
        sp_gen_param(g, j[RIGHT], ch, -hi, -lo, SP_GROUP_POSE);
    else
        sp_gen_param(g, j[RIGHT], ch, lo, hi, SP_GROUP_POSE);
}

static void scale_lr(sp_gen_rig* g, const int* j, double lo, double hi)
{
    sp_gen_param(g, j[LEFT], SP_CH_S, lo, hi, SP_GROUP_SHAPE);
    sp_gen_param(g, j[RIGHT], SP_CH_S, lo, hi, SP_GROUP_SHAPE);
}

static void build_params(man* w)
{
    sp_gen_rig* g = &w->g;
    // Placement in the picture: he is redrawn where he stands, so he may
    // move by about a third of his height (a jump, a step aside), turn in
    // the picture, and be drawn a little larger or smaller.
    sp_gen_param(g, w->root, SP_CH_TX, -0.6, 0.6, SP_GROUP_POSE);
    sp_gen_param(g, w->root, SP_CH_TY, -0.6, 0.6, SP_GROUP_POSE);
    sp_gen_param(g, w->root, SP_CH_RZ, -0.8, 0.8, SP_GROUP_POSE);
    sp_gen_param(g, w->root, SP_CH_S, 0.8, 1.25, SP_GROUP_SHAPE);
    // Vertical joints: rx turns about the spine, ry leans (+ backwards), rz
    // bends sideways. Human ranges: the back turns about 35 degrees, the
    // neck and head about 60 more (an outline of a head turned further than
    // that would show the back of his head).
    sp_gen_param(g, w->pelvis, SP_CH_RX, -0.8, 0.8, SP_GROUP_POSE);
    sp_gen_param(g, w->pelvis, SP_CH_RY, -0.5, 0.4, SP_GROUP_POSE);
    static const double lim[5][3][2] = {
        {{-0.2, 0.2}, {-0.4, 0.3}, {-0.3, 0.3}},     // spine_1
        {{-0.2, 0.2}, {-0.35, 0.25}, {-0.25, 0.25}}, // spine_2
        {{-0.2, 0.2}, {-0.3, 0.25}, {-0.25, 0.25}},  // chest
        {{-0.4, 0.4}, {-0.5, 0.4}, {-0.4, 0.4}},     // neck
        {{-0.6, 0.6}, {-0.5, 0.5}, {-0.4, 0.4}},     // head
    };
    for (int k = 0; k < 5; ++k)
        for (int c = 0; c < 3; ++c)
            sp_gen_param(g, w->spine[k], (sp_channel)(SP_CH_RX + c), lim[k][c][0], lim[k][c][1], SP_GROUP_POSE);
    // A bone's scale carries everything below it: the head's is the only
    // one along the spine (a spine or neck scale would grow the head and
    // arms with it, compounding into a balloon head).
    sp_gen_param(g, w->spine[4], SP_CH_S, 0.8, 1.25, SP_GROUP_SHAPE);
    // Brows go up and down (in the head's frame, X is up); the eyes look
    // about (rx: sideways, ry: up and down).
    for (int s = 0; s < 2; ++s)
        sp_gen_param(g, w->brow[s], SP_CH_TX, -0.012, 0.03, SP_GROUP_POSE);
    param_lr(g, w->eye, SP_CH_RX, -0.35, 0.35);
    param_lr(g, w->eye, SP_CH_RY, -0.3, 0.3);
    // Arms (left side; ry < 0 swings forwards).
    param_lr(g, w->clav, SP_CH_RY, -0.3, 0.3);
    param_lr(g, w->clav, SP_CH_RZ, -0.2, 0.4);
    param_lr(g, w->upper, SP_CH_RX, -1.0, 1.0);
    param_lr(g, w->upper, SP_CH_RY, -1.5, 1.0);
    param_lr(g, w->upper, SP_CH_RZ, -0.6, 1.9);
    scale_lr(g, w->upper, 0.85, 1.2);
    param_lr(g, w->fore, SP_CH_RX, -1.0, 1.0);
    param_lr(g, w->fore, SP_CH_RY, -1.9, 0.1);
    param_lr(g, w->fore, SP_CH_RZ, -0.3, 1.5);
    scale_lr(g, w->fore, 0.9, 1.15);
    param_lr(g, w->hand, SP_CH_RX, -1.0, 1.0);
    param_lr(g, w->hand, SP_CH_RY, -1.2, 0.9);
    param_lr(g, w->hand, SP_CH_RZ, -0.6, 0.6);
    scale_lr(g, w->hand, 0.85, 1.25);
    param_lr(g, w->fing1, SP_CH_RY, -1.1, 0.2);
    param_lr(g, w->fing2, SP_CH_RY, -1.0, 0.2);
    param_lr(g, w->thumb1, SP_CH_RY, -1.0, 0.3);
    param_lr(g, w->thumb1, SP_CH_RZ, -0.3, 0.5);
    param_lr(g, w->thumb2, SP_CH_RY, -1.0, 0.2);
    // Legs (X down: ry > 0 swings backwards; rz > 0 spreads the left leg).
    param_lr(g, w->thigh, SP_CH_RX, -0.7, 0.7);
    param_lr(g, w->thigh, SP_CH_RY, -1.4, 0.5);
    param_lr(g, w->thigh, SP_CH_RZ, -0.35, 0.9);
    scale_lr(g, w->thigh, 0.9, 1.15);
    param_lr(g, w->shin, SP_CH_RX, -0.3, 0.3);
    param_lr(g, w->shin, SP_CH_RY, 0.0, 1.9);
    param_lr(g, w->shin, SP_CH_RZ, -0.25, 0.25);
    scale_lr(g, w->shin, 0.9, 1.15);
    param_lr(g, w->foot, SP_CH_RX, -0.6, 0.6);
    param_lr(g, w->foot, SP_CH_RY, -0.6, 0.8);
    param_lr(g, w->foot, SP_CH_RZ, -0.3, 0.3);
    scale_lr(g, w->foot, 0.85, 1.2);
    param_lr(g, w->toes, SP_CH_RY, -0.6, 0.4);
}

static void build_torso_and_head(man* w)
{
    sp_gen_mesh* m = &w->m;
    torso_ctx tc = {0.745, 1.36};
    sp_vec3 ends[2] = {{0, tc.y0, 0}, {0, tc.y1, 0}};
    sp_gen_path path;
    sp_gen_path_points(&path, ends, 2);
    sp_gen_chain ch = {0};
    sp_gen_chain_add(&ch, w->pelvis, 0.0, 0.0);
    static const double blend[5] = {0.05, 0.04, 0.045, 0.03, 0.025};
    for (int k = 0; k < 5; ++k)
        sp_gen_chain_add(&ch, w->spine[k], k_spine_y[k] - tc.y0, blend[k]);
    int first = sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                                   .rings = 18,
                                                   .segments = 16,
                                                   .side = {1, 0, 0},
                                                   .profile = torso_profile,
                                                   .color = torso_color,
                                                   .user = &tc,
                                                   .chain = &ch,
                                                   .cap0_rings = 2,
                                                   .cap0_len = 0.6});
    sp_gen_path_free(&path);
    // The seat follows the thighs part of the way, so a raised leg does not
    // leave the trousers' seat hanging under the hip.
    for (int v = first; v < m->vertex_count; ++v) {
        double x = m->pos[3 * v], y = m->pos[3 * v + 1];
        double f = 0.45 * sp_gen_smoothstep(0.87, 0.77, y) * sp_gen_smoothstep(0.0, 0.08, fabs(x));
        if (f <= 0) continue;
        sp_gen_skin th = sp_gen_skin_one(w->thigh[x > 0 ? LEFT : RIGHT]);
        m->skin[v] = sp_gen_skin_lerp(&m->skin[v], &th, f);
    }

    int head = w->spine[4];
    sp_gen_skin hs = sp_gen_skin_one(head);
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = k_head_c,
                                                 .ax = {0, k_head_r.y, 0},
                                                 .ay = {0, 0, k_head_r.z},
                                                 .az = {k_head_r.x, 0, 0},
                                                 .rings = 12,
                                                 .segments = 20,
                                                 .color = head_color,
                                                 .skin = hs});
    // A bulb nose and ears.
    double nz = face_z(0, 1.5);
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = {0, 1.495, nz + 0.012},
                                                 .ax = {0, 0, 0.042},
                                                 .ay = {0, 0.038, 0},
                                                 .az = {-0.044, 0, 0},
                                                 .rings = 5,
                                                 .segments = 8,
                                                 .color = flat_color,
                                                 .user = (void*)&k_nose,
                                                 .skin = hs});
    for (int s = 0; s < 2; ++s)
        sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = mirror(sp_v3(0.2, 1.5, -0.005), s),
                                                     .ax = {0, 0.066, 0},
                                                     .ay = {0, 0, 0.045},
                                                     .az = {0.034, 0, 0},
                                                     .rings = 5,
                                                     .segments = 8,
                                                     .color = flat_color,
                                                     .user = (void*)&k_skin,
                                                     .skin = hs});
    // The face's features are decorations: inside the silhouette, and
    // nothing a person draws in an outline.
    m->decorating = true;
    for (int s = 0; s < 2; ++s) {
        sp_vec3 c = eye_center(s);
        sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = c,
                                                     .ax = {0, 0, 0.034},
                                                     .ay = {0, 0.058, 0},
                                                     .az = {-0.044, 0, 0},
                                                     .rings = 7,
                                                     .segments = 10,
                                                     .color = eye_color,
                                                     .skin = sp_gen_skin_one(w->eye[s])});
        // The brow, on its own joint.
        sp_vec3 bc[3];
        for (int k = 0; k < 3; ++k) {
            double x = 0.034 + 0.039 * k, y = 1.657 + (k == 1 ? 0.014 : 0.0);
            bc[k] = mirror(sp_v3(x, y, face_z(x, y) + 0.004), s);
        }
        sp_gen_path bp;
        sp_gen_path_catmull(&bp, bc, 3, 8);
        static const double br[2] = {0.011, 0.008};
        sp_gen_tube(m, &(sp_gen_tube_desc){.path = &bp,
                                           .rings = 5,
                                           .segments = 5,
                                           .profile = small_profile,
                                           .color = brow_color,
                                           .user = (void*)br,
                                           .skin = sp_gen_skin_one(w->brow[s]),
                                           .cap0_rings = 1,
                                           .cap0_len = 0.8,
                                           .cap1_rings = 1,
                                           .cap1_len = 0.8});
        sp_gen_path_free(&bp);
    }
    // A wide smile.
    sp_vec3 mc[5];
    for (int k = 0; k < 5; ++k) {
        double x = -0.085 + 0.0425 * k, y = 1.425 + 3.2 * x * x;
        mc[k] = sp_v3(x, y, face_z(x, y) - 0.002);
    }
    sp_gen_path mp;
    sp_gen_path_catmull(&mp, mc, 5, 8);
    static const double mr[2] = {0.011, 0.007};
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &mp,
                                       .rings = 8,
                                       .segments = 5,
                                       .profile = small_profile,
                                       .color = mouth_color,
                                       .user = (void*)mr,
                                       .skin = hs,
                                       .cap0_rings = 1,
                                       .cap0_len = 0.8,
                                       .cap1_rings = 1,
                                       .cap1_len = 0.8});
    sp_gen_path_free(&mp);
    m->decorating = false;
}

static void build_arm(man* w, int s)
{
    sp_gen_mesh* m = &w->m;
    arm_pts a = arm_points(s);
    // Sleeve and arm: clavicle (inside the shoulder) to the wrist.
    sp_vec3 ctrl[5] = {a.clav, a.shoulder, a.elbow, a.wrist, sp_v3_add(a.wrist, sp_v3_scale(a.dir, 0.015))};
    ctrl[0] = sp_v3_add(a.clav, sp_v3_scale(sp_v3_norm(sp_v3_sub(a.clav, a.shoulder)), 0.04));
    sp_gen_path path;
    sp_gen_path_catmull(&path, ctrl, 5, 16);
    limb_ctx lc = {.len = path.length, .kind = 0};
    for (int k = 0; k < 4; ++k)
        lc.s[k] = sp_gen_path_project(&path, ctrl[k]);
    // Wide blends (about 1.5 radii) spread a bend over the joint: an elbow
    // bent 90 degrees keeps its volume instead of pinching.
    sp_gen_chain ch = {0};
    sp_gen_chain_add(&ch, w->clav[s], 0.0, 0.0);
    sp_gen_chain_add(&ch, w->upper[s], lc.s[1], 0.095);
    sp_gen_chain_add(&ch, w->fore[s], lc.s[2], 0.09);
    sp_gen_chain_add(&ch, w->hand[s], lc.s[3], 0.035);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                       .rings = 16,
                                       .segments = 10,
                                       .profile = arm_profile,
                                       .color = arm_color,
                                       .user = &lc,
                                       .chain = &ch,
                                       .cap0_rings = 1,
                                       .cap0_len = 0.8,
                                       .cap1_rings = 1,
                                       .cap1_len = 0.5});
    sp_gen_path_free(&path);

    // The hand: a broad palm and mitten fingers in the picture plane (palm
    // to the front), thickness along Z.
    sp_vec3 hc[4] = {sp_v3_sub(a.wrist, sp_v3_scale(a.dir, 0.01)), a.knuckles, a.fingers_2,
                     sp_v3_sub(a.tip, sp_v3_scale(a.dir, 0.02))};
    sp_gen_path hp;
    sp_gen_path_catmull(&hp, hc, 4, 6);
    hand_ctx hx = {sp_gen_path_project(&hp, a.knuckles), sp_gen_path_project(&hp, a.fingers_2), hp.length};
    sp_gen_chain hch = {0};
    sp_gen_chain_add(&hch, w->hand[s], 0.0, 0.0);
    sp_gen_chain_add(&hch, w->fing1[s], hx.sK, 0.025);
    sp_gen_chain_add(&hch, w->fing2[s], hx.sF, 0.02);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &hp,
                                       .rings = 10,
                                       .segments = 10,
                                       .side = a.out,
                                       .profile = hand_profile,
                                       .color = flat_color,
                                       .user = (void*)&k_skin,
                                       .chain = &hch,
                                       .cap0_rings = 1,
                                       .cap0_len = 0.6,
                                       .cap1_rings = 2,
                                       .cap1_len = 0.6});
    sp_gen_path_free(&hp);
    // The thumb, out to the side (palms face the viewer).
    sp_vec3 tc[4] = {sp_v3_sub(a.thumb_1, sp_v3_scale(a.thumb_dir, 0.035)), a.thumb_1, a.thumb_2,
                     sp_v3_sub(a.thumb_tip, sp_v3_scale(a.thumb_dir, 0.018))};
    sp_gen_path tp;
    sp_gen_path_catmull(&tp, tc, 4, 6);
    sp_gen_chain tch = {0};
    sp_gen_chain_add(&tch, w->hand[s], 0.0, 0.0);
    sp_gen_chain_add(&tch, w->thumb1[s], sp_gen_path_project(&tp, a.thumb_1), 0.015);
    sp_gen_chain_add(&tch, w->thumb2[s], sp_gen_path_project(&tp, a.thumb_2), 0.012);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &tp,
                                       .rings = 7,
                                       .segments = 8,
                                       .profile = thumb_profile,
                                       .color = flat_color,
                                       .user = (void*)&k_skin,
                                       .chain = &tch,
                                       .cap0_rings = 1,
                                       .cap0_len = 0.6,
                                       .cap1_rings = 2,
                                       .cap1_len = 1.0});
    sp_gen_path_free(&tp);
}

static void build_leg(man* w, int s)
{
    sp_gen_mesh* m = &w->m;
    leg_pts l = leg_points(s);
    sp_vec3 ctrl[5] = {mirror(sp_v3(0.09, 1.08, 0), s), l.hip, l.knee, l.ankle, sp_v3_add(l.ankle, sp_v3(0, -0.04, 0))};
    sp_gen_path path;
    sp_gen_path_catmull(&path, ctrl, 5, 16);
    limb_ctx lc = {.len = path.length, .kind = 1};
    for (int k = 0; k < 4; ++k)
        lc.s[k] = sp_gen_path_project(&path, ctrl[k]);
    sp_gen_chain ch = {0};
    sp_gen_chain_add(&ch, w->pelvis, 0.0, 0.0);
    sp_gen_chain_add(&ch, w->thigh[s], lc.s[1], 0.11);
    sp_gen_chain_add(&ch, w->shin[s], lc.s[2], 0.09);
    sp_gen_chain_add(&ch, w->foot[s], lc.s[3], 0.03);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                       .rings = 16,
                                       .segments = 10,
                                       .profile = leg_profile,
                                       .color = leg_color,
                                       .user = &lc,
                                       .chain = &ch,
                                       .cap0_rings = 1,
                                       .cap0_len = 0.6,
                                       .cap1_rings = 1,
                                       .cap1_len = 0.4});
    sp_gen_path_free(&path);
    // The shoe, heel to toe along +Z.
    sp_vec3 sc[3] = {l.heel, sp_v3_add(l.heel, sp_v3(0, 0, 0.125)), l.toe};
    sp_gen_path sp;
    sp_gen_path_catmull(&sp, sc, 3, 8);
    sp_gen_chain sch = {0};
    sp_gen_chain_add(&sch, w->foot[s], 0.0, 0.0);
    sp_gen_chain_add(&sch, w->toes[s], sp_gen_path_project(&sp, l.ball), 0.035);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &sp,
                                       .rings = 9,
                                       .segments = 10,
                                       .side = {-1, 0, 0},
                                       .profile = shoe_profile,
                                       .color = shoe_color,
                                       .chain = &sch,
                                       .cap0_rings = 2,
                                       .cap0_len = 0.7,
                                       .cap1_rings = 2,
                                       .cap1_len = 0.9});
    sp_gen_path_free(&sp);
}

static sp_abstraction build_stick(const man* w)
{
    sp_abstraction st;
    sp_gen_stick_begin(&st);
    const sp_gen_rig* g = &w->g;
    int spine[6] = {w->pelvis, w->spine[0], w->spine[1], w->spine[2], w->spine[3], w->spine[4]};
    // The top of the head is a little in front of the neck (a relaxed posture), so a nod shows which way it goes.
    sp_gen_stick_curve(&st, g, "spine", spine, 6, sp_v3(0, k_head_c.y + k_head_r.y, 0.05), 46);
    for (int s = 0; s < 2; ++s) {
        arm_pts a = arm_points(s);
        int arm[6] = {w->clav[s], w->upper[s], w->fore[s], w->hand[s], w->fing1[s], w->fing2[s]};
        sp_gen_stick_curve(&st, g, s == LEFT ? "arm_l" : "arm_r", arm, 6, a.tip, 36);
    }
    for (int s = 0; s < 2; ++s) {
        leg_pts l = leg_points(s);
        int leg[4] = {w->pelvis, w->thigh[s], w->shin[s], w->foot[s]};
        sp_gen_stick_curve(&st, g, s == LEFT ? "leg_l" : "leg_r", leg, 4, l.sole, 36);
    }
    return st;
}

// The outline: the front silhouette (sp_outline_trace), 353 points as in the
// paper (706 coordinates), each bound to the surface under it. Its depths
// are then smoothed along the curve (8 passes): a limb's silhouette runs
// between the rings of a coarse tube, so the nearest vertex alternates
// between the front and the back of the limb, and a limb swinging or
// twisting out of the picture would move neighbouring points apart (a zigzag
// outline).
static sp_result build_outline(const sp_gen_mesh* m, sp_abstraction* out, sp_error* err)
{
    sp_vec3 lo, hi;
    sp_bounds(m->pos, m->vertex_count, &lo, &hi);
    sp_camera cam = sp_gen_side_camera(lo, hi, 1.35); // what sp_gen_save frames
    sp_error e = {0};
    if (sp_gen_outline(m, &cam, 353, 8, out, &e) != SP_OK) return sp_fail(err, SP_ERR_INVALID, "cartoon_man: %s", e.text);
    return SP_OK;
}

// The `wave` clip: he raises his left hand (the viewer's right), waves three
// times with the forearm and hand, tilts his head and lifts his brows, and
// lowers the arm again; the loop starts and ends at rest.
static void build_clip(man* w)
{
    enum { KEYS = 49 };
    sp_gen_rig* g = &w->g;
    double up[KEYS], fore[KEYS], hand[KEYS], head[KEYS], chest[KEYS];
    sp_vec3 brow[KEYS];
    for (int k = 0; k < KEYS; ++k) {
        double t = (double)k / (KEYS - 1);
        double env = sp_gen_smoothstep(0.0, 0.2, t) * (1.0 - sp_gen_smoothstep(0.8, 1.0, t));
        double wave = sin(2.0 * k_pi * 3.0 * (t - 0.2) / 0.6);
        up[k] = 1.6 * env;
        fore[k] = env * (0.75 + 0.35 * wave);
        hand[k] = env * 0.25 * sin(2.0 * k_pi * 3.0 * (t - 0.2) / 0.6 + 0.6);
        head[k] = 0.12 * env;
        chest[k] = -0.06 * env;
        brow[k] = sp_v3(0.018 * env, 0, 0);
    }
    sp_gen_clip_begin(g, "wave", 2.4, KEYS);
    sp_gen_clip_rz(g, w->upper[LEFT], up);
    sp_gen_clip_rz(g, w->fore[LEFT], fore);
    sp_gen_clip_rz(g, w->hand[LEFT], hand);
    sp_gen_clip_rz(g, w->spine[4], head);
    sp_gen_clip_rz(g, w->spine[2], chest);
    sp_gen_clip_translate(g, w->brow[LEFT], brow);
    sp_gen_clip_translate(g, w->brow[RIGHT], brow);
}

sp_result sp_character_cartoon_man(const char* path, sp_error* err)
{
    man w;
    memset(&w, 0, sizeof w);
    sp_gen_rig_init(&w.g);
    build_joints(&w);
    build_params(&w);
    build_torso_and_head(&w);
    for (int s = 0; s < 2; ++s)
        build_arm(&w, s), build_leg(&w, s);
    sp_abstraction stick = build_stick(&w);
    build_clip(&w);
    sp_abstraction abs[2] = {stick, {{0}}};
    sp_result r = build_outline(&w.m, &abs[1], err);
    if (r == SP_OK)
        r = sp_gen_save(
            &w.g, &w.m,
            &(sp_gen_save_desc){.name = "cartoon_man", .abstractions = abs, .abstraction_count = 2, .no_outline = true}, path,
            err);
    sp_abstraction_free(&abs[0]);
    sp_abstraction_free(&abs[1]);
    sp_gen_mesh_free(&w.m);
    sp_gen_rig_free(&w.g);
    return r;
}
