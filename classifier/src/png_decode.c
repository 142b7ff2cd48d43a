// png_decode.c: stb_image's PNG decoder (png_decode.h), from Debian's libstb
// (libstb-dev), not compiled in here.
#include "png_decode.h"

#include <limits.h>
#include <stb/stb_image.h>
#include <string.h>

bool sp_png_decode(const unsigned char* bytes, size_t len, sp_png_image* out, const char** why)
{
    memset(out, 0, sizeof *out);
    if (len > INT_MAX) {
        *why = "file too large";
        return false;
    }
    // Colour type 0 (grey) at byte 25, in IHDR: asking for one channel drops
    // the alpha stb would make of a tRNS key, as OpenCV's decoder did.
    int want = len > 25 && bytes[25] == 0 ? 1 : 0;
    int w, h, comp;
    bool wide = stbi_is_16_bit_from_memory(bytes, (int)len) != 0;
    void* px = wide ? (void*)stbi_load_16_from_memory(bytes, (int)len, &w, &h, &comp, want)
                    : (void*)stbi_load_from_memory(bytes, (int)len, &w, &h, &comp, want);
    if (!px) {
        *why = stbi_failure_reason();
        return false;
    }
    *out = (sp_png_image){px, w, h, want ? want : comp, wide};
    return true;
}

void sp_png_image_free(sp_png_image* img)
{
    stbi_image_free(img->samples);
    memset(img, 0, sizeof *img);
}
