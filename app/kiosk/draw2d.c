// draw2d.c: one shader, one vertex buffer, signed-distance coverage per primitive.
#include "sp/draw2d.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "sp/render.h"

// clang-format off
static const char* k_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec2 a_px;\n"
    "layout(location = 1) in vec2 a_uv;\n"
    "layout(location = 2) in vec4 a_col;\n"
    "layout(location = 3) in vec4 a_a;\n"
    "layout(location = 4) in vec4 a_b;\n"
    "uniform vec2 u_size;\n"
    "out vec2 v_px;\n"
    "out vec2 v_uv;\n"
    "out vec4 v_col;\n"
    "flat out vec4 v_a;\n"
    "flat out vec4 v_b;\n"
    "void main() {\n"
    "    v_px = a_px; v_uv = a_uv; v_col = a_col; v_a = a_a; v_b = a_b;\n"
    "    gl_Position = vec4(2.0 * a_px.x / u_size.x - 1.0, 1.0 - 2.0 * a_px.y / u_size.y, 0.0, 1.0);\n"
    "}\n";

// Modes (v_b.w): 0 flat, 1 rounded rectangle (a: centre, half size; b.x
// radius, b.y border), 2 capsule (a: ends; b.x radius), 3 glyph (distance
// field), 4 arc (a: centre, radius, width; b.xy angles), 5 triangle (a, b.xy: corners).
static const char* k_fs =
    "#version 330 core\n"
    "in vec2 v_px;\n"
    "in vec2 v_uv;\n"
    "in vec4 v_col;\n"
    "flat in vec4 v_a;\n"
    "flat in vec4 v_b;\n"
    "uniform sampler2D u_atlas;\n"
    "out vec4 o_col;\n"
    "float cov(float d) { return clamp(0.5 - d, 0.0, 1.0); }\n"
    "float dseg(vec2 p, vec2 a, vec2 b) {\n"
    "    vec2 pa = p - a, ba = b - a;\n"
    "    float h = clamp(dot(pa, ba) / max(dot(ba, ba), 1e-12), 0.0, 1.0);\n"
    "    return length(pa - ba * h);\n"
    "}\n"
    "float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }\n"
    "void main() {\n"
    "    int mode = int(v_b.w + 0.5);\n"
    "    float a = 1.0;\n"
    "    if (mode == 1) {\n"
    "        vec2 q = abs(v_px - v_a.xy) - v_a.zw + vec2(v_b.x);\n"
    "        float d = length(max(q, 0.0)) + min(max(q.x, q.y), 0.0) - v_b.x;\n"
    "        a = cov(d);\n"
    "        if (v_b.y > 0.0) a *= 1.0 - cov(d + v_b.y);\n"
    "    } else if (mode == 2) {\n"
    "        a = cov(dseg(v_px, v_a.xy, v_a.zw) - v_b.x);\n"
    "    } else if (mode == 3) {\n"
    "        float s = texture(u_atlas, v_uv).r;\n"
    "        float w = max(fwidth(s), 1e-4);\n"
    "        a = clamp((s - 0.502) / w + 0.5, 0.0, 1.0);\n"
    "    } else if (mode == 4) {\n"
    "        vec2 p = v_px - v_a.xy;\n"
    "        float ang = atan(p.x, -p.y);\n"
    "        if (ang < 0.0) ang += 6.28318530718;\n"
    "        float d;\n"
    "        if (ang >= v_b.x && ang <= v_b.y) d = abs(length(p) - v_a.z);\n"
    "        else {\n"
    "            vec2 e0 = v_a.z * vec2(sin(v_b.x), -cos(v_b.x)), e1 = v_a.z * vec2(sin(v_b.y), -cos(v_b.y));\n"
    "            d = min(length(p - e0), length(p - e1));\n"
    "        }\n"
    "        a = cov(d - 0.5 * v_a.w);\n"
    "    } else if (mode == 5) {\n"
    "        vec2 p0 = v_a.xy, p1 = v_a.zw, p2 = v_b.xy;\n"
    "        float d = min(dseg(v_px, p0, p1), min(dseg(v_px, p1, p2), dseg(v_px, p2, p0)));\n"
    "        float s = sign(cross2(p1 - p0, p2 - p0));\n"
    "        bool in_ = s * cross2(p1 - p0, v_px - p0) >= 0.0 && s * cross2(p2 - p1, v_px - p1) >= 0.0 && s * cross2(p0 - p2, v_px - p2) >= 0.0;\n"
    "        a = cov(in_ ? -d : d);\n"
    "    }\n"
    "    if (a <= 0.0) discard;\n"
    "    o_col = vec4(v_col.rgb, v_col.a * a);\n"
    "}\n";
// clang-format on

typedef struct vertex {
    float px[2], uv[2], col[4], a[4], b[4];
} vertex;

