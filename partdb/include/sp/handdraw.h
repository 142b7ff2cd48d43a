/// sp/handdraw.h: synthetic "hand-drawn" sketches of a part's abstraction,
/// the classifier's training data for the dragon parts (issue 5, item 4).
///
/// A clean sketch (the abstraction projected at random shape and pose
/// parameters within bounds, sp/synth.h) is passed through a perturbation
/// model of how people draw: each curve is traced along its arc length with
/// rounded corners (Gaussian smoothing), low-frequency wobble and a little
/// tremor, in either direction, a closed curve from a random start and ending
/// with a gap or an overshoot (and a sideways miss) at closure, a curve drawn
/// only partly or in several pieces, points sampled at a fixed rate at a
/// varying pen speed (uneven spacing, slower in corners, with timestamps);
/// the whole drawing is rotated, its aspect changed, scaled and moved on the
/// canvas. Every random choice comes from the seed (splitmix64): the same
/// seed gives the same bits on every machine.
///
///     sp_handdraw_params hp = sp_handdraw_preset(SP_HANDDRAW_HARSH);
///     sp_handdraw_info info;
///     sp_handdraw_part(&ch.rig, a, &ch.camera, &(sp_handdraw_desc){.params = &hp}, seed, &sketch, &info);
///
/// or, for many sketches of one part with labels, sp_handdraw_dataset.
/// Lengths in the parameters are fractions of the clean drawing's bounding-box
/// diagonal ("D") or of the curve's own length, so they mean the same on any
/// canvas.
#ifndef SP_HANDDRAW_H
#define SP_HANDDRAW_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/result.h"
#include "sp/rig.h"
#include "sp/sketch.h"
#include "sp/sketch_io.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Named settings of the perturbation model.
typedef enum sp_handdraw_style {
    SP_HANDDRAW_NORMAL = 0, ///< a careful visitor: the training data
    SP_HANDDRAW_HARSH,      ///< a hasty one: larger wobble, gaps, overshoots, rotations; held-out evaluation
    SP_HANDDRAW_CLEAN,      ///< no perturbation at all (the projected abstraction, resampled)
    SP_HANDDRAW_STYLE_COUNT
} sp_handdraw_style;

/// "normal", "harsh", "clean".
const char* sp_handdraw_style_name(sp_handdraw_style s);
/// Parses a style name; SP_HANDDRAW_STYLE_COUNT when unknown.
sp_handdraw_style sp_handdraw_style_parse(const char* name);

/// The perturbation model's magnitudes. Each random quantity is drawn
/// uniformly up to its maximum unless said otherwise; 0 switches an effect off.
typedef struct sp_handdraw_params {
    double rotation_deg;             ///< whole drawing rotated by up to +-this, degrees (<= 180)
    double aspect;                   ///< width:height changed by a factor in [1/aspect, aspect] (>= 1; 1 = off)
    double shear;                    ///< horizontal shear up to +-this (dx per dy)
    double wobble;                   ///< low-frequency sideways drift, largest amplitude, fraction of D
    double wobble_waves;             ///< wobble cycles over one curve's length, at most (>= 1)
    double tremor;                   ///< high-frequency jitter (standard deviation), fraction of D
    double corner;                   ///< corner rounding: Gaussian smoothing width along the curve, fraction of D
    double gap;                      ///< closed curves: largest gap left at closure, fraction of the curve length
    double overshoot;                ///< closed curves: largest overshoot past the start, fraction of the curve length
    double gap_probability;          ///< closed curves: chance of ending short (a gap) rather than beyond the start
    double miss;                     ///< closed curves: sideways miss of the end point at closure, fraction of D
    double partial_probability;      ///< chance a curve is drawn only in part
    double partial;                  ///< largest share of such a curve left out
    double split_probability;        ///< chance a curve is drawn as 2 or 3 strokes (restarts overlap or leave small gaps)
    double reverse_probability;      ///< chance a curve is drawn against the abstraction's direction
    bool random_start;               ///< closed curves start anywhere (people rarely start where the abstraction does)
    double spacing_min, spacing_max; ///< point spacing (pen speed x sample interval), fraction of D; uneven between these
    double scale_min, scale_max;     ///< size on the canvas relative to the clean drawing
    double shift;                    ///< largest move of the drawing's centre, fraction of the canvas side
} sp_handdraw_params;

/// The settings of a named style.
sp_handdraw_params sp_handdraw_preset(sp_handdraw_style s);
/// True when every field is finite and in its range (see the field comments).
bool sp_handdraw_params_valid(const sp_handdraw_params* p);

/// What one perturbed sketch got (for tests and curators' sanity checks).
typedef struct sp_handdraw_info {
    double rotation;                 ///< radians, counter-clockwise as seen on screen (y down)
    double aspect;                   ///< width factor / height factor actually applied
    double scale;                    ///< size factor actually applied
    int curves;                      ///< curves of the abstraction drawn
    int closed_curves;               ///< of which closed
    int gaps;                        ///< closed curves ending short of their start
    int overshoots;                  ///< closed curves ending past their start
    double closure_min, closure_max; ///< signed closure over closed curves, fraction of curve length (< 0 gap, > 0 overshoot)
    int partial;                     ///< curves drawn only in part
    double covered_min;              ///< smallest share of a curve's length traced (1 = all of it)
    int split;                       ///< curves drawn as several strokes
    int reversed;                    ///< curves drawn against the abstraction's direction
} sp_handdraw_info;

