// ui.c: the kiosk's pure UI state machine (see ui.h). No GL, no clock, no
// allocation after create: a tap storm or 10^4 strokes a minute only ever
// touch fixed buffers.
#include "sp/kiosk_ui.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* const k_target_names[SP_KT_COUNT] = {
    NULL, "undo", "redraw", "start_over", "play", "turn", "save", "label", "guess1", "guess2",
};

static const char* const k_event_names[SP_KEV_TYPE_COUNT] = {NULL, "down", "move", "up", "cancel", "press", "frame"};

const char* sp_kiosk_target_name(sp_kiosk_target t)
{
    return t > SP_KT_NONE && t < SP_KT_COUNT ? k_target_names[t] : NULL;
}

sp_kiosk_target sp_kiosk_target_parse(const char* s)
{
    for (int i = 1; s && i < SP_KT_COUNT; ++i)
        if (strcmp(s, k_target_names[i]) == 0) return (sp_kiosk_target)i;
    return SP_KT_NONE;
}

const char* sp_kiosk_event_name(sp_kiosk_event_type t)
{
    return t > SP_KEV_NONE && t < SP_KEV_TYPE_COUNT ? k_event_names[t] : NULL;
}

sp_kiosk_event_type sp_kiosk_event_parse(const char* s)
{
    for (int i = 1; s && i < SP_KEV_TYPE_COUNT; ++i)
        if (strcmp(s, k_event_names[i]) == 0) return (sp_kiosk_event_type)i;
    return SP_KEV_NONE;
}

// ------------------------------------------------------------------ lines

static bool line_alloc(sp_kiosk_line* l, int cap, bool times)
{
    l->count = 0;
    l->xy = malloc(sizeof(float) * 2 * (size_t)cap);
    l->t = times ? malloc(sizeof(double) * (size_t)cap) : NULL;
    return l->xy && (!times || l->t);
}

static void line_free(sp_kiosk_line* l)
{
    free(l->xy);
    free(l->t);
    memset(l, 0, sizeof *l);
}

static void line_copy(sp_kiosk_line* dst, const sp_kiosk_line* src)
{
    dst->count = src->count;
    memcpy(dst->xy, src->xy, sizeof(float) * 2 * (size_t)src->count);
    if (dst->t && src->t) memcpy(dst->t, src->t, sizeof(double) * (size_t)src->count);
}

// Copies at most cap points of a float array (thinning evenly when longer).
static void line_set(sp_kiosk_line* dst, const float* xy, int n, int cap)
{
    dst->count = 0;
    if (!xy || n <= 0) return;
    int m = n <= cap ? n : cap;
    for (int i = 0; i < m; ++i) {
        int k = n <= cap ? i : (int)((long long)i * (n - 1) / (m - 1));
        float x = xy[2 * k], y = xy[2 * k + 1];
        if (!isfinite(x) || !isfinite(y)) continue;
        dst->xy[2 * dst->count] = x, dst->xy[2 * dst->count + 1] = y;
        if (dst->t) dst->t[dst->count] = 0;
        ++dst->count;
    }
}

// ------------------------------------------------------------------ create

static sp_kiosk_ui_desc with_defaults(const sp_kiosk_ui_desc* d)
{
    sp_kiosk_ui_desc o = d ? *d : (sp_kiosk_ui_desc){0};
    if (!(o.min_target_mm > 0)) o.min_target_mm = 15;
    if (!(o.button_mm > 0)) o.button_mm = 18;
    if (o.button_mm < o.min_target_mm) o.button_mm = o.min_target_mm;
    if (o.idle_ms == 0 || isnan(o.idle_ms)) o.idle_ms = 90000;
    if (!(o.countdown_ms > 0)) o.countdown_ms = 10000;
    if (!(o.flash_ms > 0)) o.flash_ms = 800;
    if (!(o.fade_ms > 0)) o.fade_ms = 1200;
    if (!(o.hint_ms > 0)) o.hint_ms = 4000;
    if (!(o.banner_ms > 0)) o.banner_ms = 15000;
    if (!(o.confirm_ms > 0)) o.confirm_ms = 3000;
    if (!(o.tap_mm > 0)) o.tap_mm = 4;
    return o;
}

