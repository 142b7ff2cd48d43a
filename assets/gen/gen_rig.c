// gen_rig.c: skeleton, parameters, clips and saving of generated parts.
#include "gen_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/derive.h"
#include "sp/outline.h"

void sp_gen_rig_init(sp_gen_rig* g)
{
    memset(g, 0, sizeof *g);
}

void sp_gen_rig_free(sp_gen_rig* g)
{
    sp_rig_free(&g->rig);
    free(g->pivot), free(g->angle);
    memset(g, 0, sizeof *g);
}

static sp_quat rot_z(double a)
{
    return sp_quat_axis_angle(sp_v3(0, 0, 1), a);
}

int sp_gen_joint(sp_gen_rig* g, const char* name, int parent, sp_vec3 pivot, double angle)
{
    sp_rig* r = &g->rig;
    int j = r->joint_count;
    r->joints = sp_gen_check_alloc(realloc(r->joints, sizeof(sp_joint) * (size_t)(j + 1)));
    g->pivot = sp_gen_check_alloc(realloc(g->pivot, sizeof(sp_vec3) * (size_t)(j + 1)));
    g->angle = sp_gen_check_alloc(realloc(g->angle, sizeof(double) * (size_t)(j + 1)));
    sp_joint* jt = &r->joints[j];
    memset(jt, 0, sizeof *jt);
    snprintf(jt->name, sizeof jt->name, "%s", name);
    jt->parent = parent;
    if (parent >= 0) {
        double pa = g->angle[parent];
        jt->rest_t = sp_quat_rotate(rot_z(-pa), sp_v3_sub(pivot, g->pivot[parent]));
        jt->rest_r = rot_z(angle - pa);
    } else {
        jt->rest_t = pivot;
        jt->rest_r = rot_z(angle);
    }
    jt->rest_s = sp_v3(1, 1, 1);
    sp_mat4 world = sp_mat4_trs(pivot, rot_z(angle), sp_v3(1, 1, 1));
    sp_mat4_inverse(&world, &jt->inverse_bind);
    g->pivot[j] = pivot;
    g->angle[j] = angle;
    r->joint_count = j + 1;
    return j;
}

void sp_gen_param(sp_gen_rig* g, int joint, sp_channel ch, double min, double max, sp_group group)
{
    if (sp_rig_add_param(&g->rig, joint, ch, min, max, group) < 0) {
        fprintf(stderr, "sp-assetgen: cannot add parameter %d on joint %d\n", (int)ch, joint);
        exit(1);
    }
}

// ---- clips ---------------------------------------------------------------

void sp_gen_clip_begin(sp_gen_rig* g, const char* name, double duration_s, int keys)
{
    sp_rig* r = &g->rig;
    r->animations = sp_gen_check_alloc(realloc(r->animations, sizeof(sp_animation) * (size_t)(r->animation_count + 1)));
    sp_animation* a = &r->animations[r->animation_count++];
    memset(a, 0, sizeof *a);
    snprintf(a->name, sizeof a->name, "%s", name);
    a->duration_s = duration_s;
    g->clip_keys = keys;
    g->clip_s = duration_s;
}

static sp_anim_channel* clip_channel(sp_gen_rig* g, int joint, sp_anim_path path)
{
    sp_animation* a = &g->rig.animations[g->rig.animation_count - 1];
    a->channels = sp_gen_check_alloc(realloc(a->channels, sizeof(sp_anim_channel) * (size_t)(a->channel_count + 1)));
    sp_anim_channel* c = &a->channels[a->channel_count++];
    memset(c, 0, sizeof *c);
    c->joint = joint;
    c->path = path;
    c->interp = SP_INTERP_LINEAR;
    c->key_count = g->clip_keys;
    c->times = sp_gen_check_alloc(malloc(sizeof(float) * (size_t)g->clip_keys));
    c->values = sp_gen_check_alloc(malloc(sizeof(float) * 4 * (size_t)g->clip_keys));
    for (int k = 0; k < g->clip_keys; ++k)
        c->times[k] = (float)(g->clip_s * k / (g->clip_keys - 1));
    return c;
}

