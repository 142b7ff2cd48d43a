// ui.c: the kiosk's pure UI state machine (see sp/kiosk_ui.h). No GL, no clock, no
// allocation after create: a tap storm or 10^4 strokes a minute only ever
// touch fixed buffers.
#include "sp/kiosk_ui.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/kiosk_text.h"

static const char* const k_target_names[SP_KT_COUNT] = {
    NULL,    "undo",  "redraw", "start_over", "play",  "turn",  "save",  "label", "guess1", "guess2", "guess3", "more",
    "part1", "part2", "part3",  "part4",      "part5", "part6", "part7", "part8", "part9",  "part10", "part11", "part12",
};
_Static_assert(SP_KIOSK_ROW_MAX == 12, "k_target_names lists part1..part12");

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
    // The countdown is a warning, not most of the wait: a short --idle
    // would otherwise show it nearly all the time.
    if (o.idle_ms > 0 && o.countdown_ms > o.idle_ms / 3) o.countdown_ms = o.idle_ms / 3;
    if (!(o.flash_ms > 0)) o.flash_ms = 800;
    if (!(o.fade_ms > 0)) o.fade_ms = 1200;
    if (!(o.offer_ms > 0)) o.offer_ms = 8000;
    if (!(o.hint_ms > 0)) o.hint_ms = 4000;
    if (!(o.banner_ms > 0)) o.banner_ms = 15000;
    if (!(o.confirm_ms > 0)) o.confirm_ms = 3000;
    if (!(o.tap_mm > 0)) o.tap_mm = 4;
    if (o.join_ms == 0 || isnan(o.join_ms)) o.join_ms = 200;
    if (!(o.join_mm > 0)) o.join_mm = 8;
    return o;
}

sp_result sp_kiosk_ui_create(const sp_kiosk_ui_desc* desc, sp_kiosk_ui** out, sp_error* err)
{
    *out = NULL;
    sp_kiosk_ui* ui = calloc(1, sizeof *ui);
    if (!ui) return sp_fail(err, SP_ERR_NO_MEMORY, "kiosk: out of memory making the UI");
    ui->desc = with_defaults(desc);
    bool ok =
        line_alloc(&ui->stroke, SP_KIOSK_STROKE_MAX, true) && line_alloc(&ui->job_stroke, SP_KIOSK_STROKE_MAX, true) &&
        line_alloc(&ui->flash_stroke, SP_KIOSK_STROKE_MAX, true) && line_alloc(&ui->fade_stroke, SP_KIOSK_STROKE_MAX, true) &&
        line_alloc(&ui->held_stroke, SP_KIOSK_STROKE_MAX, true) && line_alloc(&ui->last_stroke, SP_KIOSK_STROKE_MAX, true) &&
        line_alloc(&ui->scene, SP_KIOSK_STROKE_MAX, false) && line_alloc(&ui->flash_outline, SP_KIOSK_OUTLINE_MAX, false);
    for (int i = 0; i < SP_KIOSK_PENDING_MAX; ++i)
        ok = ok && line_alloc(&ui->pending[i], SP_KIOSK_STROKE_MAX, true);
    if (!ok) {
        sp_kiosk_ui_destroy(ui);
        return sp_fail(err, SP_ERR_NO_MEMORY, "kiosk: out of memory making the UI");
    }
    ui->mode = SP_KM_ATTRACT;
    ui->playing = ui->desc.start_playing;
    ui->flash_until = ui->fade_until = ui->held_until = ui->hint_until = ui->banner_until = ui->clear_armed_until = -1;
    ui->undo_at = ui->target_at = -SP_KIOSK_REPEAT_MIN_MS;
    sp_kiosk_ui_resize(ui, 1280, 800, 0);
    *out = ui;
    return SP_OK;
}

