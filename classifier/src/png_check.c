// png_check.c: stb_image's PNG decoder as a quiet check (png_check.h), from
// Debian's libstb (libstb-dev), not compiled in here.
#include "png_check.h"

#include <limits.h>
#include <stb/stb_image.h>

bool sp_png_decodes(const unsigned char* bytes, size_t len, const char** why)
{
    if (len > INT_MAX) {
        *why = "file too large";
        return false;
    }
    int w, h, comp;
    stbi_uc* px = stbi_load_from_memory(bytes, (int)len, &w, &h, &comp, 0);
    if (!px) {
        *why = stbi_failure_reason();
        return false;
    }
    stbi_image_free(px);
    return true;
}
