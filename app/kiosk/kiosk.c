// kiosk.c: the kiosk's core: the UI's jobs against the pipeline, saving,
// the mesh cache, the canvas <-> framebuffer mapping.
#include "kiosk_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sp/kiosk_text.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "sp/clock.h"

static void forget_strokes(sp_kiosk* k);
static void replaced_free(replaced_part* u);

// ------------------------------------------------------------------ mapping

static double fit_factor(const sp_kiosk* k)
{
    return fmin((double)k->fb_w / k->canvas_w, (double)k->fb_h / k->canvas_h);
}

sp_vec2 kiosk_canvas_to_fb(const sp_kiosk* k, sp_vec2 c)
{
    double f = fit_factor(k);
    return (sp_vec2){0.5 * k->fb_w + (c.x - 0.5 * k->canvas_w) * f, 0.5 * k->fb_h + (c.y - 0.5 * k->canvas_h) * f};
}

sp_vec2 kiosk_fb_to_canvas(const sp_kiosk* k, sp_vec2 p)
{
    double f = fit_factor(k);
    return (sp_vec2){0.5 * k->canvas_w + (p.x - 0.5 * k->fb_w) / f, 0.5 * k->canvas_h + (p.y - 0.5 * k->fb_h) / f};
}

sp_camera kiosk_fb_camera(const sp_kiosk* k)
{
    return sp_camera_resize(&k->canvas_cam, k->fb_w, k->fb_h);
}

int kiosk_fitted_outline(const sp_dragon_part* p, float** out, int* cap, int* breaks, int max_breaks, int* nbreaks)
{
    // The abstraction at the fitted parameters, seen in the part's own view:
    // exactly what the solver matched to the stroke (before any attachment).
    return kiosk_outline(&p->character->rig, p->abstraction, p->params, &p->view, out, cap, breaks, max_breaks, nbreaks);
}

int kiosk_outline(const sp_rig* rig, int abstraction, const double* params, const sp_camera* view, float** out, int* cap,
                  int* breaks, int max_breaks, int* nbreaks)
{
    *nbreaks = 0;
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return 0;
    const sp_abstraction* ab = &rig->abstractions[abstraction];
    int need = ab->point_count + ab->curve_count;
    if (need > *cap) {
        float* o = realloc(*out, sizeof(float) * 2 * (size_t)need);
        if (!o) return 0;
        *out = o, *cap = need;
    }
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    double* z = malloc(sizeof(double) * 3 * (size_t)(ab->point_count + 1));
    double* mesh = ab->rest ? NULL : malloc(sizeof(double) * 3 * (size_t)(rig->vertex_count + 1));
    int n = 0;
    if (ev && z && (ab->rest || mesh)) {
        sp_rig_eval_update(ev, params, false);
        if (mesh) sp_rig_eval_points(ev, sp_rig_mesh_points(rig), mesh);
        sp_rig_eval_abstraction(ev, ab, mesh, z);
        for (int c = 0; c < ab->curve_count; ++c) {
            const sp_curve* cv = &ab->curves[c];
            if (cv->point_count <= 0) continue;
            if (n > 0 && *nbreaks < max_breaks) breaks[(*nbreaks)++] = n;
            for (int j = 0; j <= cv->point_count; ++j) {
                if (j == cv->point_count && !cv->closed) break;
                int q = cv->first_point + (j % cv->point_count);
                sp_vec2 px = sp_camera_project(view, (sp_vec3){z[3 * q], z[3 * q + 1], z[3 * q + 2]});
                (*out)[2 * n] = (float)px.x, (*out)[2 * n + 1] = (float)px.y;
                ++n;
            }
        }
    }
    free(mesh);
    free(z);
    sp_rig_eval_destroy(ev);
    return n;
}

// ------------------------------------------------------------------ meshes

sp_render_mesh* mesh_cache_get(const mesh_cache* c, uint64_t id)
{
    for (int i = 0; i < c->count; ++i)
        if (c->items[i].id == id) return c->items[i].mesh;
    return NULL;
}

// Display triangles for a part (0: all): one per LOD_PX_PER_TRIANGLE px^2 of
// its box on the canvas, LOD_MIN_TRIANGLES to c->lod_triangles. Why by
// size: llvmpipe pays per triangle (and per fragment: what a part costs
// beyond its triangles), and a small part needs fewer triangles than a big
// one to look the same.
#define LOD_PX_PER_TRIANGLE 16.0
#define LOD_MIN_TRIANGLES 400
static int lod_budget(const mesh_cache* c, const sp_dragon* d, const double* xyz, int n)
{
    if (c->lod_triangles <= 0) return 0;
    sp_vec3 lo, hi;
    sp_bounds(xyz, n, &lo, &hi);
    sp_camera cam = sp_dragon_camera(d);
    sp_vec2 a = sp_camera_project(&cam, lo), b = sp_camera_project(&cam, hi);
    double area = fabs((b.x - a.x) * (b.y - a.y)), want = area / LOD_PX_PER_TRIANGLE;
    if (!(want < c->lod_triangles)) return c->lod_triangles;
    return want > LOD_MIN_TRIANGLES ? (int)want : LOD_MIN_TRIANGLES;
}

