// The kiosk's UI state machine without a GPU: flow, layout and hit testing
// at several screens, idle timeout, tap storms, stroke floods, session files
// and record -> replay. A small fake pipeline answers the UI's jobs.
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fixtures.h"
#include "sp/kiosk_lod.h"
#include "sp/kiosk_session.h"
#include "sp/kiosk_ui.h"
#include "test.h"

// ------------------------------------------------------------ fake pipeline

static const char* const k_cats[6] = {"head", "wings", "tail", "torso", "front_legs", "hind_legs"};

typedef struct fake {
    int parts;
    int cat[256]; // category index per part
    int fits, refits, undos, clears, saves, rejects;
    int heavy_per_frame; // heavy jobs answered per drain (0: all)
    char log[8192];      // one letter per job, for replay comparisons
    int log_n;
} fake;

static void fake_log(fake* f, char c)
{
    if (f->log_n < (int)sizeof f->log - 1) f->log[f->log_n++] = c, f->log[f->log_n] = 0;
}

// Category from the stroke's length (deterministic); strokes that stay
// within 40 px of a vertical line are "rejected" scribbles.
static int fake_classify(const sp_kiosk_line* s)
{
    double len = 0, xmin = 1e9, xmax = -1e9;
    for (int i = 0; i < s->count; ++i) {
        if (i) len += hypot(s->xy[2 * i] - s->xy[2 * i - 2], s->xy[2 * i + 1] - s->xy[2 * i - 1]);
        xmin = fmin(xmin, s->xy[2 * i]), xmax = fmax(xmax, s->xy[2 * i]);
    }
    if (xmax - xmin < 40) return -1;
    return (int)(len / 100) % 6;
}

static void fake_label(const fake* f, sp_kiosk_part_label* l)
{
    if (f->parts == 0) {
        *l = (sp_kiosk_part_label){0};
        return;
    }
    int c = f->cat[f->parts - 1];
    *l = (sp_kiosk_part_label){k_cats[c], {k_cats[(c + 1) % 6], k_cats[(c + 2) % 6]}};
}

static void fake_drain(sp_kiosk_ui* ui, fake* f)
{
    sp_kiosk_job j;
    int heavy = 0;
    while ((f->heavy_per_frame == 0 || heavy < f->heavy_per_frame) && sp_kiosk_ui_next_job(ui, &j)) {
        heavy += j.heavy;
        switch (j.kind) {
        case SP_KJOB_FIT: {
            fake_log(f, j.replace ? 'R' : 'F');
            int c = fake_classify(j.stroke);
            if (c < 0) {
                ++f->rejects;
                sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = false});
                break;
            }
            ++f->fits;
            if (!j.replace || f->parts == 0) f->parts = f->parts < 256 ? f->parts + 1 : f->parts;
            f->cat[f->parts - 1] = c;
            float outline[2 * 64];
            int n = j.stroke->count < 64 ? j.stroke->count : 64;
            for (int i = 0; i < n; ++i) {
                int k = (int)((long)i * (j.stroke->count - 1) / (n > 1 ? n - 1 : 1));
                outline[2 * i] = j.stroke->xy[2 * k] + 2, outline[2 * i + 1] = j.stroke->xy[2 * k + 1] - 1;
            }
            sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = true,
                                                            .category = k_cats[c],
                                                            .guesses = {k_cats[(c + 1) % 6], k_cats[(c + 2) % 6]},
                                                            .part_count = f->parts,
                                                            .outline = outline,
                                                            .outline_count = n});
            break;
        }
        case SP_KJOB_REFIT: {
            fake_log(f, 'G');
            ++f->refits;
            int c = 0;
            while (c < 6 && strcmp(k_cats[c], j.category) != 0)
                ++c;
            if (c == 6 || f->parts == 0) {
                sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = false});
                break;
            }
            f->cat[f->parts - 1] = c;
            float xy[4] = {10, 10, 200, 200};
            sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = true,
                                                            .category = k_cats[c],
                                                            .guesses = {k_cats[(c + 1) % 6]},
                                                            .part_count = f->parts,
                                                            .outline = xy,
                                                            .outline_count = 2,
                                                            .stroke = xy,
                                                            .stroke_count = 2});
            break;
        }
        case SP_KJOB_UNDO: {
            fake_log(f, 'U');
            ++f->undos;
            if (f->parts > 0) --f->parts;
            sp_kiosk_part_label l;
            fake_label(f, &l);
            sp_kiosk_ui_parts_changed(ui, f->parts, &l);
            break;
        }
        case SP_KJOB_CLEAR:
            fake_log(f, 'C');
            ++f->clears;
            f->parts = 0;
            sp_kiosk_ui_parts_changed(ui, 0, NULL);
            break;
        case SP_KJOB_SAVE:
            fake_log(f, 'S');
            ++f->saves;
            sp_kiosk_ui_saved(ui, true, "K7QX");
            break;
        default:
            break;
        }
    }
}

// ------------------------------------------------------------ input helpers

static void send(sp_kiosk_ui* ui, sp_kiosk_event_type type, double t, float x, float y)
{
    sp_kiosk_ui_event(ui, &(sp_kiosk_event){type, t, x, y, 0});
}

static void frame(sp_kiosk_ui* ui, fake* f, double t)
{
    send(ui, SP_KEV_FRAME, t, 0, 0);
    fake_drain(ui, f);
}

