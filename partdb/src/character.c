// character.c: the C half of the glTF import: our extras (sp_dofs, sp_rest,
// sp_abstraction, sp_pose, sp_part), default DOFs, finalising, warnings,
// the default camera, and the character's lifetime.
#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_internal.h"

void sp_character_free(sp_character* ch)
{
    if (!ch) return;
    sp_rig_free(&ch->rig);
    free(ch->pose);
    free(ch->colors);
    sp_part_free(&ch->part);
    free(ch->warnings);
    memset(ch, 0, sizeof *ch);
}

sp_result sp_character_clone(const sp_character* src, sp_character* dst, sp_error* err)
{
    memset(dst, 0, sizeof *dst);
    if (sp_rig_clone(&src->rig, &dst->rig) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "character: out of memory");
    size_t np = (size_t)src->rig.param_count, nc = 4 * (size_t)src->rig.vertex_count;
    dst->pose = src->pose ? malloc(sizeof(double) * (np + 1)) : NULL;
    dst->colors = src->colors ? malloc(sizeof(float) * (nc + 1)) : NULL;
    dst->warnings = src->warning_count > 0 ? malloc(sizeof *src->warnings * (size_t)src->warning_count) : NULL;
    bool ok = (!src->pose || dst->pose) && (!src->colors || dst->colors) && (src->warning_count == 0 || dst->warnings) &&
              (!src->has_part || sp_part_copy(&src->part, &dst->part, NULL) == SP_OK);
    if (!ok) {
        sp_character_free(dst);
        return sp_fail(err, SP_ERR_NO_MEMORY, "character: out of memory");
    }
    if (src->pose) memcpy(dst->pose, src->pose, sizeof(double) * np);
    if (src->colors) memcpy(dst->colors, src->colors, sizeof(float) * nc);
    if (src->warning_count > 0) memcpy(dst->warnings, src->warnings, sizeof *src->warnings * (size_t)src->warning_count);
    dst->warning_count = src->warning_count;
    dst->has_camera = src->has_camera, dst->camera = src->camera;
    dst->has_part = src->has_part;
    dst->derived_abstraction = src->derived_abstraction, dst->derived_dofs = src->derived_dofs;
    dst->mesh_skins = src->mesh_skins;
    dst->textured = src->textured;
    return SP_OK;
}

void sp_character_warn(sp_character* ch, const char* fmt, ...)
{
    char(*grown)[SP_WARNING_MAX] = realloc(ch->warnings, sizeof *ch->warnings * (size_t)(ch->warning_count + 1));
    if (!grown) return; // a lost warning is not worth failing a load for
    ch->warnings = grown;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ch->warnings[ch->warning_count], SP_WARNING_MAX, fmt, ap);
    va_end(ap);
    sp_text_escape_controls(ch->warnings[ch->warning_count], SP_WARNING_MAX); // one line, as sp_fail's
    ++ch->warning_count;
}

// The front orthographic view framing the skinned vertices (or, without a
// mesh, the joints) at the default parameters.
static sp_result default_camera(sp_character* ch)
{
    const sp_rig* rig = &ch->rig;
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    double* p = malloc(sizeof(double) * (size_t)(rig->param_count + 1));
    int n = rig->vertex_count > 0 ? rig->vertex_count : rig->joint_count;
    double* xyz = malloc(sizeof(double) * 3 * (size_t)n);
    if (!ev || !p || !xyz) {
        sp_rig_eval_destroy(ev);
        free(p), free(xyz);
        return SP_ERR_NO_MEMORY;
    }
    sp_rig_defaults(rig, p);
    sp_rig_eval_update(ev, p, false);
    if (rig->vertex_count > 0) {
        sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    } else {
        const sp_mat4* g = sp_rig_eval_world(ev);
        for (int j = 0; j < n; ++j) {
            sp_vec3 t = sp_mat4_translation(&g[j]);
            xyz[3 * j] = t.x, xyz[3 * j + 1] = t.y, xyz[3 * j + 2] = t.z;
        }
    }
    ch->camera = sp_camera_default_view(xyz, n, SP_GLTF_CANVAS_W, SP_GLTF_CANVAS_H);
    sp_rig_eval_destroy(ev);
    free(p), free(xyz);
    return SP_OK;
}

