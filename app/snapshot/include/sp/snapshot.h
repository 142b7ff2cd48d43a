/// snapshot.h: one posed character with its overlays, rendered headless to PNG.
///
/// Used by the commands that show a result (`pose`, `drawover`, `render`,
/// `dragon`): the character shaded at `params`, the user's strokes in blue,
/// the fitted abstraction in yellow, on the camera's canvas.
///
///     sp_snapshot_desc d = {.character = &ch, .params = p, .camera = &cam,
///                           .abstraction = 0, .strokes = &sketch};
///     if (sp_snapshot_png(&d, "out.png", &err) != SP_OK) ...
#ifndef SP_SNAPSHOT_H
#define SP_SNAPSHOT_H

#include "sp/gltf.h"
#include "sp/image.h"
#include "sp/sketch.h"

typedef struct sp_snapshot_desc {
    const sp_character* character;
    const double* params;        ///< rig.param_count; NULL: the character's pose
    const sp_camera* camera;     ///< the canvas is its width x height
    int abstraction;             ///< index of the abstraction to overlay, -1: none
    const sp_abstraction* extra_abstraction; ///< overlaid too if not NULL (e.g. a draw-over curve)
    const sp_sketch* strokes;    ///< blue overlay, may be NULL
    const sp_sketch* ghost;      ///< grey overlay (e.g. the draw-over source stroke), may be NULL
} sp_snapshot_desc;

/// The picture is the canvas scaled to at most SP_SNAPSHOT_MAX_SIDE pixels on
/// its longer side and, where that allows, SP_SNAPSHOT_MIN_SIDE on its
/// shorter: a stroke file's canvas (up to 1e6 px, an A4 drawing's viewBox of
/// 21000 x 29700) is a drawing's units, not a picture size. Its size here.
enum { SP_SNAPSHOT_MAX_SIDE = 4096, SP_SNAPSHOT_MIN_SIDE = 16 };
void sp_snapshot_size(const sp_camera* cam, int* w, int* h);

/// Renders to RGBA (img allocated by the call; sp_image_free it).
sp_result sp_snapshot_render(const sp_snapshot_desc* d, sp_image* img, sp_error* err);
/// Renders and writes a PNG.
sp_result sp_snapshot_png(const sp_snapshot_desc* d, const char* path, sp_error* err);

#endif
