// sketch_sheet.c: contact sheets of drawings on the CPU (sketch_sheet.h).
#include "sp/sketch_sheet.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_easy_font.h>

enum { MARGIN = 14, TEXT_H = 34, TITLE_H = 30 };

typedef struct rgb {
    float r, g, b;
} rgb;

static const rgb k_stroke_colors[] = {{0.08f, 0.20f, 0.62f}, {0.78f, 0.33f, 0.05f}, {0.10f, 0.55f, 0.20f}, {0.55f, 0.12f, 0.55f}};

// Blends colour c at coverage a (0..1) into pixel (x, y); outside is ignored.
static void blend(sp_image* img, int x, int y, rgb c, float a)
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height || a <= 0) return;
    if (a > 1) a = 1;
    uint8_t* p = sp_image_at(img, x, y);
    p[0] = (uint8_t)lrintf(p[0] * (1 - a) + 255.f * c.r * a);
    p[1] = (uint8_t)lrintf(p[1] * (1 - a) + 255.f * c.g * a);
    p[2] = (uint8_t)lrintf(p[2] * (1 - a) + 255.f * c.b * a);
}

static void fill_rect(sp_image* img, double x0, double y0, double x1, double y1, rgb c)
{
    for (int y = (int)floor(y0); y < (int)ceil(y1); ++y)
        for (int x = (int)floor(x0); x < (int)ceil(x1); ++x)
            blend(img, x, y, c, 1.0f);
}

// An anti-aliased segment of width w: coverage from the distance to the segment.
static void segment(sp_image* img, sp_vec2 a, sp_vec2 b, double w, rgb c)
{
    double r = 0.5 * w;
    int x0 = (int)floor(fmin(a.x, b.x) - r - 1), x1 = (int)ceil(fmax(a.x, b.x) + r + 1);
    int y0 = (int)floor(fmin(a.y, b.y) - r - 1), y1 = (int)ceil(fmax(a.y, b.y) + r + 1);
    double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            double px = x + 0.5 - a.x, py = y + 0.5 - a.y;
            double t = l2 > 0 ? fmin(1.0, fmax(0.0, (px * dx + py * dy) / l2)) : 0.0;
            double d = hypot(px - t * dx, py - t * dy);
            float cov = (float)(r + 0.5 - d);
            // Segments of one polyline overlap at joints: keep the stronger coverage, do not add.
            if (cov > 0) {
                if (x < 0 || y < 0 || x >= img->width || y >= img->height) continue;
                uint8_t* p = sp_image_at(img, x, y);
                float have = 1.0f - (float)(p[0] + p[1] + p[2]) / (3 * 255.f); // ink already there (paper is white)
                if (cov > have) blend(img, x, y, c, cov > 1 ? 1 : cov);
            }
        }
}

static void dot(sp_image* img, sp_vec2 p, double rad, rgb c)
{
    for (int y = (int)floor(p.y - rad - 1); y <= (int)ceil(p.y + rad + 1); ++y)
        for (int x = (int)floor(p.x - rad - 1); x <= (int)ceil(p.x + rad + 1); ++x)
            blend(img, x, y, c, (float)(rad + 0.5 - hypot(x + 0.5 - p.x, y + 0.5 - p.y)));
}

// ASCII text with stb_easy_font's quads, scaled; a text wider than max_w
// pixels is drawn smaller (down to 0.65 of scale), and only then cut, ending
// in "..": a name cut silently reads as another name.
static void text(sp_image* img, double x, double y, const char* s, double scale, double max_w, rgb c)
{
    if (!s || !*s) return;
    char buf[128]; // stb_easy_font needs about 270 bytes of quads a character
    snprintf(buf, sizeof buf, "%s", s);
    double w = stb_easy_font_width(buf);
    if (w * scale > max_w) scale = fmax(0.65 * scale, max_w / w);
    if (w * scale > max_w) {
        size_t n = strlen(buf);
        while (n > 3 && stb_easy_font_width(buf) * scale > max_w) {
            buf[--n] = 0;
            buf[n - 2] = buf[n - 1] = '.';
        }
    }
    char vb[128 * 300];
    int quads = stb_easy_font_print(0, 0, buf, NULL, vb, (int)sizeof vb);
    for (int q = 0; q < quads; ++q) {
        const float* v0 = (const float*)(vb + (size_t)q * 4 * 16);
        const float* v2 = (const float*)(vb + ((size_t)q * 4 + 2) * 16);
        fill_rect(img, x + scale * v0[0], y + scale * v0[1], x + scale * v2[0], y + scale * v2[1], c);
    }
}

