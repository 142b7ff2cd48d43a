/// sp/sketch.h: strokes and sketches, the 2D input every module shares.
///
/// A stroke is a polyline in pixels (origin top-left, y down) with optional
/// timestamps; a sketch is a list of strokes on a canvas. All arrays are
/// malloc'd and owned by the sketch (sp_sketch_free).
#ifndef SP_SKETCH_H
#define SP_SKETCH_H

#include <stdbool.h>

#include "sp/math.h"
#include "sp/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sp_stroke {
    int count;
    sp_vec2* points; ///< count points, pixels
    double* t;       ///< count timestamps in ms, or NULL
} sp_stroke;

typedef struct sp_sketch {
    double canvas_w, canvas_h; ///< pixels; 0 when unknown
    int stroke_count;
    sp_stroke* strokes;
} sp_sketch;

/// Frees every stroke and zeroes the sketch.
void sp_sketch_free(sp_sketch* s);
/// Appends a copy of `count` points (and times, may be NULL). Returns SP_ERR_NO_MEMORY on failure.
sp_result sp_sketch_add_stroke(sp_sketch* s, const sp_vec2* points, const double* t, int count);
/// Deep copy.
sp_result sp_sketch_clone(const sp_sketch* src, sp_sketch* dst);
/// Total number of points over all strokes.
int sp_sketch_point_count(const sp_sketch* s);
/// Bounding box of all points; false if the sketch has no points.
bool sp_sketch_bounds(const sp_sketch* s, sp_vec2* lo, sp_vec2* hi);
/// True when every coordinate (and time) is finite.
bool sp_sketch_is_valid(const sp_sketch* s);
/// Points of the stroke outside the w x h canvas [0, w] x [0, h] (a point
/// that is not finite counts as outside).
int sp_stroke_points_off_canvas(const sp_stroke* st, double w, double h);
/// Whether a stroke is drawn as a loop: at least 8 points, its ends within a
/// fifth of its bounding box's diagonal (people leave gaps when they close
/// an outline). The solver matches a loop to a closed outline in order first.
bool sp_stroke_is_loop(const sp_stroke* st);

#ifdef __cplusplus
}
#endif
#endif
