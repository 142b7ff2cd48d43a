// pose_io.c: reading and writing pose files (see pose_io.h).
#include "pose_io.h"

#include "sp/sketch_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int find_param(const sp_param* params, int count, const char* name)
{
    for (int k = 0; k < count; ++k)
        if (!strcmp(params[k].name, name)) return k;
    return -1;
}

sp_result sp_pose_parse(const char* text, size_t len, const char* what, const sp_param* params, int count, double* p,
                        int* clamped, sp_error* err)
{
    if (clamped) *clamped = 0;
    // As a stroke file: a NUL ended the file silently, a key given twice was
    // dropped, and 60 MB of small values took 2.4 GB (an outside review).
    sp_result r = sp_json_document_check(text, len, SP_SKETCH_MAX_JSON_VALUES, what, err);
    if (r != SP_OK) return r;
    cJSON* root = cJSON_ParseWithLength(text, len);
    if (!root) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    const cJSON* values = cJSON_GetObjectItemCaseSensitive(root, "parameters");
    if (!cJSON_IsObject(values)) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: expected {\"parameters\": {\"<joint>.<channel>\": value, ...}}", what);
        goto done;
    }
    const cJSON* it;
    cJSON_ArrayForEach(it, values)
    {
        int k = find_param(params, count, it->string);
        if (k < 0) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: unknown parameter '%s' (see `sketchpose inspect`)", what, it->string);
            goto done;
        }
        if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble)) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: parameter '%s' is not a finite number", what, it->string);
            goto done;
        }
        double v = it->valuedouble;
        const sp_param* q = &params[k];
        double c = sp_param_clamp(v, q->min, q->max, q->def);
        if (c != v) {
            fprintf(stderr, "sketchpose: warning: %s: parameter '%s' = %g is outside [%g, %g], clamped to %g\n", what, it->string,
                    v, q->min, q->max, c);
            v = c;
            if (clamped) ++*clamped;
        }
        p[k] = v;
    }
done:
    cJSON_Delete(root);
    return r;
}

sp_result sp_pose_read(const char* path, const sp_param* params, int count, double* p, int* clamped, sp_error* err)
{
    char* text;
    size_t n;
    sp_result r = sp_sketch_file_read(path, &text, &n, err); // a pose file is as small as a drawing
    if (r != SP_OK) return r;
    r = sp_pose_parse(text, n, path, params, count, p, clamped, err);
    free(text);
    return r;
}

cJSON* sp_pose_params_json(const sp_param* params, int count, const double* p)
{
    cJSON* o = cJSON_CreateObject();
    for (int k = 0; o && k < count; ++k)
        cJSON_AddNumberToObject(o, params[k].name, p[k]);
    return o;
}

cJSON* sp_pose_to_json(const sp_param* params, int count, const double* p)
{
    cJSON* root = cJSON_CreateObject();
    cJSON* values = sp_pose_params_json(params, count, p);
    if (root && values)
        cJSON_AddItemToObject(root, "parameters", values);
    else
        cJSON_Delete(values);
    return root;
}

sp_result sp_pose_write(const char* path, const sp_param* params, int count, const double* p, sp_error* err)
{
    cJSON* root = sp_pose_to_json(params, count, p);
    char* text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    size_t n = text ? strlen(text) : 0;
    char* line = text ? realloc(text, n + 2) : NULL;
    if (!line) {
        free(text);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    line[n] = '\n';
    // Written whole: a pose file the user had is never left half overwritten.
    sp_result r = sp_file_write(path, line, n + 1, err);
    free(line);
    return r;
}
