/// ui.h: the kiosk's UI as a pure state machine: events in, jobs out, no GL.
///
/// How to use (the window's main loop; a test does the same with a fake pipeline):
///
///     sp_kiosk_ui* ui;
///     if (sp_kiosk_ui_create(&(sp_kiosk_ui_desc){0}, &ui, &err) != SP_OK) ... err.text ...
///     sp_kiosk_ui_resize(ui, fb_w, fb_h, px_per_mm);   // and on every resize
///     ... per GLFW callback: sp_kiosk_ui_event(ui, &ev);
///     ... per frame: sp_kiosk_ui_event(ui, &(sp_kiosk_event){SP_KEV_FRAME, now_ms});
///         sp_kiosk_job job;
///         while (sp_kiosk_ui_next_job(ui, &job)) {        // in order
///             switch (job.kind) { case SP_KJOB_FIT: ... sp_kiosk_ui_fit_done(ui, &result); ... }
///             if (job.heavy) break;                       // one fit or save a frame keeps frames short
///         }
///         ... draw from the read-only fields of *ui (mode, stroke, flash, chips, rects, ...) ...
///     sp_kiosk_ui_destroy(ui);
///
/// The UI decides everything a visitor sees and when (attract screen, the
/// live stroke, the fitted outline's flash, chips, hints, the idle
/// countdown); the caller only executes jobs (classify and fit a stroke,
/// undo, save...) and reports their results. Time is the events' t_ms only
/// (never a clock), so a replayed session makes the same decisions.
///
/// Coordinates are framebuffer pixels, y down; sizes come from px_per_mm so
/// that every touch target is at least desc.min_target_mm (15 mm) on any
/// screen.
///
/// Chips refer to the last stroke only: the last part's label, two other
/// guesses and "Other?", which opens a row of every part
/// (sp_kiosk_ui_set_parts; a tap on one re-fits the last part as it, a
/// REFIT job), or, when the last stroke was refused, that stroke's three
/// best guesses and the row, offered while the refused stroke stays on
/// screen (desc.offer_ms); a tap on one makes the stroke that part (a FIT
/// job with a category). A new stroke hides the chips until its own answer.
#ifndef SP_KIOSK_UI_H
#define SP_KIOSK_UI_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sp/kiosk_event.h"
#include "sp/result.h"

enum {
    SP_KIOSK_ROW_MAX = 12, ///< parts in the refusal's row (sp_kiosk_ui_set_parts): the six shipped and six more a curator adds
};

/// Touch targets (the order of the toolbar).
typedef enum sp_kiosk_target {
    SP_KT_NONE = 0,
    SP_KT_UNDO,        ///< remove the last part
    SP_KT_REDRAW,      ///< the next stroke replaces the last part (toggles)
    SP_KT_START_OVER,  ///< two taps, the second SP_KIOSK_CONFIRM_MIN_MS to confirm_ms after the first: remove every part
    SP_KT_PLAY,        ///< play / pause the animation
    SP_KT_TURN,        ///< orbit mode (drag turns the dragon) / back to the drawing view
    SP_KT_SAVE,        ///< export .glb + postcard, show the code
    SP_KT_CHIP_LABEL,  ///< the last part's category (informative; hidden while a refused stroke is offered)
    SP_KT_CHIP_GUESS1, ///< next guess: re-fit the last part as this category; a refused stroke: its best guess
    SP_KT_CHIP_GUESS2, ///< the guess after that
    SP_KT_CHIP_GUESS3, ///< a refused stroke's third guess
    SP_KT_CHIP_MORE,   ///< "Other?" beside the last part's chips: opens the parts row for it (toggles)
    SP_KT_PART1,       ///< the row of parts, in sp_kiosk_ui_set_parts order: make the refused stroke, or the last part, this part
    SP_KT_PART_LAST = SP_KT_PART1 + SP_KIOSK_ROW_MAX - 1,
    SP_KT_COUNT
} sp_kiosk_target;

/// "undo", "redraw", "start_over", "play", "turn", "save", "label", "guess1", "guess2", "guess3",
/// "more", "part1".."part12"; NULL otherwise.
const char* sp_kiosk_target_name(sp_kiosk_target t);
/// Parses a target name; SP_KT_NONE when unknown.
sp_kiosk_target sp_kiosk_target_parse(const char* s);

/// Which screen.
typedef enum sp_kiosk_mode {
    SP_KM_ATTRACT, ///< "draw a dragon": an animation shows how; a touch starts, a stroke is the first part
    SP_KM_DRAW,    ///< strokes become parts
    SP_KM_TURN,    ///< drags orbit the view
} sp_kiosk_mode;