void sp_gen_clip_rz(sp_gen_rig* g, int joint, const double* angles)
{
    sp_anim_channel* c = clip_channel(g, joint, SP_ANIM_ROTATION);
    sp_quat rest = g->rig.joints[joint].rest_r;
    for (int k = 0; k < c->key_count; ++k) {
        sp_quat q = sp_quat_norm(sp_quat_mul(rest, rot_z(angles[k])));
        c->values[4 * k] = (float)q.x, c->values[4 * k + 1] = (float)q.y;
        c->values[4 * k + 2] = (float)q.z, c->values[4 * k + 3] = (float)q.w;
    }
}

void sp_gen_clip_scale(sp_gen_rig* g, int joint, const sp_vec3* factors)
{
    sp_anim_channel* c = clip_channel(g, joint, SP_ANIM_SCALE);
    sp_vec3 rest = g->rig.joints[joint].rest_s;
    for (int k = 0; k < c->key_count; ++k) {
        c->values[3 * k] = (float)(rest.x * factors[k].x);
        c->values[3 * k + 1] = (float)(rest.y * factors[k].y);
        c->values[3 * k + 2] = (float)(rest.z * factors[k].z);
    }
}

void sp_gen_clip_translate(sp_gen_rig* g, int joint, const sp_vec3* offsets)
{
    sp_anim_channel* c = clip_channel(g, joint, SP_ANIM_TRANSLATION);
    sp_vec3 rest = g->rig.joints[joint].rest_t;
    for (int k = 0; k < c->key_count; ++k) {
        c->values[3 * k] = (float)(rest.x + offsets[k].x);
        c->values[3 * k + 1] = (float)(rest.y + offsets[k].y);
        c->values[3 * k + 2] = (float)(rest.z + offsets[k].z);
    }
}

// ---- saving --------------------------------------------------------------

sp_camera sp_gen_side_camera(sp_vec3 lo, sp_vec3 hi, double margin)
{
    return sp_part_side_camera(lo, hi, margin);
}

sp_result sp_gen_outline(const sp_gen_mesh* mesh, const sp_camera* cam, int points, int depth_passes, sp_abstraction* out,
                         sp_error* err)
{
    size_t nv = (size_t)mesh->vertex_count;
    uint16_t* joints = sp_gen_check_alloc(calloc(SP_GEN_SKIN_MAX * nv + 1, sizeof(uint16_t)));
    double* weights = sp_gen_check_alloc(calloc(SP_GEN_SKIN_MAX * nv + 1, sizeof(double)));
    for (size_t i = 0; i < nv; ++i)
        for (int k = 0; k < mesh->skin[i].n; ++k) {
            joints[SP_GEN_SKIN_MAX * i + (size_t)k] = (uint16_t)mesh->skin[i].joint[k];
            weights[SP_GEN_SKIN_MAX * i + (size_t)k] = mesh->skin[i].w[k];
        }
    sp_outline_desc d = {.vertex_count = mesh->vertex_count,
                         .positions = mesh->pos,
                         .influences = SP_GEN_SKIN_MAX,
                         .joints = joints,
                         .weights = weights,
                         .triangle_count = mesh->tri_count,
                         .triangles = mesh->tris,
                         .skip_vertex = mesh->deco_vertex,
                         .skip_triangle = mesh->deco_tri,
                         .camera = cam,
                         .points = points,
                         .depth_passes = depth_passes};
    sp_result r = sp_outline_trace(&d, out, NULL, err);
    free(joints), free(weights);
    return r;
}