/// Perturbs a clean sketch (one stroke per curve; a stroke whose last point
/// equals its first is a closed curve). `out` gets new strokes with
/// timestamps (ms) and the canvas of `clean`. info may be NULL.
/// Fails (SP_ERR_INVALID) on an empty or non-finite sketch or invalid params.
sp_result sp_handdraw_apply(const sp_sketch* clean, const sp_handdraw_params* params, uint64_t seed, sp_sketch* out,
                            sp_handdraw_info* info, sp_error* err);

/// What of a part a sketch shows (before the hand-drawing model perturbs it).
typedef enum sp_handdraw_shape {
    SP_HANDDRAW_SHAPE_OUTLINE = 0, ///< the abstraction's curves (or, with `details`, the mesh's silhouette)
    SP_HANDDRAW_SHAPE_TOP,         ///< only the upper side of the closed outline, leftmost to rightmost point (one open stroke)
    SP_HANDDRAW_SHAPE_UNDERSIDE,   ///< only its lower side
    SP_HANDDRAW_SHAPE_LINE,        ///< one line through the joints: skeletons of one or two chains (tails, leg pairs)
    /// the silhouette of the part's far end only: the mesh around a joint's subtree holding 25-75% of the
    /// vertices, the smallest holding at least half when there is one (a head without its neck, a wing's
    /// hand, a tail's far half), else drawn from the seed (one leg of a pair)
    SP_HANDDRAW_SHAPE_PIECE,
    SP_HANDDRAW_SHAPE_COUNT
} sp_handdraw_shape;

/// How to draw a part. Zero means the default.
typedef struct sp_handdraw_desc {
    const sp_handdraw_params* params; ///< NULL: sp_handdraw_preset(style)
    sp_handdraw_style style;          ///< used when params is NULL (default normal)
    double amplitude;                 ///< pose amplitude, radians (sp_synth_params); 0: SP_HANDDRAW_AMPLITUDE
    /// sp_handdraw_dataset: share of the sketches (evenly spread) drawn in the
    /// clean style instead, in [0, 1]: they anchor a small training set on the
    /// part's exact shape while the others teach the variation.
    double clean_share;
    sp_handdraw_shape shape; ///< what is drawn (default: the abstraction)
    /// Outline, top and underside: the silhouette of the whole posed mesh, with
    /// its decorations (horns, spikes, teeth, claws), traced from a raster,
    /// instead of the abstraction (which leaves decorations out). Top and
    /// underside use the silhouette anyway when the abstraction is not one closed curve.
    bool details;
    /// Chance in [0, 1] that a row of 3-8 spikes or teeth is added along 12-35%
    /// of the curve (a detail the visitor adds that the part lacks).
    double spikes;
} sp_handdraw_desc;

/// Default pose amplitude of synthetic part sketches (radians): visibly posed,
/// within what a visitor would draw for the part.
#define SP_HANDDRAW_AMPLITUDE 0.4

/// The seed of sketch `i` of a seed family: distinct families give unrelated
/// streams of poses and perturbations.
uint64_t sp_handdraw_seed(uint64_t family, int i);
/// A part's own seed family: the same family number gives every part (by
/// name) an unrelated stream, so that parts drawn with one family do not share
/// their rotations and wobbles.
uint64_t sp_handdraw_part_family(uint64_t family, const char* part_name);

/// One hand-drawn sketch of abstraction `abstraction` of `rig`, seen by `cam`:
/// random shape and pose parameters within bounds from `seed`, then the
/// perturbation model. info may be NULL.
sp_result sp_handdraw_part(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_handdraw_desc* desc, uint64_t seed,
                           sp_sketch* out, sp_handdraw_info* info, sp_error* err);

/// False when the rig cannot be drawn as `shape` (LINE needs a skeleton whose
/// joints form one chain or two chains from a common joint, PIECE a joint
/// whose subtree holds 25-75% of the vertices).
bool sp_handdraw_shape_available(const sp_rig* rig, sp_handdraw_shape shape);
/// The clean drawing of `shape` at parameters p, seen by cam, before any
/// perturbation (closed curves repeat their first point at the end);
/// `spikes` and `seed` as in sp_handdraw_desc. SP_ERR_INVALID when the shape
/// is not available or the mesh has no area in the view.
sp_result sp_handdraw_clean_shape(const sp_rig* rig, int abstraction, const sp_camera* cam, const double* p,
                                  sp_handdraw_shape shape, bool details, double spikes, uint64_t seed, sp_sketch* out);

/// Appends `n` hand-drawn sketches (seeds sp_handdraw_seed(family, 0..n-1)) to
/// `ds` with label `label` (< ds->category_count); sample indices continue
/// from `first_index`. Sketch i is clean when floor((i+1)*clean_share) >
/// floor(i*clean_share). On failure `ds` is unchanged.
sp_result sp_handdraw_dataset(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_handdraw_desc* desc,
                              uint64_t family, int n, int label, int first_index, sp_dataset* ds, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
