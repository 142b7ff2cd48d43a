/// sp/sketch_io.h: reading (and writing) the sketch files people feed us.
///
/// Formats (DESIGN.md "Files people feed it"):
///   - the JSON stroke file `{"format": "sketchpose-strokes", "version": 1, ...}` (read and write);
///   - Quick, Draw! `.ndjson`, many drawings per file;
///   - SVG line/path drawings (TU Berlin: <path d> with M/L/H/V/C/S/Q/T/Z, group transforms), curves flattened;
///   - PNG raster sketches (dark lines on a light background), kept as pixels;
///   - a labelled folder `DIR/<category>/*.{json,svg,png}` and/or `DIR/<category>.ndjson`.
///
///     sp_sketch s = {0}; sp_error err = {0};
///     if (sp_sketch_read_json("S.json", &s, &err) != SP_OK) fprintf(stderr, "%s\n", err.text);
///     ...
///     sp_sketch_free(&s);
///
/// Every reader validates what it reads (finite coordinates, at most
/// SP_SKETCH_MAX_POINTS points, PNGs at most SP_RASTER_MAX_SIDE a side) and
/// fails with one line in `err` naming the file and the problem. Nothing is
/// partially returned on failure.
#ifndef SP_SKETCH_IO_H
#define SP_SKETCH_IO_H

#include <stddef.h>

#include "sp/result.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Most points one sketch may hold (all strokes together).
#define SP_SKETCH_MAX_POINTS 1000000
/// Largest PNG side accepted (checked from the header, before decoding).
#define SP_RASTER_MAX_SIDE 8192
/// Largest file any reader loads into memory (bytes).
#define SP_SKETCH_MAX_FILE_BYTES (256u << 20)

/// An 8-bit grey image, row-major, w*h bytes, 0 = black ink, 255 = white paper.
typedef struct sp_raster {
    int w, h;
    unsigned char* pixels;
} sp_raster;

/// One labelled drawing: strokes, or (for PNG) pixels.
typedef struct sp_sample {
    sp_sketch sketch; ///< strokes; empty for raster samples
    sp_raster raster; ///< pixels for PNG samples; {0} otherwise
    int label;        ///< index into sp_dataset.categories
    int index;        ///< position of the drawing within its category (file order), used for folds
} sp_sample;

/// A labelled set of drawings. Categories are sorted by name.
typedef struct sp_dataset {
    int count;
    sp_sample* samples;
    int category_count;
    char** categories;
} sp_dataset;

/// Reads a JSON stroke file.
sp_result sp_sketch_read_json(const char* path, sp_sketch* out, sp_error* err);
/// Parses a JSON stroke document of `len` bytes; `name` is used in messages.
sp_result sp_sketch_parse_json(const char* text, size_t len, const char* name, sp_sketch* out, sp_error* err);
/// Writes a sketch as a JSON stroke file (version 1). Times are written when every stroke has them.
sp_result sp_sketch_write_json(const char* path, const sp_sketch* s, sp_error* err);

/// Reads an SVG drawing: one stroke per subpath (and per <line>/<polyline>/<polygon>).
sp_result sp_sketch_read_svg(const char* path, sp_sketch* out, sp_error* err);
/// Parses SVG text of `len` bytes (need not be NUL-terminated).
sp_result sp_sketch_parse_svg(const char* text, size_t len, const char* name, sp_sketch* out, sp_error* err);

/// Reads a PNG into grey pixels (alpha composited over white). Refuses files whose
/// header says more than SP_RASTER_MAX_SIDE a side before decoding anything, and
/// files that are not PNGs whatever their name.
sp_result sp_raster_read_png(const char* path, sp_raster* out, sp_error* err);
/// Frees the pixels and zeroes the raster.
void sp_raster_free(sp_raster* r);

/// Parses Quick, Draw! ndjson (one drawing per line) and appends every drawing
/// to `ds` with label `label` (which must be < ds->category_count, or -1).
sp_result sp_dataset_parse_ndjson(sp_dataset* ds, const char* text, size_t len, const char* name, int label, sp_error* err);
/// Reads one .ndjson file into `ds` with label `label`.
sp_result sp_dataset_read_ndjson(sp_dataset* ds, const char* path, int label, sp_error* err);
/// Loads a labelled folder: `dir/<category>/*.{json,svg,png}` and `dir/<category>.ndjson`.
/// Files are read in name order so that sample indices (and folds) are reproducible.
/// Fails on the first unreadable file, naming it.
sp_result sp_dataset_load(const char* dir, sp_dataset* out, sp_error* err);
/// Adds a category name (copied) and returns its index, or -1 when out of memory.
int sp_dataset_add_category(sp_dataset* ds, const char* name);
/// Frees everything and zeroes the set.
void sp_dataset_free(sp_dataset* ds);

/// Reads any single drawing by extension (.json, .svg, .png; .ndjson gives its first drawing).
/// For a PNG, `raster` receives the pixels and `sketch` stays empty; `raster` may be NULL
/// when the caller only accepts strokes.
sp_result sp_drawing_read(const char* path, sp_sketch* sketch, sp_raster* raster, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
