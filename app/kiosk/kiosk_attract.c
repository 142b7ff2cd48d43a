// kiosk_attract.c: the attract screen shows what to do: one line per part is
// drawn (blue, with a fingertip), its fitted outline flashes yellow, the 3D
// part appears; when the dragon is complete it comes alive (its animation
// plays), then it starts over. The demo dragon is a second pipeline fed with
// synthetic sketches of the database's own parts, so whatever parts a curator
// installs are the ones shown.
#include "kiosk_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sp/synth.h"

// Where each category goes in the demo's frame (fractions of its width and
// height) and its size (box diagonal, fraction of its height), in drawing
// order. The frame keeps the layout's own aspect (it was made on 1280 x 800),
// so the parts stay together on any screen: placed by the canvas's width and
// sized by its height, head and tail floated off the body on an ultrawide
// screen (an outside review).
static const struct {
    const char* category;
    double cx, cy, size;
} k_layout[] = {
    {"torso", 0.50, 0.55, 0.46},      {"head", 0.72, 0.40, 0.24},      {"wings", 0.50, 0.34, 0.34}, {"tail", 0.27, 0.58, 0.36},
    {"front_legs", 0.60, 0.74, 0.22}, {"hind_legs", 0.40, 0.74, 0.24}, {"legs", 0.50, 0.74, 0.22},
};
enum { LAYOUT_N = sizeof k_layout / sizeof k_layout[0] };
static const double k_frame_aspect = 1.6;
// The dragon's top and bottom in its frame (fractions of its height): the
// wings' tips and the feet.
static const double k_dragon_top = 0.18, k_dragon_bottom = 0.87;

// The demo's frame (canvas pixels): as large as the canvas's width allows
// with the dragon between top and bottom (under the title, above "Touch to
// start", which covered half of it on a phone held sideways), centred there.
static sp_kiosk_rect attract_frame(double canvas_w, double canvas_h, double top, double bottom)
{
    double span = k_dragon_bottom - k_dragon_top;
    if (!(bottom - top > 0.1 * canvas_h)) top = 0, bottom = canvas_h; // no room between them: the whole canvas
    double h = fmin(canvas_w / k_frame_aspect, (bottom - top) / span), w = h * k_frame_aspect;
    double y = 0.5 * (top + bottom) - h * 0.5 * (k_dragon_top + k_dragon_bottom);
    return (sp_kiosk_rect){(float)(0.5 * (canvas_w - w)), (float)y, (float)w, (float)h};
}

// Timeline (ms): each part is drawn, then flashes; then the dragon lives.
static const double k_draw_ms = 1100, k_flash_ms = 600, k_alive_ms = 6000;

static void demo_stroke(sp_kiosk* k, sp_db* db, int li, const sp_kiosk_rect* frame)
{
    sp_error err = {0};
    sp_character ch = {0};
    double* p = NULL;
    sp_sketch sk = {0};
    int a = 0;
    if (kiosk_load_category_part(db, k_layout[li].category, &ch, &a, &err) != SP_OK) goto done;
    if (!(p = malloc(sizeof(double) * ((size_t)ch.rig.param_count + 1)))) goto done;
    sp_synth_params(&ch.rig, 11 + (uint64_t)li, 0.2, p);
    if (sp_synth_sketch(&ch.rig, a, &ch.camera, p, &sk) != SP_OK) goto done;
    int n = sp_sketch_point_count(&sk);
    sp_vec2 lo, hi;
    if (n < 2 || !sp_sketch_bounds(&sk, &lo, &hi)) goto done;
    demo_part* d = &k->demo_parts[k->demo_count];
    if (!(d->xy = malloc(sizeof(sp_vec2) * (size_t)n))) goto done;
    // Several curves become one stroke, as a visitor would draw them.
    double f = k_layout[li].size * frame->h / fmax(1e-9, sp_v2_len(sp_v2_sub(hi, lo)));
    sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
    double x0 = frame->x + k_layout[li].cx * frame->w, y0 = frame->y + k_layout[li].cy * frame->h;
    int m = 0;
    for (int s = 0; s < sk.stroke_count; ++s)
        for (int i = 0; i < sk.strokes[s].count; ++i, ++m)
            d->xy[m] = (sp_vec2){x0 + f * (sk.strokes[s].points[i].x - c.x), y0 + f * (sk.strokes[s].points[i].y - c.y)};
    d->n = n;
    d->part = -1;
    snprintf(d->category, sizeof d->category, "%s", k_layout[li].category);
    ++k->demo_count;
done:
    sp_sketch_free(&sk);
    free(p);
    sp_character_free(&ch);
}

