/// sp/kiosk.h: the dragon kiosk without its window: UI state machine + pipeline + drawing.
///
/// How to use (dragon_kiosk.c's main loop; a GL 3.3 core context is current):
///
///     sp_kiosk* k = sp_kiosk_create(&(sp_kiosk_desc){.db_path = db, .canvas_w = fb_w, .canvas_h = fb_h}, &err);
///     sp_kiosk_resize(k, fb_w, fb_h, px_per_mm);
///     ... input: sp_kiosk_input(k, &ev);  (pointer events, t_ms on the session clock)
///     ... per frame: sp_kiosk_update(k, now_ms); sp_kiosk_draw(k); swap buffers;
///     sp_kiosk_screenshot(k, "out.png", &err); sp_kiosk_export(k, "out.glb", &err);
///     sp_kiosk_destroy(k);
///
/// sp_kiosk_update runs the UI's jobs against the pipeline (dragon.h): at
/// most one classify+fit, re-fit or save a frame, so a frame never waits for
/// more than one of them. Saving writes <code>.glb and <code>.png (a
/// postcard) into the export folder; <code> is four characters that are
/// easy to read aloud and not already used there.
#ifndef SP_KIOSK_H
#define SP_KIOSK_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/kiosk_ui.h"
#include "sp/result.h"

typedef struct sp_kiosk sp_kiosk;
typedef struct sp_dragon sp_dragon; // dragon.h

/// Free space (MB) on the export folder's disk under which Save is refused:
/// the rest is the database's (visitors' strokes, a curator's `db train`),
/// where saves of 6-12 MB each filled a busy museum's disk in weeks.
#define SP_KIOSK_SAVE_RESERVE_MB 256.0
/// Free space (MB) on the database's disk under which a visitor's stroke is
/// not collected: more than saves keep, so that the room left after both
/// stop is a curator's `db train` (a model of tens of MB, written twice
/// through the WAL).
#define SP_KIOSK_COLLECT_RESERVE_MB 512.0

/// Zero means the default.
typedef struct sp_kiosk_desc {
    const char* db_path;    ///< NULL: sp_db_default_path(); created from assets_dir when missing
    const char* assets_dir; ///< NULL: the pipeline's default ($SP_ASSETS, else "assets")
    const char* export_dir; ///< where Save writes; NULL: "dragon-exports" (created when needed)
    const char* font_path;  ///< NULL: DejaVu Sans Bold
    int canvas_w, canvas_h; ///< the drawing canvas in pixels (the first framebuffer size); 0: 1280 x 800
    sp_kiosk_ui_desc ui;    ///< UI timings and sizes
    uint64_t code_seed;     ///< first save code's seed (0: 1); a live kiosk passes the clock
    bool no_attract_demo;   ///< skip fitting the attract screen's demo dragon (tests of other things)
    double fit_time_cap_ms; ///< the solver's wall-clock cap per part; 0: the pipeline's (250 ms). A replay raises it so results
                            ///< never depend on the machine's speed
    int lod_triangles; ///< display mesh budget per part (lod.h); 0: 4000 on software renderers, full meshes on GPUs; < 0: full
                       ///< meshes
    int max_parts;     ///< parts a dragon may have (sp_dragon_desc.max_parts); 0: the pipeline's (48)
    int keep_saves_days; ///< saves older than this many days are removed, at start and after each save; 0: kept
    double save_reserve_mb;    ///< Save is refused while the export folder's disk, when it is the database's, has less free; 0:
                               ///< SP_KIOSK_SAVE_RESERVE_MB; < 0: none
    double collect_reserve_mb; ///< strokes are not collected while the database's disk has less free; 0:
                               ///< SP_KIOSK_COLLECT_RESERVE_MB; < 0: none
    bool no_collect;   ///< keep no visitors' strokes (default: each part left on the canvas is stored as a pending kiosk
                       ///< sketch; docs/DESIGN.md "Collecting visitors' strokes")
} sp_kiosk_desc;

