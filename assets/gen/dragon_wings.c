// dragon_wings.c: a pair of raised bat-like wings: arm bones (humerus,
// forearm) along the leading edge, four fingers fanning back from the wrist,
// a dark membrane with scalloped trailing edges between them and down to
// the back, a thumb claw. Both wings share one skeleton (the far wing is the
// near one mirrored through the body's mid-plane), so from the side view
// they coincide and every in-plane parameter moves both.
//
// Skeleton: wing_root -> shoulder -> elbow -> wrist -> finger_k_a -> finger_k_b (k = 1..4).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dragon.h"

static const double k_pi = 3.14159265358979323846;

enum { FINGERS = 4 };

typedef struct finger {
    double angle, length, knuckle; ///< direction from the wrist (radians), length, knuckle at this fraction
    double curl;                   ///< sideways bow of the bone (fraction of its length)
} finger;

static const finger k_fingers[FINGERS] = {
    {100.0 * 3.14159265358979323846 / 180.0, 0.85, 0.5, 0.03},
    {140.0 * 3.14159265358979323846 / 180.0, 1.25, 0.52, 0.05},
    {178.0 * 3.14159265358979323846 / 180.0, 1.3, 0.52, 0.05},
    {215.0 * 3.14159265358979323846 / 180.0, 1.05, 0.5, 0.04},
};

typedef struct tube_ctx {
    double r0, r1;
} tube_ctx;

static sp_gen_section bone_profile(double u, void* user)
{
    const tube_ctx* c = user;
    double r = c->r0 + (c->r1 - c->r0) * u;
    return (sp_gen_section){r, r, r * 0.85};
}

static sp_gen_rgb bone_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_gen_shade(sp_dragon_scales(u, a, p, 0.0, 0.0), 0.9);
}

static sp_gen_rgb membrane_color(double s, double t, sp_vec3 p, void* user)
{
    (void)user;
    // Darker in the middle of each panel, veined along the bones, a little
    // lighter towards the thin trailing edge; a faint mottle.
    double vein = exp(-t * 14.0) + exp(-(1.0 - t) * 14.0);
    sp_gen_rgb c = sp_gen_mix(sp_dragon_membrane, sp_dragon_membrane_vein, 0.7 * sp_gen_clamp(vein, 0, 1));
    c = sp_gen_mix(c, sp_dragon_membrane_vein, 0.25 * sp_gen_smoothstep(0.6, 1.0, s));
    double n = sp_gen_noise2(p.x * 9.0, p.y * 9.0, 7u);
    return sp_gen_shade(c, 0.9 + 0.2 * n);
}

static sp_gen_rgb knob_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_gen_shade(sp_dragon_scales(u, a, p, 0.0, 0.0), 0.9);
}

// Finger k's bone as a polyline from the wrist, bowed slightly backwards.
static sp_vec3 finger_point(sp_vec3 w, const finger* f, double s)
{
    sp_vec3 d = sp_v3(cos(f->angle), sin(f->angle), 0);
    sp_vec3 n = sp_v3(-d.y, d.x, 0); // to the left of the bone (counter-clockwise)
    double bow = f->curl * f->length * sin(k_pi * s);
    return sp_v3_add(w, sp_v3_add(sp_v3_scale(d, s * f->length), sp_v3_scale(n, bow)));
}

// Skin of a membrane panel between two bones leaving the wrist: by the
// angle about the wrist (linear between the bones' rest directions) and,
// along each bone, its own chain at the same distance from the wrist. For
// the last panel (finger 4 to the arm) this holds near the wrist only, where
// the panel is a fan; it hands over to the panel's own blend by `r_far`.
typedef struct panel_ctx {
    sp_vec3 w;
    double a0, a1;               ///< rest directions of the two bones
    const sp_gen_chain *c0, *c1; ///< their chains (by arc length from the wrist)
    double r_near, r_far;        ///< fan up to r_near, the default blend beyond r_far (0: fan everywhere)
} panel_ctx;