static void prepare(sp_kiosk* k)
{
    k->demo_prepared = true;
    ++k->stats.attract_builds;
    if (k->desc.no_attract_demo) return;
    struct stat st;
    if (stat(k->db_path, &st) == 0) k->demo_dev = st.st_dev, k->demo_ino = st.st_ino;
    sp_db* db = NULL;
    sp_error err = {0};
    if (sp_db_open(k->db_path, SP_DB_READONLY, &db, &err) != SP_OK) {
        sp_kiosk_log("attract screen without its demo: %s", err.text);
        return;
    }
    char** cats = NULL;
    int n = 0;
    if (sp_db_categories(db, &cats, &n, &err) == SP_OK) k->demo_source = kiosk_row_source(db, cats, n);
    sp_db_free_strings(cats, n);
    float top, bottom;
    kiosk_attract_band(k->ui, (float)k->fb_h, &top, &bottom);
    sp_kiosk_rect frame = attract_frame(k->canvas_w, k->canvas_h, kiosk_fb_to_canvas(k, (sp_vec2){0, top}).y,
                                        kiosk_fb_to_canvas(k, (sp_vec2){0, bottom}).y);
    for (int li = 0; li < LAYOUT_N && k->demo_count < DEMO_MAX; ++li)
        demo_stroke(k, db, li, &frame);
    sp_db_close(db);
    if (k->demo_count == 0) return;
    if (sp_dragon_create(&(sp_dragon_desc){.db_path = k->db_path,
                                           .canvas_w = k->canvas_w,
                                           .canvas_h = k->canvas_h,
                                           .solve = {.time_cap_ms = k->desc.fit_time_cap_ms},
                                           .no_model = true}, // its strokes name their parts: no model to wait for
                         &k->demo, &err) != SP_OK)
        sp_kiosk_log("attract screen without its demo: %s", err.text);
}

// Where the demo is: the part being drawn (or -1 once all are), the time
// within its phase, and the animation time once alive.
static void timeline(const sp_kiosk* k, int* part, double* in_part, double* alive_s)
{
    double at = k->ui->now - k->ui->mode_since;
    double cycle = k->demo_count * (k_draw_ms + k_flash_ms) + k_alive_ms;
    double tt = fmod(fmax(0.0, at), cycle);
    double per = k_draw_ms + k_flash_ms;
    if (tt < k->demo_count * per) {
        *part = (int)(tt / per);
        *in_part = tt - *part * per;
        *alive_s = 0;
    } else {
        *part = -1;
        *in_part = 0;
        *alive_s = (tt - k->demo_count * per) / 1000.0;
    }
}

void kiosk_attract_update(sp_kiosk* k)
{
    // Not before the first frame is on screen: starting fast matters more.
    if (k->updates < 2) return;
    if (!k->demo_prepared) {
        // A rebuild reads parts like the first build: in a frame of its own.
        bool rebuild = k->stats.attract_builds > 0;
        if (rebuild && k->heavy_done) return;
        prepare(k);
        if (rebuild) {
            k->heavy_done = true;
            return;
        }
    }
    if (!k->demo) return;
    // Fit the next demo part (one a frame, and only when the visitor's jobs left room).
    if (!k->heavy_done) {
        for (int i = 0; i < k->demo_count; ++i) {
            demo_part* d = &k->demo_parts[i];
            if (d->tried) continue;
            d->tried = true;
            k->heavy_done = true;
            sp_dragon_result res;
            sp_error err = {0};
            sp_result rc =
                sp_dragon_add_points(k->demo, d->xy, d->n, &(sp_dragon_stroke_opts){.category = d->category}, &res, &err);
            if (rc == SP_OK && !res.rejected && res.part >= 0) {
                d->part = res.part;
                ++k->stats.attract_parts;
                d->outline_n = kiosk_fitted_outline(sp_dragon_part_get(k->demo, res.part), &d->outline, &d->outline_cap,
                                                    d->breaks, 16, &d->break_n);
            }
            k->demo_posed_parts = -1;
            break;
        }
    }
    int part;
    double in_part, alive;
    timeline(k, &part, &in_part, &alive);
    int n = sp_dragon_part_count(k->demo);
    if (alive != k->demo_posed_t || n != k->demo_posed_parts) {
        sp_error err = {0};
        if (sp_dragon_pose_at(k->demo, alive, &err) == SP_OK) mesh_cache_sync(&k->demo_meshes, k->r, k->demo, true);
        k->demo_posed_t = alive;
        k->demo_posed_parts = n;
    }
}

