// dragon_kiosk.c: the kiosk window. GLFW turns touches (pointer events) into
// sp_kiosk_events; kiosk.h does the rest. With --script the session file is
// replayed on a virtual clock (its own timestamps, 60 updates a second, every
// tenth one drawn), so a run is deterministic whatever the machine's speed.
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <cjson/cJSON.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "cli.h"
#include "sp/clock.h"
#include "sp/dragon.h"
#include "sp/draw2d.h"
#include "sp/kiosk.h"
#include "sp/kiosk_session.h"
#include "sp/kiosk_text.h"
#include "sp/partdb.h"
#include "sp/sketch_io.h"

static const char* const k_cmd = "dragon-kiosk";

typedef struct app {
    sp_kiosk* k;
    GLFWwindow* win;
    bool scripted;
    double t0;
    sp_kiosk_session rec;
    bool recording;
    int fb_w, fb_h;
    double ppm;          // measured (or the script's)
    double ppm_override; // from the script, 0: none
    // Stats.
    double up_wall[8]; // wall times of pen-ups whose strokes wait for the pipeline (ring)
    int up_head, up_count;
    int seen_fits, seen_dropped, seen_finished;
    double* latency; // pen-up -> fitted outline on screen, ms
    int latency_n, latency_cap;
    double frame_ms[8192], update_ms[8192], draw_ms[8192], swap_ms[8192];
    int frames;
    long rss_kb[512];
    int rss_n, rss_next_stroke;
} app;

static volatile sig_atomic_t g_quit = 0;

static void on_signal(int sig)
{
    (void)sig;
    g_quit = 1;
}

// Past a file-size limit a write fails (a sketch dropped, a save that says
// so) instead of the signal killing the kiosk; so does a write to a log pipe
// whose reader is gone (SIGPIPE killed it, the visit lost).
static void ignore_write_signals(void)
{
    signal(SIGXFSZ, SIG_IGN);
    signal(SIGPIPE, SIG_IGN);
}

// Ctrl-C, a stop and a hang-up (the terminal or session gone) end the kiosk
// cleanly: the visit on the canvas is kept (a hang-up lost it, exit 129).
static void catch_quit_signals(void)
{
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGHUP, on_signal);
}

// Pixels per millimetre of the framebuffer: the monitor's physical size
// when it reports a plausible one, else 96 dpi times the content scale.
static double measure_ppm(GLFWwindow* win, int fb_w)
{
    GLFWmonitor* mon = glfwGetWindowMonitor(win);
    if (!mon) mon = glfwGetPrimaryMonitor();
    int win_w = 0, win_h = 0;
    glfwGetWindowSize(win, &win_w, &win_h);
    double fb_per_screen = win_w > 0 ? (double)fb_w / win_w : 1.0;
    int mm_w = 0, mm_h = 0;
    const GLFWvidmode* mode = mon ? glfwGetVideoMode(mon) : NULL;
    if (mon) glfwGetMonitorPhysicalSize(mon, &mm_w, &mm_h);
    if (mode && mm_w >= 50 && mode->width > 0) {
        double ppm = mode->width / (double)mm_w;
        // 40..600 dpi: anything else is a made-up EDID.
        if (ppm >= 40 / 25.4 && ppm <= 600 / 25.4) return ppm * fb_per_screen;
    }
    float sx = 1, sy = 1;
    glfwGetWindowContentScale(win, &sx, &sy);
    if (!(sx > 0.25f && sx < 8.0f)) sx = 1;
    return 96.0 / 25.4 * sx * fb_per_screen;
}

static void push_event(app* a, const sp_kiosk_event* ev)
{
    const sp_kiosk_ui* ui = sp_kiosk_ui_of(a->k);
    int before = ui->strokes_finished, merged = ui->merged;
    sp_kiosk_input(a->k, ev);
    if (a->recording && ev->type != SP_KEV_FRAME && sp_kiosk_session_append(&a->rec, ev) != SP_OK) {
        sp_kiosk_log("recording full or out of memory; recording stops here");
        a->recording = false;
    }
    if (ui->merged > merged && a->up_count > 0) {
        // Drawn on before its first piece was fitted: one stroke, timed from its last pen-up.
        a->up_wall[(a->up_head + a->up_count - 1) % 8] = sp_now_ms();
    } else if (ui->strokes_finished > before) {
        a->up_wall[(a->up_head + a->up_count) % 8] = sp_now_ms();
        if (a->up_count < 8)
            ++a->up_count;
        else
            a->up_head = (a->up_head + 1) % 8;
    }
}

static double live_t(const app* a)
{
    return (glfwGetTime() - a->t0) * 1000.0;
}