void mesh_cache_sync(mesh_cache* c, sp_renderer* r, const sp_dragon* d, bool update_positions)
{
    for (int i = 0; i < c->count; ++i)
        c->items[i].seen = false;
    int n = d ? sp_dragon_part_count(d) : 0;
    for (int i = 0; i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        const sp_rig* rig = &p->character->rig;
        const double* xyz = sp_dragon_part_xyz(d, i);
        if (!xyz || rig->vertex_count <= 0 || rig->triangle_count <= 0) continue;
        int at = -1;
        for (int j = 0; j < c->count; ++j)
            if (c->items[j].id == p->id && c->items[j].character == p->character) at = j;
        if (at >= 0) {
            struct cached_mesh* it = &c->items[at];
            it->seen = true;
            if (update_positions) {
                if (it->coarse) {
                    sp_lod_positions(&it->lod, xyz, c->scratch);
                    sp_render_mesh_update(it->mesh, c->scratch, NULL);
                } else {
                    sp_render_mesh_update(it->mesh, xyz, NULL);
                }
            }
            continue;
        }
        if (c->count == c->cap) {
            int cap = c->cap ? 2 * c->cap : 16;
            struct cached_mesh* it = realloc(c->items, sizeof *it * (size_t)cap);
            if (!it) continue; // not drawn this frame; tried again next frame
            c->items = it, c->cap = cap;
        }
        sp_error err = {0};
        struct cached_mesh it = {p->id, p->character, NULL, true, false, {0}, rig->triangle_count};
        sp_mesh_desc md = {.vertex_count = rig->vertex_count,
                           .positions = xyz,
                           .colors = p->character->colors,
                           .triangle_count = rig->triangle_count,
                           .triangles = rig->triangles};
        int budget = lod_budget(c, d, xyz, rig->vertex_count);
        if (budget > 0 && rig->triangle_count > budget &&
            sp_lod_build(xyz, rig->vertex_count, rig->triangles, rig->triangle_count, p->character->colors, budget, &it.lod) ==
                SP_OK) {
            if (it.lod.cluster_count > c->scratch_cap) {
                double* s = realloc(c->scratch, sizeof(double) * 3 * (size_t)it.lod.cluster_count);
                if (s) c->scratch = s, c->scratch_cap = it.lod.cluster_count;
            }
            if (it.lod.cluster_count <= c->scratch_cap) {
                sp_lod_positions(&it.lod, xyz, c->scratch);
                md = (sp_mesh_desc){.vertex_count = it.lod.cluster_count,
                                    .positions = c->scratch,
                                    .colors = it.lod.colors,
                                    .triangle_count = it.lod.tri_count,
                                    .triangles = it.lod.tris};
                it.coarse = true;
                it.triangles = it.lod.tri_count;
            }
        }
        sp_render_mesh_create(r, &md, &it.mesh, &err);
        if (!it.mesh) {
            sp_kiosk_log("part %s: %s", p->name, err.text);
            sp_lod_free(&it.lod);
            continue;
        }
        c->items[c->count++] = it;
    }
    // Parts that are gone (undo, clear, redraw) or changed free their meshes.
    int w = 0;
    for (int i = 0; i < c->count; ++i) {
        if (c->items[i].seen) {
            c->items[w++] = c->items[i];
        } else {
            sp_render_mesh_destroy(c->items[i].mesh);
            sp_lod_free(&c->items[i].lod);
        }
    }
    c->count = w;
}

int mesh_cache_triangles(const mesh_cache* c)
{
    int n = 0;
    for (int i = 0; i < c->count; ++i)
        n += c->items[i].triangles;
    return n;
}

void mesh_cache_free(mesh_cache* c)
{
    for (int i = 0; i < c->count; ++i) {
        sp_render_mesh_destroy(c->items[i].mesh);
        sp_lod_free(&c->items[i].lod);
    }
    free(c->items);
    free(c->scratch);
    memset(c, 0, sizeof *c);
}

// ------------------------------------------------------------------ create

sp_kiosk* sp_kiosk_create(const sp_kiosk_desc* desc, sp_error* err)
{
    sp_kiosk* k = calloc(1, sizeof *k);
    if (!k) {
        sp_fail(err, SP_ERR_NO_MEMORY, "kiosk: out of memory");
        return NULL;
    }
    k->desc = desc ? *desc : (sp_kiosk_desc){0};
    snprintf(k->db_path, sizeof k->db_path, "%s", k->desc.db_path ? k->desc.db_path : sp_db_default_path());
    snprintf(k->export_dir, sizeof k->export_dir, "%s", k->desc.export_dir ? k->desc.export_dir : "dragon-exports");
    k->desc.db_path = k->db_path;
    k->desc.export_dir = k->export_dir;
    k->canvas_w = k->desc.canvas_w > 0 ? k->desc.canvas_w : 1280;
    k->canvas_h = k->desc.canvas_h > 0 ? k->desc.canvas_h : 800;
    k->fb_w = k->canvas_w, k->fb_h = k->canvas_h;
    k->code_state = k->desc.code_seed ? k->desc.code_seed : 1;
    kiosk_prune_saves(k);
    for (int i = 0; i < DEMO_MAX; ++i)
        k->demo_parts[i].part = -1;
    if (!(k->font = sp_font_load(k->desc.font_path, err))) goto fail;
    if (sp_kiosk_ui_create(&k->desc.ui, &k->ui, err) != SP_OK) goto fail;
    // The collector's writable handle first: opening it migrates an older
    // schema, which the pipeline's read-only handle could not read. A
    // database that does not exist yet is built by the pipeline.
    double collect_reserve = k->desc.collect_reserve_mb == 0 ? SP_KIOSK_COLLECT_RESERVE_MB : k->desc.collect_reserve_mb;
    if (!k->desc.no_collect && access(k->db_path, F_OK) == 0)
        k->collector = kiosk_collector_open(k->db_path, k->canvas_w, k->canvas_h, collect_reserve);
    // The pipeline's own attachment (docs/DESIGN.md, "Which strokes join a
    // dragon"): a part drawn far from every body stays where it was drawn.
    if (sp_dragon_create(&(sp_dragon_desc){.db_path = k->db_path,
                                           .assets_dir = k->desc.assets_dir,
                                           .canvas_w = k->canvas_w,
                                           .canvas_h = k->canvas_h,
                                           .solve = {.time_cap_ms = k->desc.fit_time_cap_ms},
                                           .max_parts = k->desc.max_parts,
                                           .background_model = true},
                         &k->dragon, err) != SP_OK)
        goto fail;
    if (!k->desc.no_collect && !k->collector)
        k->collector = kiosk_collector_open(k->db_path, k->canvas_w, k->canvas_h, collect_reserve);
    k->canvas_cam = sp_dragon_camera(k->dragon);
    if (sp_renderer_create(&(sp_renderer_desc){0}, &k->r, err) != SP_OK) goto fail;
    // Software rasterisers pay per triangle: coarser display meshes there.
    const char* gl_name = (const char*)glGetString(GL_RENDERER);
    k->software = gl_name && (strstr(gl_name, "llvmpipe") || strstr(gl_name, "softpipe") || strstr(gl_name, "swrast") ||
                              strstr(gl_name, "SWR"));
    int lod = k->desc.lod_triangles < 0 ? 0 : k->desc.lod_triangles > 0 ? k->desc.lod_triangles : k->software ? 4000 : 0;
    k->meshes.lod_triangles = k->demo_meshes.lod_triangles = lod;
    if (!(k->d2 = sp_draw2d_create(k->font, err))) goto fail;
    sp_kiosk_resize(k, k->canvas_w, k->canvas_h, 0);
    return k;
fail:
    sp_kiosk_destroy(k);
    return NULL;
}

