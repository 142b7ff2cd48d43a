// outline.c: the side-view silhouette of a rest mesh as a skinned closed curve
// (sp/outline.h). Moved here from the asset generator, which calls it for the
// shipped parts: any change to the arithmetic changes their bytes (the
// `assets_regenerate_identical` test).
#include "sp/outline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CELLS = 1000, MARGIN = 6 };

typedef struct grid {
    int w, h;
    unsigned char* c; // 1 inside
} grid;

void sp_skin8_add(sp_skin8* s, int joint, double w)
{
    if (!(w > 0.0)) return;
    for (int i = 0; i < s->n; ++i)
        if (s->joint[i] == joint) {
            s->w[i] += w;
            return;
        }
    if (s->n < SP_OUTLINE_INFLUENCES_MAX) {
        s->joint[s->n] = joint, s->w[s->n] = w, ++s->n;
        return;
    }
    int weakest = 0;
    for (int i = 1; i < s->n; ++i)
        if (s->w[i] < s->w[weakest]) weakest = i;
    if (w > s->w[weakest]) s->joint[weakest] = joint, s->w[weakest] = w;
}

void sp_skin8_pack(const sp_skin8* s, uint16_t joints[4], float weights[4])
{
    int idx[SP_OUTLINE_INFLUENCES_MAX];
    int n = s->n;
    for (int i = 0; i < n; ++i)
        idx[i] = i;
    // Insertion sort: strongest first, lower joint first on ties.
    for (int i = 1; i < n; ++i) {
        int v = idx[i], k = i;
        while (k > 0) {
            int u = idx[k - 1];
            bool before = s->w[v] > s->w[u] || (s->w[v] == s->w[u] && s->joint[v] < s->joint[u]);
            if (!before) break;
            idx[k] = u, --k;
        }
        idx[k] = v;
    }
    double sum = 0.0;
    int keep = n < 4 ? n : 4;
    for (int i = 0; i < keep; ++i)
        sum += s->w[idx[i]];
    for (int i = 0; i < 4; ++i)
        joints[i] = 0, weights[i] = 0.0f;
    if (!(sum > 0.0)) {
        weights[0] = 1.0f;
        return;
    }
    for (int i = 0; i < keep; ++i) {
        joints[i] = (uint16_t)s->joint[idx[i]];
        weights[i] = (float)(s->w[idx[i]] / sum);
    }
}

static int get(const grid* g, int x, int y)
{
    if (x < 0 || y < 0 || x >= g->w || y >= g->h) return 0;
    return g->c[(size_t)y * (size_t)g->w + (size_t)x];
}

// fmin and fmax by comparison: libm's calls cost more than the rest of a
// small triangle, and the corners are finite here (no NaN rule to keep).
static inline double lo(double a, double b)
{
    return b < a ? b : a;
}

static inline double hi(double a, double b)
{
    return b > a ? b : a;
}

void sp_raster_triangle(unsigned char* cells, int w, int h, const double a[2], const double b[2], const double c[2])
{
    if (!isfinite(a[0] + a[1] + b[0] + b[1] + c[0] + c[1])) return;
    double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (area == 0.0) return;
    // The cells whose centres the box holds, clamped to the grid before the
    // cast (a far-flung corner would overflow an int).
    double x0 = ceil(lo(a[0], lo(b[0], c[0])) - 0.5), x1 = floor(hi(a[0], hi(b[0], c[0])) - 0.5);
    double y0 = ceil(lo(a[1], lo(b[1], c[1])) - 0.5), y1 = floor(hi(a[1], hi(b[1], c[1])) - 0.5);
    if (x1 < 0 || y1 < 0 || x0 > w - 1 || y0 > h - 1) return;
    int cx0 = (int)hi(x0, 0), cx1 = (int)lo(x1, w - 1), cy0 = (int)hi(y0, 0), cy1 = (int)lo(y1, h - 1);
    double sgn = area > 0 ? 1.0 : -1.0;
    for (int y = cy0; y <= cy1; ++y)
        for (int x = cx0; x <= cx1; ++x) {
            double px = x + 0.5, py = y + 0.5;
            double e0 = sgn * ((b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]));
            double e1 = sgn * ((c[0] - b[0]) * (py - b[1]) - (c[1] - b[1]) * (px - b[0]));
            double e2 = sgn * ((a[0] - c[0]) * (py - c[1]) - (a[1] - c[1]) * (px - c[0]));
            if (e0 >= 0 && e1 >= 0 && e2 >= 0) cells[(size_t)y * (size_t)w + (size_t)x] = 1;
        }
}

