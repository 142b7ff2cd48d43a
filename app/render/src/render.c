// render.c: meshes (smooth-shaded, CPU normals), 2D overlays (capsule
// coverage), the sp_camera -> GL projection, offscreen targets.
#include "sp/render.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

// ---------------------------------------------------------------- shaders

// clang-format off
static const char* k_mesh_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_nrm;\n"
    "layout(location = 2) in vec4 a_col;\n"
    "uniform mat4 u_model_view;\n"
    "uniform mat4 u_proj;\n"
    "uniform mat3 u_normal;\n"
    "out vec3 v_pos;\n"
    "out vec3 v_nrm;\n"
    "out vec4 v_col;\n"
    "void main() {\n"
    "    vec4 p = u_model_view * vec4(a_pos, 1.0);\n"
    "    v_pos = p.xyz;\n"
    "    v_nrm = u_normal * a_nrm;\n"
    "    v_col = a_col;\n"
    "    gl_Position = u_proj * p;\n"
    "}\n";

// Lights live in camera space so that a character is lit the same way from
// whatever view it is sketched. Why wrap lighting and a hemisphere ambient:
// sketch-view renders are mostly front-on, where plain Lambert leaves the
// silhouette flat and dark; the rim light separates it from the background.
static const char* k_mesh_fs =
    "#version 330 core\n"
    "in vec3 v_pos;\n"
    "in vec3 v_nrm;\n"
    "in vec4 v_col;\n"
    "uniform bool u_ortho;\n"
    "uniform vec3 u_up;\n"
    "uniform float u_exposure;\n"
    "uniform float u_ambient;\n"
    "uniform float u_rim;\n"
    "out vec4 o_col;\n"
    "float wrap(float d, float w) { return max((d + w) / (1.0 + w), 0.0); }\n"
    "vec3 to_srgb(vec3 c) {\n"
    "    c = clamp(c, 0.0, 1.0);\n"
    "    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));\n"
    "}\n"
    "void main() {\n"
    "    vec3 n = normalize(v_nrm);\n"
    "    vec3 v = u_ortho ? vec3(0.0, 0.0, 1.0) : normalize(-v_pos);\n"
    "    if (dot(n, v) < 0.0) n = -n;\n"
    "    vec3 albedo = v_col.rgb;\n"
    "    vec3 key_dir = normalize(vec3(-0.45, 0.65, 0.62));\n"
    "    vec3 fill_dir = normalize(vec3(0.75, 0.05, 0.55));\n"
    "    vec3 rim_dir = normalize(vec3(0.35, 0.55, -0.75));\n"
    "    vec3 key = vec3(1.00, 0.95, 0.88) * 1.0 * wrap(dot(n, key_dir), 0.15);\n"
    "    vec3 fill = vec3(0.75, 0.85, 1.0) * 0.3 * wrap(dot(n, fill_dir), 0.4);\n"
    "    float hemi = 0.5 + 0.5 * dot(n, u_up);\n"
    "    vec3 amb = mix(vec3(0.32, 0.28, 0.25), vec3(0.55, 0.62, 0.75), hemi) * u_ambient;\n"
    "    vec3 h = normalize(key_dir + v);\n"
    "    float spec = 0.12 * pow(max(dot(n, h), 0.0), 48.0) * step(0.0, dot(n, key_dir));\n"
    "    float fres = pow(1.0 - max(dot(n, v), 0.0), 3.0);\n"
    "    vec3 rim = vec3(0.9, 0.95, 1.0) * u_rim * fres * (0.35 + 0.65 * max(dot(n, rim_dir) + 0.5, 0.0));\n"
    "    vec3 c = albedo * (key + fill + amb) + spec + rim * (0.4 + 0.6 * albedo);\n"
    "    c *= u_exposure;\n"
    "    c = 1.05 * c / (1.0 + 0.2 * max(max(c.r, c.g), c.b));\n" // gentle shoulder: no clipped highlights
    "    o_col = vec4(to_srgb(c), 1.0);\n"
    "}\n";

// Overlay primitives in camera pixels. Each vertex carries the primitive it
// belongs to; the fragment shader computes coverage analytically:
// mode 0: capsule (segment a-b, radius), mode 1: soft ellipse (centre,
// radii), mode 2: flat colour (background gradient).
static const char* k_overlay_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec2 a_px;\n"
    "layout(location = 1) in vec4 a_seg;\n"
    "layout(location = 2) in vec4 a_par;\n"
    "layout(location = 3) in vec4 a_col;\n"
    "layout(location = 4) in vec4 a_nb;\n"
    "layout(location = 5) in float a_z;\n"
    "uniform vec2 u_size;\n"
    "out vec2 v_px;\n"
    "flat out vec4 v_seg;\n"
    "flat out vec4 v_par;\n"
    "out vec4 v_col;\n"
    "flat out vec4 v_nb;\n"
    "void main() {\n"
    "    v_px = a_px; v_seg = a_seg; v_par = a_par; v_col = a_col; v_nb = a_nb;\n"
    "    gl_Position = vec4(2.0 * a_px.x / u_size.x - 1.0, 1.0 - 2.0 * a_px.y / u_size.y, a_z, 1.0);\n"
    "}\n";

