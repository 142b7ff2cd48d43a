// dragon_head.c: the head on its neck: an S-curved neck of five joints, a
// skull with brow ridges and a tapering snout, a hinged lower jaw, swept-back
// horns, slit-pupil eyes, fangs, cheek spikes and a dorsal crest.
//
// Skeleton: neck_root -> neck_1 -> neck_2 -> neck_3 -> neck_4 -> head,
// head -> snout, head -> jaw, head -> horns.
#include <math.h>
#include <stdlib.h>

#include "dragon.h"

static const double k_pi = 3.14159265358979323846;

enum { NECK_OWNERS = 6 };
// Regions along the neck path: neck_root, neck_1 .. neck_4, then the head.
static const double k_neck_cut[NECK_OWNERS] = {0.0, 0.2, 0.4, 0.6, 0.8, 0.97};

static sp_gen_section neck_profile(double u, void* user)
{
    (void)user;
    static const double r[][2] = {{0.0, 0.21}, {0.3, 0.18}, {0.6, 0.155}, {1.0, 0.14}};
    double k = sp_gen_interp(r, 4, u);
    return (sp_gen_section){k * 1.05, k * 1.08, k * 0.88};
}

static double neck_bump(double u, double a, void* user)
{
    (void)user, (void)u;
    return 1.0 + 0.06 * exp(-(1.0 - cos(a)) / 0.02);
}

static sp_gen_rgb neck_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_dragon_scales(u, a, p, 0.9, 12.0);
}

static sp_gen_section skull_profile(double u, void* user)
{
    (void)user;
    static const double up[][2] = {{0.0, 0.13},   {0.14, 0.2},   {0.3, 0.225}, {0.45, 0.19},
                                   {0.62, 0.135}, {0.85, 0.115}, {1.0, 0.1}};
    static const double down[][2] = {{0.0, 0.13}, {0.15, 0.16}, {0.32, 0.11}, {0.5, 0.075}, {0.8, 0.065}, {1.0, 0.06}};
    static const double side[][2] = {{0.0, 0.13}, {0.2, 0.19}, {0.36, 0.195}, {0.52, 0.145}, {0.8, 0.1}, {1.0, 0.085}};
    return (sp_gen_section){sp_gen_interp(up, 7, u), sp_gen_interp(down, 6, u), sp_gen_interp(side, 6, u)};
}

static double skull_bump(double u, double a, void* user)
{
    (void)user;
    double sa = fabs(sin(a)), ca = cos(a);
    // Brow ridges over the eyes, nostril swellings at the end of the snout.
    double brow = 0.16 * exp(-pow((u - 0.36) / 0.07, 2)) * exp(-pow((ca - 0.45) / 0.25, 2)) * sa;
    double nose = 0.12 * exp(-pow((u - 0.9) / 0.05, 2)) * exp(-pow((ca - 0.5) / 0.3, 2)) * sa;
    return 1.0 + brow + nose;
}

static sp_gen_rgb skull_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    sp_gen_rgb c = sp_dragon_scales(u, a, p, 0.0, 0.0);
    // The upper jaw's underside is the roof of the mouth; its rim lighter.
    double ca = cos(a);
    double lip = sp_gen_smoothstep(-0.2, -0.5, ca) * sp_gen_smoothstep(0.35, 0.5, u);
    c = sp_gen_mix(c, sp_dragon_belly, 0.7 * sp_gen_smoothstep(-0.25, -0.45, ca) * (1.0 - lip));
    return sp_gen_mix(c, sp_dragon_mouth, 0.9 * sp_gen_smoothstep(-0.75, -0.95, ca) * sp_gen_smoothstep(0.3, 0.45, u));
}

static sp_gen_section jaw_profile(double u, void* user)
{
    (void)user;
    static const double down[][2] = {{0.0, 0.1}, {0.35, 0.1}, {0.7, 0.075}, {1.0, 0.055}};
    static const double side[][2] = {{0.0, 0.14}, {0.4, 0.115}, {0.75, 0.09}, {1.0, 0.07}};
    double s = sp_gen_interp(side, 4, u);
    return (sp_gen_section){0.035, sp_gen_interp(down, 4, u), s};
}