// The row pass of morph: row y's cells or'd (and'ed) with their left and
// right neighbours into r.
static void morph_row(const grid* g, bool grow, size_t y, unsigned char* r)
{
    size_t w = (size_t)g->w;
    const unsigned char* c = g->c + y * w;
    for (size_t x = 0; x < w; ++x) {
        unsigned char l = x > 0 ? c[x - 1] : 0, m = c[x], n = x + 1 < w ? c[x + 1] : 0;
        r[x] = grow ? (unsigned char)(l | m | n) : (unsigned char)(l & m & n);
    }
}

// 3x3 dilation (grow = true) or erosion of the inside, cells off the grid
// empty, in place. Separable (a row pass, then a column pass over three row
// results): the same cells as the 3x3 window, in rows the compiler
// vectorises, because the training recipe traces a silhouette for many of
// its sketches. `ring` (3 * w, the caller's) holds the row results of rows
// y-1..y+1; row y+1's is taken before row y is overwritten, so the grid
// needs no copy.
static void morph(grid* g, bool grow, unsigned char* ring)
{
    size_t w = (size_t)g->w, h = (size_t)g->h;
    if (h == 0) return;
    morph_row(g, grow, 0, ring);
    if (h > 1) morph_row(g, grow, 1, ring + w);
    for (size_t y = 0; y < h; ++y) {
        if (y > 0 && y + 1 < h) morph_row(g, grow, y + 1, ring + ((y + 1) % 3) * w);
        const unsigned char* u = y > 0 ? ring + ((y - 1) % 3) * w : NULL;
        const unsigned char* m = ring + (y % 3) * w;
        const unsigned char* d = y + 1 < h ? ring + ((y + 1) % 3) * w : NULL;
        unsigned char* o = g->c + y * w;
        if (!u || !d) {
            for (size_t x = 0; x < w; ++x)
                o[x] = grow ? (unsigned char)((u ? u[x] : 0) | m[x] | (d ? d[x] : 0)) : 0;
        } else if (grow) {
            for (size_t x = 0; x < w; ++x)
                o[x] = (unsigned char)(u[x] | m[x] | d[x]);
        } else {
            for (size_t x = 0; x < w; ++x)
                o[x] = (unsigned char)(u[x] & m[x] & d[x]);
        }
    }
}

// Flood-fills the 4-connected region of cells equal to `from` around cell
// `seed`, setting them to `to` (!= from), a row span at a time (a division
// per span, not per cell); returns its size, -1 when out of memory. Marking
// the grid itself needs no label grid (4 bytes a cell, fresh pages for every
// trace). `stack` (cell indices) grows as needed and is the caller's to free.
static long long fill(grid* g, unsigned char from, unsigned char to, size_t seed, size_t** stack, size_t* cap)
{
    size_t w = (size_t)g->w, h = (size_t)g->h, top = 0;
    long long size = 0;
    (*stack)[top++] = seed;
    while (top) {
        size_t k = (*stack)[--top];
        if (g->c[k] != from) continue;
        size_t y = k / w, row = y * w, l = k - row, r = l;
        unsigned char* c = g->c + row;
        while (l > 0 && c[l - 1] == from)
            --l;
        while (r + 1 < w && c[r + 1] == from)
            ++r;
        memset(c + l, to, r - l + 1);
        size += (long long)(r - l + 1);
        // The first cell of every run of the span's neighbours above and below.
        for (int side = 0; side < 2; ++side) {
            if ((side == 0 && y == 0) || (side == 1 && y + 1 >= h)) continue;
            const unsigned char* n = g->c + (side == 0 ? row - w : row + w);
            bool run = false;
            for (size_t x = l; x <= r; ++x) {
                bool in = n[x] == from;
                if (in && !run) {
                    if (top == *cap) {
                        size_t* grown = realloc(*stack, sizeof(size_t) * 2 * *cap);
                        if (!grown) return -1;
                        *stack = grown, *cap *= 2;
                    }
                    (*stack)[top++] = (size_t)(n + x - g->c);
                }
                run = in;
            }
        }
    }
    return size;
}

