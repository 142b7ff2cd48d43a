// features.c: normalise, rasterise, describe (Eitz 2012 local orientation descriptors).
#include "feat.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cv_adapter.h"

sp_result sp_feat_check_drawing(const sp_sketch* s, int* total, sp_vec2* lo, sp_vec2* hi, sp_error* err)
{
    *total = sp_sketch_point_count(s);
    if (*total == 0) return sp_fail(err, SP_ERR_INVALID, "empty drawing (no points)");
    if (*total > SP_SKETCH_MAX_POINTS)
        return sp_fail(err, SP_ERR_UNSUPPORTED, "drawing has more than %d points", SP_SKETCH_MAX_POINTS);
    if (!sp_sketch_is_valid(s)) return sp_fail(err, SP_ERR_INVALID, "drawing has non-finite coordinates");
    sp_sketch_bounds(s, lo, hi);
    return SP_OK;
}

sp_result sp_feat_rasterise(const sp_sketch* s, unsigned char* canvas, sp_error* err)
{
    int total;
    sp_vec2 lo, hi;
    sp_result rc = sp_feat_check_drawing(s, &total, &lo, &hi, err);
    if (rc != SP_OK) return rc;
    double ext = fmax(hi.x - lo.x, hi.y - lo.y);
    const double fit = SP_FEAT_FRAME - 2 * SP_FEAT_PAD;
    // A single dot (or all points equal) has no extent: draw it as a dot in the middle.
    double scale = ext > 1e-12 ? fit / ext : 1.0;
    double cx = 0.5 * (lo.x + hi.x), cy = 0.5 * (lo.y + hi.y);
    const double mid = 0.5 * SP_FEAT_CANVAS;
    float* xy = malloc(sizeof(float) * 2 * (size_t)total);
    int* counts = malloc(sizeof(int) * (size_t)(s->stroke_count ? s->stroke_count : 1));
    if (!xy || !counts) {
        free(xy);
        free(counts);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory rasterising");
    }
    int k = 0, nl = 0;
    for (int i = 0; i < s->stroke_count; ++i) {
        const sp_stroke* st = &s->strokes[i];
        if (st->count == 0) continue;
        for (int j = 0; j < st->count; ++j) {
            xy[2 * k] = (float)(mid + (st->points[j].x - cx) * scale);
            xy[2 * k + 1] = (float)(mid + (st->points[j].y - cy) * scale);
            ++k;
        }
        counts[nl++] = st->count;
    }
    rc = sp_cv_draw_polylines(xy, counts, nl, SP_FEAT_CANVAS, SP_FEAT_THICKNESS, canvas, err);
    free(xy);
    free(counts);
    return rc;
}

sp_result sp_feat_rasterise_raster(const sp_raster* r, unsigned char* canvas, sp_error* err)
{
    if (!r->pixels || r->w <= 0 || r->h <= 0) return sp_fail(err, SP_ERR_INVALID, "empty raster");
    return sp_cv_fit_raster(r->pixels, r->w, r->h, SP_FEAT_CANVAS, SP_FEAT_MARGIN + SP_FEAT_PAD, SP_FEAT_FRAME - 2 * SP_FEAT_PAD,
                            canvas, err);
}

