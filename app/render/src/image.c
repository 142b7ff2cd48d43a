// image.c: PNG in and out through stb_image / stb_image_write (Debian libstb-dev).
#include "sp/image.h"
#include "sp/sketch_io.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

// Why static: another module may compile stb too; static copies cannot clash
// at link time. The pragmas silence stb's own warnings so that -Wall -Wextra
// -pedantic -Werror stays usable; -Wunused-function stays off for the whole
// file because GCC reports static functions that are declared but never
// defined (Debian's stb_image declares one it never defines) at the end of
// the translation unit, after any pop.
#pragma GCC diagnostic ignored "-Wunused-function"
#define STB_IMAGE_STATIC
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

sp_result sp_image_alloc(sp_image* img, int width, int height)
{
    assert(img && width > 0 && height > 0);
    sp_image_free(img);
    img->rgba = calloc((size_t)width * (size_t)height, 4);
    if (!img->rgba) return SP_ERR_NO_MEMORY;
    img->width = width;
    img->height = height;
    return SP_OK;
}

void sp_image_free(sp_image* img)
{
    if (!img) return;
    free(img->rgba);
    memset(img, 0, sizeof *img);
}

void sp_image_flip_rows(sp_image* img)
{
    size_t stride = (size_t)img->width * 4;
    uint8_t* tmp = malloc(stride);
    if (!tmp) return; // only with no memory at all; callers do not depend on it failing loudly
    for (int y = 0; y < img->height / 2; ++y) {
        uint8_t* a = img->rgba + stride * (size_t)y;
        uint8_t* b = img->rgba + stride * (size_t)(img->height - 1 - y);
        memcpy(tmp, a, stride);
        memcpy(a, b, stride);
        memcpy(b, tmp, stride);
    }
    free(tmp);
}

uint8_t* sp_image_at(const sp_image* img, int x, int y)
{
    assert(x >= 0 && y >= 0 && x < img->width && y < img->height);
    return img->rgba + 4 * ((size_t)y * (size_t)img->width + (size_t)x);
}

sp_result sp_image_write_png(const sp_image* img, const char* path, sp_error* err)
{
    assert(img && img->rgba && path);
    // Encoded in memory and written whole: stbi_write_png does not check its writes.
    int len = 0;
    unsigned char* png = stbi_write_png_to_mem(img->rgba, img->width * 4, img->width, img->height, 4, &len);
    if (!png) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory while encoding the PNG", path);
    sp_result r = sp_file_write(path, png, (size_t)len, err);
    STBIW_FREE(png);
    return r;
}

sp_result sp_image_read_png(const char* path, sp_image* img, sp_error* err)
{
    assert(img && path);
    sp_image_free(img);
    int w = 0, h = 0, comp = 0;
    unsigned char* data = stbi_load(path, &w, &h, &comp, 4);
    if (!data) return sp_fail(err, SP_ERR_PARSE, "%s: cannot read PNG (%s)", path, stbi_failure_reason());
    // Copy into malloc'd memory so that sp_image_free (free) matches the allocator.
    img->rgba = malloc((size_t)w * (size_t)h * 4);
    if (!img->rgba) {
        stbi_image_free(data);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    memcpy(img->rgba, data, (size_t)w * (size_t)h * 4);
    stbi_image_free(data);
    img->width = w;
    img->height = h;
    return SP_OK;
}

sp_result sp_image_sheet(const sp_image* images, int n, int cols, int gap, sp_image* out)
{
    if (n < 1 || cols < 1 || gap < 0) return SP_ERR_INVALID;
    int w = images[0].width, h = images[0].height, rows = (n + cols - 1) / cols;
    for (int i = 1; i < n; ++i)
        if (images[i].width != w || images[i].height != h) return SP_ERR_INVALID;
    int sw = cols * w + (cols + 1) * gap, sh = rows * h + (rows + 1) * gap;
    if (sp_image_alloc(out, sw, sh) != SP_OK) return SP_ERR_NO_MEMORY;
    for (size_t k = 0; k < (size_t)sw * (size_t)sh; ++k)
        memcpy(out->rgba + 4 * k, (const uint8_t[4]){250, 250, 250, 255}, 4);
    for (int i = 0; i < n; ++i) {
        int ox = gap + (i % cols) * (w + gap), oy = gap + (i / cols) * (h + gap);
        for (int y = 0; y < h; ++y)
            memcpy(sp_image_at(out, ox, oy + y), sp_image_at(&images[i], 0, y), 4 * (size_t)w);
    }
    return SP_OK;
}