struct sp_draw2d {
    const sp_font* font;
    float cap; // cap height, em units
    GLuint prog, vao, vbo, tex;
    GLint u_size, u_atlas;
    size_t vbo_bytes;
    vertex* v;
    size_t n, cap_v;
    int w, h;
};

sp_draw2d* sp_draw2d_create(const sp_font* font, sp_error* err)
{
    sp_draw2d* d = calloc(1, sizeof *d);
    if (!d) {
        sp_fail(err, SP_ERR_NO_MEMORY, "draw2d: out of memory");
        return NULL;
    }
    d->font = font;
    const sp_font_glyph* H = sp_font_glyph_for(font, 'H');
    d->cap = -(H->y0 + font->sdf_spread);
    if (!(d->cap > 0.3f && d->cap < 1.2f)) d->cap = 0.72f;
    d->prog = sp_gl_program(k_vs, k_fs, "draw2d", err);
    if (!d->prog) {
        free(d);
        return NULL;
    }
    d->u_size = glGetUniformLocation(d->prog, "u_size");
    d->u_atlas = glGetUniformLocation(d->prog, "u_atlas");
    glGenVertexArrays(1, &d->vao);
    glGenBuffers(1, &d->vbo);
    glBindVertexArray(d->vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->vbo);
    const GLsizei stride = (GLsizei)sizeof(vertex);
    const size_t off[5] = {offsetof(vertex, px), offsetof(vertex, uv), offsetof(vertex, col), offsetof(vertex, a),
                           offsetof(vertex, b)};
    const int size[5] = {2, 2, 4, 4, 4};
    for (int i = 0; i < 5; ++i) {
        glEnableVertexAttribArray((GLuint)i);
        glVertexAttribPointer((GLuint)i, size[i], GL_FLOAT, GL_FALSE, stride, (const void*)off[i]);
    }
    glBindVertexArray(0);
    glGenTextures(1, &d->tex);
    glBindTexture(GL_TEXTURE_2D, d->tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, font->atlas_w, font->atlas_h, 0, GL_RED, GL_UNSIGNED_BYTE, font->atlas);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        sp_fail(err, SP_ERR_INTERNAL, "draw2d: GL error 0x%x while creating", e);
        sp_draw2d_destroy(d);
        return NULL;
    }
    return d;
}

void sp_draw2d_destroy(sp_draw2d* d)
{
    if (!d) return;
    if (d->prog) glDeleteProgram(d->prog);
    if (d->vbo) glDeleteBuffers(1, &d->vbo);
    if (d->vao) glDeleteVertexArrays(1, &d->vao);
    if (d->tex) glDeleteTextures(1, &d->tex);
    free(d->v);
    free(d);
}

void sp_draw2d_begin(sp_draw2d* d, int fb_w, int fb_h)
{
    d->n = 0;
    d->w = fb_w > 0 ? fb_w : 1;
    d->h = fb_h > 0 ? fb_h : 1;
}

void sp_draw2d_end(sp_draw2d* d)
{
    if (d->n == 0) return;
    glViewport(0, 0, d->w, d->h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(d->prog);
    glUniform2f(d->u_size, (float)d->w, (float)d->h);
    glUniform1i(d->u_atlas, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, d->tex);
    glBindVertexArray(d->vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->vbo);
    size_t bytes = d->n * sizeof(vertex);
    if (bytes > d->vbo_bytes) {
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes, d->v, GL_STREAM_DRAW);
        d->vbo_bytes = bytes;
    } else {
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)d->vbo_bytes, NULL, GL_STREAM_DRAW); // orphan: last frame may still read it
        glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)bytes, d->v);
    }
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)d->n);
    glBindVertexArray(0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    glDepthMask(GL_TRUE);
    d->n = 0;
}

// One quad [x0, x1] x [y0, y1] carrying a primitive (uv corners for glyphs).
static void quad(sp_draw2d* d, float x0, float y0, float x1, float y1, const float uv[4], const float col[4], const float a[4],
                 const float b[4])
{
    if (d->n + 6 > d->cap_v) {
        size_t cap = d->cap_v ? 2 * d->cap_v : 4096;
        vertex* v = realloc(d->v, cap * sizeof *v);
        if (!v) return; // drop the primitive rather than the frame
        d->v = v, d->cap_v = cap;
    }
    static const int order[6] = {0, 1, 2, 0, 2, 3};
    const float cx[4] = {x0, x1, x1, x0}, cy[4] = {y0, y0, y1, y1};
    for (int i = 0; i < 6; ++i) {
        int k = order[i];
        vertex* o = &d->v[d->n++];
        o->px[0] = cx[k], o->px[1] = cy[k];
        o->uv[0] = uv ? (k == 0 || k == 3 ? uv[0] : uv[2]) : 0;
        o->uv[1] = uv ? (k < 2 ? uv[1] : uv[3]) : 0;
        memcpy(o->col, col, sizeof o->col);
        memcpy(o->a, a, sizeof o->a);
        memcpy(o->b, b, sizeof o->b);
    }
}

