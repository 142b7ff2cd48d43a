/// sp/part.h: a kiosk part's description, the scene's `extras.sp_part`
/// (DESIGN.md), parsed once, here.
///
/// How to use:
///
///     sp_part part = {0};
///     sp_error err = {0};
///     if (sp_part_parse_json("{\"category\": \"tail\", \"attach\": {\"joint\": \"tail_root\"}}", "tail.glb", &part, &err)
///         != SP_OK) { fprintf(stderr, "%s\n", err.text); ... }
///     ... part.category, part.attach.joint ...
///     char* text = NULL;
///     sp_part_write_json(&part, &text, &err); // {"attach":{"joint":"tail_root"},"category":"tail"}
///     free(text);
///     sp_part_free(&part);
///
/// The loader (sp/gltf.h) fills sp_character.part from the file and the
/// savers write it back through the same writer. Keys the struct does not
/// know, at the top level, in a socket or in `attach`, are kept verbatim as
/// compact JSON (`extra`) and merged back on writing, so that a part survives
/// load -> save -> load whatever else its file carries. Known keys are written
/// in their full form: `"attach": "<joint>"` becomes `{"joint": "<joint>"}`,
/// `"accepts": "<category>"` a list of one. The writer sorts keys as glTF
/// files are written (tinygltf's maps), so its text equals the file's. One
/// loss in files: tinygltf's values have no null, so an unknown key whose
/// value is null, or a null inside one, is dropped when saved as glTF.
#ifndef SP_PART_H
#define SP_PART_H

#include <stdbool.h>

#include "sp/math.h"
#include "sp/result.h"
#include "sp/rig.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Where a body holds a part of another kind (a hint: which side and facing).
typedef struct sp_part_socket {
    char name[SP_NAME_MAX];       ///< required; equals the category it takes (assets/) unless `accepts` says more
    char joint[SP_NAME_MAX];      ///< the joint it rides, "" = the part's root
    bool has_position;            ///< else the joint's origin
    sp_vec3 position;             ///< model space at the rest pose
    int accept_count;             ///< further categories it takes
    char (*accepts)[SP_NAME_MAX]; ///< accept_count names (owned)
    char* extra;                  ///< keys the struct does not know, a compact JSON object, or NULL (owned)
} sp_part_socket;

/// Where the part meets a body.
typedef struct sp_part_attach {
    char socket[SP_NAME_MAX]; ///< the socket it prefers, "" = none
    char joint[SP_NAME_MAX];  ///< its attachment joint, "" = the root
    bool has_position;        ///< else the joint's origin
    sp_vec3 position;         ///< model space at the rest pose
    char* extra;              ///< unknown keys, compact JSON object, or NULL (owned)
} sp_part_attach;

/// A scene's `extras.sp_part`. Every key is optional.
typedef struct sp_part {
    char category[SP_NAME_MAX];    ///< "" = none
    char abstraction[SP_NAME_MAX]; ///< what its sketches show, "" = none said
    char family[SP_NAME_MAX];      ///< parts told apart by where on a body they are drawn (front and hind legs), "" = none
    int socket_count;              ///< a part with sockets is a body
    sp_part_socket* sockets;       ///< socket_count (owned)
    bool has_attach;               ///< it says where it attaches
    sp_part_attach attach;         ///< (has_attach)
    char* extra;                   ///< unknown keys, compact JSON object, or NULL (owned)
} sp_part;

/// Parses an sp_part JSON object (text); `what` (the file) names it in
/// messages. SP_ERR_PARSE for text that is not JSON, SP_ERR_INVALID (one
/// line) for a known key of the wrong kind: a name (`category`,
/// `abstraction`, `family`, a socket's or a joint's) that is not a string of 1
/// to SP_NAME_MAX - 1 characters, `sockets` not a list of objects, a socket
/// without a name, a position that is not 3 finite numbers, `accepts` not a
/// name or a list of names, `attach` not an object or a joint name. On
/// failure *out is zeroed.
sp_result sp_part_parse_json(const char* json, const char* what, sp_part* out, sp_error* err);
/// Writes the part as compact JSON, keys sorted, unknown keys merged back
/// (*json freed by the caller with free()). SP_ERR_INVALID for a socket
/// without a name or a position that is not finite.
sp_result sp_part_write_json(const sp_part* part, char** json, sp_error* err);
/// Deep copy into *dst (zeroed on failure).
sp_result sp_part_copy(const sp_part* src, sp_part* dst, sp_error* err);
/// Frees what the part owns and zeroes it.
void sp_part_free(sp_part* part);
/// Whether s is a plain name, as the part database takes part names and
/// categories (they name files and folders of an export): [A-Za-z0-9_.-], 1
/// to SP_NAME_MAX - 1 characters, not starting with '.'.
bool sp_part_name_is_plain(const char* s);

#ifdef __cplusplus
}
#endif
#endif
