#include "sp/dragon_snapshot.h"

#include <math.h>
#include <stdlib.h>

#include "sp/headless.h"
#include "sp/render.h"

sp_result sp_dragon_snapshot_render(sp_dragon* d, const sp_dragon_snapshot_desc* desc, sp_image* img, sp_error* err)
{
    sp_dragon_snapshot_desc o = desc ? *desc : (sp_dragon_snapshot_desc){0};
    sp_camera cam = o.camera ? *o.camera : sp_dragon_camera(d);
    sp_result res = sp_dragon_pose_at(d, o.t, err);
    if (res != SP_OK) return res;
    int n = sp_dragon_part_count(d);
    sp_vec3 lo, hi;
    if (sp_dragon_bounds(d, &lo, &hi)) sp_render_fit_depth(&cam, lo, hi);
    sp_headless* gl;
    if ((res = sp_headless_create(&gl, err)) != SP_OK) return res;
    sp_renderer* r;
    sp_render_target* t = NULL;
    res = sp_renderer_create(&(sp_renderer_desc){0}, &r, err);
    if (res == SP_OK) res = sp_render_target_create(cam.width, cam.height, 0, &t, err);
    sp_render_mesh** meshes = calloc((size_t)(n > 0 ? n : 1), sizeof *meshes);
    if (res != SP_OK) goto done;
    if (!meshes) {
        res = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory while rendering");
        goto done;
    }
    for (int i = 0; i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        const sp_rig* rig = &p->character->rig;
        if (rig->vertex_count <= 0 || rig->triangle_count <= 0) continue;
        const sp_mesh_desc md = sp_mesh_desc_of_rig(rig, sp_dragon_part_xyz(d, i), p->character->colors);
        if ((res = sp_render_mesh_create(r, &md, &meshes[i], err)) != SP_OK) goto done;
    }
    sp_render_target_bind(t);
    sp_renderer_begin(r, &cam, cam.width, cam.height);
    sp_renderer_clear(r, SP_COLOR_BACKGROUND_TOP, SP_COLOR_BACKGROUND_BOTTOM);
    if (n > 0 && sp_dragon_bounds(d, &lo, &hi)) sp_renderer_draw_ground_shadow(r, lo, hi, 0);
    for (int i = 0; i < n; ++i)
        if (meshes[i]) sp_renderer_draw_mesh(r, meshes[i], NULL);
    float line = (float)fmax(2.0, cam.height / 160.0);
    for (int i = 0; i < sp_dragon_detail_count(d); ++i) {
        sp_dragon_detail e;
        if (sp_dragon_detail_get(d, i, &e) && e.xyz)
            sp_renderer_draw_curve3d_facing(r, e.xyz, e.normal, e.point_count, line, SP_COLOR_INK);
    }
    for (int i = 0; o.strokes && i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        sp_renderer_draw_polyline(r, p->stroke_xy, p->stroke_points, false, SP_STROKE_UNDER_FIT * line, SP_COLOR_STROKE);
    }
    for (int i = 0; o.outlines && i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        sp_renderer_draw_abstraction(r, &p->character->rig.abstractions[p->abstraction], sp_dragon_part_outline(d, i), line,
                                     SP_COLOR_ABSTRACTION);
    }
    sp_renderer_end(r);
    res = sp_render_target_read(t, img, err);
done:
    for (int i = 0; meshes && i < n; ++i)
        sp_render_mesh_destroy(meshes[i]);
    free(meshes);
    sp_render_target_destroy(t);
    sp_renderer_destroy(r);
    sp_headless_destroy(gl);
    return res;
}

sp_result sp_dragon_snapshot_png(sp_dragon* d, const sp_dragon_snapshot_desc* desc, const char* path, sp_error* err)
{
    sp_image img = {0};
    sp_result r = sp_dragon_snapshot_render(d, desc, &img, err);
    if (r == SP_OK) r = sp_image_write_png(&img, path, err);
    sp_image_free(&img);
    return r;
}