void sp_kiosk_ui_destroy(sp_kiosk_ui* ui)
{
    if (!ui) return;
    line_free(&ui->stroke);
    line_free(&ui->job_stroke);
    line_free(&ui->flash_stroke);
    line_free(&ui->fade_stroke);
    line_free(&ui->held_stroke);
    line_free(&ui->scene);
    line_free(&ui->last_stroke);
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

static bool offering(const sp_kiosk_ui* ui)
{
    return ui->held_stroke.count > 0;
}

// "Other?" goes with a part's own chips (not a refused stroke's),
// when there is a row of parts to open.
static bool more_shown(const sp_kiosk_ui* ui)
{
    return !ui->chips_offer && ui->chip[0][0] && ui->row_count > 0;
}

// The row opened by "Other?" for the last part (and still about it).
static bool row_for_part(const sp_kiosk_ui* ui)
{
    return ui->row_open && more_shown(ui);
}

// The row of parts: a refused stroke's offer, or opened for the last part.
static bool row_shown(const sp_kiosk_ui* ui)
{
    return ui->row_count > 0 && (offering(ui) || row_for_part(ui));
}

// The row opened for the last part holds every guess: it takes the guess
// chips' place (on a small screen both would not fit above the toolbar).
static bool guess_hidden(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    return t >= SP_KT_CHIP_GUESS1 && t <= SP_KT_CHIP_GUESS3 && row_for_part(ui);
}

// Points of a line inside rect r.
static int points_in(const sp_kiosk_line* l, const sp_kiosk_rect* r)
{
    int n = 0;
    for (int i = 0; i < l->count; ++i) {
        float x = l->xy[2 * i], y = l->xy[2 * i + 1];
        n += x >= r->x && x < r->x + r->w && y >= r->y && y < r->y + r->h;
    }
    return n;
}

// Points of a line with y in [y0, y1), at any x.
static int points_within(const sp_kiosk_line* l, float y0, float y1)
{
    return points_in(l, &(sp_kiosk_rect){-1e9f, y0, 2e9f, y1 - y0});
}

// The stroke the row is about stays in sight (the refused one, or the last
// part's, kept from its flash): when the parts row and the hint under it
// (from top to end) would cover more of it than at the canvas's bottom,
// they go there, the hint above the row. The chips stay at the top.
static void keep_stroke_in_sight(sp_kiosk_ui* ui, float top, float end, float margin, float gap)
{
    const sp_kiosk_line* l = offering(ui) ? &ui->held_stroke : &ui->flash_stroke;
    float bottom = ui->canvas.y + ui->canvas.h - margin, start = bottom - (end - top);
    if (start <= top || points_within(l, top, end) <= points_within(l, start, bottom)) return;
    float row_end = end - ui->hint_box.h - gap, dy = bottom - row_end;
    for (int i = 0; i < ui->row_fit; ++i)
        ui->target[SP_KT_PART1 + i].y += dy;
    ui->hint_box.y = start;
}

// Points of the lines the chips are about (the refused stroke offered, or
// the last part's stroke and fitted outline), and of the parts on the
// canvas (the scene), under the chips.
static int chips_cover(const sp_kiosk_ui* ui)
{
    int n = 0;
    for (int t = SP_KT_CHIP_LABEL; t <= SP_KT_CHIP_MORE; ++t)
        n += (offering(ui) ? points_in(&ui->held_stroke, &ui->target[t])
                           : points_in(&ui->flash_stroke, &ui->target[t]) + points_in(&ui->flash_outline, &ui->target[t])) +
             points_in(&ui->scene, &ui->target[t]);
    return n;
}

// Each row of chips moved to end at `right`, in the same order.
static void chips_to_right(sp_kiosk_ui* ui, float right)
{
    enum { first = SP_KT_CHIP_LABEL, n = SP_KT_CHIP_MORE - SP_KT_CHIP_LABEL + 1 };
    sp_kiosk_rect* c = &ui->target[first];
    float shift[n];
    for (int i = 0; i < n; ++i) {
        float end = c[i].x + c[i].w; // its row's end
        for (int j = 0; j < n; ++j)
            if (c[j].w > 0 && c[j].y == c[i].y) end = fmaxf(end, c[j].x + c[j].w);
        shift[i] = right - end;
    }
    for (int i = 0; i < n; ++i)
        if (c[i].w > 0) c[i].x += shift[i];
}

// The chips a screen too small for all of them leaves out, least useful
// first: the guesses from the last (the parts row offers every part), then
// the label (the row draws the part's own tile as chosen), "Other?" last.
static const sp_kiosk_target k_drop_order[] = {SP_KT_CHIP_GUESS3, SP_KT_CHIP_GUESS2, SP_KT_CHIP_GUESS1, SP_KT_CHIP_LABEL,
                                               SP_KT_CHIP_MORE};
enum { DROP_MAX = sizeof k_drop_order / sizeof k_drop_order[0] };

static bool dropped(sp_kiosk_target t, int drop)
{
    for (int i = 0; i < drop; ++i)
        if (k_drop_order[i] == t) return true;
    return false;
}

// Chips sit in a row at the canvas's top-left and wrap when the row is
// full, all but the `drop` least useful. Chip widths follow the text: a
// DejaVu Sans character averages ~0.6 of the text height, and the renderer
// shrinks text that would not fit anyway. Returns where what goes under
// them starts (the canvas's top margin when none is shown).
static float line_up_chips(sp_kiosk_ui* ui, int drop, float h)
{
    float pad = (float)mm(ui, 4.0), gap = (float)mm(ui, 3.0), margin = (float)mm(ui, 3.0);
    float min = (float)mm(ui, ui->desc.min_target_mm);
    float chip_text = 0.42f * h;
    float left = ui->canvas.x + margin, right = ui->canvas.x + ui->canvas.w - margin;
    float x = left, y = ui->canvas.y + margin;
    bool any = false;
    for (int i = 0; i < 5; ++i) {
        sp_kiosk_target t = (sp_kiosk_target)(SP_KT_CHIP_LABEL + i);
        sp_kiosk_rect* r = &ui->target[t];
        char text[SP_KIOSK_TEXT_MAX];
        size_t n = strlen(sp_kiosk_ui_target_text(ui, t, text, sizeof text));
        if (n == 0 || (t == SP_KT_CHIP_MORE && !more_shown(ui)) || guess_hidden(ui, t) || dropped(t, drop)) {
            *r = (sp_kiosk_rect){0};
            continue;
        }
        // The label chip says "<tick> Wings"; guesses say "Wings?".
        float w = (float)(n + 1) * 0.62f * chip_text + 2 * pad + (i == 0 ? 0.9f * chip_text : 0.0f);
        if (w < min * 1.6f) w = min * 1.6f;
        if (w > right - left) w = right - left;
        if (w < min) w = min;
        if (x + w > right && x > left) {
            x = left;
            y += h + gap;
        }
        *r = (sp_kiosk_rect){x, y, w, h};
        x += w + gap;
        any = true;
    }
    return any ? y + h + gap : y;
}

// A stroke drawn at the top-left (the one the chips are about, or a part
// drawn before: a dragon drawn in the corner had its head under them)
// would be under them: they go to the top-right when less is there, or to
// the bottom (below); `end` is where they end. Returns how far they went down.
static float chips_out_of_the_way(sp_kiosk_ui* ui, float end)
{
    float margin = (float)mm(ui, 3.0), right = ui->canvas.x + ui->canvas.w - margin;
    int covered = chips_cover(ui);
    float up = 0; // how far the chips went down to the canvas's bottom
    if (covered == 0) return 0;
    sp_kiosk_rect at_left[SP_KT_CHIP_MORE - SP_KT_CHIP_LABEL + 1];
    memcpy(at_left, &ui->target[SP_KT_CHIP_LABEL], sizeof at_left);
    chips_to_right(ui, right);
    if (chips_cover(ui) >= covered) memcpy(&ui->target[SP_KT_CHIP_LABEL], at_left, sizeof at_left); // no better
    covered = chips_cover(ui);
    // A stroke along the whole top (wings reaching the top edge) lay
    // under them either way: they go to the bottom when less is there,
    // left or right. Not with the parts row, which goes under them, nor
    // where they fill a quarter of the canvas (a phone's).
    if (covered > 0 && !row_shown(ui) && end - ui->canvas.y < 0.25f * ui->canvas.h) {
        sp_kiosk_rect kept[SP_KT_CHIP_MORE - SP_KT_CHIP_LABEL + 1];
        memcpy(kept, &ui->target[SP_KT_CHIP_LABEL], sizeof kept);
        float dy = ui->canvas.y + ui->canvas.h - margin - end;
        for (int side = 0; side < 2 && covered > 0; ++side) {
            memcpy(&ui->target[SP_KT_CHIP_LABEL], at_left, sizeof at_left);
            for (int t = SP_KT_CHIP_LABEL; t <= SP_KT_CHIP_MORE; ++t)
                if (ui->target[t].w > 0) ui->target[t].y += dy;
            if (side) chips_to_right(ui, right);
            int c = chips_cover(ui);
            if (c < covered) covered = c, up = dy, memcpy(kept, &ui->target[SP_KT_CHIP_LABEL], sizeof kept);
        }
        memcpy(&ui->target[SP_KT_CHIP_LABEL], kept, sizeof kept);
    }
    return up;
}

// The parts row from `below` down: an outline over its name, 26 x 22 mm,
// smaller (down to the smallest target) where the rows and the hint would
// not fit on the canvas. Sets row_fit; returns where the hint goes.
static float layout_row(sp_kiosk_ui* ui, float below)
{
    float gap = (float)mm(ui, 3.0), margin = (float)mm(ui, 3.0), min = (float)mm(ui, ui->desc.min_target_mm);
    float left = ui->canvas.x + margin, right = ui->canvas.x + ui->canvas.w - margin;
    float chips_end = below;
    bool row = row_shown(ui);
    float bottom = ui->canvas.y + ui->canvas.h - 2.2f * ui->text_px;
    for (float scale = 1.0f; row; scale -= 0.1f) {
        float bw = fmaxf((float)mm(ui, 26.0) * scale, min), bh = fmaxf((float)mm(ui, 22.0) * scale, min);
        if (bw > right - left) bw = fmaxf(right - left, min);
        float x = left, y = below;
        for (int i = 0; i < ui->row_count; ++i) {
            if (x + bw > right && x > left) {
                x = left;
                y += bh + gap;
            }
            ui->target[SP_KT_PART1 + i] = (sp_kiosk_rect){x, y, bw, bh};
            x += bw + gap;
        }
        if (y + bh + gap <= bottom || (bw <= min && bh <= min)) {
            below = y + bh + gap;
            break;
        }
    }
    // Tiles that do not fit even at the smallest target size (a phone, a
    // portrait tablet with the guesses on a line each) are not offered:
    // past the canvas they lay over the toolbar and took its taps.
    ui->row_fit = 0;
    float canvas_end = ui->canvas.y + ui->canvas.h - margin, canvas_right = ui->canvas.x + ui->canvas.w;
    for (; row && ui->row_fit < ui->row_count; ++ui->row_fit) {
        const sp_kiosk_rect* r = &ui->target[SP_KT_PART1 + ui->row_fit];
        if (r->y + r->h > canvas_end || r->x + r->w > canvas_right) break;
    }
    if (row && ui->row_fit < ui->row_count) {
        // The hint goes under the tiles shown (under the chips when none is).
        const sp_kiosk_rect* last = &ui->target[SP_KT_PART1 + ui->row_fit - 1];
        below = ui->row_fit > 0 ? last->y + last->h + gap : chips_end;
    }
    for (int i = ui->row_fit; i < SP_KIOSK_ROW_MAX; ++i)
        ui->target[SP_KT_PART1 + i] = (sp_kiosk_rect){0};
    return below;
}

// The chips, while a refused stroke is offered or "Other?" is open the row
// of parts under them, and the hint under both.
static void layout_chips(sp_kiosk_ui* ui)
{
    float h = (float)mm(ui, ui->desc.min_target_mm + 1.0), gap = (float)mm(ui, 3.0), margin = (float)mm(ui, 3.0);
    float end = ui->canvas.y + ui->canvas.h - margin;
    // Chips run past the canvas lay over the toolbar and took its taps (an
    // outside review: on a small phone a tap on Undo opened the parts row):
    // the least useful go until the chips fit on the canvas, and the parts
    // row when shown offers every part, or as many as it can.
    int best = DROP_MAX, best_fit = -1;
    for (int drop = 0; drop <= DROP_MAX; ++drop) {
        float below = line_up_chips(ui, drop, h);
        if (below - gap > end && drop < DROP_MAX) continue;
        if (!row_shown(ui)) {
            best = drop;
            break;
        }
        layout_row(ui, below);
        if (ui->row_fit > best_fit) best = drop, best_fit = ui->row_fit;
        if (ui->row_fit == ui->row_count) break;
    }
    float chips_end = line_up_chips(ui, best, h);
    float up = chips_out_of_the_way(ui, chips_end - gap);
    float below = layout_row(ui, chips_end);
    bool row = row_shown(ui);
    float hw = ui->canvas.w - 2 * margin, hh = 2.2f * ui->text_px;
    if (hw > (float)mm(ui, 220)) hw = (float)mm(ui, 220);
    // A canvas too small for the hint under the parts row (a phone held
    // upright) shows none: the chips and the row say enough.
    if (below + hh > ui->canvas.y + ui->canvas.h && row) hh = 0;
    // Chips at the bottom: the hint above them.
    if (up > 0) below = ui->canvas.y + margin + up - gap - hh;
    ui->hint_box = (sp_kiosk_rect){ui->canvas.x + 0.5f * (ui->canvas.w - hw), below, hw, hh};
    if (row) keep_stroke_in_sight(ui, chips_end, below + hh, margin, gap);
}

static bool inside(const sp_kiosk_rect* r, float x, float y)
{
    return x >= r->x && x < r->x + r->w && y >= r->y && y < r->y + r->h;
}

// The save banner: the code big, what it is for under it, centred at the
// canvas's bottom. Its width follows the text (DejaVu Sans averages ~0.6 of
// the text height a character); the renderer shrinks text that would not fit.
static void layout_banner(sp_kiosk_ui* ui)
{
    float big = 0.75f * ui->big_text_px, small = ui->text_px;
    float w = fmaxf(0.6f * big * (float)strlen(ui->banner[0]), 0.6f * small * (float)strlen(ui->banner[1])) + 2.0f * big;
    w = fminf(w, 0.92f * ui->canvas.w);
    float h = 1.7f * big + 1.6f * small + 0.4f * big;
    ui->banner_box =
        (sp_kiosk_rect){ui->canvas.x + 0.5f * (ui->canvas.w - w), ui->canvas.y + ui->canvas.h - h - (float)mm(ui, 3.0), w, h};
}

// The toolbar: below the canvas in rows or beside it in columns, whichever
// leaves the canvas larger, for buttons bh tall (and bw_side wide beside it).
typedef struct toolbar {
    bool bottom;
    int k, rows;   // below: buttons a row, rows
    int kc, cols;  // beside: buttons a column, columns
    double bw, bh; // a button's size
    double strip;  // the strip's height (below) or width (beside)
    double canvas_area;
} toolbar;

static toolbar plan_toolbar(const sp_kiosk_ui* ui, double bw_side, double bh)
{
    const double W = ui->width, H = ui->height, min = mm(ui, ui->desc.min_target_mm);
    const double bw_pref = mm(ui, ui->desc.button_mm) * 1.4; // room for an icon over a short word
    const double gap = mm(ui, 3.0), margin = mm(ui, 3.0);
    const int n = SP_KT_SAVE - SP_KT_UNDO + 1;
    toolbar a = {.bh = bh}, b = {.bh = bh, .bw = bw_side};
    // Below: as many buttons a row as fit at their minimum width.
    a.k = (int)floor((W - 2 * margin + gap) / (min + gap));
    a.k = a.k < 1 ? 1 : a.k > n ? n : a.k;
    a.rows = (n + a.k - 1) / a.k;
    a.bw = fmin(bw_pref * 1.15, fmax(min, (W - 2 * margin - (a.k - 1) * gap) / a.k));
    a.strip = a.rows * bh + (a.rows - 1) * gap + 2 * margin;
    a.canvas_area = W * fmax(0.0, H - a.strip);
    a.bottom = true;
    // Beside: as many buttons a column as fit.
    b.kc = (int)floor((H - 2 * margin + gap) / (bh + gap));
    b.kc = b.kc < 1 ? 1 : b.kc > n ? n : b.kc;
    b.cols = (n + b.kc - 1) / b.kc;
    b.strip = b.cols * bw_side + (b.cols - 1) * gap + 2 * margin;
    b.canvas_area = H * fmax(0.0, W - b.strip);
    return a.canvas_area >= b.canvas_area ? a : b;
}

static void place_toolbar(sp_kiosk_ui* ui, const toolbar* tb)
{
    const double W = ui->width, H = ui->height, gap = mm(ui, 3.0), margin = mm(ui, 3.0);
    const int n = SP_KT_SAVE - SP_KT_UNDO + 1;
    for (int i = 0; i < n; ++i) {
        sp_kiosk_rect* r = &ui->target[SP_KT_UNDO + i];
        if (tb->bottom) {
            int row = i / tb->k, col = i % tb->k;
            int in_row = row == tb->rows - 1 ? n - row * tb->k : tb->k;
            double row_w = in_row * tb->bw + (in_row - 1) * gap;
            double x0 = 0.5 * (W - row_w);
            if (x0 < margin && W >= row_w + 2 * margin) x0 = margin;
            if (x0 < 0) x0 = 0;
            double y0 = H - tb->strip + margin + row * (tb->bh + gap);
            *r = (sp_kiosk_rect){(float)(x0 + col * (tb->bw + gap)), (float)y0, (float)tb->bw, (float)tb->bh};
        } else {
            int col = i / tb->kc, row = i % tb->kc;
            int in_col = col == tb->cols - 1 ? n - col * tb->kc : tb->kc;
            double col_h = in_col * tb->bh + (in_col - 1) * gap;
            double y0 = 0.5 * (H - col_h);
            if (y0 < 0) y0 = 0;
            double x0 = W - tb->strip + margin + col * (tb->bw + gap);
            *r = (sp_kiosk_rect){(float)x0, (float)(y0 + row * (tb->bh + gap)), (float)tb->bw, (float)tb->bh};
        }
    }
    if (tb->bottom)
        ui->canvas = (sp_kiosk_rect){0, 0, (float)W, (float)fmax(0.0, H - tb->strip)};
    else
        ui->canvas = (sp_kiosk_rect){0, 0, (float)fmax(0.0, W - tb->strip), (float)H};
}

void sp_kiosk_ui_resize(sp_kiosk_ui* ui, int width, int height, double px_per_mm)
{
    if (width < 1) width = 1;
    if (height < 1) height = 1;
    if (!(px_per_mm > 0) || !isfinite(px_per_mm)) px_per_mm = 96.0 / 25.4;
    ui->width = width, ui->height = height, ui->px_per_mm = px_per_mm;
    ui->text_px = (float)fmax(10.0, mm(ui, 6.0));
    ui->big_text_px = (float)fmax(16.0, mm(ui, 13.0));
    ui->line_px = (float)fmax(3.0, mm(ui, 1.8));
    const double min = mm(ui, ui->desc.min_target_mm), bh = mm(ui, ui->desc.button_mm);
    toolbar tb = plan_toolbar(ui, bh * 1.4, bh);
    // Buttons of the preferred size that leave the canvas under half the
    // window shrink to the smallest target, below or beside: on a phone held
    // sideways two rows of them left a canvas 17 mm tall (an outside review).
    if (tb.canvas_area < 0.5 * (double)width * height) {
        toolbar small = plan_toolbar(ui, min, min);
        if (small.canvas_area > tb.canvas_area) tb = small;
    }
    place_toolbar(ui, &tb);
    layout_chips(ui);
    layout_banner(ui);
}

// ------------------------------------------------------------------ queries

static bool visible(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    if (t <= SP_KT_NONE || t >= SP_KT_COUNT || ui->target[t].w <= 0) return false;
    if (ui->mode == SP_KM_ATTRACT) return false;
    if (t >= SP_KT_PART1) return ui->mode == SP_KM_DRAW && row_shown(ui) && (int)t - SP_KT_PART1 < ui->row_fit;
    if (t == SP_KT_CHIP_MORE) return ui->mode == SP_KM_DRAW && ui->part_count > 0 && more_shown(ui);
    if (t >= SP_KT_CHIP_LABEL)
        return ui->mode == SP_KM_DRAW && (ui->part_count > 0 || ui->chips_offer) && ui->chip[t - SP_KT_CHIP_LABEL][0] &&
               !guess_hidden(ui, t);
    return true;
}

bool sp_kiosk_ui_target_visible(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    return visible(ui, t);
}

bool sp_kiosk_ui_target_enabled(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    if (!visible(ui, t)) return false;
    switch (t) {
    case SP_KT_TURN:
        return ui->part_count > 0 || ui->mode == SP_KM_TURN;
    case SP_KT_CHIP_GUESS1:
    case SP_KT_CHIP_GUESS2:
    case SP_KT_CHIP_GUESS3:
    case SP_KT_CHIP_MORE:
        return ui->chips_offer || !ui->refit_queued;
    case SP_KT_CHIP_LABEL:
        return true;
    case SP_KT_SAVE:
        return ui->part_count > 0 && !ui->save_queued;
    case SP_KT_UNDO: // also takes back a refused stroke that is still offered
        return ui->part_count > 0 || offering(ui);
    default:
        if (t >= SP_KT_PART1) return offering(ui) || !ui->refit_queued;
        return ui->part_count > 0;
    }
}

// Whether (x, y) is in a visible target's touch area: it reaches half the
// 3 mm gap beyond the drawn rectangle, so a finger that lands on the rim
// still counts and neighbours never overlap.
static bool hits(const sp_kiosk_ui* ui, int t, float x, float y)
{
    float slop = (float)mm(ui, 1.4);
    const sp_kiosk_rect* r = &ui->target[t];
    return visible(ui, (sp_kiosk_target)t) && x >= r->x - slop && x < r->x + r->w + slop && y >= r->y - slop &&
           y < r->y + r->h + slop;
}

sp_kiosk_target sp_kiosk_ui_hit(const sp_kiosk_ui* ui, float x, float y)
{
    if (!isfinite(x) || !isfinite(y)) return SP_KT_NONE;
    // The toolbar's buttons first: a chip that reached one took its taps (an
    // outside review: on a small phone a tap on Undo opened the parts row).
    for (int t = SP_KT_UNDO; t <= SP_KT_SAVE; ++t)
        if (hits(ui, t, x, y)) return (sp_kiosk_target)t;
    for (int t = SP_KT_COUNT - 1; t > SP_KT_SAVE; --t)
        if (hits(ui, t, x, y)) return (sp_kiosk_target)t;
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

bool sp_kiosk_ui_offering(const sp_kiosk_ui* ui)
{
    return offering(ui);
}

bool sp_kiosk_ui_target_current(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    return t >= SP_KT_PART1 && t <= SP_KT_PART_LAST && (int)t - SP_KT_PART1 < ui->row_count && row_for_part(ui) &&
           !strcmp(ui->row[t - SP_KT_PART1], ui->chip[0]);
}

const char* sp_kiosk_ui_target_category(const sp_kiosk_ui* ui, sp_kiosk_target t)
{
    if (t >= SP_KT_CHIP_LABEL && t <= SP_KT_CHIP_GUESS3) return ui->chip[t - SP_KT_CHIP_LABEL];
    if (t >= SP_KT_PART1 && t <= SP_KT_PART_LAST && (int)t - SP_KT_PART1 < ui->row_count) return ui->row[t - SP_KT_PART1];
    return "";
}

const char* sp_kiosk_ui_target_text(const sp_kiosk_ui* ui, sp_kiosk_target t, char* out, size_t cap)
{
    if (t == SP_KT_CHIP_MORE) {
        snprintf(out, cap, "%s", sp_kiosk_text(SP_KTEXT_MORE));
        return out;
    }
    char name[SP_KIOSK_NAME_MAX];
    sp_kiosk_part_name(sp_kiosk_ui_target_category(ui, t), name, sizeof name);
    bool guess = t >= SP_KT_CHIP_GUESS1 && t <= SP_KT_CHIP_GUESS3 && name[0];
    snprintf(out, cap, guess ? "%s?" : "%s", name);
    return out;
}

const char* sp_kiosk_ui_message(const sp_kiosk_ui* ui)
{
    if (sp_kiosk_ui_hint_visible(ui)) return ui->hint;
    // An empty canvas always says what to do: at the start, after Start over, after the last Undo.
    bool idle_canvas = ui->mode == SP_KM_DRAW && ui->part_count == 0 && ui->capture != SP_KCAP_STROKE && ui->pending_count == 0 &&
                       !ui->fit_in_flight && !offering(ui) && !sp_kiosk_ui_flashing(ui);
    return idle_canvas ? sp_kiosk_text(SP_KTEXT_PROMPT) : NULL;
}

bool sp_kiosk_ui_banner_visible(const sp_kiosk_ui* ui)
{
    // Only while the code names the dragon on screen: a changed dragon is
    // not the one saved under it.
    return ui->code[0] && ui->now < ui->banner_until && ui->revision == ui->saved_revision;
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
    ui->hint_of_offer = ui->hint_of_row = false;
}

// Copies a category into a fixed label (GCC cannot tell that the two, both
// often inside *ui, never overlap, so no snprintf).
static void copy_label(char dst[SP_KIOSK_LABEL_MAX], const char* src)
{
    size_t n = src ? strnlen(src, SP_KIOSK_LABEL_MAX - 1) : 0;
    memmove(dst, src ? src : "", n);
    dst[n] = 0;
}

// The chips: a label and guesses, or (label NULL) none. A guess equal to the
// label or to an earlier guess is dropped (it would re-fit to the same
// thing); the rest close up.
static void set_chip_list(sp_kiosk_ui* ui, const char* label, const char* const* guesses, int n, bool offer)
{
    char tmp[4][SP_KIOSK_LABEL_MAX]; // the inputs may point into ui->chip (refresh after undo)
    memset(tmp, 0, sizeof tmp);
    copy_label(tmp[0], label);
    int k = 1;
    for (int i = 0; i < n && k < 4 && (label || offer); ++i) {
        if (!guesses[i] || !guesses[i][0]) continue;
        bool dup = false;
        for (int j = 0; j < k; ++j)
            dup = dup || !strncmp(guesses[i], tmp[j], SP_KIOSK_LABEL_MAX - 1);
        if (!dup) copy_label(tmp[k++], guesses[i]);
    }
    memcpy(ui->chip, tmp, sizeof tmp);
    ui->chips_offer = offer;
    ui->row_open = false; // new chips: the row opens again only when asked
    layout_chips(ui);
}

static void set_chips(sp_kiosk_ui* ui, const char* label, const char* g1, const char* g2)
{
    set_chip_list(ui, label, (const char* const[2]){g1, g2}, label ? 2 : 0, false);
}

// The refused stroke is no longer offered: it fades out (fade) or goes at
// once, and its chips and the parts row go with it.
static void end_offer(sp_kiosk_ui* ui, bool fade)
{
    if (!offering(ui)) return;
    if (fade) {
        line_copy(&ui->fade_stroke, &ui->held_stroke);
        ui->fade_until = ui->now + ui->desc.fade_ms;
    }
    ui->held_stroke.count = 0;
    ui->held_until = -1;
    ui->held_kept = false;
    if (ui->hint_of_offer) ui->hint_until = -1;
    if (ui->chips_offer)
        set_chips(ui, NULL, NULL, NULL);
    else
        layout_chips(ui); // the parts row goes
}

static void clear_overlays(sp_kiosk_ui* ui)
{
    end_offer(ui, false);
    ui->flash_until = ui->fade_until = -1;
    ui->flash_stroke.count = ui->flash_outline.count = ui->fade_stroke.count = 0;
    ui->flash_break_count = 0;
}

// Queues a FIT job for a stroke (copied into the pending ring); NULL when the job queue is full.
static sp_kiosk_job* queue_fit(sp_kiosk_ui* ui, const sp_kiosk_line* stroke)
{
    if (ui->pending_count == SP_KIOSK_PENDING_MAX) drop_oldest_fit(ui);
    sp_kiosk_job* j = push_job(ui, SP_KJOB_FIT);
    if (!j) {
        ++ui->dropped_strokes;
        return NULL;
    }
    int slot = (ui->pending_head + ui->pending_count++) % SP_KIOSK_PENDING_MAX;
    line_copy(&ui->pending[slot], stroke);
    ui->banner_until = -1; // drawing on: the banner would cover the stroke's chips and row
    j->replace = ui->redraw_armed;
    ui->redraw_armed = ui->redraw_for_offer = false;
    return j;
}

// A chip or the parts row chose what the held stroke is: fit it as that.
static void take_offer(sp_kiosk_ui* ui, const char* category)
{
    if (!offering(ui) || !category[0]) return;
    sp_kiosk_job* j = queue_fit(ui, &ui->held_stroke);
    if (!j) return;
    copy_label(j->category, category);
    j->replace_detail = ui->held_kept;
    ++ui->chosen;
    end_offer(ui, false);
}

// The stroke just queued (j) is the one a next stroke may continue.
static void remember_last(sp_kiosk_ui* ui, const sp_kiosk_job* j)
{
    line_copy(&ui->last_stroke, &ui->stroke);
    ui->last_up = ui->now;
    ui->last_replace = j->replace;
    ui->last_outcome = SP_KLAST_PENDING;
}

// Whether a stroke begun now at (x, y) continues the last stroke: soon
// after its pen-up, where the finger would have got to: near its end, or
// farther ahead along its last direction by its speed at the end.
static bool continues_last(const sp_kiosk_ui* ui, float x, float y)
{
    const sp_kiosk_line* l = &ui->last_stroke;
    double gap = ui->now - ui->last_up;
    if (ui->last_outcome == SP_KLAST_NONE || ui->last_outcome == SP_KLAST_INFLIGHT || l->count < 2 || !(ui->desc.join_ms > 0) ||
        !(gap >= 0 && gap <= ui->desc.join_ms))
        return false;
    int e = l->count - 1, b = e - 1;
    while (b > 0 && l->t[e] - l->t[b - 1] <= 50) // its last 50 ms
        --b;
    float ex = l->xy[2 * e], ey = l->xy[2 * e + 1];
    double d = hypot(x - ex, y - ey), near = mm(ui, ui->desc.join_mm);
    if (d <= near) return true;
    double vx = ex - l->xy[2 * b], vy = ey - l->xy[2 * b + 1], len = hypot(vx, vy), dt = l->t[e] - l->t[b];
    if (!(len > 0) || !(dt > 0)) return false;
    // A finger moves at most about half a metre a second.
    double speed = fmin(len / dt, mm(ui, 0.5));
    bool ahead = ((x - ex) * vx + (y - ey) * vy) / len >= cos(M_PI / 4) * d;
    return ahead && d <= near + speed * gap;
}

// The stroke just finished (ui->stroke, the last one's points first)
// continues the last stroke: the two are fitted as one. False when the
// last stroke's job is being run (its answer is not in yet): then it is a
// stroke of its own.
static bool continue_last(sp_kiosk_ui* ui)
{
    const sp_kiosk_line* s = &ui->stroke;
    switch (ui->last_outcome) {
    case SP_KLAST_PENDING: { // its job has not run: it fits the whole line instead
        int slot = (ui->pending_head + ui->pending_count - 1) % SP_KIOSK_PENDING_MAX;
        line_copy(&ui->pending[slot], s);
        line_copy(&ui->last_stroke, s);
        ui->last_up = ui->now;
        ++ui->joined, ++ui->merged;
        return true;
    }
    case SP_KLAST_PART:
    case SP_KLAST_DETAIL:
    case SP_KLAST_REFUSED: {
        // What the first piece made goes; a part a Redraw made is replaced
        // again (the part it replaced is gone).
        bool redrawn = ui->last_outcome == SP_KLAST_PART && ui->last_replace;
        bool undo = !redrawn && ui->last_outcome != SP_KLAST_REFUSED;
        end_offer(ui, false); // a refused first piece is part of the line drawn now
        ui->fade_until = -1, ui->fade_stroke.count = 0;
        set_chips(ui, NULL, NULL, NULL);
        sp_kiosk_job* j = queue_fit(ui, s);
        ui->last_outcome = SP_KLAST_NONE;
        if (!j) return true;
        j->replace = j->replace || redrawn;
        j->undo_first = undo;
        remember_last(ui, j);
        ++ui->joined;
        return true;
    }
    default:
        return false;
    }
}

// The diagonal of the box of a line's points from index `from` on (0 for none).
static double line_diag(const sp_kiosk_line* l, int from)
{
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = from; i < l->count; ++i)
        for (int c = 0; c < 2; ++c)
            lo[c] = fminf(lo[c], l->xy[2 * i + c]), hi[c] = fmaxf(hi[c], l->xy[2 * i + c]);
    return l->count > from ? hypot(hi[0] - lo[0], hi[1] - lo[1]) : 0;
}

// A stroke that closes the last one, an open line drawn just before: its
// two ends meet that line's two ends (within the join distance), so the
// two are one outline drawn in two strokes (a child's body drawn as two
// arcs from the same side: the first became a sliver of a body and the
// second was refused, an outside review). *reversed: it runs from the last
// line's start to its end. Parts drawn at a body touch it, not both ends of
// the stroke drawn before them.
#define SP_KIOSK_CLOSE_MS 3000.0
static bool closes_last(const sp_kiosk_ui* ui, const sp_kiosk_line* s, bool* reversed)
{
    const sp_kiosk_line* l = &ui->last_stroke;
    bool after =
        ui->last_outcome == SP_KLAST_PENDING || ui->last_outcome == SP_KLAST_PART || ui->last_outcome == SP_KLAST_REFUSED;
    if (!after || l->count < 2 || s->count < 2 || !(ui->desc.join_ms > 0) || !(ui->now - ui->last_up <= SP_KIOSK_CLOSE_MS))
        return false;
    double diag = line_diag(l, 0);
    const float *l0 = l->xy, *l1 = l->xy + 2 * (l->count - 1), *s0 = s->xy, *s1 = s->xy + 2 * (s->count - 1);
#define SP_GAP(a, b) hypot((a)[0] - (b)[0], (a)[1] - (b)[1])
    double near = mm(ui, ui->desc.join_mm);
    bool open = SP_GAP(l0, l1) > fmax(0.2 * diag, 2 * near); // not a loop already
    bool on = SP_GAP(s0, l1) <= near && SP_GAP(s1, l0) <= near, back = SP_GAP(s0, l0) <= near && SP_GAP(s1, l1) <= near;
#undef SP_GAP
    *reversed = back && !on;
    if (!open || !(on || back)) return false;
    // Not the same line drawn again over it (a refused leg redrawn): its
    // middle lies away from the last line, across the shape they close.
    const float* mid = s->xy + 2 * (s->count / 2);
    double apart = INFINITY;
    for (int i = 0; i < l->count; ++i)
        apart = fmin(apart, hypot(mid[0] - l->xy[2 * i], mid[1] - l->xy[2 * i + 1]));
    return apart > fmax(2 * near, 0.1 * diag);
}

// ui->stroke (the piece just drawn) becomes the last line and then it, run
// on from the last line's end (reversed when it was drawn from its start),
// thinned evenly to SP_KIOSK_STROKE_MAX points; the times keep the order
// they were drawn in.
static bool join_closing(sp_kiosk_ui* ui, bool reversed)
{
    sp_kiosk_line* s = &ui->stroke;
    const sp_kiosk_line* l = &ui->last_stroke;
    int n = l->count + s->count, step = (n + SP_KIOSK_STROKE_MAX - 1) / SP_KIOSK_STROKE_MAX;
    float* xy = malloc(sizeof(float) * 2 * (size_t)n);
    double* t = malloc(sizeof(double) * (size_t)n);
    if (!xy || !t) { // no room: the piece stays a stroke of its own
        free(xy), free(t);
        return false;
    }
    for (int i = 0; i < n; ++i) {
        bool first = i < l->count;
        int k = first ? i : reversed ? n - 1 - i : i - l->count;
        const sp_kiosk_line* from = first ? l : s;
        xy[2 * i] = from->xy[2 * k], xy[2 * i + 1] = from->xy[2 * k + 1];
        t[i] = first ? l->t[i] : s->t[i - l->count];
    }
    s->count = 0;
    for (int i = 0; i < n; i += step, ++s->count) {
        int k = i + step >= n ? n - 1 : i; // the end kept
        s->xy[2 * s->count] = xy[2 * k], s->xy[2 * s->count + 1] = xy[2 * k + 1], s->t[s->count] = t[k];
    }
    free(xy), free(t);
    return true;
}

static void finish_stroke(sp_kiosk_ui* ui)
{
    ui->redraw_spent = false;
    sp_kiosk_line* s = &ui->stroke;
    bool cont = ui->continuing;
    ui->continuing = false;
    // A continuation's own piece decides whether it was a tap.
    int from = cont ? ui->continued_from : 0;
    double diag = line_diag(s, from);
    if (s->count - from < 2 || diag < mm(ui, ui->desc.tap_mm)) {
        s->count = 0;
        if (cont) return; // a finger bouncing off the glass at the end: the last stroke stands
        ++ui->taps;
        ui->last_outcome = SP_KLAST_NONE;
        // A touch that only stopped the countdown needs no lesson in drawing,
        // nor the second tap of a double tap on a chip or button that moved
        // from under the finger ("Other?" as the row opens).
        // Nor a tap on the save banner, which only shows the code.
        if (!ui->woke && !ui->down_on_banner && ui->now - ui->target_at >= SP_KIOSK_REPEAT_MIN_MS)
            set_hint(ui, sp_kiosk_text(SP_KTEXT_TAP));
        return;
    }
    ++ui->strokes_finished;
    bool reversed = false;
    if (!cont && closes_last(ui, s, &reversed) && join_closing(ui, reversed)) {
        cont = true;
        ++ui->closed;
    }
    if (cont && continue_last(ui)) {
        s->count = 0;
        return;
    }
    // This is the last stroke now: chips and offers of earlier ones go.
    end_offer(ui, true);
    set_chips(ui, NULL, NULL, NULL);
    sp_kiosk_job* j = queue_fit(ui, s);
    if (j)
        remember_last(ui, j);
    else
        ui->last_outcome = SP_KLAST_NONE;
    s->count = 0;
}

// ------------------------------------------------------------------ events

// What a new dragon starts from (Start over, the idle timeout): nothing on
// the canvas but the first-draw prompt, the animation stopped at its start,
// the drawing view.
static void fresh_canvas(sp_kiosk_ui* ui)
{
    ui->last_outcome = SP_KLAST_NONE;
    clear_overlays(ui);
    set_chips(ui, NULL, NULL, NULL);
    ui->hint[0] = 0;
    ui->hint_until = -1;
    ui->code[0] = 0;
    ui->banner_until = ui->clear_armed_until = -1;
    ui->redraw_armed = false;
    ui->playing = ui->desc.start_playing;
    ui->anim_ms = 0;
    ui->yaw = ui->pitch = 0;
}

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
    fresh_canvas(ui);
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
    if (offering(ui) && t >= ui->held_until) {
        // A Redraw whose stroke was refused and left unanswered lapses with
        // it: the button went on glowing after the hint had gone, and a
        // visitor's next, unrelated part replaced the last one.
        end_offer(ui, true);
        if (ui->redraw_for_offer) ui->redraw_armed = ui->redraw_for_offer = false;
    }
    if (ui->mode != SP_KM_ATTRACT && ui->desc.idle_ms > 0 && t - ui->last_input >= ui->desc.idle_ms) reset_to_attract(ui);
}

