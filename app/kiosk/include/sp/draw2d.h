/// sp/draw2d.h: the kiosk's flat 2D layer (buttons, chips, icons, text) in OpenGL 3.3.
///
///     sp_draw2d* d = sp_draw2d_create(font, &err);      // a GL 3.3 core context is current
///     sp_draw2d_begin(d, fb_w, fb_h);
///     sp_draw2d_rect(d, x, y, w, h, radius, 0, fill);  // filled rounded rectangle
///     sp_draw2d_text(d, "Undo", cx, cy, 24, SP_ALIGN_CENTER, white);
///     sp_draw2d_end(d);                                 // one draw call for everything
///
/// Everything is analytic coverage (signed distances in the fragment
/// shader), so edges stay smooth at any scale without multisampling. Pixels
/// are framebuffer pixels, y down. Colours are display (sRGB) RGBA, written
/// as given. Draws in call order on top of whatever is in the framebuffer.
#ifndef SP_KIOSK_DRAW2D_H
#define SP_KIOSK_DRAW2D_H

#include <stdbool.h>

#include "sp/font.h"
#include "sp/result.h"

typedef struct sp_draw2d sp_draw2d;

typedef enum sp_align { SP_ALIGN_LEFT, SP_ALIGN_CENTER, SP_ALIGN_RIGHT } sp_align;

/// Compiles the shader and uploads the font atlas. NULL and err on failure.
sp_draw2d* sp_draw2d_create(const sp_font* font, sp_error* err);
void sp_draw2d_destroy(sp_draw2d* d);
/// Starts a batch for a fb_w x fb_h framebuffer (the bound one).
void sp_draw2d_begin(sp_draw2d* d, int fb_w, int fb_h);
/// Draws the batch.
void sp_draw2d_end(sp_draw2d* d);

/// A rounded rectangle; border > 0 draws only a ring of that width inside the edge.
void sp_draw2d_rect(sp_draw2d* d, float x, float y, float w, float h, float radius, float border, const float rgba[4]);
/// A line with round caps.
void sp_draw2d_line(sp_draw2d* d, float x0, float y0, float x1, float y1, float width, const float rgba[4]);
/// Consecutive lines (xy: n by 2), closed or not.
void sp_draw2d_polyline(sp_draw2d* d, const float* xy, int n, bool closed, float width, const float rgba[4]);
/// A filled disc.
void sp_draw2d_disc(sp_draw2d* d, float cx, float cy, float r, const float rgba[4]);
/// An arc of a ring (radius r to the middle of the band) from angle a0 to a1
/// (radians, 0 = up, clockwise on screen).
void sp_draw2d_arc(sp_draw2d* d, float cx, float cy, float r, float width, float a0, float a1, const float rgba[4]);
/// A filled triangle (anti-aliased edges).
void sp_draw2d_triangle(sp_draw2d* d, float x0, float y0, float x1, float y1, float x2, float y2, const float rgba[4]);
/// One line of UTF-8 text with an em of px pixels, vertically centred on y
/// (cap height), aligned on x. Returns the width drawn.
float sp_draw2d_text(sp_draw2d* d, const char* text, float x, float y, float px, sp_align align, const float rgba[4]);
/// Text shrunk (never grown) to fit max_w. Returns the em size used.
float sp_draw2d_text_fit(sp_draw2d* d, const char* text, float x, float y, float px, float max_w, sp_align align,
                         const float rgba[4]);

#endif
