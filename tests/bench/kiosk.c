// tests/bench/kiosk: the kiosk's speed on a headless OpenGL context (Mesa
// llvmpipe in CI): the same code as the window (sp_kiosk), drawing into a
// 1280 x 800 offscreen framebuffer and waiting for each frame (glFinish).
//   build/tests/bench/kiosk [--json] [--runs N] [--db DB] [--lod N (triangles per part, -1: all)] [--png last.png]
//                           [--no-collect (keep no visitors' strokes: the A/B of collection)]
//   build/tests/bench/kiosk --soak N [--json]   N strokes in one session (undo, start over and
//   save now and then); resident memory right after each Start over (every 40
//   strokes): the first one after 200 strokes (warm-up) against the largest later one.
//   build/tests/bench/kiosk --model-swap [--db DB] [--runs N] [--json]   a copy of the database;
//   N times its newest model stored again (what `db train` commits), while the
//   kiosk draws frames at 60 per second of wall time: the longest frame until
//   the kiosk uses the new model, and how long that took.
// Cases: start to first frame, pen-up to the fitted part on screen (the
// first stroke of each part after start, and all of them; the paper's solve
// alone took 100 ms; target 50 ms), frames of the attract
// screen, of an empty canvas, of six animated parts and of 20 (target 33 ms),
// pen-up to part with 6-19 parts on screen, and a Save's tap to its code (no target).
// Without --db it builds the test database of tests/support/kiosk_parts.h.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <sqlite3.h>

#include "bench.h"
#include "fixtures.h"
#include "kiosk_parts.h"
#include "sp/clock.h"
#include "sp/dragon.h"
#include "sp/headless.h"
#include "sp/kiosk.h"
#include "sp/render.h"

enum { W = 1280, H = 800 };

static void ev(sp_kiosk* k, sp_kiosk_event_type type, double t, double x, double y)
{
    sp_kiosk_input(k, &(sp_kiosk_event){type, t, (float)x, (float)y, 0});
}

// Process CPU time (every thread, llvmpipe's too): on a busy machine a
// steadier figure than the wall clock.
static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static double g_cpu[4096];
static int g_ncpu;

static double g_upd_cpu[4096];

static GLuint g_fbo;
static sp_render_target* g_target;

static double frame(sp_kiosk* k, double t)
{
    // Screenshots and postcards bind their own framebuffers.
    if (g_target)
        sp_render_target_bind(g_target);
    else
        glBindFramebuffer(GL_FRAMEBUFFER, g_fbo);
    double t0 = sp_now_ms(), c0 = cpu_ms();
    sp_kiosk_update(k, t);
    if (g_ncpu < 4096) g_upd_cpu[g_ncpu] = cpu_ms() - c0;
    sp_kiosk_draw(k);
    glFinish();
    if (g_ncpu < 4096) g_cpu[g_ncpu++] = cpu_ms() - c0;
    return sp_now_ms() - t0;
}

// The CPU time of the frames since the last call, as an extra JSON member.
// A kiosk at the canvas size, its first frame drawn; NULL (said on stderr) when it does not start.
static sp_kiosk* start_kiosk(const sp_kiosk_desc* desc)
{
    sp_error err = {0};
    sp_kiosk* k = sp_kiosk_create(desc, &err);
    if (!k) {
        fprintf(stderr, "bench kiosk: %s\n", err.text);
        return NULL;
    }
    sp_kiosk_resize(k, W, H, 96 / 25.4);
    frame(k, 0);
    return k;
}

static void cpu_extra(sp_bench_row* r)
{
    double med = 0, p90 = 0, umed = 0;
    if (g_ncpu > 0) sp_bench_stats(g_cpu, g_ncpu, &med, &p90);
    if (g_ncpu > 0) sp_bench_stats(g_upd_cpu, g_ncpu, &umed, &p90);
    size_t n = strlen(r->extra);
    snprintf(r->extra + n, sizeof r->extra - n, "%s\"cpu_ms_median\": %.2f, \"update_cpu_ms_median\": %.2f", n ? ", " : "", med,
             umed);
    g_ncpu = 0;
}

static void press(sp_kiosk* k, double t, sp_kiosk_target target)
{
    sp_kiosk_input(k, &(sp_kiosk_event){SP_KEV_PRESS, t, 0, 0, target});
}