static void add_point(sp_kiosk_ui* ui, float x, float y, bool last)
{
    sp_kiosk_line* s = &ui->stroke;
    // Strokes that leave the canvas stay on its edge: a part fitted to ink
    // over the toolbar (or off the window) would sit hidden under it.
    const sp_kiosk_rect* c = &ui->canvas;
    x = fminf(fmaxf(x, c->x), fmaxf(c->x, c->x + c->w - 1.0f));
    y = fminf(fmaxf(y, c->y), fmaxf(c->y, c->y + c->h - 1.0f));
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
        ui->continued_from = (ui->continued_from + 1) / 2;
        ui->stroke_spacing *= 2.0;
    }
    s->xy[2 * s->count] = x, s->xy[2 * s->count + 1] = y;
    s->t[s->count] = ui->now;
    ++s->count;
}

// The row opened for the last part closes, and its hint with it.
static void close_row(sp_kiosk_ui* ui)
{
    ui->row_open = false;
    if (ui->hint_of_row) ui->hint_until = -1;
    layout_chips(ui);
}

// A guess chip or the row chose another part for the last one: re-fit it as that.
static void refit_last(sp_kiosk_ui* ui, const char* category)
{
    sp_kiosk_job* j = push_job(ui, SP_KJOB_REFIT);
    if (j) {
        copy_label(j->category, category);
        ui->refit_queued = true;
    }
}