sp_kiosk_ui* sp_kiosk_ui_create(const sp_kiosk_ui_desc* desc)
{
    sp_kiosk_ui* ui = calloc(1, sizeof *ui);
    if (!ui) return NULL;
    ui->desc = with_defaults(desc);
    bool ok = line_alloc(&ui->stroke, SP_KIOSK_STROKE_MAX, true) && line_alloc(&ui->job_stroke, SP_KIOSK_STROKE_MAX, true) &&
              line_alloc(&ui->flash_stroke, SP_KIOSK_STROKE_MAX, true) &&
              line_alloc(&ui->fade_stroke, SP_KIOSK_STROKE_MAX, true) &&
              line_alloc(&ui->flash_outline, SP_KIOSK_OUTLINE_MAX, false);
    for (int i = 0; i < SP_KIOSK_PENDING_MAX; ++i)
        ok = ok && line_alloc(&ui->pending[i], SP_KIOSK_STROKE_MAX, true);
    if (!ok) {
        sp_kiosk_ui_destroy(ui);
        return NULL;
    }
    ui->mode = SP_KM_ATTRACT;
    ui->playing = ui->desc.start_playing;
    ui->flash_until = ui->fade_until = ui->hint_until = ui->banner_until = ui->clear_armed_until = -1;
    sp_kiosk_ui_resize(ui, 1280, 800, 0);
    return ui;
}

void sp_kiosk_ui_destroy(sp_kiosk_ui* ui)
{
    if (!ui) return;
    line_free(&ui->stroke);
    line_free(&ui->job_stroke);
    line_free(&ui->flash_stroke);
    line_free(&ui->fade_stroke);
    line_free(&ui->flash_outline);
    for (int i = 0; i < SP_KIOSK_PENDING_MAX; ++i)
        line_free(&ui->pending[i]);
    free(ui);
}

// ------------------------------------------------------------------ layout

static double mm(const sp_kiosk_ui* ui, double v)
{
    return v * ui->px_per_mm;
}

// Chips sit in a row at the canvas's top-left and wrap when the row is full.
// Their width follows the text: a DejaVu Sans character averages ~0.6 of
// the text height, and the renderer shrinks text that would not fit anyway.
static void layout_chips(sp_kiosk_ui* ui)
{
    float h = (float)mm(ui, ui->desc.min_target_mm + 1.0);
    float pad = (float)mm(ui, 4.0), gap = (float)mm(ui, 3.0), margin = (float)mm(ui, 3.0);
    float chip_text = 0.42f * h;
    float x = ui->canvas.x + margin, y = ui->canvas.y + margin;
    float right = ui->canvas.x + ui->canvas.w - margin;
    for (int i = 0; i < 3; ++i) {
        sp_kiosk_rect* r = &ui->target[SP_KT_CHIP_LABEL + i];
        size_t n = strlen(ui->chip[i]);
        if (n == 0) {
            *r = (sp_kiosk_rect){0};
            continue;
        }
        // The label chip says "<icon> Wings"; guesses say "Wings?".
        float w = (float)(n + 1) * 0.62f * chip_text + 2 * pad + (i == 0 ? 0.9f * chip_text : 0.0f);
        float minw = (float)mm(ui, ui->desc.min_target_mm) * 1.6f;
        if (w < minw) w = minw;
        if (w > right - (ui->canvas.x + margin)) w = right - (ui->canvas.x + margin);
        if (w < (float)mm(ui, ui->desc.min_target_mm)) w = (float)mm(ui, ui->desc.min_target_mm);
        if (x + w > right && x > ui->canvas.x + margin) {
            x = ui->canvas.x + margin;
            y += h + gap;
        }
        *r = (sp_kiosk_rect){x, y, w, h};
        x += w + gap;
    }
    float below = y + h + gap;
    float hw = ui->canvas.w - 2 * margin;
    if (hw > (float)mm(ui, 220)) hw = (float)mm(ui, 220);
    ui->hint_box = (sp_kiosk_rect){ui->canvas.x + 0.5f * (ui->canvas.w - hw), below, hw, 2.2f * ui->text_px};
}