typedef struct pt {
    double x, y;
} pt;

// Follows the boundary edges of the inside (4-connected, no holes) with the
// inside on the right (y down), from the top edge of the top-left cell.
// NULL when out of memory.
static pt* trace(const grid* g, int* count)
{
    int sx = -1, sy = -1;
    for (int y = 0; y < g->h && sx < 0; ++y)
        for (int x = 0; x < g->w; ++x)
            if (get(g, x, y)) {
                sx = x, sy = y;
                break;
            }
    int cap = 4096, n = 0;
    pt* out = malloc(sizeof(pt) * (size_t)cap);
    if (!out) return NULL;
    // Directions: 0 +x, 1 +y, 2 -x, 3 -y (y down; "right" of +x is +y).
    const int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
    int X = sx, Y = sy, d = 0;
    do {
        if (n == cap) {
            cap *= 2;
            pt* grown = realloc(out, sizeof(pt) * (size_t)cap);
            if (!grown) {
                free(out);
                return NULL;
            }
            out = grown;
        }
        out[n++] = (pt){X, Y};
        X += dx[d], Y += dy[d];
        // The cells ahead of corner (X, Y) going in direction d: the one on
        // the right and the one on the left.
        int rx, ry, lx, ly;
        switch (d) {
        case 0:
            rx = X, ry = Y, lx = X, ly = Y - 1;
            break;
        case 1:
            rx = X - 1, ry = Y, lx = X, ly = Y;
            break;
        case 2:
            rx = X - 1, ry = Y - 1, lx = X - 1, ly = Y;
            break;
        default:
            rx = X, ry = Y - 1, lx = X - 1, ly = Y - 1;
            break;
        }
        int R = get(g, rx, ry), L = get(g, lx, ly);
        if (!R)
            d = (d + 1) % 4; // turn right
        else if (L)
            d = (d + 3) % 4; // turn left
    } while (!(X == sx && Y == sy && d == 0) && n < 64 * (g->w + g->h));
    *count = n;
    return out;
}

static bool skipped(const unsigned char* flags, int i)
{
    return flags && flags[i];
}

// The input skin of vertex v (entries with weight 0 are unused).
static sp_skin8 vertex_skin(const sp_outline_desc* d, int v)
{
    sp_skin8 s = {0};
    for (int k = 0; k < d->influences; ++k) {
        double w = d->weights[(size_t)v * (size_t)d->influences + (size_t)k];
        if (!(w > 0.0)) continue;
        s.joint[s.n] = d->joints[(size_t)v * (size_t)d->influences + (size_t)k];
        s.w[s.n++] = w;
    }
    return s;
}

// The nearest point of projected triangle q to (px, py): its squared
// distance in pixels and barycentric coordinates b. Edge-on triangles (no
// area in the view, common along a silhouette) are their edges.
static double triangle_nearest(const double* xy, const uint32_t* q, double px, double py, double b[3])
{
    const double* v[3] = {xy + 2 * (size_t)q[0], xy + 2 * (size_t)q[1], xy + 2 * (size_t)q[2]};
    double area = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[1][1] - v[0][1]) * (v[2][0] - v[0][0]);
    if (area != 0.0) {
        double l[3];
        for (int e = 0; e < 3; ++e) {
            const double *a = v[(e + 1) % 3], *c = v[(e + 2) % 3];
            l[e] = ((c[0] - a[0]) * (py - a[1]) - (c[1] - a[1]) * (px - a[0])) / area;
        }
        if (l[0] >= 0 && l[1] >= 0 && l[2] >= 0) {
            b[0] = l[0], b[1] = l[1], b[2] = l[2];
            return 0.0;
        }
    }
    double best = INFINITY;
    for (int e = 0; e < 3; ++e) {
        const double *a = v[e], *c = v[(e + 1) % 3];
        double ex = c[0] - a[0], ey = c[1] - a[1], len2 = ex * ex + ey * ey;
        double t = len2 > 0 ? ((px - a[0]) * ex + (py - a[1]) * ey) / len2 : 0.0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double dx = a[0] + t * ex - px, dy = a[1] + t * ey - py, d2 = dx * dx + dy * dy;
        if (d2 < best) {
            best = d2;
            b[e] = 1.0 - t, b[(e + 1) % 3] = t, b[(e + 2) % 3] = 0.0;
        }
    }
    return best;
}