// Live frames come at most 60 a second: where the swap does not wait for the
// display (software GL, Xvfb) the loop drew 200 a second of an idle
// screen. Input is handled while waiting (each event keeps its own time), and
// a stroke's pen-up (a job) starts the next frame at once.
static void wait_for_frame(const app* a, double until)
{
    for (double now = glfwGetTime(); now < until && !g_quit; now = glfwGetTime()) {
        glfwWaitEventsTimeout(until - now);
        if (sp_kiosk_ui_peek_job(sp_kiosk_ui_of(a->k)) != SP_KJOB_NONE) return;
    }
}

static void cb_button(GLFWwindow* w, int button, int action, int mods)
{
    (void)mods;
    app* a = glfwGetWindowUserPointer(w);
    if (a->scripted) return;
    double x = 0, y = 0;
    glfwGetCursorPos(w, &x, &y);
    int ww = 1, wh = 1;
    glfwGetWindowSize(w, &ww, &wh);
    double sx = ww > 0 ? (double)a->fb_w / ww : 1, sy = wh > 0 ? (double)a->fb_h / wh : 1;
    sp_kiosk_event ev = {action == GLFW_PRESS ? SP_KEV_DOWN : SP_KEV_UP, live_t(a), (float)(x * sx), (float)(y * sy), button};
    push_event(a, &ev);
}

static void cb_cursor(GLFWwindow* w, double x, double y)
{
    app* a = glfwGetWindowUserPointer(w);
    if (a->scripted) return;
    int ww = 1, wh = 1;
    glfwGetWindowSize(w, &ww, &wh);
    double sx = ww > 0 ? (double)a->fb_w / ww : 1, sy = wh > 0 ? (double)a->fb_h / wh : 1;
    sp_kiosk_event ev = {SP_KEV_MOVE, live_t(a), (float)(x * sx), (float)(y * sy), 0};
    push_event(a, &ev);
}

static void cb_focus(GLFWwindow* w, int focused)
{
    app* a = glfwGetWindowUserPointer(w);
    if (a->scripted || focused) return;
    sp_kiosk_event ev = {SP_KEV_CANCEL, live_t(a), 0, 0, 0};
    push_event(a, &ev);
}

static void relayout(app* a)
{
    glfwGetFramebufferSize(a->win, &a->fb_w, &a->fb_h);
    a->ppm = a->ppm_override > 0 ? a->ppm_override : measure_ppm(a->win, a->fb_w);
    sp_kiosk_resize(a->k, a->fb_w, a->fb_h, a->ppm);
}

static void cb_resize(GLFWwindow* w, int fw, int fh)
{
    (void)fw, (void)fh;
    relayout(glfwGetWindowUserPointer(w));
}

static void cb_scale(GLFWwindow* w, float sx, float sy)
{
    (void)sx, (void)sy;
    relayout(glfwGetWindowUserPointer(w));
}

static void cb_key(GLFWwindow* w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    // Staff only: Ctrl+Shift+Q closes the kiosk (visitors need no keyboard).
    if (key == GLFW_KEY_Q && action == GLFW_PRESS && (mods & GLFW_MOD_CONTROL) && (mods & GLFW_MOD_SHIFT))
        glfwSetWindowShouldClose(w, 1);
}

static void cb_error(int code, const char* text)
{
    sp_kiosk_log("GLFW error 0x%x: %s", code, text);
}

// Until the window is open, GLFW's last error is kept for the one line
// that says why there is none (it was a time-stamped log line above it).
static char g_glfw_early[256];

static void cb_error_early(int code, const char* text)
{
    (void)code;
    snprintf(g_glfw_early, sizeof g_glfw_early, "%s", text ? text : "");
}

// One frame: update at t, draw, swap; the pen-up latency of strokes whose fit just landed.
static void frame(app* a, double t, bool render)
{
    double w0 = sp_now_ms();
    sp_kiosk_update(a->k, t);
    double wu = sp_now_ms(), wd = wu;
    const sp_kiosk_ui* ui = sp_kiosk_ui_of(a->k);
    const sp_kiosk_stats* st = sp_kiosk_stats_of(a->k);
    int fits = st->fit_count, dropped = ui->dropped_strokes;
    if (render) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        sp_kiosk_draw(a->k);
        if (a->scripted) glFinish(); // frame times mean finished frames, not queued ones
        wd = sp_now_ms();
        glfwSwapBuffers(a->win);
    }
    double w1 = sp_now_ms();
    for (; a->seen_dropped < dropped && a->up_count > 0; ++a->seen_dropped)
        a->up_head = (a->up_head + 1) % 8, --a->up_count;
    a->seen_dropped = dropped;
    for (; a->seen_fits < fits; ++a->seen_fits) {
        if (a->up_count == 0) continue;
        double up = a->up_wall[a->up_head];
        a->up_head = (a->up_head + 1) % 8, --a->up_count;
        if (a->latency_n == a->latency_cap) {
            int cap = a->latency_cap ? 2 * a->latency_cap : 1024;
            double* l = realloc(a->latency, sizeof *l * (size_t)cap);
            if (!l) continue;
            a->latency = l, a->latency_cap = cap;
        }
        a->latency[a->latency_n++] = w1 - up;
    }
    if (render) {
        int f = a->frames++ % 8192;
        a->frame_ms[f] = w1 - w0, a->update_ms[f] = wu - w0, a->draw_ms[f] = wd - wu, a->swap_ms[f] = w1 - wd;
    }
    if (st->strokes >= a->rss_next_stroke && a->rss_n < 512) {
        a->rss_kb[a->rss_n++] = sp_rss_kb();
        a->rss_next_stroke += 100;
    }
}