void sp_kiosk_ui_resize(sp_kiosk_ui* ui, int width, int height, double px_per_mm)
{
    if (width < 1) width = 1;
    if (height < 1) height = 1;
    if (!(px_per_mm > 0) || !isfinite(px_per_mm)) px_per_mm = 96.0 / 25.4;
    ui->width = width, ui->height = height, ui->px_per_mm = px_per_mm;
    const double W = width, H = height;
    const double min = mm(ui, ui->desc.min_target_mm);
    const double bh = mm(ui, ui->desc.button_mm);
    const double bw_pref = bh * 1.4; // room for an icon over a short word
    const double gap = mm(ui, 3.0), margin = mm(ui, 3.0);
    const int n = SP_KT_SAVE - SP_KT_UNDO + 1;
    ui->text_px = (float)fmax(10.0, mm(ui, 6.0));
    ui->big_text_px = (float)fmax(16.0, mm(ui, 13.0));
    ui->line_px = (float)fmax(3.0, mm(ui, 1.8));

    // Bottom strip: as many buttons per row as fit at their minimum width.
    int k = (int)floor((W - 2 * margin + gap) / (min + gap));
    k = k < 1 ? 1 : k > n ? n : k;
    int rows = (n + k - 1) / k;
    double bw_a = fmin(bw_pref * 1.15, fmax(min, (W - 2 * margin - (k - 1) * gap) / k));
    double strip_a = rows * bh + (rows - 1) * gap + 2 * margin;
    double area_a = W * fmax(0.0, H - strip_a);
    // Right strip: as many buttons per column as fit.
    int kc = (int)floor((H - 2 * margin + gap) / (bh + gap));
    kc = kc < 1 ? 1 : kc > n ? n : kc;
    int cols = (n + kc - 1) / kc;
    double strip_b = cols * bw_pref + (cols - 1) * gap + 2 * margin;
    double area_b = H * fmax(0.0, W - strip_b);
    bool bottom = area_a >= area_b;

    for (int i = 0; i < n; ++i) {
        sp_kiosk_rect* r = &ui->target[SP_KT_UNDO + i];
        if (bottom) {
            int row = i / k, col = i % k;
            int in_row = row == rows - 1 ? n - row * k : k;
            double row_w = in_row * bw_a + (in_row - 1) * gap;
            double x0 = 0.5 * (W - row_w);
            if (x0 < margin && W >= row_w + 2 * margin) x0 = margin;
            if (x0 < 0) x0 = 0;
            double y0 = H - strip_a + margin + row * (bh + gap);
            *r = (sp_kiosk_rect){(float)(x0 + col * (bw_a + gap)), (float)y0, (float)bw_a, (float)bh};
        } else {
            int col = i / kc, row = i % kc;
            int in_col = col == cols - 1 ? n - col * kc : kc;
            double col_h = in_col * bh + (in_col - 1) * gap;
            double y0 = 0.5 * (H - col_h);
            if (y0 < 0) y0 = 0;
            double x0 = W - strip_b + margin + col * (bw_pref + gap);
            *r = (sp_kiosk_rect){(float)x0, (float)(y0 + row * (bh + gap)), (float)bw_pref, (float)bh};
        }
    }
    if (bottom)
        ui->canvas = (sp_kiosk_rect){0, 0, (float)W, (float)fmax(0.0, H - strip_a)};
    else
        ui->canvas = (sp_kiosk_rect){0, 0, (float)fmax(0.0, W - strip_b), (float)H};
    layout_chips(ui);
}

// ------------------------------------------------------------------ queries

static bool visible(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    if (t <= SP_KT_NONE || t >= SP_KT_COUNT || ui->target[t].w <= 0) return false;
    if (ui->mode == SP_KM_ATTRACT) return false;
    if (t >= SP_KT_CHIP_LABEL) return ui->mode == SP_KM_DRAW && ui->part_count > 0 && ui->chip[t - SP_KT_CHIP_LABEL][0];
    return true;
}

bool sp_kiosk_ui_target_enabled(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    if (!visible(ui, t)) return false;
    switch (t) {
    case SP_KT_TURN:
        return ui->part_count > 0 || ui->mode == SP_KM_TURN;
    case SP_KT_CHIP_GUESS1:
    case SP_KT_CHIP_GUESS2:
        return !ui->refit_queued;
    case SP_KT_CHIP_LABEL:
        return true;
    case SP_KT_SAVE:
        return ui->part_count > 0 && !ui->save_queued;
    default:
        return ui->part_count > 0;
    }
}