typedef struct candidate {
    int t;
    double d, b[3];
} candidate;

// Binds a contour point (px, py) to the surface under it: among the
// triangles whose (interpolated) normal faces out of the silhouette along
// (ox, oy) and whose nearest point lies within `front` pixels of the nearest
// such one, the one nearest the camera (where a near and a far leg share a
// stretch of contour, the visible one, so neighbouring points agree); the
// nearest triangle of all when no outward one is within `slack` pixels of
// it. Writes the world point (the contour at the surface's depth) into w and
// returns the interpolated skin. `zv`: the vertices' depths in the view.
static sp_skin8 surface_bind(const sp_outline_desc* d, const double* xy, const double* nrm, const double* zv, double px,
                             double py, double ox, double oy, double slack, double front, candidate** list, int* cap, double* w)
{
    int near_t = -1, n = 0;
    double near_d = INFINITY, out_d = INFINITY, near_b[3] = {1, 0, 0};
    for (int t = 0; t < d->triangle_count; ++t) {
        if (skipped(d->skip_triangle, t)) continue;
        const uint32_t* q = d->triangles + 3 * (size_t)t;
        double b[3];
        double dd = sqrt(triangle_nearest(xy, q, px, py, b));
        if (dd > near_d + slack && dd > out_d + front) continue;
        if (dd < near_d) near_d = dd, near_t = t, memcpy(near_b, b, sizeof b);
        double nx = 0, ny = 0;
        for (int k = 0; k < 3; ++k)
            nx += b[k] * nrm[2 * q[k]], ny += b[k] * nrm[2 * q[k] + 1];
        double nl = hypot(nx, ny);
        if (!(nl > 0 && nx * ox + ny * oy > 0.5 * nl) || dd > out_d + front) continue;
        out_d = fmin(out_d, dd);
        if (n == *cap) {
            int c = *cap ? 2 * *cap : 64;
            candidate* g = realloc(*list, sizeof(candidate) * (size_t)c);
            if (!g) continue; // keeps the candidates so far: a slightly worse choice, not a failure
            *list = g, *cap = c;
        }
        (*list)[n++] = (candidate){t, dd, {b[0], b[1], b[2]}};
    }
    int best_t = near_t;
    double best_b[3] = {near_b[0], near_b[1], near_b[2]}, best_z = -INFINITY;
    if (n > 0 && out_d <= near_d + slack)
        for (int i = 0; i < n; ++i) {
            const candidate* c = &(*list)[i];
            if (c->d > out_d + front) continue;
            const uint32_t* q = d->triangles + 3 * (size_t)c->t;
            double z = c->b[0] * zv[q[0]] + c->b[1] * zv[q[1]] + c->b[2] * zv[q[2]];
            if (z > best_z) best_z = z, best_t = c->t, memcpy(best_b, c->b, sizeof best_b);
        }
    const uint32_t* q = d->triangles + 3 * (size_t)best_t;
    const sp_camera* cam = d->camera;
    double z = 0;
    sp_skin8 s = {0};
    for (int k = 0; k < 3; ++k) {
        z += best_b[k] * zv[q[k]];
        sp_skin8 v = vertex_skin(d, (int)q[k]);
        for (int e = 0; e < v.n; ++e)
            sp_skin8_add(&s, v.joint[e], best_b[k] * v.w[e]);
    }
    sp_mat4 inv_view;
    sp_mat4_inverse(&cam->view, &inv_view);
    sp_vec3 c = sp_mat4_point(&inv_view, sp_v3((px - cam->cx) / cam->scale, (cam->cy - py) / cam->scale, z));
    w[0] = c.x, w[1] = c.y, w[2] = c.z;
    return s;
}

