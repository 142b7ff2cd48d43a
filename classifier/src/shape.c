// shape.c: global shape descriptors of a drawing (shape.h).
#include "shape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cv_adapter.h"
#include "feat.h"
#include "sp/curve.h"
#include "sp/sketch_io.h"

static const char* const k_names[SP_SHAPE_DIM] = {
    "gap",           "log_aspect",      "elongation",      "axis_horizontal", "axis_diagonal",  "log_ink",     "centroid_side",
    "centroid_down", "ink_top",         "ink_middle_row",  "ink_bottom",      "ink_middle_col", "ink_lr",      "solidity",
    "hull_fill",     "defects_10",      "defects_25",      "defect_depth",    "defect_down",    "defect_up",   "defect_side",
    "defect_max",    "defect_max_side", "defect_max_down", "turn_0_20",       "turn_20_60",     "turn_60_120", "turn_120_180",
    "turn_total",    "turn_net",        "fourier_1",       "fourier_2",       "fourier_3",      "fourier_4",   "fourier_5",
    "fourier_6",     "fourier_7",       "fourier_8",       "runs_bottom",     "runs_top",       "runs_sides",  "runs_lr",
};

const char* sp_shape_feature_name(int i)
{
    return i >= 0 && i < SP_SHAPE_DIM ? k_names[i] : "?";
}

// Coarser samples for turning angles: the tremor of a hand is not a turn.
#define TURN_SAMPLES 48
// Integer units per bounding-box side for the hull (OpenCV's defects want integer points).
#define HULL_UNITS 1000
#define MAX_DEFECTS 64

// How often the samples enter a band of their box (a run starting at the first sample counts).
static int runs_in(const float* v, int n, float lo, float hi)
{
    int runs = 0;
    bool in = false;
    for (int i = 0; i < n; ++i) {
        bool now = v[i] >= lo && v[i] <= hi;
        runs += now && !in;
        in = now;
    }
    return runs < 8 ? runs : 8;
}

// Convexity: solidity, hull fill and the defects (depth in box sides, and where they open).
static sp_result convexity(const sp_vec2* u, int n, double bw, double bh, float* f, sp_error* err)
{
    int* xy = malloc(sizeof(int) * 2 * (size_t)n);
    if (!xy) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    for (int i = 0; i < n; ++i) {
        xy[2 * i] = (int)lround(u[i].x * HULL_UNITS);
        xy[2 * i + 1] = (int)lround(u[i].y * HULL_UNITS);
    }
    sp_cv_defect d[MAX_DEFECTS];
    int nd = 0;
    double area, hull;
    sp_result rc = sp_cv_convexity(xy, n, &area, &hull, d, MAX_DEFECTS, &nd, err);
    free(xy);
    if (rc != SP_OK) return rc;
    const double units2 = (double)HULL_UNITS * HULL_UNITS;
    f[13] = hull > 0 ? (float)fmin(area / hull, 1.0) : 1.0f;
    f[14] = bw * bh > 1e-9 ? (float)fmin(hull / units2 / (bw * bh), 1.0) : 0.0f;
    float deepest = 0;
    for (int k = 0; k < nd; ++k) {
        float depth = d[k].depth / HULL_UNITS;
        if (depth < 0.04f || d[k].far < 0 || d[k].far >= n || d[k].start < 0 || d[k].start >= n || d[k].end < 0 || d[k].end >= n)
            continue;
        // Where the notch opens: from its deepest point to the middle of the hull edge over it.
        sp_vec2 mid = sp_v2_scale(sp_v2_add(u[d[k].start], u[d[k].end]), 0.5);
        sp_vec2 dir = sp_v2_sub(mid, u[d[k].far]);
        double len = sp_v2_len(dir);
        double dx = len > 1e-9 ? fabs(dir.x) / len : 0, dy = len > 1e-9 ? dir.y / len : 0;
        f[15] += depth > 0.10f;
        f[16] += depth > 0.25f;
        f[17] += depth;
        f[18] += depth * (float)fmax(dy, 0);  // y down: opens downwards (between legs)
        f[19] += depth * (float)fmax(-dy, 0); // opens upwards
        f[20] += depth * (float)dx;
        if (depth > deepest) deepest = depth, f[21] = depth, f[22] = (float)dx, f[23] = (float)dy;
    }
    f[15] = fminf(f[15], 8), f[16] = fminf(f[16], 8);
    return SP_OK;
}

