// picture.c: a small picture of where the line runs which way (picture.h).
#include "picture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cv_adapter.h"
#include "feat.h"
#include "sp/curve.h"

#define GRID 24 // cells a side before the blur and the halving
#define PLANES 5
// Samples per bounding-box diagonal: a few per cell, so that every cell the
// line crosses gets a segment.
#define STEPS_PER_DIAGONAL 100.0
// Samples per drawing at most: a scribble's ink is many diagonals long.
#define MAX_SAMPLES 4096
// The grid spans this many root-mean-square radii each side of the centroid.
#define SPAN 2.5
// Blur in cells of the 24 x 24 grid: a line one cell off still overlaps.
#define BLUR_SIGMA 1.0

typedef struct grid {
    float cell[PLANES][GRID * GRID];
    sp_vec2 c;     // centroid
    double scale;  // grid cells per pixel
    double mirror; // -1 mirrored, 1 not
} grid;

static int cell_of(const grid* g, sp_vec2 p)
{
    double x = (g->mirror * (p.x - g->c.x)) * g->scale + GRID / 2.0, y = (p.y - g->c.y) * g->scale + GRID / 2.0;
    int i = (int)floor(x), j = (int)floor(y);
    i = i < 0 ? 0 : i >= GRID ? GRID - 1 : i;
    j = j < 0 ? 0 : j >= GRID ? GRID - 1 : j;
    return j * GRID + i;
}

// One resampled stroke: each segment marks its middle's cell in the direction
// planes (1 along a plane's direction, falling to 0 at 45 degrees off), the
// ends mark theirs in the fifth plane.
static void mark(grid* g, const sp_vec2* u, int m)
{
    static const double ref[4] = {0.0, M_PI / 4, M_PI / 2, 3 * M_PI / 4};
    for (int i = 0; i + 1 < m; ++i) {
        double dx = g->mirror * (u[i + 1].x - u[i].x), dy = u[i + 1].y - u[i].y;
        if (dx == 0.0 && dy == 0.0) continue;
        double th = fmod(atan2(dy, dx) + M_PI, M_PI);
        int at = cell_of(g, sp_v2_scale(sp_v2_add(u[i], u[i + 1]), 0.5));
        for (int k = 0; k < 4; ++k) {
            double d = fabs(th - ref[k]);
            d = fmin(d, M_PI - d);
            float w = (float)fmax(0.0, 1.0 - d / (M_PI / 4));
            if (w > g->cell[k][at]) g->cell[k][at] = w;
        }
    }
    g->cell[4][cell_of(g, u[0])] = 1.0f;
    g->cell[4][cell_of(g, u[m - 1])] = 1.0f;
}

sp_result sp_picture_describe(const sp_sketch* s, bool mirrored, float out[SP_PICTURE_DIM], sp_error* err)
{
    memset(out, 0, sizeof(float) * SP_PICTURE_DIM);
    int total;
    sp_vec2 lo, hi;
    sp_result rc = sp_feat_check_drawing(s, &total, &lo, &hi, err);
    if (rc != SP_OK) return rc;
    double diag = sp_v2_len(sp_v2_sub(hi, lo)), ink = 0.0;
    for (int i = 0; i < s->stroke_count; ++i)
        ink += sp_curve_length(s->strokes[i].points, s->strokes[i].count, false);
    double step = fmax(diag / STEPS_PER_DIAGONAL, ink / MAX_SAMPLES);
    grid* g = calloc(1, sizeof *g);
    sp_vec2* u = malloc(sizeof(sp_vec2) * (MAX_SAMPLES + 2 * (size_t)s->stroke_count));
    int* first = malloc(sizeof(int) * ((size_t)s->stroke_count + 1));
    if (!g || !u || !first) {
        rc = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    // Resampled strokes one after another (first[i]: where stroke i starts),
    // then their centroid and spread.
    int n = 0;
    for (int i = 0; i < s->stroke_count; ++i) {
        const sp_stroke* st = &s->strokes[i];
        first[i] = n;
        if (st->count == 0) continue;
        double len = sp_curve_length(st->points, st->count, false);
        int m = step > 0.0 && isfinite(len / step) ? 1 + (int)fmin(len / step, MAX_SAMPLES) : 1;
        if (m < 2) m = 2;
        if ((rc = sp_curve_resample(st->points, st->count, false, m, u + n)) != SP_OK) {
            rc = sp_fail(err, rc, "drawing cannot be resampled");
            goto done;
        }
        n += m;
    }
    first[s->stroke_count] = n;
    sp_vec2 c = {0, 0};
    for (int i = 0; i < n; ++i)
        c = sp_v2_add(c, u[i]);
    c = sp_v2_scale(c, 1.0 / n);
    double r2 = 0.0;
    for (int i = 0; i < n; ++i) {
        sp_vec2 d = sp_v2_sub(u[i], c);
        r2 += (d.x * d.x + d.y * d.y) / n;
    }
    g->c = c;
    g->mirror = mirrored ? -1.0 : 1.0;
    g->scale = r2 > 1e-18 ? GRID / (2.0 * SPAN * sqrt(r2)) : 0.0; // a dot: every sample in the middle cell
    for (int i = 0; i < s->stroke_count; ++i)
        if (first[i + 1] > first[i]) mark(g, u + first[i], first[i + 1] - first[i]);
    rc = sp_cv_blur_halve(&g->cell[0][0], PLANES, GRID, BLUR_SIGMA, out, err);
done:
    free(g);
    free(u);
    free(first);
    return rc;
}
