// fuzz_png.c: libFuzzer entry for the PNG drawing decoder: the header read
// before decoding, the chunk CRC walk and stb_image behind them, as
// sp_raster_read_png runs them.
#include <stddef.h>
#include <stdint.h>

#include "png_decode.h"

// Smaller than SP_RASTER_MAX_SIDE (8192), which the reader allows: a fuzzed
// header of that size makes stb allocate hundreds of MB an input and the run
// crawls; the paths taken are the same.
enum { FUZZ_MAX_SIDE = 512 };

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    uint32_t w, h;
    if (sp_png_header(data, size, &w, &h) || w > FUZZ_MAX_SIDE || h > FUZZ_MAX_SIDE) return 0;
    sp_png_image img;
    const char* why = NULL;
    if (sp_png_decode(data, size, &img, &why)) sp_png_image_free(&img);
    return 0;
}