void sp_kiosk_destroy(sp_kiosk* k)
{
    if (!k) return;
    sp_kiosk_close_collection(k);
    forget_strokes(k);
    kiosk_attract_free(k);
    kiosk_row_free(k);
    mesh_cache_free(&k->meshes);
    sp_draw2d_destroy(k->d2);
    sp_renderer_destroy(k->r);
    sp_dragon_destroy(k->dragon);
    sp_kiosk_ui_destroy(k->ui);
    sp_font_free(k->font);
    free(k->guesses);
    free(k->scratch);
    free(k->outline_px);
    free(k->scene_px);
    free(k);
}

void sp_kiosk_resize(sp_kiosk* k, int fb_w, int fb_h, double px_per_mm)
{
    k->fb_w = fb_w > 0 ? fb_w : 1;
    k->fb_h = fb_h > 0 ? fb_h : 1;
    if (px_per_mm > 0) k->ppm = px_per_mm;
    sp_kiosk_ui_resize(k->ui, k->fb_w, k->fb_h, k->ppm);
    k->ppm = k->ui->px_per_mm;
    // The drawing area in canvas pixels: a window turned or resized after the
    // start shows the canvas scaled into it, and the area then reaches
    // beyond the canvas (strokes there were clamped onto its edge and their
    // parts fitted flat; an outside review). Every area of the run: a part
    // drawn beyond the canvas is fitted again from its stroke (a chip, Undo)
    // after the window has turned back (a second review).
    const sp_kiosk_rect* c = &k->ui->canvas;
    sp_vec2 lo = kiosk_fb_to_canvas(k, (sp_vec2){c->x, c->y}), hi = kiosk_fb_to_canvas(k, (sp_vec2){c->x + c->w, c->y + c->h});
    double* a = k->area;
    bool first = !(a[2] > a[0]);
    a[0] = fmin(first ? 0 : a[0], lo.x), a[1] = fmin(first ? 0 : a[1], lo.y);
    a[2] = fmax(first ? k->canvas_w : a[2], hi.x), a[3] = fmax(first ? k->canvas_h : a[3], hi.y);
    if (k->dragon) sp_dragon_set_stroke_area(k->dragon, a[0], a[1], a[2], a[3]);
}

void sp_kiosk_input(sp_kiosk* k, const sp_kiosk_event* ev)
{
    sp_kiosk_ui_event(k->ui, ev);
}

const sp_kiosk_ui* sp_kiosk_ui_of(const sp_kiosk* k)
{
    return k->ui;
}

const sp_kiosk_stats* sp_kiosk_stats_of(const sp_kiosk* k)
{
    return &k->stats;
}

void sp_kiosk_collect_counts(const sp_kiosk* k, int* stored, int* dropped)
{
    if (k->collector)
        kiosk_collector_counts(k->collector, stored, dropped);
    else
        *stored = k->collect_stored, *dropped = k->collect_dropped;
}

const sp_dragon* sp_kiosk_dragon(const sp_kiosk* k)
{
    return k->dragon;
}

const char* sp_kiosk_last_save(const sp_kiosk* k)
{
    return k->last_save;
}

// ------------------------------------------------------------------ guesses per part

static part_guesses* guesses_of(sp_kiosk* k, uint64_t id, bool create)
{
    for (int i = 0; i < k->guess_count; ++i)
        if (k->guesses[i].id == id) return &k->guesses[i];
    if (!create) return NULL;
    // Forget parts that are gone first: the list stays as long as the dragon.
    int w = 0;
    for (int i = 0; i < k->guess_count; ++i) {
        bool alive = false;
        for (int j = 0; j < sp_dragon_part_count(k->dragon) && !alive; ++j)
            alive = sp_dragon_part_get(k->dragon, j)->id == k->guesses[i].id;
        if (alive)
            k->guesses[w++] = k->guesses[i];
        else
            free(k->guesses[i].xy), free(k->guesses[i].t); // undone or redrawn: never collected
    }
    k->guess_count = w;
    if (k->guess_count == k->guess_cap) {
        int cap = k->guess_cap ? 2 * k->guess_cap : 16;
        part_guesses* g = realloc(k->guesses, sizeof *g * (size_t)cap);
        if (!g) return NULL;
        k->guesses = g, k->guess_cap = cap;
    }
    part_guesses* g = &k->guesses[k->guess_count++];
    memset(g, 0, sizeof *g);
    g->id = id;
    return g;
}

// Forgets every part's chips and kept stroke.
static void forget_strokes(sp_kiosk* k)
{
    for (int i = 0; i < k->guess_count; ++i)
        free(k->guesses[i].xy), free(k->guesses[i].t);
    k->guess_count = 0;
    for (int i = 0; i < k->replaced_n; ++i)
        replaced_free(&k->replaced[i]);
    k->replaced_n = 0;
}