static const char* k_overlay_fs =
    "#version 330 core\n"
    "in vec2 v_px;\n"
    "flat in vec4 v_seg;\n"
    "flat in vec4 v_par;\n"
    "in vec4 v_col;\n"
    "flat in vec4 v_nb;\n"
    "uniform float u_aa;\n" // camera pixels per viewport pixel
    "out vec4 o_col;\n"
    "float dseg(vec2 p, vec2 a, vec2 b) {\n"
    "    vec2 pa = p - a, ba = b - a;\n"
    "    float h = clamp(dot(pa, ba) / max(dot(ba, ba), 1e-12), 0.0, 1.0);\n"
    "    return length(pa - ba * h);\n"
    "}\n"
    "void main() {\n"
    "    float a = 1.0;\n"
    "    if (v_par.y < 0.5) {\n"
    // Distance to the polyline near this segment: it and its two neighbours,
    // so that overlapping capsules agree on every pixel's coverage.
    "        float d = min(dseg(v_px, v_seg.xy, v_seg.zw),\n"
    "                      min(dseg(v_px, v_nb.xy, v_seg.xy), dseg(v_px, v_seg.zw, v_nb.zw)));\n"
    "        a = clamp((v_par.x - d) / u_aa + 0.5, 0.0, 1.0);\n"
    "    } else if (v_par.y < 1.5) {\n"
    "        vec2 q = (v_px - v_seg.xy) / v_seg.zw;\n"
    "        float r = length(q);\n"
    "        a = 1.0 - smoothstep(v_par.z, 1.0, r);\n"
    "    }\n"
    "    if (a <= 0.0) discard;\n"
    "    o_col = vec4(v_col.rgb, v_col.a * a);\n"
    "}\n";

// clang-format on

// ------------------------------------------------------------------ types

typedef struct overlay_vertex {
    float px[2], seg[4], par[4], col[4], nb[4];
    float z; // NDC depth, used only by depth-tested overlays (ink on a surface)
} overlay_vertex;

struct sp_renderer {
    GLuint mesh_prog, overlay_prog;
    GLint u_model_view, u_proj, u_normal, u_ortho, u_up, u_exposure, u_ambient, u_rim;
    GLint u_size, u_aa;
    GLuint overlay_vao, overlay_vbo;
    size_t overlay_vbo_bytes;
    overlay_vertex* ov;
    size_t ov_count, ov_cap;
    bool ov_oom;
    int stencil_ref; // last stencil value used by a translucent polyline
    float exposure, ambient, rim;
    // Frame state.
    sp_camera cam;
    sp_mat4 proj;
    int vw, vh;
    bool in_frame;
};

struct sp_render_mesh {
    sp_renderer* r;
    int nv, nt;
    uint32_t* tris; // nt by 3
    int* weld;      // nv: representative vertex of each position class
    float* pos;     // nv by 3
    float* nrm;     // nv by 3
    double* acc;    // nv by 3, normal accumulator
    sp_vec3 lo, hi;
    GLuint vao, vbo_pos, vbo_nrm, vbo_col, ebo;
};

struct sp_render_target {
    int w, h, samples;
    GLuint fbo_ms, rb_color_ms, rb_depth_ms;
    GLuint fbo_resolve, rb_color;
};

// ---------------------------------------------------------------- helpers

