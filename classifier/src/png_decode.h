// png_decode.h: the classifier's one PNG decoder, stb_image (internal).
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/// A decoded PNG: rows top down, samples interleaved R, G, B, A.
typedef struct sp_png_image {
    void* samples; // w * h * channels samples: unsigned char, or uint16_t (native order) when wide
    int w, h;      // pixels
    int channels;  // 1 grey, 2 grey and alpha, 3 RGB, 4 RGBA
    bool wide;     // 16 bits a sample (a 16-bit PNG), else 8
} sp_png_image;

/// The size the PNG's header (its first 24 bytes will do) says: NULL with *w
/// and *h, else why not (static text: "not a PNG file", "PNG header
/// truncated", "PNG has zero size"). Read before decoding, so that a caller
/// can refuse a size before the decoder allocates it.
const char* sp_png_header(const unsigned char* bytes, size_t len, uint32_t* w, uint32_t* h);

/// Decodes the PNG in bytes; false with *why (static, per-thread text) when
/// it does not decode, or a chunk runs past the end or fails its CRC. Quiet:
/// libpng, under OpenCV's decoder, printed its own "libpng error: ..." line
/// to stderr for a broken file, stb prints nothing.
/// The channels are those OpenCV's decoder gave, so the grey conversion after
/// it is unchanged: a grey PNG's tRNS colour key is ignored, any other tRNS
/// becomes alpha.
bool sp_png_decode(const unsigned char* bytes, size_t len, sp_png_image* out, const char** why);

/// Frees what sp_png_decode made (NULL samples is fine).
void sp_png_image_free(sp_png_image* img);
