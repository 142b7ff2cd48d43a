// png_decode.c: stb_image's PNG decoder (png_decode.h), from Debian's libstb
// (libstb-dev), not compiled in here.
#include "png_decode.h"

#include <limits.h>
#include <stb/stb_image.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <zlib.h>

static uint32_t be32(const unsigned char* p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

// True when every chunk is whole and its CRC matches (zlib's crc32 over type
// and data). stb_image checks no CRC at all, so a damaged chunk would decode
// to other pixels without a word (libpng refused it); and it takes a chunk's
// length on trust, so a 100-byte file whose IDAT claims 1.7 GB made it
// allocate that much before finding the data missing.
static bool chunks_intact(const unsigned char* bytes, size_t len, const char** why)
{
    static _Thread_local char said[128]; // *why outlives the call
    size_t at = 8;                       // after the signature
    while (at + 12 <= len) {
        uint32_t n = be32(bytes + at);
        char type[5] = {0};
        for (int i = 0; i < 4; ++i)
            type[i] = bytes[at + 4 + i] >= 0x20 && bytes[at + 4 + i] < 0x7f ? (char)bytes[at + 4 + i] : '?';
        if (n > len - at - 12) {
            snprintf(said, sizeof said, "chunk '%s' at byte %zu claims %u bytes, %zu are left", type, at, (unsigned)n,
                     len - at - 12);
            *why = said;
            return false;
        }
        if ((uint32_t)crc32(0L, bytes + at + 4, n + 4) != be32(bytes + at + 8 + n)) {
            snprintf(said, sizeof said, "chunk '%s' at byte %zu fails its CRC", type, at);
            *why = said;
            return false;
        }
        if (!memcmp(bytes + at + 4, "IEND", 4)) return true;
        at += 12 + (size_t)n;
    }
    return true;
}

const char* sp_png_header(const unsigned char* bytes, size_t len, uint32_t* w, uint32_t* h)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (len < 8 || memcmp(bytes, sig, 8) != 0) return "not a PNG file";
    if (len < 24 || memcmp(bytes + 12, "IHDR", 4) != 0) return "PNG header truncated";
    *w = be32(bytes + 16);
    *h = be32(bytes + 20);
    return *w == 0 || *h == 0 ? "PNG has zero size" : NULL;
}

bool sp_png_decode(const unsigned char* bytes, size_t len, sp_png_image* out, const char** why)
{
    memset(out, 0, sizeof *out);
    if (len > INT_MAX) {
        *why = "file too large";
        return false;
    }
    if (!chunks_intact(bytes, len, why)) return false;
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