static void activate(sp_kiosk_ui* ui, sp_kiosk_target t)
{
    ++ui->activations[t];
    ui->target_at = ui->now;
    bool after_refusal = ui->last_outcome == SP_KLAST_REFUSED;
    if (t != SP_KT_REDRAW) ui->redraw_spent = false;
    ui->last_outcome = SP_KLAST_NONE; // a button between two strokes: the next one is a stroke of its own
    if (!sp_kiosk_ui_target_enabled(ui, t)) {
        if (ui->part_count == 0 && t < SP_KT_CHIP_LABEL) set_hint(ui, sp_kiosk_text(SP_KTEXT_NEED_PART));
        return;
    }
    if (t >= SP_KT_PART1) {
        if (offering(ui)) {
            take_offer(ui, ui->row[t - SP_KT_PART1]);
            return;
        }
        if (!sp_kiosk_ui_target_current(ui, t)) { // the same part again: nothing to do
            refit_last(ui, ui->row[t - SP_KT_PART1]);
            ++ui->others_chosen;
        }
        close_row(ui);
        return;
    }
    switch (t) {
    case SP_KT_UNDO:
        if (ui->now - ui->undo_at < SP_KIOSK_REPEAT_MIN_MS) break;
        ui->undo_at = ui->now;
        // The refused stroke was the last thing drawn: it is what goes (kept as ink, the dragon gives it back too).
        if (offering(ui) && !ui->held_kept) {
            end_offer(ui, false);
        } else if (push_job(ui, SP_KJOB_UNDO)) {
            clear_overlays(ui);
            if (ui->redraw_armed && !strcmp(ui->hint, sp_kiosk_text(SP_KTEXT_REDRAW))) ui->hint_until = -1; // no longer true
            ui->redraw_armed = false;
        }
        break;
    case SP_KT_REDRAW:
        // Tapped in the turn view it means "draw it again": back to drawing,
        // armed (it stayed armed unseen, and the next part replaced the last).
        if (ui->mode == SP_KM_TURN) {
            ui->mode = SP_KM_DRAW;
            ui->mode_since = ui->now;
            ui->redraw_armed = false;
        } else if (offering(ui) || after_refusal || ui->redraw_spent) {
            // The refused stroke (on screen, or just faded: "A bit bigger
            // please!") is the last thing drawn, and what a child means to
            // draw again: it goes, as with Undo, and the next stroke is a new
            // part, or still the replacement a Redraw before it was for; so
            // do more taps until a stroke is drawn (an outside review: armed
            // to replace the last part, the leg drawn again took the place of
            // the front legs drawn right; a second tap did the same).
            bool for_part = ui->redraw_for_offer;
            if (offering(ui) && !ui->held_kept)
                end_offer(ui, false);
            else if (offering(ui) && push_job(ui, SP_KJOB_UNDO))
                clear_overlays(ui);
            ui->redraw_spent = !for_part;
            ui->redraw_armed = ui->redraw_for_offer = for_part;
            set_hint(ui, sp_kiosk_text(for_part ? SP_KTEXT_REDRAW : SP_KTEXT_DRAW_AGAIN));
            break;
        }
        ui->redraw_armed = !ui->redraw_armed;
        ui->redraw_for_offer = false; // the visitor's own Redraw: it waits for them
        if (ui->redraw_armed)
            set_hint(ui, sp_kiosk_text(SP_KTEXT_REDRAW));
        else
            ui->hint_until = -1;
        break;
    case SP_KT_START_OVER:
        if (sp_kiosk_ui_clear_armed(ui) && ui->now - ui->clear_armed_at < SP_KIOSK_CONFIRM_MIN_MS) {
            ui->clear_armed_at = ui->now; // the same touch again, a bounce: the question stands, the wait starts over
            break;
        } else if (sp_kiosk_ui_clear_armed(ui)) {
            if (push_job(ui, SP_KJOB_CLEAR)) {
                fresh_canvas(ui);
                ui->mode = SP_KM_DRAW;
            }
        } else {
            ui->clear_armed_until = ui->now + ui->desc.confirm_ms;
            ui->clear_armed_at = ui->now;
            set_hint(ui, sp_kiosk_text(SP_KTEXT_CONFIRM_CLEAR));
        }
        break;
    case SP_KT_PLAY:
        ui->playing = !ui->playing;
        break;
    case SP_KT_TURN:
        ui->mode = ui->mode == SP_KM_TURN ? SP_KM_DRAW : SP_KM_TURN;
        ui->mode_since = ui->now;
        end_offer(ui, false);            // its chips only show in the drawing view
        if (ui->row_open) close_row(ui); // and so does the row opened for the last part
        ui->redraw_armed = ui->redraw_for_offer = false; // a Redraw waits for a stroke in this view only
        if (ui->mode == SP_KM_TURN)
            set_hint(ui, sp_kiosk_text(SP_KTEXT_TURN));
        else
            ui->hint_until = -1;
        break;
    case SP_KT_SAVE:
        // Saving says "this is my dragon": a refused stroke still offered
        // is not on it, and the banner takes the canvas's bottom, where the
        // parts row may be (its hidden tiles took a child's tap on the banner).
        end_offer(ui, true);
        if (ui->row_open) close_row(ui);
        if (ui->code[0] && ui->saved_revision == ui->revision) {
            ui->banner_until = ui->now + ui->desc.banner_ms; // same dragon: same code, no new files
        } else if (push_job(ui, SP_KJOB_SAVE)) {
            ui->save_queued = true;
            set_hint(ui, sp_kiosk_text(SP_KTEXT_SAVING));
        }
        break;
    case SP_KT_CHIP_LABEL:
        set_hint(ui, sp_kiosk_text(SP_KTEXT_LABEL));
        break;
    case SP_KT_CHIP_GUESS1:
    case SP_KT_CHIP_GUESS2:
    case SP_KT_CHIP_GUESS3: {
        const char* c = ui->chip[t - SP_KT_CHIP_LABEL];
        if (ui->chips_offer) {
            take_offer(ui, c);
            break;
        }
        refit_last(ui, c);
        break;
    }
    case SP_KT_CHIP_MORE:
        if (ui->row_open) {
            close_row(ui);
        } else {
            ui->row_open = true;
            ui->banner_until = -1; // the row goes where the banner is
            ++ui->others;
            layout_chips(ui);
            set_hint(ui, sp_kiosk_text(SP_KTEXT_PICK_PART));
            ui->hint_of_row = true;
        }
        break;
    default:
        break;
    }
}