// A horizontal zig-zag stroke of n points from (x, y), 8 ms apart; returns the end time.
static double stroke(sp_kiosk_ui* ui, double t, float x, float y, int n, float step)
{
    send(ui, SP_KEV_DOWN, t, x, y);
    for (int i = 1; i < n; ++i)
        send(ui, SP_KEV_MOVE, t + 8 * i, x + step * (float)i, y + (i & 1 ? 20.0f : 0.0f));
    send(ui, SP_KEV_UP, t + 8 * n, x + step * (float)(n - 1), y);
    return t + 8 * n;
}

static void tap(sp_kiosk_ui* ui, double t, sp_kiosk_target tg)
{
    const sp_kiosk_rect* r = &ui->target[tg];
    send(ui, SP_KEV_DOWN, t, r->x + 0.5f * r->w, r->y + 0.5f * r->h);
    send(ui, SP_KEV_UP, t + 60, r->x + 0.5f * r->w, r->y + 0.5f * r->h);
}

static sp_kiosk_ui* started(fake* f)
{
    sp_kiosk_ui* ui = sp_kiosk_ui_create(NULL);
    ENSURE(ui);
    sp_kiosk_ui_resize(ui, 1280, 800, 96.0 / 25.4);
    memset(f, 0, sizeof *f);
    send(ui, SP_KEV_DOWN, 0, 640, 400);
    send(ui, SP_KEV_UP, 50, 640, 400);
    return ui;
}

// ------------------------------------------------------------ tests

