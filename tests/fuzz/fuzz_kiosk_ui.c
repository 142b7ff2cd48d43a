// fuzz_kiosk_ui.c: libFuzzer entry for the kiosk's UI state machine and its
// session scripts (app/kiosk_ui). An input that starts with '{' is a
// session document: parsed, and when it parses, replayed as the kiosk's
// --script does. Any other input is a stream of operations: touches
// anywhere (off the window, NaN, time running backwards), button presses,
// frames, resizes, and a pipeline whose answers the input chooses (a part,
// a refusal with offers, a detail kept, a failure, a save that fails). The
// UI must stay within its bounds whatever comes; ASan and UBSan watch the
// rest.
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sp/kiosk_session.h"
#include "sp/kiosk_ui.h"

// Aborts (a finding) when an invariant breaks.
#define CHECK(c) ((c) ? (void)0 : abort())

typedef struct reader {
    const uint8_t* p;
    size_t n;
} reader;

static unsigned byte(reader* r)
{
    if (!r->n) return 0;
    --r->n;
    return *r->p++;
}

static unsigned u16(reader* r)
{
    unsigned lo = byte(r);
    return lo | byte(r) << 8;
}

// Categories the pipeline may answer with: the database's, and names it never has.
static const char* const k_cats[] = {"torso",      "head",      "wings", "tail",
                                     "front_legs", "hind_legs", "",      "a_part_name_that_is_longer_than_any_label_may_hold_x"};
enum { CAT_N = sizeof k_cats / sizeof k_cats[0] };

static const char* cat(reader* r)
{
    return k_cats[byte(r) % CAT_N];
}

// A pipeline that answers whatever the input says; it keeps the part count
// honest (the UI is told the truth about the parts).
typedef struct pipeline {
    int parts;
} pipeline;

static void answer(sp_kiosk_ui* ui, pipeline* pl, reader* r)
{
    sp_kiosk_job j;
    float outline[2 * 64];
    int breaks[2] = {0, 16};
    while (sp_kiosk_ui_next_job(ui, &j)) {
        CHECK(j.kind > SP_KJOB_NONE && j.kind <= SP_KJOB_SAVE);
        unsigned how = byte(r);
        switch (j.kind) {
        case SP_KJOB_FIT:
        case SP_KJOB_REFIT: {
            if (j.kind == SP_KJOB_FIT) {
                CHECK(j.stroke && j.stroke->count >= 1 && j.stroke->count <= SP_KIOSK_STROKE_MAX);
                for (int i = 0; i < j.stroke->count; ++i)
                    CHECK(isfinite(j.stroke->xy[2 * i]) && isfinite(j.stroke->xy[2 * i + 1]));
            }
            if (j.undo_first && pl->parts > 0 && (how & 0x80)) --pl->parts;
            int n = (int)(how % 65);
            for (int i = 0; i < n; ++i)
                outline[2 * i] = (float)(u16(r) % 2000) - 300, outline[2 * i + 1] = (float)(u16(r) % 1400) - 300;
            sp_kiosk_fit_result res = {.part_count = pl->parts};
            switch (how % 4) {
            case 0: // a part (REFIT: the last part again)
                if (j.kind == SP_KJOB_FIT && !j.replace) ++pl->parts;
                if (pl->parts == 0) pl->parts = 1;
                res = (sp_kiosk_fit_result){.ok = true,
                                            .waiting = how & 0x40,
                                            .hint = how & 0x20 ? "a note beside the part" : NULL,
                                            .category = cat(r),
                                            .guesses = {cat(r), byte(r) & 1 ? NULL : cat(r)},
                                            .part_count = pl->parts,
                                            .outline = outline,
                                            .outline_count = n,
                                            .outline_breaks = n > 16 ? breaks : NULL,
                                            .outline_break_count = n > 16 ? 2 : 0,
                                            .stroke = how & 0x10 ? outline : NULL,
                                            .stroke_count = how & 0x10 ? n : 0};
                break;
            case 1: // refused, offered with guesses
                res = (sp_kiosk_fit_result){.refusal = (sp_kiosk_refusal)(byte(r) % 6),
                                            .offer = true,
                                            .offers = {cat(r), cat(r), byte(r) & 1 ? NULL : cat(r)},
                                            .part_count = pl->parts};
                break;
            case 2: // kept as a detail on the dragon
                res = (sp_kiosk_fit_result){.refusal = SP_KREF_DETAIL,
                                            .kept = pl->parts > 0,
                                            .offers = {cat(r), cat(r), cat(r)},
                                            .part_count = pl->parts};
                break;
            default: // failed (out of memory, a fit that went wrong)
                break;
            }
            sp_kiosk_ui_fit_done(ui, &res);
            break;
        }
        case SP_KJOB_UNDO: {
            if (pl->parts > 0) --pl->parts;
            sp_kiosk_part_label l = {pl->parts ? cat(r) : NULL, {cat(r), NULL}, pl->parts % 2 == 1};
            sp_kiosk_ui_parts_changed(ui, pl->parts, &l);
            break;
        }
        case SP_KJOB_CLEAR:
            pl->parts = 0;
            sp_kiosk_ui_parts_changed(ui, 0, NULL);
            break;
        case SP_KJOB_SAVE:
            sp_kiosk_ui_saved(ui, how & 1, how & 2 ? "K7QX" : NULL);
            break;
        default:
            break;
        }
    }
}