// sRGB to linear (the glTF COLOR_0 convention).
static float to_linear(double c)
{
    c = sp_gen_clamp(c, 0.0, 1.0);
    return (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
}

sp_result sp_gen_save(sp_gen_rig* g, const sp_gen_mesh* mesh, const sp_gen_save_desc* d, const char* path, sp_error* err)
{
    sp_rig* r = &g->rig;
    const char* what = d->name ? d->name : path;
    size_t nv = (size_t)mesh->vertex_count;
    r->vertex_count = mesh->vertex_count;
    r->rest = sp_gen_check_alloc(malloc(sizeof(double) * 3 * nv));
    r->joints4 = sp_gen_check_alloc(malloc(sizeof(uint16_t) * 4 * nv));
    r->weights4 = sp_gen_check_alloc(malloc(sizeof(float) * 4 * nv));
    memcpy(r->rest, mesh->pos, sizeof(double) * 3 * nv);
    for (size_t i = 0; i < nv; ++i)
        sp_gen_skin_pack(&mesh->skin[i], r->joints4 + 4 * i, r->weights4 + 4 * i);
    r->triangle_count = mesh->tri_count;
    r->triangles = sp_gen_check_alloc(malloc(sizeof(uint32_t) * 3 * (size_t)mesh->tri_count));
    memcpy(r->triangles, mesh->tris, sizeof(uint32_t) * 3 * (size_t)mesh->tri_count);

    sp_vec3 lo, hi;
    sp_bounds(mesh->pos, mesh->vertex_count, &lo, &hi);
    sp_camera cam = sp_gen_side_camera(lo, hi, d->frame_margin > 0 ? d->frame_margin : 1.35);
    if (d->root_reach_view) {
        double reach = 0.5 * fmax(cam.width, cam.height) / cam.scale;
        for (int q = 0; q < r->param_count; ++q)
            if (r->params[q].joint == 0 && (r->params[q].channel == SP_CH_TX || r->params[q].channel == SP_CH_TY))
                r->params[q].min = -reach, r->params[q].max = reach;
    }
    int na = d->abstraction_count + (d->no_outline ? 0 : 1);
    r->abstractions = sp_gen_check_alloc(calloc((size_t)na + 1, sizeof(sp_abstraction)));
    for (int a = 0; a < d->abstraction_count; ++a) {
        r->abstractions[r->abstraction_count++] = d->abstractions[a];
        memset(&d->abstractions[a], 0, sizeof d->abstractions[a]);
    }
    if (!d->no_outline) {
        sp_abstraction ab;
        sp_error e = {0};
        if (sp_gen_outline(mesh, &cam, d->outline_points > 0 ? d->outline_points : 150, 0, &ab, &e) != SP_OK)
            return sp_fail(err, SP_ERR_INVALID, "%s: %s", what, e.text);
        r->abstractions[r->abstraction_count++] = ab;
    }

    int renorm = 0;
    sp_result res = sp_rig_finalize(r, what, &renorm, err);
    if (res != SP_OK) return res;
    if (renorm) return sp_fail(err, SP_ERR_INTERNAL, "%s: %d vertices had unnormalised weights", what, renorm);
    sp_rig copy;
    if (sp_rig_clone(r, &copy) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    sp_character ch;
    res = sp_character_from_rig(&copy, &ch, err);
    if (res != SP_OK) return res;
    for (size_t i = 0; i < nv; ++i) {
        ch.colors[4 * i] = to_linear(mesh->color[i].r);
        ch.colors[4 * i + 1] = to_linear(mesh->color[i].g);
        ch.colors[4 * i + 2] = to_linear(mesh->color[i].b);
        ch.colors[4 * i + 3] = 1.0f;
    }
    ch.camera = cam;
    ch.has_camera = true;
    if (d->part) {
        ch.has_part = true;
        if ((res = sp_part_copy(d->part, &ch.part, err)) != SP_OK) {
            sp_character_free(&ch);
            return res;
        }
    }
    res = sp_gltf_save(&ch, NULL, path, err);
    sp_character_free(&ch);
    return res;
}
