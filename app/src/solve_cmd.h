/// solve_cmd.h: the solve-report-write path that `pose`, `drawover` and
/// `animate` share, for either kind of rig (rig_handle.h): strokes solved
/// into a pose and its report (DESIGN.md's report keys, `parameters` by the
/// rig's names), then --report, the report on stdout, --out and --render.
///
///     sp_solve_cmd s = {.cmd = "sketchpose pose", .rig = rig, .abstraction = a, .desc = desc};
///     cJSON* report = NULL;
///     if (!sp_solve_cmd_solve(&s, &cam, &sketch, "S.json", p, p, &rep, &report)) ... exit 1 ...
///     bool ok = sp_solve_cmd_write(&s, report, p, &(sp_solve_outputs){.report = ..., .out = ..., .render = ...});
///     cJSON_Delete(report);
///     sp_solve_cmd_end(&s);
///
/// Both calls print their own errors on stderr, one line "<cmd>: <what>".
#ifndef SP_SOLVE_CMD_H
#define SP_SOLVE_CMD_H

#include <cjson/cJSON.h>
#include <stdbool.h>

#include "rig_handle.h"

typedef struct sp_solve_cmd {
    const char* cmd;    ///< "sketchpose pose": the prefix of messages
    sp_rig_handle* rig; ///< outlives the sp_solve_cmd
    int abstraction;    ///< what the strokes draw (drawover: its embedded curves)
    sp_solve_desc desc;
    sp_camera cam;     ///< the view of the current solver, which points here
    sp_solver* solver; ///< made by the first solve and again when the canvas changes
} sp_solve_cmd;

/// Solves sk (read from the file `strokes`, named in errors), seen by cam,
/// from `start` into p (param_count values; may be start). The solver is
/// made on the first call and again when cam's canvas differs from the last
/// one's (keys on one canvas share its coarsening). On success *report is
/// the report JSON (caller deletes); false after printing why.
bool sp_solve_cmd_solve(sp_solve_cmd* s, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* start,
                        double* p, sp_solve_report* rep, cJSON** report);

/// What a posing command writes after its solves.
typedef struct sp_solve_outputs {
    const char* report;       ///< --report: the JSON is written there too (NULL: stdout only)
    const char* out;          ///< --out: the rig at p as glTF (a plugin's posed mesh, static)
    const char* render;       ///< --render: the rig at p in the solver's view, the fitted abstraction yellow
    const sp_sketch* strokes; ///< --render: blue overlay (may be NULL)
    const sp_sketch* ghost;   ///< --render: grey overlay (may be NULL)
    const char* note;         ///< printed on stderr as "<cmd>: <note>" at the end when not empty
} sp_solve_outputs;

/// Writes `report` to --report (all or nothing) and stdout, then the rig
/// at p to --out and --render, then the note. False after printing why.
bool sp_solve_cmd_write(const sp_solve_cmd* s, const cJSON* report, const double* p, const sp_solve_outputs* o);

/// The solver's weight (sp_solve_desc.lambda_*) for a --lambda-* option:
/// NAN (not given) is 0, the solver's default; a typed 0 or less turns the
/// term off (a typed 0 was the default weight, 0.5 for W_pose).
double sp_solve_cmd_lambda(double typed);

/// Destroys the solver.
void sp_solve_cmd_end(sp_solve_cmd* s);

#endif
