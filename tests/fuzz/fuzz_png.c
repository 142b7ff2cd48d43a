// fuzz_png.c: libFuzzer entry for the PNG drawing decoder: the header read
// before decoding, the chunk CRC walk and stb_image behind them, as
// sp_raster_read_png runs them.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "png_decode.h"

// Smaller than SP_RASTER_MAX_SIDE (8192), which the reader allows: a fuzzed
// header of that size makes stb allocate hundreds of MB an input and the run
// crawls; the paths taken are the same.
enum { FUZZ_MAX_SIDE = 512 };

static void decode(const uint8_t* data, size_t size)
{
    uint32_t w, h;
    if (sp_png_header(data, size, &w, &h) || w > FUZZ_MAX_SIDE || h > FUZZ_MAX_SIDE) return;
    sp_png_image img;
    const char* why = NULL;
    if (sp_png_decode(data, size, &img, &why)) sp_png_image_free(&img);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    decode(data, size);
    // Again with every whole chunk's CRC made right: a mutation almost never
    // keeps them, and the decoder behind the CRC walk must see such input too.
    uint8_t* fixed = malloc(size ? size : 1);
    if (!fixed) return 0;
    memcpy(fixed, data, size);
    for (size_t at = 8; at + 12 <= size;) {
        uint32_t n = (uint32_t)fixed[at] << 24 | (uint32_t)fixed[at + 1] << 16 | (uint32_t)fixed[at + 2] << 8 | fixed[at + 3];
        if (n > size - at - 12) break;
        uint32_t c = (uint32_t)crc32(0L, fixed + at + 4, n + 4);
        uint8_t* p = fixed + at + 8 + n;
        p[0] = (uint8_t)(c >> 24), p[1] = (uint8_t)(c >> 16), p[2] = (uint8_t)(c >> 8), p[3] = (uint8_t)c;
        at += 12 + (size_t)n;
    }
    decode(fixed, size);
    free(fixed);
    return 0;
}