// Where the save codes start: two kiosks started in the same second (one
// export folder on a share) start apart; a code is claimed on the disk anyway.
static uint64_t code_seed(void)
{
    char host[256] = "";
    uint64_t h = 1469598103934665603ull; // FNV-1a
    if (gethostname(host, sizeof host - 1) == 0)
        for (const char* c = host; *c; ++c)
            h = (h ^ (unsigned char)*c) * 1099511628211ull;
    return (uint64_t)time(NULL) ^ ((uint64_t)getpid() << 32) ^ h;
}

// An empty --export-dir (an unset variable's name): every Save failed.
static bool export_named(const char* dir)
{
    if (!dir || dir[0]) return true;
    fprintf(stderr, "%s: --export-dir needs a folder name, got an empty value\n", k_cmd);
    return false;
}

// Save makes its folder at the first Save; a file in its place, or a
// nearest folder this user cannot write into, failed every Save with one log
// line (an outside review): said before the window opens.
static bool saves_folder_ok(const char* export_dir)
{
    return sp_cli_check_folder_to_make(k_cmd, "--export-dir", export_dir ? export_dir : "dragon-exports",
                                       "Save writes the visitors' dragons");
}

// The database is read and written, named or not: a recording over it
// replaced it with the session, every visitor's sketch then dropped.
static bool outs_spare_database(const char* db, const char* record, const char* shot, const char* out_glb)
{
    return !sp_cli_out_is_input(k_cmd, "--record", record, "the database", db) &&
           !sp_cli_out_is_input(k_cmd, "--screenshot", shot, "the database", db) &&
           !sp_cli_out_is_input(k_cmd, "--export", out_glb, "the database", db);
}

static double quantile(const double* v, int n, double q)
{
    if (n <= 0) return 0;
    double* s = malloc(sizeof *s * (size_t)n);
    if (!s) return 0;
    memcpy(s, v, sizeof *s * (size_t)n);
    qsort(s, (size_t)n, sizeof *s, sp_cmp_double);
    double r = sp_sorted_quantile(s, n, q);
    free(s);
    return r;
}

// Prints ` "name": "value",` with value JSON-escaped.
static void print_string_field(const char* name, const char* value)
{
    cJSON* v = cJSON_CreateString(value);
    char* text = v ? cJSON_PrintUnformatted(v) : NULL;
    printf(" \"%s\": %s,\n", name, text ? text : "\"\"");
    free(text);
    cJSON_Delete(v);
}