static GLuint compile(GLenum type, const char* src, const char* what, sp_error* err)
{
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[400] = {0};
        glGetShaderInfoLog(s, sizeof log - 1, NULL, log);
        for (char* c = log; *c; ++c)
            if (*c == '\n') *c = ' ';
        sp_fail(err, SP_ERR_INTERNAL, "render: %s shader: %s", what, log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

unsigned sp_gl_program(const char* vs_src, const char* fs_src, const char* what, sp_error* err)
{
    GLuint vs = compile(GL_VERTEX_SHADER, vs_src, what, err);
    if (!vs) return 0;
    GLuint fs = compile(GL_FRAGMENT_SHADER, fs_src, what, err);
    if (!fs) {
        glDeleteShader(vs);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[400] = {0};
        glGetProgramInfoLog(p, sizeof log - 1, NULL, log);
        sp_fail(err, SP_ERR_INTERNAL, "render: %s program: %s", what, log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

static void mat4_to_float(const sp_mat4* m, float out[16])
{
    for (int i = 0; i < 16; ++i)
        out[i] = (float)m->m[i];
}

// ----------------------------------------------------------------- camera

sp_mat4 sp_render_projection(const sp_camera* cam)
{
    double n = cam->znear, f = cam->zfar;
    // Orthographic depth may start behind the eye (n <= 0); perspective may not.
    bool ok = isfinite(n) && isfinite(f) && f > n && (cam->kind == SP_CAMERA_ORTHOGRAPHIC || n > 0.0);
    if (!ok) n = 0.01, f = 1000.0;
    double W = cam->width > 0 ? cam->width : 1, H = cam->height > 0 ? cam->height : 1;
    sp_mat4 P = {{0}};
    double* m = P.m; // m[col*4 + row]
    if (cam->kind == SP_CAMERA_ORTHOGRAPHIC) {
        // u = cx + s*x -> ndc_x = 2u/W - 1; v = cy - s*y -> ndc_y = 1 - 2v/H.
        m[0] = 2.0 * cam->scale / W;
        m[12] = 2.0 * cam->cx / W - 1.0;
        m[5] = 2.0 * cam->scale / H;
        m[13] = 1.0 - 2.0 * cam->cy / H;
        m[10] = -2.0 / (f - n);
        m[14] = -(f + n) / (f - n);
        m[15] = 1.0;
    } else {
        // u = cx + f*x/d with d = -z: clip_x = (2f/W) x + (1 - 2cx/W) z, w = -z.
        m[0] = 2.0 * cam->scale / W;
        m[8] = 1.0 - 2.0 * cam->cx / W;
        m[5] = 2.0 * cam->scale / H;
        m[9] = 2.0 * cam->cy / H - 1.0;
        m[10] = -(f + n) / (f - n);
        m[14] = -2.0 * f * n / (f - n);
        m[11] = -1.0;
    }
    return P;
}

void sp_render_fit_depth(sp_camera* cam, sp_vec3 lo, sp_vec3 hi)
{
    double zmin = INFINITY, zmax = -INFINITY;
    for (int i = 0; i < 8; ++i) {
        sp_vec3 p = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
        double d = -sp_mat4_point(&cam->view, p).z;
        zmin = fmin(zmin, d), zmax = fmax(zmax, d);
    }
    if (!isfinite(zmin) || !isfinite(zmax)) return;
    double pad = 0.05 * (zmax - zmin) + 1e-3 * fmax(fabs(zmax), 1.0);
    double n = zmin - pad, f = zmax + pad;
    // Why 1e-3 of far: a perspective near plane at ~0 wastes all depth precision.
    if (cam->kind == SP_CAMERA_PERSPECTIVE) n = fmax(n, 1e-3 * f);
    if (f > n) cam->znear = n, cam->zfar = f;
}

// --------------------------------------------------------------- renderer

sp_result sp_renderer_create(const sp_renderer_desc* desc, sp_renderer** out, sp_error* err)
{
    *out = NULL;
    sp_result res = SP_ERR_INTERNAL;
    sp_renderer_desc d = desc ? *desc : (sp_renderer_desc){0};
    sp_renderer* r = calloc(1, sizeof *r);
    if (!r) {
        return sp_fail(err, SP_ERR_NO_MEMORY, "render: out of memory");
    }
    r->exposure = d.exposure > 0 ? d.exposure : 1.0f;
    r->ambient = d.ambient > 0 ? d.ambient : 0.35f;
    r->rim = d.no_rim ? 0.0f : 0.45f;
    r->mesh_prog = sp_gl_program(k_mesh_vs, k_mesh_fs, "mesh", err);
    if (!r->mesh_prog) goto fail;
    r->overlay_prog = sp_gl_program(k_overlay_vs, k_overlay_fs, "overlay", err);
    if (!r->overlay_prog) goto fail;
    r->u_model_view = glGetUniformLocation(r->mesh_prog, "u_model_view");
    r->u_proj = glGetUniformLocation(r->mesh_prog, "u_proj");
    r->u_normal = glGetUniformLocation(r->mesh_prog, "u_normal");
    r->u_ortho = glGetUniformLocation(r->mesh_prog, "u_ortho");
    r->u_up = glGetUniformLocation(r->mesh_prog, "u_up");
    r->u_exposure = glGetUniformLocation(r->mesh_prog, "u_exposure");
    r->u_ambient = glGetUniformLocation(r->mesh_prog, "u_ambient");
    r->u_rim = glGetUniformLocation(r->mesh_prog, "u_rim");
    r->u_size = glGetUniformLocation(r->overlay_prog, "u_size");
    r->u_aa = glGetUniformLocation(r->overlay_prog, "u_aa");

    glGenVertexArrays(1, &r->overlay_vao);
    glGenBuffers(1, &r->overlay_vbo);
    glBindVertexArray(r->overlay_vao);
    glBindBuffer(GL_ARRAY_BUFFER, r->overlay_vbo);
    const GLsizei stride = (GLsizei)sizeof(overlay_vertex);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, (const void*)offsetof(overlay_vertex, px));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, (const void*)offsetof(overlay_vertex, seg));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride, (const void*)offsetof(overlay_vertex, par));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, stride, (const void*)offsetof(overlay_vertex, col));
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 4, GL_FLOAT, GL_FALSE, stride, (const void*)offsetof(overlay_vertex, nb));
    glEnableVertexAttribArray(5);
    glVertexAttribPointer(5, 1, GL_FLOAT, GL_FALSE, stride, (const void*)offsetof(overlay_vertex, z));
    glBindVertexArray(0);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        res = sp_fail(err, SP_ERR_INTERNAL, "render: GL error 0x%x while creating the renderer", e);
        goto fail;
    }
    *out = r;
    return SP_OK;
fail:
    sp_renderer_destroy(r);
    return res;
}

void sp_renderer_destroy(sp_renderer* r)
{
    if (!r) return;
    if (r->mesh_prog) glDeleteProgram(r->mesh_prog);
    if (r->overlay_prog) glDeleteProgram(r->overlay_prog);
    if (r->overlay_vbo) glDeleteBuffers(1, &r->overlay_vbo);
    if (r->overlay_vao) glDeleteVertexArrays(1, &r->overlay_vao);
    free(r->ov);
    free(r);
}

void sp_renderer_begin(sp_renderer* r, const sp_camera* cam, int vw, int vh)
{
    assert(r && cam);
    r->cam = *cam;
    if (r->cam.width <= 0) r->cam.width = vw > 0 ? vw : 1;
    if (r->cam.height <= 0) r->cam.height = vh > 0 ? vh : 1;
    r->vw = vw > 0 ? vw : r->cam.width;
    r->vh = vh > 0 ? vh : r->cam.height;
    r->proj = sp_render_projection(&r->cam);
    r->ov_count = 0;
    r->in_frame = true;
    glViewport(0, 0, r->vw, r->vh);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_STENCIL_TEST);
    glEnable(GL_MULTISAMPLE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
}

static bool ov_reserve(sp_renderer* r, size_t extra)
{
    if (r->ov_count + extra <= r->ov_cap) return true;
    size_t cap = r->ov_cap ? r->ov_cap : 1024;
    while (cap < r->ov_count + extra)
        cap *= 2;
    overlay_vertex* p = realloc(r->ov, cap * sizeof *p);
    if (!p) {
        r->ov_oom = true; // drop the overlay rather than crash a frame
        return false;
    }
    r->ov = p;
    r->ov_cap = cap;
    return true;
}

