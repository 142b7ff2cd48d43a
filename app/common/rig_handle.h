/// rig_handle.h: one handle on either kind of rig the commands take: a glTF
/// character (skinned; analytic Jacobians) or a black-box rig plugin (a
/// shared object, sp/blackbox.h; finite differences). A command loads a
/// `--rig` path and then asks the handle, not the kind: parameters (names,
/// bounds, defaults, groups, units), the start pose, abstractions, the sketch
/// view, a solver, synthetic strokes, and the rig posed at p as a character to
/// render or save. What only a glTF file has (joints, animations, extras, load
/// warnings) is its character, sp_rig_handle_character.
///
///     sp_rig_handle* rig = NULL;
///     if (sp_rig_handle_load(path, &rig, &err) != SP_OK) ... err.text ...
///     int a = sp_rig_handle_pick_abstraction(rig, NULL, &err);
///     sp_camera cam = sp_rig_handle_camera(rig, sketch.canvas_w, sketch.canvas_h);
///     double* p = NULL;                               // sp_rig_handle_param_count(rig) values
///     if (sp_rig_handle_read_pose(rig, NULL, &p, NULL, &err) != SP_OK) ...   // or a --start file
///     sp_solver* s;
///     if (sp_rig_handle_solver(rig, a, &cam, &(sp_solve_desc){0}, &s, &err) != SP_OK) ... err.text ...
///     ... sp_solver_solve(s, &sketch, p, p, &report, &err) ...
///     sp_solver_destroy(s);
///     sp_rig_handle_free(rig);                        // after every solver made from it
///
/// A plugin posed at p is baked into a static character (its posed mesh with
/// the rig's colours, the fitted abstraction as rigid curves, one joint, no
/// parameters), which the glTF writer and the snapshot take like any other:
/// a glTF file cannot carry an arbitrary deformer.
#ifndef SP_RIG_HANDLE_H
#define SP_RIG_HANDLE_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/gltf.h"
#include "sp/sketch.h"
#include "sp/solver.h"

typedef struct sp_rig_handle sp_rig_handle;

/// True when `path` names a black-box rig plugin: its file name ends with
/// ".so" or has ".so." in it (a versioned shared object). Anything else is
/// read as glTF (.gltf or .glb).
bool sp_rig_path_is_plugin(const char* path);
/// Loads a glTF character or a plugin, by sp_rig_path_is_plugin. On failure
/// *out is NULL and err names the file and the problem (the loaders' messages).
sp_result sp_rig_handle_load(const char* path, sp_rig_handle** out, sp_error* err);
/// sp_rig_handle_load for commands that need a glTF character's joints and
/// mesh (`command` names it in the message): a plugin path is refused in one
/// line, before it is loaded, as "<path>: <command> needs a glTF character;
/// a black-box rig plugin is posed by `pose`".
sp_result sp_rig_handle_load_character(const char* path, const char* command, sp_rig_handle** out, sp_error* err);
/// Frees the rig (and unloads a plugin). NULL is fine.
void sp_rig_handle_free(sp_rig_handle* h);

/// True for a plugin.
bool sp_rig_handle_is_black_box(const sp_rig_handle* h);
/// The glTF character (mutable: `drawover` adds its curves, `animate` its
/// animation); NULL for a plugin.
sp_character* sp_rig_handle_character(sp_rig_handle* h);
/// After a glTF file `out` was written from a textured character: one
/// warning line on stderr that the texture is not in it (nothing otherwise).
void sp_rig_handle_warn_textures(const char* cmd, const sp_rig_handle* h, const char* out);
/// Mesh vertices and triangles.
int sp_rig_handle_vertex_count(const sp_rig_handle* h);
int sp_rig_handle_triangle_count(const sp_rig_handle* h);

/// Parameters: names, bounds, defaults and groups (a skinned rig's
/// "<joint>.<channel>", a plugin's own names), param_count of them.
int sp_rig_handle_param_count(const sp_rig_handle* h);
const sp_param* sp_rig_handle_params(const sp_rig_handle* h);
/// How W_pose measures parameter k of a plugin ("angle", "length", "factor",
/// "weight"); NULL for a skinned rig, whose channels say it.
const char* sp_rig_handle_unit(const sp_rig_handle* h, int k);
/// A new pose (*p: param_count values, malloc'd, caller frees, even on
/// failure): the rig's start pose (a glTF file's stored pose, extras.sp_pose,
/// else its defaults; a plugin's defaults), overridden by the pose file
/// `path` when it is not NULL (pose_io.h: unknown names and non-numbers are
/// errors, values out of bounds clamped with a warning on stderr, counted in
/// *clamped, which may be NULL).
sp_result sp_rig_handle_read_pose(const sp_rig_handle* h, const char* path, double** p, int* clamped, sp_error* err);

/// Abstractions: abstraction_count of them in one array.
int sp_rig_handle_abstraction_count(const sp_rig_handle* h);
const sp_abstraction* sp_rig_handle_abstractions(const sp_rig_handle* h);
/// Index of the abstraction called `name` (NULL: the one the part's
/// `sp_part.abstraction` names, else the first one); -1 and a
/// message naming the rig and the abstractions it has if there is none.
int sp_rig_handle_pick_abstraction(const sp_rig_handle* h, const char* name, sp_error* err);

/// The sketch view on a width x height canvas (pixels, rounded; below 1: the
/// view's own canvas). A glTF file's camera or default view; a plugin's view,
/// framed on 640x480 like a glTF character's default view and then fitted to
/// the canvas, so that strokes drawn for one canvas size pose the same.
sp_camera sp_rig_handle_camera(const sp_rig_handle* h, double width, double height);

/// A solver for abstraction a seen by cam (sp_solver_create or
/// sp_solver_create_blackbox, whose failures it returns); h and cam must
/// outlive it.
sp_result sp_rig_handle_solver(const sp_rig_handle* h, int a, const sp_camera* cam, const sp_solve_desc* desc, sp_solver** out,
                               sp_error* err);

/// A random pose within bounds (sp_synth_params' amplitude rule), deterministic for a seed.
void sp_rig_handle_synth_params(const sp_rig_handle* h, uint64_t seed, double amplitude, double* p);
/// Abstraction a at p projected by cam, one stroke per curve.
sp_result sp_rig_handle_synth_sketch(const sp_rig_handle* h, int a, const sp_camera* cam, const double* p, sp_sketch* out,
                                     sp_error* err);

/// The rig at p as a character to render or save.
typedef struct sp_rig_posed {
    const sp_character* character; ///< the glTF character, or `baked`
    const double* params;          ///< p for a glTF character; NULL (its own static pose) for a baked one
    int abstraction;               ///< the asked abstraction's index in `character`, -1 when all were asked for
    int saved_abstractions;        ///< how many of character's abstractions a file gets (not the curves drawover adds)
    sp_character baked;            ///< a plugin's posed mesh (owned; zeroed for a glTF character)
} sp_rig_posed;
/// The rig at p: a glTF character as it is (with p), a plugin baked with
/// abstraction a (-1: all of them) and `cam` as its view.
sp_result sp_rig_handle_posed(const sp_rig_handle* h, int a, const double* p, const sp_camera* cam, sp_rig_posed* out,
                              sp_error* err);
/// Writes it as glTF (sp_gltf_save: .glb, else .gltf with embedded buffers).
sp_result sp_rig_posed_save(const sp_rig_posed* v, const char* path, sp_error* err);
/// Frees a baked character; zeroes v.
void sp_rig_posed_free(sp_rig_posed* v);

#endif