sp_result sp_character_from_rig(sp_rig* rig, sp_character* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    out->rig = *rig;
    memset(rig, 0, sizeof *rig);
    size_t nv = (size_t)out->rig.vertex_count;
    out->pose = malloc(sizeof(double) * (size_t)(out->rig.param_count + 1));
    out->colors = malloc(sizeof(float) * 4 * (nv + 1));
    if (!out->pose || !out->colors || default_camera(out) != SP_OK) {
        sp_character_free(out);
        return sp_fail(err, SP_ERR_NO_MEMORY, "character: out of memory");
    }
    sp_rig_defaults(&out->rig, out->pose);
    for (size_t i = 0; i < 4 * nv; ++i)
        out->colors[i] = (i % 4 == 3) ? 1.0f : SP_GLTF_TEXTURE_GREY;
    return SP_OK;
}

// ---- transforms ---------------------------------------------------------

// Column-major 3x3, orthonormal.
static sp_quat quat_from_rotation(const double m[9])
{
    double m00 = m[0], m11 = m[4], m22 = m[8];
    double tr = m00 + m11 + m22;
    sp_quat q;
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        q = (sp_quat){(m[5] - m[7]) / s, (m[6] - m[2]) / s, (m[1] - m[3]) / s, 0.25 * s};
    } else if (m00 > m11 && m00 > m22) {
        double s = sqrt(1.0 + m00 - m11 - m22) * 2;
        q = (sp_quat){0.25 * s, (m[3] + m[1]) / s, (m[6] + m[2]) / s, (m[5] - m[7]) / s};
    } else if (m11 > m22) {
        double s = sqrt(1.0 + m11 - m00 - m22) * 2;
        q = (sp_quat){(m[3] + m[1]) / s, 0.25 * s, (m[7] + m[5]) / s, (m[6] - m[2]) / s};
    } else {
        double s = sqrt(1.0 + m22 - m00 - m11) * 2;
        q = (sp_quat){(m[6] + m[2]) / s, (m[7] + m[5]) / s, 0.25 * s, (m[1] - m[3]) / s};
    }
    return sp_quat_norm(q);
}

void sp_gltf_decompose(const sp_mat4* a, sp_vec3* t, sp_quat* r, sp_vec3* s)
{
    *t = sp_mat4_translation(a);
    sp_vec3 c[3];
    for (int k = 0; k < 3; ++k)
        c[k] = sp_v3(a->m[4 * k], a->m[4 * k + 1], a->m[4 * k + 2]);
    double sx = sp_v3_len(c[0]), sy = sp_v3_len(c[1]), sz = sp_v3_len(c[2]);
    if (sp_v3_dot(sp_v3_cross(c[0], c[1]), c[2]) < 0) sx = -sx;
    *s = sp_v3(sx, sy, sz);
    double m[9];
    double sc[3] = {sx, sy, sz};
    for (int k = 0; k < 3; ++k) {
        double inv = sc[k] != 0 ? 1.0 / sc[k] : 0.0;
        m[3 * k] = c[k].x * inv, m[3 * k + 1] = c[k].y * inv, m[3 * k + 2] = c[k].z * inv;
    }
    *r = quat_from_rotation(m);
}

// ---- extras -------------------------------------------------------------

// The largest bounds a channel may have besides a move's
// (SP_GLTF_MOVE_MAX): a turn (radians; a few turns is plenty) and a scale.
#define DOF_TURN_MAX 100.0
#define DOF_SCALE_MAX 1e3

static bool json_number(const cJSON* o, const char* key, double* v)
{
    const cJSON* it = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsNumber(it)) return false;
    *v = it->valuedouble;
    return true;
}