// A press on a chip or tile (drawn over the canvas) whose path, with (x, y),
// reaches the canvas's tap size ("strokes under 4 mm are taps") is a line
// begun there, even if it never leaves the chip: on a phone a whole head
// fits inside one, and was taken as a tap that re-fitted the last part (an
// outside review).
static bool press_drew(sp_kiosk_ui* ui, float x, float y)
{
    if (ui->mode != SP_KM_DRAW || ui->pressed < SP_KT_CHIP_LABEL || !inside(&ui->canvas, ui->down_x, ui->down_y)) return false;
    float* b = ui->press_box;
    b[0] = fminf(b[0], x), b[1] = fminf(b[1], y), b[2] = fmaxf(b[2], x), b[3] = fmaxf(b[3], y);
    return hypot(b[2] - b[0], b[3] - b[1]) >= mm(ui, ui->desc.tap_mm);
}

// A line begun on a chip or tile that ends on it less than twice the tap
// size across is a tap on it: a child's tap slides and rolls 4-5 mm, and
// taken as a line it lost the refused drawing the chip was to fix (a second
// review); a part drawn inside a phone's chip is 10 mm or more.
static bool stroke_was_tap(const sp_kiosk_ui* ui, float x, float y)
{
    return ui->stroke_target != SP_KT_NONE && !ui->continuing && line_diag(&ui->stroke, 0) < 2 * mm(ui, ui->desc.tap_mm) &&
           sp_kiosk_ui_hit(ui, x, y) == ui->stroke_target;
}