// Closes the filled cells' hairline gaps, fills their holes and keeps the
// largest inside region (1 in g, all else 0); a silhouette in several big
// pieces is refused unless d->keep_largest.
static sp_result keep_silhouette(const sp_outline_desc* d, grid* g, double k, sp_outline_info* info, sp_error* err)
{
    sp_result res = SP_OK;
    int* sizes = NULL;
    size_t *seeds = NULL, *stack = NULL;
    size_t stack_cap = 4096;
    // Closing (dilate, erode) removes hairline gaps between touching pieces.
    size_t ncell = (size_t)g->w * (size_t)g->h;
    unsigned char* ring = malloc(3 * (size_t)g->w);
    if (!ring) goto oom;
    morph(g, true, ring), morph(g, true, ring), morph(g, false, ring), morph(g, false, ring);
    // Fill holes: everything not reachable from the border is inside.
    stack = malloc(sizeof(size_t) * stack_cap);
    // The background (2) from the corner cell, which is always empty (margin).
    if (!stack || fill(g, 0, 2, 0, &stack, &stack_cap) < 0) goto oom;
    for (size_t i = 0; i < ncell; ++i)
        g->c[i] = g->c[i] != 2;
    // The inside's regions (marked 2), numbered from 1 in the order of their
    // first cell row by row; keep the largest, refuse a silhouette in several
    // big pieces.
    int regions = 0, room = 0;
    for (size_t i = 0; i < ncell; ++i) {
        if (g->c[i] != 1) continue;
        if (regions + 2 > room) {
            room = room ? 2 * room : 16;
            int* grown = realloc(sizes, sizeof(int) * (size_t)room);
            size_t* grown_seeds = realloc(seeds, sizeof(size_t) * (size_t)room);
            if (grown) sizes = grown;
            if (grown_seeds) seeds = grown_seeds;
            if (!grown || !grown_seeds) goto oom;
        }
        long long size = fill(g, 1, 2, i, &stack, &stack_cap);
        if (size < 0) goto oom;
        sizes[++regions] = (int)size, seeds[regions] = i;
    }
    int best = 1, second = 0;
    long long total = 0;
    for (int r = 2; r <= regions; ++r)
        if (sizes[r] > sizes[best]) best = r;
    for (int r = 1; r <= regions; ++r) {
        total += sizes[r];
        if (r != best && sizes[r] > second) second = sizes[r];
    }
    if (info) {
        info->regions = regions;
        info->dropped_share = total > 0 ? (double)(total - (regions ? sizes[best] : 0)) / (double)total : 0.0;
        info->cell_px = 1.0 / k;
    }
    if (regions == 0) {
        res = sp_fail(err, SP_ERR_INVALID,
                      "outline: the mesh covers no area in the sketch view (it is seen edge-on, or "
                      "its triangles are flat)");
        goto done;
    }
    bool ok = second < sizes[best] / 200 || d->keep_largest;
    if (!ok) {
        res = sp_fail(err, SP_ERR_INVALID, "outline: the side silhouette falls apart (%d regions, second largest %d of %d cells)",
                      regions, second, sizes[best]);
        goto done;
    }
    if (fill(g, 2, 3, seeds[best], &stack, &stack_cap) < 0) goto oom;
    for (size_t i = 0; i < ncell; ++i)
        g->c[i] = g->c[i] == 3;
    goto done;
oom:
    res = sp_fail(err, SP_ERR_NO_MEMORY, "outline: out of memory");
done:
    free(sizes), free(seeds), free(stack), free(ring);
    return res;
}

// Smooths the traced staircase: a few passes of (1/4, 1/2, 1/4) averaging.
static void smooth_polygon(pt* poly, pt* tmp, int n)
{
    for (int pass = 0; pass < 6; ++pass) {
        for (int i = 0; i < n; ++i) {
            pt a = poly[(i + n - 1) % n], b = poly[i], c = poly[(i + 1) % n];
            tmp[i] = (pt){0.25 * a.x + 0.5 * b.x + 0.25 * c.x, 0.25 * a.y + 0.5 * b.y + 0.25 * c.y};
        }
        memcpy(poly, tmp, sizeof(pt) * (size_t)n);
    }
}