enum {
    SP_KIOSK_STROKE_MAX = 2048,  ///< points kept per stroke (longer strokes are thinned, never cut)
    SP_KIOSK_OUTLINE_MAX = 4096, ///< points of a fitted outline kept for the flash
    SP_KIOSK_PENDING_MAX = 2,    ///< finished strokes waiting for the pipeline; a third drops the oldest
    SP_KIOSK_JOBS_MAX = 32,      ///< queued jobs; more are dropped (tap storms)
    /// A category's name with its NUL: the part database takes up to 63
    /// characters (SP_NAME_MAX), and one cut short here matched no part.
    SP_KIOSK_LABEL_MAX = 64,
    SP_KIOSK_TEXT_MAX = 160,
    /// Start over's second tap comes at least this long after the first: a
    /// double tap (0.1-0.3 s) is one touch, not a confirmation read and given.
    SP_KIOSK_CONFIRM_MIN_MS = 400,
    /// An Undo this soon after the last one is the same touch (a bouncing
    /// finger, a double tap): without Redo, a second part lost for nothing.
    SP_KIOSK_REPEAT_MIN_MS = 300,
};

/// Zero means the default.
typedef struct sp_kiosk_ui_desc {
    double min_target_mm; ///< smallest side of any touch target; 0: 15
    double button_mm;     ///< preferred toolbar button height; 0: 18 (never below min_target_mm)
    double idle_ms;       ///< no input for this long returns to the attract screen; 0: 90000; < 0: never
    double countdown_ms;  ///< the last part of idle_ms, shown as a countdown; 0: 10000; never more than a third of idle_ms
    double flash_ms;      ///< fitted outline shown over the stroke; 0: 800
    double fade_ms;       ///< a rejected stroke fades out; 0: 1200
    double offer_ms;      ///< a refused stroke stays, with its guesses and the parts row, this long; 0: 8000
    double hint_ms;       ///< hints stay this long; 0: 4000
    double banner_ms;     ///< the save code stays this long; 0: 15000
    double confirm_ms;    ///< Start over needs a second tap within this; 0: 3000
    double tap_mm;        ///< a stroke whose box diagonal is smaller is a tap, not a part; 0: 4
    double join_ms;       ///< a stroke begun this soon after the last one's pen-up may continue it; 0: 200; < 0: never
    double join_mm;       ///< ... when it begins this near the last one's end (plus its speed times the pause); 0: 8
    bool start_playing;   ///< animation on from the start (default: paused until Play)
} sp_kiosk_ui_desc;

typedef struct sp_kiosk_rect {
    float x, y, w, h; ///< pixels, top-left corner and size
} sp_kiosk_rect;

/// A polyline owned by the UI (pixels).
typedef struct sp_kiosk_line {
    int count;
    float* xy; ///< count by 2 (capacity fixed at create)
    double* t; ///< count timestamps (ms) for strokes; NULL for outlines
} sp_kiosk_line;

/// What the caller has to do next.
typedef enum sp_kiosk_job_kind {
    SP_KJOB_NONE = 0,
    SP_KJOB_FIT,   ///< classify + fit `stroke` (as `category` when not ""); replace: it replaces the last part (Redraw)
    SP_KJOB_REFIT, ///< re-fit the last part's stroke as `category`
    SP_KJOB_UNDO,  ///< remove the last part
    SP_KJOB_CLEAR, ///< remove every part (Start over, idle timeout)
    SP_KJOB_SAVE,  ///< export the dragon (.glb + PNG postcard)
} sp_kiosk_job_kind;

/// One job. Pointers stay valid until the next sp_kiosk_ui_next_job call.
typedef struct sp_kiosk_job {
    sp_kiosk_job_kind kind;
    bool heavy;                        ///< FIT, REFIT, SAVE: do one per frame
    bool replace;                      ///< FIT: replace the last part
    bool replace_detail;               ///< FIT with a category: the stroke was kept as a detail; the part takes its place
    bool undo_first; ///< FIT: the stroke continues the last one: take back the last change (the part or detail it made) first
    const sp_kiosk_line* stroke;       ///< FIT: the stroke (pixels, with times)
    char category[SP_KIOSK_LABEL_MAX]; ///< REFIT; FIT: "" to classify, else the part the visitor chose for a refused stroke
    double t_ms;                       ///< when it was asked for
} sp_kiosk_job;

