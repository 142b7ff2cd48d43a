/// pose_io.h: the pose file that `export --pose`, `pose --start`, `synth
/// --truth` and the reports share: JSON `{"parameters": {"<name>": value,
/// ...}}`, the names of a rig's parameter table (a skinned rig's
/// "<joint>.<channel>", a black-box rig's own names; sp_rig_handle_params).
///
///     sp_rig_defaults(rig, p);                       // or a stored pose
///     if (sp_pose_read("p.json", rig->params, rig->param_count, p, NULL, &err) != SP_OK) ... err.text ...
///
/// Reading overwrites only the listed parameters. An unknown name, a value
/// that is not a finite number or a malformed file is an error naming the
/// file and the parameter; a value outside its bounds is clamped and reported
/// on stderr as a one-line warning.
#ifndef SP_POSE_IO_H
#define SP_POSE_IO_H

#include <cjson/cJSON.h>

#include "sp/result.h"
#include "sp/rig.h"

/// Reads `path` into p (count values of `params`, pre-filled by the caller).
/// *clamped (may be NULL) receives the number of clamped values.
sp_result sp_pose_read(const char* path, const sp_param* params, int count, double* p, int* clamped, sp_error* err);
/// Same from JSON text (len bytes: a NUL in it is refused, not an end);
/// `what` names the source in messages.
sp_result sp_pose_parse(const char* text, size_t len, const char* what, const sp_param* params, int count, double* p,
                        int* clamped, sp_error* err);
/// {"<name>": value, ...} for p (caller deletes it).
cJSON* sp_pose_params_json(const sp_param* params, int count, const double* p);
/// The pose object {"parameters": {...}} for p (caller deletes it).
cJSON* sp_pose_to_json(const sp_param* params, int count, const double* p);
/// Writes the pose file.
sp_result sp_pose_write(const char* path, const sp_param* params, int count, const double* p, sp_error* err);

#endif
