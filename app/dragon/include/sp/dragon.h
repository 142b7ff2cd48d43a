/// dragon.h: the kiosk pipeline without a window: strokes in, a growing,
/// animated dragon of rigged parts out.
///
/// How to use (the kiosk window, `sketchpose dragon`, tests):
///
///     sp_error err = {0};
///     sp_dragon* d;
///     if (sp_dragon_create(&(sp_dragon_desc){.db_path = "sketchpose.db", .canvas_w = 1280, .canvas_h = 800}, &d, &err) != SP_OK)
///         ... fprintf(stderr, "%s\n", err.text) ...
///     sp_dragon_result res;
///     if (sp_dragon_add_stroke(d, &stroke, NULL, &res, &err) != SP_OK) ... bad numbers: err.text ...
///     else if (res.rejected) ... a friendly hint (res.reason); nothing changed ...
///     else ... res.guesses[0..2] are the chips, res.part the new part ...
///     sp_dragon_pose_at(d, t_seconds);                      // every part, animated and attached
///     for (int i = 0; i < sp_dragon_part_count(d); ++i) {
///         const sp_dragon_part* p = sp_dragon_part_get(d, i);  // p->character->rig.triangles, ->colors
///         draw(sp_dragon_part_xyz(d, i), ...);                // world space, vertex_count by 3
///     }
///     sp_dragon_export(d, "dragon.glb", &err);
///     sp_dragon_destroy(d);
///
/// The shared world (one for the whole dragon, so that parts drawn in
/// different places end up in those places): right-handed, y up, z towards
/// the viewer. The drawing canvas (canvas_w x canvas_h pixels, origin top
/// left, y down) is the front orthographic view of the plane z = 0 looking
/// along -Z, centred on the origin, the canvas height spanning 2 world units:
///     x = (u - canvas_w / 2) / s,  y = (canvas_h / 2 - v) / s,  s = canvas_h / 2 pixels per unit.
/// sp_dragon_camera gives that camera (sp_camera_project maps world to
/// canvas pixels exactly), so rendering with it puts each part under its
/// stroke; the kiosk's Turn orbits a copy of it.
///
/// Placement: a part is fitted in its own sketch view (the glTF's camera, or
/// the default front view), zoomed and panned so that its rest-pose
/// abstraction covers the stroke's bounding box (same centre, same
/// diagonal); the solver then fits shape and pose (with the root's own
/// placement parameters if the part has them). Because both views are
/// orthographic, the part's model space maps into the world by a
/// similarity (rotation, uniform scale, translation) that makes the two
/// projections agree: the 3D part lands exactly where its fitted outline
/// was drawn, with its rest-pose centre at depth z = 0. A perspective
/// part camera is replaced by its weak-perspective (orthographic) equivalent
/// at the depth of the rest-pose centre. A part that reaches sideways from
/// its attachment end (a head, a tail) is also fitted facing the other way
/// (the stroke mirrored left-right; placed, the part is turned half round
/// the vertical axis, still a similarity): the facing its socket hints at
/// (a head drawn at the tail end of a body faces away from it) is kept
/// unless the other fits clearly better (mean error under 0.8 times).
///
/// Attachment: a part that is not a body (a body: category "torso", or
/// sockets in its `sp_part`) attaches to the body whose surface, seen on the
/// canvas at the fits, comes nearest its attachment end (`sp_part.attach`:
/// a joint and a point; default: the root joint's origin), when that is
/// within `snap_fraction` of the canvas diagonal; farther from every body it
/// stays free where it was drawn. The attachment end moves onto that
/// surface point (not at all when drawn over the body, where the nearest
/// point is under it): on the body's near side (its visible surface), or on
/// its far side for a second part of a kind drawn at the same place (their
/// strokes' boxes overlap with IoU >= 0.3; a third goes near again), so
/// two parts drawn at the same place do not z-fight; the body's socket for
/// the category (if any) says which side the first one takes (the far side
/// when the socket lies behind the body's middle). The body's joints that
/// skin that surface point (the corners' skin weights blended by its
/// barycentric coordinates) carry the part: at every time its attachment
/// end is the skinned surface point and it turns and scales with the
/// blended skin matrix (its nearest similarity), so it rides the body's
/// animation with no gap. A body whose triangles have no area cannot hold
/// a part: one drawn there stays free (sp_dragon_result.note says so).
/// Attachments are recomputed when the bodies change, so a body drawn last
/// still collects the parts drawn before it, and undoing it frees them.
///
/// Animation: each part's first glTF animation clip, applied as offsets on
/// its fitted parameters: p(t) = clamp(p_fit + clip(t') - rest) for
/// angles and translations, p_fit * clip(t') / rest for scales, rest being
/// the rig's default parameters (the clips are keyed as offsets from rest),
/// so a part moves about its fitted pose (at t = 0 it is off the fit by
/// the clip's first offsets). Clips loop together with one
/// period T (the longest clip): a clip of duration c repeats n = round(T / c)
/// times in T, slightly retimed, so the whole dragon loops seamlessly and
/// the export holds ONE animation of length T.
///
/// Live update: before each stroke (and on sp_dragon_reload_if_changed) the
/// database generation is polled; a new model or part is used for the next
/// stroke (desc.background_model: the first stroke after it has been read).
/// A database file replaced on disk (a new inode) is reopened. Parts
/// already on the canvas keep the rig they were fitted with. A failed reload
/// keeps the previous model and parts (the kiosk keeps running).
///
/// Not thread-safe: one sp_dragon is used by one thread at a time.
#ifndef SP_DRAGON_H
#define SP_DRAGON_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/classifier.h"
#include "sp/gltf.h"
#include "sp/partdb.h"
#include "sp/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Ranked guesses kept per stroke (the label chip and two alternatives).
enum { SP_DRAGON_GUESSES = 3 };
/// Strokes longer than this are resampled to it (arc length) before classifying and fitting.
enum { SP_DRAGON_MAX_STROKE_POINTS = 4096 };

