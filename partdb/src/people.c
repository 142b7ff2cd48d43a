// people.c: the people's own strokes of the dragon parts that the default
// recipe trains on (sp_db_people_strokes in sp/partdb.h). The repository
// keeps only which strokes they are (assets/sketches/picks.json); the strokes
// themselves are read from the Quick, Draw! data, which is not ours to copy.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "db_internal.h"
#include "sp/math.h"
#include "sp/sketch_io.h"

// Line `line` (from 1) of `text`, as a pointer and length; false when the text is shorter.
static bool nth_line(const char* text, size_t len, int line, const char** at, size_t* n)
{
    size_t b = 0;
    for (int i = 1; b < len; ++i) {
        size_t e = b;
        while (e < len && text[e] != '\n')
            ++e;
        if (i == line) {
            *at = text + b, *n = e - b;
            return true;
        }
        b = e + 1;
    }
    return false;
}

// The data file last read: a category's picks of one file mostly follow each other.
typedef struct data_file {
    char path[4200];
    char* text;
    size_t len;
} data_file;

// Stroke `stroke` of line `line` of `path`, checked against `key_id`, as a one-stroke sketch.
static sp_result read_pick(data_file* f, const char* path, int line, int stroke, const char* key_id, sp_sketch* out, sp_error* err)
{
    if (!f->text || strcmp(f->path, path) != 0) {
        free(f->text);
        f->text = NULL;
        sp_result r = sp_sketch_file_read(path, &f->text, &f->len, err);
        if (r != SP_OK) return r;
        snprintf(f->path, sizeof f->path, "%s", path);
    }
    const char* at;
    size_t n;
    if (!nth_line(f->text, f->len, line, &at, &n))
        return sp_fail(err, SP_ERR_INVALID, "%s: no line %d (assets/sketches/picks.json names it)", path, line);
    sp_result r = SP_OK;
    cJSON* j = cJSON_ParseWithLength(at, n);
    const char* key = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "key_id"));
    if (!key || strcmp(key, key_id) != 0) {
        r = sp_fail(err, SP_ERR_INVALID, "%s:%d: key_id %s, picks.json expects %s (another copy of the data?)", path, line,
                    key ? key : "missing", key_id);
    }
    cJSON_Delete(j);
    sp_dataset one = {0};
    if (r == SP_OK) r = sp_dataset_parse_ndjson(&one, at, n, path, -1, err);
    if (r == SP_OK && (one.count != 1 || stroke >= one.samples[0].sketch.stroke_count))
        r = sp_fail(err, SP_ERR_INVALID, "%s:%d: no stroke %d", path, line, stroke);
    if (r == SP_OK) {
        const sp_sketch* s = &one.samples[0].sketch;
        const sp_stroke* st = &s->strokes[stroke];
        *out = (sp_sketch){.canvas_w = s->canvas_w, .canvas_h = s->canvas_h};
        if (sp_sketch_add_stroke(out, st->points, st->t, st->count) != SP_OK)
            r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    sp_dataset_free(&one);
    return r;
}

// assets_dir/sketches/picks.json parsed (*root NULL: there is none) and the
// data's folder it names, or `quickdraw_dir`, in dir; *missing when that
// folder is not there (an error when the caller named it).
static sp_result load_picks(const char* assets_dir, const char* quickdraw_dir, cJSON** root, char dir[2048], bool* missing,
                            sp_error* err)
{
    *root = NULL;
    *missing = false;
    char path[2048];
    snprintf(path, sizeof path, "%s/sketches/picks.json", assets_dir);
    struct stat st;
    if (stat(path, &st) != 0) return SP_OK; // an assets folder without people's strokes
    sp_result r = db_read_json(path, root, err);
    if (r != SP_OK) return r;
    const char* from = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(*root, "quickdraw"));
    if (!cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(*root, "picks")) || !from) {
        cJSON_Delete(*root);
        *root = NULL;
        return sp_fail(err, SP_ERR_PARSE, "%s: not a picks file (want {\"quickdraw\": DIR, \"picks\": [...]})", path);
    }
    if (quickdraw_dir) snprintf(dir, 2048, "%s", quickdraw_dir);
    else if (from[0] == '/') snprintf(dir, 2048, "%s", from);
    else snprintf(dir, 2048, "%s/sketches/%s", assets_dir, from);
    *missing = stat(dir, &st) != 0 || !S_ISDIR(st.st_mode);
    if (*missing && quickdraw_dir) {
        cJSON_Delete(*root);
        *root = NULL;
        return sp_fail(err, SP_ERR_IO, "%s: no such folder (the Quick, Draw! data)", dir);
    }
    return SP_OK;
}