// Keeps an accepted part's stroke for collection (canvas pixels; ms since
// its first point): only when collecting, and only the points and times.
static void keep_stroke(sp_kiosk* k, int part, const sp_vec2* xy, const double* t, int n)
{
    if (!k->collector || part < 0 || part >= sp_dragon_part_count(k->dragon) || n < 2) return;
    part_guesses* g = guesses_of(k, sp_dragon_part_get(k->dragon, part)->id, false);
    if (!g) return;
    free(g->xy), free(g->t);
    g->xy = malloc(sizeof *g->xy * (size_t)n);
    g->t = t ? malloc(sizeof *g->t * (size_t)n) : NULL;
    if (!g->xy || (t && !g->t)) {
        free(g->xy), free(g->t);
        g->xy = NULL, g->t = NULL, g->n = 0;
        return;
    }
    memcpy(g->xy, xy, sizeof *g->xy * (size_t)n);
    for (int i = 0; t && i < n; ++i)
        g->t[i] = t[i] - t[0];
    g->n = n;
}

static bool has_body(const sp_dragon* d)
{
    for (int i = 0; i < sp_dragon_part_count(d); ++i)
        if (sp_dragon_part_get(d, i)->is_torso) return true;
    return false;
}

// Where the parts are on the screen (their strokes), for the chips to keep
// clear of: told to the UI before it lays them out.
static void tell_scene(sp_kiosk* k)
{
    int total = 0, n = sp_dragon_part_count(k->dragon);
    for (int i = 0; i < n; ++i)
        total += sp_dragon_part_get(k->dragon, i)->stroke_points;
    if (total > k->scene_cap) {
        float* p = realloc(k->scene_px, sizeof *p * 2 * (size_t)total);
        if (!p) total = 0;
        if (p) k->scene_px = p, k->scene_cap = total;
    }
    int m = 0;
    for (int i = 0; i < n && m < total; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(k->dragon, i);
        for (int j = 0; j < p->stroke_points && m < total; ++j, ++m) {
            sp_vec2 q = kiosk_canvas_to_fb(k, p->stroke_xy[j]);
            k->scene_px[2 * m] = (float)q.x, k->scene_px[2 * m + 1] = (float)q.y;
        }
    }
    sp_kiosk_ui_set_scene(k->ui, k->scene_px, m);
}

// The label chip and the next two guesses of the last part, for the UI.
static void last_label(sp_kiosk* k, sp_kiosk_part_label* l)
{
    *l = (sp_kiosk_part_label){0};
    int n = sp_dragon_part_count(k->dragon);
    if (n == 0) return;
    const sp_dragon_part* p = sp_dragon_part_get(k->dragon, n - 1);
    l->category = p->category;
    l->waiting = !p->is_torso && !has_body(k->dragon);
    const part_guesses* g = guesses_of(k, p->id, false);
    if (g) l->guesses[0] = g->guess[0], l->guesses[1] = g->guess[1];
}

// ------------------------------------------------------------------ jobs

static sp_kiosk_refusal refusal_of(sp_dragon_reject r)
{
    switch (r) {
    case SP_DRAGON_TOO_SHORT:
        return SP_KREF_TOO_SMALL;
    case SP_DRAGON_NO_PART:
    case SP_DRAGON_NOTHING_TO_REFIT:
        return SP_KREF_NOT_READY;
    case SP_DRAGON_FIT_FAILED:
        return SP_KREF_TRICKY;
    case SP_DRAGON_FULL:
        return SP_KREF_FULL;
    case SP_DRAGON_DETAIL:
        return SP_KREF_DETAIL;
    default:
        return SP_KREF_UNRECOGNISED;
    }
}

// What to tell about an accepted part (NULL: nothing).
static const char* note_hint(sp_dragon_note n)
{
    return n == SP_DRAGON_NOTE_NO_SURFACE ? sp_kiosk_text(SP_KTEXT_NO_SURFACE) : NULL;
}

// The chips' guesses for a stroke: the classifier's ranked categories that
// have a part but `skip` (the part it became, or the one that did not fit),
// then, as a sure classifier votes for few categories, the model's others in
// the parts row's order, so that the visitor always has `want` to choose from.
static int stroke_guesses(const sp_kiosk* k, const sp_dragon_result* res, const char* skip, char out[][SP_NAME_MAX], int want)
{
    int n = 0;
    for (int i = 0; i < res->guess_count && n < want; ++i)
        if ((!skip || strcmp(res->guesses[i].category, skip) != 0) && sp_dragon_has_part(k->dragon, res->guesses[i].category))
            snprintf(out[n++], SP_NAME_MAX, "%s", res->guesses[i].category);
    const sp_clf* clf = sp_dragon_model(k->dragon);
    while (clf && n < want) {
        const char* next = NULL;
        for (int c = 0; c < sp_clf_category_count(clf); ++c) {
            const char* name = sp_clf_category(clf, c);
            bool used = (skip && !strcmp(name, skip)) || !sp_dragon_has_part(k->dragon, name);
            for (int q = 0; q < n; ++q)
                used = used || !strcmp(name, out[q]);
            if (!used && (!next || sp_kiosk_part_order(name) < sp_kiosk_part_order(next))) next = name;
        }
        if (!next) break;
        snprintf(out[n++], SP_NAME_MAX, "%s", next);
    }
    return n;
}

