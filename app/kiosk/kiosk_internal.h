// kiosk_internal.h: the sp_kiosk struct, shared by kiosk.c (jobs, saving),
// kiosk_draw.c (the frame), kiosk_attract.c (the attract screen's demo) and
// kiosk_row.c (the parts offered with a refused stroke).
#ifndef SP_KIOSK_INTERNAL_H
#define SP_KIOSK_INTERNAL_H

#include <sys/types.h>

#include "sp/dragon.h"
#include "sp/draw2d.h"
#include "sp/font.h"
#include "sp/kiosk.h"
#include "sp/kiosk_lod.h"
#include "sp/render.h"

/// Render meshes of one dragon's parts, by part id (coarsened when lod_triangles > 0).
typedef struct mesh_cache {
    struct cached_mesh {
        uint64_t id;
        const void* character; ///< the part's character: a part keeps its id when a body drawn later changes it
        sp_render_mesh* mesh;
        bool seen;
        bool coarse;
        sp_lod lod;
        int triangles; ///< drawn
    } * items;
    int count, cap;
    int lod_triangles; ///< triangle budget per part; 0: full meshes
    double* scratch;   ///< coarse positions
    int scratch_cap;
} mesh_cache;

/// The chips of each part (the pipeline keeps its stroke, not its guesses).
typedef struct part_guesses {
    uint64_t id;
    char guess[2][SP_NAME_MAX];
    bool chosen; ///< the visitor chose its category (a guess chip, or a part for a refused stroke)
    // The stroke as the visitor drew it, for collection: canvas pixels and
    // ms since its first point (NULL when not kept).
    sp_vec2* xy;
    double* t;
    int n;
} part_guesses;

/// A part a chip or a Redraw replaced, for Undo to bring back while the
/// part that replaced it is the last change.
enum { KIOSK_REPLACED_MAX = 8 };
typedef struct replaced_part {
    uint64_t replaced, by; ///< the part's id, and its replacement's
    char category[SP_NAME_MAX];
    bool chosen; ///< its category was a chip's (else the classifier's: fitted again as classified)
    char guess[2][SP_NAME_MAX];
    // A Redraw's: the part's own stroke (canvas pixels, as fitted) and the
    // one kept for collection (NULL: a chip's, the stroke is the same).
    sp_vec2* stroke;
    int stroke_n;
    part_guesses kept;
} replaced_part;

/// The writer of visitors' strokes (kiosk_collect.c): a thread with its own
/// database handle, so that the frame loop never waits for the database.
typedef struct kiosk_collector kiosk_collector;

/// One stroke of the attract screen's demo dragon.
typedef struct demo_part {
    char category[SP_NAME_MAX];
    sp_vec2* xy; // canvas pixels
    int n;
    int part; // index in the demo dragon, -1 until fitted (or when it failed)
    bool tried;
    float* outline; // canvas pixels at the fit (outline_n by 2), with curve breaks
    int outline_n, outline_cap, breaks[16], break_n;
} demo_part;

enum { DEMO_MAX = 8 };

/// One button of the refusal's parts row: a category's outline at rest.
typedef struct part_icon {
    char category[SP_NAME_MAX];
    float* xy; ///< n by 2 in the unit square (y down), centred, aspect kept
    int n, breaks[8], break_n;
} part_icon;