static void stroke_px(sp_kiosk* k, const sp_vec2* xy, int n)
{
    if (n > k->scratch_cap) {
        sp_vec2* s = realloc(k->scratch, sizeof *s * (size_t)n);
        if (!s) return;
        k->scratch = s, k->scratch_cap = n;
    }
    for (int i = 0; i < n; ++i)
        k->scratch[i] = kiosk_canvas_to_fb(k, xy[i]);
}

sp_camera kiosk_attract_camera(sp_kiosk* k)
{
    sp_camera c = kiosk_fb_camera(k);
    sp_vec3 lo, hi;
    if (k->demo && sp_dragon_bounds(k->demo, &lo, &hi)) sp_render_fit_depth(&c, lo, hi);
    return c;
}

void kiosk_attract_draw_scene(sp_kiosk* k)
{
    if (!k->demo || k->demo_count == 0) return;
    int part;
    double in_part, alive;
    timeline(k, &part, &in_part, &alive);
    // Parts drawn before the current one are there; all of them once alive.
    for (int i = 0; i < k->demo_count; ++i) {
        const demo_part* d = &k->demo_parts[i];
        if (d->part < 0 || (part >= 0 && i >= part)) continue;
        sp_render_mesh* m = mesh_cache_get(&k->demo_meshes, sp_dragon_part_get(k->demo, d->part)->id);
        if (m) sp_renderer_draw_mesh(k->r, m, NULL);
    }
    if (part < 0) return;
    const demo_part* d = &k->demo_parts[part];
    float lw = k->ui->line_px;
    int shown = in_part >= k_draw_ms ? d->n : (int)ceil(d->n * in_part / k_draw_ms);
    if (shown < 1) shown = 1;
    stroke_px(k, d->xy, shown);
    sp_renderer_draw_polyline(k->r, k->scratch, shown, false, lw, SP_COLOR_STROKE);
    if (in_part < k_draw_ms) {
        // The fingertip drawing it.
        sp_vec2 tip = k->scratch[shown - 1];
        sp_renderer_draw_dots(k->r, &tip, 1, 2.6f * lw, (const float[4]){0.95f, 0.75f, 0.6f, 0.9f});
        sp_renderer_draw_dots(k->r, &tip, 1, 1.2f * lw, SP_COLOR_STROKE);
    } else if (d->outline_n > 0) {
        int start = 0;
        for (int b = 0; b <= d->break_n; ++b) {
            int end = b < d->break_n ? d->breaks[b] : d->outline_n;
            if (end - start > 0) {
                sp_vec2* q = malloc(sizeof *q * (size_t)(end - start));
                if (!q) break;
                for (int i = start; i < end; ++i)
                    q[i - start] = kiosk_canvas_to_fb(k, (sp_vec2){d->outline[2 * i], d->outline[2 * i + 1]});
                sp_renderer_draw_polyline(k->r, q, end - start, false, 0.75f * lw, SP_COLOR_ABSTRACTION);
                free(q);
            }
            start = end;
        }
    }
}

void kiosk_attract_free(sp_kiosk* k)
{
    mesh_cache_free(&k->demo_meshes);
    sp_dragon_destroy(k->demo);
    k->demo = NULL;
    for (int i = 0; i < DEMO_MAX; ++i) {
        free(k->demo_parts[i].xy);
        free(k->demo_parts[i].outline);
        memset(&k->demo_parts[i], 0, sizeof k->demo_parts[i]);
    }
    k->demo_count = 0;
    free(k->demo_source);
    k->demo_source = NULL;
}

void kiosk_attract_rebuild(sp_kiosk* k)
{
    int lod = k->demo_meshes.lod_triangles;
    kiosk_attract_free(k);
    k->demo_meshes.lod_triangles = lod;
    k->demo_prepared = k->demo_stale = false;
    k->demo_posed_parts = -1;
    k->stats.attract_parts = 0;
}