/// Why a stroke was refused (each has its sentence in kiosk_text.h).
typedef enum sp_kiosk_refusal {
    SP_KREF_UNRECOGNISED = 0, ///< not a part the kiosk knows, or no model to tell (a refit: the part did not fit)
    SP_KREF_TOO_SMALL,        ///< too small for a part
    SP_KREF_TRICKY,           ///< no part of the category could take its shape
    SP_KREF_NOT_READY,        ///< the database has no part of the category: staff needed
    SP_KREF_FULL,             ///< the dragon has all the parts it can take
    SP_KREF_DETAIL,           ///< a small line drawn on a part (an eye, a spot): a detail, not a part
} sp_kiosk_refusal;

/// The answer to a FIT or REFIT job.
typedef struct sp_kiosk_fit_result {
    bool ok;                  ///< false: refused (a hint; the stroke is offered or fades; no part changes)
    sp_kiosk_refusal refusal; ///< !ok: why
    bool offer;               ///< !ok, FIT: the stroke can still become a part by a tap (it stays, with the parts row)
    bool kept;                ///< !ok, FIT: the stroke stays on the dragon as a detail (Undo takes it back as a change)
    const char* offers[3];    ///< !ok: the refused stroke's best guesses, best first (NULL or "" when none)
    bool waiting;             ///< ok: the part waits for a body to join (none on the canvas)
    const char* hint;         ///< ok: a note shown beside the part (NULL: none; it replaces the waiting hint)
    const char* category;     ///< the fitted part's category
    const char* guesses[2];   ///< next two guesses (NULL or "" when none)
    int part_count;           ///< parts after the job (also when refused: an undo_first job may have taken one back)
    const float* outline;     ///< outline_count by 2: the fitted abstraction in pixels (flashed in yellow)
    int outline_count;
    const int* outline_breaks; ///< indices where a new curve of the outline starts (may be NULL)
    int outline_break_count;
    const float* stroke; ///< stroke_count by 2: the stroke that was fitted (REFIT: the part's; NULL: the job's)
    int stroke_count;
} sp_kiosk_fit_result;

/// The last part's chips after an undo / clear, or NULL labels when there is no part.
typedef struct sp_kiosk_part_label {
    const char* category;
    const char* guesses[2];
    bool waiting; ///< the part waits for a body (no body on the canvas)
} sp_kiosk_part_label;

