// rig_handle.c: a glTF character or a black-box plugin behind one handle
// (see rig_handle.h). Each call branches on the kind once; everything above
// it (the commands) is the same code for both.
#include "rig_handle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pose_io.h"
#include "posing.h"
#include "sp/blackbox.h"
#include "sp/plugin.h"
#include "sp/sketch_io.h"
#include "sp/synth.h"

struct sp_rig_handle {
    char* path;
    sp_character ch;       // a glTF rig (zeroed for a plugin)
    sp_blackbox* bb;       // a plugin (NULL for a glTF rig)
    int file_abstractions; // the glTF file's own abstractions (drawover appends after them)
    sp_camera view;        // the sketch view on its own canvas
};

bool sp_rig_path_is_plugin(const char* path)
{
    if (!path) return false;
    const char* base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = strlen(base);
    // A glTF's own extension wins: `cm.so.backup.glb` was dlopen'ed.
    if (sp_path_ext_is(base, "glb") || sp_path_ext_is(base, "gltf")) return false;
    return (n > 3 && !strcmp(base + n - 3, ".so")) || strstr(base, ".so.") != NULL;
}

sp_result sp_rig_handle_load(const char* path, sp_rig_handle** out, sp_error* err)
{
    *out = NULL;
    sp_rig_handle* h = calloc(1, sizeof *h);
    if (h) h->path = strdup(path);
    if (!h || !h->path) {
        free(h);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    sp_result r;
    if (sp_rig_path_is_plugin(path)) {
        r = sp_blackbox_load_plugin(path, &h->bb, err);
        if (r == SP_OK) h->view = sp_blackbox_camera(h->bb, 640, 480);
    } else {
        r = sp_gltf_load(path, &h->ch, err);
        h->file_abstractions = h->ch.rig.abstraction_count;
        h->view = h->ch.camera;
    }
    if (r != SP_OK) {
        sp_rig_handle_free(h);
        return r;
    }
    *out = h;
    return SP_OK;
}

sp_result sp_rig_handle_load_character(const char* path, const char* command, sp_rig_handle** out, sp_error* err)
{
    *out = NULL;
    if (sp_rig_path_is_plugin(path))
        return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: %s needs a glTF character; a black-box rig plugin is posed by `pose`", path,
                       command);
    return sp_rig_handle_load(path, out, err);
}

void sp_rig_handle_free(sp_rig_handle* h)
{
    if (!h) return;
    sp_character_free(&h->ch);
    sp_blackbox_destroy(h->bb);
    free(h->path);
    free(h);
}

bool sp_rig_handle_is_black_box(const sp_rig_handle* h)
{
    return h->bb != NULL;
}

sp_character* sp_rig_handle_character(sp_rig_handle* h)
{
    return h->bb ? NULL : &h->ch;
}

int sp_rig_handle_vertex_count(const sp_rig_handle* h)
{
    return h->bb ? sp_blackbox_desc(h->bb)->vertex_count : h->ch.rig.vertex_count;
}

int sp_rig_handle_triangle_count(const sp_rig_handle* h)
{
    return h->bb ? sp_blackbox_desc(h->bb)->triangle_count : h->ch.rig.triangle_count;
}

int sp_rig_handle_param_count(const sp_rig_handle* h)
{
    return h->bb ? sp_blackbox_desc(h->bb)->param_count : h->ch.rig.param_count;
}

const sp_param* sp_rig_handle_params(const sp_rig_handle* h)
{
    return h->bb ? sp_blackbox_params(h->bb) : h->ch.rig.params;
}

const char* sp_rig_handle_unit(const sp_rig_handle* h, int k)
{
    static const char* const UNITS[] = {"angle", "length", "factor", "weight"}; // sp_blackbox_unit
    return h->bb ? UNITS[sp_blackbox_desc(h->bb)->params[k].unit] : NULL;
}

sp_result sp_rig_handle_read_pose(const sp_rig_handle* h, const char* path, double** p, int* clamped, sp_error* err)
{
    if (clamped) *clamped = 0;
    int n = sp_rig_handle_param_count(h);
    *p = malloc(sizeof(double) * (size_t)(n + 1));
    if (!*p) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (h->bb)
        sp_blackbox_defaults(h->bb, *p);
    else
        memcpy(*p, h->ch.pose, sizeof(double) * (size_t)n);
    return path ? sp_pose_read(path, sp_rig_handle_params(h), n, *p, clamped, err) : SP_OK;
}

