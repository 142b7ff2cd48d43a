#include "sp/sketch.h"

#include <stdlib.h>
#include <string.h>

void sp_sketch_free(sp_sketch* s)
{
    if (!s) return;
    for (int i = 0; i < s->stroke_count; ++i) {
        free(s->strokes[i].points);
        free(s->strokes[i].t);
    }
    free(s->strokes);
    memset(s, 0, sizeof *s);
}

sp_result sp_sketch_add_stroke(sp_sketch* s, const sp_vec2* points, const double* t, int count)
{
    if (count < 0) return SP_ERR_INVALID;
    sp_stroke* grown = realloc(s->strokes, sizeof(sp_stroke) * (size_t)(s->stroke_count + 1));
    if (!grown) return SP_ERR_NO_MEMORY;
    s->strokes = grown;
    sp_stroke st = {count, malloc(sizeof(sp_vec2) * (size_t)(count ? count : 1)), NULL};
    if (!st.points) return SP_ERR_NO_MEMORY;
    if (count) memcpy(st.points, points, sizeof(sp_vec2) * (size_t)count);
    if (t) {
        st.t = malloc(sizeof(double) * (size_t)(count ? count : 1));
        if (!st.t) {
            free(st.points);
            return SP_ERR_NO_MEMORY;
        }
        if (count) memcpy(st.t, t, sizeof(double) * (size_t)count);
    }
    s->strokes[s->stroke_count++] = st;
    return SP_OK;
}

sp_result sp_sketch_clone(const sp_sketch* src, sp_sketch* dst)
{
    sp_sketch out = {src->canvas_w, src->canvas_h, 0, NULL};
    for (int i = 0; i < src->stroke_count; ++i) {
        sp_result r = sp_sketch_add_stroke(&out, src->strokes[i].points, src->strokes[i].t, src->strokes[i].count);
        if (r != SP_OK) {
            sp_sketch_free(&out);
            return r;
        }
    }
    *dst = out;
    return SP_OK;
}

int sp_sketch_point_count(const sp_sketch* s)
{
    int n = 0;
    for (int i = 0; i < s->stroke_count; ++i) n += s->strokes[i].count;
    return n;
}

bool sp_sketch_bounds(const sp_sketch* s, sp_vec2* lo, sp_vec2* hi)
{
    bool any = false;
    for (int i = 0; i < s->stroke_count; ++i)
        for (int j = 0; j < s->strokes[i].count; ++j) {
            sp_vec2 p = s->strokes[i].points[j];
            if (!any) {
                *lo = *hi = p;
                any = true;
            }
            if (p.x < lo->x) lo->x = p.x;
            if (p.y < lo->y) lo->y = p.y;
            if (p.x > hi->x) hi->x = p.x;
            if (p.y > hi->y) hi->y = p.y;
        }
    return any;
}

bool sp_sketch_is_valid(const sp_sketch* s)
{
    for (int i = 0; i < s->stroke_count; ++i)
        for (int j = 0; j < s->strokes[i].count; ++j) {
            if (!sp_v2_is_valid(s->strokes[i].points[j])) return false;
            if (s->strokes[i].t && !isfinite(s->strokes[i].t[j])) return false;
        }
    return true;
}

int sp_stroke_points_off_canvas(const sp_stroke* st, double w, double h)
{
    int off = 0;
    for (int k = 0; k < st->count; ++k) {
        sp_vec2 q = st->points[k];
        off += !(q.x >= 0 && q.x <= w && q.y >= 0 && q.y <= h);
    }
    return off;
}

// Why a fifth: gaps at closure are common in hand drawing (see the
// hand-drawing model of the classifier's training data).
bool sp_stroke_is_loop(const sp_stroke* st)
{
    if (st->count < 8) return false;
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int i = 0; i < st->count; ++i) {
        lx = fmin(lx, st->points[i].x), hx = fmax(hx, st->points[i].x);
        ly = fmin(ly, st->points[i].y), hy = fmax(hy, st->points[i].y);
    }
    double diag = hypot(hx - lx, hy - ly);
    sp_vec2 gap = sp_v2_sub(st->points[st->count - 1], st->points[0]);
    return diag > 0 && sp_v2_len(gap) <= 0.2 * diag;
}