static sp_gen_rgb jaw_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    double ca = cos(a);
    sp_gen_rgb c = sp_dragon_scales(u, a + k_pi, p, 0.0, 0.0);
    c = sp_gen_mix(c, sp_dragon_belly, sp_gen_smoothstep(0.2, -0.4, ca));
    return sp_gen_mix(c, sp_dragon_mouth, sp_gen_smoothstep(0.7, 0.95, ca));
}

static sp_gen_rgb eye_color(double u, double a, sp_vec3 p, void* user)
{
    (void)p, (void)user;
    // Outward pole at u = 1: a vertical slit pupil in a golden iris, a dark rim.
    double slit = u > 0.72 ? sp_gen_smoothstep(0.5, 0.3, fabs(sin(a)) * (1.25 - u) * 6.0) : 0.0;
    sp_gen_rgb c = sp_gen_mix(sp_dragon_eye, sp_gen_shade(sp_dragon_eye, 0.55), sp_gen_smoothstep(0.75, 0.45, u));
    c = sp_gen_mix(c, sp_dragon_pupil, slit);
    return sp_gen_mix(c, sp_dragon_back, sp_gen_smoothstep(0.5, 0.3, u));
}

static sp_gen_rgb nostril_color(double u, double a, sp_vec3 p, void* user)
{
    (void)u, (void)a, (void)p, (void)user;
    return sp_dragon_pupil;
}

// A point on the skull surface at tube parameter u, section angle a.
static sp_vec3 skull_point(const sp_gen_path* path, double u, double a, double f)
{
    sp_vec3 T;
    sp_vec3 c = sp_gen_path_at(path, u * path->length, &T);
    sp_vec3 B = sp_v3(0, 0, 1);
    sp_vec3 N = sp_v3_norm(sp_v3_cross(B, T));
    sp_gen_section s = skull_profile(u, NULL);
    double h = cos(a) >= 0 ? s.up : s.down;
    return sp_v3_add(c, sp_v3_add(sp_v3_scale(N, cos(a) * h * f), sp_v3_scale(B, sin(a) * s.side * f)));
}

typedef struct head_rig {
    int j[NECK_OWNERS]; ///< neck_root .. head
    int head, snout, jaw, horns;
    sp_vec3 hinge, chin; ///< the jaw's hinge and its chin at rest (a little open)
} head_rig;

static const sp_vec3 k_horn_base = {0.8, 1.36, 0.0}, k_horn_bend = {0.6, 1.5, 0}, k_horn_tip = {0.36, 1.56, 0};