static void start_stroke(sp_kiosk_ui* ui, float x, float y, double t);

static void end_capture(sp_kiosk_ui* ui, float x, float y, bool up)
{
    switch (ui->capture) {
    case SP_KCAP_STROKE:
        if (up && stroke_was_tap(ui, x, y)) {
            ui->stroke.count = 0;
            activate(ui, ui->stroke_target);
            break;
        }
        if (up) add_point(ui, x, y, true);
        finish_stroke(ui);
        break;
    case SP_KCAP_TARGET:
        if (up && press_drew(ui, x, y) && hypot(x - ui->down_x, y - ui->down_y) >= 2 * mm(ui, ui->desc.tap_mm)) {
            // A line drawn with no move between touch and lift.
            start_stroke(ui, ui->down_x, ui->down_y, ui->down_t);
            add_point(ui, x, y, true);
            finish_stroke(ui);
        } else if (up && ui->pressed != SP_KT_NONE && sp_kiosk_ui_hit(ui, x, y) == ui->pressed) {
            activate(ui, ui->pressed);
        }
        break;
    case SP_KCAP_ORBIT:
        // A child who tries to draw while turning only spins the dragon: each
        // turn says again how to get back to drawing.
        if (up && ui->mode == SP_KM_TURN) set_hint(ui, sp_kiosk_text(SP_KTEXT_TURN));
        break;
    default:
        break;
    }
    ui->capture = SP_KCAP_NONE;
    ui->pressed = SP_KT_NONE;
}

