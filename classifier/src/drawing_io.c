// drawing_io.c: the drawings that need a decoder (PNG: stb_image decodes it,
// OpenCV makes it grey), any drawing by its extension, and labelled folders
// (which may hold PNGs). The stroke files themselves are read by sketchio
// (sp/sketch_io.h).
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cv_adapter.h"
#include "png_decode.h"
#include "sp/classifier.h"
#include "sp/math.h"

// ---------------------------------------------------------------------------
// PNG

sp_result sp_raster_read_png(const char* path, sp_raster* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    // One read (regular files only, at most a drawing file's size), then
    // the header before the decoder: it would allocate the whole image
    // before we could refuse a 20000x20000 file.
    char* bytes;
    size_t len;
    sp_result rc = sp_sketch_file_read(path, &bytes, &len, err);
    if (rc != SP_OK) return rc;
    uint32_t w, h;
    const char* bad = sp_png_header((const unsigned char*)bytes, len, &w, &h);
    if (bad || w > SP_RASTER_MAX_SIDE || h > SP_RASTER_MAX_SIDE) {
        free(bytes);
        if (bad) return sp_fail(err, SP_ERR_PARSE, "%s: %s", path, bad);
        return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: PNG is %ux%u, larger than %dx%d", path, w, h, SP_RASTER_MAX_SIDE,
                       SP_RASTER_MAX_SIDE);
    }
    // Why stb and not OpenCV's decoder: it is quiet (see png_decode.h), and
    // the pixels it gives go straight to the grey conversion: one decode.
    const char* why = NULL;
    sp_png_image img;
    bool decoded = sp_png_decode((const unsigned char*)bytes, len, &img, &why);
    free(bytes);
    if (!decoded)
        return sp_fail(err, SP_ERR_PARSE, "%s: PNG data corrupt or truncated (%s)", path, why && *why ? why : "undecodable");
    if (img.w != (int)w || img.h != (int)h) {
        sp_png_image_free(&img);
        return sp_fail(err, SP_ERR_PARSE, "%s: decoded size differs from the PNG header", path);
    }
    rc = sp_cv_grey(img.samples, img.w, img.h, img.channels, img.wide, path, &out->pixels, err);
    if (rc == SP_OK) out->w = img.w, out->h = img.h;
    sp_png_image_free(&img);
    return rc;
}

// ---------------------------------------------------------------------------
// Any drawing, folders

sp_result sp_drawing_read(const char* path, sp_sketch* sketch, sp_raster* raster, sp_error* err)
{
    memset(sketch, 0, sizeof *sketch);
    if (raster) memset(raster, 0, sizeof *raster);
    if (sp_path_ext_is(path, "json")) return sp_sketch_read_json(path, sketch, err);
    if (sp_path_ext_is(path, "svg")) return sp_sketch_read_svg(path, sketch, err);
    if (sp_path_ext_is(path, "png")) {
        if (!raster) return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: a PNG has no strokes; give a .json or .svg", path);
        return sp_raster_read_png(path, raster, err);
    }
    if (sp_path_ext_is(path, "ndjson")) {
        sp_dataset ds = {0};
        sp_result rc = sp_dataset_read_ndjson(&ds, path, -1, err);
        if (rc == SP_OK && ds.count == 0) rc = sp_fail(err, SP_ERR_INVALID, "%s: no drawings", path);
        if (rc == SP_OK) {
            *sketch = ds.samples[0].sketch;
            ds.samples[0].sketch = (sp_sketch){0};
        }
        sp_dataset_free(&ds);
        return rc;
    }
    return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: unknown drawing type (want .json, .svg, .png or .ndjson)", path);
}

static bool is_dir(const char* path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

sp_result sp_dataset_load(const char* dir, sp_dataset* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    char** names;
    int n;
    sp_result rc = sp_dir_list(dir, &names, &n, err);
    if (rc != SP_OK) return rc;
    sp_dataset ds = {0};
    char path[4096];
    // Categories first (sorted), so labels do not depend on which kind of file came first.
    for (int i = 0; i < n && rc == SP_OK; ++i) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        char cat[1024];
        if (is_dir(path))
            snprintf(cat, sizeof cat, "%s", names[i]);
        else if (sp_path_ext_is(names[i], "ndjson")) {
            snprintf(cat, sizeof cat, "%s", names[i]);
            cat[strlen(cat) - 7] = '\0';
        } else
            continue;
        if (sp_dataset_add_category(&ds, cat) < 0) rc = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", dir);
    }
    if (rc == SP_OK && ds.category_count > 1) qsort(ds.categories, (size_t)ds.category_count, sizeof(char*), sp_cmp_cstr);
    for (int i = 0; i < n && rc == SP_OK; ++i) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        if (is_dir(path)) {
            int label = sp_dataset_add_category(&ds, names[i]);
            char** files;
            int nf;
            if ((rc = sp_dir_list(path, &files, &nf, err)) != SP_OK) break;
            for (int j = 0; j < nf && rc == SP_OK; ++j) {
                if (!sp_path_ext_is(files[j], "json") && !sp_path_ext_is(files[j], "svg") && !sp_path_ext_is(files[j], "png"))
                    continue;
                char fp[4096 + 256];
                snprintf(fp, sizeof fp, "%s/%s", path, files[j]);
                sp_sample smp = {.label = label};
                rc = sp_drawing_read(fp, &smp.sketch, &smp.raster, err);
                if (rc == SP_OK && sp_dataset_add_sample(&ds, &smp) != SP_OK) {
                    sp_sketch_free(&smp.sketch);
                    sp_raster_free(&smp.raster);
                    rc = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", fp);
                }
            }
            sp_dir_list_free(files, nf);
        } else if (sp_path_ext_is(names[i], "ndjson")) {
            char cat[1024];
            snprintf(cat, sizeof cat, "%s", names[i]);
            cat[strlen(cat) - 7] = '\0';
            rc = sp_dataset_read_ndjson(&ds, path, sp_dataset_add_category(&ds, cat), err);
        }
    }
    sp_dir_list_free(names, n);
    if (rc == SP_OK && ds.count == 0)
        rc = sp_fail(err, SP_ERR_INVALID, "%s: no drawings (want <category>/*.json|svg|png or <category>.ndjson)", dir);
    if (rc != SP_OK) {
        sp_dataset_free(&ds);
        return rc;
    }
    *out = ds;
    return SP_OK;
}
