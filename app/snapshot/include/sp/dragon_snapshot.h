/// dragon_snapshot.h: the whole dragon rendered headless to a PNG (the
/// `sketchpose dragon --render` picture): every part shaded at time t, the
/// details drawn on them in ink, the strokes in blue and the fitted outlines
/// in yellow on the drawing canvas.
///
///     sp_dragon_snapshot_png(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true}, "out.png", &err);
#ifndef SP_DRAGON_SNAPSHOT_H
#define SP_DRAGON_SNAPSHOT_H

#include "sp/dragon.h"
#include "sp/image.h"

typedef struct sp_dragon_snapshot_desc {
    double t;                ///< animation time, seconds (0: the loop's start; as fitted where a clip starts at rest)
    bool strokes;            ///< overlay each part's stroke in blue
    bool outlines;           ///< overlay each part's fitted abstraction in yellow
    const sp_camera* camera; ///< NULL: sp_dragon_camera (the canvas)
} sp_dragon_snapshot_desc;

/// Renders to RGBA (img allocated by the call; sp_image_free it). Poses the
/// dragon at desc->t (sp_dragon_pose_at). SP_ERR_UNSUPPORTED without EGL.
sp_result sp_dragon_snapshot_render(sp_dragon* d, const sp_dragon_snapshot_desc* desc, sp_image* img, sp_error* err);
/// Renders and writes a PNG.
sp_result sp_dragon_snapshot_png(sp_dragon* d, const sp_dragon_snapshot_desc* desc, const char* path, sp_error* err);

#endif