static void test_flow(void)
{
    fake f;
    sp_kiosk_ui* ui = sp_kiosk_ui_create(NULL);
    sp_kiosk_ui_resize(ui, 1280, 800, 96.0 / 25.4);
    memset(&f, 0, sizeof f);
    ENSURE(ui->mode == SP_KM_ATTRACT);
    ENSURE(sp_kiosk_ui_hit(ui, ui->target[SP_KT_UNDO].x + 5, ui->target[SP_KT_UNDO].y + 5) == SP_KT_NONE); // no toolbar yet
    // A touch starts; the touch itself draws nothing.
    send(ui, SP_KEV_DOWN, 100, 640, 300);
    send(ui, SP_KEV_MOVE, 120, 700, 300);
    ENSURE(ui->stroke.count == 0);
    send(ui, SP_KEV_UP, 150, 700, 300);
    ENSURE(ui->mode == SP_KM_DRAW);
    frame(ui, &f, 160);
    ENSURE(f.log_n == 0);
    // Buttons that need a part do nothing yet.
    tap(ui, 200, SP_KT_UNDO);
    frame(ui, &f, 300);
    ENSURE(f.log_n == 0 && sp_kiosk_ui_hint_visible(ui));
    // A stroke: live points while drawing, a FIT job on release.
    send(ui, SP_KEV_DOWN, 1000, 300, 300);
    for (int i = 1; i < 30; ++i)
        send(ui, SP_KEV_MOVE, 1000 + 10 * i, 300.0f + 12.0f * (float)i, 300.0f + 40.0f * sinf(0.3f * (float)i));
    ENSURE(ui->stroke.count >= 29);
    send(ui, SP_KEV_UP, 1300, 660, 310);
    ENSURE(ui->stroke.count == 0 && ui->pending_count == 1);
    sp_kiosk_job j;
    ENSURE(sp_kiosk_ui_next_job(ui, &j));
    ENSURE(j.kind == SP_KJOB_FIT && j.heavy && !j.replace && j.stroke->count >= 30);
    ENSURE_NEAR(j.stroke->xy[0], 300, 1e-6);
    ENSURE_NEAR(j.stroke->t[j.stroke->count - 1], 1300, 1e-9);
    ENSURE(!sp_kiosk_ui_next_job(ui, &j));
    float outline[6] = {300, 300, 480, 330, 660, 310};
    sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = true,
                                                    .category = "wings",
                                                    .guesses = {"tail", "head"},
                                                    .part_count = 1,
                                                    .outline = outline,
                                                    .outline_count = 3});
    // The outline flashes for 0.8 s, then the part is there with its chips.
    ENSURE(sp_kiosk_ui_flashing(ui) && ui->flash_outline.count == 3 && ui->flash_stroke.count >= 30);
    frame(ui, &f, 1300 + 790);
    ENSURE(sp_kiosk_ui_flashing(ui));
    frame(ui, &f, 1300 + 810);
    ENSURE(!sp_kiosk_ui_flashing(ui));
    ENSURE(ui->part_count == 1 && strcmp(ui->chip[0], "wings") == 0 && strcmp(ui->chip[1], "tail") == 0 &&
           strcmp(ui->chip[2], "head") == 0);
    for (int t = SP_KT_CHIP_LABEL; t <= SP_KT_CHIP_GUESS2; ++t)
        ENSURE(sp_kiosk_ui_target_enabled(ui, (sp_kiosk_target)t));
    // A guess chip re-fits as that category.
    tap(ui, 2500, SP_KT_CHIP_GUESS2);
    ENSURE(sp_kiosk_ui_next_job(ui, &j) && j.kind == SP_KJOB_REFIT && strcmp(j.category, "head") == 0);
    tap(ui, 2600, SP_KT_CHIP_GUESS1); // ignored while the re-fit runs
    ENSURE(!sp_kiosk_ui_next_job(ui, &j));
    sp_kiosk_ui_fit_done(ui,
                         &(sp_kiosk_fit_result){.ok = true, .category = "head", .guesses = {"wings", "tail"}, .part_count = 1});
    ENSURE(strcmp(ui->chip[0], "head") == 0 && strcmp(ui->chip[1], "wings") == 0);
    ENSURE(!sp_kiosk_ui_hint_visible(ui));
    // An accepted part with a note (e.g. the body it touches cannot hold
    // it): the part is there and the note shows.
    tap(ui, 2700, SP_KT_CHIP_GUESS1);
    ENSURE(sp_kiosk_ui_next_job(ui, &j) && j.kind == SP_KJOB_REFIT);
    sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = true,
                                                    .hint = "It stays where you drew it",
                                                    .category = "head",
                                                    .guesses = {"wings", "tail"},
                                                    .part_count = 1});
    ENSURE(ui->part_count == 1 && sp_kiosk_ui_hint_visible(ui) && strcmp(ui->hint, "It stays where you drew it") == 0);
    // A rejected stroke: hint, fading stroke, nothing else changes.
    double t = stroke(ui, 4000, 100, 500, 20, 10);
    ENSURE(sp_kiosk_ui_next_job(ui, &j) && j.kind == SP_KJOB_FIT);
    sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = false, .hint = "Try a head"});
    ENSURE(ui->part_count == 1 && strcmp(ui->chip[0], "head") == 0 && strcmp(ui->hint, "Try a head") == 0);
    ENSURE(sp_kiosk_ui_fade(ui) > 0.99 && ui->fade_stroke.count > 2 && !sp_kiosk_ui_flashing(ui));
    frame(ui, &f, t + 600);
    ENSURE(sp_kiosk_ui_fade(ui) > 0.3 && sp_kiosk_ui_fade(ui) < 0.7);
    frame(ui, &f, t + 1300);
    ENSURE(sp_kiosk_ui_fade(ui) == 0);
    // Redraw: the next stroke replaces the last part; a second tap disarms.
    tap(ui, 6000, SP_KT_REDRAW);
    ENSURE(ui->redraw_armed);
    tap(ui, 6200, SP_KT_REDRAW);
    ENSURE(!ui->redraw_armed);
    tap(ui, 6400, SP_KT_REDRAW);
    stroke(ui, 6600, 200, 200, 20, 15);
    ENSURE(sp_kiosk_ui_next_job(ui, &j) && j.kind == SP_KJOB_FIT && j.replace && !ui->redraw_armed);
    sp_kiosk_ui_fit_done(ui, &(sp_kiosk_fit_result){.ok = false}); // rejected: still armed
    ENSURE(ui->redraw_armed);
    // Play, Turn (drag orbits; Back eases to the drawing view), Save.
    ENSURE(!ui->playing);
    tap(ui, 8000, SP_KT_PLAY);
    ENSURE(ui->playing);
    frame(ui, &f, 9000);
    ENSURE_NEAR(ui->anim_ms, 940, 1e-6); // playing since the tap's release at 8060
    tap(ui, 9100, SP_KT_TURN);
    ENSURE(ui->mode == SP_KM_TURN);
    send(ui, SP_KEV_DOWN, 9300, 600, 300);
    send(ui, SP_KEV_MOVE, 9320, 800, 250);
    send(ui, SP_KEV_UP, 9340, 800, 250);
    ENSURE(ui->yaw > 0.5 && ui->pitch < 0 && ui->stroke.count == 0 && ui->pending_count == 0);
    tap(ui, 9400, SP_KT_TURN);
    ENSURE(ui->mode == SP_KM_DRAW);
    frame(ui, &f, 11000);
    ENSURE(ui->yaw == 0 && ui->pitch == 0);
    tap(ui, 11100, SP_KT_SAVE);
    tap(ui, 11200, SP_KT_SAVE); // queued already: not twice
    frame(ui, &f, 11300);
    ENSURE(f.saves == 1 && sp_kiosk_ui_banner_visible(ui) && strcmp(ui->code, "K7QX") == 0);
    tap(ui, 11400, SP_KT_SAVE); // same dragon: same code, no new files
    frame(ui, &f, 11500);
    ENSURE(f.saves == 1 && sp_kiosk_ui_banner_visible(ui));
    // Undo, then Start over needs a second tap within 3 s.
    tap(ui, 12000, SP_KT_UNDO);
    frame(ui, &f, 12100);
    ENSURE(f.undos == 1 && ui->part_count == 0 && ui->chip[0][0] == 0 && !sp_kiosk_ui_target_enabled(ui, SP_KT_UNDO));
    ENSURE(!sp_kiosk_ui_target_enabled(ui, SP_KT_CHIP_LABEL));
    f.parts = 0;
    stroke(ui, 13000, 200, 200, 20, 15);
    frame(ui, &f, 13200);
    ENSURE(ui->part_count == 1);
    tap(ui, 14000, SP_KT_START_OVER);
    frame(ui, &f, 14100);
    ENSURE(f.clears == 0 && sp_kiosk_ui_clear_armed(ui));
    frame(ui, &f, 17200); // too late: disarmed
    ENSURE(!sp_kiosk_ui_clear_armed(ui));
    tap(ui, 17300, SP_KT_START_OVER);
    tap(ui, 18000, SP_KT_START_OVER);
    frame(ui, &f, 18100);
    ENSURE(f.clears == 1 && ui->part_count == 0 && ui->mode == SP_KM_DRAW);
    sp_kiosk_ui_destroy(ui);
}

static void check_rect_mm(const sp_kiosk_ui* ui, const sp_kiosk_rect* r, const char* what, double min_mm)
{
    double min_px = min_mm * ui->px_per_mm - 1e-3;
    if (!(r->w >= min_px && r->h >= min_px))
        fprintf(stderr, "  %s at %dx%d, %.2f px/mm: %.1f x %.1f px (%.1f x %.1f mm)\n", what, ui->width, ui->height,
                ui->px_per_mm, r->w, r->h, r->w / ui->px_per_mm, r->h / ui->px_per_mm);
    ENSURE(r->w >= min_px && r->h >= min_px);
    ENSURE(r->x >= -1e-3 && r->y >= -1e-3 && r->x + r->w <= ui->width + 1e-3 && r->y + r->h <= ui->height + 1e-3);
}