static head_rig head_skeleton(sp_gen_rig* g, const sp_gen_path* neck, const sp_gen_path* skull)
{
    double L = neck->length, H = skull->length;
    static const char* names[NECK_OWNERS] = {"neck_root", "neck_1", "neck_2", "neck_3", "neck_4", "head"};
    head_rig h;
    for (int k = 0; k < NECK_OWNERS; ++k) {
        sp_vec3 T;
        sp_vec3 at = sp_gen_path_at(neck, k_neck_cut[k] * L, &T);
        double ang = atan2(T.y, T.x);
        if (k == NECK_OWNERS - 1) {
            sp_vec3 Ts;
            sp_gen_path_at(skull, 0.5 * H, &Ts);
            ang = atan2(Ts.y, Ts.x);
        }
        h.j[k] = sp_gen_joint(g, names[k], k ? h.j[k - 1] : -1, at, ang);
    }
    h.head = h.j[NECK_OWNERS - 1];
    sp_vec3 Tsn;
    sp_vec3 snout_at = sp_gen_path_at(skull, 0.5 * H, &Tsn);
    h.snout = sp_gen_joint(g, "snout", h.head, snout_at, atan2(Tsn.y, Tsn.x));
    // The mouth is a little open at rest, so that the outline runs into it
    // and follows the jaw when it opens or closes.
    const sp_vec3 hinge = {0.86, 1.075, 0}, closed_chin = {1.56, 0.935, 0};
    const double gape = 0.2;
    h.hinge = hinge;
    h.chin = sp_v3_add(hinge, sp_v3(cos(-gape) * (closed_chin.x - hinge.x) - sin(-gape) * (closed_chin.y - hinge.y),
                                    sin(-gape) * (closed_chin.x - hinge.x) + cos(-gape) * (closed_chin.y - hinge.y), 0));
    h.jaw = sp_gen_joint(g, "jaw", h.head, hinge, atan2(h.chin.y - hinge.y, h.chin.x - hinge.x));
    h.horns = sp_gen_joint(g, "horns", h.head, k_horn_base, atan2(k_horn_tip.y - k_horn_base.y, k_horn_tip.x - k_horn_base.x));

    sp_dragon_root_params(g, h.j[0]);
    for (int k = 1; k <= 4; ++k) {
        sp_gen_param(g, h.j[k], SP_CH_RZ, -0.45, 0.45, SP_GROUP_POSE);
        sp_gen_param(g, h.j[k], SP_CH_S, 0.75, 1.35, SP_GROUP_SHAPE);
    }
    sp_gen_param(g, h.head, SP_CH_RZ, -0.6, 0.6, SP_GROUP_POSE);
    sp_gen_param(g, h.head, SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(g, h.snout, SP_CH_SX, 0.7, 1.5, SP_GROUP_SHAPE);
    sp_gen_param(g, h.snout, SP_CH_SY, 0.75, 1.35, SP_GROUP_SHAPE);
    sp_gen_param(g, h.jaw, SP_CH_RZ, -0.5, 0.2, SP_GROUP_POSE);
    sp_gen_param(g, h.jaw, SP_CH_SX, 0.8, 1.3, SP_GROUP_SHAPE);
    sp_gen_param(g, h.jaw, SP_CH_SY, 0.75, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(g, h.horns, SP_CH_RZ, -0.5, 0.5, SP_GROUP_POSE);
    sp_gen_param(g, h.horns, SP_CH_S, 0.6, 1.6, SP_GROUP_SHAPE);
    return h;
}

// Neck, skull and lower jaw; the neck's skin chain goes to `nch` for the
// crest along it.
static void head_body(sp_gen_mesh* m, const head_rig* h, const sp_gen_path* neck, const sp_gen_path* skull, sp_gen_chain* nch)
{
    double L = neck->length, H = skull->length;
    *nch = (sp_gen_chain){0};
    for (int k = 0; k < NECK_OWNERS; ++k)
        sp_gen_chain_add(nch, h->j[k], k_neck_cut[k] * L, 0.5 * L);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = neck,
                                       .rings = 110,
                                       .segments = 40,
                                       .profile = neck_profile,
                                       .bump = neck_bump,
                                       .color = neck_color,
                                       .chain = nch,
                                       .cap0_rings = 3,
                                       .cap0_len = 0.4});
    // Skull: head behind, snout in front, blended over a fifth of its length.
    sp_gen_chain sch = {0};
    sp_gen_chain_add(&sch, h->head, 0.0, 0.0);
    sp_gen_chain_add(&sch, h->snout, 0.5 * H, 0.18 * H);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = skull,
                                       .rings = 90,
                                       .segments = 48,
                                       .profile = skull_profile,
                                       .bump = skull_bump,
                                       .color = skull_color,
                                       .chain = &sch,
                                       .cap0_rings = 5,
                                       .cap0_len = 0.9,
                                       .cap1_rings = 4,
                                       .cap1_len = 0.7});
    // Lower jaw: rigid to the jaw, eased into the head at the hinge.
    sp_vec3 jaw_pts[2] = {h->hinge, h->chin};
    sp_gen_path jawp;
    sp_gen_path_points(&jawp, jaw_pts, 2);
    sp_gen_chain jch = {0};
    sp_gen_chain_add(&jch, h->head, 0.0, 0.0);
    sp_gen_chain_add(&jch, h->jaw, 0.06 * jawp.length, 0.06 * jawp.length);
    sp_gen_tube(m, &(sp_gen_tube_desc){.path = &jawp,
                                       .rings = 60,
                                       .segments = 32,
                                       .profile = jaw_profile,
                                       .color = jaw_color,
                                       .chain = &jch,
                                       .cap0_rings = 3,
                                       .cap0_len = 0.8,
                                       .cap1_rings = 3,
                                       .cap1_len = 0.8});
    sp_gen_path_free(&jawp);
    // Horns, one each side.
    int h0 = m->vertex_count, ht = m->tri_count;
    sp_gen_cone(m, &(sp_gen_cone_desc){.base = sp_v3(k_horn_base.x, k_horn_base.y, 0.1),
                                       .bend = sp_v3(k_horn_bend.x, k_horn_bend.y, 0.14),
                                       .tip = sp_v3(k_horn_tip.x, k_horn_tip.y, 0.17),
                                       .base_radius = 0.055,
                                       .tip_radius = 0.008,
                                       .taper = 1.1,
                                       .flat = 0.8,
                                       .rings = 20,
                                       .segments = 16,
                                       .base_color = sp_dragon_horn,
                                       .tip_color = sp_dragon_horn_tip,
                                       .skin = sp_gen_skin_one(h->horns)});
    sp_gen_mesh_mirror_z(m, h0, ht);
}