// What the kiosk reads every frame to draw the screen.
static void look(const sp_kiosk_ui* ui)
{
    char text[128];
    CHECK(ui->stroke.count >= 0 && ui->stroke.count <= SP_KIOSK_STROKE_MAX);
    CHECK(ui->job_count >= 0 && ui->job_count <= SP_KIOSK_JOBS_MAX);
    CHECK(ui->pending_count >= 0 && ui->pending_count <= SP_KIOSK_PENDING_MAX);
    CHECK(ui->part_count >= 0);
    CHECK(ui->mode == SP_KM_ATTRACT || ui->mode == SP_KM_DRAW || ui->mode == SP_KM_TURN);
    for (int t = 0; t < SP_KT_COUNT; ++t) {
        sp_kiosk_target k = (sp_kiosk_target)t;
        sp_kiosk_ui_target_visible(ui, k);
        sp_kiosk_ui_target_enabled(ui, k);
        sp_kiosk_ui_target_current(ui, k);
        sp_kiosk_ui_target_category(ui, k);
        const char* s = sp_kiosk_ui_target_text(ui, k, text, sizeof text);
        CHECK(!s || strlen(s) < sizeof text || s != text);
    }
    // The parts row's tiles shown lie on the canvas (past it they lay over the toolbar).
    CHECK(ui->row_fit >= 0 && ui->row_fit <= ui->row_count && ui->row_count <= SP_KIOSK_ROW_MAX);
    for (int i = 0; i < SP_KIOSK_ROW_MAX; ++i) {
        sp_kiosk_target k = (sp_kiosk_target)(SP_KT_PART1 + i);
        if (!sp_kiosk_ui_target_visible(ui, k)) continue;
        const sp_kiosk_rect* r = &ui->target[k];
        CHECK(i < ui->row_fit && r->y + r->h <= ui->canvas.y + ui->canvas.h + 1e-3f &&
              r->x + r->w <= ui->canvas.x + ui->canvas.w + 1e-3f);
    }
    const char* m = sp_kiosk_ui_message(ui);
    CHECK(!m || strlen(m) < 4096);
    double c = sp_kiosk_ui_countdown_s(ui), f = sp_kiosk_ui_fade(ui);
    CHECK(c >= 0 && isfinite(c) && isfinite(f));
    sp_kiosk_ui_flashing(ui);
    sp_kiosk_ui_offering(ui);
    sp_kiosk_ui_hint_visible(ui);
    sp_kiosk_ui_banner_visible(ui);
    sp_kiosk_ui_clear_armed(ui);
    sp_kiosk_ui_hit(ui, 0.5f * (float)ui->width, 0.5f * (float)ui->height);
}

static float coord(reader* r, int size)
{
    unsigned v = u16(r);
    switch (v >> 13) { // one in eight is a value no finger gives
    case 7:
        return (v & 1) ? NAN : (v & 2) ? INFINITY : -1e30f;
    case 6:
        return (float)((int)(v & 0x1fff) - 4096); // off the window
    default:
        return (float)(v % (unsigned)(size > 0 ? size : 1));
    }
}

