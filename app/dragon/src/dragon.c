// dragon.c: creating and destroying the pipeline, and its small accessors.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"

const char* sp_dragon_reject_name(sp_dragon_reject r)
{
    switch (r) {
    case SP_DRAGON_ACCEPTED:
        return "accepted";
    case SP_DRAGON_TOO_SHORT:
        return "too_short";
    case SP_DRAGON_UNRECOGNISED:
        return "unrecognised";
    case SP_DRAGON_NO_PART:
        return "no_part";
    case SP_DRAGON_NO_MODEL:
        return "no_model";
    case SP_DRAGON_FIT_FAILED:
        return "fit_failed";
    case SP_DRAGON_NOTHING_TO_REFIT:
        return "nothing_to_refit";
    case SP_DRAGON_FULL:
        return "full";
    case SP_DRAGON_DETAIL:
        return "detail";
    }
    return "unknown";
}

const char* sp_dragon_note_name(sp_dragon_note n)
{
    switch (n) {
    case SP_DRAGON_NOTE_NONE:
        return "none";
    case SP_DRAGON_NOTE_NO_SURFACE:
        return "no_surface";
    case SP_DRAGON_NOTE_NOT_FINITE:
        return "not_finite";
    }
    return "unknown";
}

const char* sp_dragon_default_assets(void)
{
    const char* env = getenv("SP_ASSETS");
    return env && *env ? env : SP_SOURCE_ASSETS;
}

sp_result sp_dragon_create(const sp_dragon_desc* desc, sp_dragon** out, sp_error* err)
{
    *out = NULL;
    sp_dragon* d = calloc(1, sizeof *d);
    if (!d) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory making the dragon pipeline");
    d->desc = desc ? *desc : (sp_dragon_desc){0};
    sp_dragon_desc* o = &d->desc;
    if (o->canvas_w <= 0 || o->canvas_h <= 0) o->canvas_w = 1280, o->canvas_h = 800;
    // Kiosk defaults: a visitor waits for the fit (target 50 ms pen-up to part);
    // 100 representatives and 48 samples per curve halve the solve on the
    // shipped parts at the same accuracy for freehand strokes (notes/pipeline.md).
    if (!(o->solve.time_cap_ms > 0)) o->solve.time_cap_ms = 250;
    if (o->solve.representatives <= 0) o->solve.representatives = 100;
    if (o->solve.samples <= 0) o->solve.samples = 48;
    if (o->snap_fraction == 0) o->snap_fraction = 0.06;
    if (o->max_variants <= 0) o->max_variants = 4;
    if (!(o->fps > 0)) o->fps = 30;
    if (o->max_parts <= 0) o->max_parts = 48;
    o->solve.active = NULL; // a flag array would belong to one rig; parts differ
    d->next_id = 1;
    // The world camera (dragon.h): canvas height = 2 units, origin at the centre, eye on +Z.
    sp_camera w = {0};
    w.kind = SP_CAMERA_ORTHOGRAPHIC;
    w.view = sp_mat4_translate((sp_vec3){0, 0, -10});
    w.scale = 0.5 * o->canvas_h;
    w.cx = 0.5 * o->canvas_w, w.cy = 0.5 * o->canvas_h;
    w.width = o->canvas_w, w.height = o->canvas_h;
    w.znear = 0.1, w.zfar = 20;
    d->world = w;
    if (o->db) {
        d->db = o->db;
        dragon_copy_name(d->db_path, sizeof d->db_path, sp_db_path(o->db));
    } else {
        dragon_copy_name(d->db_path, sizeof d->db_path, o->db_path ? o->db_path : sp_db_default_path());
        dragon_copy_name(d->assets_dir, sizeof d->assets_dir, o->assets_dir ? o->assets_dir : sp_dragon_default_assets());
        sp_result r = sp_db_open_or_create_default(d->db_path, d->assets_dir, SP_DB_READONLY, &d->db, err);
        if (r != SP_OK) {
            free(d);
            return r;
        }
        dragon_db_file_id(d);
        d->own_db = true;
    }
    o->db = NULL, o->db_path = NULL, o->assets_dir = NULL; // not kept: the caller's strings
    d->gen = sp_db_generation(d->db);
    dragon_reload_model(d, false); // without one, strokes need a forced category
    *out = d;
    return SP_OK;
}

void sp_dragon_destroy(sp_dragon* d)
{
    if (!d) return;
    (void)dragon_model_load_take(d, true); // a read in the background ends first
    sp_dragon_clear(d);
    free(d->parts);
    dragon_cache_clear(d);
    sp_clf_destroy(d->clf);
    if (d->own_db) sp_db_close(d->db);
    free(d);
}

const sp_clf* sp_dragon_model(const sp_dragon* d)
{
    return d->clf;
}

const char* sp_dragon_model_error(const sp_dragon* d)
{
    return d->model_error;
}

int sp_dragon_part_count(const sp_dragon* d)
{
    return d->part_n;
}

const sp_dragon_part* sp_dragon_part_get(const sp_dragon* d, int i)
{
    return i >= 0 && i < d->part_n ? &d->parts[i]->pub : NULL;
}

sp_camera sp_dragon_camera(const sp_dragon* d)
{
    return d->world;
}

double sp_dragon_period(const sp_dragon* d)
{
    return d->period;
}