static void print_stats(const app* a, double start_ms)
{
    const sp_kiosk_stats* st = sp_kiosk_stats_of(a->k);
    const sp_kiosk_ui* ui = sp_kiosk_ui_of(a->k);
    int bodies = 0, loose = sp_kiosk_loose_parts(a->k, &bodies);
    int nf = a->frames < 8192 ? a->frames : 8192, nfit = st->fit_count < 4096 ? st->fit_count : 4096;
    printf(
        "{\"parts\": %d, \"strokes\": %d, \"parts_added\": %d, \"rejected\": %d, \"refits\": %d, \"undos\": %d, \"clears\": %d, "
        "\"saves\": %d, \"save_failures\": %d, \"pipeline_errors\": %d, \"reloads\": %d, \"taps\": %d, \"dropped_strokes\": %d, "
        "\"dropped_jobs\": %d, \"resets\": %d, \"offered\": %d, \"chosen\": %d, \"waiting\": %d, \"kept\": %d, \"kept_chosen\": "
        "%d, "
        "\"bodies\": %d, \"loose_parts\": %d, \"mode\": \"%s\", \"code\": \"%s\", \"last_save\": \"%s\",\n",
        st->parts, st->strokes, st->parts_added, st->rejected, st->refits, st->undos, st->clears, st->saves, st->save_failures,
        st->pipeline_errors, st->reloads, ui->taps, ui->dropped_strokes, ui->dropped_jobs, ui->resets, ui->offered, st->chosen,
        st->waiting, st->kept, st->kept_chosen, bodies, loose,
        ui->mode == SP_KM_ATTRACT ? "attract"
        : ui->mode == SP_KM_TURN  ? "turn"
                                  : "draw",
        ui->code, sp_kiosk_last_save(a->k));
    int stored = 0, dropped = 0;
    sp_kiosk_collect_counts(a->k, &stored, &dropped);
    printf(" \"collected\": %d, \"collect_stored\": %d, \"collect_dropped\": %d, \"models_loaded\": %d,\n", st->collected, stored,
           dropped, st->models_loaded);
    printf(" \"others\": %d, \"others_chosen\": %d, \"joined\": %d, \"merged\": %d, \"closed\": %d,\n", ui->others,
           ui->others_chosen, ui->joined, ui->merged, ui->closed);
    // What a visitor reads on screen now (JSON-escaped): the message box
    // (a hint, or the first-draw prompt) and the save banner.
    char banner[2 * SP_KIOSK_TEXT_MAX + 2] = "";
    if (sp_kiosk_ui_banner_visible(ui)) snprintf(banner, sizeof banner, "%s %s", ui->banner[0], ui->banner[1]);
    const char* message = sp_kiosk_ui_message(ui);
    print_string_field("hint", message ? message : "");
    print_string_field("banner", banner);
    printf(" \"framebuffer\": [%d, %d], \"px_per_mm\": %.4f, \"gl_renderer\": \"%s\", \"start_ms\": %.1f, \"frames\": %d, "
           "\"frame_ms_median\": %.2f, \"frame_ms_p90\": %.2f, \"frame_ms_max\": %.2f, \"fit_ms_median\": %.2f, "
           "\"fit_ms_p90\": %.2f, "
           "\"latency_ms_median\": %.2f, \"latency_ms_p90\": %.2f, \"latency_n\": %d, \"update_ms_median\": %.2f, "
           "\"draw_ms_median\": %.2f, \"swap_ms_median\": %.2f,\n \"rss_kb\": [",
           a->fb_w, a->fb_h, a->ppm, (const char*)glGetString(GL_RENDERER), start_ms, a->frames, quantile(a->frame_ms, nf, 0.5),
           quantile(a->frame_ms, nf, 0.9), quantile(a->frame_ms, nf, 1), quantile(st->fit_ms, nfit, 0.5),
           quantile(st->fit_ms, nfit, 0.9), quantile(a->latency, a->latency_n, 0.5), quantile(a->latency, a->latency_n, 0.9),
           a->latency_n, quantile(a->update_ms, nf, 0.5), quantile(a->draw_ms, nf, 0.5), quantile(a->swap_ms, nf, 0.5));
    for (int i = 0; i < a->rss_n; ++i)
        printf("%s%ld", i ? ", " : "", a->rss_kb[i]);
    printf("],\n \"categories\": [");
    const sp_dragon* d = sp_kiosk_dragon(a->k);
    for (int i = 0; i < sp_dragon_part_count(d); ++i)
        printf("%s\"%s\"", i ? ", " : "", sp_dragon_part_get(d, i)->category);
    printf("],\n \"attached_to\": [");
    for (int i = 0; i < sp_dragon_part_count(d); ++i)
        printf("%s%d", i ? ", " : "", sp_dragon_part_get(d, i)->attached_to);
    printf("],\n \"details_on\": [");
    for (int i = 0; i < sp_dragon_detail_count(d); ++i) {
        sp_dragon_detail e;
        sp_dragon_detail_get(d, i, &e);
        printf("%s%d", i ? ", " : "", e.part);
    }
    printf("]}\n");
}

// Building the default database (parts, synthetic sketches, training) takes
// a while the first time: say so on screen instead of showing nothing.
static void loading_screen(GLFWwindow* win, const char* font_path)
{
    sp_error err = {0};
    sp_font* font = sp_font_load(font_path, &err);
    sp_draw2d* d = font ? sp_draw2d_create(font, &err) : NULL;
    int w = 0, h = 0;
    glfwGetFramebufferSize(win, &w, &h);
    glViewport(0, 0, w, h);
    glClearColor(0.81f, 0.83f, 0.875f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    if (d) {
        sp_draw2d_begin(d, w, h);
        sp_draw2d_text_fit(d, sp_kiosk_text(SP_KTEXT_LOADING), 0.5f * w, 0.5f * h, 0.06f * h, 0.9f * w, SP_ALIGN_CENTER,
                           (const float[4]){0.06f, 0.07f, 0.1f, 1});
        sp_draw2d_end(d);
    }
    glfwSwapBuffers(win);
    glfwPollEvents();
    sp_draw2d_destroy(d);
    sp_font_free(font);
}

// Why not under AddressSanitizer: glfwTerminate unloads Mesa's GLX driver,
// after which LeakSanitizer reports the driver's own few hundred bytes as
// leaks of an "<unknown module>" that no suppression can name. Loaded, they
// stay attributable (and reachable). Everything of ours is freed before.
#if defined(__SANITIZE_ADDRESS__)
#define SP_KEEP_GL_DRIVER 1
#endif
static void terminate_glfw(void)
{
#ifndef SP_KEEP_GL_DRIVER
    glfwTerminate();
#endif
}

// The database is about to be built by the default recipe: a line when the
// people's strokes are not there to go in, and the loading screen.
static void announce_build(GLFWwindow* win, const char* assets, const char* font)
{
    char note[1200];
    if (sp_db_people_note(assets, note, sizeof note)) fprintf(stderr, "%s: %s\n", k_cmd, note);
    loading_screen(win, font);
}

// Writes <screenshot stem>-<mark>.png.
static void mark_path(const char* shot, const char* name, char* out, size_t cap)
{
    const char* dot = strrchr(shot, '.');
    const char* slash = strrchr(shot, '/');
    size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - shot) : strlen(shot);
    snprintf(out, cap, "%.*s-%s.png", (int)stem, shot, name);
}