sp_kiosk_target sp_kiosk_ui_hit(const sp_kiosk_ui* ui, float x, float y)
{
    if (!isfinite(x) || !isfinite(y)) return SP_KT_NONE;
    // Touch areas reach half the 3 mm gap beyond the drawn rectangle, so a
    // finger that lands on the rim still counts and neighbours never overlap.
    float slop = (float)mm(ui, 1.4);
    // Chips are drawn over the canvas: test them first.
    for (int t = SP_KT_COUNT - 1; t > SP_KT_NONE; --t) {
        if (!visible(ui, (sp_kiosk_target)t)) continue;
        const sp_kiosk_rect* r = &ui->target[t];
        if (x >= r->x - slop && x < r->x + r->w + slop && y >= r->y - slop && y < r->y + r->h + slop) return (sp_kiosk_target)t;
    }
    return SP_KT_NONE;
}

double sp_kiosk_ui_countdown_s(const sp_kiosk_ui* ui)
{
    if (ui->mode == SP_KM_ATTRACT || ui->desc.idle_ms < 0) return 0;
    double idle = ui->now - ui->last_input;
    double left = ui->desc.idle_ms - idle;
    if (left > ui->desc.countdown_ms || left <= 0) return 0;
    return left / 1000.0;
}

bool sp_kiosk_ui_flashing(const sp_kiosk_ui* ui)
{
    return ui->now < ui->flash_until;
}

double sp_kiosk_ui_fade(const sp_kiosk_ui* ui)
{
    if (ui->now >= ui->fade_until) return 0;
    return fmin(1.0, (ui->fade_until - ui->now) / ui->desc.fade_ms);
}

bool sp_kiosk_ui_hint_visible(const sp_kiosk_ui* ui)
{
    return ui->hint[0] && ui->now < ui->hint_until;
}

bool sp_kiosk_ui_banner_visible(const sp_kiosk_ui* ui)
{
    return ui->code[0] && ui->now < ui->banner_until;
}

bool sp_kiosk_ui_clear_armed(const sp_kiosk_ui* ui)
{
    return ui->now < ui->clear_armed_until;
}

// ------------------------------------------------------------------ jobs

static sp_kiosk_job* push_job(sp_kiosk_ui* ui, sp_kiosk_job_kind kind)
{
    if (ui->job_count >= SP_KIOSK_JOBS_MAX) {
        ++ui->dropped_jobs;
        return NULL;
    }
    sp_kiosk_job* j = &ui->jobs[(ui->job_head + ui->job_count++) % SP_KIOSK_JOBS_MAX];
    memset(j, 0, sizeof *j);
    j->kind = kind;
    j->heavy = kind == SP_KJOB_FIT || kind == SP_KJOB_REFIT || kind == SP_KJOB_SAVE;
    j->t_ms = ui->now;
    return j;
}

// Removes the oldest queued FIT job (its stroke is the oldest pending one).
static void drop_oldest_fit(sp_kiosk_ui* ui)
{
    for (int i = 0; i < ui->job_count; ++i) {
        sp_kiosk_job* j = &ui->jobs[(ui->job_head + i) % SP_KIOSK_JOBS_MAX];
        if (j->kind == SP_KJOB_FIT) {
            j->kind = SP_KJOB_NONE;
            break;
        }
    }
    ui->pending_head = (ui->pending_head + 1) % SP_KIOSK_PENDING_MAX;
    --ui->pending_count;
    ++ui->dropped_strokes;
}

static void set_hint(sp_kiosk_ui* ui, const char* text)
{
    snprintf(ui->hint, sizeof ui->hint, "%s", text ? text : "");
    ui->hint_until = ui->now + ui->desc.hint_ms;
}

static void clear_overlays(sp_kiosk_ui* ui)
{
    ui->flash_until = ui->fade_until = -1;
    ui->flash_stroke.count = ui->flash_outline.count = ui->fade_stroke.count = 0;
    ui->flash_break_count = 0;
}

