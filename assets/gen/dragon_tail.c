// dragon_tail.c: the tail: a long tapering S-curve with dorsal spikes and a
// spade at the tip, on a chain of eight joints from the root (attached to
// the torso's tail socket) to the spade.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dragon.h"

static const double k_pi = 3.14159265358979323846;

enum { OWNERS = 8 };
// Where each joint's region starts along the tail (arc-length fractions).
static const double k_cut[OWNERS] = {0.0, 0.12, 0.25, 0.38, 0.51, 0.64, 0.77, 0.9};

static sp_gen_section profile(double u, void* user)
{
    (void)user;
    static const double r[][2] = {{0.0, 0.17}, {0.2, 0.14}, {0.5, 0.095}, {0.8, 0.055}, {1.0, 0.032}};
    double k = sp_gen_interp(r, 5, u);
    return (sp_gen_section){k * 1.05, k * 1.0, k * 0.9};
}

static double bump(double u, double a, void* user)
{
    (void)user, (void)u;
    return 1.0 + 0.06 * exp(-(1.0 - cos(a)) / 0.02);
}

static sp_gen_rgb color(double u, double a, sp_vec3 p, void* user)
{
    (void)user;
    return sp_dragon_scales(u, a, p, 0.8, 22.0);
}

// The spade: a thin leaf, widest a third of the way, to a point.
static sp_gen_section spade_profile(double u, void* user)
{
    (void)user;
    static const double w[][2] = {{0.0, 0.03}, {0.12, 0.11}, {0.32, 0.17}, {0.6, 0.11}, {1.0, 0.008}};
    double k = sp_gen_interp(w, 5, u);
    return (sp_gen_section){k, k, 0.025 + 0.01 * (1.0 - u)};
}

static sp_gen_rgb spade_color(double u, double a, sp_vec3 p, void* user)
{
    (void)user, (void)a, (void)p;
    return sp_gen_mix(sp_dragon_spike, sp_dragon_spike_tip, sp_gen_smoothstep(0.1, 0.9, u));
}

sp_result sp_dragon_tail(const char* path, sp_error* err)
{
    const sp_vec3 ctrl[] = {{0.0, 0.0, 0},   {-0.5, -0.07, 0}, {-1.0, -0.06, 0}, {-1.5, 0.05, 0},
                            {-1.95, 0.2, 0}, {-2.35, 0.36, 0}, {-2.62, 0.5, 0}};
    sp_gen_path tail;
    sp_gen_path_catmull(&tail, ctrl, 7, 48);
    double L = tail.length;

    static const char* names[OWNERS] = {"tail_root", "tail_1", "tail_2", "tail_3", "tail_4", "tail_5", "tail_6", "tail_tip"};
    sp_gen_rig g;
    sp_gen_rig_init(&g);
    int j[OWNERS];
    for (int k = 0; k < OWNERS; ++k) {
        sp_vec3 T;
        sp_vec3 at = sp_gen_path_at(&tail, k_cut[k] * L, &T);
        j[k] = sp_gen_joint(&g, names[k], k ? j[k - 1] : -1, at, atan2(T.y, T.x));
    }
    sp_dragon_root_params(&g, j[0]);
    sp_gen_param(&g, j[0], SP_CH_SY, 0.7, 1.4, SP_GROUP_SHAPE);
    for (int k = 1; k < OWNERS; ++k)
        sp_gen_param(&g, j[k], SP_CH_RZ, -0.5, 0.5, SP_GROUP_POSE);
    // Uniform scales along the chain: a per-axis scale would shear the
    // rotated joints below it into kinks. Per-axis only on the spade (a leaf).
    for (int k = 1; k < OWNERS; ++k)
        sp_gen_param(&g, j[k], SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
    sp_gen_param(&g, j[7], SP_CH_SX, 0.6, 1.6, SP_GROUP_SHAPE);

    sp_gen_chain ch = {0};
    for (int k = 0; k < OWNERS; ++k)
        sp_gen_chain_add(&ch, j[k], k_cut[k] * L, 0.5 * L);

    sp_gen_mesh m = {0};
    sp_gen_tube(&m, &(sp_gen_tube_desc){.path = &tail,
                                        .rings = 170,
                                        .side = {0, 0, -1}, // runs along -X: keep "up" up
                                        .segments = 40,
                                        .profile = profile,
                                        .bump = bump,
                                        .color = color,
                                        .chain = &ch,
                                        .cap0_rings = 4,
                                        .cap0_len = 0.5,
                                        .cap1_rings = 3,
                                        .cap1_len = 0.8});
    m.decorating = true;
    sp_dragon_spikes(&m, &(sp_dragon_spikes_desc){.path = &tail,
                                                  .chain = &ch,
                                                  .profile = profile,
                                                  .s0 = 0.03 * L,
                                                  .s1 = 0.8 * L,
                                                  .path_s0 = 0.0,
                                                  .path_s1 = L,
                                                  .count = 13,
                                                  .height = 0.15,
                                                  .width = 0.055,
                                                  .lean = 0.6,
                                                  .side = {0, 0, -1},
                                                  .falloff = 1.0});
    m.decorating = false;
    // The spade continues the tail's last direction, rigid to the tip joint.
    sp_vec3 T;
    sp_vec3 end = sp_gen_path_at(&tail, L, &T);
    sp_vec3 sp[2] = {sp_v3_sub(end, sp_v3_scale(T, 0.06)), sp_v3_add(end, sp_v3_scale(T, 0.42))};
    sp_gen_path spade;
    sp_gen_path_points(&spade, sp, 2);
    sp_gen_tube(&m, &(sp_gen_tube_desc){.path = &spade,
                                        .rings = 40,
                                        .side = {0, 0, -1},
                                        .segments = 24,
                                        .profile = spade_profile,
                                        .color = spade_color,
                                        .skin = sp_gen_skin_one(j[7]),
                                        .cap1_rings = 2,
                                        .cap1_len = 1.0});
    sp_gen_path_free(&spade);

    // Sway: a travelling wave down the tail, growing towards the tip.
    enum { KEYS = 33 };
    sp_gen_clip_begin(&g, "sway", 2.0, KEYS);
    for (int k = 1; k < OWNERS; ++k) {
        double a[KEYS];
        for (int q = 0; q < KEYS; ++q)
            a[q] = (0.05 + 0.025 * k) * sin(2.0 * k_pi * q / (KEYS - 1) - 0.75 * k);
        sp_gen_clip_rz(&g, j[k], a);
    }

    sp_part part = sp_dragon_attach_part("tail", "tail", "tail_root", g.pivot[j[0]]);
    sp_result r = sp_gen_save(&g, &m, &(sp_gen_save_desc){.part = &part, .name = "tail", .root_reach_view = true}, path, err);
    sp_gen_mesh_free(&m);
    sp_gen_path_free(&tail);
    sp_gen_rig_free(&g);
    return r;
}
