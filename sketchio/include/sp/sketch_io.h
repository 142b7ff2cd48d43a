/// sp/sketch_io.h: reading and writing the stroke files people feed us, beside
/// the stroke type (sp/sketch.h). No OpenCV: a command that only reads
/// strokes (`pose`, `drawover`, `animate`) needs only this and a JSON parser.
///
/// Formats (DESIGN.md "Files people feed it"):
///   - the JSON stroke file `{"format": "sketchpose-strokes", "version": 1, ...}` (read and write);
///   - Quick, Draw! `.ndjson`, many drawings per file;
///   - SVG line/path drawings (TU Berlin: <path d> with M/L/H/V/C/S/Q/T/Z, group transforms), curves flattened;
///   - labelled sets of drawings (sp_dataset) as data. PNG raster sketches, any drawing by its
///     extension and labelled folders are read by the classifier (sp/classifier.h:
///     sp_raster_read_png, sp_drawing_read, sp_dataset_load), which decodes PNGs with OpenCV.
///
///     sp_sketch s = {0}; sp_error err = {0};
///     if (sp_sketch_read_json("S.json", &s, &err) != SP_OK) fprintf(stderr, "%s\n", err.text);
///     ...
///     sp_sketch_free(&s);
///
/// Every reader validates what it reads (finite coordinates, at most
/// SP_SKETCH_MAX_POINTS points) and fails with one line in `err` naming the
/// file and the problem. Nothing is partially returned on failure.
#ifndef SP_SKETCH_IO_H
#define SP_SKETCH_IO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "sp/result.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Most points one sketch may hold (all strokes together).
#define SP_SKETCH_MAX_POINTS 1000000
/// Largest |x| or |y| a stroke file may hold, and largest canvas side: what
/// every reader accepts, so what the database stores must keep to them too.
#define SP_SKETCH_COORD_MAX 1e9
#define SP_SKETCH_CANVAS_MAX 1e6
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
    int capacity; // samples allocated; grow them only with sp_dataset_reserve
    int category_count;
    char** categories;
} sp_dataset;

/// Reads a JSON stroke file.
sp_result sp_sketch_read_json(const char* path, sp_sketch* out, sp_error* err);
/// Parses a JSON stroke document of `len` bytes; `name` is used in messages.
sp_result sp_sketch_parse_json(const char* text, size_t len, const char* name, sp_sketch* out, sp_error* err);
/// Writes a sketch as a JSON stroke file (version 1). Times are written when every stroke has them.
sp_result sp_sketch_write_json(const char* path, const sp_sketch* s, sp_error* err);
/// Significant digits with which every double reads back exactly.
#define SP_SKETCH_JSON_EXACT 17
/// A sketch as JSON stroke text (NUL-terminated, malloc'd: the caller frees
/// it), each number with `digits` significant digits (sp_sketch_write_json:
/// SP_SKETCH_JSON_EXACT). NULL when out of memory.
char* sp_sketch_to_json(const sp_sketch* s, int digits);

/// Reads an SVG drawing: one stroke per subpath (and per <line>/<polyline>/<polygon>).
sp_result sp_sketch_read_svg(const char* path, sp_sketch* out, sp_error* err);
/// Parses SVG text of `len` bytes (need not be NUL-terminated).
sp_result sp_sketch_parse_svg(const char* text, size_t len, const char* name, sp_sketch* out, sp_error* err);

/// Frees the pixels and zeroes the raster.
void sp_raster_free(sp_raster* r);