static void operations(reader* r)
{
    sp_kiosk_ui_desc desc = {0};
    if (byte(r) & 1) { // a kiosk set up with short timers (a visit's timeouts within a few thousand events)
        desc.idle_ms = byte(r) * 40.0 - 200;
        desc.countdown_ms = byte(r) * 20.0;
        desc.offer_ms = byte(r) * 10.0;
        desc.join_ms = byte(r) * 4.0 - 100;
        desc.start_playing = byte(r) & 1;
    }
    sp_kiosk_ui* ui = NULL;
    CHECK(sp_kiosk_ui_create(&desc, &ui, NULL) == SP_OK && ui);
    int w = 1280, h = 800;
    sp_kiosk_ui_resize(ui, w, h, 96 / 25.4);
    const char* row[SP_KIOSK_ROW_MAX + 2];
    for (int i = 0; i < SP_KIOSK_ROW_MAX + 2; ++i)
        row[i] = k_cats[i % 6];
    sp_kiosk_ui_set_parts(ui, row, 6);
    pipeline pl = {0};
    double t = 0;
    while (r->n) {
        unsigned op = byte(r);
        t += (op >> 4) * (op & 8 ? 97.0 : 3.0);                // time passes, some events far apart
        double et = op & 0x80 && (op & 7) == 7 ? t - 5000 : t; // late events count as now
        switch (op & 7) {
        case 0:
        case 1:
        case 2: { // a finger: down, some moves, maybe an up or a cancel
            float x = coord(r, w), y = coord(r, h);
            sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_DOWN, et, x, y, (int)(byte(r) % 8 == 0)});
            int moves = (int)byte(r) * ((op & 7) == 2 ? 20 : 1); // some strokes longer than the UI keeps
            unsigned dir = byte(r);
            for (int i = 0; i < moves; ++i) {
                x += (float)((int)(dir & 15) - 7), y += (float)((int)(dir >> 4) - 7);
                if (i % 64 == 63) dir = byte(r);
                sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_MOVE, et += 4, x, y, 0});
            }
            unsigned end = byte(r) % 8;
            if (end < 6) sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_UP, et + 4, x, y, 0});
            if (end == 6) sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_CANCEL, et + 4, 0, 0, 0});
            t = fmax(t, et);
            break;
        }
        case 3: { // a single event of any kind
            sp_kiosk_event_type ty = (sp_kiosk_event_type)(byte(r) % (SP_KEV_TYPE_COUNT + 1));
            float x = coord(r, w), y = coord(r, h);
            sp_kiosk_ui_event(ui, &(sp_kiosk_event){ty, et, x, y, (int)(int8_t)byte(r)});
            break;
        }
        case 4: // a tap on a target, as a script's "press" does
            sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_PRESS, et, 0, 0, (int)(byte(r) % (SP_KT_COUNT + 2)) - 1});
            break;
        case 5: // a frame: the pipeline answers what is waiting
            sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_FRAME, et, 0, 0, 0});
            answer(ui, &pl, r);
            break;
        case 6: { // the window changes (a rotated tablet, a tiny or a huge window)
            unsigned s = byte(r);
            w = (int)(u16(r) % 5000), h = (int)(u16(r) % 5000);
            sp_kiosk_ui_resize(ui, w, h, s == 0 ? NAN : s * 0.05);
            break;
        }
        default: { // a curator's change: the parts row
            int n = (int)(byte(r) % (SP_KIOSK_ROW_MAX + 3));
            sp_kiosk_ui_set_parts(ui, row, n);
            break;
        }
        }
        look(ui);
    }
    sp_kiosk_ui_destroy(ui);
}

// A script, replayed as the kiosk replays one: mapped to a window, frames between events.
static void script(const uint8_t* data, size_t size)
{
    sp_kiosk_session s = {0};
    sp_error err = {0};
    if (sp_kiosk_session_parse((const char*)data, size, "fuzz.json", &s, &err) != SP_OK) {
        CHECK(err.text[0]); // every refusal says why
        sp_kiosk_session_free(&s);
        return;
    }
    sp_kiosk_ui* ui = NULL;
    CHECK(sp_kiosk_ui_create(NULL, &ui, NULL) == SP_OK && ui);
    sp_kiosk_ui_resize(ui, 1280, 800, 96 / 25.4);
    pipeline pl = {0};
    static const uint8_t k_answers[] = {0, 1, 2, 3, 0x40, 0x81, 0x10};
    reader answers = {k_answers, sizeof k_answers};
    double t = 0;
    // At most this many events and frames: a script may say it lasts for years.
    int budget = 200000;
    for (int i = 0; i < s.count && budget > 0; ++i, --budget) {
        sp_kiosk_event e = sp_kiosk_session_map(&s, &s.events[i], 1280, 800);
        for (; t + 16 < e.t_ms && budget > 0; --budget) {
            t += 16;
            sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_FRAME, t, 0, 0, 0});
            answers = (reader){k_answers, sizeof k_answers};
            answer(ui, &pl, &answers);
        }
        sp_kiosk_ui_event(ui, &e);
        look(ui);
    }
    sp_kiosk_ui_destroy(ui);
    sp_kiosk_session_free(&s);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size && data[0] == '{') {
        script(data, size);
    } else {
        reader r = {data, size};
        operations(&r);
    }
    return 0;
}