struct sp_kiosk {
    sp_kiosk_desc desc;
    char db_path[1024], export_dir[1024];
    bool prune_checked, prune_held; // kiosk_prune_saves: the clock looked at its first call; saves kept this run
    sp_kiosk_ui* ui;
    sp_dragon* dragon;
    sp_renderer* r;
    sp_font* font;
    sp_draw2d* d2;
    int fb_w, fb_h;
    double area[4]; // where the pipeline takes strokes, canvas pixels: every drawing area of the run so far
    double ppm;
    int canvas_w, canvas_h;
    sp_camera canvas_cam; // the pipeline's world camera on its canvas
    mesh_cache meshes;
    part_guesses* guesses;
    int guess_count, guess_cap;
    replaced_part replaced[KIOSK_REPLACED_MAX]; // newest last
    int replaced_n;
    kiosk_collector* collector;          // NULL: collection off (--no-collect) or closed
    int collect_stored, collect_dropped; // the collector's counts when it closed
    uint64_t rev;                        // grows with every change of the dragon
    uint64_t posed_rev;                  // rev and time of the last pose_at
    double posed_t;
    bool posed;
    // The attract screen's demo dragon.
    sp_dragon* demo;
    mesh_cache demo_meshes;
    demo_part demo_parts[DEMO_MAX];
    int demo_count;
    bool demo_prepared;
    bool demo_stale;   // the parts or the database file changed since it was built
    char* demo_source; // kiosk_row_source of the parts it was built from (NULL: not read)
    dev_t demo_dev;  // the database file it was built from
    ino_t demo_ino;
    int updates;   // sp_kiosk_update calls (the demo waits for the first frame)
    bool software; // a software rasteriser (llvmpipe): cheaper background, coarser meshes
    double demo_posed_t;
    int demo_posed_parts;
    // The refusal's parts row (kiosk_row.c), in the UI's row order.
    part_icon icons[SP_KIOSK_ROW_MAX];
    int icon_count;
    bool icons_loaded;
    char* row_source;  // what the icons were drawn from (kiosk_row.c); NULL: read them again
    bool parts_loaded; // every part of the database is loaded (sp_dragon_preload_step said so)
    // Bookkeeping.
    sp_kiosk_stats stats;
    uint64_t code_state;
    char last_save[1100];
    double last_reload_check;
    char db_problem[sizeof(sp_error){0}.text]; // the database problem last logged ("": none), said once until it changes or ends
    uint64_t reloads_seen; // sp_dragon_reload_count when the parts row and parts were last reloaded
    bool heavy_done; // a heavy job ran in this update
    bool save_shown; // a frame was drawn since the Save job was queued (its hint and the Save button's state)
    sp_vec2* scratch;
    int scratch_cap;
    float* outline_px;
    int outline_cap;
    float* scene_px; // the parts' strokes for the chips to keep clear of (framebuffer pixels, by 2)
    int scene_cap;
    int breaks[64];
};

// kiosk.c
/// Canvas pixels -> framebuffer pixels and back (the canvas is scaled to fit, centred).
sp_vec2 kiosk_canvas_to_fb(const sp_kiosk* k, sp_vec2 c);
sp_vec2 kiosk_fb_to_canvas(const sp_kiosk* k, sp_vec2 p);
/// The pipeline camera on the current framebuffer.
sp_camera kiosk_fb_camera(const sp_kiosk* k);
/// A part's abstraction as fitted (its parameters, its own view), in canvas
/// pixels: out (grown as needed) gets n points, breaks[] the curve starts. Returns n.
int kiosk_fitted_outline(const sp_dragon_part* p, float** out, int* cap, int* breaks, int max_breaks, int* nbreaks);
/// Triangles the cached meshes draw.
int mesh_cache_triangles(const mesh_cache* c);
/// The same for any rig's abstraction at parameters params, projected by view.
int kiosk_outline(const sp_rig* rig, int abstraction, const double* params, const sp_camera* view, float** out, int* cap,
                  int* breaks, int max_breaks, int* nbreaks);
/// Loads the first part of a category from db (*abstraction: the one its sketches are drawn of). SP_ERR_INVALID: none.
sp_result kiosk_load_category_part(sp_db* db, const char* category, sp_character* ch, int* abstraction, sp_error* err);
/// MB free to this user on the disk holding path; < 0 when unknown (kiosk_save.c).
double kiosk_free_mb(const char* path);