// Turning angles along the line: a histogram of their sizes, the total and the net turn (in turns).
static void turning(const sp_vec2* pts, int n, float* f)
{
    sp_vec2 r[TURN_SAMPLES];
    if (sp_curve_resample(pts, n, false, TURN_SAMPLES, r) != SP_OK) return;
    double total = 0, net = 0;
    int counted = 0;
    for (int i = 1; i + 1 < TURN_SAMPLES; ++i) {
        sp_vec2 a = sp_v2_sub(r[i], r[i - 1]), b = sp_v2_sub(r[i + 1], r[i]);
        if (sp_v2_len(a) < 1e-12 || sp_v2_len(b) < 1e-12) continue;
        double t = atan2(a.x * b.y - a.y * b.x, sp_v2_dot(a, b));
        double deg = fabs(t) * 180.0 / M_PI;
        f[deg < 20 ? 24 : deg < 60 ? 25 : deg < 120 ? 26 : 27] += 1;
        total += fabs(t), net += t;
        ++counted;
    }
    for (int k = 24; k < 28; ++k)
        f[k] = counted ? f[k] / (float)counted : 0;
    f[28] = (float)log1p(total / (2 * M_PI));
    f[29] = (float)fmin(fabs(net) / (2 * M_PI), 3.0);
}

// Centroid-distance Fourier magnitudes (start and direction do not matter; scaled by the mean distance).
static void fourier(const sp_vec2* u, int n, float* f)
{
    sp_vec2 c = {0, 0};
    for (int i = 0; i < n; ++i)
        c = sp_v2_add(c, u[i]);
    c = sp_v2_scale(c, 1.0 / n);
    double r[SP_SHAPE_SAMPLES], mean = 0;
    for (int i = 0; i < n; ++i)
        mean += r[i] = sp_v2_len(sp_v2_sub(u[i], c));
    mean /= n;
    if (!(mean > 1e-9)) return;
    for (int h = 1; h <= 8; ++h) {
        double re = 0, im = 0;
        for (int i = 0; i < n; ++i) {
            double a = 2 * M_PI * h * i / n;
            re += r[i] * cos(a), im -= r[i] * sin(a);
        }
        f[29 + h] = (float)(hypot(re, im) / (n * mean));
    }
}

