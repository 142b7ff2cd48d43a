// kiosk_row.c: the row of parts offered with a refused stroke: every category
// of the database as a button showing its first part's outline at rest (as
// the attract screen draws outlines) over its name. The outlines are loaded
// once, after the first frame, and again when the database changes.
#include "kiosk_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/kiosk_text.h"

sp_result kiosk_load_category_part(sp_db* db, const char* category, sp_character* ch, int* abstraction, sp_error* err)
{
    char** names = NULL;
    int count = 0;
    sp_db_part_info info;
    sp_result r = sp_db_category_parts(db, category, &names, &count, err);
    if (r == SP_OK && count == 0) r = sp_fail(err, SP_ERR_INVALID, "%s: no part of category %s", sp_db_path(db), category);
    if (r == SP_OK) r = sp_db_load_part(db, names[0], ch, err);
    if (r == SP_OK) r = sp_db_part(db, names[0], &info, err);
    if (r == SP_OK && ch->rig.abstraction_count == 0)
        r = sp_fail(err, SP_ERR_INVALID, "%s: part %s has no abstraction", sp_db_path(db), names[0]);
    if (r == SP_OK) {
        int a = sp_rig_find_abstraction(&ch->rig, info.abstraction);
        *abstraction = a < 0 ? 0 : a;
    } else {
        sp_character_free(ch);
    }
    sp_db_free_strings(names, count);
    return r;
}

static int by_row_order(const void* a, const void* b)
{
    const char *x = *(const char*const*)a, *y = *(const char*const*)b;
    int ox = sp_kiosk_part_order(x), oy = sp_kiosk_part_order(y);
    return ox != oy ? (ox < oy ? -1 : 1) : strcmp(x, y);
}

// The outline in the unit square (y down), centred, its aspect kept.
static void normalise(part_icon* ic)
{
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < ic->n; ++i)
        for (int c = 0; c < 2; ++c)
            lo[c] = fminf(lo[c], ic->xy[2 * i + c]), hi[c] = fmaxf(hi[c], ic->xy[2 * i + c]);
    float s = fmaxf(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(s > 0)) {
        ic->n = 0;
        return;
    }
    for (int i = 0; i < ic->n; ++i)
        for (int c = 0; c < 2; ++c)
            ic->xy[2 * i + c] = 0.5f + (ic->xy[2 * i + c] - 0.5f * (lo[c] + hi[c])) / s;
}

void kiosk_row_free(sp_kiosk* k)
{
    for (int i = 0; i < k->icon_count; ++i)
        free(k->icons[i].xy);
    memset(k->icons, 0, sizeof k->icons);
    k->icon_count = 0;
    free(k->row_source);
    k->row_source = NULL;
}

char* kiosk_row_source(sp_db* db, char* const* cats, int n)
{
    sp_db_part_info* parts = NULL;
    int np = 0;
    sp_error err = {0};
    if (sp_db_list_parts(db, &parts, &np, &err) != SP_OK) return NULL;
    // Sized exactly: a category's name has no length limit in the database.
    size_t cap = 1;
    for (int c = 0; c < n; ++c)
        cap += strlen(cats[c]) + 1;
    for (int i = 0; i < np; ++i)
        cap += strlen(parts[i].name) + strlen(parts[i].category) + strlen(parts[i].abstraction) + strlen(parts[i].sha256) + 4;
    char* s = malloc(cap);
    size_t at = 0;
    for (int c = 0; s && c < n; ++c)
        at += (size_t)snprintf(s + at, cap - at, "%s\n", cats[c]);
    for (int i = 0; s && i < np; ++i)
        at += (size_t)snprintf(s + at, cap - at, "%s %s %s %s\n", parts[i].name, parts[i].category, parts[i].abstraction,
                               parts[i].sha256);
    free(parts);
    return s;
}

// One line for a curator: the categories past the row's room, which a
// visitor reaches only as a guess.
static void left_out(const sp_kiosk* k, char* const* cats, int from, int n)
{
    char names[512] = "";
    size_t at = 0;
    for (int i = from; i < n && at < sizeof names; ++i)
        at += (size_t)snprintf(names + at, sizeof names - at, "%s%s", i > from ? ", " : "", cats[i]);
    sp_kiosk_log("%s: %d part categories, more than the parts row's %d: not offered in it (only as guesses): %s%s", k->db_path, n,
                 SP_KIOSK_ROW_MAX, names, at >= sizeof names ? "..." : "");
}