/// Parses Quick, Draw! ndjson (one drawing per line) and appends every drawing
/// to `ds` with label `label` (which must be < ds->category_count, or -1).
sp_result sp_dataset_parse_ndjson(sp_dataset* ds, const char* text, size_t len, const char* name, int label, sp_error* err);
/// Reads one .ndjson file into `ds` with label `label`.
sp_result sp_dataset_read_ndjson(sp_dataset* ds, const char* path, int label, sp_error* err);
/// Adds a category name (copied) and returns its index, or -1 when out of memory.
int sp_dataset_add_category(sp_dataset* ds, const char* name);
/// Why a drawing of strokes cannot be drawn or classified, else NULL: "the
/// drawing has no points", or "the drawing has no extent: all its points
/// are at one place" (a dot, or strokes scaled to nothing).
const char* sp_sketch_extent_problem(const sp_sketch* s);
/// A grey level under this is ink in a picture (the classifier's threshold).
#define SP_RASTER_INK_BELOW 191
/// Why a picture (a PNG drawing) cannot be classified, else NULL: "the
/// picture has no dark lines" (blank: no pixel under SP_RASTER_INK_BELOW).
const char* sp_raster_ink_problem(const sp_raster* r);
/// Takes out of `ds` the stroke drawings that sp_sketch_extent_problem
/// refuses and the pictures sp_raster_ink_problem refuses, renumbering
/// `index` within each category; returns how many were taken out.
int sp_dataset_drop_no_extent(sp_dataset* ds);
/// Frees everything and zeroes the set.
void sp_dataset_free(sp_dataset* ds);

/// Appends a drawing to `ds`, which takes over its strokes and pixels, and
/// sets its `index` (its position within its category). SP_ERR_NO_MEMORY
/// leaves `smp` with the caller.
sp_result sp_dataset_add_sample(sp_dataset* ds, sp_sample* smp);
/// Makes room for n more samples past `count` (geometric growth); the
/// samples in the set stay. SP_ERR_NO_MEMORY changes nothing.
sp_result sp_dataset_reserve(sp_dataset* ds, int n);

/// Reads a whole file into *data (malloc'd, NUL-terminated, *size bytes
/// without the NUL): regular files only (a device or a pipe is refused, never
/// read without end) of at most max_bytes. One line in `err` names the path.
sp_result sp_file_read(const char* path, size_t max_bytes, void** data, size_t* size, sp_error* err);
/// sp_file_read of a drawing file: at most SP_SKETCH_MAX_FILE_BYTES.
sp_result sp_sketch_file_read(const char* path, char** out, size_t* len, sp_error* err);
/// Whether text holds one JSON document, after a parser read it and stopped
/// at `end` (`parsed`: it succeeded): SP_OK when only white space follows,
/// else SP_ERR_PARSE with err naming `name` and the line ("malformed JSON
/// near line 3", "text after the JSON document, line 9").
sp_result sp_json_document_end(const char* text, size_t len, bool parsed, const char* end, const char* name, sp_error* err);
/// Most JSON values a stroke file may hold: its SP_SKETCH_MAX_POINTS points
/// with their times, and room for the rest. A parsed value takes ~64 bytes,
/// so a file of small values under SP_SKETCH_MAX_FILE_BYTES could take 10 GB.
#define SP_SKETCH_MAX_JSON_VALUES (5u * SP_SKETCH_MAX_POINTS)
/// A JSON text measured in one pass before it is parsed (parsers recurse a
/// level a frame and take ~64 bytes a value): how deep its arrays and objects
/// nest, and a bound on its values (commas + containers + 1: every value but
/// the root follows a comma or opens its container). Strings are skipped.
typedef struct sp_json_shape {
    size_t depth, values;
} sp_json_shape;
sp_json_shape sp_json_measure(const char* text, size_t len);
/// Whether text holds at most max_values values (sp_json_measure): SP_OK,
/// else SP_ERR_INVALID with err naming `name`.
sp_result sp_json_values_within(const char* text, size_t len, size_t max_values, const char* name, sp_error* err);
/// Whether text (len bytes) is one JSON document as every reader of a user's
/// JSON file wants it (pose files, kiosk sessions, a database folder's
/// manifest; stroke files add their own messages): at most max_values values
/// (0: no cap), nothing but white space after it, no NUL byte in it, and no
/// object anywhere holding a key twice (cJSON keeps both and lookups find
/// the first: `"events": [], "events": [...]` replayed nothing). SP_OK, then
/// parse it; else err names `name` (and the line, where it tells). It parses
/// the text itself, so that no cJSON type is in this header.
sp_result sp_json_document_check(const char* text, size_t len, size_t max_values, const char* name, sp_error* err);
/// Whether s holds a control character (a byte below 0x20, or DEL 0x7f).
bool sp_text_has_control(const char* s);
/// `s` for a one-line message (returns buf, cap > 0): a control character
/// is written as \n, \r, \t or \xNN and a backslash as \\, so that a name
/// someone typed cannot break the line or drive a terminal (an escape
/// code); text past cap ends in "...". NULL reads as "".
const char* sp_text_printable(const char* s, char* buf, size_t cap);
/// The folder that holds `path` (malloc'd; NULL when out of memory): "." for
/// a bare name, "/" for "/x"; trailing slashes are not a level ("out/" is
/// held by the folder out is in).
char* sp_path_folder(const char* path);
/// `path` with every symbolic link followed, a dangling one's last hop too,
/// up to an open file's name (sp_path_descriptor) or one under /proc/ (the
/// kernel's links there name open files, not paths):
/// the file a write through `path` makes or replaces (malloc'd; `path`
/// itself when it is no link; NULL when out of memory or the links loop).
char* sp_path_follow_links(const char* path);
/// The descriptor an open file's name stands for (/dev/stdout 1, /dev/stderr
/// 2, /dev/fd/N, /proc/self/fd/N), else -1: written through it, never
/// replaced by a temporary file. Whether it is open is the caller's to check.
int sp_path_descriptor(const char* path);
/// A new name for a temporary file in the folder of `target`,
/// "<folder>/.sp-<pid>-<k><ext>" (malloc'd; NULL when out of memory): short,
/// so that a name near the file system's 255-byte limit still has one beside
/// it, and hidden, so that a folder reader (a category of drawings, a folder
/// of parts) never takes one that a killed process left for its own.
char* sp_path_temp_beside(const char* target, const char* ext);