// Appends a quad (two triangles) with corners c (4 by 2, in order around it), all
// carrying the same primitive description; z: the corners' depths (NULL: 0).
static void ov_quad(sp_renderer* r, const float* c, const float* z, const float seg[4], const float nb[4], const float par[4],
                    const float col[4], const float* col_bottom)
{
    if (!ov_reserve(r, 6)) return;
    static const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; ++i) {
        overlay_vertex* v = &r->ov[r->ov_count++];
        int k = order[i];
        v->px[0] = c[2 * k], v->px[1] = c[2 * k + 1];
        v->z = z ? z[k] : 0.0f;
        memcpy(v->seg, seg, sizeof v->seg);
        memcpy(v->nb, nb ? nb : seg, sizeof v->nb);
        memcpy(v->par, par, sizeof v->par);
        // Corners 2 and 3 are the bottom ones for the gradient.
        memcpy(v->col, (col_bottom && k >= 2) ? col_bottom : col, sizeof v->col);
    }
}

// once: every pixel is blended by the first capsule that reaches it (the
// stencil marks it), so a polyline does not darken or bead where its
// capsules overlap at the joins. That first capsule's coverage is already
// the whole polyline's there: the shader measures the distance to the
// neighbouring segments too.
static void ov_flush_ex(sp_renderer* r, bool once, bool depth)
{
    if (!r->ov_count) return;
    if (once) {
        if (r->stencil_ref == 255) {
            glStencilMask(0xFF);
            glClear(GL_STENCIL_BUFFER_BIT);
            r->stencil_ref = 0;
        }
        ++r->stencil_ref;
        glEnable(GL_STENCIL_TEST);
        glStencilMask(0xFF);
        glStencilFunc(GL_NOTEQUAL, r->stencil_ref, 0xFF);
    }
    glUseProgram(r->overlay_prog);
    glUniform2f(r->u_size, (float)r->cam.width, (float)r->cam.height);
    glUniform1f(r->u_aa, (float)r->cam.width / (float)r->vw);
    glBindVertexArray(r->overlay_vao);
    glBindBuffer(GL_ARRAY_BUFFER, r->overlay_vbo);
    size_t bytes = r->ov_count * sizeof(overlay_vertex);
    if (bytes > r->overlay_vbo_bytes) {
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes, r->ov, GL_STREAM_DRAW);
        r->overlay_vbo_bytes = bytes;
    } else {
        // Why orphan first: the driver may still read last frame's data.
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)r->overlay_vbo_bytes, NULL, GL_STREAM_DRAW);
        glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)bytes, r->ov);
    }
    if (depth) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LEQUAL);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    if (once) glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)r->ov_count);
    if (once) glDisable(GL_STENCIL_TEST);
    if (depth) glDisable(GL_DEPTH_TEST);
    glBindVertexArray(0);
    glDepthMask(GL_TRUE);
    r->ov_count = 0;
}

static void ov_flush(sp_renderer* r)
{
    ov_flush_ex(r, false, false);
}

void sp_renderer_clear(sp_renderer* r, const float top[4], const float bottom[4])
{
    assert(r && r->in_frame && top);
    ov_flush(r);
    glClearColor(top[0], top[1], top[2], top[3]);
    glClearDepth(1.0);
    glClearStencil(0);
    glStencilMask(0xFF);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    r->stencil_ref = 0;
    if (!bottom) return;
    float W = (float)r->cam.width, H = (float)r->cam.height;
    const float c[8] = {0, 0, W, 0, W, H, 0, H};
    const float seg[4] = {0}, par[4] = {0, 2, 0, 0};
    ov_quad(r, c, NULL, seg, NULL, par, top, bottom);
    ov_flush(r);
}

void sp_renderer_end(sp_renderer* r)
{
    assert(r && r->in_frame);
    ov_flush(r);
    glUseProgram(0);
    r->in_frame = false;
}

// ------------------------------------------------------------------ overlays

// Segment a-b of a polyline whose neighbouring points are p0 (before a) and
// p3 (after b); p0 == a and p3 == b at the ends. z: the depths of a and b (NULL: 0).
static void capsule(sp_renderer* r, sp_vec2 p0, sp_vec2 a, sp_vec2 b, sp_vec2 p3, const float* z, float radius,
                    const float rgba[4])
{
    // The quad covers the capsule plus a feather of two viewport pixels.
    double pad = radius + 2.0 * (double)r->cam.width / (double)r->vw;
    sp_vec2 d = sp_v2_sub(b, a);
    double len = sp_v2_len(d);
    sp_vec2 t = len > 1e-9 ? sp_v2_scale(d, 1.0 / len) : (sp_vec2){1, 0};
    sp_vec2 nrm = {-t.y, t.x};
    sp_vec2 a0 = sp_v2_sub(a, sp_v2_scale(t, pad)), b0 = sp_v2_add(b, sp_v2_scale(t, pad));
    sp_vec2 off = sp_v2_scale(nrm, pad);
    sp_vec2 q[4] = {sp_v2_add(a0, off), sp_v2_add(b0, off), sp_v2_sub(b0, off), sp_v2_sub(a0, off)};
    float c[8];
    for (int i = 0; i < 4; ++i)
        c[2 * i] = (float)q[i].x, c[2 * i + 1] = (float)q[i].y;
    const float seg[4] = {(float)a.x, (float)a.y, (float)b.x, (float)b.y};
    const float nb[4] = {(float)p0.x, (float)p0.y, (float)p3.x, (float)p3.y};
    const float par[4] = {radius, 0, 0, 0};
    const float zq[4] = {z ? z[0] : 0, z ? z[1] : 0, z ? z[1] : 0, z ? z[0] : 0}; // corners 0, 3 at a; 1, 2 at b
    ov_quad(r, c, zq, seg, nb, par, rgba, NULL);
}