static sp_gen_skin panel_skin(sp_vec3 p, const sp_gen_skin* blend, void* user)
{
    const panel_ctx* c = user;
    sp_vec3 d = sp_v3_sub(p, c->w);
    double a = atan2(d.y, d.x);
    while (a < c->a0 - k_pi)
        a += 2.0 * k_pi;
    while (a > c->a0 + k_pi)
        a -= 2.0 * k_pi;
    double t = sp_gen_clamp((a - c->a0) / (c->a1 - c->a0), 0.0, 1.0);
    double r = sqrt(d.x * d.x + d.y * d.y);
    sp_gen_skin s0 = sp_gen_chain_skin(c->c0, r), s1 = sp_gen_chain_skin(c->c1, r);
    sp_gen_skin fan = sp_gen_skin_lerp(&s0, &s1, t);
    if (c->r_far <= 0) return fan;
    return sp_gen_skin_lerp(&fan, blend, sp_gen_smoothstep(c->r_near, c->r_far, r));
}

// The arm's joints in the wing's plane: shoulder, elbow, wrist, and where
// the membrane meets the back.
static const sp_vec3 k_S = {0.0, 0.12, 0}, k_E = {0.42, 0.7, 0}, k_W = {0.12, 1.45, 0}, k_back = {-0.6, 0.02, 0};

typedef struct wing_bones {
    int root, shoulder, elbow, wrist;
    int fa[FINGERS], fb[FINGERS]; ///< each finger's proximal and distal joint
} wing_bones;

static wing_bones wings_skeleton(sp_gen_rig* g)
{
    const sp_vec3 S = k_S, E = k_E, W = k_W;
    wing_bones b;
    b.root = sp_gen_joint(g, "wing_root", -1, sp_v3(0, 0, 0), 0.5 * k_pi);
    b.shoulder = sp_gen_joint(g, "shoulder", b.root, S, atan2(E.y - S.y, E.x - S.x));
    b.elbow = sp_gen_joint(g, "elbow", b.shoulder, E, atan2(W.y - E.y, W.x - E.x));
    b.wrist = sp_gen_joint(g, "wrist", b.elbow, W, atan2(W.y - E.y, W.x - E.x));
    for (int k = 0; k < FINGERS; ++k) {
        const finger* f = &k_fingers[k];
        char na[32], nb[32];
        snprintf(na, sizeof na, "finger_%d_a", k + 1);
        snprintf(nb, sizeof nb, "finger_%d_b", k + 1);
        sp_vec3 kn = finger_point(W, f, f->knuckle), tip = finger_point(W, f, 1.0);
        b.fa[k] = sp_gen_joint(g, na, b.wrist, W, atan2(kn.y - W.y, kn.x - W.x));
        b.fb[k] = sp_gen_joint(g, nb, b.fa[k], kn, atan2(tip.y - kn.y, tip.x - kn.x));
    }
    sp_dragon_root_params(g, b.root);
    // Bone scales are lengths (sx, in the wing's plane): the wings sit off
    // the skeleton's plane (both wings share it), where a uniform scale
    // about a pivot would shear them through their own thickness.
    sp_gen_param(g, b.shoulder, SP_CH_RZ, -0.6, 0.6, SP_GROUP_POSE);
    sp_gen_param(g, b.shoulder, SP_CH_SX, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(g, b.elbow, SP_CH_RZ, -0.4, 0.4, SP_GROUP_POSE);
    sp_gen_param(g, b.elbow, SP_CH_SX, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(g, b.wrist, SP_CH_RZ, -0.35, 0.35, SP_GROUP_POSE);
    for (int k = 0; k < FINGERS; ++k) {
        // Spread limits: a finger turns at most 0.3 rad in all (both
        // joints), so neighbours (about 38 degrees apart) never cross and
        // the membrane between them never folds over.
        sp_gen_param(g, b.fa[k], SP_CH_RZ, -0.15, 0.15, SP_GROUP_POSE);
        sp_gen_param(g, b.fa[k], SP_CH_SX, 0.7, 1.4, SP_GROUP_SHAPE);
        sp_gen_param(g, b.fb[k], SP_CH_RZ, -0.15, 0.15, SP_GROUP_POSE);
    }
    return b;
}

// Arm: shoulder -> elbow -> wrist, thick at the shoulder; knobs at the elbow
// and wrist, a shoulder stub on the back.
static void wings_arm(sp_gen_mesh* m, const wing_bones* b)
{
    const sp_vec3 S = k_S, E = k_E, W = k_W;
    const sp_vec3 pts[] = {S, E, W};
    sp_gen_path arm;
    sp_gen_path_catmull(&arm, pts, 3, 40);
    sp_gen_chain ch = {0};
    double se = sp_gen_path_project(&arm, E), sw = sp_gen_path_project(&arm, W);
    sp_gen_chain_add(&ch, b->shoulder, 0.0, 0.0);
    sp_gen_chain_add(&ch, b->elbow, se, 0.12);
    sp_gen_chain_add(&ch, b->wrist, sw - 0.02, 0.04);
    tube_ctx tc = {0.085, 0.05};
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &arm,
                                       .rings = 60,
                                       .segments = 20,
                                       .profile = bone_profile,
                                       .color = bone_color,
                                       .user = &tc,
                                       .chain = &ch,
                                       .cap0_rings = 3,
                                       .cap0_len = 1.0,
                                       .cap1_rings = 3,
                                       .cap1_len = 1.0});
    sp_gen_path_free(&arm);
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = E,
                                                 .ax = sp_v3(0, 0.075, 0),
                                                 .ay = sp_v3(0, 0, 0.065),
                                                 .az = sp_v3(0.075, 0, 0),
                                                 .rings = 8,
                                                 .segments = 12,
                                                 .color = knob_color,
                                                 .skin = sp_gen_skin_one(b->elbow)});
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = W,
                                                 .ax = sp_v3(0, 0.065, 0),
                                                 .ay = sp_v3(0, 0, 0.055),
                                                 .az = sp_v3(0.065, 0, 0),
                                                 .rings = 8,
                                                 .segments = 12,
                                                 .color = knob_color,
                                                 .skin = sp_gen_skin_one(b->wrist)});
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = sp_v3(-0.05, 0.08, 0),
                                                 .ax = sp_v3(0, 0.1, 0),
                                                 .ay = sp_v3(0, 0, 0.09),
                                                 .az = sp_v3(0.16, 0, 0),
                                                 .rings = 10,
                                                 .segments = 14,
                                                 .color = knob_color,
                                                 .skin = sp_gen_skin_one(b->root)});
}

