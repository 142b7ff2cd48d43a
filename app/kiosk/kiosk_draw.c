// kiosk_draw.c: one frame of the kiosk: the dragon (renderer), the strokes and
// outlines over it, then the flat UI (draw2d): toolbar, chips, hints, the
// save code, the idle countdown, the attract screen's titles; and the postcard.
#include "kiosk_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/kiosk_text.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

// High contrast, readable in a bright museum hall (display sRGB).
static const float k_navy[4] = {0.08f, 0.15f, 0.32f, 0.96f};
static const float k_grey[4] = {0.42f, 0.45f, 0.52f, 0.92f};
static const float k_white[4] = {1, 1, 1, 1};
static const float k_dim_white[4] = {0.85f, 0.87f, 0.9f, 1};
static const float k_ink[4] = {0.06f, 0.07f, 0.1f, 1};
static const float k_yellow[4] = {1.0f, 0.82f, 0.1f, 1};
static const float k_orange[4] = {1.0f, 0.55f, 0.12f, 1};
static const float k_green[4] = {0.1f, 0.5f, 0.24f, 0.97f};
static const float k_panel[4] = {0.05f, 0.07f, 0.12f, 0.82f};
static const float k_bar[4] = {0.05f, 0.07f, 0.12f, 0.55f};

// ------------------------------------------------------------------ scene

static void polyline_px(sp_kiosk* k, const float* xy, int n, bool closed, float width, const float rgba[4])
{
    if (n <= 0) return;
    if (n > k->scratch_cap) {
        sp_vec2* s = realloc(k->scratch, sizeof *s * (size_t)n);
        if (!s) return;
        k->scratch = s, k->scratch_cap = n;
    }
    for (int i = 0; i < n; ++i)
        k->scratch[i] = (sp_vec2){xy[2 * i], xy[2 * i + 1]};
    sp_renderer_draw_polyline(k->r, k->scratch, n, closed, width, rgba);
}

static void draw_line(sp_kiosk* k, const sp_kiosk_line* l, float width, const float rgba[4])
{
    polyline_px(k, l->xy, l->count, false, width, rgba);
}

// The flashed outline, one polyline per curve.
static void draw_outline(sp_kiosk* k, const float* xy, int n, const int* breaks, int nb, float width, const float rgba[4])
{
    int start = 0;
    for (int b = 0; b <= nb; ++b) {
        int end = b < nb ? breaks[b] : n;
        if (end > start) polyline_px(k, xy + 2 * start, end - start, false, width, rgba);
        start = end;
    }
}

static sp_camera scene_camera(sp_kiosk* k, bool orbit, bool* any, sp_vec3* lo, sp_vec3* hi)
{
    const sp_kiosk_ui* ui = k->ui;
    sp_camera cam = kiosk_fb_camera(k);
    *any = sp_dragon_bounds(k->dragon, lo, hi);
    if (!*any) return cam;
    sp_vec3 c = sp_v3_scale(sp_v3_add(*lo, *hi), 0.5);
    if (orbit && (ui->yaw != 0 || ui->pitch != 0)) {
        // Turn the world about the dragon's centre: the view matrix carries it,
        // so meshes, shadow and depth range all follow.
        sp_quat q = sp_quat_mul(sp_quat_axis_angle(sp_v3(1, 0, 0), ui->pitch), sp_quat_axis_angle(sp_v3(0, 1, 0), ui->yaw));
        sp_mat4 a = sp_mat4_trs(c, q, sp_v3(1, 1, 1));
        sp_mat4 b = sp_mat4_trs(sp_v3_scale(c, -1), sp_quat_identity(), sp_v3(1, 1, 1));
        sp_mat4 m = sp_mat4_mul(&a, &b);
        cam.view = sp_mat4_mul(&cam.view, &m);
    }
    // A sphere around the box bounds the depth whatever the orbit.
    double r = 0.5 * sp_v3_len(sp_v3_sub(*hi, *lo)) + 1e-3;
    sp_render_fit_depth(&cam, sp_v3_sub(c, sp_v3(r, r, r)), sp_v3_add(c, sp_v3(r, r, r)));
    return cam;
}

