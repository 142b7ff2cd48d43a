/// outputs.h: a command's output files, all or none.
///
/// Each output is written under a temporary name in its own folder and put
/// in place with the others at the end, so that a command that fails (in its
/// work, in a writer, or in putting one of them in place) leaves every output
/// as it was: the old file, or none.
///
///     sp_outputs o = {0};
///     const char* tmp;
///     if (sp_outputs_stage(&o, out, &tmp, &err) == SP_OK && write(tmp) == SP_OK) r = sp_outputs_commit(&o, &err);
///     else sp_outputs_undo(&o, &err);
#ifndef SP_OUTPUTS_H
#define SP_OUTPUTS_H

#include "sp/result.h"

#define SP_OUTPUTS_MAX 8

typedef struct sp_outputs {
    const char* paths[SP_OUTPUTS_MAX]; ///< as given
    char* staged[SP_OUTPUTS_MAX];      ///< written instead, NULL when written in place
    char* target[SP_OUTPUTS_MAX];      ///< what the rename replaces: paths[i] with its links followed
    int count;
} sp_outputs;

/// Sets *write_to to the name to write `path` under: a new hidden file in
/// the folder of the file `path` names (through links, a dangling one's
/// too), ending in path's own extension, which the writers go by; or `path`
/// itself for "-" and streams (a pipe, a device: written as they go). NULL
/// path: *write_to NULL, nothing added.
sp_result sp_outputs_stage(sp_outputs* o, const char* path, const char** write_to, sp_error* err);
/// Renames every staged file into place (a replaced file keeps its
/// permissions, a link stays a link) and forgets them. When one cannot be
/// put in place, those already put are put back (a replaced file from a hard
/// link kept until the end, a new one removed) and the staged files removed.
/// Interrupting signals wait until it is done.
sp_result sp_outputs_commit(sp_outputs* o, sp_error* err);
/// Removes the staged files and forgets them; nothing in place changes. A
/// staged name in err (a writer's message) becomes the name the user gave.
void sp_outputs_undo(sp_outputs* o, sp_error* err);

#endif
