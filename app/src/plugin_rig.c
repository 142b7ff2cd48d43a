#include "plugin_rig.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "posing.h"
#include "report.h"
#include "sp/sketch_io.h"
#include "sp/snapshot.h"
#include "sp/synth.h"

bool sp_is_plugin_path(const char* path)
{
    if (!path) return false;
    const char* base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = strlen(base);
    return (n > 3 && !strcmp(base + n - 3, ".so")) || strstr(base, ".so.") != NULL;
}

int sp_plugin_pick_abstraction(const sp_blackbox* bb, const char* path, const char* name, sp_error* err)
{
    if (!name) return 0;
    int a = sp_blackbox_find_abstraction(bb, name);
    if (a < 0) {
        const sp_blackbox_rig* r = sp_blackbox_desc(bb);
        char list[256] = "";
        for (int i = 0; i < r->abstraction_count; ++i) {
            size_t n = strlen(list);
            snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", r->abstractions[i].name);
        }
        sp_fail(err, SP_ERR_INVALID, "%s: no abstraction '%s' (it has: %s)", path, name, list);
    }
    return a;
}

sp_camera sp_plugin_camera(const sp_blackbox* bb, int width, int height)
{
    // Framed on 640x480 like a glTF character's default view, then fitted
    // to the canvas, so strokes drawn for one canvas size pose the same.
    sp_camera base = sp_blackbox_camera(bb, 640, 480);
    return width >= 1 && height >= 1 ? sp_camera_resize(&base, width, height) : base;
}

static int find_param(const sp_blackbox* bb, const char* name)
{
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    for (int i = 0; i < r->param_count; ++i)
        if (!strcmp(r->params[i].name, name)) return i;
    return -1;
}

sp_result sp_plugin_read_pose(const char* path, const sp_blackbox* bb, double* p, sp_error* err)
{
    FILE* f = fopen(path, "rb");
    if (!f) return sp_fail(err, SP_ERR_IO, "%s: cannot open the pose file", path);
    char* text = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 8192;
            char* t = realloc(text, cap);
            if (!t) {
                free(text);
                fclose(f);
                return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
            }
            text = t;
        }
        size_t got = fread(text + len, 1, 4096, f);
        len += got;
        if (got < 4096) break;
    }
    fclose(f);
    text[len] = 0;
    cJSON* j = cJSON_Parse(text);
    free(text);
    const cJSON* params = cJSON_GetObjectItemCaseSensitive(j, "parameters");
    if (!cJSON_IsObject(params)) {
        cJSON_Delete(j);
        return sp_fail(err, SP_ERR_PARSE, "%s: not a pose file (expected {\"parameters\": {...}})", path);
    }
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    for (const cJSON* it = params->child; it; it = it->next) {
        int k = it->string ? find_param(bb, it->string) : -1;
        if (k < 0) {
            sp_fail(err, SP_ERR_INVALID, "%s: the rig has no parameter '%s'", path, it->string ? it->string : "");
            cJSON_Delete(j);
            return SP_ERR_INVALID;
        }
        if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble)) {
            sp_fail(err, SP_ERR_INVALID, "%s: parameter '%s' is not a finite number", path, it->string);
            cJSON_Delete(j);
            return SP_ERR_INVALID;
        }
        double v = it->valuedouble, c = fmin(fmax(v, r->params[k].min), r->params[k].max);
        if (c != v)
            fprintf(stderr, "warning: %s: parameter '%s' = %g is outside [%g, %g], clamped\n", path, it->string, v,
                    r->params[k].min, r->params[k].max);
        p[k] = c;
    }
    cJSON_Delete(j);
    return SP_OK;
}

cJSON* sp_plugin_pose_json(const sp_blackbox* bb, const double* p)
{
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    cJSON* o = cJSON_CreateObject();
    cJSON* params = cJSON_AddObjectToObject(o, "parameters");
    for (int i = 0; i < r->param_count; ++i)
        cJSON_AddNumberToObject(params, r->params[i].name, p[i]);
    return o;
}