// The parts and the details drawn on them (ink `ink` pixels wide).
static void draw_dragon(sp_kiosk* k, const mesh_cache* meshes, bool hide_last, float ink)
{
    int n = sp_dragon_part_count(k->dragon);
    for (int i = 0; i < n; ++i) {
        if (hide_last && i == n - 1) continue;
        sp_render_mesh* m = mesh_cache_get(meshes, sp_dragon_part_get(k->dragon, i)->id);
        if (m) sp_renderer_draw_mesh(k->r, m, NULL);
    }
    for (int i = 0; i < sp_dragon_detail_count(k->dragon); ++i) {
        sp_dragon_detail e;
        if (sp_dragon_detail_get(k->dragon, i, &e) && e.xyz && !(hide_last && e.part == n - 1))
            sp_renderer_draw_curve3d_facing(k->r, e.xyz, e.normal, e.point_count, ink, SP_COLOR_INK);
    }
}

// ------------------------------------------------------------------ icons

static void icon(sp_draw2d* d, sp_kiosk_target t, bool alt, float cx, float cy, float s, const float c[4])
{
    float lw = fmaxf(2.0f, 0.13f * s);
    switch (t) {
    case SP_KT_UNDO: { // an arrow curling back to the left
        float r = 0.36f * s;
        sp_draw2d_arc(d, cx, cy + 0.05f * s, r, lw, 4.71f, 4.71f + 4.0f, c);
        float ax = cx - r, ay = cy + 0.05f * s;
        sp_draw2d_triangle(d, ax - 0.24f * s, ay - 0.04f * s, ax + 0.24f * s, ay - 0.04f * s, ax, ay + 0.3f * s, c);
        break;
    }
    case SP_KT_REDRAW: { // a pencil
        float x0 = cx + 0.32f * s, y0 = cy - 0.32f * s, x1 = cx - 0.14f * s, y1 = cy + 0.14f * s;
        sp_draw2d_line(d, x0, y0, x1, y1, 0.26f * s, c);
        sp_draw2d_triangle(d, x1 - 0.13f * s, y1 - 0.13f * s, x1 + 0.13f * s, y1 + 0.13f * s, cx - 0.4f * s, cy + 0.4f * s, c);
        break;
    }
    case SP_KT_START_OVER: { // a fresh page
        sp_draw2d_rect(d, cx - 0.3f * s, cy - 0.42f * s, 0.6f * s, 0.84f * s, 0.08f * s, lw, c);
        sp_draw2d_line(d, cx - 0.15f * s, cy, cx + 0.15f * s, cy, lw, c);
        sp_draw2d_line(d, cx, cy - 0.15f * s, cx, cy + 0.15f * s, lw, c);
        break;
    }
    case SP_KT_PLAY:
        if (alt) { // pause
            sp_draw2d_rect(d, cx - 0.3f * s, cy - 0.36f * s, 0.2f * s, 0.72f * s, 0.04f * s, 0, c);
            sp_draw2d_rect(d, cx + 0.1f * s, cy - 0.36f * s, 0.2f * s, 0.72f * s, 0.04f * s, 0, c);
        } else {
            sp_draw2d_triangle(d, cx - 0.26f * s, cy - 0.4f * s, cx - 0.26f * s, cy + 0.4f * s, cx + 0.4f * s, cy, c);
        }
        break;
    case SP_KT_TURN:
        if (alt) { // back to drawing: the pencil
            icon(d, SP_KT_REDRAW, false, cx, cy, s, c);
        } else { // an orbit around a dot
            float pts[2 * 24];
            int n = 0;
            for (int i = 0; i < 24; ++i, ++n) {
                float a = 0.5f + (float)i / 23.0f * 5.0f;
                pts[2 * n] = cx + 0.46f * s * cosf(a), pts[2 * n + 1] = cy + 0.2f * s * sinf(a);
            }
            sp_draw2d_polyline(d, pts, n, false, lw, c);
            float ex = pts[2 * n - 2], ey = pts[2 * n - 1];
            sp_draw2d_triangle(d, ex - 0.05f * s, ey - 0.2f * s, ex - 0.05f * s, ey + 0.2f * s, ex + 0.25f * s, ey + 0.05f * s,
                               c);
            sp_draw2d_disc(d, cx, cy, 0.11f * s, c);
        }
        break;
    case SP_KT_SAVE: { // an arrow into a tray
        sp_draw2d_line(d, cx, cy - 0.42f * s, cx, cy + 0.02f * s, lw, c);
        sp_draw2d_triangle(d, cx - 0.22f * s, cy - 0.04f * s, cx + 0.22f * s, cy - 0.04f * s, cx, cy + 0.2f * s, c);
        float tray[8] = {cx - 0.4f * s, cy + 0.08f * s, cx - 0.4f * s, cy + 0.38f * s,
                         cx + 0.4f * s, cy + 0.38f * s, cx + 0.4f * s, cy + 0.08f * s};
        sp_draw2d_polyline(d, tray, 4, false, lw, c);
        break;
    }
    default:
        break;
    }
}