// Fingers, each with its skin chain (wrist, proximal, distal) and the
// membrane's side along it, from just outside the wrist knob to the tip.
static void wings_fingers(sp_gen_mesh* m, const wing_bones* b, sp_gen_curve side[FINGERS], sp_gen_chain fch[FINGERS])
{
    const sp_vec3 W = k_W;
    for (int k = 0; k < FINGERS; ++k) {
        const finger* f = &k_fingers[k];
        enum { N = 32 };
        sp_vec3 pts[N + 1];
        for (int i = 0; i <= N; ++i)
            pts[i] = finger_point(W, f, (double)i / N);
        sp_gen_path fp;
        sp_gen_path_points(&fp, pts, N + 1);
        sp_gen_chain ch = {0};
        sp_gen_chain_add(&ch, b->wrist, 0.0, 0.0);
        sp_gen_chain_add(&ch, b->fa[k], 0.06, 0.05);
        sp_gen_chain_add(&ch, b->fb[k], f->knuckle * fp.length, 0.15 * fp.length);
        fch[k] = ch;
        tube_ctx tc = {0.04, 0.014};
        sp_gen_tube(m, &(sp_gen_tube_desc){.path = &fp,
                                           .s0 = 0.03,
                                           .rings = 50,
                                           .segments = 12,
                                           .profile = bone_profile,
                                           .color = bone_color,
                                           .user = &tc,
                                           .chain = &ch,
                                           .cap1_rings = 2,
                                           .cap1_len = 1.0});
        for (int i = 0; i <= N; ++i) {
            double s = 0.07 + 0.93 * (double)i / N;
            sp_vec3 p = finger_point(W, f, s);
            sp_gen_skin sk = sp_gen_chain_skin(&ch, s * fp.length);
            sp_gen_curve_push(&side[k], p, &sk);
        }
        sp_gen_curve_finish(&side[k]);
        sp_gen_path_free(&fp);
    }
}

