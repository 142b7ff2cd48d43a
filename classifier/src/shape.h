/// shape.h (private): global shape descriptors of a drawing, the evidence the
/// bag of local features lacks.
///
/// The drawing's strokes, joined in drawing order, are resampled by arc length
/// and measured in their bounding box: open or closed, aspect and elongation,
/// the principal axis against the upright canvas (legs point down, wings up),
/// where the ink lies, solidity and convexity defects (how deep, and whether
/// they open downwards, upwards or sideways), the turning-angle histogram,
/// centroid-distance Fourier magnitudes, and how often the line visits each
/// side of its box. Every value is mirror-invariant (a part may face either
/// way) and finite; the vector is deterministic for a given drawing.
#ifndef SP_CLF_SHAPE_H
#define SP_CLF_SHAPE_H

#include "sp/result.h"
#include "sp/sketch.h"

/// Values in a shape descriptor.
#define SP_SHAPE_DIM 42
/// Arc-length samples the descriptors are measured on.
#define SP_SHAPE_SAMPLES 128

/// The shape descriptor of a stroke drawing (pixels, y down). Fails with
/// SP_ERR_INVALID on a drawing without points or with a non-finite
/// coordinate, SP_ERR_UNSUPPORTED beyond SP_SKETCH_MAX_POINTS points; a
/// drawing without extent (a dot) is described as one.
sp_result sp_shape_describe(const sp_sketch* s, float out[SP_SHAPE_DIM], sp_error* err);

/// The names of the descriptor's values, for reports and tests.
const char* sp_shape_feature_name(int i);

#endif