// Smooth the skins along the curve: where the contour passes from one
// bone's surface to another's (girdle to leg, leg to leg at the crotch)
// the curve then stretches evenly instead of kinking at one point.
static void smooth_skins(sp_skin8* bound, sp_skin8* tmp_skin, int points)
{
    for (int pass = 0; pass < 3; ++pass) {
        for (int i = 0; i < points; ++i) {
            const sp_skin8 *a = &bound[(i + points - 1) % points], *b = &bound[i], *c = &bound[(i + 1) % points];
            sp_skin8 r = {0};
            for (int q = 0; q < a->n; ++q)
                sp_skin8_add(&r, a->joint[q], 0.25 * a->w[q]);
            for (int q = 0; q < b->n; ++q)
                sp_skin8_add(&r, b->joint[q], 0.5 * b->w[q]);
            for (int q = 0; q < c->n; ++q)
                sp_skin8_add(&r, c->joint[q], 0.25 * c->w[q]);
            tmp_skin[i] = r;
        }
        memcpy(bound, tmp_skin, sizeof(sp_skin8) * (size_t)points);
    }
}

// The vertex nearest the contour point (px, py) whose normal faces out
// along (ox, oy), within a few cells of the nearest of all, which is the
// fallback.
static int nearest_outward(const sp_outline_desc* d, const double* xy, const double* nrm, const double* nlen, double px,
                           double py, double ox, double oy, double cell_px)
{
    int nv = d->vertex_count;
    int best_v = 0, near_v = 0;
    double best_d = INFINITY, near_d = INFINITY;
    for (int v = 0; v < nv; ++v) {
        if (skipped(d->skip_vertex, v)) continue;
        double ddx = xy[2 * v] - px, ddy = xy[2 * v + 1] - py, dd = ddx * ddx + ddy * ddy;
        if (dd < near_d) near_d = dd, near_v = v;
        double nl = nlen[v];
        bool outward = nl > 0 && (nrm[2 * v] * ox + nrm[2 * v + 1] * oy) > 0.5 * nl;
        if (outward && dd < best_d) best_d = dd, best_v = v;
    }
    if (!(sqrt(best_d) <= sqrt(near_d) + 4.0 * cell_px)) best_v = near_v;
    return best_v;
}

// Depths along the curve: world z, the depth of a view along -Z (false:
// out of memory).
static bool smooth_depths(sp_abstraction* out, int points, int passes)
{
    double* z = passes > 0 ? malloc(sizeof(double) * (size_t)points) : NULL;
    if (passes > 0 && !z) return false;
    for (int pass = 0; pass < passes; ++pass) {
        for (int i = 0; i < points; ++i)
            z[i] = 0.25 * out->rest[3 * ((i + points - 1) % points) + 2] + 0.5 * out->rest[3 * i + 2] +
                   0.25 * out->rest[3 * ((i + 1) % points) + 2];
        for (int i = 0; i < points; ++i)
            out->rest[3 * i + 2] = z[i];
    }
    free(z);
    return true;
}

// Adds each triangle's area-weighted normal, in the view's pixel frame, to
// its vertices' (nrm: 2 a vertex, zeroed).
static void view_normals(const sp_outline_desc* d, double* nrm)
{
    for (int t = 0; t < d->triangle_count; ++t) {
        if (skipped(d->skip_triangle, t)) continue;
        const uint32_t* q = d->triangles + 3 * (size_t)t;
        const double *pa = d->positions + 3 * (size_t)q[0], *pb = d->positions + 3 * (size_t)q[1],
                     *pc = d->positions + 3 * (size_t)q[2];
        sp_vec3 a = {pa[0], pa[1], pa[2]}, b = {pb[0], pb[1], pb[2]}, c = {pc[0], pc[1], pc[2]};
        sp_vec3 nv3 = sp_mat4_dir(&d->camera->view, sp_v3_cross(sp_v3_sub(b, a), sp_v3_sub(c, a)));
        for (int j = 0; j < 3; ++j)
            nrm[2 * q[j]] += nv3.x, nrm[2 * q[j] + 1] -= nv3.y;
    }
}