// A polyline; z (NULL: none) gives each point's depth, and then it is
// depth-tested against the meshes drawn before it.
static void polyline(sp_renderer* r, const sp_vec2* px, const float* z, int n, bool closed, float width, const float rgba[4])
{
    if (n <= 0 || !(width > 0)) return;
    float radius = 0.5f * width;
    // Keep only points at least a capsule's reach apart (the last point
    // always): with shorter segments a pixel could be nearer to a segment two
    // or more steps away than to the neighbours the shader looks at. The
    // shape changes by less than the line's own width.
    double reach = radius + 2.0 * (double)r->cam.width / (double)r->vw;
    sp_vec2 stack[256];
    float zstack[256];
    sp_vec2* q = n <= 256 ? stack : malloc(sizeof(sp_vec2) * (size_t)n);
    float* qz = n <= 256 ? zstack : malloc(sizeof(float) * (size_t)n);
    if (!q || !qz) {
        if (q != stack) free(q);
        if (qz != zstack) free(qz);
        return;
    }
    int m = 0;
    for (int i = 0; i < n; ++i) {
        if (!sp_v2_is_valid(px[i]) || (z && !isfinite(z[i]))) continue;
        if (m > 0 && sp_v2_len(sp_v2_sub(px[i], q[m - 1])) < reach) {
            if (i == n - 1 && m > 1) q[m - 1] = px[i], qz[m - 1] = z ? z[i] : 0; // keep the true end
            continue;
        }
        qz[m] = z ? z[i] : 0;
        q[m++] = px[i];
    }
    if (m == 1 && n > 1) {
        // Everything within one reach: a short dash from the first to the last valid point.
        for (int i = n - 1; i > 0; --i)
            if (sp_v2_is_valid(px[i]) && !(z && !isfinite(z[i]))) {
                qz[m] = z ? z[i] : 0;
                q[m++] = px[i];
                break;
            }
    }
    const float* zz = z ? qz : NULL;
    if (m == 1 && !z) capsule(r, q[0], q[0], q[0], q[0], NULL, radius, rgba);
    if (m == 1 && z) {
        ov_flush(r);
        capsule(r, q[0], q[0], q[0], q[0], (const float[2]){qz[0], qz[0]}, radius, rgba);
        ov_flush_ex(r, false, true);
    }
    if (m >= 2) {
        ov_flush(r); // this polyline gets its own stencil value
        bool loop = closed && m > 2;
        int segs = loop ? m : m - 1;
        for (int i = 0; i < segs; ++i) {
            int ia = i, ib = (i + 1) % m;
            sp_vec2 a = q[ia], b = q[ib];
            sp_vec2 p0 = (i > 0 || loop) ? q[(i + m - 1) % m] : a;
            sp_vec2 p3 = (i + 2 < m || loop) ? q[(i + 2) % m] : b;
            capsule(r, p0, a, b, p3, zz ? (const float[2]){zz[ia], zz[ib]} : NULL, radius, rgba);
        }
        ov_flush_ex(r, true, z != NULL);
    }
    if (q != stack) free(q);
    if (qz != zstack) free(qz);
}

void sp_renderer_draw_polyline(sp_renderer* r, const sp_vec2* px, int n, bool closed, float width, const float rgba[4])
{
    assert(r && r->in_frame && rgba && (px || n == 0));
    polyline(r, px, NULL, n, closed, width, rgba);
}

void sp_renderer_draw_dots(sp_renderer* r, const sp_vec2* px, int n, float radius, const float rgba[4])
{
    assert(r && r->in_frame && rgba && (px || n == 0));
    for (int i = 0; i < n; ++i)
        if (sp_v2_is_valid(px[i])) capsule(r, px[i], px[i], px[i], px[i], NULL, radius, rgba);
}

void sp_renderer_draw_curve3d(sp_renderer* r, const double* xyz, int n, bool closed, float width, const float rgba[4])
{
    assert(r && r->in_frame && (xyz || n == 0));
    if (n <= 0) return;
    sp_vec2 stack[256];
    sp_vec2* px = n <= 256 ? stack : malloc(sizeof(sp_vec2) * (size_t)n);
    if (!px) return;
    for (int i = 0; i < n; ++i)
        px[i] = sp_camera_project(&r->cam, sp_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
    sp_renderer_draw_polyline(r, px, n, closed, width, rgba);
    if (px != stack) free(px);
}

void sp_renderer_draw_curve3d_facing(sp_renderer* r, const double* xyz, const double* normal, int n, float width,
                                     const float rgba[4])
{
    assert(r && r->in_frame && ((xyz && normal) || n == 0));
    if (n <= 0) return;
    sp_vec2 stack[256];
    float zstack[256];
    sp_vec2* px = n <= 256 ? stack : malloc(sizeof(sp_vec2) * (size_t)n);
    float* z = n <= 256 ? zstack : malloc(sizeof(float) * (size_t)n);
    if (!px || !z) {
        if (px != stack) free(px);
        if (z != zstack) free(z);
        return;
    }
    // Lifted towards the camera by more than the line's own width before the
    // depth test: on a curved surface the ink must not sink into it, and a
    // part in front of it still covers it.
    double lift_px = fmax(4.0, 1.5 * (double)width);
    const double* P = r->proj.m;
    for (int i = 0; i < n;) {
        int j = i;
        for (; j < n; ++j) {
            sp_vec3 p = {xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]};
            sp_vec3 dir = sp_camera_view_dir(&r->cam, p);
            sp_vec3 nrm = {normal[3 * j], normal[3 * j + 1], normal[3 * j + 2]};
            bool air = nrm.x == 0 && nrm.y == 0 && nrm.z == 0; // no surface under it: seen from every side
            if (!air && !(sp_v3_dot(dir, nrm) < 0)) break;
            sp_vec3 c = sp_mat4_point(&r->cam.view, p);
            double per_px = r->cam.kind == SP_CAMERA_ORTHOGRAPHIC ? 1.0 / r->cam.scale : fabs(c.z) / r->cam.scale;
            sp_vec3 q = sp_v3_sub(p, sp_v3_scale(dir, lift_px * per_px));
            sp_vec3 cq = sp_mat4_point(&r->cam.view, q);
            double w = P[11] * cq.z + P[15];
            px[j - i] = sp_camera_project(&r->cam, p);
            z[j - i] = (float)((P[10] * cq.z + P[14]) / w);
        }
        if (j > i) polyline(r, px, z, j - i, false, width, rgba);
        i = j + 1;
    }
    if (px != stack) free(px);
    if (z != zstack) free(z);
}

