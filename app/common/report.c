#include "report.h"
#include "sp/sketch_io.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pose_io.h"

static cJSON* terms_json(const sp_energy_terms* e)
{
    cJSON* o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "total", e->total);
    cJSON_AddNumberToObject(o, "match", e->match);
    cJSON_AddNumberToObject(o, "pose", e->pose);
    cJSON_AddNumberToObject(o, "plane", e->plane);
    cJSON_AddNumberToObject(o, "dist", e->dist);
    return o;
}

cJSON* sp_report_to_json(const sp_solve_report* rep, const sp_rig* rig, const sp_abstraction* ab, const double* p)
{
    return sp_report_json(rep, ab, rig ? rig->params : NULL, rig ? rig->param_count : 0, rig ? p : NULL);
}

cJSON* sp_report_json(const sp_solve_report* rep, const sp_abstraction* ab, const sp_param* params, int count, const double* p)
{
    cJSON* o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "ms", rep->ms);
    cJSON_AddNumberToObject(o, "iterations", rep->iterations);
    cJSON_AddNumberToObject(o, "icp_rounds", rep->icp_rounds);
    cJSON_AddStringToObject(o, "stopped", sp_stop_reason_name(rep->stopped));
    cJSON_AddNumberToObject(o, "energy_before", rep->before.total);
    cJSON_AddNumberToObject(o, "energy_after", rep->after.total);
    cJSON_AddItemToObject(o, "terms_before", terms_json(&rep->before));
    cJSON_AddItemToObject(o, "terms_after", terms_json(&rep->after));
    cJSON_AddNumberToObject(o, "mean_error_px", rep->mean_error_px);
    cJSON_AddNumberToObject(o, "max_error_px", rep->max_error_px);
    cJSON_AddNumberToObject(o, "bbox_diagonal_px", rep->bbox_diagonal_px);
    cJSON* curves = cJSON_AddArrayToObject(o, "curves");
    for (int c = 0; c < rep->curve_count; ++c) {
        cJSON* cv = cJSON_CreateObject();
        cJSON_AddStringToObject(cv, "curve", ab && c < ab->curve_count ? ab->curves[c].name : "");
        if (rep->curves[c].stroke >= 0) cJSON_AddNumberToObject(cv, "stroke", rep->curves[c].stroke);
        else cJSON_AddNullToObject(cv, "stroke");
        cJSON_AddBoolToObject(cv, "reversed", rep->curves[c].reversed);
        cJSON_AddNumberToObject(cv, "mean_error_px", rep->curves[c].mean_px);
        cJSON_AddNumberToObject(cv, "max_error_px", rep->curves[c].max_px);
        cJSON_AddItemToArray(curves, cv);
    }
    cJSON_AddNumberToObject(o, "unused_strokes", rep->unused_strokes);
    cJSON_AddStringToObject(o, "note", rep->note);
    if (p) {
        cJSON* values = sp_pose_params_json(params, count, p);
        cJSON_AddItemToObject(o, "parameters", values ? values : cJSON_CreateObject());
    }
    return o;
}

void sp_json_print(const cJSON* j)
{
    char* s = cJSON_Print(j);
    if (s) {
        fputs(s, stdout);
        fputc('\n', stdout);
        fflush(stdout);
    }
    free(s);
}

sp_result sp_json_write_file(const char* path, const cJSON* j, sp_error* err)
{
    if (!strcmp(path, "-")) {
        sp_json_print(j);
        return SP_OK;
    }
    char* s = cJSON_Print(j);
    if (!s) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory while writing JSON", path);
    size_t n = strlen(s);
    s[n] = '\n'; // cJSON_Print's terminator becomes the file's last newline
    sp_result r = sp_file_write(path, s, n + 1, err);
    free(s);
    return r;
}
