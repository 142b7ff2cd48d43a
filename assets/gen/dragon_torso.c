// dragon_torso.c: the torso: a deep-chested scaly body from the tail root to
// the neck root, a row of dorsal spikes, five sockets for the other parts.
//
// Skeleton (root in the middle, two chains outwards so either half bends):
//   torso -> lumbar -> pelvis -> tail_base        (towards -X)
//   torso -> chest -> shoulders -> neck_base      (towards +X)
//   torso -> belly                                (the belly's bulge, breathing)
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dragon.h"

static const double k_pi = 3.14159265358979323846;

// The body path is cut at these arc-length fractions into the regions the
// joints own, from the tail end: tail_base, pelvis, lumbar, torso, chest,
// shoulders, neck_base. A back-chain joint pivots at the inner end of its
// region, a front-chain joint at the inner start of its own.
enum { OWNERS = 7 };
static const double k_cut[OWNERS] = {0.0, 0.13, 0.29, 0.42, 0.58, 0.74, 0.88};

static sp_gen_section profile(double u, void* user)
{
    (void)user;
    // A deep chest keel in front, a narrower waist, haunches behind; both
    // ends narrow to the neck and tail roots.
    static const double up[][2] = {{0.0, 0.15},  {0.1, 0.23}, {0.2, 0.33},  {0.36, 0.31},
                                   {0.52, 0.34}, {0.7, 0.39}, {0.86, 0.27}, {1.0, 0.17}};
    static const double down[][2] = {{0.0, 0.14}, {0.1, 0.21},  {0.22, 0.31}, {0.4, 0.42},
                                     {0.6, 0.55}, {0.75, 0.46}, {0.88, 0.28}, {1.0, 0.17}};
    static const double side[][2] = {{0.0, 0.15}, {0.15, 0.27}, {0.4, 0.40}, {0.6, 0.42}, {0.8, 0.32}, {0.9, 0.24}, {1.0, 0.17}};
    return (sp_gen_section){sp_gen_interp(up, 8, u), sp_gen_interp(down, 8, u), sp_gen_interp(side, 7, u)};
}

static double bump(double u, double a, void* user)
{
    (void)user;
    double sa = sin(a), ca = cos(a);
    // Haunch and shoulder muscles on the flanks, a low ridge along the spine.
    double haunch = 0.09 * exp(-pow((u - 0.2) / 0.08, 2)) * sa * sa * sp_gen_smoothstep(-0.6, 0.2, ca);
    double shoulder = 0.08 * exp(-pow((u - 0.76) / 0.07, 2)) * sa * sa * sp_gen_smoothstep(-0.6, 0.2, ca);
    double ridge = 0.05 * exp(-(1.0 - ca) / 0.02);
    return 1.0 + haunch + shoulder + ridge;
}

static sp_gen_rgb color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_dragon_scales(u, a, p, 1.0, 16.0);
}

static sp_part_socket socket_at(const char* name, const char* joint, sp_vec3 p)
{
    sp_part_socket s = {.has_position = true, .position = sp_dragon_part_position(p)};
    snprintf(s.name, sizeof s.name, "%s", name);
    snprintf(s.joint, sizeof s.joint, "%s", joint);
    return s;
}