// A small cone (a tooth or a spike) from `base` along `dir` for `len`.
static void head_tooth(sp_gen_mesh* m, sp_vec3 base, sp_vec3 tip_offset, sp_vec3 dir, double len, double radius, int joint)
{
    sp_gen_cone(m, &(sp_gen_cone_desc){.base = base,
                                       .bend = sp_v3_add(base, sp_v3_scale(dir, 0.5 * len)),
                                       .tip = sp_v3_add(base, sp_v3_add(sp_v3_scale(dir, len), tip_offset)),
                                       .base_radius = radius,
                                       .tip_radius = 0.003,
                                       .taper = 1.0,
                                       .flat = 1.0,
                                       .rings = 6,
                                       .segments = 10,
                                       .base_color = sp_dragon_tooth,
                                       .tip_color = sp_dragon_tooth,
                                       .skin = sp_gen_skin_one(joint)});
}

// Decorations: eyes, nostrils, fangs, cheek spikes (both sides), the neck's crest.
static void head_decorations(sp_gen_mesh* m, const head_rig* h, const sp_gen_path* neck, const sp_gen_path* skull,
                             const sp_gen_chain* nch)
{
    double L = neck->length;
    m->decorating = true;
    int e0 = m->vertex_count, et = m->tri_count;
    sp_vec3 eye_c = skull_point(skull, 0.38, 0.9, 0.84);
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = eye_c,
                                                 .ax = sp_v3(0.0, 0.0, 0.06),
                                                 .ay = sp_v3(-0.014, 0.058, 0.0),
                                                 .az = sp_v3(-0.08, -0.019, 0.0),
                                                 .rings = 16,
                                                 .segments = 20,
                                                 .color = eye_color,
                                                 .skin = sp_gen_skin_one(h->head)});
    sp_vec3 nos_c = skull_point(skull, 0.93, 0.75, 0.95);
    sp_gen_ellipsoid(m, &(sp_gen_ellipsoid_desc){.center = nos_c,
                                                 .ax = sp_v3(0.0, 0.0, 0.018),
                                                 .ay = sp_v3(0.0, 0.012, 0.0),
                                                 .az = sp_v3(-0.025, 0.0, 0.0),
                                                 .rings = 8,
                                                 .segments = 10,
                                                 .color = nostril_color,
                                                 .skin = sp_gen_skin_one(h->snout)});
    for (int k = 0; k < 4; ++k) {
        double u = 0.58 + 0.1 * k;
        sp_vec3 base = skull_point(skull, u, 0.62 * k_pi, 0.9);
        head_tooth(m, base, sp_v3(-0.01, 0, 0), sp_v3(0.0, -1.0, 0.0), k == 0 ? 0.075 : 0.045, 0.018, h->snout);
    }
    for (int k = 0; k < 3; ++k) {
        double f = 0.5 + 0.15 * k;
        sp_vec3 jd = sp_v3_sub(h->chin, h->hinge);
        sp_vec3 base = sp_v3_add(h->hinge, sp_v3_add(sp_v3_scale(jd, f), sp_v3(0, 0.02, 0.06 - 0.012 * k)));
        sp_vec3 up = sp_v3_norm(sp_v3(-jd.y, jd.x, 0));
        head_tooth(m, base, sp_v3(0, 0, 0), up, 0.05 - 0.008 * k, 0.016, h->jaw);
    }
    for (int k = 0; k < 3; ++k) {
        sp_vec3 base = sp_v3(0.86 - 0.02 * k, 1.1 + 0.05 * k, 0.14);
        sp_vec3 tip = sp_v3(base.x - 0.16 + 0.03 * k, base.y - 0.03 + 0.02 * k, 0.19);
        sp_gen_cone(m, &(sp_gen_cone_desc){.base = base,
                                           .bend = sp_v3_scale(sp_v3_add(base, tip), 0.5),
                                           .tip = tip,
                                           .base_radius = 0.03,
                                           .tip_radius = 0.004,
                                           .taper = 1.2,
                                           .flat = 0.5,
                                           .rings = 8,
                                           .segments = 12,
                                           .base_color = sp_dragon_spike,
                                           .tip_color = sp_dragon_spike_tip,
                                           .skin = sp_gen_skin_one(h->head)});
    }
    sp_gen_mesh_mirror_z(m, e0, et);
    sp_dragon_spikes(m, &(sp_dragon_spikes_desc){.path = neck,
                                                 .chain = nch,
                                                 .profile = neck_profile,
                                                 .s0 = 0.1 * L,
                                                 .s1 = 0.92 * L,
                                                 .path_s0 = 0.0,
                                                 .path_s1 = L,
                                                 .count = 8,
                                                 .height = 0.16,
                                                 .width = 0.06,
                                                 .lean = 0.7});
    m->decorating = false;
}