void sp_renderer_draw_abstraction(sp_renderer* r, const sp_abstraction* a, const double* xyz, float width, const float rgba[4])
{
    assert(r && a && (xyz || a->point_count == 0));
    for (int c = 0; c < a->curve_count; ++c) {
        const sp_curve* cv = &a->curves[c];
        if (cv->first_point < 0 || cv->point_count <= 0 || cv->first_point + cv->point_count > a->point_count) continue;
        sp_renderer_draw_curve3d(r, xyz + 3 * (size_t)cv->first_point, cv->point_count, cv->closed, width, rgba);
    }
}

void sp_renderer_draw_ground_shadow(sp_renderer* r, sp_vec3 lo, sp_vec3 hi, float opacity)
{
    assert(r && r->in_frame);
    if (!sp_v3_is_valid(lo) || !sp_v3_is_valid(hi)) return;
    if (!(opacity > 0)) opacity = 0.35f;
    // The ground ellipse (world +Y up) under the box, slightly larger than
    // its footprint; project a ring of it and take its screen-space box.
    sp_vec3 c = {0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)};
    double rx = 0.5 * (hi.x - lo.x), rz = 0.5 * (hi.z - lo.z);
    double rmax = fmax(rx, rz);
    rx = fmax(rx, 0.35 * rmax) * 0.9, rz = fmax(rz, 0.35 * rmax) * 0.9;
    double ulo = INFINITY, uhi = -INFINITY, vlo = INFINITY, vhi = -INFINITY;
    for (int i = 0; i < 32; ++i) {
        double t = 2.0 * 3.14159265358979323846 * i / 32;
        sp_vec2 p = sp_camera_project(&r->cam, sp_v3(c.x + rx * cos(t), c.y, c.z + rz * sin(t)));
        ulo = fmin(ulo, p.x), uhi = fmax(uhi, p.x), vlo = fmin(vlo, p.y), vhi = fmax(vhi, p.y);
    }
    sp_vec2 centre = sp_camera_project(&r->cam, c);
    double ex = 0.5 * (uhi - ulo);
    double ey = 0.5 * (vhi - vlo);
    // Seen edge-on the ellipse collapses to a line: keep it a soft oval.
    ey = fmax(ey, 0.12 * ex);
    if (!(ex > 0.5) || !isfinite(ex) || !isfinite(ey)) return;
    float pad = 1.0f;
    float x0 = (float)(centre.x - ex) - pad, x1 = (float)(centre.x + ex) + pad;
    float y0 = (float)(centre.y - ey) - pad, y1 = (float)(centre.y + ey) + pad;
    const float q[8] = {x0, y0, x1, y0, x1, y1, x0, y1};
    const float seg[4] = {(float)centre.x, (float)centre.y, (float)ex, (float)ey};
    const float par[4] = {0, 1, 0.15f, 0};
    const float col[4] = {0.1f, 0.1f, 0.14f, opacity};
    ov_quad(r, q, NULL, seg, NULL, par, col, NULL);
    // Why flush now: the shadow belongs behind the meshes drawn after it.
    ov_flush(r);
}

// -------------------------------------------------------------------- meshes

static const float* g_sort_pos; // qsort has no context argument in C11

static int cmp_pos(const void* a, const void* b)
{
    const float* p = g_sort_pos + 3 * (size_t) * (const int*)a;
    const float* q = g_sort_pos + 3 * (size_t) * (const int*)b;
    for (int k = 0; k < 3; ++k)
        if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
    int ia = *(const int*)a, ib = *(const int*)b;
    return (ia > ib) - (ia < ib);
}

// Vertices that share a rest position (UV or colour seams) share a normal,
// so seams do not show as creases.
static bool build_weld(sp_render_mesh* m)
{
    int* order = malloc(sizeof(int) * (size_t)m->nv);
    if (!order) return false;
    for (int i = 0; i < m->nv; ++i)
        order[i] = i;
    g_sort_pos = m->pos;
    qsort(order, (size_t)m->nv, sizeof(int), cmp_pos);
    g_sort_pos = NULL;
    for (int i = 0; i < m->nv;) {
        int j = i;
        const float* p = m->pos + 3 * (size_t)order[i];
        while (j < m->nv && !memcmp(p, m->pos + 3 * (size_t)order[j], 3 * sizeof(float)))
            m->weld[order[j++]] = order[i];
        i = j;
    }
    free(order);
    return true;
}

static void compute_normals(sp_render_mesh* m)
{
    memset(m->acc, 0, sizeof(double) * 3 * (size_t)m->nv);
    for (int t = 0; t < m->nt; ++t) {
        const uint32_t* tr = m->tris + 3 * (size_t)t;
        const float *a = m->pos + 3 * (size_t)tr[0], *b = m->pos + 3 * (size_t)tr[1], *c = m->pos + 3 * (size_t)tr[2];
        sp_vec3 e1 = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2 = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        sp_vec3 n = sp_v3_cross(e1, e2); // length = 2 * area: area weighting for free
        for (int k = 0; k < 3; ++k) {
            double* acc = m->acc + 3 * (size_t)m->weld[tr[k]];
            acc[0] += n.x, acc[1] += n.y, acc[2] += n.z;
        }
    }
    for (int i = 0; i < m->nv; ++i) {
        const double* acc = m->acc + 3 * (size_t)m->weld[i];
        double l = sqrt(acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2]);
        float* n = m->nrm + 3 * (size_t)i;
        if (l > 0)
            n[0] = (float)(acc[0] / l), n[1] = (float)(acc[1] / l), n[2] = (float)(acc[2] / l);
        else
            n[0] = 0, n[1] = 0, n[2] = 1;
    }
}

