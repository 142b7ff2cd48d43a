#include "report.h"
#include "sp/sketch_io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

sp_result sp_outputs_stage(sp_outputs* o, const char* path, const char** write_to, sp_error* err)
{
    static unsigned serial;
    *write_to = path;
    if (!path) return SP_OK;
    if (o->count >= (int)(sizeof o->paths / sizeof o->paths[0]))
        return sp_fail(err, SP_ERR_INTERNAL, "%s: too many outputs for one command", path);
    struct stat st;
    bool link = lstat(path, &st) == 0 && S_ISLNK(st.st_mode);
    char* real = link ? realpath(path, NULL) : NULL;
    const char* target = real ? real : path;
    // Written in place: stdout, a stream, a dangling link (what it names is created).
    if (!strcmp(path, "-") || (link && !real) || (stat(target, &st) == 0 && !S_ISREG(st.st_mode)) || !strncmp(path, "/dev/", 5)) {
        free(real);
        return SP_OK;
    }
    const char* base = strrchr(target, '/');
    const char* dot = strrchr(base ? base + 1 : target, '.');
    size_t n = strlen(target) + 64;
    char* tmp = malloc(n);
    if (!tmp) {
        free(real);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    snprintf(tmp, n, "%s.part%ld-%u%s", target, (long)getpid(), serial++, dot ? dot : "");
    o->paths[o->count] = path;
    o->staged[o->count] = tmp;
    o->target[o->count] = real;
    ++o->count;
    *write_to = tmp;
    return SP_OK;
}

static void forget(sp_outputs* o, int i)
{
    free(o->staged[i]);
    free(o->target[i]);
    o->staged[i] = o->target[i] = NULL;
}

sp_result sp_outputs_commit(sp_outputs* o, sp_error* err)
{
    sp_result r = SP_OK;
    for (int i = 0; i < o->count; ++i) {
        if (!o->staged[i]) continue;
        const char* target = o->target[i] ? o->target[i] : o->paths[i];
        struct stat st;
        if (r == SP_OK) {
            if (stat(target, &st) == 0 && S_ISREG(st.st_mode)) chmod(o->staged[i], st.st_mode & 07777);
            if (rename(o->staged[i], target) == 0)
                sp_path_sync_folder(target);
            else
                r = sp_fail(err, SP_ERR_IO, "%s: cannot write (%s)", o->paths[i], strerror(errno));
        }
        if (r != SP_OK) unlink(o->staged[i]);
        forget(o, i);
    }
    o->count = 0;
    return r;
}

void sp_outputs_undo(sp_outputs* o, sp_error* err)
{
    for (int i = 0; i < o->count; ++i) {
        if (!o->staged[i]) continue;
        unlink(o->staged[i]);
        for (char* at = err ? strstr(err->text, o->staged[i]) : NULL; at; at = strstr(at, o->staged[i])) {
            char rest[sizeof err->text];
            snprintf(rest, sizeof rest, "%s", at + strlen(o->staged[i]));
            snprintf(at, sizeof err->text - (size_t)(at - err->text), "%s%s", o->paths[i], rest);
            at += strlen(o->paths[i]);
        }
        forget(o, i);
    }
    o->count = 0;
}
