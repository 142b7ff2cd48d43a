/// sp/font.h: one TrueType font baked into a signed-distance-field atlas (stb_truetype).
///
///     sp_font* f = sp_font_load(NULL, &err);       // DejaVu Sans Bold from fonts-dejavu-core
///     float w = sp_font_width(f, "Undo", 24);      // pixels at a 24 px em
///     ... draw2d.h uploads f->atlas and draws quads from sp_font_glyph ...
///     sp_font_free(f);
///
/// Why a distance field: one small atlas draws crisp text at every size the
/// layout asks for (from 10 px chips on a small window to 150 px titles on
/// 4K), so a resize never re-bakes anything. CPU only: no GL here.
#ifndef SP_KIOSK_FONT_H
#define SP_KIOSK_FONT_H

#include "sp/result.h"

/// The font the kiosk uses when none is given.
#define SP_FONT_DEFAULT_PATH "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf"

/// Glyph metrics in em units (multiply by the pixel size of the em).
typedef struct sp_font_glyph {
    float x0, y0, x1, y1; ///< quad relative to the pen on the baseline, y down
    float u0, v0, u1, v1; ///< atlas texture coordinates
    float advance;
    int codepoint;
} sp_font_glyph;

typedef struct sp_font {
    int atlas_w, atlas_h;
    unsigned char* atlas;  ///< atlas_w * atlas_h bytes, distance field (128 = the outline, larger = inside)
    float sdf_spread;      ///< distance field range in em units: one atlas byte step = sdf_spread / 128 em
    float ascent, descent; ///< em units (descent negative)
    int glyph_count;
    sp_font_glyph* glyphs; ///< sorted by codepoint
    void* impl;            ///< stb_truetype state (kerning)
} sp_font;

/// Loads and bakes a TTF (path NULL: SP_FONT_DEFAULT_PATH). A missing file
/// says which Debian package to install.
sp_font* sp_font_load(const char* path, sp_error* err);
void sp_font_free(sp_font* f);
/// The glyph for a codepoint ('?' when the font lacks it).
const sp_font_glyph* sp_font_glyph_for(const sp_font* f, int codepoint);
/// Kerning between two codepoints, em units.
float sp_font_kern(const sp_font* f, int a, int b);
/// Advance width of UTF-8 text at an em of `px` pixels.
float sp_font_width(const sp_font* f, const char* text, float px);
/// Decodes one UTF-8 codepoint at *s and advances *s (bad bytes give '?').
int sp_utf8_next(const char** s);

#endif
