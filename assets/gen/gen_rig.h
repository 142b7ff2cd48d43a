/// gen_rig.h: skeleton, parameters, animation and saving for generated parts.
///
/// How to use:
///
///     sp_gen_rig g;
///     sp_gen_rig_init(&g);
///     int root = sp_gen_joint(&g, "tail_root", -1, sp_v3(0, 0, 0), 0.0);      // pivot, in-plane angle
///     int t1 = sp_gen_joint(&g, "tail_1", root, sp_v3(-0.3, 0, 0), M_PI);
///     sp_gen_param(&g, root, SP_CH_TX, -2, 2, SP_GROUP_POSE);
///     ... build an sp_gen_mesh skinned to these joints ...
///     sp_gen_clip_begin(&g, "sway", 2.0, 25);
///     sp_gen_clip_rz(&g, t1, angles);                 // 25 angles, radians, offsets from rest
///     sp_gen_save(&g, &mesh, &(sp_gen_save_desc){.part = &part}, "assets/tail.glb", &err);
///
/// Joints are placed by their pivot in the part's rest space and an
/// in-plane rest angle (rotation about +Z: the bone's direction in the side
/// view), so every joint's local Z is the view axis and an `rz` parameter
/// is a rotation in the sketch plane; local X runs along the bone, so `sx`
/// is the bone's length and `sy` its thickness in the view.
#ifndef SP_GEN_RIG_H
#define SP_GEN_RIG_H

#include <stdbool.h>

#include "gen_mesh.h"
#include "sp/gltf.h"
#include "sp/rig.h"

/// A rig under construction (joints in parent-first order).
typedef struct sp_gen_rig {
    sp_rig rig;
    sp_vec3* pivot; ///< joint_count world rest pivots
    double* angle;  ///< joint_count world in-plane rest angles, radians
    int clip_keys;  ///< keys of the clip being built
    double clip_s;  ///< its duration, seconds
} sp_gen_rig;

void sp_gen_rig_init(sp_gen_rig* g);
void sp_gen_rig_free(sp_gen_rig* g);
/// Adds a joint (parent before child); returns its index.
int sp_gen_joint(sp_gen_rig* g, const char* name, int parent, sp_vec3 pivot, double angle);
/// Declares a parameter (bounds: radians, offsets in parent units, scale factors).
void sp_gen_param(sp_gen_rig* g, int joint, sp_channel ch, double min, double max, sp_group group);

/// Starts a looping animation clip of `keys` evenly spaced keys over
/// `duration_s` (the last key repeats the first for a seamless loop).
void sp_gen_clip_begin(sp_gen_rig* g, const char* name, double duration_s, int keys);
/// A rotation channel: rest rotation then Rz(angles[k]) (keys values):
/// the clip's offset on the joint's `rz` parameter.
void sp_gen_clip_rz(sp_gen_rig* g, int joint, const double* angles);
/// A scale channel: rest scale times factors[k] (keys values): offsets on
/// the joint's sx/sy/sz (factor - 1).
void sp_gen_clip_scale(sp_gen_rig* g, int joint, const sp_vec3* factors);
/// A translation channel: rest translation plus offsets[k] (parent units).
void sp_gen_clip_translate(sp_gen_rig* g, int joint, const sp_vec3* offsets);

typedef struct sp_gen_save_desc {
    const sp_part* part;   ///< the scene's extras.sp_part, or NULL (copied)
    int outline_points;    ///< 0: 150
    double frame_margin;   ///< the camera frames the rest pose grown by this factor (0: 1.35)
    const char* name;      ///< for messages
    /// Sets the bounds of the root's tx/ty parameters to the sketch view:
    /// +- half the canvas's larger side in world units, i.e. the part's
    /// origin may go anywhere on the canvas (and no further).
    bool root_reach_view;
    /// Further abstractions (e.g. a `stick`), written before the outline;
    /// sp_gen_save moves them into the rig (their arrays become the rig's
    /// and the structs are zeroed), also when it fails.
    sp_abstraction* abstractions;
    int abstraction_count;
    /// No outline abstraction (a character posed through its stick figure only).
    bool no_outline;
} sp_gen_save_desc;

/// Packs the mesh into the rig, traces the outline in the side view,
/// finalizes, and writes the .glb (vertex colours linearised, the side
/// camera, the part extras). Frees nothing of g or mesh.
sp_result sp_gen_save(sp_gen_rig* g, const sp_gen_mesh* mesh, const sp_gen_save_desc* d, const char* path, sp_error* err);

/// The side view used for every part: orthographic, looking along -Z, +Y up,
/// framing the box [lo, hi] grown by `margin`, on 640x480 (sp_part_side_camera).
sp_camera sp_gen_side_camera(sp_vec3 lo, sp_vec3 hi, double margin);

/// The outline abstraction of the mesh without its decorations, traced in the
/// view `cam` by partdb's sp_outline_trace (sp/outline.h) with `points`
/// points and `depth_passes` passes of depth smoothing. Its points are bind
/// space: the generator's rest space.
sp_result sp_gen_outline(const sp_gen_mesh* mesh, const sp_camera* cam, int points, int depth_passes, sp_abstraction* out,
                         sp_error* err);

#endif