static void test_layout(void)
{
    // Screens: desktop, the e2e window, a 10" tablet, HiDPI laptop (content
    // scale 2), 4K on 27", portrait tablet, a small window on a dense screen.
    const struct {
        int w, h;
        double ppm;
    } screens[] = {
        {1280, 800, 96 / 25.4},      {1920, 1080, 3.6},        {1280, 800, 149 / 25.4},
        {2560, 1600, 2 * 96 / 25.4}, {3840, 2160, 163 / 25.4}, {800, 1280, 216 / 25.4},
        {640, 480, 96 / 25.4},       {1024, 600, 150 / 25.4},  {480, 800, 96 / 25.4},
    };
    fake f;
    for (size_t s = 0; s < sizeof screens / sizeof screens[0]; ++s) {
        sp_kiosk_ui* ui = started(&f);
        sp_kiosk_ui_resize(ui, screens[s].w, screens[s].h, screens[s].ppm);
        // Give it a part so every chip shows, with a long category name.
        stroke(ui, 1000, 0.2f * (float)screens[s].w, 0.3f * (float)screens[s].h, 20, 0.02f * (float)screens[s].w);
        sp_kiosk_job j;
        ENSURE(sp_kiosk_ui_next_job(ui, &j));
        sp_kiosk_ui_fit_done(
            ui, &(sp_kiosk_fit_result){.ok = true, .category = "front_legs", .guesses = {"hind_legs", "wings"}, .part_count = 1});
        for (int t = SP_KT_UNDO; t < SP_KT_COUNT; ++t) {
            const sp_kiosk_rect* r = &ui->target[t];
            check_rect_mm(ui, r, sp_kiosk_target_name((sp_kiosk_target)t), 15.0);
            // The centre and every point 1 mm inside the edge hit this target.
            float in = (float)ui->px_per_mm;
            float pts[5][2] = {{r->x + 0.5f * r->w, r->y + 0.5f * r->h},
                               {r->x + in, r->y + in},
                               {r->x + r->w - in, r->y + in},
                               {r->x + in, r->y + r->h - in},
                               {r->x + r->w - in, r->y + r->h - in}};
            for (int k = 0; k < 5; ++k)
                ENSURE(sp_kiosk_ui_hit(ui, pts[k][0], pts[k][1]) == (sp_kiosk_target)t);
            // No two targets overlap (at least 2 mm apart), and toolbar buttons stay off the canvas.
            for (int u = SP_KT_UNDO; u < t; ++u) {
                const sp_kiosk_rect* q = &ui->target[u];
                double gap =
                    fmax(fmax(q->x - (r->x + r->w), r->x - (q->x + q->w)), fmax(q->y - (r->y + r->h), r->y - (q->y + q->h)));
                ENSURE(gap >= 2.0 * ui->px_per_mm - 1e-3);
            }
            if (t <= SP_KT_SAVE) {
                const sp_kiosk_rect* c = &ui->canvas;
                bool apart = r->y >= c->y + c->h || r->x >= c->x + c->w;
                ENSURE(apart);
            }
        }
        // The canvas keeps most of the screen.
        ENSURE(ui->canvas.w * ui->canvas.h >= 0.45 * screens[s].w * screens[s].h);
        // Far from every target: nothing.
        ENSURE(sp_kiosk_ui_hit(ui, ui->canvas.x + 0.5f * ui->canvas.w, ui->canvas.y + 0.6f * ui->canvas.h) == SP_KT_NONE);
        ENSURE(sp_kiosk_ui_hit(ui, NAN, 3) == SP_KT_NONE);
        sp_kiosk_ui_destroy(ui);
    }
    // Degenerate sizes and densities never crash and fall back to 96 dpi.
    sp_kiosk_ui* ui = sp_kiosk_ui_create(NULL);
    sp_kiosk_ui_resize(ui, 0, -5, NAN);
    ENSURE(ui->width == 1 && ui->height == 1);
    ENSURE_NEAR(ui->px_per_mm, 96 / 25.4, 1e-9);
    sp_kiosk_ui_resize(ui, 100000, 3, 1e-9);
    sp_kiosk_ui_destroy(ui);
}

static void test_idle_timeout(void)
{
    fake f;
    sp_kiosk_ui* ui = started(&f);
    double t = stroke(ui, 1000, 200, 300, 30, 10);
    frame(ui, &f, t + 10);
    ENSURE(ui->part_count == 1);
    // 80 s of nothing: the countdown shows 10 s...
    frame(ui, &f, t + 79900);
    ENSURE(sp_kiosk_ui_countdown_s(ui) == 0);
    frame(ui, &f, t + 80500);
    ENSURE_NEAR(sp_kiosk_ui_countdown_s(ui), 9.5, 1e-9);
    // ...a touch anywhere cancels it and does nothing else.
    send(ui, SP_KEV_DOWN, t + 81000, 400, 400);
    send(ui, SP_KEV_MOVE, t + 81050, 600, 420);
    send(ui, SP_KEV_UP, t + 81100, 600, 420);
    frame(ui, &f, t + 81200);
    ENSURE(sp_kiosk_ui_countdown_s(ui) == 0 && f.fits == 1 && ui->mode == SP_KM_DRAW && ui->pending_count == 0);
    // Held still with a finger down still times out (a stuck touch cannot keep the kiosk busy).
    double t2 = t + 81100;
    send(ui, SP_KEV_DOWN, t2 + 100, 400, 400);
    frame(ui, &f, t2 + 100 + 89000);
    ENSURE_NEAR(sp_kiosk_ui_countdown_s(ui), 1.0, 1e-9);
    frame(ui, &f, t2 + 100 + 90000);
    ENSURE(ui->mode == SP_KM_ATTRACT && f.clears == 1 && ui->part_count == 0 && ui->resets == 1);
    send(ui, SP_KEV_UP, t2 + 100 + 90100, 400, 400);
    ENSURE(ui->mode == SP_KM_ATTRACT);
    // Attract never times out.
    frame(ui, &f, t2 + 1e7);
    ENSURE(ui->mode == SP_KM_ATTRACT && f.clears == 1);
    sp_kiosk_ui_destroy(ui);
}

