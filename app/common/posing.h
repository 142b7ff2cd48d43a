/// posing.h: what the posing commands (pose, synth, drawover, animate,
/// dragon) share: choosing an abstraction, reading strokes with the file
/// named in errors.
#ifndef SP_POSING_H
#define SP_POSING_H

#include "sp/gltf.h"
#include "sp/sketch.h"
#include "sp/solver.h"

/// Index of the abstraction called `name` (NULL: the first one) among
/// abs[0..count). -1 and a message naming the rig and the abstractions it
/// has if there is none.
int sp_pick_abstraction(const sp_abstraction* abs, int count, const char* rig_path, const char* name, sp_error* err);
/// Reads a stroke file as it is: JSON, or an SVG drawing (a name ending in
/// .svg, in any case), whose viewBox is the canvas (one without is
/// refused: its canvas is unknown); err names the file.
sp_result sp_read_drawing(const char* path, sp_sketch* sk, sp_error* err);
/// Reads a stroke file (sp_read_drawing) and checks that it has at least one stroke of two
/// or more points and no empty stroke (one-point taps are kept); err names the file.
sp_result sp_read_strokes(const char* path, sp_sketch* sk, sp_error* err);
/// The parameters a draw-over solve may move (sp_solve_desc.active;
/// malloc'd, param_count of them; NULL when out of memory): all but the
/// placement joint's (the first joint with parameters, when it translates
/// the whole character: its translations, rotation and scale) and those of
/// the body's root (the nearest common ancestor of the other joints with
/// parameters: hips, pelvis). Draw-over bends the character where it
/// stands: a curve over one arm moved the whole of CesiumMan (the loader's
/// derived placement) to fit it, and turned and grew the whole cartoon man.
/// With emb (the curves embedded in the mesh, sp_embed_curve), only the
/// joints that carry them (SP_DRAWOVER_CARRIER_SHARE of the skin at a tenth
/// of the curve's points; a joint moving more than SP_DRAWOVER_LIMB_SHARE of
/// the mesh counts only points where no joint under it has that share),
/// the limb above them (ancestors moving at most
/// SP_DRAWOVER_LIMB_SHARE of the mesh), and
/// the joints below them move (posing.c, curve_carriers). An arm redrawn
/// raised past its bounds twisted the cartoon man's spine, chest, neck and
/// head to their bounds, for 1.0 px where the arm alone fits to 2.1.
#define SP_DRAWOVER_CARRIER_SHARE 0.15
#define SP_DRAWOVER_LIMB_SHARE 0.25
bool* sp_drawover_active(const sp_rig* rig, const sp_abstraction* emb);
/// Appends to a best-effort or loose-fit note (cap bytes in all) which
/// joints the draw-over could move (where each moving limb starts), or that
/// none could: a redraw out of their reach said only "cannot reach".
void sp_drawover_note_held(const sp_rig* rig, const bool* active, char* note, size_t cap);
/// Scales a draw-over solve's regulariser weights (0: the defaults; < 0:
/// off, kept) by (the character's size on the canvas / the embedded curves'
/// size there)^2, clamped to [1, 10000] (curves of no size: 10000), and
/// returns that factor. Why: the solver measures the match term over the
/// abstraction's own size, so a curve drawn over the neck, a seventh of the
/// character, weighed 50 times more against the paper's regularisers than a
/// whole figure's stick, and a redrawn neck swung the arms (xyz: the mesh
/// at the start pose; emb: the curves embedded in it, sp_embed_curve: their
/// size is the one the solver measures, where the strokes as drawn may run
/// off the mesh).
double sp_drawover_scale_weights(sp_solve_desc* d, const sp_rig* rig, const double* xyz, const sp_camera* cam,
                                 const sp_abstraction* emb);

#endif
