/// image.h: RGBA8 images in memory and as PNG files.
///
///     sp_image img = {0};
///     if (sp_image_alloc(&img, 640, 480) != SP_OK) ...;
///     ... sp_render_target_read(target, &img) ...
///     sp_image_write_png(&img, "out.png", &err);
///     sp_image_free(&img);
///
/// Rows are stored top-down (row 0 is the top of the picture, like pixels
/// y-down everywhere else); OpenGL's bottom-up rows are flipped on readback.
#ifndef SP_IMAGE_H
#define SP_IMAGE_H

#include <stdint.h>

#include "sp/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sp_image {
    int width, height; ///< pixels
    uint8_t* rgba;     ///< width*height by 4, top-down rows, sRGB-encoded, straight alpha
} sp_image;

/// Allocates a zeroed (transparent black) image; frees what *img held before.
sp_result sp_image_alloc(sp_image* img, int width, int height);
/// Frees the pixels and zeroes the image.
void sp_image_free(sp_image* img);
/// Reverses the row order in place (GL bottom-up <-> top-down).
void sp_image_flip_rows(sp_image* img);
/// Pointer to pixel (x, y), y from the top; asserts the pixel is inside.
uint8_t* sp_image_at(const sp_image* img, int x, int y);
/// Lays n equally sized images out in a grid of `cols` columns, row by row,
/// `gap` pixels apart and around, on a near-white sheet (*out allocated).
/// SP_ERR_INVALID when the sizes differ or n or cols is not positive.
sp_result sp_image_sheet(const sp_image* images, int n, int cols, int gap, sp_image* out);
/// Writes an 8-bit RGBA PNG. err names the path on failure.
sp_result sp_image_write_png(const sp_image* img, const char* path, sp_error* err);
/// Reads any PNG (grey, RGB, palette, 16-bit) as RGBA8 into *img (freed first).
sp_result sp_image_read_png(const char* path, sp_image* img, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