typedef struct sp_dragon sp_dragon;

/// Options. Zero means the default.
typedef struct sp_dragon_desc {
    sp_db* db;              ///< an open database to use (not owned, must outlive the dragon); NULL: open db_path
    const char* db_path;    ///< NULL: sp_db_default_path(); created from assets_dir when missing
    const char* assets_dir; ///< parts for a missing default database; NULL: sp_dragon_default_assets()
    int canvas_w, canvas_h; ///< drawing canvas, pixels; 0: 1280 x 800
    sp_solve_desc solve; ///< solver options; zero: the solver's defaults except time_cap_ms 250, representatives 100, samples 48
    double min_confidence; ///< a top guess scoring below this is rejected too; 0: 0.0 (only the classifier's own rejection)
    double snap_fraction;  ///< how near a body a part attaches, fraction of the canvas diagonal; 0: 0.06; < 0: never attach
    int max_variants;      ///< parts of one category fitted per stroke, best kept; 0: 4
    double fps;            ///< key rate of the exported animation, per second; 0: 30
    int max_parts;         ///< a stroke beyond this many parts is rejected (a kiosk runs all day); 0: 48
    bool no_model;         ///< every stroke names its category (the attract screen's demo): the model is never loaded
    /// A new model (once one is in use, and the database is the pipeline's
    /// own: db_path) is read on a thread of its own, and the pipeline goes on
    /// with the one it has until sp_dragon_model_update takes it (a kiosk's
    /// frames go on); false: read at the poll that finds it.
    bool background_model;
} sp_dragon_desc;