// Nod: the neck sways a little, the head dips, the jaw opens at the low point.
static void head_nod(sp_gen_rig* g, const head_rig* h)
{
    enum { KEYS = 33 };
    sp_gen_clip_begin(g, "nod", 2.4, KEYS);
    for (int k = 1; k <= 5; ++k) {
        double a[KEYS];
        for (int q = 0; q < KEYS; ++q) {
            double ph = 2.0 * k_pi * q / (KEYS - 1);
            a[q] = k < 5 ? 0.05 * sin(ph - 0.35 * k) : -0.16 * sin(ph - 1.9);
        }
        sp_gen_clip_rz(g, h->j[k], a);
    }
    double jaw_a[KEYS];
    for (int q = 0; q < KEYS; ++q)
        jaw_a[q] = -0.14 * pow(0.5 - 0.5 * cos(2.0 * k_pi * q / (KEYS - 1)), 3.0);
    sp_gen_clip_rz(g, h->jaw, jaw_a);
}

sp_result sp_dragon_head(const char* path, sp_error* err)
{
    const sp_vec3 neck_ctrl[] = {{0.0, 0.0, 0}, {0.16, 0.33, 0}, {0.36, 0.67, 0}, {0.6, 0.96, 0}, {0.86, 1.12, 0}};
    const sp_vec3 skull_ctrl[] = {{0.70, 1.23, 0}, {1.15, 1.14, 0}, {1.64, 1.01, 0}};
    sp_gen_path neck, skull;
    sp_gen_path_catmull(&neck, neck_ctrl, 5, 48);
    sp_gen_path_catmull(&skull, skull_ctrl, 3, 64);

    sp_gen_rig g;
    sp_gen_rig_init(&g);
    head_rig h = head_skeleton(&g, &neck, &skull);
    sp_gen_mesh m = {0};
    sp_gen_chain nch;
    head_body(&m, &h, &neck, &skull, &nch);
    head_decorations(&m, &h, &neck, &skull, &nch);
    head_nod(&g, &h);

    sp_part part = sp_dragon_attach_part("head", "head", "neck_root", g.pivot[h.j[0]]);
    sp_result r = sp_gen_save(&g, &m, &(sp_gen_save_desc){.part = &part, .name = "head", .root_reach_view = true}, path, err);
    sp_gen_mesh_free(&m);
    sp_gen_path_free(&neck);
    sp_gen_path_free(&skull);
    sp_gen_rig_free(&g);
    return r;
}
