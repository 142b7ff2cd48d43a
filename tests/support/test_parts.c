// test_parts.c: the kiosk pipeline test's parts; see test_parts.h.
#include "test_parts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fixtures.h"
#include "sp/gltf.h"
#include "test.h"

#define PI 3.14159265358979323846

const test_part_spec k_test_parts[TEST_PART_COUNT] = {
    {"torso_t",
     "torso",
     4,
     1.0,
     0.0,
     0.0,
     0.55,
     0.45,
     2.0,
     0.06,
     {0.35f, 0.55f, 0.3f},
     "{\"category\": \"torso\", \"sockets\": ["
     "{\"name\": \"neck\", \"joint\": \"j3\", \"accepts\": [\"head\"]},"
     "{\"name\": \"tail\", \"joint\": \"j0\", \"accepts\": [\"tail\"]},"
     "{\"name\": \"back\", \"joint\": \"j1\", \"position\": [1.0, 0.5, 0.0], \"accepts\": [\"wings\"]},"
     "{\"name\": \"hips\", \"joint\": \"j1\", \"position\": [0.8, -0.5, 0.0], \"accepts\": [\"legs\"]}]}"},
    {"tail_t",
     "tail",
     6,
     0.6,
     PI,
     -0.25,
     0.22,
     0.03,
     1.0,
     0.3,
     {0.3f, 0.5f, 0.3f},
     "{\"category\": \"tail\", \"attach\": {\"joint\": \"j0\"}}"},
    {"head_t",
     "head",
     3,
     0.35,
     0.5,
     -0.5,
     0.3,
     0.32,
     0.8,
     0.25,
     {0.4f, 0.6f, 0.35f},
     "{\"category\": \"head\", \"attach\": \"j0\"}"},
    {"wings_t", "wings", 4, 0.7, 1.2, -0.7, 0.06, 0.35, 0.5, 0.4, {0.7f, 0.3f, 0.25f}, "{\"category\": \"wings\"}"},
    {"legs_t",
     "legs",
     4,
     0.5,
     -PI / 2,
     0.25,
     0.12,
     0.12,
     0.0,
     0.0,
     {0.3f, 0.45f, 0.25f},
     "{\"category\": \"legs\", \"attach\": {\"joint\": \"j0\"}}"},
};
const test_part_spec k_test_part_horns = {
    "horns_t", "horns", 5, 0.3, PI / 2, 0.9, 0.12, 0.01, 0.0, 0.0, {0.8f, 0.8f, 0.7f}, "{\"category\": \"horns\"}"};

