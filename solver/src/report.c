// report.c: the solve report's 2D errors at the result.
#include <stdlib.h>

#include "solver_internal.h"

// The polyline distances of closest pairs (see sp__fill_errors): queries of
// direction `dir` (and curve `curve` for dir 0) against polylines p/next.
// Leaves d[] alone for other pairs or when out of memory (d is then the
// sample-to-sample distance, an upper bound).
static void polyline_errors(const sp_solver* s, int dir, int curve, const sp_vec2* p, const int* next, int n, double* d)
{
    sp_vec2* q = malloc(sizeof(sp_vec2) * (size_t)(s->pair_count + 1));
    int* which = malloc(sizeof(int) * (size_t)(s->pair_count + 1));
    double* out = malloc(sizeof(double) * (size_t)(s->pair_count + 1));
    int nq = 0;
    for (int i = 0; q && which && out && i < s->pair_count; ++i) {
        const pair* pr = &s->pairs[i];
        if (pr->dir != dir || (dir == 0 && pr->curve != curve)) continue;
        which[nq] = i;
        q[nq++] = dir == 0 ? pr->y : sp__sample_at(s, pr->s);
    }
    if (nq > 0 && sp_polyline_distances(p, next, n, q, nq, out) == SP_OK)
        for (int k = 0; k < nq; ++k)
            d[which[k]] = fmin(d[which[k]], out[k]);
    free(q), free(which), free(out);
}

// The report's 2D errors. Ordered pairs: the distance between corresponding
// samples. Closest pairs: the distance of each sample to the other side's
// polyline, not to its nearest sample: two samplings of the same curve are
// up to half a spacing apart, which would put a floor of about 0.7% of the
// diagonal under every closest-point fit (seen on the dragon outlines).
void sp__fill_errors(sp_solver* s, sp_correspondence mode, sp_solve_report* rep)
{
    double sum = 0, mx = 0;
    double csum[SP_REPORT_CURVES] = {0}, cmax[SP_REPORT_CURVES] = {0};
    int cn[SP_REPORT_CURVES] = {0};
    // Out of memory, d stays NULL and every pair keeps its sample distance.
    double* d = malloc(sizeof(double) * (size_t)(s->pair_count + 1));
    for (int i = 0; d && i < s->pair_count; ++i)
        d[i] = sp_v2_len(sp_v2_sub(sp__sample_at(s, s->pairs[i].s), s->pairs[i].y));
    const int l = s->ab->point_count, ny = s->ypoly_count;
    int* next = d && mode == SP_CORR_CLOSEST ? malloc(sizeof(int) * (size_t)(l > ny ? l + 1 : ny + 1)) : NULL;
    sp_vec2* z = next ? malloc(sizeof(sp_vec2) * (size_t)(l + 1)) : NULL;
    if (next && z) {
        // Stroke samples to their curve's projected polyline.
        for (int c = 0; c < s->ab->curve_count; ++c) {
            const sp_curve* cv = &s->ab->curves[c];
            for (int k = 0; k < cv->point_count; ++k) {
                next[k] = k + 1 < cv->point_count ? k + 1 : (cv->closed && k > 0 ? 0 : -1);
                z[k] = (sp_vec2){s->z2[2 * (cv->first_point + k)], s->z2[2 * (cv->first_point + k) + 1]};
            }
            polyline_errors(s, 0, c, z, next, cv->point_count, d);
        }
        // Curve samples to the resampled strokes (consecutive samples of one stroke are joined).
        for (int k = 0; k < ny; ++k)
            next[k] = k + 1 < ny && s->ypoly_stroke[k + 1] == s->ypoly_stroke[k] ? k + 1 : -1;
        if (ny > 0) polyline_errors(s, 1, -1, s->ypoly, next, ny, d);
    }
    free(next), free(z);
    for (int i = 0; i < s->pair_count; ++i) {
        double di = d ? d[i] : sp_v2_len(sp_v2_sub(sp__sample_at(s, s->pairs[i].s), s->pairs[i].y));
        sum += di;
        if (di > mx) mx = di;
        int c = s->pairs[i].curve;
        if (c >= 0 && c < SP_REPORT_CURVES) {
            csum[c] += di, cn[c]++;
            if (di > cmax[c]) cmax[c] = di;
        }
    }
    free(d);
    rep->mean_error_px = s->pair_count ? sum / s->pair_count : 0;
    rep->max_error_px = mx;
    for (int c = 0; c < rep->curve_count; ++c) {
        rep->curves[c].mean_px = cn[c] ? csum[c] / cn[c] : 0;
        rep->curves[c].max_px = cmax[c];
    }
}