static void set_chips(sp_kiosk_ui* ui, const char* label, const char* g1, const char* g2)
{
    const char* s[3] = {label, g1, g2};
    char tmp[3][SP_KIOSK_LABEL_MAX]; // the labels may point into ui->chip (refresh after undo)
    for (int i = 0; i < 3; ++i)
        snprintf(tmp[i], sizeof tmp[i], "%s", s[i] && label ? s[i] : "");
    memcpy(ui->chip, tmp, sizeof tmp);
    // A guess equal to the label (or to the other guess) would re-fit to the same thing.
    if (ui->chip[1][0] && strcmp(ui->chip[1], ui->chip[0]) == 0) ui->chip[1][0] = 0;
    if (ui->chip[2][0] && (strcmp(ui->chip[2], ui->chip[0]) == 0 || strcmp(ui->chip[2], ui->chip[1]) == 0)) ui->chip[2][0] = 0;
    if (!ui->chip[1][0] && ui->chip[2][0]) {
        memcpy(ui->chip[1], ui->chip[2], sizeof ui->chip[1]);
        ui->chip[2][0] = 0;
    }
    layout_chips(ui);
}

static void finish_stroke(sp_kiosk_ui* ui)
{
    sp_kiosk_line* s = &ui->stroke;
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < s->count; ++i)
        for (int c = 0; c < 2; ++c)
            lo[c] = fminf(lo[c], s->xy[2 * i + c]), hi[c] = fmaxf(hi[c], s->xy[2 * i + c]);
    double diag = s->count > 0 ? hypot(hi[0] - lo[0], hi[1] - lo[1]) : 0;
    if (s->count < 2 || diag < mm(ui, ui->desc.tap_mm)) {
        ++ui->taps;
        set_hint(ui, "Press, draw one line, then lift your finger");
        s->count = 0;
        return;
    }
    ++ui->strokes_finished;
    if (ui->pending_count == SP_KIOSK_PENDING_MAX) drop_oldest_fit(ui);
    sp_kiosk_job* j = push_job(ui, SP_KJOB_FIT);
    if (!j) {
        ++ui->dropped_strokes;
        s->count = 0;
        return;
    }
    int slot = (ui->pending_head + ui->pending_count++) % SP_KIOSK_PENDING_MAX;
    line_copy(&ui->pending[slot], s);
    j->replace = ui->redraw_armed;
    ui->redraw_armed = false;
    s->count = 0;
}

// ------------------------------------------------------------------ events

static void reset_to_attract(sp_kiosk_ui* ui)
{
    // Jobs already queued run first (their results are cleared by CLEAR).
    ui->pending_count = 0;
    for (int i = 0; i < ui->job_count; ++i) {
        sp_kiosk_job* j = &ui->jobs[(ui->job_head + i) % SP_KIOSK_JOBS_MAX];
        if (j->kind == SP_KJOB_FIT || j->kind == SP_KJOB_SAVE || j->kind == SP_KJOB_REFIT) j->kind = SP_KJOB_NONE;
    }
    ui->refit_queued = ui->save_queued = false;
    push_job(ui, SP_KJOB_CLEAR);
    ui->mode = SP_KM_ATTRACT;
    ui->mode_since = ui->now;
    ui->capture = SP_KCAP_NONE;
    ui->pressed = SP_KT_NONE;
    ui->stroke.count = 0;
    clear_overlays(ui);
    ui->hint[0] = 0;
    ui->code[0] = 0;
    ui->banner_until = ui->clear_armed_until = -1;
    ui->redraw_armed = false;
    ui->playing = ui->desc.start_playing;
    ui->anim_ms = 0;
    ui->yaw = ui->pitch = 0;
    ++ui->resets;
}

static void advance(sp_kiosk_ui* ui, double t)
{
    double dt = t - ui->now;
    if (!(dt > 0)) return;
    ui->now = t;
    if (ui->playing) ui->anim_ms += dt;
    if (ui->mode != SP_KM_TURN && (ui->yaw != 0 || ui->pitch != 0)) {
        // Back to the drawing view smoothly (~0.15 s time constant).
        double f = exp(-dt / 150.0);
        ui->yaw *= f, ui->pitch *= f;
        if (fabs(ui->yaw) < 1e-3 && fabs(ui->pitch) < 1e-3) ui->yaw = ui->pitch = 0;
    }
    if (ui->mode != SP_KM_ATTRACT && ui->desc.idle_ms > 0 && t - ui->last_input >= ui->desc.idle_ms) reset_to_attract(ui);
}

