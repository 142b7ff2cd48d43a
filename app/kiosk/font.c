// font.c: stb_truetype (Debian libstb-dev) signed distance fields, shelf-packed.
#include "sp/font.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sp/sketch_io.h"

// Why static and the pragmas: as in image.c, our copy cannot clash with
// another module's, and stb's own warnings must not break -Werror builds.
#pragma GCC diagnostic ignored "-Wunused-function"
#define STBTT_STATIC
#define STB_TRUETYPE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <stb/stb_truetype.h>
#pragma GCC diagnostic pop

enum {
    BAKE_PX = 48, // em size of the baked glyphs
    PAD = 6,      // distance field reach around each glyph, atlas pixels
    ATLAS_W = 1024,
};

typedef struct impl {
    stbtt_fontinfo info;
    unsigned char* ttf;
    float scale; // font units -> baked pixels
} impl;

// ASCII, plus the few non-ASCII characters the UI's texts use.
static const int k_extra[] = {0x2026 /* … */, 0x00B7 /* · */, 0x2190, 0x2192, 0x21BA /* ↺ */, 0x00D7 /* × */};

int sp_utf8_next(const char** s)
{
    const unsigned char* p = (const unsigned char*)*s;
    int c = p[0], n = 0;
    if (c < 0x80)
        n = 0;
    else if ((c & 0xE0) == 0xC0)
        c &= 0x1F, n = 1;
    else if ((c & 0xF0) == 0xE0)
        c &= 0x0F, n = 2;
    else if ((c & 0xF8) == 0xF0)
        c &= 0x07, n = 3;
    else {
        *s += 1;
        return '?';
    }
    for (int i = 1; i <= n; ++i) {
        if ((p[i] & 0xC0) != 0x80) {
            *s += i;
            return '?';
        }
        c = (c << 6) | (p[i] & 0x3F);
    }
    *s += n + 1;
    return c;
}

static unsigned char* read_file(const char* path, size_t* size, sp_error* err)
{
    void* data = NULL;
    if (access(path, F_OK) != 0 && errno == ENOENT)
        sp_fail(err, SP_ERR_IO, "%s: font missing (install the Debian package fonts-dejavu-core)", path);
    else if (sp_file_read(path, (size_t)64 << 20, &data, size, err) == SP_OK && *size == 0) {
        sp_fail(err, SP_ERR_IO, "%s: the font file is empty", path);
        free(data);
        data = NULL;
    }
    return data;
}