sp_result sp_db_people_source(const char* assets_dir, const char* quickdraw_dir, int* picks, bool* missing, sp_error* err)
{
    cJSON* root;
    char dir[2048];
    sp_result r = load_picks(assets_dir, quickdraw_dir, &root, dir, missing, err);
    *picks = root ? cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(root, "picks")) : 0;
    cJSON_Delete(root);
    return r;
}

sp_result sp_db_people_strokes(const char* assets_dir, const char* quickdraw_dir, sp_dataset* out, bool* missing, sp_error* err)
{
    memset(out, 0, sizeof *out);
    cJSON* root;
    char dir[2048];
    bool gone;
    sp_result r = load_picks(assets_dir, quickdraw_dir, &root, dir, &gone, err);
    if (missing) *missing = gone;
    if (r != SP_OK || !root || gone) {
        cJSON_Delete(root);
        return r;
    }
    const cJSON* picks = cJSON_GetObjectItemCaseSensitive(root, "picks");
    // Categories sorted, as a labelled folder would give them; strokes in the file's order.
    sp_dataset ds;
    int bad = 0;
    r = db_dataset_labels(picks, "category", &ds, &bad, err);
    if (r == SP_ERR_PARSE) sp_fail(err, r, "%s/sketches/picks.json: a pick without \"category\"", assets_dir);
    const cJSON* p;
    data_file f = {.text = NULL};
    for (int k = 0; r == SP_OK && k < ds.category_count; ++k) {
        cJSON_ArrayForEach(p, picks)
        {
            if (strcmp(cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(p, "category")), ds.categories[k]) != 0) continue;
            const char* file = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(p, "file"));
            const char* key = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(p, "key_id"));
            const cJSON* line = cJSON_GetObjectItemCaseSensitive(p, "line");
            const cJSON* stroke = cJSON_GetObjectItemCaseSensitive(p, "stroke");
            if (!file || !key || !cJSON_IsNumber(line) || !cJSON_IsNumber(stroke) || line->valueint < 1 || stroke->valueint < 0 ||
                strchr(file, '/')) {
                r = sp_fail(err, SP_ERR_PARSE,
                            "%s/sketches/picks.json: a pick needs \"file\" (a name in the data's folder), \"line\" >= 1, \"stroke\" >= 0, "
                            "\"key_id\"",
                            assets_dir);
                break;
            }
            char fp[4200];
            snprintf(fp, sizeof fp, "%s/%s", dir, file);
            sp_sample smp = {.label = k};
            if ((r = read_pick(&f, fp, line->valueint, stroke->valueint, key, &smp.sketch, err)) != SP_OK) break;
            if (sp_dataset_add_sample(&ds, &smp) != SP_OK) {
                sp_sketch_free(&smp.sketch);
                r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", fp);
                break;
            }
        }
    }
    free(f.text);
    cJSON_Delete(root);
    if (r != SP_OK) sp_dataset_free(&ds);
    else *out = ds;
    return r;
}

bool sp_db_people_note(const char* assets_dir, char* note, size_t cap)
{
    int picks;
    bool missing = false;
    sp_error err = {0};
    if (sp_db_people_source(assets_dir, NULL, &picks, &missing, &err) != SP_OK || !missing) return false;
    snprintf(note, cap,
             "%s/sketches/picks.json: the Quick, Draw! data it names is not there; building the database without the people's "
             "strokes (fewer visitors' drawings recognised)",
             assets_dir);
    return true;
}