/// The state. Read-only outside ui.c (the renderer and tests read it).
typedef struct sp_kiosk_ui {
    sp_kiosk_ui_desc desc; ///< with defaults filled in
    // Layout (sp_kiosk_ui_resize).
    int width, height; ///< framebuffer pixels
    double px_per_mm;
    sp_kiosk_rect canvas;              ///< where strokes start (the window minus the toolbar)
    sp_kiosk_rect target[SP_KT_COUNT]; ///< drawn rectangles (w = 0: not shown)
    sp_kiosk_rect hint_box;            ///< where hints go
    sp_kiosk_rect banner_box;          ///< where the save banner goes (over the canvas's bottom)
    float text_px;                     ///< body text height
    float big_text_px;                 ///< titles, the countdown
    float line_px;                     ///< stroke width
    // Time.
    double now;        ///< t_ms of the last event
    double last_input; ///< t_ms of the last pointer event (idle timer)
    double mode_since; ///< when the current mode began
    sp_kiosk_mode mode;
    // The finger.
    enum { SP_KCAP_NONE, SP_KCAP_STROKE, SP_KCAP_TARGET, SP_KCAP_ORBIT, SP_KCAP_SWALLOW } capture;
    sp_kiosk_target pressed; ///< the target under the finger (drawn pressed)
    float last_x, last_y;
    float down_x, down_y; ///< where the finger now down touched, and when
    double down_t;
    float press_box[4];    ///< a press on a chip or tile: its path's box so far (x0, y0, x1, y1)
    sp_kiosk_target stroke_target; ///< the chip or tile the stroke being drawn began on (SP_KT_NONE: none)
    bool down_on_banner;   ///< it touched the save banner
    sp_kiosk_line stroke;  ///< the stroke being drawn (blue)
    double stroke_spacing; ///< current thinning distance, pixels
    bool continuing;       ///< the stroke being drawn continues the last one (it starts with the last one's points)
    int continued_from;    ///< points of the stroke being drawn that are the last one's
    // The last stroke drawn (not a chip's), while a stroke may still continue it.
    sp_kiosk_line last_stroke;
    double last_up;    ///< its pen-up
    bool last_replace; ///< it was a Redraw
    enum {
        SP_KLAST_NONE,     ///< no stroke to continue (anything else happened since)
        SP_KLAST_PENDING,  ///< its FIT job waits (the newest pending stroke)
        SP_KLAST_INFLIGHT, ///< its FIT job was handed out, not answered
        SP_KLAST_PART,     ///< it made a part
        SP_KLAST_DETAIL,   ///< it was kept as a detail
        SP_KLAST_REFUSED,  ///< it was refused (nothing on the dragon)
    } last_outcome;
    // Finished strokes waiting for FIT jobs (ring).
    sp_kiosk_line pending[SP_KIOSK_PENDING_MAX];
    int pending_head, pending_count;
    int dropped_strokes; ///< strokes dropped because the pipeline fell behind
    // Jobs (ring).
    sp_kiosk_job jobs[SP_KIOSK_JOBS_MAX];
    int job_head, job_count;
    int dropped_jobs;
    sp_kiosk_line job_stroke; ///< the stroke of the FIT job last handed out
    bool fit_in_flight;       ///< a FIT/REFIT handed out and not answered yet
    sp_kiosk_job_kind inflight_kind;
    bool inflight_replace;
    bool inflight_undo; ///< the FIT in flight takes back the last change first
    bool refit_queued, save_queued;
    // Results on screen.
    sp_kiosk_line flash_stroke, flash_outline; ///< shown until flash_until (the stroke kept after: the last part's)
    int flash_breaks[64];
    int flash_break_count;
    double flash_until;
    sp_kiosk_line fade_stroke; ///< a rejected stroke, fading until fade_until
    double fade_until;
    sp_kiosk_line scene;       ///< the strokes of the parts on the canvas, thinned (sp_kiosk_ui_set_scene)
    sp_kiosk_line held_stroke; ///< the last stroke, refused, offered until held_until (then it fades)
    double held_until;
    bool held_kept; ///< the held stroke is also kept as a detail: Undo takes it back from the dragon too
    char hint[SP_KIOSK_TEXT_MAX];
    double hint_until;
    bool hint_of_offer, hint_of_row;   ///< the hint is the held offer's / the opened row's: it goes when they do
    bool woke;                         ///< the finger now down touched during the idle countdown or on the attract screen
    char code[16];                     ///< the last save code
    char banner[2][SP_KIOSK_TEXT_MAX]; ///< the save banner: the code, then what it is for
    double banner_until;
    bool save_failed;
    // Parts as the caller reported them.
    int part_count;
    char chip[4][SP_KIOSK_LABEL_MAX];               ///< categories of the label and guesses 1-3 ("" = hidden)
    bool chips_offer;                               ///< the guesses are the held stroke's (no label)
    int row_count;                                  ///< parts in the row (a refusal's, or opened by "Other?")
    int row_fit; ///< of them, those whose tiles fit on the canvas now (in order; the others are not offered on this screen)
    bool row_open;                                  ///< the row is open for the last part ("Other?")
    char row[SP_KIOSK_ROW_MAX][SP_KIOSK_LABEL_MAX]; ///< their categories
    uint64_t revision;                              ///< grows with every change of the dragon
    uint64_t saved_revision;                        ///< revision at the last successful save (0: never)
    bool redraw_armed;
    bool redraw_for_offer; ///< armed again by a refused Redraw: it lapses with the offer
    bool redraw_spent;     ///< Redraw took a refused stroke back: more taps do the same until a stroke is drawn
    double clear_armed_until;
    double clear_armed_at; ///< when Start over was first tapped
    double undo_at;        ///< when Undo last acted
    double target_at;      ///< when a chip or button was last tapped
    // Animation and view.
    bool playing;
    double anim_ms;    ///< animation clock, advances only while playing
    double yaw, pitch; ///< orbit, radians (0, 0: the drawing view)
    // Counters (tests, logs).
    int strokes_finished, taps, activations[SP_KT_COUNT], resets;
    int joined, merged;        ///< strokes that continued the last one; of them, merged into its waiting FIT job
    int closed;                ///< of the joined, those that closed the last line (both ends meeting its ends)
    int offered, chosen;       ///< refused strokes held with offers; of them, made a part by a tap
    int others, others_chosen; ///< rows opened by "Other?"; of them, closed by re-fitting the part as another
} sp_kiosk_ui;

/// A fresh UI on the attract screen. desc may be NULL. Fails only when out
/// of memory; then *out is NULL.
sp_result sp_kiosk_ui_create(const sp_kiosk_ui_desc* desc, sp_kiosk_ui** out, sp_error* err);
/// NULL is fine.
void sp_kiosk_ui_destroy(sp_kiosk_ui* ui);