sp_font* sp_font_load(const char* path, sp_error* err)
{
    if (!path) path = SP_FONT_DEFAULT_PATH;
    size_t size = 0;
    unsigned char* ttf = read_file(path, &size, err);
    if (!ttf) return NULL;
    sp_font* f = calloc(1, sizeof *f);
    impl* im = calloc(1, sizeof *im);
    if (!f || !im) {
        free(ttf);
        free(f);
        free(im);
        sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
        return NULL;
    }
    f->impl = im;
    im->ttf = ttf;
    int ncp = 95 + (int)(sizeof k_extra / sizeof k_extra[0]);
    f->glyphs = calloc((size_t)ncp, sizeof *f->glyphs);
    if (!f->glyphs) {
        sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
        goto fail;
    }
    int offset = stbtt_GetFontOffsetForIndex(im->ttf, 0);
    if (offset < 0 || !stbtt_InitFont(&im->info, im->ttf, offset)) {
        sp_fail(err, SP_ERR_PARSE, "%s: not a TrueType font", path);
        goto fail;
    }
    im->scale = stbtt_ScaleForMappingEmToPixels(&im->info, BAKE_PX);
    int asc, desc, gap;
    stbtt_GetFontVMetrics(&im->info, &asc, &desc, &gap);
    f->ascent = (float)asc * im->scale / BAKE_PX;
    f->descent = (float)desc * im->scale / BAKE_PX;
    f->sdf_spread = (float)PAD / BAKE_PX;

    // Bake every glyph, shelf-pack them into a growing atlas.
    int cap_h = 256;
    f->atlas = calloc((size_t)ATLAS_W * (size_t)cap_h, 1);
    if (!f->atlas) {
        sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
        goto fail;
    }
    int x = 1, y = 1, shelf = 0;
    for (int k = 0; k < ncp; ++k) {
        int cp = k < 95 ? 32 + k : k_extra[k - 95];
        if (k >= 95 && stbtt_FindGlyphIndex(&im->info, cp) == 0) continue;
        int w = 0, h = 0, xo = 0, yo = 0, adv = 0, lsb = 0;
        unsigned char* bm = stbtt_GetCodepointSDF(&im->info, im->scale, cp, PAD, 128, 128.0f / PAD, &w, &h, &xo, &yo);
        stbtt_GetCodepointHMetrics(&im->info, cp, &adv, &lsb);
        sp_font_glyph* g = &f->glyphs[f->glyph_count++];
        g->codepoint = cp;
        g->advance = (float)adv * im->scale / BAKE_PX;
        if (!bm || w <= 0 || h <= 0) { // a space
            if (bm) stbtt_FreeSDF(bm, NULL);
            continue;
        }
        if (x + w + 1 > ATLAS_W) x = 1, y += shelf + 1, shelf = 0;
        while (y + h + 1 > cap_h) {
            unsigned char* a = realloc(f->atlas, (size_t)ATLAS_W * (size_t)cap_h * 2);
            if (!a) {
                stbtt_FreeSDF(bm, NULL);
                sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
                goto fail;
            }
            memset(a + (size_t)ATLAS_W * (size_t)cap_h, 0, (size_t)ATLAS_W * (size_t)cap_h);
            f->atlas = a;
            cap_h *= 2;
        }
        for (int r = 0; r < h; ++r)
            memcpy(f->atlas + (size_t)(y + r) * ATLAS_W + (size_t)x, bm + (size_t)r * (size_t)w, (size_t)w);
        stbtt_FreeSDF(bm, NULL);
        g->x0 = (float)xo / BAKE_PX, g->y0 = (float)yo / BAKE_PX;
        g->x1 = (float)(xo + w) / BAKE_PX, g->y1 = (float)(yo + h) / BAKE_PX;
        g->u0 = (float)x, g->v0 = (float)y, g->u1 = (float)(x + w), g->v1 = (float)(y + h); // pixels for now
        x += w + 1;
        if (h > shelf) shelf = h;
    }
    f->atlas_w = ATLAS_W;
    f->atlas_h = cap_h;
    for (int k = 0; k < f->glyph_count; ++k) {
        sp_font_glyph* g = &f->glyphs[k];
        g->u0 /= (float)ATLAS_W, g->u1 /= (float)ATLAS_W, g->v0 /= (float)cap_h, g->v1 /= (float)cap_h;
    }
    // Sorted by codepoint for the binary search (the extras are out of order).
    for (int i = 1; i < f->glyph_count; ++i)
        for (int j = i; j > 0 && f->glyphs[j - 1].codepoint > f->glyphs[j].codepoint; --j) {
            sp_font_glyph t = f->glyphs[j];
            f->glyphs[j] = f->glyphs[j - 1];
            f->glyphs[j - 1] = t;
        }
    return f;
fail:
    sp_font_free(f);
    return NULL;
}

void sp_font_free(sp_font* f)
{
    if (!f) return;
    impl* im = f->impl;
    if (im) free(im->ttf);
    free(im);
    free(f->atlas);
    free(f->glyphs);
    free(f);
}

const sp_font_glyph* sp_font_glyph_for(const sp_font* f, int cp)
{
    for (int pass = 0; pass < 2; ++pass, cp = '?') {
        int lo = 0, hi = f->glyph_count - 1;
        while (lo <= hi) {
            int mid = (lo + hi) / 2;
            if (f->glyphs[mid].codepoint == cp) return &f->glyphs[mid];
            if (f->glyphs[mid].codepoint < cp)
                lo = mid + 1;
            else
                hi = mid - 1;
        }
    }
    return &f->glyphs[0];
}

float sp_font_kern(const sp_font* f, int a, int b)
{
    const impl* im = f->impl;
    return (float)stbtt_GetCodepointKernAdvance(&im->info, a, b) * im->scale / BAKE_PX;
}

float sp_font_width(const sp_font* f, const char* text, float px)
{
    float w = 0;
    int prev = 0;
    for (const char* s = text; s && *s;) {
        int cp = sp_utf8_next(&s);
        if (prev) w += sp_font_kern(f, prev, cp);
        w += sp_font_glyph_for(f, cp)->advance;
        prev = cp;
    }
    return w * px;
}