// A database that is there must have parts to draw: checked before any
// window opens, one line when not. One not there is built by the default
// recipe (sp_kiosk_create). A kiosk that collects opens it to write when it
// may, as its collector does, so that an older schema is migrated (the
// read-only open refuses one, and the kiosk would not start on last
// season's database after an upgrade: an outside review).
static bool has_parts(const char* path, const char* assets, bool collect)
{
    struct stat st;
    // Missing, it is built from the assets: without them the kiosk said
    // only "assets: cannot open the folder", after opening its window.
    if (access(path, F_OK) != 0 && (stat(assets, &st) != 0 || !S_ISDIR(st.st_mode))) {
        sp_cli_say("%s: no part database at %s, and no folder '%s' of parts to build one from (give --db DB, or --assets DIR: "
                   "the source tree's assets/)",
                   k_cmd, path, assets);
        return false;
    }
    if (access(path, F_OK) != 0) return true;
    sp_error err = {0};
    sp_db* db = NULL;
    char** cats = NULL;
    int n = 0;
    bool ok = collect && access(path, W_OK) == 0 && sp_db_open(path, 0, &db, &err) == SP_OK;
    if (!ok) err = (sp_error){0}, ok = sp_db_open(path, SP_DB_READONLY, &db, &err) == SP_OK;
    ok = ok && sp_db_categories(db, &cats, &n, &err) == SP_OK;
    if (!ok)
        fprintf(stderr, "%s: %s\n", k_cmd, err.text);
    else if (n == 0)
        fprintf(stderr,
                "%s: %s: no parts to draw (add them with `sketchpose db add-part`, or name a file that is not there to build "
                "the default database)\n",
                k_cmd, path);
    sp_db_free_strings(cats, n);
    sp_db_close(db);
    return ok && n > 0;
}

// The number options in their ranges (one line and false otherwise); those
// not given become the kiosk's defaults (0; --msaa -1: chosen by the renderer).
static bool numbers_ok(int* lod, int* msaa, int* max_parts, int* keep_days, double idle_s)
{
    if (*lod != SP_CLI_UNSET && *lod != -1 && (*lod < 1 || *lod > 10000000)) {
        fprintf(stderr, "%s: --lod must be -1 (all) or 1..10000000, got %d\n", k_cmd, *lod);
        return false;
    }
    if ((*msaa != SP_CLI_UNSET && !sp_cli_check_int(k_cmd, "--msaa", *msaa, 0, 16)) ||
        (*max_parts != SP_CLI_UNSET && !sp_cli_check_int(k_cmd, "--max-parts", *max_parts, 1, 1000)) ||
        (*keep_days != SP_CLI_UNSET && !sp_cli_check_int(k_cmd, "--keep-saves-days", *keep_days, 1, 36500)))
        return false;
    // A typed 0 was the default (90 s): no timeout is asked for by a negative value.
    if (idle_s == 0) {
        fprintf(stderr, "%s: --idle must be more than 0 seconds, or negative: never\n", k_cmd);
        return false;
    }
    if (*lod == SP_CLI_UNSET) *lod = 0;
    if (*msaa == SP_CLI_UNSET) *msaa = -1; // 4, or 1 on a software rasteriser (below)
    if (*max_parts == SP_CLI_UNSET) *max_parts = 0;
    if (*keep_days == SP_CLI_UNSET) *keep_days = 0;
    return true;
}

