// dragon_legs.c: the front and hind leg pairs. Each part is a girdle (a
// rounded bar across the body, which the torso's socket holds) and two legs
// with their own chains, the near one stepping forward and the far one back
// so that both read in the side view: thick upper limb, lower limb, a
// metapodial, a three-toed foot with claws.
//
// Skeleton: <root> -> near_<a> -> near_<b> -> near_<c> -> near_toes, the same for far_.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dragon.h"

static const double k_pi = 3.14159265358979323846;

typedef struct leg_desc {
    const char* category;
    const char* root_name;
    const char* seg[3]; ///< joint names of the three limb segments (the toes are "toes")
    sp_vec3 pt[5];      ///< joint pivots at stance 0: top, 1st bend, 2nd bend, ball of the foot, toe tips
    double radius[4];   ///< limb radius at pt[0..3]
    double lim[4][2];   ///< rz limits of the segments and the toes (the top one: of the near leg; mirrored for the far leg)
    double stance_near, stance_far;
    double girdle_radius;
    double walk_swing;    ///< amplitude of the top segment in the walk clip
    int lower_bends_back; ///< +1 if the second bend folds forward-to-back (knee of a hind leg), -1 else
} leg_desc;

typedef struct leg_ctx {
    const leg_desc* d;
    double s0, s1, s2, s3, len; ///< arc lengths of the top pivot, the bends, the ball of the foot, the end
    int root;
} leg_ctx;

static sp_gen_skin leg_skin(double s, const sp_gen_skin* base, void* user)
{
    const leg_ctx* c = user;
    sp_gen_skin root = sp_gen_skin_one(c->root);
    return sp_gen_skin_lerp(base, &root, 0.4 * (1.0 - sp_gen_smoothstep(0.0, c->s0 + 0.5 * (c->s1 - c->s0), s)));
}

static sp_gen_section leg_profile(double u, void* user)
{
    const leg_ctx* c = user;
    const double* R = c->d->radius;
    double s0 = c->s0, s1 = c->s1, s2 = c->s2, s3 = c->s3;
    // Narrow where it hides in the girdle, a muscular upper limb, knobbly
    // joints, slim lower limbs, a broad foot.
    double k[11][2] = {{0.0, R[0] * 0.4},
                       {s0, R[0] * 0.95},
                       {s0 + 0.35 * (s1 - s0), R[0] * 1.08},
                       {s0 + 0.8 * (s1 - s0), R[1] * 1.12},
                       {s1, R[1] * 1.2},
                       {s1 + 0.3 * (s2 - s1), R[1] * 0.92},
                       {s1 + 0.75 * (s2 - s1), R[2] * 0.95},
                       {s2, R[2] * 1.15},
                       {s2 + 0.5 * (s3 - s2), R[3] * 0.95},
                       {s3, R[3] * 1.25},
                       {c->len, R[3] * 1.0}};
    for (int i = 0; i < 11; ++i)
        k[i][0] /= c->len;
    double r = sp_gen_interp((const double(*)[2])k, 11, u);
    double foot = sp_gen_smoothstep(s2 / c->len, s3 / c->len, u);
    return (sp_gen_section){r * (1.0 - 0.25 * foot), r * (1.0 - 0.25 * foot), r * (0.92 + 0.25 * foot)};
}

static sp_gen_rgb leg_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_dragon_scales(u, a, p, 0.0, 0.0);
}

static sp_gen_section girdle_profile(double u, void* user)
{
    double r = *(const double*)user;
    double f = 0.8 + 0.2 * sin(k_pi * u);
    return (sp_gen_section){r * f * 0.8, r * f * 0.8, r * f * 1.5};
}

static sp_gen_rgb girdle_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_dragon_scales(u, a, p, 0.0, 0.0);
}

static sp_gen_section toe_profile(double u, void* user)
{
    double r = *(const double*)user * (1.0 - 0.35 * u);
    return (sp_gen_section){r, r * 0.8, r};
}