// ------------------------------------------------------------------ UI

static void draw_button(sp_kiosk* k, sp_kiosk_target t)
{
    const sp_kiosk_ui* ui = k->ui;
    const sp_kiosk_rect* r = &ui->target[t];
    bool enabled = sp_kiosk_ui_target_enabled(ui, t);
    bool pressed = ui->pressed == t && ui->capture == SP_KCAP_TARGET;
    bool active = (t == SP_KT_REDRAW && ui->redraw_armed) || (t == SP_KT_START_OVER && sp_kiosk_ui_clear_armed(ui)) ||
                  (t == SP_KT_TURN && ui->mode == SP_KM_TURN);
    const float* bg = pressed ? k_yellow : active ? k_orange : enabled ? k_navy : k_grey;
    const float* fg = pressed || active ? k_ink : enabled ? k_white : k_dim_white;
    float rad = 0.16f * fminf(r->w, r->h);
    sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, 0, bg);
    // A white rim keeps dark buttons apart from a dark dragon behind them.
    sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, fmaxf(1.5f, 0.025f * r->h),
                   (const float[4]){1, 1, 1, enabled ? 0.9f : 0.5f});
    bool alt = (t == SP_KT_PLAY && ui->playing) || (t == SP_KT_TURN && ui->mode == SP_KM_TURN);
    sp_kiosk_text_id label = t == SP_KT_UNDO     ? SP_KTEXT_BUTTON_UNDO
                             : t == SP_KT_REDRAW ? SP_KTEXT_BUTTON_REDRAW
                             : t == SP_KT_START_OVER
                                 ? (sp_kiosk_ui_clear_armed(ui) ? SP_KTEXT_BUTTON_SURE : SP_KTEXT_BUTTON_START_OVER)
                             : t == SP_KT_PLAY ? (alt ? SP_KTEXT_BUTTON_PAUSE : SP_KTEXT_BUTTON_PLAY)
                             : t == SP_KT_TURN ? (alt ? SP_KTEXT_BUTTON_DRAW : SP_KTEXT_BUTTON_TURN)
                                               : SP_KTEXT_BUTTON_SAVE;
    float s = fminf(r->h * 0.46f, r->w * 0.5f);
    icon(k->d2, t, alt, r->x + 0.5f * r->w, r->y + 0.38f * r->h, s, fg);
    sp_draw2d_text_fit(k->d2, sp_kiosk_text(label), r->x + 0.5f * r->w, r->y + 0.79f * r->h, 0.21f * r->h, 0.9f * r->w,
                       SP_ALIGN_CENTER, fg);
}

static void draw_chips(sp_kiosk* k)
{
    const sp_kiosk_ui* ui = k->ui;
    for (int t = SP_KT_CHIP_LABEL; t <= SP_KT_CHIP_MORE; ++t) {
        if (!sp_kiosk_ui_target_visible(ui, (sp_kiosk_target)t)) continue;
        const sp_kiosk_rect* r = &ui->target[t];
        char text[SP_KIOSK_LABEL_MAX + 8];
        sp_kiosk_ui_target_text(ui, (sp_kiosk_target)t, text, sizeof text);
        bool pressed = (int)ui->pressed == t && ui->capture == SP_KCAP_TARGET;
        bool enabled = sp_kiosk_ui_target_enabled(ui, (sp_kiosk_target)t);
        float rad = 0.5f * r->h, px = 0.42f * r->h;
        if (t == SP_KT_CHIP_LABEL) {
            sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, 0, pressed ? k_yellow : k_white);
            sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, fmaxf(1.5f, 0.05f * r->h), k_ink);
            // A tick: this is what the kiosk thinks it is.
            float ix = r->x + 0.45f * r->h, iy = r->y + 0.5f * r->h, s = 0.3f * r->h;
            float tick[6] = {ix - 0.5f * s, iy, ix - 0.1f * s, iy + 0.4f * s, ix + 0.6f * s, iy - 0.45f * s};
            sp_draw2d_polyline(k->d2, tick, 3, false, fmaxf(2.0f, 0.09f * r->h), k_green);
            float left = r->x + 0.8f * r->h;
            sp_draw2d_text_fit(k->d2, text, 0.5f * (left + r->x + r->w - 0.3f * r->h), r->y + 0.5f * r->h, px,
                               r->x + r->w - left - 0.3f * r->h, SP_ALIGN_CENTER, k_ink);
        } else {
            sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, 0, pressed ? k_yellow : enabled ? k_navy : k_grey);
            sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, fmaxf(1.5f, 0.05f * r->h), pressed ? k_ink : k_white);
            sp_draw2d_text_fit(k->d2, text, r->x + 0.5f * r->w, r->y + 0.5f * r->h, px, r->w - 0.6f * r->h, SP_ALIGN_CENTER,
                               pressed ? k_ink : k_white);
        }
    }
}