// Every kind of input, at random, for 10^4 events a minute and more: the
// UI stays consistent and bounded, and answers a normal stroke afterwards.
static void test_tap_storm(void)
{
    fake f;
    sp_kiosk_ui* ui = started(&f);
    sp_test_rng rng = {42};
    double t = 100;
    for (int i = 0; i < 20000; ++i) {
        t += sp_test_range(&rng, 0, 6);
        double u = sp_test_uniform(&rng);
        sp_kiosk_target tg = (sp_kiosk_target)(1 + (int)(sp_test_uniform(&rng) * (SP_KT_COUNT - 1)));
        const sp_kiosk_rect* r = &ui->target[tg];
        float x = r->x + (float)sp_test_uniform(&rng) * r->w, y = r->y + (float)sp_test_uniform(&rng) * r->h;
        if (u < 0.1)
            x = (float)sp_test_range(&rng, -500, 2000), y = (float)sp_test_range(&rng, -500, 1500); // anywhere, off-screen too
        sp_kiosk_event_type ty = u < 0.4    ? SP_KEV_DOWN
                                 : u < 0.75 ? SP_KEV_UP
                                 : u < 0.9  ? SP_KEV_MOVE
                                 : u < 0.93 ? SP_KEV_CANCEL
                                            : SP_KEV_PRESS;
        int button = sp_test_uniform(&rng) < 0.05 ? 1 : 0;
        if (ty == SP_KEV_PRESS) button = (int)sp_test_range(&rng, -2, SP_KT_COUNT + 2);
        if (sp_test_uniform(&rng) < 0.01) x = NAN;
        double tt = sp_test_uniform(&rng) < 0.01 ? t - 1000 : t; // late events count as now
        if (sp_test_uniform(&rng) < 0.6) {                       // a quick tap on the target
            sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_DOWN, tt, x, y, 0});
            ty = SP_KEV_UP, button = 0, tt += sp_test_range(&rng, 0, 6);
        }
        sp_kiosk_ui_event(ui, &(sp_kiosk_event){ty, tt, x, y, button});
        if (i % 3 == 0) frame(ui, &f, t);
        ENSURE(ui->job_count <= SP_KIOSK_JOBS_MAX && ui->pending_count <= SP_KIOSK_PENDING_MAX);
        ENSURE(ui->stroke.count <= SP_KIOSK_STROKE_MAX);
        ENSURE(ui->part_count == f.parts);
        ENSURE(ui->mode == SP_KM_ATTRACT || ui->mode == SP_KM_DRAW || ui->mode == SP_KM_TURN);
    }
    int total = 0;
    for (int k = 1; k < SP_KT_COUNT; ++k)
        total += ui->activations[k];
    ENSURE(total > 1000);
    // Every job kind ran during the storm.
    ENSURE(f.undos > 0 && f.clears > 0 && f.saves > 0 && f.refits > 0);
    // Still responsive: back to drawing, one stroke, one part more.
    send(ui, SP_KEV_CANCEL, t + 1, 0, 0);
    frame(ui, &f, t + 2);
    if (ui->mode == SP_KM_ATTRACT) {
        send(ui, SP_KEV_DOWN, t + 3, 640, 300);
        send(ui, SP_KEV_UP, t + 4, 640, 300);
    }
    if (ui->mode == SP_KM_TURN) tap(ui, t + 5, SP_KT_TURN);
    ENSURE(ui->mode == SP_KM_DRAW);
    int before = f.parts, fits = f.fits;
    stroke(ui, t + 100, 200, 200, 30, 11);
    frame(ui, &f, t + 500);
    ENSURE(f.fits == fits + 1 && ui->part_count == (before < 256 ? before + 1 : before));
    sp_kiosk_ui_destroy(ui);
}

// 10^4 strokes in one minute against a pipeline that takes one job a frame
// at 60 frames a second: the backlog stays at two strokes, the rest are
// counted as dropped, the last stroke is always fitted.
static void test_stroke_flood(void)
{
    fake f;
    sp_kiosk_ui* ui = started(&f);
    f.heavy_per_frame = 1;
    double next_frame = 0;
    int n = 10000;
    for (int i = 0; i < n; ++i) {
        double t0 = 100 + 6.0 * i; // 10^4 in 60 s
        send(ui, SP_KEV_DOWN, t0, 100.0f + (float)(i % 7) * 50, 200);
        send(ui, SP_KEV_MOVE, t0 + 2, 300.0f + (float)(i % 7) * 50, 260);
        send(ui, SP_KEV_UP, t0 + 4, 420.0f + (float)(i % 5) * 30, 200);
        ENSURE(ui->pending_count <= SP_KIOSK_PENDING_MAX);
        while (next_frame <= t0 + 4) {
            frame(ui, &f, next_frame);
            next_frame += 1000.0 / 60.0;
        }
    }
    for (int k = 0; k < 10; ++k)
        frame(ui, &f, next_frame + 17 * k);
    ENSURE(ui->strokes_finished == n);
    ENSURE(f.fits + f.rejects + ui->dropped_strokes == n);
    ENSURE(f.fits + f.rejects >= 3500); // ~one a frame
    ENSURE(ui->pending_count == 0 && ui->job_count == 0);
    sp_kiosk_ui_destroy(ui);
}