static void add_point(sp_kiosk_ui* ui, float x, float y, bool last)
{
    sp_kiosk_line* s = &ui->stroke;
    // Strokes that leave the window stay on its edge.
    x = fminf(fmaxf(x, 0.0f), (float)ui->width - 1.0f);
    y = fminf(fmaxf(y, 0.0f), (float)ui->height - 1.0f);
    if (s->count > 0) {
        float dx = x - s->xy[2 * s->count - 2], dy = y - s->xy[2 * s->count - 1];
        double d = hypot(dx, dy);
        if (d == 0 || (d < ui->stroke_spacing && !last)) return;
    }
    if (s->count == SP_KIOSK_STROKE_MAX) {
        // Thin to every other point (ends kept) and space further from now on:
        // memory stays bounded however long a finger wanders.
        int m = 0;
        for (int i = 0; i < s->count; i += 2, ++m) {
            s->xy[2 * m] = s->xy[2 * i], s->xy[2 * m + 1] = s->xy[2 * i + 1];
            s->t[m] = s->t[i];
        }
        s->count = m;
        ui->stroke_spacing *= 2.0;
    }
    s->xy[2 * s->count] = x, s->xy[2 * s->count + 1] = y;
    s->t[s->count] = ui->now;
    ++s->count;
}

static bool inside(const sp_kiosk_rect* r, float x, float y)
{
    return x >= r->x && x < r->x + r->w && y >= r->y && y < r->y + r->h;
}

static void activate(sp_kiosk_ui* ui, sp_kiosk_target t)
{
    ++ui->activations[t];
    if (!sp_kiosk_ui_target_enabled(ui, t)) {
        if (ui->part_count == 0 && t < SP_KT_CHIP_LABEL) set_hint(ui, "Draw a dragon part first");
        return;
    }
    switch (t) {
    case SP_KT_UNDO:
        if (push_job(ui, SP_KJOB_UNDO)) {
            clear_overlays(ui);
            ui->redraw_armed = false;
        }
        break;
    case SP_KT_REDRAW:
        ui->redraw_armed = !ui->redraw_armed;
        if (ui->redraw_armed)
            set_hint(ui, "Draw the new part: it replaces the last one");
        else
            ui->hint_until = -1;
        break;
    case SP_KT_START_OVER:
        if (sp_kiosk_ui_clear_armed(ui)) {
            if (push_job(ui, SP_KJOB_CLEAR)) {
                clear_overlays(ui);
                ui->redraw_armed = false;
                ui->clear_armed_until = -1;
                ui->hint_until = -1;
                ui->yaw = ui->pitch = 0;
                ui->mode = SP_KM_DRAW;
            }
        } else {
            ui->clear_armed_until = ui->now + ui->desc.confirm_ms;
            set_hint(ui, "Tap again to start over");
        }
        break;
    case SP_KT_PLAY:
        ui->playing = !ui->playing;
        break;
    case SP_KT_TURN:
        ui->mode = ui->mode == SP_KM_TURN ? SP_KM_DRAW : SP_KM_TURN;
        ui->mode_since = ui->now;
        if (ui->mode == SP_KM_TURN)
            set_hint(ui, "Drag to turn your dragon");
        else
            ui->hint_until = -1;
        break;
    case SP_KT_SAVE:
        if (ui->code[0] && ui->saved_revision == ui->revision) {
            ui->banner_until = ui->now + ui->desc.banner_ms; // same dragon: same code, no new files
        } else if (push_job(ui, SP_KJOB_SAVE)) {
            ui->save_queued = true;
        }
        break;
    case SP_KT_CHIP_LABEL:
        set_hint(ui, "Not right? Tap another guess");
        break;
    case SP_KT_CHIP_GUESS1:
    case SP_KT_CHIP_GUESS2: {
        sp_kiosk_job* j = push_job(ui, SP_KJOB_REFIT);
        if (j) {
            // Both live in *ui (GCC cannot tell they never overlap): copy by hand.
            const char* c = ui->chip[t - SP_KT_CHIP_LABEL];
            size_t n = strnlen(c, sizeof j->category - 1);
            memcpy(j->category, c, n);
            j->category[n] = 0;
            ui->refit_queued = true;
        }
        break;
    }
    default:
        break;
    }
}

