/// cv_adapter.h: the classifier's only door to OpenCV (implemented in cv_adapter.cpp).
///
/// Pure C; no OpenCV type crosses it. Every function catches every exception
/// and turns it into an sp_result (cv::Exception -> SP_ERR_INTERNAL with its
/// message, std::bad_alloc -> SP_ERR_NO_MEMORY).
#ifndef SP_CV_ADAPTER_H
#define SP_CV_ADAPTER_H

#include <stdbool.h>
#include <stddef.h>

#include "sp/result.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Draws polylines anti-aliased in white on a black `size` x `size` 8-bit image.
/// xy: total points by 2 (pixels, already in image coordinates); counts: points per
/// polyline. thickness in pixels. out: size*size bytes (row-major).
sp_result sp_cv_draw_polylines(const float* xy, const int* counts, int polylines, int size, int thickness, unsigned char* out,
                               sp_error* err);

/// Grey pixels of a decoded image, alpha composited over white. samples: w*h
/// pixels of `channels` (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA) interleaved,
/// 8 bits each, or 16 when wide (scaled to 8 by 1/257). *pixels is malloc'd
/// (free()), w*h bytes. `name` is for messages.
sp_result sp_cv_grey(const void* samples, int w, int h, int channels, bool wide, const char* name, unsigned char** pixels,
                     sp_error* err);

/// Fits the ink of a grey raster (0 = ink, 255 = paper) into the box [pad, pad+fit) of a
/// `size` x `size` image keeping aspect, centred, ink white on black (like sp_cv_draw_polylines).
/// Returns SP_ERR_INVALID when the raster has no ink.
sp_result sp_cv_fit_raster(const unsigned char* grey, int w, int h, int size, int pad, int fit, unsigned char* out,
                           sp_error* err);

/// Orientation responses of an ink image (size x size, ink bright): gradient magnitude split
/// into 4 unsigned orientation bins (0, 45, 90, 135 degrees, linear interpolation between
/// bins), downsampled by `down` (1 or 2) and Gaussian-smoothed with `sigma` (in output pixels).
/// maps: 4 planes of (size/down)^2 floats, plane-major.
sp_result sp_cv_orientation_maps(const unsigned char* img, int size, int down, double sigma, float* maps, sp_error* err);

/// Blurs each of `count` planes (size x size floats, plane-major) with a
/// Gaussian of `sigma` pixels (reflected at the borders, 4 sigma wide each
/// side) and halves it by averaging 2 x 2 blocks: out is count planes of
/// (size/2)^2. size must be even.
sp_result sp_cv_blur_halve(const float* planes, int count, int size, double sigma, float* out, sp_error* err);

/// Dot products of every row of `a` (n by dim) with every row of `b` (k by dim):
/// out is n by k, row-major (OpenCV's gemm: several times faster than a
/// hand-vectorised scan on this machine; BENCHMARKS.md, "Quick, Draw! 100 categories").
sp_result sp_cv_dot_rows(const float* a, int n, const float* b, int k, int dim, float* out, sp_error* err);

/// One convexity defect of a polygon: the hull edge from point `start` to point
/// `end` (indices into the polygon) and the polygon's point `far` between them
/// deepest inside the hull, `depth` from the edge (the polygon's units).
typedef struct sp_cv_defect {
    int start, end, far;
    float depth;
} sp_cv_defect;

/// Convex hull and convexity defects of a polygon (xy: n points by 2, integer
/// coordinates stored as int, n >= 4; the last point joins the first; it may
/// cross itself). *area: the polygon's area (its absolute shoelace sum, crossings
/// counted as they wind), *hull_area the hull's. defects: at most `max` of them,
/// in polygon order, *count written.
sp_result sp_cv_convexity(const int* xy, int n, double* area, double* hull_area, sp_cv_defect* defects, int max, int* count,
                          sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