// n strokes in one session: the six parts drawn again and again, shifted a
// little each time, with Undo, Start over and Save mixed in.
static void soak_run(sp_kiosk* k, const kp_stroke* strokes, int n, sp_bench_row* row)
{
    double t = 1e6, step = 1000.0 / 60.0;
    sp_test_rng rng = {77};
    long warm = 0, peak = 0;
    static double samples[4096];
    int ns = 0;
    double t0 = sp_now_ms();
    sp_vec2* xy = NULL;
    int cap = 0;
    for (int i = 0; i < n; ++i) {
        const kp_stroke* s = &strokes[i % DRAGON_PART_COUNT];
        if (s->n > cap) {
            xy = realloc(xy, sizeof *xy * (size_t)s->n);
            cap = s->n;
        }
        double dx = sp_test_range(&rng, -40, 40), dy = sp_test_range(&rng, -30, 30);
        for (int p = 0; p < s->n; ++p)
            xy[p] = (sp_vec2){s->xy[p].x + dx, s->xy[p].y + dy};
        ev(k, SP_KEV_DOWN, t, xy[0].x, xy[0].y);
        for (int p = 1; p < s->n; ++p)
            ev(k, SP_KEV_MOVE, t + 0.01 * p, xy[p].x, xy[p].y);
        t += 0.01 * s->n;
        ev(k, SP_KEV_UP, t, xy[s->n - 1].x, xy[s->n - 1].y);
        for (int f = 0; f < 3; ++f)
            frame(k, t += step);
        if (i % 7 == 6) press(k, t += step, SP_KT_UNDO);
        if (i % 97 == 96) press(k, t += step, SP_KT_SAVE);
        bool cleared = i % 40 == 39;
        if (cleared) {
            press(k, t += step, SP_KT_START_OVER);
            press(k, t += step, SP_KT_START_OVER);
        }
        frame(k, t += step);
        // Memory is compared in the same state, right after each Start over
        // (between them it grows with the parts on screen, as it should).
        if (cleared) {
            long r = sp_rss_kb();
            if (!warm && i + 1 >= (n >= 400 ? 200 : n / 2))
                warm = r;
            else if (warm && r > peak)
                peak = r;
            if (warm && ns < 4096) samples[ns++] = (double)r;
            fprintf(stderr, "soak: %d strokes, %ld kB resident\n", i + 1, r);
        }
    }
    free(xy);
    long end = sp_rss_kb();
    if (!peak) peak = warm;
    double ms = (sp_now_ms() - t0) / n;
    *row = (sp_bench_row){"soak: ms per stroke", ms, ms, n, -1, -1, ""};
    // The last ten samples' median: the level memory settles at (a single
    // sample can catch the allocator holding a freed postcard or export).
    double settled = 0, p90 = 0;
    int last = ns < 10 ? ns : 10;
    if (last > 0) sp_bench_stats(samples + ns - last, last, &settled, &p90);
    snprintf(row->extra, sizeof row->extra,
             "\"rss_kb_warm\": %ld, \"rss_kb_peak\": %ld, \"rss_kb_settled\": %.0f, \"rss_kb_end\": %ld, \"growth_pct\": %.2f, "
             "\"peak_growth_pct\": %.2f, \"saves\": %d",
             warm, peak, settled, end, warm > 0 ? 100.0 * (settled - (double)warm) / (double)warm : 0.0,
             warm > 0 ? 100.0 * (double)(peak - warm) / (double)warm : 0.0, sp_kiosk_stats_of(k)->saves);
}