// Reads n finite numbers from a JSON array.
static bool json_vec(const cJSON* a, double* v, int n)
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return false;
    int i = 0;
    const cJSON* it;
    cJSON_ArrayForEach(it, a)
    {
        if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble)) return false;
        v[i++] = it->valuedouble;
    }
    return true;
}

sp_result sp_gltf_joint_extras(sp_rig* rig, int joint, const char* json, bool* has_dofs, bool* has_rest, const char* what,
                               sp_error* err)
{
    *has_dofs = *has_rest = false;
    if (!json || !*json) return SP_OK;
    cJSON* root = cJSON_Parse(json);
    if (!root) return sp_fail(err, SP_ERR_PARSE, "%s: joint '%s': extras are not valid JSON", what, rig->joints[joint].name);
    sp_result r = SP_OK;
    const char* jn = rig->joints[joint].name;
    const cJSON* dofs = cJSON_GetObjectItemCaseSensitive(root, "sp_dofs");
    if (cJSON_IsNull(dofs)) *has_dofs = true;
    // Why null counts as empty: JSON writers (tinygltf's among them) may
    // write an empty list as null.
    if (dofs && !cJSON_IsNull(dofs)) {
        *has_dofs = true;
        if (!cJSON_IsArray(dofs)) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': sp_dofs must be a list", what, jn);
            goto done;
        }
        const cJSON* d;
        cJSON_ArrayForEach(d, dofs)
        {
            const cJSON* chn = cJSON_GetObjectItemCaseSensitive(d, "channel");
            sp_channel c = cJSON_IsString(chn) ? sp_channel_parse(chn->valuestring) : SP_CH_COUNT;
            if (c == SP_CH_COUNT) {
                r = sp_fail(err, SP_ERR_INVALID,
                            "%s: joint '%s': sp_dofs entry without a known channel (rx|ry|rz|tx|ty|tz|sx|sy|sz|s)", what, jn);
                goto done;
            }
            const char* cn = sp_channel_name(c);
            double lo, hi;
            if (!json_number(d, "min", &lo) || !json_number(d, "max", &hi)) {
                r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': sp_dofs channel %s needs numeric min and max", what, jn, cn);
                goto done;
            }
            if (!isfinite(lo) || !isfinite(hi) || !(lo <= hi)) {
                r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': sp_dofs channel %s has invalid bounds [%g, %g]", what, jn, cn,
                            lo, hi);
                goto done;
            }
            if (sp_channel_is_scale(c) && !(lo > 0.0)) {
                r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': scale channel %s needs min > 0 (got %g)", what, jn, cn, lo);
                goto done;
            }
            // Bounds past any pose a part takes: synth and export wrote
            // strokes and node transforms near 1e300 that our own readers
            // refuse (an outside curator review).
            double most = sp_channel_is_scale(c) ? DOF_SCALE_MAX : sp_channel_is_rotation(c) ? DOF_TURN_MAX : SP_GLTF_MOVE_MAX;
            double least = sp_channel_is_scale(c) ? 1.0 / DOF_SCALE_MAX : -most;
            if (lo < least || hi > most) {
                r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': sp_dofs channel %s has bounds [%g, %g] outside [%g, %g]", what,
                            jn, cn, lo, hi, least, most);
                goto done;
            }
            sp_group g = sp_channel_is_scale(c) ? SP_GROUP_SHAPE : SP_GROUP_POSE;
            const cJSON* grp = cJSON_GetObjectItemCaseSensitive(d, "group");
            if (grp) {
                if (cJSON_IsString(grp) && !strcmp(grp->valuestring, "pose"))
                    g = SP_GROUP_POSE;
                else if (cJSON_IsString(grp) && !strcmp(grp->valuestring, "shape"))
                    g = SP_GROUP_SHAPE;
                else {
                    r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': sp_dofs channel %s: group must be \"pose\" or \"shape\"",
                                what, jn, cn);
                    goto done;
                }
            }
            if (sp_rig_add_param(rig, joint, c, lo, hi, g) < 0) {
                r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
                goto done;
            }
        }
    }
    const cJSON* rest = cJSON_GetObjectItemCaseSensitive(root, "sp_rest");
    if (rest) {
        double t[3], q[4], s[3];
        if (!json_vec(cJSON_GetObjectItemCaseSensitive(rest, "translation"), t, 3) ||
            !json_vec(cJSON_GetObjectItemCaseSensitive(rest, "rotation"), q, 4) ||
            !json_vec(cJSON_GetObjectItemCaseSensitive(rest, "scale"), s, 3)) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: joint '%s': sp_rest needs finite translation[3], rotation[4], scale[3]", what,
                        jn);
            goto done;
        }
        sp_joint* jt = &rig->joints[joint];
        jt->rest_t = sp_v3(t[0], t[1], t[2]);
        jt->rest_r = (sp_quat){q[0], q[1], q[2], q[3]};
        jt->rest_s = sp_v3(s[0], s[1], s[2]);
        *has_rest = true;
    }
