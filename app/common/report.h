/// report.h: the solve report and other JSON the commands print or write
/// (DESIGN.md "Machine-readable outputs": keep the keys).
#ifndef SP_REPORT_H
#define SP_REPORT_H

#include <cjson/cJSON.h>

#include "sp/solver.h"

/// {"ms", "iterations", "icp_rounds", "stopped", "energy_before", "energy_after",
///  "terms_before": {...}, "terms_after": {...}, "mean_error_px", "max_error_px",
///  "bbox_diagonal_px", "curves": [{"curve", "stroke", "reversed", "mean_error_px", "max_error_px"}],
///  "unused_strokes", "note", "parameters": {...}}: `curve` names from ab,
/// "parameters" p by the names of `params` (count of them; no key when p is
/// NULL). Caller deletes.
cJSON* sp_report_json(const sp_solve_report* rep, const sp_abstraction* ab, const sp_param* params, int count, const double* p);
/// sp_report_json with a skinned rig's parameters (rig NULL: no "parameters").
cJSON* sp_report_to_json(const sp_solve_report* rep, const sp_rig* rig, const sp_abstraction* ab, const double* p);
/// Writes JSON to a file, all or nothing (temp file + rename). "-" writes to stdout.
sp_result sp_json_write_file(const char* path, const cJSON* j, sp_error* err);
/// A command's output files, written under temporary names beside them and
/// put in place together at the end, so that a command that fails leaves
/// every output as it was: the old file, or none.
///
///     sp_outputs o = {0};
///     const char* tmp;
///     if (sp_outputs_stage(&o, out, &tmp, &err) == SP_OK && write(tmp) == SP_OK) r = sp_outputs_commit(&o, &err);
///     else sp_outputs_undo(&o, &err);
typedef struct sp_outputs {
    const char* paths[8]; ///< as given
    char* staged[8];      ///< written instead, NULL when written in place
    char* target[8];      ///< what the rename replaces (a link's target), NULL: paths[i]
    int count;
} sp_outputs;
/// Sets *write_to to the name to write `path` under: a new file beside it
/// (its name ends as path does, which the writers go by), or `path` itself
/// for "-" and streams (a pipe, a device: written as they go). NULL path:
/// *write_to NULL, nothing added.
sp_result sp_outputs_stage(sp_outputs* o, const char* path, const char** write_to, sp_error* err);
/// Renames every staged file into place (a replaced file's permissions
/// kept) and forgets them.
sp_result sp_outputs_commit(sp_outputs* o, sp_error* err);
/// Removes the staged files and forgets them; nothing in place changes. A
/// staged name in err (a writer's message) becomes the name the user gave.
void sp_outputs_undo(sp_outputs* o, sp_error* err);
/// Prints JSON on stdout followed by a newline.
void sp_json_print(const cJSON* j);

#endif
