// gen_outline.c: side-view silhouette of a rest mesh as a skinned closed curve.
#include "gen_outline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CELLS = 1000, MARGIN = 6 };

typedef struct grid {
    int w, h;
    unsigned char* c; // 1 inside
} grid;

static unsigned char* at(grid* g, int x, int y)
{
    return &g->c[(size_t)y * (size_t)g->w + (size_t)x];
}
static int get(const grid* g, int x, int y)
{
    if (x < 0 || y < 0 || x >= g->w || y >= g->h) return 0;
    return g->c[(size_t)y * (size_t)g->w + (size_t)x];
}

// Cells whose centre lies in the triangle (either winding).
static void fill_triangle(grid* g, const double* a, const double* b, const double* c)
{
    double x0 = fmin(a[0], fmin(b[0], c[0])), x1 = fmax(a[0], fmax(b[0], c[0]));
    double y0 = fmin(a[1], fmin(b[1], c[1])), y1 = fmax(a[1], fmax(b[1], c[1]));
    int cx0 = (int)floor(x0 - 0.5), cx1 = (int)ceil(x1 - 0.5), cy0 = (int)floor(y0 - 0.5), cy1 = (int)ceil(y1 - 0.5);
    if (cx0 < 0) cx0 = 0;
    if (cy0 < 0) cy0 = 0;
    if (cx1 >= g->w) cx1 = g->w - 1;
    if (cy1 >= g->h) cy1 = g->h - 1;
    double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (area == 0.0) return;
    double sgn = area > 0 ? 1.0 : -1.0;
    for (int y = cy0; y <= cy1; ++y)
        for (int x = cx0; x <= cx1; ++x) {
            double px = x + 0.5, py = y + 0.5;
            double e0 = sgn * ((b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]));
            double e1 = sgn * ((c[0] - b[0]) * (py - b[1]) - (c[1] - b[1]) * (px - b[0]));
            double e2 = sgn * ((a[0] - c[0]) * (py - c[1]) - (a[1] - c[1]) * (px - c[0]));
            if (e0 >= 0 && e1 >= 0 && e2 >= 0) *at(g, x, y) = 1;
        }
}

// 3x3 dilation (grow = true) or erosion of the inside.
static void morph(grid* g, bool grow)
{
    unsigned char* out = sp_gen_check_alloc(malloc((size_t)g->w * (size_t)g->h));
    for (int y = 0; y < g->h; ++y)
        for (int x = 0; x < g->w; ++x) {
            int v = grow ? 0 : 1;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int q = get(g, x + dx, y + dy);
                    v = grow ? (v | q) : (v & q);
                }
            out[(size_t)y * (size_t)g->w + (size_t)x] = (unsigned char)v;
        }
    free(g->c);
    g->c = out;
}

// Labels 4-connected regions of cells equal to `value` into lab (region ids
// from 1); returns the count and writes each region's size into *sizes.
static int label(const grid* g, int value, int* lab, int** sizes)
{
    size_t n = (size_t)g->w * (size_t)g->h;
    int* stack = sp_gen_check_alloc(malloc(sizeof(int) * n));
    int count = 0;
    *sizes = NULL;
    for (size_t i = 0; i < n; ++i)
        lab[i] = 0;
    for (size_t i = 0; i < n; ++i) {
        if (g->c[i] != value || lab[i]) continue;
        ++count;
        *sizes = sp_gen_check_alloc(realloc(*sizes, sizeof(int) * (size_t)(count + 1)));
        int size = 0, top = 0;
        stack[top++] = (int)i;
        lab[i] = count;
        while (top) {
            int k = stack[--top];
            ++size;
            int x = k % g->w, y = k / g->w;
            const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
            for (int d = 0; d < 4; ++d) {
                int nx = x + nb[d][0], ny = y + nb[d][1];
                if (nx < 0 || ny < 0 || nx >= g->w || ny >= g->h) continue;
                size_t q = (size_t)ny * (size_t)g->w + (size_t)nx;
                if (g->c[q] == value && !lab[q]) lab[q] = count, stack[top++] = (int)q;
            }
        }
        (*sizes)[count] = size;
    }
    free(stack);
    return count;
}

typedef struct pt {
    double x, y;
} pt;