/// Why a stroke left the dragon unchanged.
typedef enum sp_dragon_reject {
    SP_DRAGON_ACCEPTED = 0,
    SP_DRAGON_TOO_SHORT,    ///< fewer than 2 points, smaller than 1% of the canvas (a tap), or a part smaller than
                            ///< SP_DRAGON_PART_MIN
    SP_DRAGON_UNRECOGNISED, ///< refused by the kiosk's policy (a scribble, or far from every part: docs/DESIGN.md), or the top
                            ///< score < min_confidence
    SP_DRAGON_NO_PART,      ///< the category has no part in the database (or none loads)
    SP_DRAGON_NO_MODEL,     ///< the database has no trained model and no category was forced
    SP_DRAGON_FIT_FAILED,   ///< every part of the category refused the stroke
    SP_DRAGON_NOTHING_TO_REFIT, ///< sp_dragon_refit_last with no stroke kept
    SP_DRAGON_FULL,             ///< max_parts parts already (Redraw, refit, undo and clear still work)
    SP_DRAGON_DETAIL,           ///< a small stroke drawn on a part (an eye): a detail, kept as ink on it (guesses filled)
} sp_dragon_reject;

/// "accepted", "too_short", "unrecognised", "no_part", "no_model", "fit_failed", "nothing_to_refit", "full", "detail".
const char* sp_dragon_reject_name(sp_dragon_reject r);

/// What else a visitor should be told about a stroke.
typedef enum sp_dragon_note {
    SP_DRAGON_NOTE_NONE = 0,
    SP_DRAGON_NOTE_NO_SURFACE, ///< accepted, drawn at a body whose triangles have no area: the part stays free where drawn
    SP_DRAGON_NOTE_NOT_FINITE, ///< a fit gave numbers that are not finite and was dropped (fit_failed when none was left)
} sp_dragon_note;

/// "none", "no_surface", "not_finite".
const char* sp_dragon_note_name(sp_dragon_note n);

/// A ranked category.
typedef struct sp_dragon_guess {
    char category[SP_NAME_MAX];
    float confidence; ///< the classifier's vote share in [0, 1]; 1 when forced
} sp_dragon_guess;

/// One part of the dragon (read only; valid until the next change).
typedef struct sp_dragon_part {
    uint64_t id;            ///< unique for the dragon's lifetime (cache render meshes by it)
    char name[SP_NAME_MAX]; ///< the database part
    char category[SP_NAME_MAX];
    float confidence;              ///< of the category (1 when forced)
    const sp_character* character; ///< the rig, triangles, colours (shared by parts of the same database part)
    int abstraction;               ///< index of the abstraction fitted
    const double* params;          ///< fitted parameters (rig.param_count)
    sp_solve_report report;        ///< the fit
    sp_camera view;                ///< the part's own zoomed sketch view on the canvas (the fit's, turned when mirrored)
    bool mirrored;                 ///< fitted facing the other way (the stroke mirrored left-right)
    sp_mat4 placement;             ///< part model space -> world at the fit (the similarity above), before attachment
    bool is_torso;                 ///< a body (carries other parts)
    sp_vec2 attach_end;            ///< its attachment end (sp_part.attach) on the canvas as fitted, pixels
    int attached_to;               ///< index of the body it hangs on, -1: free
    sp_vec2 anchor;                ///< where it attaches: the body's surface point on the canvas, pixels (NaN when free)
    bool far_side;                 ///< attached on the body's far side
    char socket[SP_NAME_MAX];      ///< the body's socket that hinted its side and facing, "" when none
    int carrier_joint;             ///< the body's joint weighing most in carrying it, when attached
    int stroke_points;             ///< the stroke as fitted (after cleaning): stroke_points by 2 in stroke_xy
    const sp_vec2* stroke_xy;
} sp_dragon_part;

/// What one stroke did.
typedef struct sp_dragon_result {
    bool rejected; ///< no part was added or changed (see reason); only a detail may have been kept (detail)
    sp_dragon_reject reason;
    sp_dragon_note note; ///< what else to tell (also when accepted)
    int guess_count;     ///< ranked categories (0..SP_DRAGON_GUESSES), also when rejected by the classifier; the accepted part's first (the fit re-ranks them)
    sp_dragon_guess guesses[SP_DRAGON_GUESSES];
    int part;                             ///< index of the new (or replaced) part, -1 when rejected
    int detail;                           ///< SP_DRAGON_DETAIL: the detail kept as ink, -1 when none (full, nothing bound)
    double ms_classify, ms_fit, ms_total; ///< wall-clock, milliseconds
    /// How far the stroke is from every part, as the refusal policy weighs it
    /// (docs/DESIGN.md, "Refusal policy"): refused as unrecognised above
    /// SP_DRAGON_FAR_LIMIT. NaN when not measured: a forced category, no model,
    /// or a stroke decided before its best guess was fitted (a tap, a
    /// scribble, a polygon, a detail). For benchmarks that sweep the limit.
    double far_score;
} sp_dragon_result;

