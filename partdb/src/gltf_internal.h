// gltf_internal.h: the C side of the glTF import, shared by the tinygltf
// adapter (gltf_adapter.cpp) and character.c / stickfig.c. The adapter turns
// the glTF document into plain C (joints, vertices, curves, extras as JSON
// text); everything that does not need tinygltf happens here, in C.
#ifndef SP_GLTF_INTERNAL_H
#define SP_GLTF_INTERNAL_H

#include <stdbool.h>

#include "sp/gltf.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Default canvas for a file camera without `sp_canvas` extras, pixels.
enum { SP_GLTF_CANVAS_W = 640, SP_GLTF_CANVAS_H = 480 };
/// Limits of the derived rotation DOFs, radians (120 degrees).
#define SP_GLTF_DEFAULT_ROT_LIMIT 2.0943951023931957
/// Colour of vertices whose material has only a texture: a neutral light grey.
#define SP_GLTF_TEXTURE_GREY 0.8f
/// Points sampled along each bone of the derived stick figure.
enum { SP_STICK_POINTS_PER_BONE = 8 };

/// What the adapter learned about the rig's joints besides sp_rig itself.
typedef struct sp_import {
    const char* what; ///< file name for messages
    bool* is_skin;    ///< joint_count: a joint of the skin (not a mere ancestor)
    bool* has_rest;   ///< joint_count: `sp_rest` extras replaced the rest TRS
    sp_vec3* node_t;  ///< joint_count: node TRS as written in the file (posed, for our exports)
    sp_quat* node_r;
    sp_vec3* node_s;
    bool any_dofs;            ///< some joint declared `sp_dofs` (then no default DOFs are added)
    const char* scene_extras; ///< JSON text of the scene's extras or NULL
} sp_import;

/// Applies one joint node's extras (JSON text, may be NULL): `sp_dofs` adds
/// parameters (sets *has_dofs), `sp_rest` replaces the rest TRS (sets *has_rest).
sp_result sp_gltf_joint_extras(sp_rig* rig, int joint, const char* json, bool* has_dofs, bool* has_rest, const char* what,
                               sp_error* err);

/// Curve identity from a node's (or primitive's) extras. *is_curve is false
/// when there is no `sp_abstraction`.
typedef struct sp_curve_tag {
    bool is_curve;
    char abstraction[SP_NAME_MAX];
    char curve[SP_NAME_MAX];
    bool has_correspondence;
    sp_correspondence correspondence;
} sp_curve_tag;
sp_result sp_gltf_curve_extras(const char* json, sp_curve_tag* tag, const char* what, sp_error* err);

/// Appends one skinned curve (n points, bind space) to the abstraction named
/// `abstraction` (created if new). Copies the arrays.
sp_result sp_gltf_append_curve(sp_rig* rig, const char* abstraction, sp_correspondence corr, const char* curve, bool closed,
                               int n, const double* rest, const uint16_t* joints, const float* weights);

/// Derives the "stick" abstraction from the skeleton (finalized rig, default
/// parameters): a curve per bone chain between skin joints. Returns SP_OK and
/// appends nothing when there is no bone. A bone whose joint's skin matrix
/// flattens space (sp_mat4_inverse_rel, SP_MAT4_FLAT) gets no points;
/// `flat_bones` (may be NULL) counts them.
sp_result sp_gltf_derive_stick(sp_rig* rig, const bool* is_skin, int* flat_bones, sp_error* err);

/// Everything after the adapter filled ch->rig (unfinalized), ch->colors and
/// perhaps ch->camera: default DOFs, finalize, warnings, the derived stick
/// figure, the pose (sp_rest node TRS, then `sp_pose`), `sp_part`, the
/// default camera.
sp_result sp_gltf_finish(sp_character* ch, const sp_import* im, sp_error* err);

/// sp/part.h's reader and writer on cJSON trees: the loader's scene extras
/// and the savers' tinygltf values.
struct cJSON;
sp_result sp_part_from_cjson(const struct cJSON* j, const char* what, sp_part* out, sp_error* err);
sp_result sp_part_to_cjson(const sp_part* part, struct cJSON** out, sp_error* err);

/// Splits an affine matrix into translation, rotation and scale (a negative
/// determinant goes into the x scale; shear is lost), as glTF nodes hold it.
void sp_gltf_decompose(const sp_mat4* a, sp_vec3* t, sp_quat* r, sp_vec3* s);

/// Reads a pose object {"<joint>.<channel>": value, ...} (JSON text) into p;
/// unknown names and non-numbers become warnings on ch; values are clamped.
void sp_gltf_apply_pose_json(sp_character* ch, const char* parameters_json, double* p);

/// The warning a part whose abstraction `a` has several curves gets (the
/// kiosk fits one stroke per part), written into line; false (nothing
/// written) for one curve. derive and add-part say it in the same words.
bool sp_part_curves_warning(const sp_rig* rig, int a, char* line, size_t cap);

/// The largest bound an `sp_dofs` move may have, in the rig's units: the
/// readers refuse more, and derive refuses a model whose placement would
/// need more (half its framed size).
#define SP_GLTF_MOVE_MAX 1e6

/// Appends a warning line to ch->warnings (printf style).
void sp_character_warn(sp_character* ch, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#ifdef __cplusplus
}
#endif
#endif