static void end_capture(sp_kiosk_ui* ui, float x, float y, bool up)
{
    switch (ui->capture) {
    case SP_KCAP_STROKE:
        if (up) add_point(ui, x, y, true);
        finish_stroke(ui);
        break;
    case SP_KCAP_TARGET:
        if (up && ui->pressed != SP_KT_NONE && sp_kiosk_ui_hit(ui, x, y) == ui->pressed) activate(ui, ui->pressed);
        break;
    case SP_KCAP_ATTRACT:
        if (up) {
            ui->mode = SP_KM_DRAW;
            ui->mode_since = ui->now;
            set_hint(ui, "Draw a dragon part in one line: a head, wings, a tail...");
        }
        break;
    default:
        break;
    }
    ui->capture = SP_KCAP_NONE;
    ui->pressed = SP_KT_NONE;
}

static void on_down(sp_kiosk_ui* ui, float x, float y)
{
    if (ui->capture != SP_KCAP_NONE) end_capture(ui, ui->last_x, ui->last_y, false);
    bool countdown = sp_kiosk_ui_countdown_s(ui) > 0;
    ui->last_input = ui->now;
    ui->last_x = x, ui->last_y = y;
    if (countdown) { // the touch only says "still here"
        ui->capture = SP_KCAP_SWALLOW;
        return;
    }
    if (ui->mode == SP_KM_ATTRACT) {
        ui->capture = SP_KCAP_ATTRACT;
        return;
    }
    sp_kiosk_target t = sp_kiosk_ui_hit(ui, x, y);
    if (t != SP_KT_NONE) {
        ui->capture = SP_KCAP_TARGET;
        ui->pressed = t;
        return;
    }
    if (ui->mode == SP_KM_TURN) {
        ui->capture = SP_KCAP_ORBIT;
        return;
    }
    if (!inside(&ui->canvas, x, y)) {
        ui->capture = SP_KCAP_SWALLOW;
        return;
    }
    // A new stroke ends the flash at once: the visitor is already drawing on.
    if (sp_kiosk_ui_flashing(ui)) ui->flash_until = ui->now;
    ui->capture = SP_KCAP_STROKE;
    ui->stroke.count = 0;
    ui->stroke_spacing = fmax(0.5, mm(ui, 0.3));
    add_point(ui, x, y, false);
}

static void on_move(sp_kiosk_ui* ui, float x, float y)
{
    if (ui->capture == SP_KCAP_NONE) return; // no hover states
    ui->last_input = ui->now;
    switch (ui->capture) {
    case SP_KCAP_STROKE:
        add_point(ui, x, y, false);
        break;
    case SP_KCAP_ORBIT: {
        // Half the shorter side of the screen turns the dragon by 180 degrees.
        double k = M_PI / fmax(1.0, 0.5 * fmin(ui->width, ui->height));
        ui->yaw = remainder(ui->yaw + k * (x - ui->last_x), 2 * M_PI);
        ui->pitch = fmin(1.2, fmax(-1.2, ui->pitch + k * (y - ui->last_y)));
        break;
    }
    default:
        break;
    }
    ui->last_x = x, ui->last_y = y;
}

void sp_kiosk_ui_event(sp_kiosk_ui* ui, const sp_kiosk_event* ev)
{
    double t = isfinite(ev->t_ms) ? ev->t_ms : ui->now;
    advance(ui, t);
    float x = ev->x, y = ev->y;
    bool pos_ok = isfinite(x) && isfinite(y);
    switch (ev->type) {
    case SP_KEV_DOWN:
        if (ev->button == 0 && pos_ok) on_down(ui, x, y);
        break;
    case SP_KEV_MOVE:
        if (pos_ok) on_move(ui, x, y);
        break;
    case SP_KEV_UP:
        if (ev->button != 0 || ui->capture == SP_KCAP_NONE) break;
        if (!pos_ok) x = ui->last_x, y = ui->last_y;
        ui->last_input = ui->now;
        end_capture(ui, x, y, true);
        break;
    case SP_KEV_CANCEL:
        if (ui->capture != SP_KCAP_NONE) end_capture(ui, ui->last_x, ui->last_y, false);
        break;
    case SP_KEV_PRESS: {
        // A scripted tap lands in the middle of wherever the target is now.
        sp_kiosk_target tg = (sp_kiosk_target)ev->button;
        if (!visible(ui, tg)) break;
        const sp_kiosk_rect* r = &ui->target[tg];
        float cx = r->x + 0.5f * r->w, cy = r->y + 0.5f * r->h;
        on_down(ui, cx, cy);
        ui->last_input = ui->now;
        end_capture(ui, cx, cy, true);
        break;
    }
    default:
        break;
    }
}