static void test_long_stroke(void)
{
    fake f;
    sp_kiosk_ui* ui = started(&f);
    send(ui, SP_KEV_DOWN, 100, 10, 10);
    for (int i = 1; i <= 100000; ++i)
        send(ui, SP_KEV_MOVE, 100 + 0.01 * i, 10.0f + (float)(i % 1000), 10.0f + (float)(i / 1000) * 5.0f);
    ENSURE(ui->stroke.count <= SP_KIOSK_STROKE_MAX && ui->stroke.count > SP_KIOSK_STROKE_MAX / 4);
    send(ui, SP_KEV_MOVE, 2000, 5000, -300); // leaves the window: clamped to its edge
    send(ui, SP_KEV_UP, 2001, 5000, -300);
    sp_kiosk_job j;
    ENSURE(sp_kiosk_ui_next_job(ui, &j) && j.kind == SP_KJOB_FIT);
    ENSURE_NEAR(j.stroke->xy[0], 10, 1e-6);
    ENSURE_NEAR(j.stroke->xy[2 * j.stroke->count - 2], 1279, 1e-6);
    ENSURE_NEAR(j.stroke->xy[2 * j.stroke->count - 1], 0, 1e-6);
    // One point, and a tiny wiggle, are taps: a hint, no job.
    send(ui, SP_KEV_DOWN, 3000, 500, 500);
    send(ui, SP_KEV_UP, 3010, 500, 500);
    send(ui, SP_KEV_DOWN, 3100, 500, 500);
    send(ui, SP_KEV_MOVE, 3110, 505, 502);
    send(ui, SP_KEV_UP, 3120, 505, 502);
    ENSURE(!sp_kiosk_ui_next_job(ui, &j) && ui->taps == 2 && sp_kiosk_ui_hint_visible(ui));
    // A focus loss in mid-stroke keeps the stroke.
    send(ui, SP_KEV_DOWN, 4000, 100, 100);
    send(ui, SP_KEV_MOVE, 4010, 300, 150);
    send(ui, SP_KEV_CANCEL, 4020, 0, 0);
    ENSURE(sp_kiosk_ui_next_job(ui, &j) && j.kind == SP_KJOB_FIT && j.stroke->count == 2);
    sp_kiosk_ui_destroy(ui);
}

// A session of strokes, taps and drags, fed with irregular frames and
// recorded; the file replayed with other frame times makes the same jobs
// and ends in the same state.
static void run_session(const sp_kiosk_session* s, double frame_ms, uint64_t seed, fake* f, sp_kiosk_ui** out,
                        sp_kiosk_session* rec)
{
    memset(f, 0, sizeof *f);
    sp_kiosk_ui* ui = sp_kiosk_ui_create(NULL);
    sp_kiosk_ui_resize(ui, 1280, 800, 96 / 25.4);
    sp_test_rng rng = {seed};
    double t = 0;
    for (int i = 0; i < s->count; ++i) {
        sp_kiosk_event e = sp_kiosk_session_map(s, &s->events[i], 1280, 800);
        while (t + frame_ms < e.t_ms) {
            t += frame_ms * (seed ? sp_test_range(&rng, 0.3, 1.0) : 1.0);
            frame(ui, f, t);
        }
        sp_kiosk_ui_event(ui, &e);
        if (rec && e.type != SP_KEV_FRAME) ENSURE(sp_kiosk_session_append(rec, &e) == SP_OK);
    }
    while (t < s->end_ms) {
        t = fmin(s->end_ms, t + frame_ms);
        frame(ui, f, t);
    }
    *out = ui;
}