done:
    cJSON_Delete(root);
    return r;
}

sp_result sp_gltf_curve_extras(const char* json, sp_curve_tag* tag, const char* what, sp_error* err)
{
    memset(tag, 0, sizeof *tag);
    if (!json || !*json) return SP_OK;
    cJSON* root = cJSON_Parse(json);
    if (!root) return sp_fail(err, SP_ERR_PARSE, "%s: node extras are not valid JSON", what);
    sp_result r = SP_OK;
    const cJSON* a = cJSON_GetObjectItemCaseSensitive(root, "sp_abstraction");
    if (a) {
        if (!cJSON_IsString(a) || !a->valuestring[0] || strlen(a->valuestring) >= SP_NAME_MAX) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: sp_abstraction must be a name of 1 to %d characters", what, SP_NAME_MAX - 1);
            goto done;
        }
        tag->is_curve = true;
        snprintf(tag->abstraction, sizeof tag->abstraction, "%s", a->valuestring);
        const cJSON* c = cJSON_GetObjectItemCaseSensitive(root, "sp_curve");
        if (cJSON_IsString(c)) snprintf(tag->curve, sizeof tag->curve, "%s", c->valuestring);
        const cJSON* k = cJSON_GetObjectItemCaseSensitive(root, "sp_correspondence");
        if (k) {
            if (cJSON_IsString(k) && !strcmp(k->valuestring, "ordered"))
                tag->correspondence = SP_CORR_ORDERED;
            else if (cJSON_IsString(k) && !strcmp(k->valuestring, "closest"))
                tag->correspondence = SP_CORR_CLOSEST;
            else {
                r = sp_fail(err, SP_ERR_INVALID, "%s: abstraction '%s': sp_correspondence must be \"ordered\" or \"closest\"",
                            what, tag->abstraction);
                goto done;
            }
            tag->has_correspondence = true;
        }
    }
done:
    cJSON_Delete(root);
    return r;
}