// A refused stroke: why, and what it could still become. Its chips are the
// classifier's best guesses (the visitor picks one, or a part from the row);
// a category that was tried and did not fit is not offered again. Strokes too
// small for a part, a full dragon and a failing pipeline offer nothing.
static void answer_refusal(sp_kiosk* k, sp_result rc, const sp_dragon_result* res, const char* tried)
{
    ++k->stats.rejected;
    if (rc == SP_OK && res->reason == SP_DRAGON_NO_PART && sp_dragon_part_error(k->dragon)[0])
        sp_kiosk_log("no part to make of that stroke: %s", sp_dragon_part_error(k->dragon));
    sp_kiosk_fit_result r = {.ok = false,
                             .refusal = rc == SP_OK ? refusal_of(res->reason) : SP_KREF_UNRECOGNISED,
                             .part_count = sp_dragon_part_count(k->dragon)};
    r.kept = rc == SP_OK && res->reason == SP_DRAGON_DETAIL && res->detail >= 0;
    r.offer = rc == SP_OK && (res->reason == SP_DRAGON_UNRECOGNISED || res->reason == SP_DRAGON_NO_MODEL ||
                              res->reason == SP_DRAGON_FIT_FAILED || res->reason == SP_DRAGON_DETAIL);
    if (res->reason == SP_DRAGON_FIT_FAILED && !tried && res->guess_count > 0) tried = res->guesses[0].category;
    char offers[3][SP_NAME_MAX];
    int n = r.offer ? stroke_guesses(k, res, tried, offers, 3) : 0;
    for (int i = 0; i < n; ++i)
        r.offers[i] = offers[i];
    tell_scene(k);
    sp_kiosk_ui_fit_done(k->ui, &r);
}

// forced: the category the visitor chose for a refused stroke (NULL: classified).
static void answer_fit(sp_kiosk* k, sp_result rc, const sp_dragon_result* res, const sp_error* err, bool refit,
                       const char* forced)
{
    if (rc != SP_OK || res->rejected || res->part < 0 || res->part >= sp_dragon_part_count(k->dragon)) {
        if (rc != SP_OK) {
            ++k->stats.pipeline_errors;
            sp_kiosk_log("%s", err->text);
        }
        answer_refusal(k, rc, res, forced);
        return;
    }
    ++k->rev;
    const sp_dragon_part* p = sp_dragon_part_get(k->dragon, res->part);
    // The chips: the fitted category, then the classifier's next guesses.
    part_guesses* g = guesses_of(k, p->id, true);
    if (g) {
        g->chosen = refit || forced;
        stroke_guesses(k, res, p->category, g->guess, 2);
    }
    // The outline as fitted, in yellow over the stroke.
    int nb = 0;
    int n = kiosk_fitted_outline(p, &k->outline_px, &k->outline_cap, k->breaks, 64, &nb);
    for (int i = 0; i < n; ++i) {
        sp_vec2 q = kiosk_canvas_to_fb(k, (sp_vec2){k->outline_px[2 * i], k->outline_px[2 * i + 1]});
        k->outline_px[2 * i] = (float)q.x, k->outline_px[2 * i + 1] = (float)q.y;
    }
    if (p->stroke_points > k->scratch_cap) {
        sp_vec2* s = realloc(k->scratch, sizeof *s * (size_t)p->stroke_points);
        if (s) k->scratch = s, k->scratch_cap = p->stroke_points;
    }
    float* stroke = NULL;
    int sn = 0;
    if (refit && p->stroke_points <= k->scratch_cap) {
        // The part's stored stroke, in fb pixels (packed as floats in the scratch buffer).
        stroke = (float*)k->scratch;
        for (int i = 0; i < p->stroke_points; ++i) {
            sp_vec2 q = kiosk_canvas_to_fb(k, p->stroke_xy[i]);
            stroke[2 * i] = (float)q.x, stroke[2 * i + 1] = (float)q.y;
        }
        sn = p->stroke_points;
    }
    // A part drawn before any body waits where it was drawn; the visitor is told to draw one.
    bool waiting = !p->is_torso && !has_body(k->dragon);
    k->stats.waiting += waiting;
    tell_scene(k);
    sp_kiosk_ui_fit_done(k->ui, &(sp_kiosk_fit_result){.ok = true,
                                                       .hint = note_hint(res->note),
                                                       .waiting = waiting,
                                                       .category = p->category,
                                                       .guesses = {g ? g->guess[0] : NULL, g ? g->guess[1] : NULL},
                                                       .part_count = sp_dragon_part_count(k->dragon),
                                                       .outline = k->outline_px,
                                                       .outline_count = n,
                                                       .outline_breaks = k->breaks,
                                                       .outline_break_count = nb,
                                                       .stroke = stroke,
                                                       .stroke_count = sn});
    if (refit)
        ++k->stats.refits;
    else
        ++k->stats.parts_added;
    if (forced) ++k->stats.chosen;
}

// What the last part is, for Undo of what replaces it: with a Redraw's
// new stroke, also its own stroke and the stroke kept for its collection
// (moved out of its chips' record).
static replaced_part describe_last(sp_kiosk* k, bool redraw)
{
    replaced_part u = {0};
    int n = sp_dragon_part_count(k->dragon);
    if (n == 0) return u;
    const sp_dragon_part* last = sp_dragon_part_get(k->dragon, n - 1);
    part_guesses* g = guesses_of(k, last->id, false);
    u.replaced = last->id;
    snprintf(u.category, sizeof u.category, "%s", last->category);
    u.chosen = g && g->chosen;
    for (int i = 0; g && i < 2; ++i)
        snprintf(u.guess[i], sizeof u.guess[i], "%s", g->guess[i]);
    if (redraw && (u.stroke = malloc(sizeof *u.stroke * (size_t)(last->stroke_points + 1)))) {
        memcpy(u.stroke, last->stroke_xy, sizeof *u.stroke * (size_t)last->stroke_points);
        u.stroke_n = last->stroke_points;
        if (g) u.kept = *g, g->xy = NULL, g->t = NULL, g->n = 0;
    }
    return u;
}

static void replaced_free(replaced_part* u)
{
    free(u->stroke), free(u->kept.xy), free(u->kept.t);
    *u = (replaced_part){0};
}

// Keeps u (taking its buffers) for Undo; the oldest goes when full.
static void replaced_push(sp_kiosk* k, replaced_part* u)
{
    if (k->replaced_n == KIOSK_REPLACED_MAX) {
        replaced_free(&k->replaced[0]);
        memmove(&k->replaced[0], &k->replaced[1], sizeof *u * --k->replaced_n);
    }
    k->replaced[k->replaced_n++] = *u;
    *u = (replaced_part){0};
}