static void draw_message(sp_kiosk* k, const sp_kiosk_rect* box, const char* text, float px, const float bg[4], const float fg[4])
{
    if (box->h <= 0) return;
    float w = sp_font_width(k->font, text, px) + 2.0f * px;
    if (w > box->w) w = box->w;
    float x = box->x + 0.5f * (box->w - w);
    sp_draw2d_rect(k->d2, x, box->y, w, box->h, 0.3f * box->h, 0, bg);
    sp_draw2d_text_fit(k->d2, text, x + 0.5f * w, box->y + 0.5f * box->h, px, w - 1.2f * px, SP_ALIGN_CENTER, fg);
}

// The save code, big, and what it is for under it, in the box the UI laid
// out (where its taps go).
static void draw_banner(sp_kiosk* k)
{
    const sp_kiosk_ui* ui = k->ui;
    float big = 0.75f * ui->big_text_px, small = ui->text_px;
    const sp_kiosk_rect* b = &ui->banner_box;
    sp_draw2d_rect(k->d2, b->x, b->y, b->w, b->h, 0.25f * b->h, 0, k_green);
    sp_draw2d_text_fit(k->d2, ui->banner[0], b->x + 0.5f * b->w, b->y + 0.2f * big + 0.85f * big, big, b->w - 1.2f * big,
                       SP_ALIGN_CENTER, k_white);
    sp_draw2d_text_fit(k->d2, ui->banner[1], b->x + 0.5f * b->w, b->y + b->h - 0.2f * big - 0.8f * small, small,
                       b->w - 1.2f * big, SP_ALIGN_CENTER, k_white);
}

static void draw_countdown(sp_kiosk* k, double left_s)
{
    const sp_kiosk_ui* ui = k->ui;
    sp_draw2d_rect(k->d2, 0, 0, (float)k->fb_w, (float)k->fb_h, 0, 0, (const float[4]){0, 0, 0, 0.45f});
    float cx = ui->canvas.x + 0.5f * ui->canvas.w, cy = ui->canvas.y + 0.45f * ui->canvas.h;
    float R = 0.22f * fminf(ui->canvas.w, ui->canvas.h);
    sp_draw2d_disc(k->d2, cx, cy, R, k_panel);
    float frac = (float)(left_s * 1000.0 / ui->desc.countdown_ms);
    sp_draw2d_arc(k->d2, cx, cy, 0.86f * R, 0.12f * R, 0, 6.2831853f * fminf(1.0f, frac), k_yellow);
    char num[16];
    snprintf(num, sizeof num, "%d", (int)ceil(left_s));
    sp_draw2d_text(k->d2, num, cx, cy, 0.8f * R, SP_ALIGN_CENTER, k_white);
    sp_kiosk_rect box = {ui->canvas.x + 0.05f * ui->canvas.w, cy + R + 0.6f * ui->text_px, 0.9f * ui->canvas.w,
                         2.2f * ui->text_px};
    draw_message(k, &box, sp_kiosk_text(SP_KTEXT_COUNTDOWN), ui->text_px, k_panel, k_white);
}

static float attract_title_px(const sp_kiosk_ui* ui, float H)
{
    return fminf(ui->big_text_px * 1.25f, 0.09f * H);
}

void kiosk_attract_band(const sp_kiosk_ui* ui, float H, float* top, float* bottom)
{
    *top = 0.09f * H + 0.9f * attract_title_px(ui, H) + 0.8f * ui->text_px;  // under the line under the title
    *bottom = H - (float)(ui->px_per_mm * (ui->desc.min_target_mm + 3 + 8)); // "Touch to start"'s top
}