sp_result sp_dragon_torso(const char* path, sp_error* err)
{
    const sp_vec3 ctrl[] = {{-1.40, 0.10, 0}, {-0.92, 0.03, 0}, {-0.35, 0.00, 0},
                            {0.30, 0.02, 0},  {0.84, 0.14, 0},  {1.24, 0.40, 0}};
    sp_gen_path body;
    sp_gen_path_catmull(&body, ctrl, 6, 64);
    double L = body.length;

    sp_gen_rig g;
    sp_gen_rig_init(&g);
    sp_vec3 at[OWNERS];
    double ang[OWNERS];
    for (int k = 0; k < OWNERS; ++k) {
        sp_vec3 T;
        at[k] = sp_gen_path_at(&body, k_cut[k] * L, &T);
        ang[k] = atan2(T.y, T.x);
    }
    sp_vec3 Tm;
    sp_vec3 mid = sp_gen_path_at(&body, 0.5 * (k_cut[3] + k_cut[4]) * L, &Tm);
    // The back chain's bones point backwards (-T), the front chain's forwards.
    int torso = sp_gen_joint(&g, "torso", -1, mid, atan2(Tm.y, Tm.x));
    int lumbar = sp_gen_joint(&g, "lumbar", torso, at[3], ang[3] + k_pi);
    int pelvis = sp_gen_joint(&g, "pelvis", lumbar, at[2], ang[2] + k_pi);
    int tail_base = sp_gen_joint(&g, "tail_base", pelvis, at[1], ang[1] + k_pi);
    int chest = sp_gen_joint(&g, "chest", torso, at[4], ang[4]);
    int shoulders = sp_gen_joint(&g, "shoulders", chest, at[5], ang[5]);
    int neck_base = sp_gen_joint(&g, "neck_base", shoulders, at[6], ang[6]);
    int belly = sp_gen_joint(&g, "belly", torso, sp_v3(mid.x - 0.12, mid.y - 0.05, 0), -0.5 * k_pi);

    sp_dragon_root_params(&g, torso);
    sp_gen_param(&g, lumbar, SP_CH_RZ, -0.45, 0.45, SP_GROUP_POSE);
    sp_gen_param(&g, lumbar, SP_CH_SX, 0.7, 1.45, SP_GROUP_SHAPE);
    sp_gen_param(&g, lumbar, SP_CH_SY, 0.75, 1.35, SP_GROUP_SHAPE);
    sp_gen_param(&g, pelvis, SP_CH_RZ, -0.45, 0.45, SP_GROUP_POSE);
    sp_gen_param(&g, pelvis, SP_CH_SY, 0.75, 1.35, SP_GROUP_SHAPE);
    sp_gen_param(&g, pelvis, SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(&g, tail_base, SP_CH_RZ, -0.5, 0.5, SP_GROUP_POSE);
    sp_gen_param(&g, tail_base, SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(&g, chest, SP_CH_RZ, -0.4, 0.4, SP_GROUP_POSE);
    sp_gen_param(&g, chest, SP_CH_SX, 0.7, 1.45, SP_GROUP_SHAPE);
    sp_gen_param(&g, chest, SP_CH_SY, 0.75, 1.35, SP_GROUP_SHAPE);
    sp_gen_param(&g, shoulders, SP_CH_RZ, -0.45, 0.45, SP_GROUP_POSE);
    sp_gen_param(&g, shoulders, SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(&g, neck_base, SP_CH_RZ, -0.6, 0.6, SP_GROUP_POSE);
    sp_gen_param(&g, neck_base, SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(&g, belly, SP_CH_RZ, -0.3, 0.3, SP_GROUP_POSE);
    sp_gen_param(&g, belly, SP_CH_S, 0.75, 1.4, SP_GROUP_SHAPE);

    // Skin along the body, in path order (tail end first).
    sp_gen_chain ch = {0};
    const int owner[OWNERS] = {tail_base, pelvis, lumbar, torso, chest, shoulders, neck_base};
    for (int k = 0; k < OWNERS; ++k)
        sp_gen_chain_add(&ch, owner[k], k_cut[k] * L, 0.5 * L);

    sp_gen_mesh m = {0};
    int first = sp_gen_tube(&m, &(sp_gen_tube_desc){.path = &body,
                                                    .rings = 150,
                                                    .segments = 56,
                                                    .profile = profile,
                                                    .bump = bump,
                                                    .color = color,
                                                    .chain = &ch,
                                                    .cap0_rings = 5,
                                                    .cap0_len = 0.6,
                                                    .cap1_rings = 5,
                                                    .cap1_len = 0.6});
    // The belly joint takes the lower middle of the body, fading out
    // smoothly in every direction, so that its scale swells the belly.
    sp_vec3 bc = g.pivot[belly];
    for (int i = first; i < m.vertex_count; ++i) {
        sp_vec3 p = {m.pos[3 * i], m.pos[3 * i + 1], m.pos[3 * i + 2]};
        double dx = (p.x - bc.x) / 0.75, dy = (p.y - (bc.y - 0.05)) / 0.42;
        double w = 0.85 * exp(-(dx * dx + dy * dy) * 1.6) * sp_gen_smoothstep(bc.y + 0.25, bc.y - 0.2, p.y);
        if (w < 0.02) continue;
        sp_gen_skin s = {0};
        for (int k = 0; k < m.skin[i].n; ++k)
            sp_gen_skin_add(&s, m.skin[i].joint[k], m.skin[i].w[k] * (1.0 - w));
        sp_gen_skin_add(&s, belly, w);
        m.skin[i] = s;
    }
    m.decorating = true;
    sp_dragon_spikes(&m, &(sp_dragon_spikes_desc){.path = &body,
                                                  .chain = &ch,
                                                  .profile = profile,
                                                  .s0 = 0.06 * L,
                                                  .s1 = 0.86 * L,
                                                  .path_s0 = 0.0,
                                                  .path_s1 = L,
                                                  .count = 12,
                                                  .height = 0.2,
                                                  .width = 0.075,
                                                  .lean = 0.55});

    // Sockets in torso rest space: where each part's attachment point goes.
    sp_vec3 T;
    sp_vec3 tail_end = sp_gen_path_at(&body, 0.0, &T);
    sp_vec3 neck_end = sp_gen_path_at(&body, L, &T);
    sp_vec3 wing_at = sp_gen_path_at(&body, 0.70 * L, &T);
    sp_vec3 front_at = sp_gen_path_at(&body, 0.74 * L, &T);
    sp_vec3 hind_at = sp_gen_path_at(&body, 0.2 * L, &T);
    sp_part_socket sockets[] = {socket_at("head", "neck_base", neck_end), socket_at("tail", "tail_base", tail_end),
                                socket_at("wings", "shoulders", sp_v3(wing_at.x, wing_at.y + 0.30, 0)),
                                socket_at("front_legs", "shoulders", sp_v3(front_at.x, front_at.y - 0.22, 0)),
                                socket_at("hind_legs", "pelvis", sp_v3(hind_at.x, hind_at.y - 0.25, 0))};
    sp_part part = {.category = "torso", .socket_count = 5, .sockets = sockets};

    // Breathing: the belly swells and the chest lifts, a slow 3 s loop.
    enum { KEYS = 25 };
    double swell[KEYS], sway[KEYS];
    sp_vec3 belly_s[KEYS], chest_s[KEYS];
    for (int k = 0; k < KEYS; ++k) {
        double ph = 2.0 * k_pi * k / (KEYS - 1);
        swell[k] = 0.5 - 0.5 * cos(ph);
        belly_s[k] = sp_v3(1.0 + 0.06 * swell[k], 1.0 + 0.06 * swell[k], 1.0 + 0.06 * swell[k]);
        chest_s[k] = sp_v3(1.0, 1.0 + 0.035 * swell[k], 1.0);
        sway[k] = 0.025 * sin(ph);
    }
    sp_gen_clip_begin(&g, "breathe", 3.0, KEYS);
    sp_gen_clip_scale(&g, belly, belly_s);
    sp_gen_clip_scale(&g, chest, chest_s);
    sp_gen_clip_rz(&g, lumbar, sway);

    sp_result r = sp_gen_save(&g, &m, &(sp_gen_save_desc){.part = &part, .name = "torso", .root_reach_view = true}, path, err);
    sp_gen_mesh_free(&m);
    sp_gen_path_free(&body);
    sp_gen_rig_free(&g);
    return r;
}