static inline float bilinear(const float* m, int n, float x, float y)
{
    if (x < 0) x = 0;
    if (y < 0) y = 0;
    if (x > n - 1.001f) x = n - 1.001f;
    if (y > n - 1.001f) y = n - 1.001f;
    int ix = (int)x, iy = (int)y;
    float fx = x - ix, fy = y - iy;
    const float* r0 = m + (size_t)iy * n + ix;
    const float* r1 = r0 + n;
    return (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
}

enum { MAP_DOWN = SP_FEAT_MAP_DOWN, MAP_N = SP_FEAT_MAP_N };

sp_result sp_feat_describe(const unsigned char* canvas, sp_feat_scratch* scratch, sp_features* out, sp_error* err)
{
    const int C = SP_FEAT_CANVAS;
    // Patch side: 12.5% of the frame's area; 4x4 cells inside it.
    const float patch = (float)(SP_FEAT_FRAME * sqrt(0.125));
    const float cell = patch / 4.0f;
    float* maps = scratch->maps;
    unsigned* integral = scratch->integral;
    // Why Gaussian-smoothed responses sampled at cell centres: this is the
    // paper's soft spatial binning, and costs 4 blurs instead of a loop over
    // every pixel of 784 overlapping patches.
    sp_result rc = sp_cv_orientation_maps(canvas, C, MAP_DOWN, 0.5 * cell / MAP_DOWN, maps, err);
    if (rc != SP_OK) return rc;
    for (int x = 0; x <= C; ++x)
        integral[x] = 0;
    for (int y = 0; y < C; ++y) {
        unsigned row = 0;
        unsigned* dst = integral + (size_t)(y + 1) * (C + 1);
        const unsigned* up = dst - (C + 1);
        dst[0] = 0;
        for (int x = 0; x < C; ++x) {
            row += canvas[(size_t)y * C + x];
            dst[x + 1] = up[x + 1] + row;
        }
    }
    out->count = 0;
    const float step = (float)SP_FEAT_FRAME / SP_FEAT_GRID;
    const int half = (int)(patch * 0.5f);
    for (int gy = 0; gy < SP_FEAT_GRID; ++gy)
        for (int gx = 0; gx < SP_FEAT_GRID; ++gx) {
            float px = SP_FEAT_MARGIN + (gx + 0.5f) * step, py = SP_FEAT_MARGIN + (gy + 0.5f) * step;
            int x0 = (int)px - half, y0 = (int)py - half, x1 = (int)px + half, y1 = (int)py + half;
            if (x0 < 0) x0 = 0;
            if (y0 < 0) y0 = 0;
            if (x1 > C) x1 = C;
            if (y1 > C) y1 = C;
            unsigned ink = integral[(size_t)y1 * (C + 1) + x1] - integral[(size_t)y0 * (C + 1) + x1] -
                           integral[(size_t)y1 * (C + 1) + x0] + integral[(size_t)y0 * (C + 1) + x0];
            if (ink < 255u * 4u) continue; // empty patch: nothing drawn there
            float* d = out->desc + (size_t)out->count * SP_FEAT_DIM;
            double norm = 0.0;
            for (int cy = 0; cy < 4; ++cy)
                for (int cx = 0; cx < 4; ++cx) {
                    float sx = (px + (cx - 1.5f) * cell) / MAP_DOWN, sy = (py + (cy - 1.5f) * cell) / MAP_DOWN;
                    for (int b = 0; b < 4; ++b) {
                        float v = bilinear(maps + (size_t)b * MAP_N * MAP_N, MAP_N, sx, sy);
                        if (v < 0) v = 0; // blur ringing never makes a response negative, but be exact
                        d[(cy * 4 + cx) * 4 + b] = v;
                        norm += (double)v * v;
                    }
                }
            if (!(norm > 1e-12)) continue;
            float inv = (float)(1.0 / sqrt(norm));
            for (int i = 0; i < SP_FEAT_DIM; ++i)
                d[i] *= inv;
            out->pos[2 * out->count] = (px - SP_FEAT_MARGIN) / SP_FEAT_FRAME;
            out->pos[2 * out->count + 1] = (py - SP_FEAT_MARGIN) / SP_FEAT_FRAME;
            ++out->count;
        }
    return SP_OK;
}

sp_result sp_feat_extract(const sp_sketch* s, const sp_raster* r, sp_feat_scratch* scratch, sp_features* out, sp_error* err)
{
    sp_feat_scratch* own = scratch ? NULL : malloc(sizeof *own);
    if (!scratch && !(scratch = own)) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    unsigned char* canvas = scratch->canvas;
    sp_result rc;
    if (s && s->stroke_count > 0)
        rc = sp_feat_rasterise(s, canvas, err);
    else if (r && r->pixels)
        rc = sp_feat_rasterise_raster(r, canvas, err);
    else
        rc = sp_fail(err, SP_ERR_INVALID, "empty drawing (no strokes)");
    if (rc == SP_OK) rc = sp_feat_describe(canvas, scratch, out, err);
    if (rc == SP_OK && out->count == 0) rc = sp_fail(err, SP_ERR_INVALID, "drawing has no ink to describe");
    free(own);
    return rc;
}