static void test_record_replay(void)
{
    const char* script = sp_test_tmp_path("script.json");
    FILE* fp = fopen(script, "w");
    ENSURE(fp);
    fprintf(fp, "{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"canvas\": [640, 400], \"coords\": \"pixels\", "
                "\"end_ms\": 30000,\n"
                " \"events\": [{\"t\": 0, \"type\": \"down\", \"x\": 320, \"y\": 200}, {\"t\": 50, \"type\": \"up\", \"x\": 320, "
                "\"y\": 200},\n");
    double t = 500;
    for (int s = 0; s < 6; ++s, t += 1500) {
        fprintf(fp, "  {\"t\": %g, \"type\": \"stroke\", \"dt\": 9, \"points\": [", t);
        for (int i = 0; i < 25; ++i)
            fprintf(fp, "%s[%d, %d]", i ? ", " : "", 60 + 20 * s + (10 + s) * i, 60 + 30 * s + (i % 3) * 7);
        fprintf(fp, "]},\n");
    }
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"guess1\"},\n", t);
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"play\"},\n", t + 300);
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"undo\"},\n", t + 600);
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"turn\"},\n", t + 900);
    fprintf(fp, "  {\"t\": %g, \"type\": \"stroke\", \"dt\": 16, \"points\": [[300, 200], [400, 180], [500, 260]]},\n", t + 1200);
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"turn\"},\n", t + 2000);
    fprintf(fp, "  {\"t\": %g, \"type\": \"mark\", \"name\": \"mid-1\"},\n", t + 2100);
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"save\"},\n", t + 2200);
    fprintf(fp, "  {\"t\": %g, \"type\": \"press\", \"target\": \"redraw\"},\n", t + 2500);
    fprintf(fp, "  {\"t\": %g, \"type\": \"stroke\", \"points\": [[100, 300], [300, 320], [500, 300]]}]}\n", t + 2800);
    fclose(fp);
    sp_kiosk_session s = {0};
    sp_error err = {0};
    ENSURE(sp_kiosk_session_read(script, &s, &err) == SP_OK);
    ENSURE(s.canvas_w == 640 && s.canvas_h == 400 && s.end_ms == 30000 && s.mark_count == 1 &&
           strcmp(s.marks[0].name, "mid-1") == 0);
    ENSURE(s.count == 2 + 6 * 26 + 4 + 4 + 1 + 1 + 1 + 4);
    // Live-like run with irregular frames, recorded in window pixels.
    fake f1, f2;
    sp_kiosk_ui *a, *b;
    sp_kiosk_session rec = {.canvas_w = 1280, .canvas_h = 800, .px_per_mm = 96 / 25.4};
    run_session(&s, 16.7, 7, &f1, &a, &rec);
    ENSURE(f1.fits >= 5 && f1.refits == 1 && f1.undos == 1 && f1.saves == 1);
    ENSURE(strchr(f1.log, 'R') != NULL); // the Redraw stroke replaced
    ENSURE(a->activations[SP_KT_TURN] == 2);
    const char* recorded = sp_test_tmp_path("recorded.json");
    ENSURE(sp_kiosk_session_write(recorded, &rec, &err) == SP_OK);
    sp_kiosk_session back = {0};
    ENSURE(sp_kiosk_session_read(recorded, &back, &err) == SP_OK);
    ENSURE(back.count == rec.count && back.canvas_w == 1280);
    for (int i = 0; i < back.count; ++i) {
        ENSURE(back.events[i].type == rec.events[i].type && back.events[i].t_ms == rec.events[i].t_ms);
        ENSURE(back.events[i].x == rec.events[i].x && back.events[i].y == rec.events[i].y &&
               back.events[i].button == rec.events[i].button);
    }
    // Replay at a fixed 60 Hz (the scripted kiosk's clock).
    back.end_ms = s.end_ms;
    run_session(&back, 1000.0 / 60.0, 0, &f2, &b, NULL);
    ENSURE(strcmp(f1.log, f2.log) == 0);
    ENSURE(a->part_count == b->part_count && a->mode == b->mode && a->playing == b->playing && a->revision == b->revision);
    for (int i = 0; i < 3; ++i)
        ENSURE(strcmp(a->chip[i], b->chip[i]) == 0);
    ENSURE(strcmp(a->code, b->code) == 0 && a->anim_ms == b->anim_ms);
    sp_kiosk_ui_destroy(a);
    sp_kiosk_ui_destroy(b);
    sp_kiosk_session_free(&s);
    sp_kiosk_session_free(&rec);
    sp_kiosk_session_free(&back);
}

static void test_session_errors(void)
{
    const struct {
        const char* text;
        const char* expect;
    } bad[] = {
        {"{", "not valid JSON"},
        {"{\"format\": \"x\", \"version\": 1, \"events\": []}", "not a kiosk session"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 2, \"events\": []}", "version"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1}", "\"events\" must be an array"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"type\": \"down\", \"x\": 1, \"y\": 2}]}",
         "events[0]: \"t\""},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 5, \"type\": \"up\", \"x\": 1, \"y\": "
         "2}, "
         "{\"t\": 4, \"type\": \"down\", \"x\": 1, \"y\": 2}]}",
         "events[1]: t = 4 goes back"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 1, \"type\": \"tap\"}]}",
         "unknown type \"tap\""},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 1, \"type\": \"press\", \"target\": "
         "\"x\"}]}",
         "\"press\" needs \"target\""},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 1, \"type\": \"down\", \"x\": 1}]}",
         "finite \"x\" and \"y\""},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 1, \"type\": \"stroke\", \"points\": "
         "[]}]}",
         "a stroke needs"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 1, \"type\": \"stroke\", \"points\": "
         "[[1, \"a\"]]}]}",
         "points[0]"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"events\": [{\"t\": 1, \"type\": \"mark\", \"name\": "
         "\"../x\"}]}",
         "a mark needs"},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"canvas\": [0, 5], \"events\": []}", "\"canvas\""},
        {"{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"coords\": \"mm\", \"events\": []}", "\"coords\""},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        sp_kiosk_session s = {0};
        sp_error err = {0};
        sp_result r = sp_kiosk_session_parse(bad[i].text, strlen(bad[i].text), "bad.json", &s, &err);
        if (r == SP_OK || !strstr(err.text, bad[i].expect) || strncmp(err.text, "bad.json: ", 10) != 0)
            fprintf(stderr, "  case %zu: got \"%s\", expected \"%s\"\n", i, err.text, bad[i].expect);
        ENSURE(r != SP_OK && strstr(err.text, bad[i].expect) && strncmp(err.text, "bad.json: ", 10) == 0);
        ENSURE(s.events == NULL && s.count == 0);
    }
    sp_kiosk_session s = {0};
    sp_error err = {0};
    ENSURE(sp_kiosk_session_read("/nonexistent/s.json", &s, &err) == SP_ERR_IO && strstr(err.text, "/nonexistent/s.json"));
    const char* ok = "{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"coords\": \"unit\", \"events\": "
                     "[{\"t\": 1, \"type\": \"down\", \"x\": 0.5, \"y\": 0.25}]}";
    ENSURE(sp_kiosk_session_parse(ok, strlen(ok), "ok.json", &s, &err) == SP_OK);
    sp_kiosk_event e = sp_kiosk_session_map(&s, &s.events[0], 1000, 800);
    ENSURE_NEAR(e.x, 500, 1e-4);
    ENSURE_NEAR(e.y, 200, 1e-4);
    ENSURE(s.end_ms == 1);
    sp_kiosk_session_free(&s);
}

