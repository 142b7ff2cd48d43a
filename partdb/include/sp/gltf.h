/// sp/gltf.h: rigged characters and parts in and out of glTF 2.0.
///
/// How to use:
///
///     sp_character ch = {0};
///     sp_error err = {0};
///     if (sp_gltf_load("CesiumMan.glb", &ch, &err) != SP_OK) { fprintf(stderr, "%s\n", err.text); ... }
///     ... ch.rig is a finalized sp_rig; ch.pose its stored pose ...
///     sp_gltf_save(&ch, ch.pose, "posed.glb", &err);
///     sp_character_free(&ch);
///
/// The loader reads .gltf (data: URI buffers, or external ones beside the
/// file) and .glb, the sketch-abstraction conventions of DESIGN.md (skinned
/// LINE_STRIP/LINE_LOOP curves with `sp_abstraction` extras, `sp_dofs` on
/// joints, `sp_part` on the scene, the scene camera), renormalises skin
/// weights and records a warning, refuses inverse bind matrices glTF forbids
/// (not finite, a fourth row other than [0, 0, 0, 1]) and warns of singular
/// ones, and for a file without our extras derives a stick-figure abstraction
/// ("stick", a curve per bone chain, ordered) and default rotation DOFs.
/// The saver writes a fresh .glb (or .gltf with embedded buffers, by file
/// extension) from the structs: parameters baked into the joint nodes, the
/// rest TRS and parameter values kept in extras so that loading the export
/// gives back the same rig and the same parameters.
#ifndef SP_GLTF_H
#define SP_GLTF_H

#include <stdbool.h>

#include "sp/part.h"
#include "sp/result.h"
#include "sp/rig.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { SP_WARNING_MAX = 256 };

typedef struct sp_character {
    sp_rig rig;               ///< finalized
    double* pose;             ///< rig.param_count values: stored pose (extras `sp_pose`), else defaults
    float* colors;            ///< rig.vertex_count by 4, linear RGBA base colour per vertex
    bool has_camera;          ///< a camera came from the file's scene
    sp_camera camera;         ///< the sketch view: the file's camera, else a front orthographic view of the rest pose
    bool has_part;            ///< the scene has `extras.sp_part` (a kiosk part)
    sp_part part;             ///< it, parsed (sp/part.h)
    bool derived_abstraction; ///< the stick figure was derived from the skeleton
    bool derived_dofs;        ///< default rotation DOFs were added
    int mesh_skins;           ///< distinct skins of the scene's skinned meshes (the rig is the first one's)
    bool textured;            ///< a skinned mesh's material has a base colour texture (never read: grey)
    int warning_count;
    char (*warnings)[SP_WARNING_MAX]; ///< one line each
} sp_character;

/// Loads a .gltf or .glb. On failure err names the file and the problem and
/// *out is left zeroed.
sp_result sp_gltf_load(const char* path, sp_character* out, sp_error* err);
/// The files the .gltf or .glb at `path` names besides itself (external
/// buffers and images whose uri is a path relative to it: the only ones the
/// loader reads, beside it), so that a
/// command keeps its outputs off its inputs: *files holds *count paths, free
/// them with sp_gltf_files_free. None (SP_OK) for a file that is not regular
/// or has no JSON to read: the loader says what is wrong with it.
sp_result sp_gltf_external_files(const char* path, char*** files, int* count, sp_error* err);
void sp_gltf_files_free(char** files, int count);
/// Loads from memory (used by the fuzzer and the database); `what` names it in messages.
sp_result sp_gltf_load_memory(const void* data, size_t size, const char* what, sp_character* out, sp_error* err);
/// Writes the character posed at `params` (rig.param_count, NULL = ch->pose).
/// ".glb" writes binary, anything else .gltf with embedded buffers.
sp_result sp_gltf_save(const sp_character* ch, const double* params, const char* path, sp_error* err);
/// Same as sp_gltf_save to a malloc'd GLB in memory (*data freed by the caller with free()).
sp_result sp_gltf_save_memory(const sp_character* ch, const double* params, void** data, size_t* size, sp_error* err);
/// One part of a scene written by sp_gltf_save_scene.
/// A polyline drawn on a part (ink: a kiosk visitor's eye or spots),
/// skinned by the part's skin like its mesh.
typedef struct sp_gltf_scene_line {
    int point_count;        ///< at least 2
    const double* rest;     ///< point_count by 3, the part's bind space (like its mesh's rest vertices)
    const uint16_t* joints; ///< point_count by 4, the part's rig joint indices
    const float* weights;   ///< point_count by 4
    float color[4];         ///< linear RGBA
} sp_gltf_scene_line;