// kiosk_collect.c
/// Opens db_path for writing (migrating an older schema) and starts the
/// writer. A database that cannot be written gives one line on stderr and a
/// collector that drops every sketch with one line each. NULL: out of memory.
/// A stroke is dropped while the database's disk has under reserve_mb free (<= 0: never).
kiosk_collector* kiosk_collector_open(const char* db_path, double canvas_w, double canvas_h, double reserve_mb);
/// Queues one stroke (copied; t may be NULL) as a pending kiosk sketch of
/// category. Never waits for the database; what cannot be stored is dropped
/// with one line on stderr.
void kiosk_collector_push(kiosk_collector* c, const char* category, const sp_vec2* xy, const double* t, int n);
/// Sketches stored and dropped so far.
void kiosk_collector_counts(kiosk_collector* c, int* stored, int* dropped);
/// Writes what is still queued, stops the writer, closes the handle (NULL is
/// fine); *stored and *dropped get the final counts.
void kiosk_collector_close(kiosk_collector* c, int* stored, int* dropped);
/// Whether two reasons for dropping a sketch are alike but for their numbers
/// (said once with a count): the free space a full disk's reason names
/// changed with every sketch, and each was said anew (an outside review).
bool kiosk_same_reason(const char* a, const char* b);
/// Brings the cached meshes in step with d's parts at its last pose_at.
void mesh_cache_sync(mesh_cache* c, sp_renderer* r, const sp_dragon* d, bool update_positions);
void mesh_cache_free(mesh_cache* c);
sp_render_mesh* mesh_cache_get(const mesh_cache* c, uint64_t id);

// kiosk_draw.c
/// The attract screen's room for its demo dragon on a framebuffer H pixels
/// tall (y down): from under its title (top) to above "Touch to start" (bottom).
void kiosk_attract_band(const sp_kiosk_ui* ui, float H, float* top, float* bottom);
/// Draws the frame into the bound framebuffer of w x h pixels.
void kiosk_draw_frame(sp_kiosk* k, int w, int h);
/// Renders the postcard (the dragon framed, a title and the code) into img.
sp_result kiosk_postcard(sp_kiosk* k, const char* code, sp_image* img, sp_error* err);
/// kiosk_save.c: Save now (the export, the postcard, the banner; refused when
/// the export folder's disk is under its reserve).
void kiosk_run_save(sp_kiosk* k);
/// The next free save code of k's sequence, claimed by making <code>.glb
/// (empty, O_EXCL) in the export folder; refused, never reused, when
/// none of 1000 is free.
sp_result kiosk_claim_code(sp_kiosk* k, char code[8], sp_error* err);
/// Removes the saves older than desc.keep_saves_days (0: none), with one line.
void kiosk_prune_saves(sp_kiosk* k);

// kiosk_row.c
/// Loads every category's outline from the database and gives the UI its row of parts.
void kiosk_row_load(sp_kiosk* k);
/// Draws the row's visible buttons (inside a draw2d batch); the last part's
/// own category green while the row is open for it.
void kiosk_row_draw(sp_kiosk* k, const float navy[4], const float yellow[4], const float ink[4], const float green[4]);
void kiosk_row_free(sp_kiosk* k);
/// What the row (and the attract screen's demo) is drawn from: the categories
/// and every part's name, category, abstraction and checksum, one line each
/// (malloc'd; NULL when they cannot be read, or no memory).
char* kiosk_row_source(sp_db* db, char* const* cats, int n);

// kiosk_attract.c
/// Builds the demo strokes (once) and fits at most one demo part (when no heavy job ran).
void kiosk_attract_update(sp_kiosk* k);
/// The camera of the attract screen (the canvas, depth fitted to the demo dragon).
sp_camera kiosk_attract_camera(sp_kiosk* k);
/// Draws the attract screen's demo: strokes being drawn, outlines, parts coming alive.
void kiosk_attract_draw_scene(sp_kiosk* k);
void kiosk_attract_free(sp_kiosk* k);
/// After a curator's change (k->demo_stale): drops the demo, which is built
/// again, in a frame with room, from the database as it is now; its pipeline
/// no longer holds a replaced file open.
void kiosk_attract_rebuild(sp_kiosk* k);

#endif
