// png_check.h: a PNG decoded once quietly before OpenCV decodes it (internal).
#pragma once

#include <stdbool.h>
#include <stddef.h>

/// Whether the PNG in bytes decodes; *why (static text) says why not. libpng,
/// under OpenCV, prints its own "libpng error: ..." line to stderr for a
/// broken file before OpenCV fails; checking first keeps bad input to our one line.
bool sp_png_decodes(const unsigned char* bytes, size_t len, const char** why);