/// The refusal policy's limit on sp_dragon_result.far_score.
#define SP_DRAGON_FAR_LIMIT 1.23
/// The smallest part a stroke makes, its box's diagonal over the canvas's
/// (3.5%: 49 px, 13 mm, on the kiosk's 1280 x 800): smaller, and not a
/// detail on a part nor chosen by a chip, it is SP_DRAGON_TOO_SHORT.
#define SP_DRAGON_PART_MIN 0.035

/// How to treat one stroke. Zero (or a NULL pointer) means: classify, append.
typedef struct sp_dragon_stroke_opts {
    const char* category; ///< use this category instead of classifying (the guesses are still filled)
    bool replace_last;    ///< the stroke replaces the last part (Redraw); a rejected stroke keeps it
    bool replace_detail;  ///< a chip for a detail: an accepted part takes the place of the last change if it is a detail
} sp_dragon_stroke_opts;

/// Opens the database (creating the default one when missing), loads the
/// newest model. On failure *out is NULL and err has one line. A database
/// without a model still opens (strokes then need a forced category).
sp_result sp_dragon_create(const sp_dragon_desc* desc, sp_dragon** out, sp_error* err);
/// The parts' folder for a missing default database when the desc names none: $SP_ASSETS, else the source tree's assets/.
const char* sp_dragon_default_assets(void);
/// Frees everything (NULL is fine). Does not close a caller's database.
void sp_dragon_destroy(sp_dragon* d);

/// Where strokes may lie, canvas pixels (x0, y0 to x1, y1; default, and for
/// an empty or non-finite box: the canvas). A kiosk window resized after the
/// start shows the canvas scaled into it, and its drawing area then reaches
/// beyond the canvas: clamped onto the canvas, a wing drawn there was fitted
/// flat on its edge (an outside review).
void sp_dragon_set_stroke_area(sp_dragon* d, double x0, double y0, double x1, double y1);

/// Classifies one stroke (pixels on the canvas), instantiates the part of
/// that category and fits it (shape and pose), attaches it. Points outside
/// the stroke area (the canvas by default) are clamped onto its edge; more than SP_DRAGON_MAX_STROKE_POINTS
/// are resampled. Returns SP_ERR_INVALID (nothing changed) for non-finite
/// coordinates; every other unusable stroke is SP_OK with out->rejected.
sp_result sp_dragon_add_stroke(sp_dragon* d, const sp_stroke* stroke, const sp_dragon_stroke_opts* opts, sp_dragon_result* out,
                               sp_error* err);
/// Same from a point array (xy: count by 2, pixels).
sp_result sp_dragon_add_points(sp_dragon* d, const sp_vec2* xy, int count, const sp_dragon_stroke_opts* opts,
                               sp_dragon_result* out, sp_error* err);
/// A chip tap: re-fits the last part's stroke as `category` (replacing that
/// part); NULL: the stroke classified again, as a Redraw of it would be
/// (Undo of a chip that replaced a classified part). Rejected (nothing
/// changed) when there is no part or no part of that category.
sp_result sp_dragon_refit_last(sp_dragon* d, const char* category, sp_dragon_result* out, sp_error* err);
/// Removes the last change: the last detail when it came after the last
/// part, else the last part; false when there was neither.
bool sp_dragon_undo(sp_dragon* d);
/// Removes every part and detail.
void sp_dragon_clear(sp_dragon* d);