// The membrane's last side: down the forearm and humerus to the shoulder,
// then back along the body to where the membrane meets the back.
static void wings_arm_side(sp_gen_curve* side, const wing_bones* b)
{
    const sp_vec3 S = k_S, E = k_E, W = k_W;
    const sp_vec3 pts[] = {W, E, S, k_back};
    // Skin along it: the wrist's knob, the forearm (the elbow's bone), the
    // humerus (the shoulder's), then the root, blended smoothly across the
    // elbow and the shoulder.
    double le = sp_v3_len(sp_v3_sub(E, W)), ls = sp_v3_len(sp_v3_sub(S, E));
    sp_gen_chain ach = {0};
    sp_gen_chain_add(&ach, b->wrist, 0.0, 0.0);
    sp_gen_chain_add(&ach, b->elbow, 0.06, 0.05);
    sp_gen_chain_add(&ach, b->shoulder, le, 0.15);
    sp_gen_chain_add(&ach, b->root, le + ls, 0.15);
    double at = 0.0;
    for (int seg = 0; seg < 3; ++seg) {
        enum { N = 16 };
        double len = sp_v3_len(sp_v3_sub(pts[seg + 1], pts[seg]));
        for (int i = seg == 0 ? 0 : 1; i <= N; ++i) {
            double t = (double)i / N;
            sp_vec3 p = sp_v3_add(pts[seg], sp_v3_scale(sp_v3_sub(pts[seg + 1], pts[seg]), t));
            double sa = at + t * len;
            if (seg == 0 && i == 0) p = sp_v3_add(W, sp_v3_scale(sp_v3_sub(E, W), 0.07)), sa = 0.07 * le;
            sp_gen_skin sk = sp_gen_chain_skin(&ach, sa);
            sp_gen_curve_push(side, p, &sk);
        }
        at += len;
    }
    sp_gen_curve_finish(side);
}

// Membrane panels between consecutive sides: a short inner edge at the
// wrist, a scalloped trailing edge sagging towards the wrist.
static void wings_membrane(sp_gen_mesh* m, const wing_bones* b, const sp_gen_curve side[FINGERS + 1],
                           const sp_gen_chain fch[FINGERS])
{
    const sp_vec3 E = k_E, W = k_W;
    // The forearm seen from the wrist: the wrist's knob, then the elbow's bone.
    sp_gen_chain forearm = {0};
    sp_gen_chain_add(&forearm, b->wrist, 0.0, 0.0);
    sp_gen_chain_add(&forearm, b->elbow, 0.06, 0.05);
    for (int k = 0; k < FINGERS; ++k) {
        const sp_gen_curve *c0 = &side[k], *c1 = &side[k + 1];
        sp_gen_curve inner = {0}, outer = {0};
        sp_gen_curve_push(&inner, c0->p[0], &c0->skin[0]);
        sp_gen_curve_push(&inner, c1->p[0], &c1->skin[0]);
        sp_gen_curve_finish(&inner);
        sp_vec3 a = c0->p[c0->n - 1], bt = c1->p[c1->n - 1];
        sp_vec3 mid = sp_v3_scale(sp_v3_add(a, bt), 0.5);
        sp_vec3 ctl = sp_v3_add(mid, sp_v3_scale(sp_v3_sub(W, mid), k == FINGERS - 1 ? 0.32 : 0.42));
        enum { N = 24 };
        for (int i = 0; i <= N; ++i) {
            double t = (double)i / N;
            sp_gen_skin sk = sp_gen_skin_lerp(&c0->skin[c0->n - 1], &c1->skin[c1->n - 1], t);
            sp_gen_curve_push(&outer, sp_gen_bezier2(a, ctl, bt, t), &sk);
        }
        sp_gen_curve_finish(&outer);
        panel_ctx pc = {W, k_fingers[k].angle, 0.0, &fch[k], k < FINGERS - 1 ? &fch[k + 1] : &forearm, 0.0, 0.0};
        if (k < FINGERS - 1) {
            pc.a1 = k_fingers[k + 1].angle;
        } else {
            pc.a1 = atan2(E.y - W.y, E.x - W.x) + 2.0 * k_pi;
            pc.r_near = 0.35, pc.r_far = 0.7;
        }
        sp_gen_membrane(m, &(sp_gen_membrane_desc){.inner = &inner,
                                                   .outer = &outer,
                                                   .side0 = c0,
                                                   .side1 = c1,
                                                   .ns = k == FINGERS - 1 ? 26 : 20,
                                                   .nt = k == FINGERS - 1 ? 18 : 12,
                                                   .thickness = 0.014,
                                                   .color = membrane_color,
                                                   .skin = panel_skin,
                                                   .user = &pc});
        sp_gen_curve_free(&inner);
        sp_gen_curve_free(&outer);
    }
}