sp_result sp_gltf_append_curve(sp_rig* rig, const char* abstraction, sp_correspondence corr, const char* curve, bool closed,
                               int n, const double* rest, const uint16_t* joints, const float* weights)
{
    int a = sp_rig_find_abstraction(rig, abstraction);
    if (a < 0) {
        sp_abstraction* grown = realloc(rig->abstractions, sizeof(sp_abstraction) * (size_t)(rig->abstraction_count + 1));
        if (!grown) return SP_ERR_NO_MEMORY;
        rig->abstractions = grown;
        a = rig->abstraction_count++;
        memset(&grown[a], 0, sizeof grown[a]);
        snprintf(grown[a].name, sizeof grown[a].name, "%s", abstraction);
        grown[a].correspondence = corr;
    }
    sp_abstraction* ab = &rig->abstractions[a];
    size_t old = (size_t)ab->point_count, total = old + (size_t)n;
    sp_curve* curves = realloc(ab->curves, sizeof(sp_curve) * (size_t)(ab->curve_count + 1));
    if (curves) ab->curves = curves;
    double* r = realloc(ab->rest, sizeof(double) * 3 * total);
    if (r) ab->rest = r;
    uint16_t* j = realloc(ab->joints, sizeof(uint16_t) * 4 * total);
    if (j) ab->joints = j;
    float* w = realloc(ab->weights, sizeof(float) * 4 * total);
    if (w) ab->weights = w;
    if (!curves || !r || !j || !w) return SP_ERR_NO_MEMORY;
    memcpy(ab->rest + 3 * old, rest, sizeof(double) * 3 * (size_t)n);
    memcpy(ab->joints + 4 * old, joints, sizeof(uint16_t) * 4 * (size_t)n);
    memcpy(ab->weights + 4 * old, weights, sizeof(float) * 4 * (size_t)n);
    sp_curve* cv = &ab->curves[ab->curve_count++];
    memset(cv, 0, sizeof *cv);
    if (curve && *curve)
        snprintf(cv->name, sizeof cv->name, "%s", curve);
    else
        snprintf(cv->name, sizeof cv->name, "curve%d", ab->curve_count - 1);
    cv->first_point = (int)old;
    cv->point_count = n;
    cv->closed = closed;
    ab->point_count = (int)total;
    return SP_OK;
}

// ---- pose ---------------------------------------------------------------

void sp_gltf_apply_pose_json(sp_character* ch, const char* parameters_json, double* p)
{
    cJSON* root = cJSON_Parse(parameters_json);
    if (!cJSON_IsObject(root)) {
        sp_character_warn(ch, "sp_pose.parameters is not a JSON object; using the default pose");
        cJSON_Delete(root);
        return;
    }
    const cJSON* it;
    cJSON_ArrayForEach(it, root)
    {
        int k = sp_rig_find_param(&ch->rig, it->string);
        if (k < 0)
            sp_character_warn(ch, "sp_pose: unknown parameter '%s' ignored", it->string);
        else if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
            sp_character_warn(ch, "sp_pose: parameter '%s' is not a finite number; default kept", it->string);
        else
            p[k] = it->valuedouble;
    }
    cJSON_Delete(root);
    int clamped = sp_rig_clamp(&ch->rig, p);
    if (clamped > 0) sp_character_warn(ch, "sp_pose: %d parameters clamped to their bounds", clamped);
}

// Scene extras: sp_part (parsed into ch->part) and sp_pose (applied to ch->pose).
static sp_result scene_extras(sp_character* ch, const char* json, const char* what, sp_error* err)
{
    if (!json || !*json) return SP_OK;
    cJSON* root = cJSON_Parse(json);
    if (!root) return sp_fail(err, SP_ERR_PARSE, "%s: scene extras are not valid JSON", what);
    sp_result r = SP_OK;
    const cJSON* part = cJSON_GetObjectItemCaseSensitive(root, "sp_part");
    if (part) {
        r = sp_part_from_cjson(part, what, &ch->part, err);
        ch->has_part = r == SP_OK;
    }
    const cJSON* pose = cJSON_GetObjectItemCaseSensitive(root, "sp_pose");
    if (r == SP_OK && pose) {
        const cJSON* params = cJSON_GetObjectItemCaseSensitive(pose, "parameters");
        char* text = params ? cJSON_PrintUnformatted(params) : NULL;
        if (text)
            sp_gltf_apply_pose_json(ch, text, ch->pose);
        else if (!cJSON_IsNull(params) || ch->rig.param_count > 0)
            sp_character_warn(ch, "sp_pose has no \"parameters\" object; using the default pose");
        free(text);
    }
    cJSON_Delete(root);
    return r;
}

// ---- finishing ----------------------------------------------------------

// How many world units one unit of joint j's parent space is at rest (the
// ancestors' rest scales, each its geometric mean).
static double parent_scale(const sp_rig* rig, int j)
{
    double s = 1;
    for (int a = rig->joints[j].parent; a >= 0; a = rig->joints[a].parent) {
        sp_vec3 k = rig->joints[a].rest_s;
        s *= cbrt(fabs(k.x * k.y * k.z));
    }
    return s;
}