static sp_gen_rgb toe_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_dragon_scales(u, a, p, 0.6, 0.0);
}

static sp_vec3 rot2(sp_vec3 p, double a)
{
    return sp_v3(p.x * cos(a) - p.y * sin(a), p.x * sin(a) + p.y * cos(a), p.z);
}

// One leg at `stance` (rotation about the top pivot) and depth z; its joints
// are appended to g, their indices in j[4].
static void build_leg(sp_gen_rig* g, sp_gen_mesh* m, const leg_desc* d, int root, const char* side, double stance, double z,
                      int j[4])
{
    // The leg's joints sit in the leg's own plane (z), so that a bone's
    // uniform scale grows the leg about its axis instead of shearing it sideways.
    sp_vec3 pt[5];
    for (int k = 0; k < 5; ++k)
        pt[k] = rot2(d->pt[k], stance), pt[k].z = z;
    char name[64];
    for (int k = 0; k < 4; ++k) {
        snprintf(name, sizeof name, "%s_%s", side, k < 3 ? d->seg[k] : "toes");
        j[k] = sp_gen_joint(g, name, k ? j[k - 1] : root, pt[k], atan2(pt[k + 1].y - pt[k].y, pt[k + 1].x - pt[k].x));
    }
    // The limb from inside the girdle to just past the ball of the foot.
    sp_vec3 T3 = sp_v3_norm(sp_v3_sub(pt[4], pt[3]));
    // It starts well above the top pivot, inside the girdle, so that the
    // blend from the girdle to the upper limb can be long: a thick limb
    // swinging 40 degrees over a short blend would fold at the armpit.
    sp_vec3 ctrl[5] = {sp_v3_add(pt[0], sp_v3(0, 0.13, 0)), pt[1], pt[2], pt[3], sp_v3_add(pt[3], sp_v3_scale(T3, 0.1))};
    sp_gen_path path;
    sp_gen_path_catmull(&path, ctrl, 5, 40);
    double s0 = sp_gen_path_project(&path, pt[0]), s1 = sp_gen_path_project(&path, pt[1]), s2 = sp_gen_path_project(&path, pt[2]),
           s3 = sp_gen_path_project(&path, pt[3]);
    // The limb's own chain; the girdle (root) fades in only partly at the
    // top (leg_skin): a full hand-over from the girdle to a thick upper limb
    // swinging 35 degrees would fold the hip or armpit.
    sp_gen_chain ch = {0};
    sp_gen_chain_add(&ch, j[0], 0.0, 0.0);
    sp_gen_chain_add(&ch, j[1], s1, 0.5 * (s1 - s0));
    sp_gen_chain_add(&ch, j[2], s2, 0.4 * (s2 - s1));
    sp_gen_chain_add(&ch, j[3], s3 - 0.02, 0.1);
    leg_ctx lc = {d, s0, s1, s2, s3, path.length, root};
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &path,
                                       .rings = 100,
                                       .segments = 28,
                                       .profile = leg_profile,
                                       .color = leg_color,
                                       .user = &lc,
                                       .chain = &ch,
                                       .skin_at = leg_skin,
                                       .cap0_rings = 3,
                                       .cap0_len = 0.3,
                                       .cap1_rings = 4,
                                       .cap1_len = 0.9});
    sp_gen_path_free(&path);
    // Three toes fanning forward from the ball of the foot, claws at the tips.
    double toe_r = d->radius[3] * 0.62;
    for (int t = 0; t < 3; ++t) {
        double spread = (t - 1) * 0.36;
        double len = (t == 1 ? 1.0 : 0.85) * sp_v3_len(sp_v3_sub(pt[4], pt[3]));
        sp_vec3 dir = sp_v3_norm(sp_v3_add(T3, sp_v3(0, 0, spread)));
        sp_vec3 a = sp_v3_add(pt[3], sp_v3(0, -0.25 * toe_r, spread * 0.08));
        sp_vec3 b = sp_v3_add(a, sp_v3_scale(dir, len));
        b.y -= 0.3 * toe_r;
        sp_vec3 tp[3] = {a, sp_v3_add(sp_v3_scale(sp_v3_add(a, b), 0.5), sp_v3(0, 0.25 * toe_r, 0)), b};
        sp_gen_path toe;
        sp_gen_path_catmull(&toe, tp, 3, 12);
        sp_gen_chain tch = {0};
        sp_gen_chain_add(&tch, j[2], 0.0, 0.0);
        sp_gen_chain_add(&tch, j[3], 0.05, 0.05);
        sp_gen_tube(m, &(sp_gen_tube_desc){.path = &toe,
                                           .rings = 18,
                                           .segments = 12,
                                           .profile = toe_profile,
                                           .color = toe_color,
                                           .user = &toe_r,
                                           .chain = &tch,
                                           .cap0_rings = 2,
                                           .cap0_len = 1.0,
                                           .cap1_rings = 2,
                                           .cap1_len = 1.0});
        sp_gen_path_free(&toe);
        bool was = m->decorating;
        m->decorating = true;
        sp_vec3 cd = sp_v3_norm(sp_v3_add(dir, sp_v3(0, -0.5, 0)));
        sp_vec3 cb = sp_v3_sub(b, sp_v3_scale(dir, 0.3 * toe_r));
        sp_vec3 ct = sp_v3_add(cb, sp_v3_scale(cd, 3.2 * toe_r));
        sp_gen_cone(m, &(sp_gen_cone_desc){.base = cb,
                                           .bend = sp_v3_add(sp_v3_scale(sp_v3_add(cb, ct), 0.5), sp_v3(0, 0.4 * toe_r, 0)),
                                           .tip = ct,
                                           .base_radius = 0.75 * toe_r,
                                           .tip_radius = 0.08 * toe_r,
                                           .taper = 1.0,
                                           .flat = 0.7,
                                           .rings = 8,
                                           .segments = 10,
                                           .base_color = sp_dragon_horn,
                                           .tip_color = sp_dragon_horn_tip,
                                           .skin = sp_gen_skin_one(j[3])});
        m->decorating = was;
    }
}

