/// foreign_gltf.h: a rigged glTF as curators get them from elsewhere, for the
/// derivation's tests and benchmark (sp/derive.h, `sketchpose derive`).
///
/// A lizard facing +X in the XY plane (body, neck and head, tail, four legs;
/// 14 joints laid out as Blender exports them: each joint's +Y along its
/// bone, rolled about it, under a non-joint "Armature" node), written without
/// any sketchpose extras as several meshes and primitives under one skin
/// (indexed and non-indexed triangles, open tube ends: not watertight), with
/// a looping "sway" clip keyed on absolute local rotations. Knobs give the
/// cases the derivation must survive: Z-up data turned upright by the
/// Armature node (like CesiumMan), a part modelled facing left (-X), a
/// texture whose image file is missing, a second skin, no skin, any size.
///
///     sp_foreign_write(&(sp_foreign_desc){.z_up = true, .vertices = 100000}, "big.glb");
#ifndef SP_FOREIGN_GLTF_H
#define SP_FOREIGN_GLTF_H

#include <stdbool.h>

typedef struct sp_foreign_desc {
    int vertices;         ///< about this many vertices (within a few percent); 0: about 3000
    bool z_up;            ///< vertex and joint data Z-up, the Armature node turns them Y-up
    bool facing_left;     ///< head towards -X (mirrored; windings kept outward)
    bool missing_texture; ///< the body's material samples "lizard_skin.png", which does not exist
    bool two_skins;       ///< the legs' mesh uses a second skin (a file derive must refuse)
    bool no_skin;         ///< meshes without skins or skin attributes (refused too)
    bool no_clip;         ///< no animation
    double clip_scale;    ///< the clip's key times times this (0: 1; the clip lasts 2 s)
} sp_foreign_desc;

/// The lizard's joints (index = node order in the file after the Armature).
enum { SP_FOREIGN_JOINTS = 14 };
extern const char* const sp_foreign_joint_names[SP_FOREIGN_JOINTS];

/// Writes the lizard: `path` ending in .gltf gets a .bin beside it (uri
/// "<name>.bin"), anything else is one .glb. Returns the vertex count, or -1
/// with a message on stderr.
int sp_foreign_write(const sp_foreign_desc* d, const char* path);

#endif