/// Details: a stroke refused as SP_DRAGON_DETAIL (an eye, spots, scales on
/// a part; fire from a mouth, a spade at a tail's tip drawn out of one) is
/// kept as ink on its part, at most SP_DRAGON_MAX_DETAILS of them. Each point
/// is bound to the part's mesh where the visitor drew it (the front-most
/// triangle under it at the fit as shown, barycentric; a point just off the
/// mesh to the nearest triangle near it); a flourish's points off the mesh
/// are carried in the air by the part's skin where the stroke leaves it. So
/// the ink rides the part's animation. A detail lives as long as its part:
/// a Redraw or chip that replaces the part drops it; while a later part has
/// the part fitted as another template or facing (legs made the other legs,
/// a part turned) it is not shown. The export writes each detail shown as a
/// line on its part's skin.
enum { SP_DRAGON_MAX_DETAILS = 256, SP_DRAGON_DETAIL_POINTS = 128 };
typedef struct sp_dragon_detail {
    uint64_t id;          ///< unique for the dragon's lifetime, from the same counter as parts' (later = larger)
    int part;             ///< index of the part it is drawn on
    int point_count;      ///< points bound (2..SP_DRAGON_DETAIL_POINTS)
    const double* xyz;    ///< at the last pose_at: world, point_count by 3; NULL when not posed or not shown
    const double* normal; ///< at the last pose_at: unit surface normal under each point, to the side drawn on; 0 in the air
} sp_dragon_detail;
/// Number of details, oldest first.
int sp_dragon_detail_count(const sp_dragon* d);
/// Detail i (0 <= i < count); false for a bad i.
bool sp_dragon_detail_get(const sp_dragon* d, int i, sp_dragon_detail* out);

/// Number of parts, in drawing order.
int sp_dragon_part_count(const sp_dragon* d);
/// Part i (0 <= i < count).
const sp_dragon_part* sp_dragon_part_get(const sp_dragon* d, int i);
/// The world camera on the canvas (see the top of this file).
sp_camera sp_dragon_camera(const sp_dragon* d);
/// The loop period in seconds (0 when no part has an animation).
double sp_dragon_period(const sp_dragon* d);

/// Evaluates every part at time t (seconds, wrapped into the loop): its
/// animated parameters, its attachment, its skinned vertices and abstraction
/// in world space, readable with the calls below until the next pose_at,
/// change, report or export (then NULL). t is also the time the dragon is
/// shown at (0 before any call): a detail drawn next is bound to its part as
/// posed then, where the visitor saw it. SP_ERR_NO_MEMORY is the only failure.
sp_result sp_dragon_pose_at(sp_dragon* d, double t, sp_error* err);
/// Part i's vertices at the last pose_at, world, rig.vertex_count by 3.
const double* sp_dragon_part_xyz(const sp_dragon* d, int i);
/// Part i's fitted abstraction at the last pose_at, world, point_count by 3
/// (draw with sp_renderer_draw_abstraction and the part's abstraction).
const double* sp_dragon_part_outline(const sp_dragon* d, int i);
/// Part i's fitted abstraction where it was fitted, before attachment moved
/// it: canvas pixels (xy: point_count entries, the part's abstraction's
/// point order), for the yellow overlay shown over the stroke right after
/// the fit. Returns the point count (xy NULL: only the count), 0 for a bad i.
int sp_dragon_part_fitted_outline(const sp_dragon* d, int i, sp_vec2* xy);
/// Part i's parameters at the last pose_at (rig.param_count).
const double* sp_dragon_part_params(const sp_dragon* d, int i);
/// Part i's model -> world transform at the last pose_at (placement, attachment
/// and the torso's motion), or NULL. Vertices above are already transformed.
const sp_mat4* sp_dragon_part_transform(const sp_dragon* d, int i);
/// World bounds of every vertex at the last pose_at; false when there are no parts.
bool sp_dragon_bounds(const sp_dragon* d, sp_vec3* lo, sp_vec3* hi);