// Follows the boundary edges of the inside (4-connected, no holes) with the
// inside on the right (y down), from the top edge of the top-left cell.
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
    pt* out = sp_gen_check_alloc(malloc(sizeof(pt) * (size_t)cap));
    // Directions: 0 +x, 1 +y, 2 -x, 3 -y (y down; "right" of +x is +y).
    const int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
    int X = sx, Y = sy, d = 0;
    do {
        if (n == cap) {
            cap *= 2;
            out = sp_gen_check_alloc(realloc(out, sizeof(pt) * (size_t)cap));
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

bool sp_gen_outline(const sp_gen_mesh* mesh, const sp_camera* cam, int points, sp_abstraction* out, char* why, size_t why_size)
{
    memset(out, 0, sizeof *out);
    int nv = mesh->vertex_count;
    double* xy = sp_gen_check_alloc(malloc(sizeof(double) * 2 * (size_t)(nv + 1)));
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int i = 0; i < nv; ++i) {
        sp_vec2 q = sp_camera_project(cam, sp_v3(mesh->pos[3 * i], mesh->pos[3 * i + 1], mesh->pos[3 * i + 2]));
        xy[2 * i] = q.x, xy[2 * i + 1] = q.y;
        if (mesh->deco_vertex[i]) continue;
        lx = fmin(lx, q.x), hx = fmax(hx, q.x), ly = fmin(ly, q.y), hy = fmax(hy, q.y);
    }
    double ext = fmax(hx - lx, hy - ly);
    if (!(ext > 0)) {
        free(xy);
        snprintf(why, why_size, "outline: the mesh has no extent in the view");
        return false;
    }
    // Grid cells: `k` cells per pixel, MARGIN empty cells around.
    double k = (CELLS - 2 * MARGIN) / ext;
    grid g = {(int)ceil((hx - lx) * k) + 2 * MARGIN + 1, (int)ceil((hy - ly) * k) + 2 * MARGIN + 1, NULL};
    g.c = sp_gen_check_alloc(calloc((size_t)g.w * (size_t)g.h, 1));
    double* cell = sp_gen_check_alloc(malloc(sizeof(double) * 2 * (size_t)(nv + 1)));
    for (int i = 0; i < nv; ++i) {
        cell[2 * i] = (xy[2 * i] - lx) * k + MARGIN;
        cell[2 * i + 1] = (xy[2 * i + 1] - ly) * k + MARGIN;
    }
    for (int t = 0; t < mesh->tri_count; ++t) {
        if (mesh->deco_tri[t]) continue;
        const uint32_t* q = mesh->tris + 3 * (size_t)t;
        fill_triangle(&g, cell + 2 * q[0], cell + 2 * q[1], cell + 2 * q[2]);
    }
    // Closing (dilate, erode) removes hairline gaps between touching pieces.
    morph(&g, true);
    morph(&g, true);
    morph(&g, false);
    morph(&g, false);
    // Fill holes: everything not reachable from the border is inside.
    size_t ncell = (size_t)g.w * (size_t)g.h;
    int* lab = sp_gen_check_alloc(malloc(sizeof(int) * ncell));
    int* sizes = NULL;
    label(&g, 0, lab, &sizes);
    int border = lab[0]; // the corner cell is always empty (margin)
    for (size_t i = 0; i < ncell; ++i)
        g.c[i] = lab[i] != border;
    free(sizes);
    // Keep the largest inside region; refuse a silhouette in several big pieces.
    int regions = label(&g, 1, lab, &sizes);
    int best = 1, second = 0;
    for (int r = 2; r <= regions; ++r)
        if (sizes[r] > sizes[best]) best = r;
    for (int r = 1; r <= regions; ++r)
        if (r != best && sizes[r] > second) second = sizes[r];
    bool ok = regions >= 1 && second < sizes[best] / 200;
    if (!ok) {
        snprintf(why, why_size, "outline: the side silhouette falls apart (%d regions, second largest %d of %d cells)", regions,
                 second, regions ? sizes[best] : 0);
        free(sizes), free(lab), free(g.c), free(cell), free(xy);
        return false;
    }
    for (size_t i = 0; i < ncell; ++i)
        g.c[i] = lab[i] == best;
    free(sizes), free(lab);

    int n = 0;
    pt* poly = trace(&g, &n);
    free(g.c);
    // Smooth the staircase: a few passes of (1/4, 1/2, 1/4) averaging.
    pt* tmp = sp_gen_check_alloc(malloc(sizeof(pt) * (size_t)n));
    for (int pass = 0; pass < 6; ++pass) {
        for (int i = 0; i < n; ++i) {
            pt a = poly[(i + n - 1) % n], b = poly[i], c = poly[(i + 1) % n];
            tmp[i] = (pt){0.25 * a.x + 0.5 * b.x + 0.25 * c.x, 0.25 * a.y + 0.5 * b.y + 0.25 * c.y};
        }
        memcpy(poly, tmp, sizeof(pt) * (size_t)n);
    }
    free(tmp);
    // Resample by arc length to `points` points.
    double* acc = sp_gen_check_alloc(malloc(sizeof(double) * (size_t)(n + 1)));
    acc[0] = 0;
    for (int i = 0; i < n; ++i) {
        pt a = poly[i], b = poly[(i + 1) % n];
        acc[i + 1] = acc[i] + hypot(b.x - a.x, b.y - a.y);
    }
    out->point_count = points;
    out->rest = sp_gen_check_alloc(malloc(sizeof(double) * 3 * (size_t)points));
    out->joints = sp_gen_check_alloc(malloc(sizeof(uint16_t) * 4 * (size_t)points));
    out->weights = sp_gen_check_alloc(malloc(sizeof(float) * 4 * (size_t)points));
    out->curves = sp_gen_check_alloc(calloc(1, sizeof(sp_curve)));
    out->curve_count = 1;
    snprintf(out->name, sizeof out->name, "outline");
    snprintf(out->curves[0].name, sizeof out->curves[0].name, "outline");
    out->curves[0].first_point = 0;
    out->curves[0].point_count = points;
    out->curves[0].closed = true;
    out->correspondence = SP_CORR_CLOSEST;
    sp_mat4 inv_view;
    sp_mat4_inverse(&cam->view, &inv_view);
    // Vertex normals in the view's pixel frame (x right, y down): a
    // silhouette point is made by a surface whose normal points out of the
    // silhouette, which tells the two legs of a pair apart where they overlap.
    double* nrm = sp_gen_check_alloc(calloc(2 * (size_t)(nv + 1), sizeof(double)));
    for (int t = 0; t < mesh->tri_count; ++t) {
        if (mesh->deco_tri[t]) continue;
        const uint32_t* q = mesh->tris + 3 * (size_t)t;
        sp_vec3 a = {mesh->pos[3 * q[0]], mesh->pos[3 * q[0] + 1], mesh->pos[3 * q[0] + 2]};
        sp_vec3 b = {mesh->pos[3 * q[1]], mesh->pos[3 * q[1] + 1], mesh->pos[3 * q[1] + 2]};
        sp_vec3 c = {mesh->pos[3 * q[2]], mesh->pos[3 * q[2] + 1], mesh->pos[3 * q[2] + 2]};
        sp_vec3 n = sp_mat4_dir(&cam->view, sp_v3_cross(sp_v3_sub(b, a), sp_v3_sub(c, a)));
        for (int k = 0; k < 3; ++k)
            nrm[2 * q[k]] += n.x, nrm[2 * q[k] + 1] -= n.y;
    }
    int seg = 0;
    sp_gen_skin* bound = sp_gen_check_alloc(malloc(sizeof(sp_gen_skin) * (size_t)points));
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
        // The nearest vertex facing outwards (within a few cells of the
        // nearest of all, which is the fallback).
        int best_v = 0, near_v = 0;
        double best_d = INFINITY, near_d = INFINITY;
        for (int v = 0; v < nv; ++v) {
            if (mesh->deco_vertex[v]) continue;
            double ddx = xy[2 * v] - px, ddy = xy[2 * v + 1] - py, dd = ddx * ddx + ddy * ddy;
            if (dd < near_d) near_d = dd, near_v = v;
            double nl = hypot(nrm[2 * v], nrm[2 * v + 1]);
            bool outward = nl > 0 && (nrm[2 * v] * ox + nrm[2 * v + 1] * oy) > 0.5 * nl;
            if (outward && dd < best_d) best_d = dd, best_v = v;
        }
        double cell_px = 1.0 / k;
        if (!(sqrt(best_d) <= sqrt(near_d) + 4.0 * cell_px)) best_v = near_v;
        // Depth of the nearest vertex, position of the contour (orthographic view).
        sp_vec3 vc =
            sp_mat4_point(&cam->view, sp_v3(mesh->pos[3 * best_v], mesh->pos[3 * best_v + 1], mesh->pos[3 * best_v + 2]));
        sp_vec3 c = {(px - cam->cx) / cam->scale, (cam->cy - py) / cam->scale, vc.z};
        sp_vec3 w = sp_mat4_point(&inv_view, c);
        out->rest[3 * i] = w.x, out->rest[3 * i + 1] = w.y, out->rest[3 * i + 2] = w.z;
        bound[i] = mesh->skin[best_v];
    }
    // Smooth the skins along the curve: where the contour passes from one
    // bone's surface to another's (girdle to leg, leg to leg at the crotch)
    // the curve then stretches evenly instead of kinking at one point.
    sp_gen_skin* tmp_skin = sp_gen_check_alloc(malloc(sizeof(sp_gen_skin) * (size_t)points));
    for (int pass = 0; pass < 3; ++pass) {
        for (int i = 0; i < points; ++i) {
            const sp_gen_skin *a = &bound[(i + points - 1) % points], *b = &bound[i], *c = &bound[(i + 1) % points];
            sp_gen_skin r = {0};
            for (int q = 0; q < a->n; ++q)
                sp_gen_skin_add(&r, a->joint[q], 0.25 * a->w[q]);
            for (int q = 0; q < b->n; ++q)
                sp_gen_skin_add(&r, b->joint[q], 0.5 * b->w[q]);
            for (int q = 0; q < c->n; ++q)
                sp_gen_skin_add(&r, c->joint[q], 0.25 * c->w[q]);
            tmp_skin[i] = r;
        }
        memcpy(bound, tmp_skin, sizeof(sp_gen_skin) * (size_t)points);
    }
    for (int i = 0; i < points; ++i)
        sp_gen_skin_pack(&bound[i], out->joints + 4 * i, out->weights + 4 * i);
    free(tmp_skin), free(bound);
    free(nrm), free(acc), free(poly), free(cell), free(xy);
    return true;
}