void kiosk_row_load(sp_kiosk* k)
{
    k->icons_loaded = true;
    sp_db* db = NULL;
    sp_error err = {0};
    char** cats = NULL;
    int n = 0;
    if (sp_db_open(k->db_path, SP_DB_READONLY, &db, &err) != SP_OK || sp_db_categories(db, &cats, &n, &err) != SP_OK) {
        sp_kiosk_log("refused strokes get no parts row: %s", err.text);
        sp_db_close(db);
        kiosk_row_free(k);
        return;
    }
    // A database change that left the parts as they were (a model, a
    // curator's sketch) keeps the row: reading six parts again held a frame
    // (BENCHMARKS.md, "A new model while the kiosk runs").
    char* source = kiosk_row_source(db, cats, n);
    // The attract screen's demo shows the parts too: built from others, it is built again.
    if (source && k->demo_prepared && !k->desc.no_attract_demo && (!k->demo_source || strcmp(source, k->demo_source) != 0))
        k->demo_stale = true;
    if (source && k->row_source && !strcmp(source, k->row_source)) {
        free(source);
        sp_db_free_strings(cats, n);
        sp_db_close(db);
        return;
    }
    kiosk_row_free(k);
    k->row_source = source;
    qsort(cats, (size_t)n, sizeof *cats, by_row_order);
    const char* row[SP_KIOSK_ROW_MAX];
    int c = 0;
    for (; c < n && k->icon_count < SP_KIOSK_ROW_MAX; ++c) {
        part_icon* ic = &k->icons[k->icon_count];
        sp_character ch = {0};
        int a = 0;
        if (kiosk_load_category_part(db, cats[c], &ch, &a, &err) != SP_OK) {
            sp_kiosk_log("parts row: %s", err.text);
            free(k->row_source); // read again at the next change: the failure may pass (busy, memory)
            k->row_source = NULL;
            continue;
        }
        int cap = 0;
        ic->n = kiosk_outline(&ch.rig, a, ch.pose, &ch.camera, &ic->xy, &cap, ic->breaks, 8, &ic->break_n);
        sp_character_free(&ch);
        normalise(ic);
        snprintf(ic->category, sizeof ic->category, "%s", cats[c]);
        row[k->icon_count++] = ic->category;
    }
    if (c < n) left_out(k, cats, c, n);
    sp_db_free_strings(cats, n);
    sp_db_close(db);
    sp_kiosk_ui_set_parts(k->ui, row, k->icon_count);
}

void kiosk_row_draw(sp_kiosk* k, const float navy[4], const float yellow[4], const float ink[4], const float green[4])
{
    const sp_kiosk_ui* ui = k->ui;
    for (int i = 0; i < k->icon_count; ++i) {
        sp_kiosk_target t = (sp_kiosk_target)(SP_KT_PART1 + i);
        if (!sp_kiosk_ui_target_visible(ui, t)) continue;
        const sp_kiosk_rect* r = &ui->target[t];
        bool pressed = ui->pressed == t && ui->capture == SP_KCAP_TARGET;
        float rad = 0.16f * fminf(r->w, r->h);
        // The part's own category, when the row is open for it, is drawn as chosen.
        sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, 0,
                       pressed                             ? yellow
                       : sp_kiosk_ui_target_current(ui, t) ? green
                                                           : navy);
        sp_draw2d_rect(k->d2, r->x, r->y, r->w, r->h, rad, fmaxf(1.5f, 0.025f * r->h), (const float[4]){1, 1, 1, 0.9f});
        // The outline in the upper part, its name under it.
        const part_icon* ic = &k->icons[i];
        float box = fminf(0.62f * r->h, 0.8f * r->w), x0 = r->x + 0.5f * (r->w - box), y0 = r->y + 0.07f * r->h;
        float lw = fmaxf(2.0f, 0.035f * r->h), pts[2 * 256];
        int start = 0;
        for (int b = 0; b <= ic->break_n; ++b) {
            int end = b < ic->break_n ? ic->breaks[b] : ic->n;
            // At most 256 points a curve: thinned evenly (an icon needs no more).
            int m = end - start < 256 ? end - start : 256;
            for (int q = 0; q < m; ++q) {
                int s = start + (m > 1 ? (int)((long)q * (end - start - 1) / (m - 1)) : 0);
                pts[2 * q] = x0 + box * ic->xy[2 * s], pts[2 * q + 1] = y0 + box * ic->xy[2 * s + 1];
            }
            if (m > 1) sp_draw2d_polyline(k->d2, pts, m, false, lw, pressed ? ink : yellow);
            start = end;
        }
        char name[SP_KIOSK_NAME_MAX];
        sp_kiosk_ui_target_text(ui, t, name, sizeof name);
        sp_draw2d_text_fit(k->d2, name, r->x + 0.5f * r->w, r->y + 0.84f * r->h, 0.17f * r->h, 0.92f * r->w, SP_ALIGN_CENTER,
                           pressed ? ink : (const float[4]){1, 1, 1, 1});
    }
}
