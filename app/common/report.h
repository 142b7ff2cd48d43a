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
/// Prints JSON on stdout followed by a newline.
void sp_json_print(const cJSON* j);

#endif