/// Syncs the folder that holds `path` (fsync(2) on the folder), so that a name
/// just made there by rename(2), link(2) or mkdir(2) survives a power cut.
/// False when the folder cannot be opened or synced; a file system that
/// cannot sync folders counts as done.
bool sp_path_sync_folder(const char* path);
/// Writes `size` bytes to `path` whole or not at all: into a temporary file
/// beside it (sp_path_temp_beside; the old file's permissions, else 0666 less the umask), synced
/// and renamed into place once every byte is written, so that a failed write
/// (a full disk, a size limit) or a power cut leaves the old file as it was
/// and no truncated one; the folder is synced after the rename. A symbolic
/// link is followed (its target is replaced, a dangling one's created, the
/// link stays; sp_path_follow_links); a path that is not a regular file (a
/// FIFO, a device) is written into directly, and
/// /dev/stdout, /dev/stderr, /dev/fd/N and /proc/self/fd/N through that
/// descriptor at its offset (a pipe, or a file the shell redirected, `>>` too). One line in `err`
/// names the path and the system's reason.
sp_result sp_file_write(const char* path, const void* data, size_t size, sp_error* err);
/// For writers that print their file: closes f, an open_memstream(3) over
/// *text and *len, and writes what was printed with sp_file_write, then frees
/// *text. A failed print is SP_ERR_NO_MEMORY naming path.
sp_result sp_file_write_printed(const char* path, FILE* f, char** text, size_t* len, sp_error* err);
/// True when `path`'s extension (after its last '.', in its last component) is `ext`, ignoring case.
bool sp_path_ext_is(const char* path, const char* ext);
/// The names in folder `dir`, sorted bytewise so that every machine reads a
/// folder in the same order, leaving out those starting with '.': *names a
/// malloc'd array of *count malloc'd strings (free with sp_dir_list_free).
/// SP_ERR_IO (naming the folder and why) when it cannot be read.
sp_result sp_dir_list(const char* dir, char*** names, int* count, sp_error* err);
void sp_dir_list_free(char** names, int count);
/// Creates folder `path` (its parent must exist); one that exists already is
/// fine. SP_ERR_IO naming it and why otherwise (also when a file has its name).
sp_result sp_dir_make(const char* path, sp_error* err);
/// Removes a folder the caller made and everything in it, deepest first,
/// going on past what cannot be removed; symbolic links are removed, not
/// followed.
void sp_dir_remove_tree(const char* path);

#ifdef __cplusplus
}
#endif
#endif