sp_result sp_sheet_render(const sp_sheet_item* items, int n, const sp_sheet_desc* desc, sp_image* out, sp_error* err)
{
    sp_sheet_desc d = desc ? *desc : (sp_sheet_desc){0};
    int cell = d.cell > 0 ? d.cell : 220;
    int cols = d.cols > 0 ? d.cols : 8;
    if (n < 1) return sp_fail(err, SP_ERR_INVALID, "contact sheet: nothing to draw");
    if (cols > n) cols = n;
    int rows = (n + cols - 1) / cols;
    int top = d.title ? TITLE_H : 0;
    long long W = (long long)cols * cell, H = (long long)rows * (cell + TEXT_H) + top;
    if (W > 16384 || H > 65536)
        return sp_fail(err, SP_ERR_INVALID, "contact sheet: %d drawings make a sheet too large (%lld x %lld)", n, W, H);
    sp_result r = sp_image_alloc(out, (int)W, (int)H);
    if (r != SP_OK) return sp_fail(err, r, "contact sheet: out of memory");
    memset(out->rgba, 255, (size_t)W * (size_t)H * 4);
    const rgb ink = {0.1f, 0.1f, 0.1f}, grey = {0.45f, 0.45f, 0.45f}, frame = {0.85f, 0.85f, 0.85f}, red = {0.85f, 0.1f, 0.1f};
    if (d.title) text(out, 8, 8, d.title, 2.0, (double)W - 16, ink);
    for (int i = 0; i < n; ++i) {
        double cx = (double)(i % cols) * cell, cy = (double)(i / cols) * (cell + TEXT_H) + top;
        rgb fc = items[i].highlight ? red : frame;
        double fw = items[i].highlight ? 3 : 1;
        fill_rect(out, cx, cy, cx + cell, cy + fw, fc);
        fill_rect(out, cx, cy + cell + TEXT_H - fw, cx + cell, cy + cell + TEXT_H, fc);
        fill_rect(out, cx, cy, cx + fw, cy + cell + TEXT_H, fc);
        fill_rect(out, cx + cell - fw, cy, cx + cell, cy + cell + TEXT_H, fc);
        const sp_sketch* s = items[i].sketch;
        sp_vec2 lo, hi;
        if (s && sp_sketch_is_valid(s) && sp_sketch_bounds(s, &lo, &hi)) {
            double span = fmax(fmax(hi.x - lo.x, hi.y - lo.y), 1e-9), k = (cell - 2.0 * MARGIN) / span;
            double ox = cx + 0.5 * cell - k * 0.5 * (lo.x + hi.x), oy = cy + 0.5 * cell - k * 0.5 * (lo.y + hi.y);
            for (int j = 0; j < s->stroke_count; ++j) {
                const sp_stroke* st = &s->strokes[j];
                rgb c = k_stroke_colors[j % (int)(sizeof k_stroke_colors / sizeof k_stroke_colors[0])];
                for (int m = 0; m + 1 < st->count; ++m)
                    segment(out, (sp_vec2){ox + k * st->points[m].x, oy + k * st->points[m].y},
                            (sp_vec2){ox + k * st->points[m + 1].x, oy + k * st->points[m + 1].y}, 2.0, c);
                if (st->count > 0) {
                    sp_vec2 p0 = {ox + k * st->points[0].x, oy + k * st->points[0].y};
                    dot(out, p0, 3.5, c);
                    if (d.number_strokes) {
                        char num[16];
                        snprintf(num, sizeof num, "%d", j);
                        text(out, p0.x + 4, p0.y - 12, num, 1.5, 40, c);
                    }
                }
            }
        }
        text(out, cx + 6, cy + cell + 2, items[i].label, 2.0, cell - 12.0, ink);
        text(out, cx + 6, cy + cell + 19, items[i].note, 1.5, cell - 12.0, grey);
    }
    return SP_OK;
}

sp_result sp_sheet_write_png(const sp_sheet_item* items, int n, const sp_sheet_desc* desc, const char* path, sp_error* err)
{
    sp_image img = {0};
    sp_result r = sp_sheet_render(items, n, desc, &img, err);
    if (r == SP_OK) r = sp_image_write_png(&img, path, err);
    sp_image_free(&img);
    return r;
}
