/// plugin_rig.h: black-box rigs (sp/blackbox.h) on the command line.
///
/// A `--rig` path ending in `.so` is a plugin: `pose` fits it through
/// finite differences and `synth` draws it; both then behave as with a glTF
/// rig (same report keys, PNG, exit codes). To show and export a result the
/// posed mesh and abstraction are baked into a static character (one joint,
/// no parameters), which the ordinary snapshot and glTF writer take.
#ifndef SP_PLUGIN_RIG_H
#define SP_PLUGIN_RIG_H

#include <cjson/cJSON.h>
#include <stdbool.h>

#include "sp/blackbox.h"
#include "sp/gltf.h"

/// True when `path` names a plugin (ends with .so or has .so. in its name).
bool sp_is_plugin_path(const char* path);
/// Abstraction `name` (NULL: the first), or -1 with a message naming the
/// plugin and the abstractions it has.
int sp_plugin_pick_abstraction(const sp_blackbox* bb, const char* path, const char* name, sp_error* err);
/// The plugin's sketch view on the sketch's canvas (640x480 when it has none),
/// framed as sp_canvas_camera frames glTF characters.
sp_camera sp_plugin_camera(const sp_blackbox* bb, int width, int height);
/// Reads a pose file {"parameters": {"<name>": value, ...}} into p (pre-filled
/// by the caller). Unknown names and non-numbers are errors naming the file;
/// values outside the bounds are clamped with a warning on stderr.
sp_result sp_plugin_read_pose(const char* path, const sp_blackbox* bb, double* p, sp_error* err);
/// {"parameters": {...}} for p (caller deletes).
cJSON* sp_plugin_pose_json(const sp_blackbox* bb, const double* p);
/// Bakes the rig at p into a static character: the posed mesh with the
/// rig's colours, abstraction a (-1: all of them) as rigid curves, and `cam`
/// as its view.
sp_result sp_plugin_bake(const sp_blackbox* bb, int a, const double* p, const sp_camera* cam, sp_character* out, sp_error* err);
/// Loads a plugin and bakes it at its defaults overridden by the pose file
/// `pose` (may be NULL), with every abstraction and its sketch view on 640x480
/// (what `render` shows).
sp_result sp_plugin_load_posed(const char* path, const char* pose, sp_character* out, sp_error* err);

/// `sketchpose pose` for a plugin, after cmd_pose parsed the options.
int sp_plugin_pose(const char* rig_path, const char* abs_name, const char* strokes, const char* start, const char* out,
                   const char* render, const char* report, const sp_solve_desc* desc);
/// `sketchpose inspect` for a plugin: the inspect keys of DESIGN.md (no
/// joints or animations; parameters carry their `unit`) plus "black_box": true.
int sp_plugin_inspect(const char* rig_path);
/// `sketchpose synth` for a plugin: a random pose (seed >= 0) or the pose
/// file `pose`; canvas w x h (0: 640x480); noise: Gaussian jitter, pixels.
int sp_plugin_synth(const char* rig_path, const char* abs_name, int seed, const char* pose, double amplitude, const char* out,
                    const char* truth, int w, int h, double noise);

#endif