sp_result sp_outline_trace(const sp_outline_desc* d, sp_abstraction* out, sp_outline_info* info, sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (info) memset(info, 0, sizeof *info);
    if (!d || !d->camera || d->vertex_count <= 0 || !d->positions || d->triangle_count <= 0 || !d->triangles || !d->joints ||
        !d->weights || d->influences < 1 || d->influences > SP_OUTLINE_INFLUENCES_MAX || d->points < 0 || d->points == 1 ||
        d->points == 2)
        return sp_fail(err, SP_ERR_INVALID, "outline: no mesh, skin or camera to trace (or a bad point count)");
    if (d->camera->kind != SP_CAMERA_ORTHOGRAPHIC || !(d->camera->scale > 0))
        return sp_fail(err, SP_ERR_INVALID, "outline: the sketch view must be an orthographic camera");
    const sp_camera* cam = d->camera;
    int points = d->points > 0 ? d->points : 150;
    int nv = d->vertex_count;
    sp_result res = SP_OK;
    double *xy = NULL, *cell = NULL, *acc = NULL, *nrm = NULL, *nlen = NULL, *zv = NULL;
    candidate* cands = NULL;
    int ncand = 0;
    pt *poly = NULL, *tmp = NULL;
    sp_skin8 *bound = NULL, *tmp_skin = NULL;
    grid g = {0, 0, NULL};
    xy = malloc(sizeof(double) * 2 * (size_t)(nv + 1));
    if (!xy) goto oom;
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int i = 0; i < nv; ++i) {
        const double* p = d->positions + 3 * (size_t)i;
        sp_vec2 q = sp_camera_project(cam, sp_v3(p[0], p[1], p[2]));
        xy[2 * i] = q.x, xy[2 * i + 1] = q.y;
        if (skipped(d->skip_vertex, i)) continue;
        lx = fmin(lx, q.x), hx = fmax(hx, q.x), ly = fmin(ly, q.y), hy = fmax(hy, q.y);
    }
    double ext = fmax(hx - lx, hy - ly);
    if (!(ext > 0) || !isfinite(ext)) {
        res = sp_fail(err, SP_ERR_INVALID, "outline: the mesh has no extent in the view");
        goto done;
    }
    // Grid cells: `k` cells per pixel, MARGIN empty cells around.
    double k = (CELLS - 2 * MARGIN) / ext;
    g.w = (int)ceil((hx - lx) * k) + 2 * MARGIN + 1;
    g.h = (int)ceil((hy - ly) * k) + 2 * MARGIN + 1;
    g.c = calloc((size_t)g.w * (size_t)g.h, 1);
    cell = malloc(sizeof(double) * 2 * (size_t)(nv + 1));
    if (!g.c || !cell) goto oom;
    for (int i = 0; i < nv; ++i) {
        cell[2 * i] = (xy[2 * i] - lx) * k + MARGIN;
        cell[2 * i + 1] = (xy[2 * i + 1] - ly) * k + MARGIN;
    }
    for (int t = 0; t < d->triangle_count; ++t) {
        if (skipped(d->skip_triangle, t)) continue;
        const uint32_t* q = d->triangles + 3 * (size_t)t;
        if (q[0] >= (uint32_t)nv || q[1] >= (uint32_t)nv || q[2] >= (uint32_t)nv) {
            res = sp_fail(err, SP_ERR_INVALID, "outline: triangle %d refers to a vertex past %d", t, nv);
            goto done;
        }
        sp_raster_triangle(g.c, g.w, g.h, cell + 2 * q[0], cell + 2 * q[1], cell + 2 * q[2]);
    }
    if ((res = keep_silhouette(d, &g, k, info, err)) != SP_OK) goto done;

    int n = 0;
    poly = trace(&g, &n);
    free(g.c);
    g.c = NULL;
    if (!poly) goto oom;
    tmp = malloc(sizeof(pt) * (size_t)n);
    if (!tmp) goto oom;
    smooth_polygon(poly, tmp, n);
    // Resample by arc length to `points` points.
    acc = malloc(sizeof(double) * (size_t)(n + 1));
    out->rest = malloc(sizeof(double) * 3 * (size_t)points);
    out->joints = malloc(sizeof(uint16_t) * 4 * (size_t)points);
    out->weights = malloc(sizeof(float) * 4 * (size_t)points);
    out->curves = calloc(1, sizeof(sp_curve));
    // Vertex normals in the view's pixel frame (x right, y down): a
    // silhouette point is made by a surface whose normal points out of the
    // silhouette, which tells the two legs of a pair apart where they overlap.
    nrm = calloc(2 * (size_t)(nv + 1), sizeof(double));
    if (d->surface && (zv = malloc(sizeof(double) * (size_t)nv)))
        for (int v = 0; v < nv; ++v) {
            const double* p = d->positions + 3 * (size_t)v;
            zv[v] = sp_mat4_point(&cam->view, sp_v3(p[0], p[1], p[2])).z;
        }
    bound = malloc(sizeof(sp_skin8) * (size_t)points);
    tmp_skin = malloc(sizeof(sp_skin8) * (size_t)points);
    if (!acc || !out->rest || !out->joints || !out->weights || !out->curves || !nrm || !bound || !tmp_skin || (d->surface && !zv))
        goto oom;
    acc[0] = 0;
    for (int i = 0; i < n; ++i) {
        pt a = poly[i], b = poly[(i + 1) % n];
        acc[i + 1] = acc[i] + hypot(b.x - a.x, b.y - a.y);
    }
    out->point_count = points;
    out->curve_count = 1;
    snprintf(out->name, sizeof out->name, "outline");
    snprintf(out->curves[0].name, sizeof out->curves[0].name, "outline");
    out->curves[0].first_point = 0;
    out->curves[0].point_count = points;
    out->curves[0].closed = true;
    out->correspondence = SP_CORR_CLOSEST;
    sp_mat4 inv_view;
    sp_mat4_inverse(&cam->view, &inv_view);
    view_normals(d, nrm);
    // Their lengths once, not once a contour point (the nearest-vertex search
    // below visits every vertex for each point).
    if (!d->surface) {
        if (!(nlen = malloc(sizeof(double) * (size_t)nv))) goto oom;
        for (int v = 0; v < nv; ++v)
            nlen[v] = hypot(nrm[2 * v], nrm[2 * v + 1]);
    }
    int seg = 0;
    for (int i = 0; i < points; ++i) {
        double s = acc[n] * i / points;
        while (seg + 1 < n && acc[seg + 1] <= s)
            ++seg;
        double len = acc[seg + 1] - acc[seg];
        double f = len > 0 ? (s - acc[seg]) / len : 0.0;
        pt a = poly[seg], b = poly[(seg + 1) % n];
        double cx = a.x + f * (b.x - a.x), cy = a.y + f * (b.y - a.y);
        // Cell coordinates back to pixels of the view.
        double px = (cx - MARGIN) / k + lx, py = (cy - MARGIN) / k + ly;
        // Outward normal of the contour here: the trace keeps the inside on
        // its right (y down), so outward is to the left of the direction.
        pt pa = poly[(seg + n - 1) % n], pb = poly[(seg + 2) % n];
        double tx = pb.x - pa.x, ty = pb.y - pa.y, tl = hypot(tx, ty);
        double ox = tl > 0 ? ty / tl : 0.0, oy = tl > 0 ? -tx / tl : 0.0;
        double cell_px = 1.0 / k;
        if (d->surface) {
            bound[i] =
                surface_bind(d, xy, nrm, zv, px, py, ox, oy, 4.0 * cell_px, 2.0 * cell_px, &cands, &ncand, &out->rest[3 * i]);
            continue;
        }
        int best_v = nearest_outward(d, xy, nrm, nlen, px, py, ox, oy, cell_px);
        // Depth of the nearest vertex, position of the contour (orthographic view).
        const double* bp = d->positions + 3 * (size_t)best_v;
        sp_vec3 vc = sp_mat4_point(&cam->view, sp_v3(bp[0], bp[1], bp[2]));
        sp_vec3 c = {(px - cam->cx) / cam->scale, (cam->cy - py) / cam->scale, vc.z};
        sp_vec3 w = sp_mat4_point(&inv_view, c);
        out->rest[3 * i] = w.x, out->rest[3 * i + 1] = w.y, out->rest[3 * i + 2] = w.z;
        bound[i] = vertex_skin(d, best_v);
    }
    smooth_skins(bound, tmp_skin, points);
    for (int i = 0; i < points; ++i)
        sp_skin8_pack(&bound[i], out->joints + 4 * i, out->weights + 4 * i);
    if (!smooth_depths(out, points, d->depth_passes)) goto oom;
    goto done;
oom:
    res = sp_fail(err, SP_ERR_NO_MEMORY, "outline: out of memory");
done:
    if (res != SP_OK) sp_abstraction_free(out);
    free(cands), free(zv);
    free(tmp_skin), free(bound), free(nrm), free(nlen), free(acc), free(tmp), free(poly), free(cell), free(xy), free(g.c);
    return res;
}