/// Measurements for logs and benchmarks.
typedef struct sp_kiosk_stats {
    int strokes, parts_added, rejected, refits, undos, clears, saves, save_failures, pipeline_errors, reloads;
    int chosen;            ///< refused strokes made a part by a tap on a guess or the parts row
    int waiting;           ///< parts drawn while no body was on the canvas (told to draw one)
    int kept, kept_chosen; ///< parts on the canvas at a Start over or timeout; of them, labelled by the visitor
    int collected;         ///< strokes handed to the collector (sp_kiosk_collect_counts: stored, dropped)
    int models_loaded;     ///< new models read in the background and put to use (reloads: database changes seen)
    int attract_parts;     ///< parts of the attract screen's demo dragon fitted so far
    int attract_builds;    ///< times the demo was built: once, then again after a curator changed the parts or the file
    double last_fit_ms;    ///< wall time of the last classify+fit (the pipeline's)
    int fit_count;
    double fit_ms[4096]; ///< the last 4096 classify+fit wall times (ring)
    double pose_ms;      ///< last pose_at + mesh update
    int parts;           ///< parts now
    int triangles;       ///< display triangles of the parts' meshes (after LOD)
} sp_kiosk_stats;

/// Opens the database (creating the default one when missing), loads the font,
/// compiles the shaders. NULL and one line in err on failure.
sp_kiosk* sp_kiosk_create(const sp_kiosk_desc* desc, sp_error* err);
void sp_kiosk_destroy(sp_kiosk* k);
/// The framebuffer size and density changed.
void sp_kiosk_resize(sp_kiosk* k, int fb_w, int fb_h, double px_per_mm);
/// One input event (framebuffer pixels; t_ms on the session clock).
void sp_kiosk_input(sp_kiosk* k, const sp_kiosk_event* ev);
/// Advances to t_ms: timers, animation, at most one heavy job, the pose.
void sp_kiosk_update(sp_kiosk* k, double t_ms);
/// Draws the frame into the bound framebuffer (fb_w x fb_h).
void sp_kiosk_draw(sp_kiosk* k);
/// Draws the frame offscreen and writes it as a PNG.
sp_result sp_kiosk_screenshot(sp_kiosk* k, const char* path, sp_error* err);
/// Writes the dragon as glTF (.glb or .gltf); SP_ERR_INVALID when it has no part.
sp_result sp_kiosk_export(sp_kiosk* k, const char* path, sp_error* err);
/// The UI state (read only).
const sp_kiosk_ui* sp_kiosk_ui_of(const sp_kiosk* k);
/// Counters and timings.
const sp_kiosk_stats* sp_kiosk_stats_of(const sp_kiosk* k);
/// Ends collection, as when the kiosk closes (sp_kiosk_destroy does it):
/// the parts still on the canvas are collected and everything queued is
/// written (each sketch waits at most SP_DB_COLLECT_BUSY_MS for the database).
void sp_kiosk_close_collection(sp_kiosk* k);
/// Visitors' strokes the collector has stored in the database and dropped
/// so far (both 0 with no_collect).
void sp_kiosk_collect_counts(const sp_kiosk* k, int* stored, int* dropped);
/// The pipeline (read only: parts, categories).
const sp_dragon* sp_kiosk_dragon(const sp_kiosk* k);
/// The path of the last save (without extension), "" before any.
const char* sp_kiosk_last_save(const sp_kiosk* k);
/// One line of the running kiosk's log on stderr: the UTC time, "dragon-kiosk: "
/// and the message (printf format, no newline), e.g. "2026-12-06T07:30:12Z
/// dragon-kiosk: ...; sketch dropped". Why the time: a kiosk runs for weeks and
/// its log is read after the fact. Safe from any thread.
void sp_kiosk_log(const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/// Parts that are not bodies and do not touch one (their boxes in the
/// drawing view, at the current animation time, 2% apart or more), and in
/// *bodies the bodies: what a visitor sees floating free.
int sp_kiosk_loose_parts(sp_kiosk* k, int* bodies);

#endif