// A stroke begins at (x, y), touched at time t.
static void start_stroke(sp_kiosk_ui* ui, float x, float y, double t)
{
    // A new stroke ends the flash at once: the visitor is already drawing on.
    if (sp_kiosk_ui_flashing(ui)) ui->flash_until = ui->now;
    ui->capture = SP_KCAP_STROKE;
    ui->pressed = SP_KT_NONE;
    ui->stroke_target = SP_KT_NONE;
    ui->stroke.count = 0;
    ui->stroke_spacing = fmax(0.5, mm(ui, 0.3));
    // Drawn on from where the last stroke ended: one line, shown as one while it is drawn.
    ui->continuing = continues_last(ui, x, y);
    ui->continued_from = 0;
    if (ui->continuing) {
        line_copy(&ui->stroke, &ui->last_stroke);
        ui->continued_from = ui->stroke.count;
    }
    int before = ui->stroke.count;
    add_point(ui, x, y, false);
    if (ui->stroke.count > before) ui->stroke.t[ui->stroke.count - 1] = t;
}

static void on_down(sp_kiosk_ui* ui, float x, float y)
{
    if (ui->capture != SP_KCAP_NONE) end_capture(ui, ui->last_x, ui->last_y, false);
    // A touch during the countdown stops it and does what it does anywhere
    // else: the visitor who was about to draw or tap should not have to do it twice.
    ui->woke = sp_kiosk_ui_countdown_s(ui) > 0;
    ui->last_input = ui->now;
    ui->last_x = x, ui->last_y = y;
    ui->down_x = x, ui->down_y = y, ui->down_t = ui->now;
    ui->press_box[0] = ui->press_box[2] = x, ui->press_box[1] = ui->press_box[3] = y;
    ui->down_on_banner = sp_kiosk_ui_banner_visible(ui) && inside(&ui->banner_box, x, y);
    // The attract screen invites drawing, so a child often starts with a
    // stroke: it leaves the screen and is already the visit's first stroke.
    // A tap only starts (no lesson in drawing); the empty canvas then shows
    // the first-draw prompt (sp_kiosk_ui_message).
    bool starting = ui->mode == SP_KM_ATTRACT;
    if (starting) {
        ui->mode = SP_KM_DRAW;
        ui->mode_since = ui->now;
        ui->woke = true;
    }
    sp_kiosk_target t = sp_kiosk_ui_hit(ui, x, y);
    if (starting && (t != SP_KT_NONE || !inside(&ui->canvas, x, y))) {
        ui->capture = SP_KCAP_SWALLOW; // the toolbar was not on screen to be aimed at
        return;
    }
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
    start_stroke(ui, x, y, ui->now);
}