/// Writes one glTF (.glb, or .gltf with embedded buffers by extension) with
/// every part (each its own skin under its placement node) in the world
/// above moved so that the dragon's box at t = 0 is centred at the origin,
/// a camera node "view" that frames it (orthographic, looking along -Z like
/// the canvas), the details shown as lines on their parts' skins ("<part>/ink<k>"),
/// and ONE looped animation of length sp_dragon_period holding
/// the joints' offsets and the attached parts' placements as their bodies
/// move (none when no part animates). Fails with SP_ERR_INVALID when there
/// are no parts. Poses the dragon at its key times (non-const: the parts'
/// pose buffers are reused; pose it again before reading poses).
sp_result sp_dragon_export(sp_dragon* d, const char* path, sp_error* err);

/// Polls the database: when another connection committed a change (or the
/// file was replaced), reloads the model and forgets the loaded parts that
/// were removed or changed (a part whose stored bytes are the same is kept). *reloaded
/// (may be NULL) tells whether anything was reloaded. On failure the previous
/// state is kept and err says why.
sp_result sp_dragon_reload_if_changed(sp_dragon* d, bool* reloaded, sp_error* err);
/// How many changes of the database the pipeline has taken in so far, by
/// sp_dragon_reload_if_changed or by a stroke's own poll: a caller that keeps
/// something drawn from the parts (the kiosk's parts row) compares it.
uint64_t sp_dragon_reload_count(const sp_dragon* d);
/// With desc.background_model: takes the model read in the background when
/// its read has ended (and starts reading a newer one stored meanwhile); true
/// when the pipeline's model changed. Cheap when there is nothing to take:
/// call it every frame. Polls and strokes take it too.
bool sp_dragon_model_update(sp_dragon* d);
/// Whether a model is being read in the background, or read and not yet taken.
bool sp_dragon_model_loading(const sp_dragon* d);
/// Loads every part of the database now (parsing, checksum, the solver's
/// coarsening), so that the first stroke of each category costs no more than
/// the others; otherwise each part is loaded by the first stroke that needs it.
/// Parts that do not load are skipped (err says the last reason, SP_OK still).
sp_result sp_dragon_preload(sp_dragon* d, sp_error* err);
/// One step of it: loads the next part neither loaded nor tried since the
/// last change of the database, and returns; *done is true when no part
/// was left to load (then nothing was done). A caller with frames to keep
/// short (the kiosk, while nobody draws) loads one part a frame. A part
/// that does not load is tried once (err says why, SP_OK still).
sp_result sp_dragon_preload_step(sp_dragon* d, bool* done, sp_error* err);
/// How many of the database's parts are loaded now.
int sp_dragon_loaded_parts(const sp_dragon* d);
/// Why a database part that the last stroke needed (or the last preload
/// step tried) did not load, naming it; "" when none failed. A category
/// whose parts all fail gives SP_DRAGON_NO_PART, and this says why. A part
/// that does not load is not tried again until the database changes.
const char* sp_dragon_part_error(const sp_dragon* d);
/// Whether a part of the category is in the database and loads (what a
/// guess needs to become a part: the model may still rank a category whose
/// part a curator removed, until the next `db train`).
bool sp_dragon_has_part(sp_dragon* d, const char* category);
/// The categories the current model knows (for hints); NULL when there is no model.
const sp_clf* sp_dragon_model(const sp_dragon* d);
/// Why sp_dragon_model is NULL, one line naming the database ("DB: no
/// trained model (run `sketchpose db train`)", "DB: model 3: stored bytes
/// do not match the checksum"); "" when there is a model or `no_model` was
/// asked for.
const char* sp_dragon_model_error(const sp_dragon* d);

/// The solve report of the whole dragon as JSON (DESIGN.md: the parts'
/// solve reports combined, plus "parts": [{"category", "confidence", "name",
/// "attached_to" (-1: free), "socket", "anchor_px" (null when free),
/// "far_side", "mirrored", "outline_bbox_px" (the attached outline at t = 0),
/// "stroke_bbox_px", "note", "report": {...}}], "details": [{"part", "points"}]).
/// Poses the dragon at t = 0.
/// *json: UTF-8 text, malloc'd, free() it; NULL on failure (out of memory).
sp_result sp_dragon_report_json(sp_dragon* d, char** json, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
