/// sp/derive.h: what the kiosk needs of a rigged glTF made elsewhere.
///
/// How to use (the `sketchpose derive` command and `db add-part`):
///
///     sp_character src = {0}, part = {0};
///     sp_error err = {0};
///     if (sp_gltf_load("fox.glb", &src, &err) != SP_OK) ...
///     sp_derive_info info;
///     if (sp_part_derive(&src, &(sp_derive_desc){.category = "head"}, &part, &info, &err) != SP_OK) {
///         fprintf(stderr, "%s\n", err.text); ...   // several skins, no mesh, an unknown --attach-joint ...
///     }
///     sp_gltf_save(&part, NULL, "fox_sp.glb", &err);
///     sp_character_free(&part), sp_character_free(&src);
///
/// The derived part follows the conventions of the shipped parts (DESIGN.md,
/// "Generated dragon parts"): the whole part is turned so that its sketch view
/// (the file's camera, else the default view, else `view`) looks along -Z with
/// +Y up, and its camera is that side view (orthographic, 640 x 480, framing
/// the rest pose grown by 35%). Joints above every joint that moves a vertex
/// (a Z-up node, an armature) are folded into the others; every remaining
/// joint gets a frame at its rest pivot whose X runs along its bone in the
/// view and whose Z is the view axis, so that `rz` turns it in the sketch
/// plane; the skinning is unchanged (inverse binds absorb the new frames), so
/// the mesh deforms exactly as the file's rig does. Parameters: the root has
/// the placement rz (+-1 rad), tx and ty (the sketch view: +- half the
/// canvas's larger side) and s (0.5..2); every other joint that moves a vertex
/// has rz (+-0.8 rad, widened to what the clip does, at most +-2) and a bone
/// scale s whose bounds keep the scale of every bone, with the joints above
/// it, within 0.6..1.6. Abstractions: `outline` (sp/outline.h: 150 points,
/// closest) then `stick` (a curve per bone chain, ordered). The first
/// animation with keys becomes the part's only clip, re-keyed on the new
/// frames (its key times, plus 30 per second where it is not linear).
/// `sp_part` gets `category`, `abstraction` and `attach` {socket, joint,
/// position} (the root's pivot, or the named joint's), as the kiosk reads it.
#ifndef SP_DERIVE_H
#define SP_DERIVE_H

#include <stdbool.h>

#include "sp/gltf.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Which way the sketch camera looks, in the file's Y-up world.
typedef enum sp_derive_view {
    SP_DERIVE_VIEW_AUTO, ///< the file's camera, else the default view (along -Z or -X, the wider spread)
    SP_DERIVE_VIEW_NEG_Z,
    SP_DERIVE_VIEW_POS_Z, ///< the -Z view from behind: a part modelled facing left then faces right
    SP_DERIVE_VIEW_NEG_X,
    SP_DERIVE_VIEW_POS_X,
} sp_derive_view;

/// "-z" -> SP_DERIVE_VIEW_NEG_Z, ...; "auto"; returns false for anything else.
bool sp_derive_view_parse(const char* s, sp_derive_view* out);

/// How to derive. Zero means the default.
typedef struct sp_derive_desc {
    const char* category;     ///< sp_part.category (1 to SP_NAME_MAX - 1 characters); NULL: the file's, else none
    const char* abstraction;  ///< "outline" (NULL) or "stick": what the part's sketches show (sp_part.abstraction)
    const char* attach_joint; ///< the joint the part attaches by (NULL: the root)
    sp_derive_view view;
    int outline_points; ///< 0: 150
} sp_derive_desc;

/// What was derived (sp_derive_info.derived).
enum sp_derived {
    SP_DERIVED_OUTLINE = 1 << 0,
    SP_DERIVED_STICK = 1 << 1,
    SP_DERIVED_PARAMETERS = 1 << 2,
    SP_DERIVED_ATTACH = 1 << 3,
    SP_DERIVED_CLIP = 1 << 4,
    SP_DERIVED_VIEW = 1 << 5,
};
enum { SP_DERIVED_COUNT = 6 };
/// "outline", "stick", "parameters", "attach", "clip", "view" for bit i (1 << i); NULL past the end.
const char* sp_derived_name(int bit);

/// What the derivation did.
typedef struct sp_derive_info {
    unsigned derived;       ///< sp_derived flags
    int joints_folded;      ///< joints above the skin's influence folded into the others (e.g. a Z-up node)
    bool root_added;        ///< the skin had several top joints: a root "sp_root" was added above them
    char root[SP_NAME_MAX]; ///< the root joint (the placement parameters)
    char attach_joint[SP_NAME_MAX];
    int outline_regions;    ///< pieces of the side silhouette (the outline follows the largest)
    double outline_dropped; ///< share of the silhouette in the other pieces
    char clip[SP_NAME_MAX]; ///< the clip's name ("" without one)
    int clip_keys;
    int clip_channels;
} sp_derive_info;

/// True when the part carries no sketch abstraction of its own (no
/// `sp_abstraction` curves): what `db add-part` derives for.
bool sp_part_needs_derivation(const sp_character* ch);

/// Derives a kiosk part from any loaded character with one skin (see the top
/// of this header). *out is a new character (sp_character_free); src is not
/// changed. `info` may be NULL. Refused with one line naming the problem and
/// *out zeroed: several skins (SP_ERR_UNSUPPORTED), no triangles, an unknown
/// or motionless attach joint, an abstraction other than outline/stick, a
/// silhouette with no area (SP_ERR_INVALID). Warnings (the source's, and e.g.
/// a silhouette in pieces) are on out->warnings.
sp_result sp_part_derive(const sp_character* src, const sp_derive_desc* desc, sp_character* out, sp_derive_info* info,
                         sp_error* err);

/// The side view of every part: orthographic, looking along -Z, +Y up, framing
/// the box [lo, hi] grown by `margin` (1.35 for the parts), on 640 x 480.
sp_camera sp_part_side_camera(sp_vec3 lo, sp_vec3 hi, double margin);

#ifdef __cplusplus
}
#endif
#endif