void sp_draw2d_rect(sp_draw2d* d, float x, float y, float w, float h, float radius, float border, const float rgba[4])
{
    if (!(w > 0 && h > 0)) return;
    float r = fminf(fmaxf(radius, 0.0f), 0.5f * fminf(w, h));
    const float a[4] = {x + 0.5f * w, y + 0.5f * h, 0.5f * w, 0.5f * h}, b[4] = {r, border, 0, 1};
    quad(d, x - 1, y - 1, x + w + 1, y + h + 1, NULL, rgba, a, b);
}

void sp_draw2d_line(sp_draw2d* d, float x0, float y0, float x1, float y1, float width, const float rgba[4])
{
    if (!(width > 0) || !isfinite(x0 + y0 + x1 + y1)) return;
    float r = 0.5f * width, pad = r + 1.5f;
    const float a[4] = {x0, y0, x1, y1}, b[4] = {r, 0, 0, 2};
    quad(d, fminf(x0, x1) - pad, fminf(y0, y1) - pad, fmaxf(x0, x1) + pad, fmaxf(y0, y1) + pad, NULL, rgba, a, b);
}

void sp_draw2d_polyline(sp_draw2d* d, const float* xy, int n, bool closed, float width, const float rgba[4])
{
    for (int i = 0; i + 1 < n; ++i)
        sp_draw2d_line(d, xy[2 * i], xy[2 * i + 1], xy[2 * i + 2], xy[2 * i + 3], width, rgba);
    if (closed && n > 2) sp_draw2d_line(d, xy[2 * n - 2], xy[2 * n - 1], xy[0], xy[1], width, rgba);
}

void sp_draw2d_disc(sp_draw2d* d, float cx, float cy, float r, const float rgba[4])
{
    sp_draw2d_line(d, cx, cy, cx, cy, 2 * r, rgba);
}

void sp_draw2d_arc(sp_draw2d* d, float cx, float cy, float r, float width, float a0, float a1, const float rgba[4])
{
    if (!(a1 > a0)) return;
    const float tau = 6.28318530718f;
    if (a1 - a0 >= tau) a0 = 0, a1 = tau;
    while (a0 < 0)
        a0 += tau, a1 += tau;
    while (a0 >= tau)
        a0 -= tau, a1 -= tau;
    if (a1 > tau) { // the shader's angles run 0..2pi: split at the top
        sp_draw2d_arc(d, cx, cy, r, width, a0, tau, rgba);
        sp_draw2d_arc(d, cx, cy, r, width, 0, a1 - tau, rgba);
        return;
    }
    float pad = r + 0.5f * width + 1.5f;
    const float a[4] = {cx, cy, r, width}, b[4] = {a0, a1, 0, 4};
    quad(d, cx - pad, cy - pad, cx + pad, cy + pad, NULL, rgba, a, b);
}

void sp_draw2d_triangle(sp_draw2d* d, float x0, float y0, float x1, float y1, float x2, float y2, const float rgba[4])
{
    const float a[4] = {x0, y0, x1, y1}, b[4] = {x2, y2, 0, 5};
    quad(d, fminf(x0, fminf(x1, x2)) - 1.5f, fminf(y0, fminf(y1, y2)) - 1.5f, fmaxf(x0, fmaxf(x1, x2)) + 1.5f,
         fmaxf(y0, fmaxf(y1, y2)) + 1.5f, NULL, rgba, a, b);
}

float sp_draw2d_text(sp_draw2d* d, const char* text, float x, float y, float px, sp_align align, const float rgba[4])
{
    if (!text || !(px > 0)) return 0;
    float w = sp_font_width(d->font, text, px);
    float pen = align == SP_ALIGN_CENTER ? x - 0.5f * w : align == SP_ALIGN_RIGHT ? x - w : x;
    float base = y + 0.5f * d->cap * px;
    const float b[4] = {0, 0, 0, 3}, a[4] = {0};
    int prev = 0;
    for (const char* s = text; *s;) {
        int cp = sp_utf8_next(&s);
        if (prev) pen += sp_font_kern(d->font, prev, cp) * px;
        const sp_font_glyph* g = sp_font_glyph_for(d->font, cp);
        if (g->x1 > g->x0) {
            const float uv[4] = {g->u0, g->v0, g->u1, g->v1};
            quad(d, pen + g->x0 * px, base + g->y0 * px, pen + g->x1 * px, base + g->y1 * px, uv, rgba, a, b);
        }
        pen += g->advance * px;
        prev = cp;
    }
    return w;
}

float sp_draw2d_text_fit(sp_draw2d* d, const char* text, float x, float y, float px, float max_w, sp_align align,
                         const float rgba[4])
{
    float w = sp_font_width(d->font, text, px);
    if (w > max_w && w > 0) px *= max_w / w;
    sp_draw2d_text(d, text, x, y, px, align, rgba);
    return px;
}