sp_result sp_plugin_bake(const sp_blackbox* bb, int a, const double* p, const sp_camera* cam, sp_character* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    int n = r->vertex_count, total = sp_blackbox_total_points(bb);
    int first_a = a >= 0 ? a : 0, na = a >= 0 ? 1 : r->abstraction_count;
    sp_rig rig = {0};
    double* z = malloc(sizeof(double) * 3 * (size_t)(total + 1));
    rig.joint_count = 1;
    rig.joints = calloc(1, sizeof(sp_joint));
    rig.vertex_count = n;
    rig.rest = malloc(sizeof(double) * 3 * (size_t)n);
    rig.joints4 = calloc(4 * (size_t)n, sizeof(uint16_t));
    rig.weights4 = calloc(4 * (size_t)n, sizeof(float));
    rig.triangle_count = r->triangle_count;
    rig.triangles = malloc(sizeof(uint32_t) * 3 * (size_t)(r->triangle_count + 1));
    rig.abstraction_count = na;
    rig.abstractions = calloc((size_t)na, sizeof(sp_abstraction));
    bool ok = z && rig.joints && rig.rest && rig.joints4 && rig.weights4 && rig.triangles && rig.abstractions;
    for (int k = 0; ok && k < na; ++k) {
        const sp_abstraction* src = sp_blackbox_abstraction_at(bb, first_a + k);
        sp_abstraction* ab = &rig.abstractions[k];
        int l = src->point_count;
        *ab = (sp_abstraction){.correspondence = src->correspondence, .curve_count = src->curve_count, .point_count = l};
        snprintf(ab->name, sizeof ab->name, "%s", src->name);
        ab->curves = malloc(sizeof(sp_curve) * (size_t)src->curve_count);
        ab->rest = malloc(sizeof(double) * 3 * (size_t)l);
        ab->joints = calloc(4 * (size_t)l, sizeof(uint16_t));
        ab->weights = calloc(4 * (size_t)l, sizeof(float));
        ok = ab->curves && ab->rest && ab->joints && ab->weights;
    }
    if (!ok) {
        free(z);
        sp_rig_free(&rig);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    // One identity joint that everything follows: a static, posed character.
    rig.joints[0] =
        (sp_joint){.name = "root", .parent = -1, .rest_r = {0, 0, 0, 1}, .rest_s = {1, 1, 1}, .inverse_bind = sp_mat4_identity()};
    sp_result res = sp_blackbox_evaluate(bb, p, rig.rest, z, err);
    if (res == SP_OK) {
        for (int i = 0; i < n; ++i)
            rig.weights4[4 * i] = 1.0f;
        memcpy(rig.triangles, r->triangles, sizeof(uint32_t) * 3 * (size_t)r->triangle_count);
        for (int k = 0; k < na; ++k) {
            const sp_abstraction* src = sp_blackbox_abstraction_at(bb, first_a + k);
            sp_abstraction* ab = &rig.abstractions[k];
            memcpy(ab->curves, src->curves, sizeof(sp_curve) * (size_t)src->curve_count);
            memcpy(ab->rest, z + 3 * (size_t)sp_blackbox_first_point(bb, first_a + k),
                   sizeof(double) * 3 * (size_t)ab->point_count);
            for (int i = 0; i < ab->point_count; ++i)
                ab->weights[4 * i] = 1.0f;
        }
        res = sp_rig_finalize(&rig, r->name, NULL, err);
    }
    free(z);
    if (res == SP_OK) res = sp_character_from_rig(&rig, out, err);
    if (res != SP_OK) {
        sp_rig_free(&rig);
        return res;
    }
    if (r->colors) memcpy(out->colors, r->colors, sizeof(float) * 4 * (size_t)n);
    out->camera = *cam;
    out->has_camera = true;
    return SP_OK;
}

sp_result sp_plugin_load_posed(const char* path, const char* pose, sp_character* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    sp_blackbox* bb = NULL;
    sp_result res = sp_blackbox_load_plugin(path, &bb, err);
    if (res != SP_OK) return res;
    double* p = malloc(sizeof(double) * (size_t)sp_blackbox_desc(bb)->param_count);
    if (!p) res = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (res == SP_OK) {
        sp_blackbox_defaults(bb, p);
        if (pose) res = sp_plugin_read_pose(pose, bb, p, err);
    }
    sp_camera cam = sp_plugin_camera(bb, 0, 0);
    if (res == SP_OK) res = sp_plugin_bake(bb, -1, p, &cam, out, err);
    free(p);
    sp_blackbox_free(bb);
    return res;
}

int sp_plugin_pose(const char* rig_path, const char* abs_name, const char* strokes, const char* start, const char* out,
                   const char* render, const char* report, const sp_solve_desc* desc)
{
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    sp_sketch sk = {0};
    sp_solver* solver = NULL;
    sp_character baked = {0};
    double* p = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_blackbox_load_plugin(rig_path, &bb, &err) != SP_OK) goto fail;
    int a = sp_plugin_pick_abstraction(bb, rig_path, abs_name, &err);
    if (a < 0) goto fail;
    if (sp_read_strokes(strokes, &sk, &err) != SP_OK) goto fail;
    sp_camera cam = sp_plugin_camera(bb, (int)lround(sk.canvas_w), (int)lround(sk.canvas_h));
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    p = malloc(sizeof(double) * (size_t)r->param_count);
    if (!p) goto oom;
    sp_blackbox_defaults(bb, p);
    if (start && sp_plugin_read_pose(start, bb, p, &err) != SP_OK) goto fail;
    solver = sp_solver_create_blackbox(bb, a, &cam, desc);
    if (!solver) goto oom;
    sp_solve_report rep;
    if (sp_solver_solve(solver, &sk, p, p, &rep, &err) != SP_OK) {
        fprintf(stderr, "sketchpose pose: %s: %s\n", strokes, err.text);
        goto done;
    }
    cJSON* j = sp_report_to_json(&rep, NULL, sp_blackbox_abstraction_at(bb, a), NULL);
    cJSON* pose = sp_plugin_pose_json(bb, p);
    cJSON_AddItemToObject(j, "parameters", cJSON_DetachItemFromObject(pose, "parameters"));
    cJSON_Delete(pose);
    sp_result wr = report ? sp_json_write_file(report, j, &err) : SP_OK;
    sp_json_print(j);
    cJSON_Delete(j);
    if (wr != SP_OK) goto fail;
    if (out || render) {
        if (sp_plugin_bake(bb, a, p, &cam, &baked, &err) != SP_OK) goto fail;
        if (out && sp_gltf_save(&baked, NULL, out, &err) != SP_OK) goto fail;
        sp_snapshot_desc d = {.character = &baked, .params = NULL, .camera = &cam, .abstraction = 0, .strokes = &sk};
        if (render && sp_snapshot_png(&d, render, &err) != SP_OK) goto fail;
    }
    if (rep.note[0]) fprintf(stderr, "sketchpose pose: %s\n", rep.note);
    exit_code = SP_EXIT_OK;
    goto done;
oom:
    sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
fail:
    fprintf(stderr, "sketchpose pose: %s\n", err.text);
done:
    sp_solver_destroy(solver);
    sp_character_free(&baked);
    free(p);
    sp_sketch_free(&sk);
    sp_blackbox_free(bb);
    return exit_code;
}

