// part_preview.c: a part at rest and in three random poses, its abstraction overlaid, as one sheet.
#include "sp/part_preview.h"

#include <stdlib.h>
#include <string.h>

#include "sp/snapshot.h"
#include "sp/synth.h"

// Amplitude of the random poses: 45 degrees, as assets/gen/previews.sh.
#define PREVIEW_AMPLITUDE 0.7853981633974483

sp_result sp_part_preview_render(const sp_character* ch, int abstraction, sp_image* img, sp_error* err)
{
    const sp_rig* rig = &ch->rig;
    double* p = malloc(sizeof(double) * (size_t)(rig->param_count + 1));
    if (!p) return sp_fail(err, SP_ERR_NO_MEMORY, "preview: out of memory");
    sp_camera cam = sp_camera_resize(&ch->camera, SP_PREVIEW_PANEL_W, SP_PREVIEW_PANEL_H);
    sp_image panel[4];
    memset(panel, 0, sizeof panel);
    sp_result r = SP_OK;
    for (int k = 0; k < 4 && r == SP_OK; ++k) {
        sp_rig_defaults(rig, p);
        if (k > 0) {
            sp_synth_params(rig, (uint64_t)k, PREVIEW_AMPLITUDE, p);
            for (int q = 0; q < rig->param_count; ++q)
                if (rig->joints[rig->params[q].joint].parent < 0) p[q] = rig->params[q].def;
        }
        r = sp_snapshot_render(&(sp_snapshot_desc){.character = ch, .params = p, .camera = &cam, .abstraction = abstraction},
                               &panel[k], err);
    }
    if (r == SP_OK && (r = sp_image_sheet(panel, 4, 2, 6, img)) != SP_OK) r = sp_fail(err, r, "preview: out of memory");
    for (int k = 0; k < 4; ++k)
        sp_image_free(&panel[k]);
    free(p);
    return r;
}

sp_result sp_part_preview_png(const sp_character* ch, int abstraction, const char* path, sp_error* err)
{
    sp_image img = {0};
    sp_result r = sp_part_preview_render(ch, abstraction, &img, err);
    if (r == SP_OK) r = sp_image_write_png(&img, path, err);
    sp_image_free(&img);
    return r;
}