static void run_fit(sp_kiosk* k, const sp_kiosk_job* j)
{
    const sp_kiosk_line* s = j->stroke;
    const char* forced = j->category[0] ? j->category : NULL;
    if (!forced) ++k->stats.strokes; // a chosen part is the same stroke again
    if (s->count > k->scratch_cap) {
        sp_vec2* p = realloc(k->scratch, sizeof *p * (size_t)s->count);
        if (!p) {
            sp_kiosk_ui_fit_done(k->ui, &(sp_kiosk_fit_result){.ok = false, .part_count = sp_dragon_part_count(k->dragon)});
            return;
        }
        k->scratch = p, k->scratch_cap = s->count;
    }
    for (int i = 0; i < s->count; ++i)
        k->scratch[i] = kiosk_fb_to_canvas(k, (sp_vec2){s->xy[2 * i], s->xy[2 * i + 1]});
    sp_dragon_result res;
    memset(&res, 0, sizeof res);
    sp_error err = {0};
    double t0 = sp_now_ms();
    // The stroke continues the last one: what its first piece made goes first (the UI's join).
    if (j->undo_first && sp_dragon_undo(k->dragon)) ++k->rev;
    // A Redraw: what the part it replaces was, for Undo.
    replaced_part u = j->replace && !j->undo_first ? describe_last(k, true) : (replaced_part){0};
    sp_result rc = sp_dragon_add_points(
        k->dragon, k->scratch, s->count,
        &(sp_dragon_stroke_opts){.category = forced, .replace_last = j->replace, .replace_detail = j->replace_detail}, &res,
        &err);
    double ms = sp_now_ms() - t0;
    k->stats.last_fit_ms = ms;
    k->stats.fit_ms[k->stats.fit_count++ % 4096] = ms;
    answer_fit(k, rc, &res, &err, false, forced);
    if (rc == SP_OK && !res.rejected) keep_stroke(k, res.part, k->scratch, s->t, s->count);
    bool made = rc == SP_OK && !res.rejected && res.part >= 0 && res.part < sp_dragon_part_count(k->dragon);
    if (u.replaced && made && (u.by = sp_dragon_part_get(k->dragon, res.part)->id) != u.replaced) {
        replaced_push(k, &u);
    } else if (u.replaced) { // refused: the part stays, with its kept stroke
        part_guesses* g = guesses_of(k, u.replaced, false);
        if (g && !g->xy) g->xy = u.kept.xy, g->t = u.kept.t, g->n = u.kept.n, u.kept = (part_guesses){0};
        replaced_free(&u);
    }
    if (rc == SP_OK && res.reason == SP_DRAGON_DETAIL && res.detail >= 0) ++k->rev; // new ink to pose
}

// The last part fitted again as `category` (NULL: as the classifier takes
// the stroke), from its own stroke or from `xy` (n points: the stroke of
// the part a Redraw replaced), forced or not. From its own stroke the
// stroke kept for collection moves to the new part (or back, when the fit
// fails and the part stays); from another, it goes with the part. True
// when the part was replaced; *new_id is the new part's id.
static bool refit_last(sp_kiosk* k, const char* category, const sp_vec2* xy, int n, bool answer, sp_dragon_result* res,
                       uint64_t* new_id)
{
    int count = sp_dragon_part_count(k->dragon);
    if (count == 0) return false;
    const sp_dragon_part* last = sp_dragon_part_get(k->dragon, count - 1);
    uint64_t old_id = last->id;
    part_guesses* old = guesses_of(k, old_id, false);
    part_guesses kept = {0};
    if (old) kept.xy = old->xy, kept.t = old->t, kept.n = old->n, old->xy = NULL, old->t = NULL, old->n = 0;
    memset(res, 0, sizeof *res);
    sp_error err = {0};
    sp_result rc = xy ? sp_dragon_add_points(k->dragon, xy, n,
                                             &(sp_dragon_stroke_opts){.category = category, .replace_last = true}, res, &err)
                      : sp_dragon_refit_last(k->dragon, category, res, &err);
    if (answer) answer_fit(k, rc, res, &err, true, NULL);
    bool moved = rc == SP_OK && !res->rejected && res->part >= 0 && res->part < sp_dragon_part_count(k->dragon);
    *new_id = moved ? sp_dragon_part_get(k->dragon, res->part)->id : old_id;
    part_guesses* to = guesses_of(k, *new_id, !answer && moved);
    if (to && !to->xy && !(xy && moved))
        to->xy = kept.xy, to->t = kept.t, to->n = kept.n;
    else
        free(kept.xy), free(kept.t);
    return moved;
}

static void run_refit(sp_kiosk* k, const sp_kiosk_job* j)
{
    replaced_part u = describe_last(k, false); // for Undo
    sp_dragon_result res;
    if (refit_last(k, j->category, NULL, 0, true, &res, &u.by) && u.replaced) replaced_push(k, &u);
}

// Undo right after a chip or a Redraw: the part it replaced comes back,
// fitted again from its stroke as it was (its chip's category, or the
// classifier's answer), with its chips. A parent who tapped the wrong chip
// on the body lost the body, and every part came loose (an outside
// review). False when the last change is not one (a part drawn since, ink).
static bool undo_replace(sp_kiosk* k)
{
    int n = sp_dragon_part_count(k->dragon), nd = sp_dragon_detail_count(k->dragon);
    if (n == 0 || k->replaced_n == 0) return false;
    replaced_part* top = &k->replaced[k->replaced_n - 1];
    uint64_t last = sp_dragon_part_get(k->dragon, n - 1)->id;
    sp_dragon_detail dd;
    if (top->by != last || (nd > 0 && sp_dragon_detail_get(k->dragon, nd - 1, &dd) && dd.id > last)) return false;
    replaced_part u = *top;
    --k->replaced_n;
    sp_dragon_result res;
    uint64_t id;
    if (!refit_last(k, u.chosen ? u.category : NULL, u.stroke, u.stroke_n, false, &res, &id)) {
        replaced_free(&u);
        return false;
    }
    part_guesses* g = guesses_of(k, id, true);
    if (g) {
        g->chosen = u.chosen;
        memcpy(g->guess, u.guess, sizeof g->guess);
        if (u.stroke && !g->xy) g->xy = u.kept.xy, g->t = u.kept.t, g->n = u.kept.n, u.kept = (part_guesses){0};
    }
    for (int i = 0; i < k->replaced_n; ++i) // one before it replaced this part, which has a new id
        if (k->replaced[i].by == u.replaced) k->replaced[i].by = id;
    replaced_free(&u);
    return true;
}