static void draw_attract_ui(sp_kiosk* k)
{
    const sp_kiosk_ui* ui = k->ui;
    float W = (float)k->fb_w, H = (float)k->fb_h;
    float big = attract_title_px(ui, H), top, by;
    kiosk_attract_band(ui, H, &top, &by);
    (void)top; // the demo dragon's
    sp_draw2d_text_fit(k->d2, sp_kiosk_text(SP_KTEXT_TITLE), 0.5f * W, 0.09f * H, big, 0.92f * W, SP_ALIGN_CENTER, k_ink);
    sp_draw2d_text_fit(k->d2, sp_kiosk_text(SP_KTEXT_ATTRACT), 0.5f * W, 0.09f * H + 0.9f * big, ui->text_px, 0.92f * W,
                       SP_ALIGN_CENTER, (const float[4]){0.15f, 0.18f, 0.25f, 1});
    // "Touch to start" breathes gently so that it reads as alive, not as a hover.
    double a = 0.8 + 0.2 * sin(ui->now / 1000.0 * 2.4);
    const char* start = sp_kiosk_text(SP_KTEXT_TOUCH_TO_START);
    float bh = (float)(ui->px_per_mm * (ui->desc.min_target_mm + 3)),
          bw = fminf(0.9f * W, sp_font_width(k->font, start, ui->text_px * 1.3f) + 3 * bh);
    float bx = 0.5f * (W - bw);
    sp_draw2d_rect(k->d2, bx, by, bw, bh, 0.5f * bh, 0, (const float[4]){k_navy[0], k_navy[1], k_navy[2], (float)a});
    icon(k->d2, SP_KT_REDRAW, false, bx + 0.6f * bh, by + 0.5f * bh, 0.55f * bh, k_yellow);
    sp_draw2d_text_fit(k->d2, start, bx + 0.5f * bw + 0.3f * bh, by + 0.5f * bh, ui->text_px * 1.3f, bw - 1.6f * bh,
                       SP_ALIGN_CENTER, k_white);
}

static void draw_ui(sp_kiosk* k, int w, int h)
{
    const sp_kiosk_ui* ui = k->ui;
    sp_draw2d_begin(k->d2, w, h);
    if (ui->mode == SP_KM_ATTRACT) {
        draw_attract_ui(k);
    } else {
        // The toolbar's strip.
        if (ui->canvas.h < h) sp_draw2d_rect(k->d2, 0, ui->canvas.h, (float)w, (float)h - ui->canvas.h, 0, 0, k_bar);
        if (ui->canvas.w < w) sp_draw2d_rect(k->d2, ui->canvas.w, 0, (float)w - ui->canvas.w, (float)h, 0, 0, k_bar);
        for (int t = SP_KT_UNDO; t <= SP_KT_SAVE; ++t)
            draw_button(k, (sp_kiosk_target)t);
        draw_chips(k);
        kiosk_row_draw(k, k_navy, k_yellow, k_ink, k_green);
        const char* message = sp_kiosk_ui_message(ui);
        if (message) draw_message(k, &ui->hint_box, message, ui->text_px, k_panel, k_white);
        if (sp_kiosk_ui_banner_visible(ui)) draw_banner(k);
        double left = sp_kiosk_ui_countdown_s(ui);
        if (left > 0) draw_countdown(k, left);
    }
    sp_draw2d_end(k->d2);
}

// ------------------------------------------------------------------ frame