static void load_positions(sp_render_mesh* m, const double* xyz)
{
    sp_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < m->nv; ++i) {
        const double* p = xyz + 3 * (size_t)i;
        m->pos[3 * i] = (float)p[0], m->pos[3 * i + 1] = (float)p[1], m->pos[3 * i + 2] = (float)p[2];
        lo.x = fmin(lo.x, p[0]), lo.y = fmin(lo.y, p[1]), lo.z = fmin(lo.z, p[2]);
        hi.x = fmax(hi.x, p[0]), hi.y = fmax(hi.y, p[1]), hi.z = fmax(hi.z, p[2]);
    }
    if (m->nv == 0) lo = hi = (sp_vec3){0, 0, 0};
    m->lo = lo, m->hi = hi;
}

static void upload_dynamic(sp_render_mesh* m)
{
    GLsizeiptr bytes = (GLsizeiptr)(sizeof(float) * 3 * (size_t)m->nv);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo_pos);
    glBufferData(GL_ARRAY_BUFFER, bytes, m->pos, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo_nrm);
    glBufferData(GL_ARRAY_BUFFER, bytes, m->nrm, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

sp_result sp_render_mesh_create(sp_renderer* r, const sp_mesh_desc* d, sp_render_mesh** out, sp_error* err)
{
    *out = NULL;
    assert(r && d);
    if (d->vertex_count < 0 || d->triangle_count < 0 || (d->vertex_count > 0 && !d->positions) ||
        (d->triangle_count > 0 && !d->triangles)) {
        return sp_fail(err, SP_ERR_INVALID, "render: mesh description is incomplete");
    }
    for (int i = 0; i < 3 * d->vertex_count; ++i)
        if (!isfinite(d->positions[i])) {
            return sp_fail(err, SP_ERR_INVALID, "render: vertex %d has a non-finite position", i / 3);
        }
    for (int i = 0; i < 3 * d->triangle_count; ++i)
        if (d->triangles[i] >= (uint32_t)d->vertex_count) {
            return sp_fail(err, SP_ERR_INVALID, "render: triangle %d refers to vertex %u of %d", i / 3, d->triangles[i],
                           d->vertex_count);
        }
    sp_render_mesh* m = calloc(1, sizeof *m);
    size_t nv = (size_t)d->vertex_count, nt = (size_t)d->triangle_count;
    float* col = NULL;
    if (m) {
        m->r = r;
        m->nv = d->vertex_count;
        m->nt = d->triangle_count;
        m->tris = malloc(sizeof(uint32_t) * 3 * (nt ? nt : 1));
        m->weld = malloc(sizeof(int) * (nv ? nv : 1));
        m->pos = malloc(sizeof(float) * 3 * (nv ? nv : 1));
        m->nrm = malloc(sizeof(float) * 3 * (nv ? nv : 1));
        m->acc = malloc(sizeof(double) * 3 * (nv ? nv : 1));
        col = malloc(sizeof(float) * 4 * (nv ? nv : 1));
    }
    if (!m || !m->tris || !m->weld || !m->pos || !m->nrm || !m->acc || !col) {
        free(col);
        sp_render_mesh_destroy(m);
        return sp_fail(err, SP_ERR_NO_MEMORY, "render: out of memory for a %d-vertex mesh", d->vertex_count);
    }
    if (nt) memcpy(m->tris, d->triangles, sizeof(uint32_t) * 3 * nt);
    load_positions(m, d->positions);
    if (!build_weld(m)) {
        free(col);
        sp_render_mesh_destroy(m);
        return sp_fail(err, SP_ERR_NO_MEMORY, "render: out of memory");
    }
    if (d->normals)
        memcpy(m->nrm, d->normals, sizeof(float) * 3 * nv);
    else
        compute_normals(m);
    float base[4] = {d->base_color[0], d->base_color[1], d->base_color[2], d->base_color[3]};
    if (base[0] == 0 && base[1] == 0 && base[2] == 0 && base[3] == 0) base[0] = base[1] = base[2] = 0.6f, base[3] = 1;
    for (size_t i = 0; i < nv; ++i)
        memcpy(col + 4 * i, d->colors ? d->colors + 4 * i : base, 4 * sizeof(float));

    glGenVertexArrays(1, &m->vao);
    glGenBuffers(1, &m->vbo_pos);
    glGenBuffers(1, &m->vbo_nrm);
    glGenBuffers(1, &m->vbo_col);
    glGenBuffers(1, &m->ebo);
    glBindVertexArray(m->vao);
    upload_dynamic(m);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo_pos);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo_nrm);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo_col);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 4 * nv), col, GL_STATIC_DRAW);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, 0, NULL);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(uint32_t) * 3 * nt), m->tris, GL_STATIC_DRAW);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    free(col);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        sp_render_mesh_destroy(m);
        return sp_fail(err, SP_ERR_INTERNAL, "render: GL error 0x%x while uploading a mesh", e);
    }
    *out = m;
    return SP_OK;
}

void sp_render_mesh_update(sp_render_mesh* m, const double* positions, const float* normals)
{
    assert(m && (positions || m->nv == 0));
    load_positions(m, positions);
    if (normals)
        memcpy(m->nrm, normals, sizeof(float) * 3 * (size_t)m->nv);
    else
        compute_normals(m);
    upload_dynamic(m);
}

void sp_render_mesh_bounds(const sp_render_mesh* m, sp_vec3* lo, sp_vec3* hi)
{
    *lo = m->lo;
    *hi = m->hi;
}