// --model-swap: frames go on while a new model is read (a kiosk on the
// copy `path`, idle on an empty canvas, the clock the wall's).
static bool model_swap_run(const char* path, const char* dir, int runs, sp_bench_row* rows, int* nr)
{
    sp_kiosk* k = start_kiosk(&(sp_kiosk_desc){
        .db_path = path, .canvas_w = W, .canvas_h = H, .export_dir = dir, .no_attract_demo = true, .no_collect = true});
    if (!k) return false;
    double t0 = sp_now_ms();
    ev(k, SP_KEV_DOWN, 10, 640, 400);
    ev(k, SP_KEV_UP, 20, 640, 400);
    for (int f = 0; f < 120; ++f) // the parts row and the parts load
        frame(k, 30 + sp_now_ms() - t0);
    double* longest = malloc(sizeof(double) * (size_t)runs * 2);
    double* took = longest + runs;
    int n = 0;
    for (int i = 0; i < runs; ++i) {
        const sp_clf* before = sp_dragon_model(sp_kiosk_dragon(k));
        if (!sp_fixture_store_model_again(path)) break;
        double s0 = sp_now_ms(), worst = 0;
        // The kiosk polls every 2 s of its clock; 30 s is far past any read.
        while (sp_dragon_model(sp_kiosk_dragon(k)) == before && sp_now_ms() - s0 < 30000) {
            double f0 = sp_now_ms();
            worst = fmax(worst, frame(k, 30 + f0 - t0));
            double rest = 1000.0 / 60.0 - (sp_now_ms() - f0);
            if (rest > 0) usleep((useconds_t)(rest * 1000));
        }
        if (sp_dragon_model(sp_kiosk_dragon(k)) == before) {
            fprintf(stderr, "bench kiosk: the new model was not in use after 30 s\n");
            break;
        }
        longest[n] = worst, took[n++] = sp_now_ms() - s0;
    }
    bool ok = n == runs;
    if (ok) {
        sp_bench_row r = {"new model stored: the longest frame until it is used", 0, 0, n, -1, 33, ""};
        sp_bench_stats(longest, n, &r.ms_median, &r.ms_p90);
        snprintf(r.extra, sizeof r.extra, "\"models_loaded\": %d, \"reloads\": %d", sp_kiosk_stats_of(k)->models_loaded,
                 sp_kiosk_stats_of(k)->reloads);
        rows[(*nr)++] = r;
        r = (sp_bench_row){"new model stored: until it is used (the poll every 2 s included)", 0, 0, n, -1, -1, ""};
        sp_bench_stats(took, n, &r.ms_median, &r.ms_p90);
        rows[(*nr)++] = r;
    }
    free(longest);
    sp_kiosk_destroy(k);
    return ok;
}

// The strokes and the GL objects main made, and the context.
static void teardown(kp_stroke* strokes, sp_render_target* target, GLuint fbo, GLuint rb[2], sp_headless* gl)
{
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        free(strokes[i].xy);
    sp_render_target_destroy(target);
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (rb[0]) glDeleteRenderbuffers(2, rb);
    sp_headless_destroy(gl);
}