void kiosk_draw_frame(sp_kiosk* k, int w, int h)
{
    const sp_kiosk_ui* ui = k->ui;
    bool attract = ui->mode == SP_KM_ATTRACT;
    bool any = false;
    sp_vec3 lo, hi;
    sp_camera cam = attract ? kiosk_attract_camera(k) : scene_camera(k, true, &any, &lo, &hi);
    sp_renderer_begin(k->r, &cam, w, h);
    // A software rasteriser spends as long on the gradient's full-screen pass
    // as on a part: a flat background there (the gradient's middle tone).
    static const float k_flat[4] = {0.81f, 0.83f, 0.875f, 1};
    if (k->software)
        sp_renderer_clear(k->r, k_flat, NULL);
    else
        sp_renderer_clear(k->r, SP_COLOR_BACKGROUND_TOP, SP_COLOR_BACKGROUND_BOTTOM);
    if (attract) {
        kiosk_attract_draw_scene(k);
    } else {
        if (any) sp_renderer_draw_ground_shadow(k->r, lo, hi, 0);
        draw_dragon(k, &k->meshes, sp_kiosk_ui_flashing(ui), 0.8f * ui->line_px);
        // Strokes and outlines belong to the drawing view only.
        if (ui->yaw == 0 && ui->pitch == 0) {
            float lw = ui->line_px;
            double fade = sp_kiosk_ui_fade(ui);
            if (fade > 0)
                draw_line(k, &ui->fade_stroke, lw,
                          (const float[4]){SP_COLOR_STROKE[0], SP_COLOR_STROKE[1], SP_COLOR_STROKE[2], (float)fade});
            if (sp_kiosk_ui_offering(ui)) draw_line(k, &ui->held_stroke, lw, SP_COLOR_STROKE);
            for (int i = 0; i < ui->pending_count; ++i)
                draw_line(k, &ui->pending[(ui->pending_head + i) % SP_KIOSK_PENDING_MAX], lw, SP_COLOR_STROKE);
            if (sp_kiosk_ui_flashing(ui)) {
                draw_line(k, &ui->flash_stroke, lw, SP_COLOR_STROKE);
                draw_outline(k, ui->flash_outline.xy, ui->flash_outline.count, ui->flash_breaks, ui->flash_break_count,
                             0.75f * lw, SP_COLOR_ABSTRACTION);
            }
            if (ui->capture == SP_KCAP_STROKE) draw_line(k, &ui->stroke, lw, SP_COLOR_STROKE);
        }
    }
    sp_renderer_end(k->r);
    draw_ui(k, w, h);
}

// ------------------------------------------------------------------ postcard

sp_result kiosk_postcard(sp_kiosk* k, const char* code, sp_image* img, sp_error* err)
{
    const int W = 1200, H = 800;
    sp_vec3 lo, hi;
    if (!sp_dragon_bounds(k->dragon, &lo, &hi)) return sp_fail(err, SP_ERR_INVALID, "postcard: the dragon has no parts");
    // The dragon framed in the upper 80%, the title below it.
    sp_camera cam = sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, lo, hi, sp_v3(0, 0, -1), sp_v3(0, 1, 0), W, (int)(0.8 * H));
    cam.height = H;
    cam.cy += 0.02 * H;
    sp_render_fit_depth(&cam, lo, hi);
    GLint bound = 0; // restored after: the caller's framebuffer need not be the window's
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    sp_render_target* t;
    sp_render_target_create(W, H, 0, &t, err);
    if (!t) return SP_ERR_INTERNAL;
    // The postcard is kept: full meshes, not the window's coarse ones (sized
    // for the canvas on a software rasteriser, they show holes in the wings
    // and steps along the legs at 1200x800).
    mesh_cache full = {0};
    const mesh_cache* meshes = &k->meshes;
    if (k->meshes.lod_triangles > 0) {
        mesh_cache_sync(&full, k->r, k->dragon, true);
        meshes = &full;
    }
    sp_render_target_bind(t);
    sp_renderer_begin(k->r, &cam, W, H);
    sp_renderer_clear(k->r, (const float[4]){0.98f, 0.95f, 0.86f, 1}, (const float[4]){0.85f, 0.78f, 0.62f, 1});
    sp_renderer_draw_ground_shadow(k->r, lo, hi, 0);
    // The ink as thick on the dragon as on the canvas it was drawn on.
    draw_dragon(k, meshes, false, (float)(0.8 * k->ui->line_px * cam.scale / kiosk_fb_camera(k).scale));
    sp_renderer_end(k->r);
    mesh_cache_free(&full);
    sp_draw2d_begin(k->d2, W, H);
    sp_draw2d_rect(k->d2, 12, 12, W - 24.0f, H - 24.0f, 18, 5, k_ink);
    sp_draw2d_text(k->d2, sp_kiosk_text(SP_KTEXT_POSTCARD_TITLE), 48, H - 70.0f, 52, SP_ALIGN_LEFT, k_ink);
    char text[64];
    snprintf(text, sizeof text, "%s %s", sp_kiosk_text(SP_KTEXT_POSTCARD_CODE), code);
    sp_draw2d_text(k->d2, text, W - 48.0f, H - 70.0f, 40, SP_ALIGN_RIGHT, (const float[4]){0.3f, 0.25f, 0.15f, 1});
    sp_draw2d_end(k->d2);
    sp_result r = sp_render_target_read(t, img, err);
    sp_render_target_destroy(t);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)bound);
    return r;
}