static void on_move(sp_kiosk_ui* ui, float x, float y)
{
    if (ui->capture == SP_KCAP_NONE) return; // no hover states
    ui->last_input = ui->now;
    switch (ui->capture) {
    case SP_KCAP_STROKE:
        add_point(ui, x, y, false);
        break;
    case SP_KCAP_TARGET:
        // A finger that leaves the chip or tile it touched (drawn over the
        // canvas), or draws past the tap size on it, is drawing a line that
        // happened to start there, as children start lines anywhere: the
        // line is kept from its touch.
        if (press_drew(ui, x, y) || (ui->mode == SP_KM_DRAW && ui->pressed >= SP_KT_CHIP_LABEL &&
                                     inside(&ui->canvas, ui->down_x, ui->down_y) && sp_kiosk_ui_hit(ui, x, y) != ui->pressed)) {
            sp_kiosk_target on = ui->pressed;
            start_stroke(ui, ui->down_x, ui->down_y, ui->down_t);
            ui->stroke_target = on; // a tap yet, if it ends small on it (stroke_was_tap)
            add_point(ui, x, y, false);
        } else if (ui->mode == SP_KM_DRAW && !inside(&ui->canvas, ui->down_x, ui->down_y) && inside(&ui->canvas, x, y) &&
                   sp_kiosk_ui_hit(ui, x, y) == SP_KT_NONE) {
            // One begun on a toolbar button and drawn into the canvas starts
            // where it enters, as from the toolbar's strip: a review's child
            // began a right-facing dragon's line on Undo, and it was lost.
            start_stroke(ui, x, y, ui->now);
        }
        break;
    case SP_KCAP_SWALLOW:
        // Touched beside the canvas (the toolbar's strip, or where its
        // buttons will be on the attract screen): a line drawn from there
        // into the canvas starts where it enters.
        if (ui->mode == SP_KM_DRAW && inside(&ui->canvas, x, y)) start_stroke(ui, x, y, ui->now);
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

sp_kiosk_job_kind sp_kiosk_ui_peek_job(const sp_kiosk_ui* ui)
{
    for (int i = 0; i < ui->job_count; ++i) {
        const sp_kiosk_job* j = &ui->jobs[(ui->job_head + i) % SP_KIOSK_JOBS_MAX];
        if (j->kind != SP_KJOB_NONE) return j->kind;
    }
    return SP_KJOB_NONE;
}

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
            if (ui->last_outcome == SP_KLAST_PENDING && ui->pending_count == 0) ui->last_outcome = SP_KLAST_INFLIGHT;
        }
        if (j->kind == SP_KJOB_FIT || j->kind == SP_KJOB_REFIT) {
            ui->fit_in_flight = true;
            ui->inflight_kind = j->kind;
            ui->inflight_replace = j->replace;
            ui->inflight_undo = j->kind == SP_KJOB_FIT && j->undo_first;
        }
        return true;
    }
    return false;
}

static const char* refusal_text(sp_kiosk_refusal why, bool refit)
{
    switch (why) {
    case SP_KREF_TOO_SMALL:
        return sp_kiosk_text(SP_KTEXT_TOO_SMALL);
    case SP_KREF_TRICKY:
        return sp_kiosk_text(SP_KTEXT_TRICKY);
    case SP_KREF_NOT_READY:
        return sp_kiosk_text(SP_KTEXT_NOT_READY);
    case SP_KREF_FULL:
        return sp_kiosk_text(SP_KTEXT_FULL);
    case SP_KREF_DETAIL:
        return sp_kiosk_text(SP_KTEXT_DETAIL);
    default:
        return sp_kiosk_text(refit ? SP_KTEXT_REFIT_FAILED : SP_KTEXT_UNRECOGNISED_NO_OFFER);
    }
}

// The refused last stroke stays, with its guesses as chips and the parts row.
static void hold(sp_kiosk_ui* ui, const sp_kiosk_fit_result* r)
{
    line_copy(&ui->held_stroke, &ui->job_stroke);
    ui->held_until = ui->now + ui->desc.offer_ms;
    ui->held_kept = r->kept;
    ui->fade_until = -1;
    set_chip_list(ui, NULL, r->offers, 3, true);
    set_hint(ui, sp_kiosk_text(r->refusal == SP_KREF_DETAIL ? SP_KTEXT_DETAIL : SP_KTEXT_UNRECOGNISED));
    ui->hint_until = ui->held_until;
    ui->hint_of_offer = true;
    ++ui->offered;
}

void sp_kiosk_ui_fit_done(sp_kiosk_ui* ui, const sp_kiosk_fit_result* r)
{
    bool refit = ui->inflight_kind == SP_KJOB_REFIT;
    ui->fit_in_flight = false;
    if (!refit && ui->last_outcome == SP_KLAST_INFLIGHT)
        ui->last_outcome = r->ok ? SP_KLAST_PART : r->kept ? SP_KLAST_DETAIL : SP_KLAST_REFUSED;
    if (refit) ui->refit_queued = false;
    // Chips and offers are for the last stroke only: not when one drawn since waits.
    bool last = ui->pending_count == 0;
    if (!r->ok) {
        if (refit) {
            set_hint(ui, refusal_text(r->refusal, true));
            return;
        }
        // Still waiting for the replacement: a chip for this stroke, or the next stroke, replaces.
        // (In the drawing view only: one tapped in the turn view meanwhile is not re-armed unseen.)
        if (ui->inflight_replace && ui->mode == SP_KM_DRAW) ui->redraw_armed = ui->redraw_for_offer = true;
        // The dragon changed all the same: what the stroke's first piece made was
        // taken back, or the stroke stays on it as ink (a save must see either).
        if (ui->inflight_undo || r->kept) {
            ui->part_count = r->part_count;
            ++ui->revision;
        }
        bool any_offer = ui->row_count > 0;
        for (int i = 0; i < 3; ++i)
            any_offer = any_offer || (r->offers[i] && r->offers[i][0]);
        if (last && r->offer && any_offer) {
            hold(ui, r);
            return;
        }
        line_copy(&ui->fade_stroke, &ui->job_stroke);
        ui->fade_until = ui->now + ui->desc.fade_ms;
        if (last) set_hint(ui, refusal_text(r->refusal, false));
        return;
    }
    ui->part_count = r->part_count;
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
    // After the lines: the chips keep clear of them (layout_chips).
    if (last)
        set_chips(ui, r->category, r->guesses[0], r->guesses[1]);
    else
        set_chips(ui, NULL, NULL, NULL);
    ui->flash_until = ui->now + ui->desc.flash_ms;
    ui->fade_until = -1;
    ui->hint_until = -1;
    // The part is there, but something needs saying (only for the last stroke).
    if (last && r->hint)
        set_hint(ui, r->hint);
    else if (last && r->waiting)
        set_hint(ui, sp_kiosk_text(SP_KTEXT_WAITING));
}

void sp_kiosk_ui_set_scene(sp_kiosk_ui* ui, const float* xy, int n)
{
    line_set(&ui->scene, xy, n, SP_KIOSK_STROKE_MAX);
}

void sp_kiosk_ui_parts_changed(sp_kiosk_ui* ui, int part_count, const sp_kiosk_part_label* label)
{
    ui->part_count = part_count < 0 ? 0 : part_count;
    clear_overlays(ui);
    // After Undo the chips are the part that is now last (its stroke is the
    // last on the canvas), unless a stroke drawn since is waiting.
    if (label && label->category && ui->part_count > 0 && ui->pending_count == 0)
        set_chips(ui, label->category, label->guesses[0], label->guesses[1]);
    else
        set_chips(ui, NULL, NULL, NULL);
    // "Draw a body" holds only while the last part waits for one (Undo of a
    // chip that had made the body a part gives the body back).
    bool waiting = label && label->category && label->waiting && ui->part_count > 0;
    if (!waiting && !strcmp(ui->hint, sp_kiosk_text(SP_KTEXT_WAITING))) ui->hint_until = -1;
    ++ui->revision;
    if (ui->part_count == 0) { // an empty canvas starts again: the animation too
        ui->redraw_armed = false;
        ui->playing = ui->desc.start_playing;
        ui->anim_ms = 0;
    }
}

void sp_kiosk_ui_saved(sp_kiosk_ui* ui, bool ok, const char* code)
{
    ui->save_queued = false;
    ui->save_failed = !ok;
    if (ok && code && code[0]) {
        snprintf(ui->code, sizeof ui->code, "%s", code);
        ui->saved_revision = ui->revision;
        ui->banner_until = ui->now + ui->desc.banner_ms;
        snprintf(ui->banner[0], sizeof ui->banner[0], "%s %s", sp_kiosk_text(SP_KTEXT_SAVED), ui->code);
        snprintf(ui->banner[1], sizeof ui->banner[1], "%s", sp_kiosk_text(SP_KTEXT_CODE_USE));
        layout_banner(ui);
        if (ui->row_open) close_row(ui); // opened while the save ran: the banner would hide it
        if (!strcmp(ui->hint, sp_kiosk_text(SP_KTEXT_SAVING))) ui->hint_until = -1; // the banner says it now
    } else {
        set_hint(ui, sp_kiosk_text(SP_KTEXT_SAVE_FAILED));
    }
}

void sp_kiosk_ui_set_parts(sp_kiosk_ui* ui, const char* const* categories, int count)
{
    ui->row_count = 0;
    for (int i = 0; categories && i < count && ui->row_count < SP_KIOSK_ROW_MAX; ++i)
        if (categories[i] && categories[i][0]) copy_label(ui->row[ui->row_count++], categories[i]);
    layout_chips(ui);
}