// A UV sphere of (rings x segs) quads, two triangles each.
static void sphere(int rings, int segs, double** xyz, int* nv, uint32_t** tris, int* nt)
{
    *nv = (rings + 1) * segs;
    *xyz = malloc(sizeof(double) * 3 * (size_t)*nv);
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s < segs; ++s) {
            double th = M_PI * r / rings, ph = 2 * M_PI * s / segs;
            double* p = *xyz + 3 * (r * segs + s);
            p[0] = sin(th) * cos(ph), p[1] = cos(th), p[2] = sin(th) * sin(ph);
        }
    *nt = 2 * rings * segs;
    *tris = malloc(sizeof(uint32_t) * 3 * (size_t)*nt);
    int k = 0;
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segs; ++s) {
            uint32_t a = (uint32_t)(r * segs + s), b = (uint32_t)(r * segs + (s + 1) % segs), c = a + (uint32_t)segs,
                     d = b + (uint32_t)segs;
            uint32_t t[6] = {a, c, b, b, c, d};
            memcpy(*tris + 3 * k, t, sizeof t);
            k += 2;
        }
}

static void test_lod(void)
{
    double* xyz;
    uint32_t* tris;
    int nv, nt;
    sphere(120, 160, &xyz, &nv, &tris, &nt);
    float* col = malloc(sizeof(float) * 4 * (size_t)nv);
    for (int v = 0; v < nv; ++v)
        col[4 * v] = xyz[3 * v + 1] > 0 ? 1.0f : 0.0f, col[4 * v + 1] = 0.5f, col[4 * v + 2] = 0, col[4 * v + 3] = 1;
    sp_lod lod;
    ENSURE(sp_lod_build(xyz, nv, tris, nt, col, 4000, &lod) == SP_OK);
    ENSURE(lod.tri_count <= 4000 && lod.tri_count > 1500); // the finest grid within the budget uses most of it
    ENSURE(lod.cluster_count < nv && lod.vertex_count == nv);
    double* pos = malloc(sizeof(double) * 3 * (size_t)lod.cluster_count);
    sp_lod_positions(&lod, xyz, pos);
    // Clusters are means of nearby points of the unit sphere: inside it, close to it.
    for (int k = 0; k < lod.cluster_count; ++k) {
        double r = sqrt(pos[3 * k] * pos[3 * k] + pos[3 * k + 1] * pos[3 * k + 1] + pos[3 * k + 2] * pos[3 * k + 2]);
        ENSURE(r <= 1 + 1e-9 && r > 0.9);
        ENSURE(lod.colors[4 * k + 1] == 0.5f && lod.colors[4 * k] >= 0 && lod.colors[4 * k] <= 1);
    }
    // No degenerate and no duplicate triangles (either winding).
    for (int i = 0; i < lod.tri_count; ++i) {
        uint32_t* t = lod.tris + 3 * i;
        ENSURE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && t[0] < (uint32_t)lod.cluster_count &&
               t[2] < (uint32_t)lod.cluster_count);
    }
    // Moving every vertex moves the clusters the same way (they follow the skinning).
    for (int v = 0; v < 3 * nv; v += 3)
        xyz[v] += 5;
    double* moved = malloc(sizeof(double) * 3 * (size_t)lod.cluster_count);
    sp_lod_positions(&lod, xyz, moved);
    for (int k = 0; k < lod.cluster_count; ++k)
        ENSURE_NEAR(moved[3 * k], pos[3 * k] + 5, 1e-5); // 1/members is a float
    sp_lod_free(&lod);
    // Within the budget: kept as is.
    ENSURE(sp_lod_build(xyz, nv, tris, nt, NULL, nt, &lod) == SP_OK);
    ENSURE(lod.cluster_count == nv && lod.colors == NULL);
    ENSURE(lod.tri_count == nt); // one cluster a vertex: every triangle stays
    sp_lod_free(&lod);
    // A sheet folded onto itself (both windings) keeps one face.
    const double sheet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    const uint32_t two[12] = {0, 1, 2, 2, 1, 3, 0, 2, 1, 2, 3, 1};
    ENSURE(sp_lod_build(sheet, 4, two, 4, NULL, 100, &lod) == SP_OK && lod.tri_count == 2);
    sp_lod_free(&lod);
    // Bad input is refused, not read out of bounds.
    const uint32_t bad[3] = {0, 1, 7};
    ENSURE(sp_lod_build(sheet, 4, bad, 1, NULL, 100, &lod) == SP_ERR_INVALID);
    double nan_xyz[12] = {0, 0, 0, NAN, 0, 0, 0, 1, 0, 1, 1, 0};
    ENSURE(sp_lod_build(nan_xyz, 4, two, 4, NULL, 1, &lod) == SP_ERR_INVALID);
    free(xyz);
    free(tris);
    free(col);
    free(pos);
    free(moved);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"flow", test_flow},
                                   {"layout", test_layout},
                                   {"idle_timeout", test_idle_timeout},
                                   {"tap_storm", test_tap_storm},
                                   {"stroke_flood", test_stroke_flood},
                                   {"long_stroke", test_long_stroke},
                                   {"record_replay", test_record_replay},
                                   {"session_errors", test_session_errors},
                                   {"lod", test_lod},
                                   {0}});
}