void sp_render_mesh_destroy(sp_render_mesh* m)
{
    if (!m) return;
    if (m->vao) glDeleteVertexArrays(1, &m->vao);
    GLuint bufs[4] = {m->vbo_pos, m->vbo_nrm, m->vbo_col, m->ebo};
    for (int i = 0; i < 4; ++i)
        if (bufs[i]) glDeleteBuffers(1, &bufs[i]);
    free(m->tris);
    free(m->weld);
    free(m->pos);
    free(m->nrm);
    free(m->acc);
    free(m);
}

void sp_renderer_draw_mesh(sp_renderer* r, const sp_render_mesh* m, const sp_mat4* model)
{
    assert(r && r->in_frame && m);
    ov_flush(r); // overlays keep call order relative to meshes
    if (!m->nt) return;
    sp_mat4 mv = model ? sp_mat4_mul(&r->cam.view, model) : r->cam.view;
    // Normal matrix: inverse transpose of the linear part of model-view.
    sp_mat4 inv;
    sp_mat4_inverse(&mv, &inv);
    float nm[9];
    for (int c = 0; c < 3; ++c)
        for (int rr = 0; rr < 3; ++rr)
            nm[c * 3 + rr] = (float)inv.m[rr * 4 + c];
    float fmv[16], fp[16];
    mat4_to_float(&mv, fmv);
    mat4_to_float(&r->proj, fp);
    // World up (+Y) in camera space, for the hemisphere ambient.
    sp_vec3 up = sp_v3_norm(sp_mat4_dir(&r->cam.view, sp_v3(0, 1, 0)));

    glUseProgram(r->mesh_prog);
    glUniformMatrix4fv(r->u_model_view, 1, GL_FALSE, fmv);
    glUniformMatrix4fv(r->u_proj, 1, GL_FALSE, fp);
    glUniformMatrix3fv(r->u_normal, 1, GL_FALSE, nm);
    glUniform1i(r->u_ortho, r->cam.kind == SP_CAMERA_ORTHOGRAPHIC);
    glUniform3f(r->u_up, (float)up.x, (float)up.y, (float)up.z);
    glUniform1f(r->u_exposure, r->exposure);
    glUniform1f(r->u_ambient, r->ambient);
    glUniform1f(r->u_rim, r->rim);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glBindVertexArray(m->vao);
    glDrawElements(GL_TRIANGLES, 3 * m->nt, GL_UNSIGNED_INT, NULL);
    glBindVertexArray(0);
}

// ------------------------------------------------------------ render target

sp_result sp_render_target_create(int width, int height, int samples, sp_render_target** out, sp_error* err)
{
    *out = NULL;
    if (width <= 0 || height <= 0) {
        return sp_fail(err, SP_ERR_INVALID, "render: bad target size %dx%d", width, height);
    }
    GLint max_rb = 0, max_samples = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
    if (width > max_rb || height > max_rb) {
        return sp_fail(err, SP_ERR_UNSUPPORTED, "render: %dx%d exceeds the GL limit of %d pixels", width, height, max_rb);
    }
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    if (samples <= 0) samples = 4;
    if (samples > max_samples) samples = max_samples;
    sp_render_target* t = calloc(1, sizeof *t);
    if (!t) {
        return sp_fail(err, SP_ERR_NO_MEMORY, "render: out of memory");
    }
    t->w = width, t->h = height, t->samples = samples;
    glGenFramebuffers(1, &t->fbo_ms);
    glGenRenderbuffers(1, &t->rb_color_ms);
    glGenRenderbuffers(1, &t->rb_depth_ms);
    glBindRenderbuffer(GL_RENDERBUFFER, t->rb_color_ms);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, t->rb_depth_ms);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH24_STENCIL8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_ms);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, t->rb_color_ms);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, t->rb_depth_ms);
    GLenum s1 = glCheckFramebufferStatus(GL_FRAMEBUFFER);

    glGenFramebuffers(1, &t->fbo_resolve);
    glGenRenderbuffers(1, &t->rb_color);
    glBindRenderbuffer(GL_RENDERBUFFER, t->rb_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_resolve);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, t->rb_color);
    GLenum s2 = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_ms);
    if (s1 != GL_FRAMEBUFFER_COMPLETE || s2 != GL_FRAMEBUFFER_COMPLETE) {
        sp_render_target_destroy(t);
        return sp_fail(err, SP_ERR_UNSUPPORTED, "render: offscreen framebuffer %dx%d (%d samples) is incomplete (0x%x, 0x%x)",
                       width, height, samples, s1, s2);
    }
    *out = t;
    return SP_OK;
}

void sp_render_target_destroy(sp_render_target* t)
{
    if (!t) return;
    GLint bound = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &bound);
    if ((GLuint)bound == t->fbo_ms || (GLuint)bound == t->fbo_resolve) glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GLuint fbos[2] = {t->fbo_ms, t->fbo_resolve};
    GLuint rbs[3] = {t->rb_color_ms, t->rb_depth_ms, t->rb_color};
    glDeleteFramebuffers(2, fbos);
    glDeleteRenderbuffers(3, rbs);
    free(t);
}

void sp_render_target_bind(const sp_render_target* t)
{
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_ms);
    glViewport(0, 0, t->w, t->h);
}

sp_result sp_render_target_read(const sp_render_target* t, sp_image* img, sp_error* err)
{
    assert(t && img);
    if (img->width != t->w || img->height != t->h || !img->rgba)
        if (sp_image_alloc(img, t->w, t->h) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "render: out of memory");
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_ms);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, t->fbo_resolve);
    glBlitFramebuffer(0, 0, t->w, t->h, 0, 0, t->w, t->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_resolve);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, t->w, t->h, GL_RGBA, GL_UNSIGNED_BYTE, img->rgba);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_ms);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) return sp_fail(err, SP_ERR_INTERNAL, "render: GL error 0x%x while reading pixels", e);
    sp_image_flip_rows(img); // GL rows are bottom-up
    return SP_OK;
}