// Flap: the shoulder sweeps, elbow and wrist follow with a lag, the fingers
// fold a little on the down-stroke.
static void wings_flap(sp_gen_rig* g, const wing_bones* b)
{
    enum { KEYS = 33 };
    sp_gen_clip_begin(g, "flap", 1.2, KEYS);
    double a[KEYS];
    for (int q = 0; q < KEYS; ++q)
        a[q] = 0.42 * sin(2.0 * k_pi * q / (KEYS - 1));
    sp_gen_clip_rz(g, b->shoulder, a);
    for (int q = 0; q < KEYS; ++q)
        a[q] = -0.3 * sin(2.0 * k_pi * q / (KEYS - 1) - 0.6);
    sp_gen_clip_rz(g, b->elbow, a);
    for (int q = 0; q < KEYS; ++q)
        a[q] = 0.22 * sin(2.0 * k_pi * q / (KEYS - 1) - 1.2);
    sp_gen_clip_rz(g, b->wrist, a);
    for (int k = 0; k < FINGERS; ++k) {
        for (int q = 0; q < KEYS; ++q)
            a[q] = 0.04 * (k - 1.5) * sin(2.0 * k_pi * q / (KEYS - 1) - 1.4);
        sp_gen_clip_rz(g, b->fa[k], a);
    }
}

sp_result sp_dragon_wings(const char* path, sp_error* err)
{
    sp_gen_rig g;
    sp_gen_rig_init(&g);
    wing_bones b = wings_skeleton(&g);

    sp_gen_mesh m = {0};
    int wing_first = m.vertex_count, wing_tri = m.tri_count;
    wings_arm(&m, &b);
    sp_gen_curve side[FINGERS + 1] = {{0}};
    sp_gen_chain fch[FINGERS];
    wings_fingers(&m, &b, side, fch);
    wings_arm_side(&side[FINGERS], &b);
    wings_membrane(&m, &b, side, fch);
    for (int k = 0; k <= FINGERS; ++k)
        sp_gen_curve_free(&side[k]);
    // Claws: the thumb at the wrist.
    m.decorating = true;
    sp_gen_cone(&m, &(sp_gen_cone_desc){.base = sp_v3_add(k_W, sp_v3(0.03, 0.03, 0)),
                                        .bend = sp_v3_add(k_W, sp_v3(0.13, 0.12, 0)),
                                        .tip = sp_v3_add(k_W, sp_v3(0.2, 0.08, 0)),
                                        .base_radius = 0.035,
                                        .tip_radius = 0.005,
                                        .taper = 1.2,
                                        .flat = 0.7,
                                        .rings = 10,
                                        .segments = 12,
                                        .base_color = sp_dragon_horn,
                                        .tip_color = sp_dragon_horn_tip,
                                        .skin = sp_gen_skin_one(b.wrist)});
    m.decorating = false;

    // Lean the wing outwards (its tip away from the body) and move it to the
    // body's side, without changing the side view; then the far wing.
    sp_gen_mesh_shear_z(&m, wing_first, 0.36, 0.2);
    sp_gen_mesh_mirror_z(&m, wing_first, wing_tri);
    wings_flap(&g, &b);

    sp_part part = sp_dragon_attach_part("wings", "wings", "wing_root", g.pivot[b.root]);
    sp_result r = sp_gen_save(&g, &m, &(sp_gen_save_desc){.part = &part, .name = "wings", .root_reach_view = true}, path, err);
    sp_gen_mesh_free(&m);
    sp_gen_rig_free(&g);
    return r;
}