int sp_plugin_synth(const char* rig_path, const char* abs_name, int seed, const char* pose, double amplitude, const char* out,
                    const char* truth, int w, int h, double noise)
{
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    sp_sketch sk = {0};
    double* p = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_blackbox_load_plugin(rig_path, &bb, &err) != SP_OK) goto fail;
    int a = sp_plugin_pick_abstraction(bb, rig_path, abs_name, &err);
    if (a < 0) goto fail;
    sp_camera cam = sp_plugin_camera(bb, w, h);
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    p = malloc(sizeof(double) * (size_t)r->param_count);
    if (!p) {
        sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
        goto fail;
    }
    sp_blackbox_defaults(bb, p);
    if (pose) {
        if (sp_plugin_read_pose(pose, bb, p, &err) != SP_OK) goto fail;
    } else {
        sp_blackbox_synth_params(bb, (uint64_t)(unsigned)seed, amplitude, p);
    }
    if (sp_blackbox_synth_sketch(bb, a, &cam, p, &sk, &err) != SP_OK) goto fail;
    if (noise > 0) sp_synth_jitter(&sk, noise, (uint64_t)(unsigned)seed);
    if (sp_sketch_write_json(out, &sk, &err) != SP_OK) goto fail;
    if (truth) {
        cJSON* j = sp_plugin_pose_json(bb, p);
        sp_result wr = sp_json_write_file(truth, j, &err);
        cJSON_Delete(j);
        if (wr != SP_OK) goto fail;
    }
    exit_code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose synth: %s\n", err.text[0] ? err.text : "out of memory");
done:
    free(p);
    sp_sketch_free(&sk);
    sp_blackbox_free(bb);
    return exit_code;
}

int sp_plugin_inspect(const char* rig_path)
{
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    if (sp_blackbox_load_plugin(rig_path, &bb, &err) != SP_OK) {
        fprintf(stderr, "sketchpose inspect: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    static const char* const UNITS[] = {"angle", "length", "factor", "weight"};
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    cJSON* root = cJSON_CreateObject();
    cJSON_AddBoolToObject(root, "black_box", true);
    cJSON_AddNumberToObject(root, "vertices", r->vertex_count);
    cJSON_AddNumberToObject(root, "triangles", r->triangle_count);
    cJSON_AddArrayToObject(root, "joints");
    cJSON* params = cJSON_AddArrayToObject(root, "parameters");
    for (int k = 0; k < r->param_count; ++k) {
        const sp_blackbox_param* q = &r->params[k];
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", q->name);
        cJSON_AddNumberToObject(o, "min", q->min);
        cJSON_AddNumberToObject(o, "max", q->max);
        cJSON_AddNumberToObject(o, "default", q->def);
        cJSON_AddStringToObject(o, "group", q->group == SP_GROUP_SHAPE ? "shape" : "pose");
        cJSON_AddStringToObject(o, "unit", UNITS[q->unit]);
        cJSON_AddItemToArray(params, o);
    }
    cJSON* abs = cJSON_AddArrayToObject(root, "abstractions");
    for (int a = 0; a < r->abstraction_count; ++a) {
        const sp_abstraction* ab = sp_blackbox_abstraction_at(bb, a);
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", ab->name);
        cJSON_AddNumberToObject(o, "curves", ab->curve_count);
        cJSON_AddNumberToObject(o, "points", ab->point_count);
        cJSON_AddStringToObject(o, "correspondence", ab->correspondence == SP_CORR_CLOSEST ? "closest" : "ordered");
        cJSON_AddBoolToObject(o, "derived", false);
        cJSON_AddItemToArray(abs, o);
    }
    cJSON_AddArrayToObject(root, "animations");
    cJSON_AddBoolToObject(root, "camera_from_file", true); // the rig declares its sketch view (or asks for the default one)
    cJSON_AddNullToObject(root, "part");
    cJSON_AddArrayToObject(root, "warnings");
    sp_json_print(root);
    cJSON_Delete(root);
    sp_blackbox_free(bb);
    return SP_EXIT_OK;
}
