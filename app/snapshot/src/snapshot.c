#include "sp/snapshot.h"

#include <math.h>
#include <stdlib.h>

#include "sp/headless.h"
#include "sp/image.h"
#include "sp/render.h"

static void draw_sketch(sp_renderer* r, const sp_sketch* s, float width, const float rgba[4])
{
    if (!s) return;
    for (int i = 0; i < s->stroke_count; ++i)
        if (s->strokes[i].count > 0) sp_renderer_draw_polyline(r, s->strokes[i].points, s->strokes[i].count, false, width, rgba);
}

void sp_snapshot_size(const sp_camera* cam, int* w, int* h)
{
    double cw = cam->width > 0 ? cam->width : 1, ch = cam->height > 0 ? cam->height : 1;
    double k = fmin(1.0, SP_SNAPSHOT_MAX_SIDE / fmax(cw, ch));
    k = fmin(fmax(k, SP_SNAPSHOT_MIN_SIDE / fmin(cw, ch)), SP_SNAPSHOT_MAX_SIDE / fmax(cw, ch));
    *w = (int)fmax(1.0, lround(cw * k));
    *h = (int)fmax(1.0, lround(ch * k));
}

sp_result sp_snapshot_render(const sp_snapshot_desc* d, sp_image* img, sp_error* err)
{
    const sp_character* ch = d->character;
    const sp_rig* rig = &ch->rig;
    sp_camera fitted = *d->camera;
    const sp_camera* cam = &fitted;
    sp_headless* gl;
    sp_result res = sp_headless_create(&gl, err);
    if (res != SP_OK) return res;
    sp_renderer* r;
    sp_render_target* t = NULL;
    res = sp_renderer_create(&(sp_renderer_desc){0}, &r, err);
    int w, h;
    sp_snapshot_size(cam, &w, &h);
    if (res == SP_OK) res = sp_render_target_create(w, h, 0, &t, err);
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    double* xyz = malloc(sizeof(double) * 3 * (size_t)(rig->vertex_count + 1));
    if (res != SP_OK) goto done;
    if (!ev || !xyz) {
        res = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while rendering");
        goto done;
    }
    sp_rig_eval_update(ev, d->params ? d->params : ch->pose, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    sp_render_mesh* m = NULL;
    if (rig->vertex_count > 0) {
        // A strongly posed mesh may leave the rest pose's depth range.
        sp_vec3 lo, hi;
        sp_bounds(xyz, rig->vertex_count, &lo, &hi);
        sp_render_fit_depth(&fitted, lo, hi);
    }
    if (rig->vertex_count > 0 && rig->triangle_count > 0) {
        const sp_mesh_desc md = sp_mesh_desc_of_rig(rig, xyz, ch->colors);
        if ((res = sp_render_mesh_create(r, &md, &m, err)) != SP_OK) goto done;
    }
    sp_render_target_bind(t);
    sp_renderer_begin(r, cam, w, h); // the overlays' pixels stay the canvas's
    sp_renderer_clear(r, SP_COLOR_BACKGROUND_TOP, SP_COLOR_BACKGROUND_BOTTOM);
    if (m) {
        sp_vec3 lo, hi;
        sp_render_mesh_bounds(m, &lo, &hi);
        sp_renderer_draw_ground_shadow(r, lo, hi, 0);
        sp_renderer_draw_mesh(r, m, NULL);
    }
    // In canvas pixels, at least 2 of the picture's (a 21 x 16 picture of an
    // 8 x 6 canvas drew its lines 5 px wide).
    float line = (float)fmax(2.0 * cam->height / h, cam->height / 160.0);
    draw_sketch(r, d->ghost, line, (const float[4]){0.45f, 0.45f, 0.5f, 0.9f});
    draw_sketch(r, d->strokes, SP_STROKE_UNDER_FIT * line, SP_COLOR_STROKE);
    const sp_abstraction* abs[2] = {d->abstraction >= 0 && d->abstraction < rig->abstraction_count ? &rig->abstractions[d->abstraction] : NULL,
                                    d->extra_abstraction};
    for (int k = 0; k < 2; ++k) {
        const sp_abstraction* a = abs[k];
        if (!a) continue;
        double* z = malloc(sizeof(double) * 3 * (size_t)(a->point_count + 1));
        if (!z) continue;
        sp_rig_eval_abstraction(ev, a, xyz, z);
        sp_renderer_draw_abstraction(r, a, z, line, SP_COLOR_ABSTRACTION);
        free(z);
    }
    sp_renderer_end(r);
    res = sp_render_target_read(t, img, err);
    sp_render_mesh_destroy(m);
done:
    free(xyz);
    sp_rig_eval_destroy(ev);
    sp_render_target_destroy(t);
    sp_renderer_destroy(r);
    sp_headless_destroy(gl);
    return res;
}

sp_result sp_snapshot_png(const sp_snapshot_desc* d, const char* path, sp_error* err)
{
    sp_image img = {0};
    sp_result r = sp_snapshot_render(d, &img, err);
    if (r == SP_OK) r = sp_image_write_png(&img, path, err);
    sp_image_free(&img);
    return r;
}