// The parts on the canvas leave it (Start over, the idle timeout, the kiosk
// closing) with the labels the visitor left them with. This is where a
// part's label is final: Undo and Redraw took back the parts they removed
// (those never get here), and a chip changes a part only while its stroke
// is the last one. Each stroke goes to the collector (docs/DESIGN.md,
// "Collecting visitors' strokes").
static void collect_parts(sp_kiosk* k)
{
    for (int i = 0; k->collector && i < sp_dragon_part_count(k->dragon); ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(k->dragon, i);
        const part_guesses* g = guesses_of(k, p->id, false);
        if (g && g->n >= 2) {
            kiosk_collector_push(k->collector, p->category, g->xy, g->t, g->n);
            ++k->stats.collected;
        }
    }
}

// Start over or the idle timeout: the visit's parts are kept (counted) and collected.
static void parts_left(sp_kiosk* k)
{
    for (int i = 0; i < sp_dragon_part_count(k->dragon); ++i) {
        const part_guesses* g = guesses_of(k, sp_dragon_part_get(k->dragon, i)->id, false);
        ++k->stats.kept;
        if (g && g->chosen) ++k->stats.kept_chosen;
    }
    collect_parts(k);
}

void sp_kiosk_close_collection(sp_kiosk* k)
{
    if (!k->collector) return;
    if (k->dragon) collect_parts(k);
    kiosk_collector_close(k->collector, &k->collect_stored, &k->collect_dropped);
    k->collector = NULL;
}

static void run_job(sp_kiosk* k, const sp_kiosk_job* j)
{
    switch (j->kind) {
    case SP_KJOB_FIT:
        run_fit(k, j);
        break;
    case SP_KJOB_REFIT:
        run_refit(k, j);
        break;
    case SP_KJOB_UNDO: {
        if (undo_replace(k) || sp_dragon_undo(k->dragon)) ++k->rev, ++k->stats.undos;
        sp_kiosk_part_label l;
        last_label(k, &l);
        tell_scene(k);
        sp_kiosk_ui_parts_changed(k->ui, sp_dragon_part_count(k->dragon), &l);
        break;
    }
    case SP_KJOB_CLEAR:
        parts_left(k);
        sp_dragon_clear(k->dragon);
        ++k->rev, ++k->stats.clears;
        forget_strokes(k);
        tell_scene(k);
        sp_kiosk_ui_parts_changed(k->ui, 0, NULL);
        break;
    case SP_KJOB_SAVE:
        kiosk_run_save(k);
        break;
    default:
        break;
    }
}

// A lasting database problem (a damaged file renamed over it) fails every
// poll: the log says it once, again only when it changes, and when it ends.
static void kiosk_poll_database(sp_kiosk* k)
{
    sp_error err = {0};
    sp_result r = sp_dragon_reload_if_changed(k->dragon, NULL, &err);
    // A deleted file is still read through the open handles, so the poll
    // succeeds; said all the same (an outside review found nothing logged):
    // curators' changes no longer arrive, and a restart would build anew.
    struct stat st;
    if (r == SP_OK && stat(k->db_path, &st) != 0 && errno == ENOENT)
        r = sp_fail(&err, SP_ERR_IO,
                    "%s: the database file is gone (deleted or moved away); the parts and model loaded stay in use until a "
                    "database is there again",
                    k->db_path);
    if (r == SP_OK) {
        if (k->db_problem[0]) sp_kiosk_log("database: %s reads again", k->db_path);
        k->db_problem[0] = '\0';
    } else if (strcmp(err.text, k->db_problem) != 0) {
        sp_kiosk_log("database: %s", err.text);
        snprintf(k->db_problem, sizeof k->db_problem, "%s", err.text);
    }
}