typedef struct sp_gltf_scene_part {
    const sp_character* character; ///< its rig, mesh and colours (written as its own skin)
    const double* params;          ///< the pose baked into its joint nodes (rig.param_count); NULL: character->pose
    const char* name;              ///< prefix of its node, mesh and skin names ("<name>/<joint>"); NULL: "part<i>"
    sp_mat4 placement;             ///< its placement node, parent of the part's root joints: model space -> scene;
                                   ///< must be a similarity (rotation, uniform positive scale, translation)
    const sp_animation* animation; ///< channels on the part's joints (channel.joint = rig joint index); NULL: none
    int placement_key_count;       ///< keys of an animated placement (0: static), LINEAR
    const float* placement_times;  ///< placement_key_count seconds, increasing
    const float* placement_trs;    ///< placement_key_count by 8: tx ty tz, qx qy qz qw, uniform scale
    int line_count;                ///< ink drawn on the part: LINE_STRIP nodes "<name>/ink<k>" on its skin
    const sp_gltf_scene_line* lines;
} sp_gltf_scene_part;

/// A scene of several rigged parts (e.g. the kiosk's dragon).
typedef struct sp_gltf_scene_desc {
    int part_count;
    const sp_gltf_scene_part* parts;
    const char* animation_name; ///< the ONE animation holding every part's channels; NULL: "animation"
    const char* extras_json;    ///< the scene's extras as a JSON object text, or NULL
    bool abstractions;          ///< also write each part's abstraction curves (off: viewers draw them as lines)
    const sp_camera* camera;    ///< written as the scene's camera (a node "view" at the inverse of its view); NULL: none
} sp_gltf_scene_desc;

/// Writes several parts into one glTF (".glb" binary, else .gltf with
/// embedded buffers): per part a placement node, its joint nodes under it,
/// its own skin and skinned mesh; every part's channels (joints and
/// placement) in one animation. SP_ERR_INVALID for no parts, a placement that
/// is not a similarity, or non-finite values.
sp_result sp_gltf_save_scene(const sp_gltf_scene_desc* desc, const char* path, sp_error* err);

/// The joints of a skeleton of one chain (a tail: its tip up to the root) or
/// two chains from one joint (a pair of legs: one leaf up to the joint they
/// share, then down to the other leaf), in that order, at most cap of them;
/// 0 for any other skeleton or one of fewer than 3 joints.
int sp_rig_line_joints(const sp_rig* rig, int* order, int cap);
/// Appends the `line` abstraction to such a rig: one open curve (ordered
/// pairs) through those joints' pivots at the default parameters, each end
/// pushed on by 0.8 of its last bone (as the training's line shape), about
/// 96 points, each rigid with the bone it lies on. What a visitor draws as
/// one line (a wavy tail, legs as a peaked line) is fitted with it.
/// *added is false, and nothing changes, for another skeleton or a rig that
/// already has a `line`; also on SP_ERR_NO_MEMORY or SP_ERR_INVALID (a
/// singular skin matrix), when the rig is not to be fitted with a line.
sp_result sp_rig_add_line(sp_rig* rig, bool* added, sp_error* err);
/// Appends the `limb` abstraction to a rig of two chains (a pair of legs):
/// the same kind of curve as `line`, from `leaf` (one of the two leaves)
/// up to the joint the chains share. A pair of legs drawn as one straight
/// line is one leg, the other hidden behind it or stepping apart; the
/// `line` would fold to take it (foot, hip and foot along one stroke).
/// *added is false, and nothing changes, for another skeleton, a leaf that
/// is not one of the two, or a rig that already has a `limb`.
sp_result sp_rig_add_limb(sp_rig* rig, int leaf, bool* added, sp_error* err);
/// Makes a character of a finalized rig, which it takes over (*rig is zeroed):
/// default pose, light grey vertices, the default front orthographic camera.
/// For generators and tests that build rigs in code and want to save them.
sp_result sp_character_from_rig(sp_rig* rig, sp_character* out, sp_error* err);
/// Deep copy (SP_ERR_NO_MEMORY leaves *dst zeroed).
sp_result sp_character_clone(const sp_character* src, sp_character* dst, sp_error* err);
/// Frees everything the character owns and zeroes it.
void sp_character_free(sp_character* ch);

#ifdef __cplusplus
}
#endif
#endif
