/// part_preview.h: a curator's picture of a part: its mesh with a sketch
/// abstraction overlaid (yellow), at rest and in three random poses within
/// its bounds, as one 2 x 2 sheet (what `sketchpose derive --preview` and
/// `db add-part --preview` write; assets/gen/previews.sh makes the shipped
/// parts' sheets the same way).
///
///     if (sp_part_preview_png(&ch, abstraction, "fox.png", &err) != SP_OK) ...
#ifndef SP_PART_PREVIEW_H
#define SP_PART_PREVIEW_H

#include "sp/image.h"
#include "sp/gltf.h"

/// Panel size of the sheet, pixels (the sheet adds 6 px gaps).
enum { SP_PREVIEW_PANEL_W = 560, SP_PREVIEW_PANEL_H = 420 };

/// Renders the sheet into *img (allocated; sp_image_free it): panel 0 the
/// rest pose, panels 1-3 `sp_synth_params` seeds 1-3 at amplitude 45 degrees
/// (shapes anywhere within bounds) with every root joint's parameters (the
/// placement) kept at rest, so the part stays in the picture. Each panel is
/// the part's sketch view on the panel. SP_ERR_UNSUPPORTED without EGL.
sp_result sp_part_preview_render(const sp_character* ch, int abstraction, sp_image* img, sp_error* err);
/// Renders and writes a PNG.
sp_result sp_part_preview_png(const sp_character* ch, int abstraction, const char* path, sp_error* err);

#endif