// ------------------------------------------------------------------ results

bool sp_kiosk_ui_next_job(sp_kiosk_ui* ui, sp_kiosk_job* job)
{
    while (ui->job_count > 0) {
        sp_kiosk_job* j = &ui->jobs[ui->job_head];
        ui->job_head = (ui->job_head + 1) % SP_KIOSK_JOBS_MAX;
        --ui->job_count;
        if (j->kind == SP_KJOB_NONE) continue;
        *job = *j;
        if (j->kind == SP_KJOB_FIT) {
            line_copy(&ui->job_stroke, &ui->pending[ui->pending_head]);
            ui->pending_head = (ui->pending_head + 1) % SP_KIOSK_PENDING_MAX;
            --ui->pending_count;
            job->stroke = &ui->job_stroke;
        }
        if (j->kind == SP_KJOB_FIT || j->kind == SP_KJOB_REFIT) {
            ui->fit_in_flight = true;
            ui->inflight_kind = j->kind;
            ui->inflight_replace = j->replace;
        }
        return true;
    }
    return false;
}

void sp_kiosk_ui_fit_done(sp_kiosk_ui* ui, const sp_kiosk_fit_result* r)
{
    bool refit = ui->inflight_kind == SP_KJOB_REFIT;
    ui->fit_in_flight = false;
    if (refit) ui->refit_queued = false;
    if (!r->ok) {
        if (!refit) {
            line_copy(&ui->fade_stroke, &ui->job_stroke);
            ui->fade_until = ui->now + ui->desc.fade_ms;
            if (ui->inflight_replace) ui->redraw_armed = true; // still waiting for the replacement
        }
        set_hint(ui, r->hint ? r->hint
                     : refit ? "That shape did not fit there"
                             : "Hmm, what is that? Try one big line for a head, wings or a tail");
        return;
    }
    ui->part_count = r->part_count;
    set_chips(ui, r->category, r->guesses[0], r->guesses[1]);
    ++ui->revision;
    if (r->stroke && r->stroke_count > 0) {
        line_set(&ui->flash_stroke, r->stroke, r->stroke_count, SP_KIOSK_STROKE_MAX);
    } else if (!refit) {
        line_copy(&ui->flash_stroke, &ui->job_stroke);
    } else {
        ui->flash_stroke.count = 0;
    }
    line_set(&ui->flash_outline, r->outline, r->outline_count, SP_KIOSK_OUTLINE_MAX);
    ui->flash_break_count = 0;
    bool thinned = r->outline_count > SP_KIOSK_OUTLINE_MAX;
    for (int i = 0; !thinned && r->outline_breaks && i < r->outline_break_count && ui->flash_break_count < 64; ++i)
        if (r->outline_breaks[i] > 0 && r->outline_breaks[i] < ui->flash_outline.count)
            ui->flash_breaks[ui->flash_break_count++] = r->outline_breaks[i];
    ui->flash_until = ui->now + ui->desc.flash_ms;
    ui->fade_until = -1;
    if (r->hint)
        set_hint(ui, r->hint); // the part is there, but something needs saying
    else
        ui->hint_until = -1;
}

void sp_kiosk_ui_parts_changed(sp_kiosk_ui* ui, int part_count, const sp_kiosk_part_label* label)
{
    ui->part_count = part_count < 0 ? 0 : part_count;
    if (label && label->category && part_count > 0)
        set_chips(ui, label->category, label->guesses[0], label->guesses[1]);
    else
        set_chips(ui, NULL, NULL, NULL);
    ++ui->revision;
    clear_overlays(ui);
    if (ui->part_count == 0) ui->redraw_armed = false;
}

void sp_kiosk_ui_saved(sp_kiosk_ui* ui, bool ok, const char* code)
{
    ui->save_queued = false;
    ui->save_failed = !ok;
    if (ok && code && code[0]) {
        snprintf(ui->code, sizeof ui->code, "%s", code);
        ui->saved_revision = ui->revision;
        ui->banner_until = ui->now + ui->desc.banner_ms;
    } else {
        set_hint(ui, "Sorry, saving did not work. Please ask a guide");
    }
}