void test_part_rig(const test_part_spec* s, bool flat, sp_rig* rig)
{
    memset(rig, 0, sizeof *rig);
    int nj = s->joints, bones = nj - 1, rings = 6, rv = 10;
    rig->joint_count = nj;
    rig->joints = calloc((size_t)nj, sizeof(sp_joint));
    sp_mat4* world = malloc(sizeof(sp_mat4) * (size_t)nj);
    for (int j = 0; j < nj; ++j) {
        sp_joint* jt = &rig->joints[j];
        snprintf(jt->name, sizeof jt->name, "j%d", j);
        jt->parent = j - 1;
        jt->rest_t = j == 0 ? sp_v3(0, 0, 0) : sp_v3(s->bone_len, 0, 0);
        jt->rest_r = sp_quat_axis_angle(sp_v3(0, 0, 1), j == 0 ? s->angle0 : s->bend);
        jt->rest_s = sp_v3(1, 1, 1);
        sp_mat4 local = sp_mat4_trs(jt->rest_t, jt->rest_r, jt->rest_s);
        world[j] = j == 0 ? local : sp_mat4_mul(&world[j - 1], &local);
        sp_mat4_inverse(&world[j], &jt->inverse_bind);
    }
    for (int j = 0; j < nj; ++j) {
        if (j == 0) {
            sp_rig_add_param(rig, j, SP_CH_RZ, -0.8, 0.8, SP_GROUP_POSE);
            sp_rig_add_param(rig, j, SP_CH_TX, -3, 3, SP_GROUP_POSE);
            sp_rig_add_param(rig, j, SP_CH_TY, -3, 3, SP_GROUP_POSE);
            sp_rig_add_param(rig, j, SP_CH_S, 0.5, 2.0, SP_GROUP_SHAPE);
        } else if (j < nj - 1) {
            sp_rig_add_param(rig, j, SP_CH_RZ, -0.9, 0.9, SP_GROUP_POSE);
            sp_rig_add_param(rig, j, SP_CH_S, 0.7, 1.4, SP_GROUP_SHAPE);
        }
    }
    sp_fixture_tube_alloc(rig, bones, rings, rv);
    // Outline: one side root -> tip, the other tip -> root (a closed loop).
    int side = bones * (rings - 1) + 1, np = 2 * side;
    sp_abstraction ab = sp_fixture_outline(np);
    int v = 0, t = 0;
    for (int b = 0; b < bones; ++b) {
        sp_vec3 a = sp_mat4_translation(&world[b]), c = sp_mat4_translation(&world[b + 1]);
        sp_vec3 dir = sp_v3_sub(c, a);
        sp_vec3 n1 = sp_v3_norm(sp_v3(-dir.y, dir.x, 0)), n2 = sp_v3(0, 0, 1);
        int base = v;
        for (int r = 0; r < rings; ++r) {
            double u = (double)r / (rings - 1), ug = (b + u) / bones;
            double radius = s->r0 + (s->r1 - s->r0) * ug;
            sp_vec3 centre = sp_v3_add(a, sp_v3_scale(dir, u));
            float w0 = (float)(1.0 - 0.5 * u), w1 = (float)(0.5 * u);
            for (int k = 0; k < rv; ++k) {
                double ang = 2.0 * PI * k / rv;
                double rm = flat ? 0.0 : radius;
                sp_vec3 p = sp_v3_add(centre, sp_v3_add(sp_v3_scale(n1, rm * cos(ang)), sp_v3_scale(n2, rm * sin(ang))));
                rig->rest[3 * v] = p.x, rig->rest[3 * v + 1] = p.y, rig->rest[3 * v + 2] = p.z;
                rig->joints4[4 * v] = (uint16_t)b, rig->joints4[4 * v + 1] = (uint16_t)(b + 1);
                rig->weights4[4 * v] = w0, rig->weights4[4 * v + 1] = w1;
                ++v;
            }
            // Outline points at this ring (the first ring of later bones repeats the previous tip ring).
            if (r == 0 && b > 0) continue;
            int i = b * (rings - 1) + r, k2 = np - 1 - i;
            sp_vec3 l = sp_v3_add(centre, sp_v3_scale(n1, radius)), rr = sp_v3_sub(centre, sp_v3_scale(n1, radius));
            ab.rest[3 * i] = l.x, ab.rest[3 * i + 1] = l.y, ab.rest[3 * i + 2] = 0;
            ab.rest[3 * k2] = rr.x, ab.rest[3 * k2 + 1] = rr.y, ab.rest[3 * k2 + 2] = 0;
            ab.joints[4 * i] = ab.joints[4 * k2] = (uint16_t)b;
            ab.joints[4 * i + 1] = ab.joints[4 * k2 + 1] = (uint16_t)(b + 1);
            ab.weights[4 * i] = ab.weights[4 * k2] = w0;
            ab.weights[4 * i + 1] = ab.weights[4 * k2 + 1] = w1;
        }
        sp_fixture_tube_triangles(rig, base, rings, rv, &t);
    }
    rig->abstraction_count = 1;
    rig->abstractions = malloc(sizeof(sp_abstraction));
    rig->abstractions[0] = ab;
    if (s->clip_s > 0) {
        // A sway of every joint but the root and the tip: rest, +sway, rest, -sway, rest.
        rig->animation_count = 1;
        rig->animations = calloc(1, sizeof(sp_animation));
        sp_animation* an = &rig->animations[0];
        snprintf(an->name, sizeof an->name, "sway");
        an->duration_s = s->clip_s;
        an->channels = calloc((size_t)nj, sizeof(sp_anim_channel));
        for (int j = 1; j < nj - 1; ++j) {
            sp_anim_channel* ch = &an->channels[an->channel_count++];
            ch->joint = j;
            ch->path = SP_ANIM_ROTATION;
            ch->interp = SP_INTERP_LINEAR;
            ch->key_count = 5;
            ch->times = malloc(sizeof(float) * 5);
            ch->values = malloc(sizeof(float) * 20);
            // Not at rest at the first key (as the shipped clips, whose phase
            // lags along a chain): the animation test tells offsets from rest
            // apart from offsets from the first frame.
            const double off[5] = {0.5, 1, -0.5, -1, 0.5};
            for (int k = 0; k < 5; ++k) {
                ch->times[k] = (float)(s->clip_s * k / 4);
                sp_quat q = sp_quat_mul(rig->joints[j].rest_r, sp_quat_axis_angle(sp_v3(0, 0, 1), s->sway * off[k]));
                ch->values[4 * k] = (float)q.x, ch->values[4 * k + 1] = (float)q.y, ch->values[4 * k + 2] = (float)q.z,
                               ch->values[4 * k + 3] = (float)q.w;
            }
        }
    }
    free(world);
    sp_error err = {0};
    sp_result r = sp_rig_finalize(rig, s->name, NULL, &err);
    if (r != SP_OK) fprintf(stderr, "  %s: %s\n", s->name, err.text);
    ENSURE(r == SP_OK);
}

void test_part_write(const test_part_spec* s, bool flat, const char* path)
{
    sp_rig rig;
    test_part_rig(s, flat, &rig);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_character_from_rig(&rig, &ch, &err) == SP_OK);
    for (int i = 0; i < ch.rig.vertex_count; ++i)
        for (int c = 0; c < 3; ++c)
            ch.colors[4 * i + c] = s->color[c];
    ENSURE(sp_part_parse_json(s->extras, s->name, &ch.part, &err) == SP_OK);
    ch.has_part = true;
    // Seen from the front (-Z), where the outline lies: the default view could pick -X for a fat, short tube.
    sp_vec3 lo, hi;
    sp_bounds(ch.rig.rest, ch.rig.vertex_count, &lo, &hi);
    ch.camera = sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, lo, hi, sp_v3(0, 0, -1), sp_v3(0, 1, 0), 640, 480);
    ch.has_camera = true;
    sp_result r = sp_gltf_save(&ch, NULL, path, &err);
    if (r != SP_OK) fprintf(stderr, "  %s\n", err.text);
    ENSURE(r == SP_OK);
    sp_character_free(&ch);
}