int sp_rig_handle_abstraction_count(const sp_rig_handle* h)
{
    return h->bb ? sp_blackbox_desc(h->bb)->abstraction_count : h->ch.rig.abstraction_count;
}

const sp_abstraction* sp_rig_handle_abstractions(const sp_rig_handle* h)
{
    return h->bb ? sp_blackbox_abstraction_at(h->bb, 0) : h->ch.rig.abstractions;
}

int sp_rig_handle_pick_abstraction(const sp_rig_handle* h, const char* name, sp_error* err)
{
    // A part says what its sketches show (`derive --abstraction stick`
    // writes it): that one, where the file lists the outline first.
    if (!name && !h->bb && h->ch.part.abstraction[0] && sp_rig_find_abstraction(&h->ch.rig, h->ch.part.abstraction) >= 0)
        name = h->ch.part.abstraction;
    return sp_pick_abstraction(sp_rig_handle_abstractions(h), sp_rig_handle_abstraction_count(h), h->path, name, err);
}

sp_camera sp_rig_handle_camera(const sp_rig_handle* h, double width, double height)
{
    if (width >= 1 && height >= 1) return sp_camera_resize(&h->view, (int)lround(width), (int)lround(height));
    return h->view;
}

sp_result sp_rig_handle_solver(const sp_rig_handle* h, int a, const sp_camera* cam, const sp_solve_desc* desc, sp_solver** out,
                               sp_error* err)
{
    return h->bb ? sp_solver_create_blackbox(h->bb, a, cam, desc, out, err)
                 : sp_solver_create(&h->ch.rig, a, cam, desc, out, err);
}

void sp_rig_handle_synth_params(const sp_rig_handle* h, uint64_t seed, double amplitude, double* p)
{
    if (h->bb)
        sp_blackbox_synth_params(h->bb, seed, amplitude, p);
    else
        sp_synth_params(&h->ch.rig, seed, amplitude, p);
}

sp_result sp_rig_handle_synth_sketch(const sp_rig_handle* h, int a, const sp_camera* cam, const double* p, sp_sketch* out,
                                     sp_error* err)
{
    if (h->bb) return sp_blackbox_synth_sketch(h->bb, a, cam, p, out, err);
    if (sp_synth_sketch(&h->ch.rig, a, cam, p, out) == SP_OK) return SP_OK;
    return sp_fail(err, SP_ERR_INTERNAL, "%s: cannot project abstraction '%s'", h->path, h->ch.rig.abstractions[a].name);
}

// The plugin at p as a static character: one identity joint that everything
// follows, the posed mesh with the rig's colours, abstraction a (-1: all) as
// rigid curves through its posed points, and `cam` as its view.
static sp_result bake(const sp_blackbox* bb, int a, const double* p, const sp_camera* cam, sp_character* out, sp_error* err)
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

sp_result sp_rig_handle_posed(const sp_rig_handle* h, int a, const double* p, const sp_camera* cam, sp_rig_posed* out,
                              sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (!h->bb) {
        *out = (sp_rig_posed){.character = &h->ch, .params = p, .abstraction = a, .saved_abstractions = h->file_abstractions};
        return SP_OK;
    }
    sp_result r = bake(h->bb, a, p, cam, &out->baked, err);
    if (r != SP_OK) return r;
    out->character = &out->baked;
    out->abstraction = a >= 0 ? 0 : -1;
    out->saved_abstractions = out->baked.rig.abstraction_count;
    return SP_OK;
}

sp_result sp_rig_posed_save(const sp_rig_posed* v, const char* path, sp_error* err)
{
    // A shallow copy that ends before the curves a command added for itself
    // (the writer takes skinned curves only; drawover's are embedded).
    sp_character c = *v->character;
    c.rig.abstraction_count = v->saved_abstractions;
    return sp_gltf_save(&c, v->params, path, err);
}

void sp_rig_posed_free(sp_rig_posed* v)
{
    sp_character_free(&v->baked);
    memset(v, 0, sizeof *v);
}

void sp_rig_handle_warn_textures(const char* cmd, const sp_rig_handle* h, const char* out)
{
    if (!h->bb && h->ch.textured)
        fprintf(stderr, "%s: warning: %s has a texture, which %s does not keep (sketchpose reads no images: it is grey)\n", cmd,
                h->path, out);
}