sp_result sp_gltf_finish(sp_character* ch, const sp_import* im, sp_error* err)
{
    sp_rig* rig = &ch->rig;
    const char* what = im->what;
    // Why only when no joint declares sp_dofs: a file that declares some has
    // chosen its parameters; an explicit empty list means "this joint is fixed".
    if (!im->any_dofs) {
        // The skin's top joint also translates, by up to 0.3 of the mesh's
        // diagonal (random poses then move it by up to 7.5%, as the shipped
        // characters' placement does; the solve reaches 20%): a
        // drawing seldom lands where the default view puts the character,
        // and without a placement the solve bent limbs to reach it (a stick
        // figure drawn 40 px off, a tenth of its size, fitted at 15 px). On
        // the node above it when there is one, so that the solve's placement
        // stage (the first joint's parameters) moves it without turning it.
        sp_vec3 lo, hi;
        sp_bounds(rig->rest, rig->vertex_count, &lo, &hi);
        double size = sp_v3_len(sp_v3_sub(hi, lo));
        int added = 0, carrier = -1;
        for (int j = 0; j < rig->joint_count && carrier < 0; ++j)
            if (im->is_skin[j])
                carrier = rig->joints[j].parent >= 0 && !im->is_skin[rig->joints[j].parent] ? rig->joints[j].parent : j;
        double reach = carrier >= 0 ? 0.3 * size / parent_scale(rig, carrier) : 0;
        for (int j = 0; j < rig->joint_count; ++j) {
            if (j == carrier && isfinite(reach) && reach > 0)
                for (int c = SP_CH_TX; c <= SP_CH_TZ; ++c)
                    if (sp_rig_add_param(rig, j, (sp_channel)c, -reach, reach, SP_GROUP_POSE) < 0)
                        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
            if (!im->is_skin[j]) continue;
            for (int c = SP_CH_RX; c <= SP_CH_RZ; ++c)
                if (sp_rig_add_param(rig, j, (sp_channel)c, -SP_GLTF_DEFAULT_ROT_LIMIT, SP_GLTF_DEFAULT_ROT_LIMIT,
                                     SP_GROUP_POSE) < 0)
                    return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
            ++added;
        }
        ch->derived_dofs = added > 0;
    }
    int renorm = 0;
    sp_result r = sp_rig_finalize(rig, what, &renorm, err);
    if (r != SP_OK) return r;
    if (renorm > 0) sp_character_warn(ch, "renormalised skin weights of %d vertices", renorm);
    if (rig->abstraction_count == 0) {
        int flat = 0;
        r = sp_gltf_derive_stick(rig, im->is_skin, &flat, err);
        if (r != SP_OK) return r;
        if (flat > 0)
            sp_character_warn(
                ch, "the stick figure leaves out %d bone%s whose skin flattens the mesh (a singular inverse bind matrix)", flat,
                flat == 1 ? "" : "s");
        if (rig->abstraction_count > 0) {
            ch->derived_abstraction = true;
            r = sp_rig_finalize(rig, what, NULL, err);
            if (r != SP_OK) return r;
        } else {
            sp_character_warn(ch, "the skeleton has no bones to derive a stick figure from");
        }
    }
    ch->pose = malloc(sizeof(double) * (size_t)(rig->param_count + 1));
    if (!ch->pose) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    sp_rig_defaults(rig, ch->pose);
    // Our exports bake the pose into the node TRS and keep the rest in
    // sp_rest: recover the parameters from the node (sp_pose refines them).
    for (int j = 0; j < rig->joint_count; ++j)
        if (im->has_rest[j] && rig->joints[j].param_count > 0)
            sp_rig_params_from_trs(rig, j, im->node_t[j], im->node_r[j], im->node_s[j], ch->pose);
    r = scene_extras(ch, im->scene_extras, what, err);
    if (r != SP_OK) return r;
    if (!ch->has_camera) {
        if (default_camera(ch) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    }
    return SP_OK;
}