// The kiosk's window, its context current (NULL, one line said, when none
// opens). Full screen takes the monitor's size into *win_w, *win_h.
static GLFWwindow* open_window(bool fullscreen, bool scripted, int msaa, int* win_w, int* win_h)
{
    glfwSetErrorCallback(cb_error_early);
    if (!glfwInit()) {
        fprintf(stderr,
                "%s: cannot open a window (%s%sno display? run it under xvfb-run, or use `sketchpose dragon` without a window)\n",
                k_cmd, g_glfw_early, g_glfw_early[0] ? "; " : "");
        return NULL;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SAMPLES, msaa >= 0 ? msaa : 4);
    glfwWindowHint(GLFW_STENCIL_BITS, 8);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, scripted ? GLFW_FALSE : GLFW_TRUE);
    GLFWmonitor* mon = fullscreen ? glfwGetPrimaryMonitor() : NULL;
    if (mon) {
        const GLFWvidmode* mode = glfwGetVideoMode(mon);
        if (mode) *win_w = mode->width, *win_h = mode->height;
    }
    GLFWwindow* win = glfwCreateWindow(*win_w, *win_h, "Dragon kiosk", mon, NULL);
    if (win) glfwMakeContextCurrent(win);
    // A software rasteriser clears and shades every sample: without --msaa,
    // its window gets one sample a pixel (the 2D layers are anti-aliased
    // analytically anyway; screenshots still render with 4 samples).
    const char* gl_name = win ? (const char*)glGetString(GL_RENDERER) : NULL;
    if (msaa < 0 && gl_name && (strstr(gl_name, "llvmpipe") || strstr(gl_name, "softpipe") || strstr(gl_name, "swrast"))) {
        glfwMakeContextCurrent(NULL);
        glfwDestroyWindow(win);
        glfwWindowHint(GLFW_SAMPLES, 0);
        win = glfwCreateWindow(*win_w, *win_h, "Dragon kiosk", mon, NULL);
        if (win) glfwMakeContextCurrent(win);
    }
    if (!win) {
        fprintf(stderr, "%s: cannot create an OpenGL 3.3 core window (%s%sinstall libgl1-mesa-dri)\n", k_cmd, g_glfw_early,
                g_glfw_early[0] ? "; " : "");
        glfwTerminate();
        return NULL;
    }
    glfwSetErrorCallback(cb_error);                                  // from now on the log's, the window open
    if (mon) glfwSetInputMode(win, GLFW_CURSOR, GLFW_CURSOR_HIDDEN); // a finger needs no arrow
    return win;
}

// Replays a session on a virtual clock; screenshots at its marks. The exit
// code: a failed mark screenshot is the input's.
static int replay(app* a, const sp_kiosk_session* session, const char* shot, double start, double* first_frame_ms)
{
    int exit_code = SP_EXIT_OK;
    sp_error err = {0};
    // Virtual clock: events at their own times, 60 frames a second of
    // session time, marks and the end hit exactly.
    const double step = 1000.0 / 60.0;
    double t = 0;
    int ei = 0, mi = 0;
    long n = 0;
    for (;;) {
        double target = fmin(t + step, session->end_ms);
        if (mi < session->mark_count && session->marks[mi].t_ms < target) target = session->marks[mi].t_ms;
        if (target < t) target = t;
        for (; ei < session->count && session->events[ei].t_ms <= target; ++ei) {
            sp_kiosk_event ev = sp_kiosk_session_map(session, &session->events[ei], a->fb_w, a->fb_h);
            push_event(a, &ev);
        }
        bool at_end = target >= session->end_ms && ei >= session->count;
        // On screen at 6 frames a second of session time: what a replay
        // decides depends only on the clock, and marks and the end render
        // their own screenshots offscreen.
        frame(a, target, n % 10 == 0 || at_end);
        if (n++ == 0) *first_frame_ms = sp_now_ms() - start;
        glfwPollEvents();
        for (; mi < session->mark_count && session->marks[mi].t_ms <= target; ++mi) {
            // After the first failed screenshot no more are tried: one line
            // says why, not one a mark (the replay still ends, --export and --record too).
            if (!shot || exit_code != SP_EXIT_OK) continue;
            char path[2048];
            mark_path(shot, session->marks[mi].name, path, sizeof path);
            if (sp_kiosk_screenshot(a->k, path, &err) != SP_OK) {
                fprintf(stderr, "%s: %s\n", k_cmd, err.text);
                exit_code = SP_EXIT_INPUT;
            }
        }
        t = target;
        if (at_end || g_quit) break;
    }
    return exit_code;
}

static int run_live(app* a, double start, double* first_frame_ms)
{
    a->t0 = glfwGetTime();
    long n = 0;
    while (!glfwWindowShouldClose(a->win) && !g_quit) {
        double slot = glfwGetTime();
        glfwPollEvents();
        frame(a, live_t(a), true);
        if (n++ == 0) *first_frame_ms = sp_now_ms() - start;
        wait_for_frame(a, slot + 1.0 / 60.0);
    }
    return SP_EXIT_OK;
}

// What the session ends with: the last frame's screenshot, the dragon's
// glTF, the recorded events (each tried; false after any one line said).
static bool write_outputs(app* a, const char* shot, const char* out_glb, const char* record, double end_ms)
{
    sp_error err = {0};
    bool ok = true;
    if (shot && sp_kiosk_screenshot(a->k, shot, &err) != SP_OK) {
        fprintf(stderr, "%s: %s\n", k_cmd, err.text);
        ok = false;
    }
    if (out_glb && sp_kiosk_export(a->k, out_glb, &err) != SP_OK) {
        fprintf(stderr, "%s: %s\n", k_cmd, err.text);
        ok = false;
    }
    if (record) {
        a->rec.end_ms = end_ms;
        if (sp_kiosk_session_write(record, &a->rec, &err) != SP_OK) {
            fprintf(stderr, "%s: %s\n", k_cmd, err.text);
            ok = false;
        }
    }
    return ok;
}