static sp_result build_pair(const leg_desc* d, const char* path, sp_error* err)
{
    sp_gen_rig g;
    sp_gen_rig_init(&g);
    int root = sp_gen_joint(&g, d->root_name, -1, sp_v3(0, 0, 0), -0.5 * k_pi);
    sp_gen_mesh m = {0};
    // The girdle: a rounded bar across the body.
    {
        double r = d->girdle_radius;
        sp_vec3 pts[2] = {{0, 0.02, -0.36}, {0, 0.02, 0.36}};
        sp_gen_path bar;
        sp_gen_path_points(&bar, pts, 2);
        sp_gen_tube(&m, &(sp_gen_tube_desc){.path = &bar,
                                            .rings = 30,
                                            .segments = 32,
                                            .side = {-1, 0, 0},
                                            .profile = girdle_profile,
                                            .color = girdle_color,
                                            .user = &r,
                                            .skin = sp_gen_skin_one(root),
                                            .cap0_rings = 4,
                                            .cap0_len = 0.8,
                                            .cap1_rings = 4,
                                            .cap1_len = 0.8});
        sp_gen_path_free(&bar);
    }
    int nj[4], fj[4];
    build_leg(&g, &m, d, root, "near", d->stance_near, 0.27, nj);
    build_leg(&g, &m, d, root, "far", d->stance_far, -0.27, fj);

    sp_dragon_root_params(&g, root);
    sp_gen_param(&g, root, SP_CH_SY, 0.75, 1.35, SP_GROUP_SHAPE);
    for (int side = 0; side < 2; ++side) {
        const int* j = side == 0 ? nj : fj;
        // The near leg stands forward, the far one back; neither upper limb
        // may swing past the other (the outline would cross itself).
        for (int k = 0; k < 4; ++k) {
            double lo = d->lim[k][0], hi = d->lim[k][1];
            if (k == 0 && side == 1) lo = -d->lim[0][1], hi = -d->lim[0][0];
            sp_gen_param(&g, j[k], SP_CH_RZ, lo, hi, SP_GROUP_POSE);
        }
        sp_gen_param(&g, j[0], SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
        sp_gen_param(&g, j[1], SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
        sp_gen_param(&g, j[2], SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
        sp_gen_param(&g, j[3], SP_CH_S, 0.7, 1.5, SP_GROUP_SHAPE);
    }

    // Walk: the legs swing in antiphase; the lower joints lift the foot on
    // the forward swing and the toes roll off the ground behind.
    enum { KEYS = 33 };
    sp_gen_clip_begin(&g, "walk", 1.0, KEYS);
    for (int side = 0; side < 2; ++side) {
        const int* j = side == 0 ? nj : fj;
        double ph0 = side == 0 ? 0.0 : k_pi;
        double a[4][KEYS];
        for (int q = 0; q < KEYS; ++q) {
            double ph = 2.0 * k_pi * q / (KEYS - 1) + ph0;
            double lift = fmax(0.0, sin(ph + 0.5 * k_pi)); // swing phase
            a[0][q] = d->walk_swing * sin(ph);
            a[1][q] = d->lower_bends_back * 0.45 * lift * lift;
            a[2][q] = -d->lower_bends_back * 0.3 * lift * lift - 0.1 * sin(ph);
            a[3][q] = 0.25 * fmax(0.0, -sin(ph)) * fmax(0.0, cos(ph));
        }
        for (int k = 0; k < 4; ++k)
            sp_gen_clip_rz(&g, j[k], a[k]);
    }

    sp_part part = sp_dragon_attach_part(d->category, d->category, d->root_name, g.pivot[root]);
    // Front and hind legs: the kiosk tells them apart by where on a body they are drawn.
    snprintf(part.family, sizeof part.family, "legs");
    sp_result r =
        sp_gen_save(&g, &m, &(sp_gen_save_desc){.part = &part, .name = d->category, .root_reach_view = true}, path, err);
    sp_gen_mesh_free(&m);
    sp_gen_rig_free(&g);
    return r;
}

sp_result sp_dragon_front_legs(const char* path, sp_error* err)
{
    static const leg_desc d = {
        .category = "front_legs",
        .root_name = "front_root",
        .seg = {"upper_arm", "forearm", "hand"},
        .pt = {{0.0, -0.02, 0}, {-0.14, -0.48, 0}, {0.0, -0.9, 0}, {0.14, -1.0, 0}, {0.32, -1.03, 0}},
        .radius = {0.19, 0.115, 0.085, 0.09},
        .lim = {{-0.3, 0.45}, {-0.45, 0.45}, {-0.5, 0.5}, {-0.4, 0.4}},
        .stance_near = 0.3,
        .stance_far = -0.3,
        .girdle_radius = 0.22,
        .walk_swing = 0.28,
        .lower_bends_back = 1,
    };
    return build_pair(&d, path, err);
}

sp_result sp_dragon_hind_legs(const char* path, sp_error* err)
{
    static const leg_desc d = {
        .category = "hind_legs",
        .root_name = "hind_root",
        .seg = {"thigh", "shin", "foot"},
        .pt = {{0.0, -0.02, 0}, {0.22, -0.42, 0}, {-0.1, -0.82, 0}, {0.02, -1.1, 0}, {0.24, -1.14, 0}},
        .radius = {0.25, 0.13, 0.09, 0.09},
        .lim = {{-0.3, 0.45}, {-0.45, 0.45}, {-0.5, 0.5}, {-0.4, 0.4}},
        .stance_near = 0.3,
        .stance_far = -0.3,
        .girdle_radius = 0.23,
        .walk_swing = 0.28,
        .lower_bends_back = -1,
    };
    return build_pair(&d, path, err);
}
