// png_check.c: stb_image's PNG decoder as a quiet check (png_check.h).
// Static, PNG only: the renderer's own stb copy is static too, so the two
// never meet at link time. The pragmas keep stb's own warnings out of
// -Werror builds (see app/render/src/image.c).
#pragma GCC diagnostic ignored "-Wunused-function"
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

#include "png_check.h"

#include <limits.h>

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
