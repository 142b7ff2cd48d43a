/// feat.h (private): sketch normalisation, rasterisation and Eitz-style local descriptors.
///
/// A drawing is fitted to its bounding box inside a 256x256 frame (aspect kept,
/// centred), drawn anti-aliased, and described on a 28x28 grid of sample points
/// by 4x4 spatial cells x 4 unsigned orientation bins (64-D) over square patches
/// of 12.5% of the frame area (Eitz, Hays, Alexa 2012). Patches without ink are
/// skipped; each descriptor is L2-normalised.
#ifndef SP_CLF_FEATURES_H
#define SP_CLF_FEATURES_H

#include "sp/result.h"
#include "sp/sketch.h"
#include "sp/sketch_io.h"

#define SP_FEAT_DIM 64
#define SP_FEAT_GRID 28
#define SP_FEAT_MAX (SP_FEAT_GRID * SP_FEAT_GRID)
/// The frame the sketch is normalised into, and the margin around it that keeps
/// every patch of a border sample point inside the image.
#define SP_FEAT_FRAME 256
#define SP_FEAT_MARGIN 48
#define SP_FEAT_CANVAS (SP_FEAT_FRAME + 2 * SP_FEAT_MARGIN)
/// The sketch's bounding box is fitted into the frame minus this inner padding a side.
#define SP_FEAT_PAD 8
/// Stroke thickness when rasterising, pixels of the 256 frame.
#define SP_FEAT_THICKNESS 3

/// The orientation maps are computed at half the canvas's resolution.
#define SP_FEAT_MAP_DOWN 2
#define SP_FEAT_MAP_N (SP_FEAT_CANVAS / SP_FEAT_MAP_DOWN)

/// The memory describing one drawing works in (about 1.1 MB). A caller that
/// describes many drawings keeps one per thread: memory that large, fresh
/// from the system for each drawing, costs more in page faults than the
/// description costs in work.
typedef struct sp_feat_scratch {
    unsigned char canvas[SP_FEAT_CANVAS * SP_FEAT_CANVAS];
    float maps[4 * SP_FEAT_MAP_N * SP_FEAT_MAP_N];
    unsigned integral[(SP_FEAT_CANVAS + 1) * (SP_FEAT_CANVAS + 1)];
} sp_feat_scratch;

typedef struct sp_features {
    int count;                             ///< descriptors kept (non-empty patches)
    float desc[SP_FEAT_MAX * SP_FEAT_DIM]; ///< count by 64, L2-normalised, non-negative
    float pos[SP_FEAT_MAX * 2];            ///< count by 2, sample point in [0,1]^2 of the frame
} sp_features;

/// What every stroke drawing must be before it is described: it has points, at
/// most SP_SKETCH_MAX_POINTS (SP_ERR_UNSUPPORTED), all finite (SP_ERR_INVALID
/// otherwise); *total gets its point count, *lo and *hi its bounding box.
sp_result sp_feat_check_drawing(const sp_sketch* s, int* total, sp_vec2* lo, sp_vec2* hi, sp_error* err);
/// Draws a sketch, normalised to the frame, into a SP_FEAT_CANVAS^2 image (ink bright).
/// Fails with SP_ERR_INVALID on an empty or non-finite sketch.
sp_result sp_feat_rasterise(const sp_sketch* s, unsigned char* canvas, sp_error* err);
/// Fits a grey raster (dark ink) into the canvas the same way.
sp_result sp_feat_rasterise_raster(const sp_raster* r, unsigned char* canvas, sp_error* err);
/// Descriptors of a rasterised canvas (which may be scratch->canvas).
sp_result sp_feat_describe(const unsigned char* canvas, sp_feat_scratch* scratch, sp_features* out, sp_error* err);
/// Rasterise (sketch, or raster when sketch has no strokes and raster has
/// pixels) and describe; scratch NULL: one is allocated for this call.
sp_result sp_feat_extract(const sp_sketch* s, const sp_raster* r, sp_feat_scratch* scratch, sp_features* out, sp_error* err);

#endif