// --size WxH (NULL: the default stays); false after the usage line.
static bool window_size(const char* size, int* w, int* h)
{
    if (!size || sp_cli_parse_size(size, w, h)) return true;
    fprintf(stderr, "%s: --size expects WxH with sides 16..8192, got '%s'\n", k_cmd,
            sp_text_printable(size, (char[160]){0}, 160));
    return false;
}

int main(int argc, char** argv)
{
    ignore_write_signals();
    double start = sp_now_ms();
    const char *db = NULL, *assets = NULL, *script = NULL, *record = NULL, *shot = NULL, *out_glb = NULL, *export_dir = NULL,
               *size = NULL;
    const char* font = NULL;
    bool fullscreen = false, stats = false, no_collect = false;
    double idle_s = NAN, join_ms = NAN; // not given: the kiosk's defaults
    // SP_CLI_UNSET: not given (the kiosk's defaults); given, a value in range.
    int lod = SP_CLI_UNSET, msaa = SP_CLI_UNSET, max_parts = SP_CLI_UNSET, keep_days = SP_CLI_UNSET;
    sp_opt opts[] = {
        {"--db", SP_OPT_STRING, &db, "DB", "part database (default: $SP_DB or sketchpose.db; created from assets/ when missing)",
         false},
        {"--assets", SP_OPT_STRING, &assets, "DIR",
         "parts for a missing database (default: $SP_ASSETS, else the source tree's assets/)", false},
        {"--fullscreen", SP_OPT_FLAG, &fullscreen, "", "full screen on the primary monitor", false},
        {"--size", SP_OPT_STRING, &size, "WxH", "window size (default 1280x800, or the script's canvas)", false},
        {"--script", SP_OPT_IN, &script, "S.json", "replay a session (virtual clock), then exit", false},
        {"--record", SP_OPT_OUT, &record, "R.json", "record the input events to a session file", false},
        {"--screenshot", SP_OPT_OUT, &shot, "out.png", "PNG of the last frame (and of every script mark)", false},
        {"--export", SP_OPT_OUT, &out_glb, "out.glb", "glTF of the dragon at the end", false},
        {"--export-dir", SP_OPT_STRING, &export_dir, "DIR", "where Save writes (default: dragon-exports)", false},
        {"--keep-saves-days", SP_OPT_INT, &keep_days, "N", "remove saves older than N days, 1..36500 (default: keep them)",
         false},
        {"--idle", SP_OPT_DOUBLE, &idle_s, "S", "seconds without input before the attract screen, > 0 (default 90; < 0: never)",
         false},
        {"--join-ms", SP_OPT_DOUBLE, &join_ms, "MS",
         "a stroke begun this soon after the last one's pen-up, where it ended, continues it (default 200; 0 or < 0: never)",
         false},
        {"--font", SP_OPT_IN, &font, "F.ttf", "font (default: DejaVu Sans Bold)", false},
        {"--msaa", SP_OPT_INT, &msaa, "N", "window multisampling, samples 0..16 (default: 4 on a GPU, 0 on software GL)", false},
        {"--lod", SP_OPT_INT, &lod, "N",
         "display triangles per part, 1..10000000 or -1: all (default: 4000 on software GL, all on a GPU)", false},
        {"--max-parts", SP_OPT_INT, &max_parts, "N",
         "parts a dragon may have before new strokes are refused, 1..1000 (default 48)", false},
        {"--no-collect", SP_OPT_FLAG, &no_collect, "",
         "keep no visitors' strokes (default: each part left on the canvas is stored in the database for review)", false},
        {"--stats", SP_OPT_FLAG, &stats, "", "print counters and timings as JSON at the end", false},
    };
    int rc = sp_cli_parse(argc, argv, k_cmd, "The dragon kiosk: draw a part in one line, see it come alive.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_out(k_cmd, "--screenshot", shot, SP_CLI_OUT_PNG) ||
        !sp_cli_check_out(k_cmd, "--export", out_glb, SP_CLI_OUT_GLTF))
        return SP_EXIT_USAGE;
    if (!numbers_ok(&lod, &msaa, &max_parts, &keep_days, idle_s) || !export_named(export_dir)) return SP_EXIT_USAGE;
    if (!outs_spare_database(db ? db : sp_db_default_path(), record, shot, out_glb)) return SP_EXIT_USAGE;
    int win_w = 1280, win_h = 800;
    if (!window_size(size, &win_w, &win_h)) return SP_EXIT_USAGE;
    sp_kiosk_session session = {0};
    sp_error err = {0};
    if (script) {
        if (sp_kiosk_session_read(script, &session, &err) != SP_OK) {
            fprintf(stderr, "%s: %s\n", k_cmd, err.text);
            return SP_EXIT_INPUT;
        }
        if (!size && session.canvas_w > 0 && !session.unit_coords) win_w = session.canvas_w, win_h = session.canvas_h;
    }
    // A mark's screenshot goes beside --screenshot (mark_path): a pipe or a
    // device has no beside.
    if (shot && session.mark_count > 0 && sp_cli_out_is_stream(shot)) {
        fprintf(stderr, "%s: --screenshot %s: the script has marks, each written as <name>-<mark>.png beside it; name a file\n",
                k_cmd, shot);
        sp_kiosk_session_free(&session);
        return SP_EXIT_USAGE;
    }
    // Written when the session ends: a folder that cannot take them is said now.
    if (!sp_cli_check_out_folders(k_cmd, opts, (int)(sizeof opts / sizeof opts[0])) || !saves_folder_ok(export_dir)) {
        sp_kiosk_session_free(&session);
        return SP_EXIT_INPUT;
    }
    if (!has_parts(db ? db : sp_db_default_path(), assets ? assets : sp_dragon_default_assets(), !no_collect)) {
        sp_kiosk_session_free(&session);
        return SP_EXIT_INPUT;
    }
    GLFWwindow* win = open_window(fullscreen, script != NULL, msaa, &win_w, &win_h);
    if (!win) {
        sp_kiosk_session_free(&session);
        return SP_EXIT_INPUT;
    }
    glfwSwapInterval(script ? 0 : 1);
    static app a; // large (frame ring): not on the stack
    a.win = win;
    a.scripted = script != NULL;
    a.ppm_override = script ? session.px_per_mm : 0;
    glfwGetFramebufferSize(win, &a.fb_w, &a.fb_h);
    sp_kiosk_desc kd = {.db_path = db,
                        .assets_dir = assets,
                        .export_dir = export_dir,
                        .font_path = font,
                        .canvas_w = a.fb_w,
                        .canvas_h = a.fb_h,
                        .ui = {.idle_ms = isnan(idle_s) ? 0
                                          : idle_s > 0  ? idle_s * 1000.0
                                                        : -1,
                               // A typed 0 ms joins nothing: never (it was the default, 200).
                               .join_ms = isnan(join_ms) ? 0
                                          : join_ms > 0  ? join_ms
                                                         : -1},
                        .code_seed = script ? 1 : code_seed(),
                        .lod_triangles = lod,
                        .max_parts = max_parts,
                        .keep_saves_days = keep_days,
                        .no_collect = no_collect,
                        // A replay must not depend on the machine's speed: the solver's
                        // wall-clock cap (a visitor's safety net) is lifted; its
                        // iteration caps still bound every fit.
                        .fit_time_cap_ms = script ? 60000 : 0};
    if (access(db ? db : sp_db_default_path(), F_OK) != 0)
        announce_build(win, assets ? assets : sp_dragon_default_assets(), font);
    a.k = sp_kiosk_create(&kd, &err);
    if (!a.k) {
        fprintf(stderr, "%s: %s\n", k_cmd, err.text);
        glfwDestroyWindow(win);
        glfwTerminate();
        sp_kiosk_session_free(&session);
        return SP_EXIT_INPUT;
    }
    if (!sp_dragon_model(sp_kiosk_dragon(a.k)))
        fprintf(stderr, "%s: %s: strokes are refused and the parts row alone makes parts\n", k_cmd,
                sp_dragon_model_error(sp_kiosk_dragon(a.k)));
    glfwSetWindowUserPointer(win, &a);
    relayout(&a);
    glfwSetMouseButtonCallback(win, cb_button);
    glfwSetCursorPosCallback(win, cb_cursor);
    glfwSetWindowFocusCallback(win, cb_focus);
    glfwSetFramebufferSizeCallback(win, cb_resize);
    glfwSetWindowContentScaleCallback(win, cb_scale);
    glfwSetKeyCallback(win, cb_key);
    catch_quit_signals();
    if (record) {
        a.recording = true;
        a.rec.canvas_w = a.fb_w, a.rec.canvas_h = a.fb_h, a.rec.px_per_mm = a.ppm;
    }
    double first_frame_ms = 0;
    int exit_code = script ? replay(&a, &session, shot, start, &first_frame_ms) : run_live(&a, start, &first_frame_ms);
    if (!write_outputs(&a, exit_code == SP_EXIT_OK ? shot : NULL, out_glb, record, script ? session.end_ms : live_t(&a)))
        exit_code = SP_EXIT_INPUT;
    sp_kiosk_close_collection(a.k); // the last visitor's parts, before the counts are printed
    if (stats) print_stats(&a, first_frame_ms);
    sp_kiosk_destroy(a.k);
    glfwDestroyWindow(win);
    terminate_glfw();
    sp_kiosk_session_free(&session);
    sp_kiosk_session_free(&a.rec);
    free(a.latency);
    return exit_code;
}