void sp_kiosk_update(sp_kiosk* k, double t_ms)
{
    ++k->updates;
    sp_kiosk_ui_event(k->ui, &(sp_kiosk_event){SP_KEV_FRAME, t_ms, 0, 0, 0});
    k->heavy_done = false;
    sp_kiosk_job j;
    sp_kiosk_job_kind next;
    if (sp_kiosk_ui_peek_job(k->ui) != SP_KJOB_SAVE) k->save_shown = false; // a save dropped meanwhile (Start over)
    while (!k->heavy_done && (next = sp_kiosk_ui_peek_job(k->ui)) != SP_KJOB_NONE) {
        // A save stops the window for many frames (BENCHMARKS.md, "The dragon kiosk"):
        // one frame first, so that the tap shows ("Saving your dragon...").
        bool shown = k->save_shown;
        k->save_shown = next == SP_KJOB_SAVE && !shown;
        if (k->save_shown) break;
        if (!sp_kiosk_ui_next_job(k->ui, &j)) break;
        run_job(k, &j);
        k->heavy_done = j.heavy;
    }
    // A model read in the background since is used from the next stroke on.
    if (sp_dragon_model_update(k->dragon)) ++k->stats.models_loaded;
    // A curator's change (or a replaced database file) is picked up between
    // strokes; add_stroke polls too, this only keeps idle kiosks current.
    if (!k->heavy_done && k->ui->capture == SP_KCAP_NONE && t_ms - k->last_reload_check >= 2000) {
        k->last_reload_check = t_ms;
        kiosk_poll_database(k);
    }
    // A change either poll took in (a stroke's came first when it was drawn
    // right after the change): a curator may have changed the parts, so the
    // parts row is read again, in a frame of its own, and the parts loaded.
    uint64_t reloads = sp_dragon_reload_count(k->dragon);
    if (reloads != k->reloads_seen) {
        k->reloads_seen = reloads, ++k->stats.reloads, k->icons_loaded = k->parts_loaded = false, k->heavy_done = true;
        // The attract screen's demo follows a database file replaced by
        // another (its pipeline held the old one open); the row, changed parts.
        struct stat st;
        if (k->demo_prepared && !k->desc.no_attract_demo && stat(k->db_path, &st) == 0 &&
            (st.st_dev != k->demo_dev || st.st_ino != k->demo_ino))
            k->demo_stale = true;
    }
    // The parts row, once the first frame is on screen (starting fast matters more).
    if (!k->heavy_done && !k->icons_loaded && k->updates >= 2) {
        kiosk_row_load(k);
        k->heavy_done = true;
    }
    if (k->demo_stale) kiosk_attract_rebuild(k);
    // Then the parts, one a frame while no finger draws, so that a visit's
    // first strokes do not wait for loading theirs.
    if (!k->heavy_done && !k->parts_loaded && k->icons_loaded && k->ui->capture == SP_KCAP_NONE &&
        (k->demo_prepared || k->ui->mode != SP_KM_ATTRACT)) { // the attract screen's demo first: it is what shows
        sp_error err = {0};
        sp_dragon_preload_step(k->dragon, &k->parts_loaded, &err);
        if (err.text[0]) sp_kiosk_log("%s", err.text); // a part that does not load is skipped
        k->heavy_done = !k->parts_loaded;
    }
    if (k->ui->mode == SP_KM_ATTRACT) kiosk_attract_update(k);
    // Pose the dragon at the animation clock (only when something moves).
    double t = k->ui->anim_ms / 1000.0;
    if (!k->posed || k->posed_rev != k->rev || k->posed_t != t) {
        double t0 = sp_now_ms();
        sp_error err = {0};
        if (sp_dragon_pose_at(k->dragon, t, &err) == SP_OK) {
            mesh_cache_sync(&k->meshes, k->r, k->dragon, true);
            k->posed = true, k->posed_rev = k->rev, k->posed_t = t;
        } else {
            sp_kiosk_log("%s", err.text);
        }
        k->stats.pose_ms = sp_now_ms() - t0;
        k->stats.triangles = mesh_cache_triangles(&k->meshes);
    }
    k->stats.parts = sp_dragon_part_count(k->dragon);
}

void sp_kiosk_draw(sp_kiosk* k)
{
    kiosk_draw_frame(k, k->fb_w, k->fb_h);
}

sp_result sp_kiosk_screenshot(sp_kiosk* k, const char* path, sp_error* err)
{
    GLint bound = 0; // restored after: the caller's framebuffer need not be the window's
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    sp_render_target* t;
    sp_render_target_create(k->fb_w, k->fb_h, 0, &t, err);
    if (!t) return SP_ERR_INTERNAL;
    sp_render_target_bind(t);
    kiosk_draw_frame(k, k->fb_w, k->fb_h);
    sp_image img = {0};
    sp_result r = sp_render_target_read(t, &img, err);
    sp_render_target_destroy(t);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)bound);
    if (r == SP_OK) r = sp_image_write_png(&img, path, err);
    sp_image_free(&img);
    return r;
}

int sp_kiosk_loose_parts(sp_kiosk* k, int* bodies)
{
    int n = sp_dragon_part_count(k->dragon), loose = 0;
    *bodies = 0;
    sp_error err = {0};
    k->posed = false;
    sp_vec2* box = malloc(sizeof *box * 2 * (size_t)(n + 1));
    if (!box || n == 0 || sp_dragon_pose_at(k->dragon, k->ui->anim_ms / 1000.0, &err) != SP_OK) {
        free(box);
        return 0;
    }
    // Boxes in the drawing view (x, y of the world).
    for (int i = 0; i < n; ++i) {
        const double* xyz = sp_dragon_part_xyz(k->dragon, i);
        box[2 * i] = (sp_vec2){INFINITY, INFINITY}, box[2 * i + 1] = (sp_vec2){-INFINITY, -INFINITY};
        for (int v = 0; xyz && v < sp_dragon_part_get(k->dragon, i)->character->rig.vertex_count; ++v) {
            box[2 * i].x = fmin(box[2 * i].x, xyz[3 * v]), box[2 * i].y = fmin(box[2 * i].y, xyz[3 * v + 1]);
            box[2 * i + 1].x = fmax(box[2 * i + 1].x, xyz[3 * v]), box[2 * i + 1].y = fmax(box[2 * i + 1].y, xyz[3 * v + 1]);
        }
        *bodies += sp_dragon_part_get(k->dragon, i)->is_torso;
    }
    for (int i = 0; i < n; ++i) {
        if (sp_dragon_part_get(k->dragon, i)->is_torso) continue;
        bool joined = false;
        for (int j = 0; j < n && !joined; ++j) {
            if (!sp_dragon_part_get(k->dragon, j)->is_torso) continue;
            double m = 0.02 * sp_v2_len(sp_v2_sub(box[2 * j + 1], box[2 * j]));
            joined = box[2 * i].x <= box[2 * j + 1].x + m && box[2 * j].x - m <= box[2 * i + 1].x &&
                     box[2 * i].y <= box[2 * j + 1].y + m && box[2 * j].y - m <= box[2 * i + 1].y;
        }
        loose += !joined;
    }
    free(box);
    return loose;
}

sp_result sp_kiosk_export(sp_kiosk* k, const char* path, sp_error* err)
{
    if (sp_dragon_part_count(k->dragon) == 0)
        return sp_fail(err, SP_ERR_INVALID, "%s: nothing to export: the dragon has no parts", path);
    return sp_dragon_export(k->dragon, path, err);
}