// Everything measured on the arc-length samples `u` (box-side units, box corner at 0)
// of a drawing whose box is bw x bh box sides (one of them 1).
static sp_result describe_samples(const sp_vec2* u, double bw, double bh, double ink, float* f, sp_error* err)
{
    const int n = SP_SHAPE_SAMPLES;
    double diag = hypot(bw, bh);
    f[0] = (float)fmin(sp_v2_len(sp_v2_sub(u[n - 1], u[0])) / diag, 1.0);
    f[1] = (float)fmax(fmin(log((bw + 0.01) / (bh + 0.01)), 2.5), -2.5);
    sp_vec2 m = {0, 0};
    for (int i = 0; i < n; ++i)
        m = sp_v2_add(m, u[i]);
    m = sp_v2_scale(m, 1.0 / n);
    double cxx = 0, cyy = 0, cxy = 0;
    for (int i = 0; i < n; ++i) {
        sp_vec2 d = sp_v2_sub(u[i], m);
        cxx += d.x * d.x, cyy += d.y * d.y, cxy += d.x * d.y;
    }
    double tr = cxx + cyy, det = cxx * cyy - cxy * cxy, disc = sqrt(fmax(tr * tr / 4 - det, 0));
    double l1 = tr / 2 + disc, l2 = tr / 2 - disc;
    double e = l1 > 1e-12 ? 1 - fmax(l2, 0) / l1 : 0, th2 = atan2(2 * cxy, cxx - cyy);
    f[2] = (float)e, f[3] = (float)(e * cos(th2)), f[4] = (float)(e * fabs(sin(th2)));
    f[5] = (float)fmax(fmin(log(ink / diag), 4.0), -1.0);
    // Where the ink lies in its box (x folded about the middle: either facing).
    float bx[SP_SHAPE_SAMPLES], by[SP_SHAPE_SAMPLES];
    double sx = 0, sy = 0;
    int left = 0, right = 0, mid_col = 0, rows[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
        bx[i] = bw > 1e-9 ? (float)(u[i].x / bw) : 0.5f;
        by[i] = bh > 1e-9 ? (float)(u[i].y / bh) : 0.5f;
        sx += bx[i], sy += by[i];
        left += bx[i]<1.0f / 3, right += bx[i]> 2.0f / 3, mid_col += bx[i] >= 1.0f / 3 && bx[i] <= 2.0f / 3;
        rows[by[i] < 1.0f / 3 ? 0 : by[i] <= 2.0f / 3 ? 1 : 2]++;
    }
    f[6] = (float)fabs(sx / n - 0.5), f[7] = (float)(sy / n - 0.5);
    f[8] = (float)rows[0] / n, f[9] = (float)rows[1] / n, f[10] = (float)rows[2] / n;
    f[11] = (float)mid_col / n, f[12] = (float)abs(left - right) / n;
    sp_result rc = convexity(u, n, bw, bh, f, err);
    if (rc != SP_OK) return rc;
    turning(u, n, f);
    fourier(u, n, f);
    f[38] = (float)runs_in(by, n, 0.8f, 1.0f);
    f[39] = (float)runs_in(by, n, 0.0f, 0.2f);
    int rl = runs_in(bx, n, 0.0f, 0.2f), rr = runs_in(bx, n, 0.8f, 1.0f);
    f[40] = (float)(rl + rr), f[41] = (float)abs(rl - rr);
    return SP_OK;
}

sp_result sp_shape_describe(const sp_sketch* s, float out[SP_SHAPE_DIM], sp_error* err)
{
    memset(out, 0, sizeof(float) * SP_SHAPE_DIM);
    int total;
    sp_vec2 lo, hi;
    sp_result rc = sp_feat_check_drawing(s, &total, &lo, &hi, err);
    if (rc != SP_OK) return rc;
    double side = fmax(hi.x - lo.x, hi.y - lo.y);
    if (!(side > 1e-9) || !isfinite(side)) return SP_OK; // a dot: nothing to measure
    // The strokes joined in drawing order, in box-side units from the box corner.
    sp_vec2* p = malloc(sizeof(sp_vec2) * (size_t)total);
    sp_vec2* u = malloc(sizeof(sp_vec2) * SP_SHAPE_SAMPLES);
    if (!p || !u) {
        free(p);
        free(u);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    int k = 0;
    for (int i = 0; i < s->stroke_count; ++i)
        for (int j = 0; j < s->strokes[i].count; ++j)
            p[k++] = sp_v2_scale(sp_v2_sub(s->strokes[i].points[j], lo), 1.0 / side);
    double ink = sp_curve_length(p, k, false);
    rc = sp_curve_resample(p, k, false, SP_SHAPE_SAMPLES, u);
    if (rc != SP_OK) rc = sp_fail(err, rc, "drawing cannot be resampled");
    if (rc == SP_OK) rc = describe_samples(u, (hi.x - lo.x) / side, (hi.y - lo.y) / side, ink, out, err);
    free(p);
    free(u);
    for (int i = 0; i < SP_SHAPE_DIM; ++i)
        if (!isfinite(out[i])) out[i] = 0; // never NaN into a model, whatever the arithmetic met
    return rc;
}
