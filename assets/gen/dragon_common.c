// dragon_common.c: the dragon palette, scaly skin, root placement, spikes.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dragon.h"

const sp_gen_rgb sp_dragon_back = {0.09, 0.27, 0.15};
const sp_gen_rgb sp_dragon_flank = {0.25, 0.53, 0.25};
const sp_gen_rgb sp_dragon_belly = {0.91, 0.80, 0.50};
const sp_gen_rgb sp_dragon_membrane = {0.36, 0.11, 0.10};
const sp_gen_rgb sp_dragon_membrane_vein = {0.55, 0.22, 0.15};
const sp_gen_rgb sp_dragon_horn = {0.94, 0.90, 0.77};
const sp_gen_rgb sp_dragon_horn_tip = {0.40, 0.33, 0.26};
const sp_gen_rgb sp_dragon_spike = {0.92, 0.62, 0.20};
const sp_gen_rgb sp_dragon_spike_tip = {0.55, 0.22, 0.08};
const sp_gen_rgb sp_dragon_eye = {1.00, 0.80, 0.10};
const sp_gen_rgb sp_dragon_pupil = {0.04, 0.03, 0.02};
const sp_gen_rgb sp_dragon_mouth = {0.50, 0.10, 0.10};
const sp_gen_rgb sp_dragon_tooth = {0.97, 0.95, 0.88};

static const double k_pi = 3.14159265358979323846;

sp_gen_rgb sp_dragon_scales(double u, double a, sp_vec3 p, double belly, double plates)
{
    double c = cos(a);
    sp_gen_rgb col = sp_gen_mix(sp_dragon_flank, sp_dragon_back, sp_gen_smoothstep(-0.1, 0.85, c));
    if (belly > 0) {
        // The belly spans the lower part of the section; `belly` widens it.
        double edge = -0.9 + 0.42 * belly;
        double b = sp_gen_smoothstep(edge + 0.12, edge - 0.12, c);
        sp_gen_rgb bc = sp_dragon_belly;
        if (plates > 0) {
            double ph = u * plates - floor(u * plates);
            double groove = sp_gen_smoothstep(0.78, 0.98, ph) * (1.0 - sp_gen_smoothstep(0.98, 1.0, ph));
            bc = sp_gen_shade(bc, 1.0 - 0.22 * groove);
        }
        col = sp_gen_mix(col, bc, b);
    }
    // Scales: a fine mottle (value noise at two scales) over the green.
    double n = 0.6 * sp_gen_noise2(p.x * 22.0 + p.z * 7.0, p.y * 22.0 - p.z * 5.0, 11u) +
               0.4 * sp_gen_noise2(p.x * 7.0 - p.z * 3.0, p.y * 7.0 + p.z * 9.0, 23u);
    return sp_gen_shade(col, 0.82 + 0.32 * n);
}

void sp_dragon_root_params(sp_gen_rig* g, int root)
{
    // Translation bounds are placeholders until sp_gen_save sets them to the
    // sketch view (root_reach_view).
    sp_gen_param(g, root, SP_CH_RZ, -1.0, 1.0, SP_GROUP_POSE);
    sp_gen_param(g, root, SP_CH_TX, -1.0, 1.0, SP_GROUP_POSE);
    sp_gen_param(g, root, SP_CH_TY, -1.0, 1.0, SP_GROUP_POSE);
    sp_gen_param(g, root, SP_CH_S, 0.5, 2.0, SP_GROUP_SHAPE);
}

sp_vec3 sp_dragon_part_position(sp_vec3 v)
{
    return sp_v3(round(v.x * 1e4) / 1e4, round(v.y * 1e4) / 1e4, round(v.z * 1e4) / 1e4);
}

sp_part sp_dragon_attach_part(const char* category, const char* socket, const char* joint, sp_vec3 position)
{
    sp_part p = {.has_attach = true};
    snprintf(p.category, sizeof p.category, "%s", category);
    snprintf(p.attach.socket, sizeof p.attach.socket, "%s", socket);
    snprintf(p.attach.joint, sizeof p.attach.joint, "%s", joint);
    p.attach.has_position = true;
    p.attach.position = sp_dragon_part_position(position);
    return p;
}

void sp_dragon_spikes(sp_gen_mesh* m, const sp_dragon_spikes_desc* d)
{
    for (int i = 0; i < d->count; ++i) {
        double f = d->count > 1 ? (double)i / (d->count - 1) : 0.5;
        double s = d->s0 + (d->s1 - d->s0) * f;
        double u = (s - d->path_s0) / (d->path_s1 - d->path_s0);
        sp_vec3 T;
        sp_vec3 c = sp_gen_path_at(d->path, s, &T);
        sp_vec3 B = sp_v3_len(d->side) > 0 ? sp_v3_norm(d->side) : sp_v3(0, 0, 1);
        sp_vec3 N = sp_v3_norm(sp_v3_cross(B, T));
        sp_gen_section sec = d->profile(u, d->user);
        double h =
            d->falloff > 0 ? d->height * (1.0 - d->falloff * 0.85 * f) : d->height * (0.4 + 0.6 * sin(k_pi * (0.15 + 0.7 * f)));
        double w = d->width * (0.5 + 0.5 * h / d->height);
        sp_vec3 base = sp_v3_add(c, sp_v3_scale(N, sec.up * 0.82));
        sp_vec3 dir = sp_v3_sub(sp_v3_scale(N, cos(d->lean)), sp_v3_scale(T, sin(d->lean)));
        sp_vec3 tip = sp_v3_add(base, sp_v3_scale(dir, h + 0.18 * sec.up));
        sp_vec3 bend = sp_v3_add(sp_v3_scale(sp_v3_add(base, tip), 0.5), sp_v3_scale(T, -0.12 * h));
        sp_gen_skin sk = sp_gen_chain_skin(d->chain, s);
        sp_gen_cone(m, &(sp_gen_cone_desc){.base = base,
                                           .bend = bend,
                                           .tip = tip,
                                           .base_radius = w,
                                           .tip_radius = 0.08 * w,
                                           .taper = 1.2,
                                           .flat = 0.4,
                                           .rings = 8,
                                           .segments = 12,
                                           .base_color = sp_dragon_spike,
                                           .tip_color = sp_dragon_spike_tip,
                                           .skin = sk});
    }
}
