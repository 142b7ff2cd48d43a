/// sp/sketch_sheet.h: labelled contact sheets of drawings, on the CPU (no GL), for
/// curators and for looking at data sets (`sketchpose db review --sheet`,
/// tests/bench/visitors --sheet).
///
///     sp_sheet_item items[] = {{.sketch = &s, .label = "41 head", .note = "2024-05-01"}};
///     sp_image img = {0};
///     if (sp_sheet_render(items, 1, &(sp_sheet_desc){0}, &img, &err) != SP_OK) ...;
///     sp_image_write_png(&img, "sheet.png", &err);
///     sp_image_free(&img);
///
/// Each drawing is fitted into its own square cell (aspect kept, the same
/// margin all round), its strokes drawn in turn in a few distinct colours
/// with a dot where each begins, so the drawing direction and the stroke
/// order can be read; the label and note go under it (ASCII, stb_easy_font).
#ifndef SP_SKETCH_SHEET_H
#define SP_SKETCH_SHEET_H

#include <stdbool.h>

#include "sp/image.h"
#include "sp/result.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One cell.
typedef struct sp_sheet_item {
    const sp_sketch* sketch; ///< NULL or empty: an empty cell with its label
    const char* label;       ///< first text line (may be NULL)
    const char* note;        ///< second text line, smaller and grey (may be NULL)
    bool highlight;          ///< a red frame (e.g. a wrong answer)
} sp_sheet_item;

/// Layout. Zero means the default.
typedef struct sp_sheet_desc {
    int cell;            ///< cell side, pixels; 0: 220
    int cols;            ///< cells per row; 0: 8 (fewer when there are fewer items)
    bool number_strokes; ///< write each stroke's index at its first point
    const char* title;   ///< a line above the grid (may be NULL)
} sp_sheet_desc;

/// Renders the sheet into *out (allocated here; free with sp_image_free).
/// SP_ERR_INVALID for n < 1 or a sheet larger than 16384 x 65536 pixels.
sp_result sp_sheet_render(const sp_sheet_item* items, int n, const sp_sheet_desc* desc, sp_image* out, sp_error* err);
/// sp_sheet_render, then a PNG at `path`.
sp_result sp_sheet_write_png(const sp_sheet_item* items, int n, const sp_sheet_desc* desc, const char* path, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