int main(int argc, char** argv)
{
    bool json = sp_bench_json_flag(argc, argv);
    int runs = 60;
    const char* db = NULL;
    const char* png = NULL;
    int lod = 0, soak = 0;
    bool no_collect = false, model_swap = false;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--lod") && i + 1 < argc)
            lod = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--png") && i + 1 < argc)
            png = argv[++i];
        else if (!strcmp(argv[i], "--soak") && i + 1 < argc)
            soak = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--db") && i + 1 < argc)
            db = argv[++i];
        else if (!strcmp(argv[i], "--no-collect"))
            no_collect = true;
        else if (!strcmp(argv[i], "--model-swap"))
            model_swap = true;
    }
    if (model_swap && runs == 60) runs = 5; // each waits for a poll (2 s) and a read
    if (runs < 3) runs = 3;
    sp_error err = {0};
    char db_path[1100], dir[1024];
    bool real = false;
    kp_stroke strokes[DRAGON_PART_COUNT];
    if (!kp_bench_setup("kiosk", &db, "bench_kiosk.db", dir, db_path, &real, strokes)) return 1;
    sp_headless* gl;
    sp_headless_create(&gl, &err);
    if (!gl) {
        fprintf(stderr, "bench kiosk: %s\n", err.text);
        return 1;
    }
    // The framebuffer the window would have: one sample a pixel on software
    // GL (dragon-kiosk's default there), 4 on a GPU.
    const char* gl_name = sp_headless_renderer_name(gl);
    bool software = strstr(gl_name, "llvmpipe") || strstr(gl_name, "softpipe") || strstr(gl_name, "swrast");
    sp_render_target* target = NULL;
    GLuint fbo = 0, rb[2] = {0, 0};
    if (software) {
        glGenFramebuffers(1, &fbo);
        glGenRenderbuffers(2, rb);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, W, H);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
        g_fbo = fbo;
    } else {
        if (sp_render_target_create(W, H, 4, &target, &err) != SP_OK) {
            fprintf(stderr, "bench kiosk: %s\n", err.text);
            return 1;
        }
        sp_render_target_bind(target);
        g_target = target;
    }
    sp_bench_row rows[16];
    int nr = 0;
    if (model_swap) {
        // On a copy: the bench stores models into it.
        char copy[1100];
        snprintf(copy, sizeof copy, "%.1024s/bench_swap.db", dir);
        remove(copy);
        sqlite3* h = NULL;
        char sql[1200];
        snprintf(sql, sizeof sql, "VACUUM INTO '%s'", copy);
        bool copied = strchr(copy, '\'') == NULL && sqlite3_open_v2(db, &h, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK &&
                      sqlite3_exec(h, sql, NULL, NULL, NULL) == SQLITE_OK;
        if (!copied) fprintf(stderr, "bench kiosk: %s: cannot copy to %s: %s\n", db, copy, h ? sqlite3_errmsg(h) : "?");
        sqlite3_close(h);
        bool ok = copied && model_swap_run(copy, dir, runs, rows, &nr);
        if (ok) sp_bench_print("kiosk: a new model (headless, 1280x800)", rows, nr, json);
        remove(copy);
        teardown(strokes, target, fbo, rb, gl);
        return ok ? 0 : 1;
    }
    if (soak > 0) {
        sp_kiosk* k = start_kiosk(&(sp_kiosk_desc){.db_path = db,
                                                   .canvas_w = W,
                                                   .canvas_h = H,
                                                   .export_dir = dir,
                                                   .lod_triangles = lod,
                                                   .no_attract_demo = true,
                                                   .no_collect = no_collect});
        if (!k) return 1;
        ev(k, SP_KEV_DOWN, 10, 640, 400);
        ev(k, SP_KEV_UP, 20, 640, 400);
        soak_run(k, strokes, soak, &rows[nr++]);
        sp_bench_print("kiosk soak (headless, 1280x800)", rows, nr, json);
        sp_kiosk_destroy(k);
        teardown(strokes, target, fbo, rb, gl);
        return 0;
    }

    // Start to first frame (the database exists, as in a museum after install).
    double t0 = sp_now_ms();
    sp_kiosk* k = start_kiosk(&(sp_kiosk_desc){
        .db_path = db, .canvas_w = W, .canvas_h = H, .export_dir = dir, .lod_triangles = lod, .no_collect = no_collect});
    if (!k) return 1;
    double start = sp_now_ms() - t0;
    rows[nr++] = (sp_bench_row){"start to first frame", start, start, 1, -1, 2000, ""};
    snprintf(rows[nr - 1].extra, sizeof rows[nr - 1].extra, "\"database\": \"%s\"", real ? "assets" : "stand-ins");

    // The attract screen (its demo dragon fits itself over the first frames).
    double t = 0, step = 1000.0 / 60.0;
    double* ms = malloc(sizeof(double) * (size_t)(runs + 64));
    // Its first 30 frames: the parts row, then the parts loading, one a frame.
    double warm[30], slowest = 0;
    for (int i = 0; i < 30; ++i)
        slowest = fmax(slowest, warm[i] = frame(k, t += step));
    sp_bench_row w = {"frame: attract screen, the first 30 (parts loading)", 0, 0, 30, -1, 33, ""};
    sp_bench_stats(warm, 30, &w.ms_median, &w.ms_p90);
    snprintf(w.extra, sizeof w.extra, "\"slowest_ms\": %.1f, \"parts_loaded\": %d", slowest,
             sp_dragon_loaded_parts(sp_kiosk_dragon(k)));
    rows[nr++] = w;
    g_ncpu = 0;
    for (int i = 0; i < runs; ++i)
        ms[i] = frame(k, t += step);
    sp_bench_row r = {"frame: attract screen 1280x800", 0, 0, runs, -1, 33, ""};
    sp_bench_stats(ms, runs, &r.ms_median, &r.ms_p90);
    cpu_extra(&r);
    rows[nr++] = r;

    // An empty canvas.
    ev(k, SP_KEV_DOWN, t += step, 640, 400);
    ev(k, SP_KEV_UP, t += 10, 640, 400);
    g_ncpu = 0;
    for (int i = 0; i < runs; ++i)
        ms[i] = frame(k, t += step);
    r = (sp_bench_row){"frame: empty canvas 1280x800", 0, 0, runs, -1, 33, ""};
    sp_bench_stats(ms, runs, &r.ms_median, &r.ms_p90);
    cpu_extra(&r);
    rows[nr++] = r;

    // Pen-up to the fitted part on screen: the stroke's events, then one
    // update + draw. Rounds of six strokes, cleared in between.
    int rounds = runs / 6 < 2 ? 2 : runs / 6, n = 0;
    double* lat = malloc(sizeof(double) * (size_t)(rounds * DRAGON_PART_COUNT));
    double* clear_ms = malloc(sizeof(double) * (size_t)rounds);
    double* save_ms = malloc(sizeof(double) * (size_t)rounds);
    int nc = 0, nsave = 0;
    for (int round = 0; round < rounds; ++round) {
        for (int i = 0; i < DRAGON_PART_COUNT; ++i) {
            const kp_stroke* s = &strokes[i];
            ev(k, SP_KEV_DOWN, t, s->xy[0].x, s->xy[0].y);
            for (int p = 1; p < s->n; ++p)
                ev(k, SP_KEV_MOVE, t + 0.01 * p, s->xy[p].x, s->xy[p].y);
            t += 0.01 * s->n;
            double up = sp_now_ms();
            ev(k, SP_KEV_UP, t, s->xy[s->n - 1].x, s->xy[s->n - 1].y);
            frame(k, t += step);
            lat[n++] = sp_now_ms() - up;
            for (int f = 0; f < 60; ++f) // the flash ends, the part shows
                frame(k, t += step);
        }
        // Save with six parts: from the tap to the code on screen (a frame
        // that shows the tap, then the one that writes the .glb, draws the
        // postcard and writes its PNG).
        int saved = sp_kiosk_stats_of(k)->saves + sp_kiosk_stats_of(k)->save_failures;
        double s0 = sp_now_ms();
        press(k, t += step, SP_KT_SAVE);
        for (int f = 0; f < 4 && sp_kiosk_stats_of(k)->saves + sp_kiosk_stats_of(k)->save_failures == saved; ++f)
            frame(k, t += step);
        save_ms[nsave++] = sp_now_ms() - s0;
        for (int f = 0; f < 30; ++f) // the code banner
            frame(k, t += step);
        if (round + 1 < rounds) {
            // The frame that clears six parts (and hands their strokes to the collector).
            press(k, t += step, SP_KT_START_OVER);
            press(k, t += step, SP_KT_START_OVER);
            clear_ms[nc++] = frame(k, t += step);
        }
    }
    // The first six strokes after start, after the attract screen's frames
    // (each the first stroke of its part: the part's loading, unless the
    // kiosk loaded it while nobody drew).
    r = (sp_bench_row){"pen-up to fitted part, the first stroke of each part after start", 0, 0, DRAGON_PART_COUNT, -1, 50, ""};
    sp_bench_stats(lat, DRAGON_PART_COUNT, &r.ms_median, &r.ms_p90);
    rows[nr++] = r;
    r = (sp_bench_row){"pen-up to fitted part on screen", 0, 0, n, 100, 50, ""};
    sp_bench_stats(lat, n, &r.ms_median, &r.ms_p90);
    snprintf(r.extra, sizeof r.extra, "\"parts\": %d, \"collect\": %s", sp_kiosk_stats_of(k)->parts,
             no_collect ? "false" : "true");
    rows[nr++] = r;
    r = (sp_bench_row){"frame: Start over with six parts", 0, 0, nc, -1, 33, ""};
    sp_bench_stats(clear_ms, nc, &r.ms_median, &r.ms_p90);
    snprintf(r.extra, sizeof r.extra, "\"collected\": %d", sp_kiosk_stats_of(k)->collected);
    rows[nr++] = r;
    free(clear_ms);
    r = (sp_bench_row){"Save with six parts: tap to code on screen", 0, 0, nsave, -1, -1, ""};
    sp_bench_stats(save_ms, nsave, &r.ms_median, &r.ms_p90);
    snprintf(r.extra, sizeof r.extra, "\"saves\": %d, \"save_failures\": %d", sp_kiosk_stats_of(k)->saves,
             sp_kiosk_stats_of(k)->save_failures);
    rows[nr++] = r;
    free(save_ms);

    // Six animated parts.
    press(k, t += step, SP_KT_PLAY);
    g_ncpu = 0;
    for (int i = 0; i < runs; ++i)
        ms[i] = frame(k, t += step);
    r = (sp_bench_row){"frame: six animated parts 1280x800", 0, 0, runs, -1, 33, ""};
    sp_bench_stats(ms, runs, &r.ms_median, &r.ms_p90);
    snprintf(r.extra, sizeof r.extra, "\"parts\": %d, \"triangles\": %d, \"playing\": %s, \"renderer\": \"%s\"",
             sp_kiosk_stats_of(k)->parts, sp_kiosk_stats_of(k)->triangles, sp_kiosk_ui_of(k)->playing ? "true" : "false",
             sp_headless_renderer_name(gl));
    cpu_extra(&r);
    rows[nr++] = r;

    // A dragon grows: 14 more strokes (the five parts again, moved along
    // the body) make 20 parts; pen-up to part with 6 to 19 parts on screen,
    // then frames of the 20 animated parts.
    press(k, t += step, SP_KT_PLAY);
    int more = 0;
    double* lat20 = malloc(sizeof(double) * 14);
    for (int j = 0; j < 14; ++j) {
        const kp_stroke* s = &strokes[1 + j % (DRAGON_PART_COUNT - 1)];
        double dx = ((j / (DRAGON_PART_COUNT - 1)) % 2 ? -1 : 1) * (50.0 + 40.0 * (j / (DRAGON_PART_COUNT - 1))), dy = 0;
        ev(k, SP_KEV_DOWN, t, s->xy[0].x + dx, s->xy[0].y + dy);
        for (int p = 1; p < s->n; ++p)
            ev(k, SP_KEV_MOVE, t + 0.01 * p, s->xy[p].x + dx, s->xy[p].y + dy);
        t += 0.01 * s->n;
        double up = sp_now_ms();
        ev(k, SP_KEV_UP, t, s->xy[s->n - 1].x + dx, s->xy[s->n - 1].y + dy);
        frame(k, t += step);
        lat20[more++] = sp_now_ms() - up;
        for (int f = 0; f < 60; ++f)
            frame(k, t += step);
    }
    r = (sp_bench_row){"pen-up to fitted part, 6-19 parts on screen", 0, 0, more, 100, 50, ""};
    sp_bench_stats(lat20, more, &r.ms_median, &r.ms_p90);
    snprintf(r.extra, sizeof r.extra, "\"parts\": %d", sp_kiosk_stats_of(k)->parts);
    rows[nr++] = r;
    free(lat20);
    if (!sp_kiosk_ui_of(k)->playing) press(k, t += step, SP_KT_PLAY);
    g_ncpu = 0;
    for (int i = 0; i < runs; ++i)
        ms[i] = frame(k, t += step);
    r = (sp_bench_row){"frame: 20 animated parts 1280x800", 0, 0, runs, -1, 33, ""};
    sp_bench_stats(ms, runs, &r.ms_median, &r.ms_p90);
    snprintf(r.extra, sizeof r.extra, "\"parts\": %d, \"triangles\": %d, \"playing\": %s", sp_kiosk_stats_of(k)->parts,
             sp_kiosk_stats_of(k)->triangles, sp_kiosk_ui_of(k)->playing ? "true" : "false");
    cpu_extra(&r);
    rows[nr++] = r;

    if (png) { // the last frame, to look at what was timed
        sp_image img = {0};
        if (sp_image_alloc(&img, W, H) == SP_OK) {
            if (g_target) {
                sp_render_target_read(g_target, &img, &err);
            } else {
                glBindFramebuffer(GL_FRAMEBUFFER, g_fbo);
                glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, img.rgba);
                sp_image_flip_rows(&img);
            }
            if (sp_image_write_png(&img, png, &err) != SP_OK) fprintf(stderr, "bench kiosk: %s\n", err.text);
        }
        sp_image_free(&img);
    }
    sp_bench_print("kiosk (headless, 1280x800)", rows, nr, json);
    free(ms);
    free(lat);
    sp_kiosk_destroy(k);
    teardown(strokes, target, fbo, rb, gl);
    return 0;
}