/// Lays the screen out for a width x height framebuffer with px_per_mm pixels
/// per millimetre (<= 0 or NaN: 96 dpi). Every target's sides are at least
/// min_target_mm whenever the window is large enough to hold them at all.
void sp_kiosk_ui_resize(sp_kiosk_ui* ui, int width, int height, double px_per_mm);

/// Feeds one event. Times before ui->now are taken as now. Never fails.
void sp_kiosk_ui_event(sp_kiosk_ui* ui, const sp_kiosk_event* ev);
/// The next job in order; false when there is none.
bool sp_kiosk_ui_next_job(sp_kiosk_ui* ui, sp_kiosk_job* job);
/// The kind of the job sp_kiosk_ui_next_job would give (SP_KJOB_NONE when none).
sp_kiosk_job_kind sp_kiosk_ui_peek_job(const sp_kiosk_ui* ui);
/// Reports a FIT or REFIT job's result.
void sp_kiosk_ui_fit_done(sp_kiosk_ui* ui, const sp_kiosk_fit_result* r);
/// Where the parts on the canvas are, for the chips to keep clear of them:
/// their strokes' points (n by 2, framebuffer pixels), thinned evenly to at
/// most SP_KIOSK_STROKE_MAX. Given before fit_done or parts_changed.
void sp_kiosk_ui_set_scene(sp_kiosk_ui* ui, const float* xy, int n);
/// Reports the parts after UNDO or CLEAR (label NULL or label->category NULL: no part left).
void sp_kiosk_ui_parts_changed(sp_kiosk_ui* ui, int part_count, const sp_kiosk_part_label* label);
/// Reports a SAVE job: ok with the code to show, or a failure (a friendly message is shown).
void sp_kiosk_ui_saved(sp_kiosk_ui* ui, bool ok, const char* code);
/// The categories of the refusal's row of parts, in order (at most
/// SP_KIOSK_ROW_MAX; more are ignored). Call when the database's parts change.
void sp_kiosk_ui_set_parts(sp_kiosk_ui* ui, const char* const* categories, int count);

/// The target whose touch area contains (x, y) (slightly larger than its
/// drawn rectangle), SP_KT_NONE when none. Only visible targets count.
sp_kiosk_target sp_kiosk_ui_hit(const sp_kiosk_ui* ui, float x, float y);
/// Whether a target is shown now (chips and the parts row come and go).
bool sp_kiosk_ui_target_visible(const sp_kiosk_ui* ui, sp_kiosk_target t);
/// Whether a target is shown and does something now (e.g. Undo needs a part).
bool sp_kiosk_ui_target_enabled(const sp_kiosk_ui* ui, sp_kiosk_target t);
/// Seconds left on the idle countdown, or 0 when it is not showing.
double sp_kiosk_ui_countdown_s(const sp_kiosk_ui* ui);
/// Whether the fitted outline is being flashed (the new part is not drawn yet).
bool sp_kiosk_ui_flashing(const sp_kiosk_ui* ui);
/// Opacity 0..1 of the fading rejected stroke.
double sp_kiosk_ui_fade(const sp_kiosk_ui* ui);
/// Whether a refused stroke is held with its offers (guess chips, parts row).
bool sp_kiosk_ui_offering(const sp_kiosk_ui* ui);
/// Whether t is the row's tile of the last part's own category while the
/// row is open for that part ("Other?"): drawn as chosen; a tap on it only
/// closes the row.
bool sp_kiosk_ui_target_current(const sp_kiosk_ui* ui, sp_kiosk_target t);
/// The category a chip or row target stands for ("" when hidden).
const char* sp_kiosk_ui_target_category(const sp_kiosk_ui* ui, sp_kiosk_target t);
/// What a chip or row target says ("Body", "Wings?"; "" when hidden) into out.
const char* sp_kiosk_ui_target_text(const sp_kiosk_ui* ui, sp_kiosk_target t, char* out, size_t cap);
/// The line of text under the chips now: a hint while one shows, else the
/// first-draw prompt on an empty canvas, else NULL.
const char* sp_kiosk_ui_message(const sp_kiosk_ui* ui);
/// Whether the hint / the save banner is showing.
bool sp_kiosk_ui_hint_visible(const sp_kiosk_ui* ui);
bool sp_kiosk_ui_banner_visible(const sp_kiosk_ui* ui);
/// Whether Start over is armed (its button asks "Sure?").
bool sp_kiosk_ui_clear_armed(const sp_kiosk_ui* ui);

#endif
