// test_render: the headless renderer draws where sp_camera_project says.
//
// A bending 3-joint tube (the shared fixture rig) is posed, rendered
// offscreen through EGL, read back and compared with the projection of its
// vertices; overlays must show their colours where they were drawn. No GL
// context is a failure, not a skip: EGL (Mesa) is present here and in CI.
#include <stdint.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "fixtures.h"
#include "sp/headless.h"
#include "sp/image.h"
#include "sp/render.h"
#include "sp/sketch_sheet.h"
#include "test.h"

enum { W = 320, H = 240 };
static const float k_bg[4] = {1.0f, 1.0f, 1.0f, 1.0f};

typedef struct scene {
    sp_rig rig;
    double* p;
    double* xyz;   // vertex_count by 3
    double* stick; // stick abstraction points by 3
    sp_vec3 lo, hi;
} scene;

static sp_headless* g_gl;
static sp_renderer* g_r;

// Every test needs the context; creating it once keeps the suite fast.
static void need_gl(void)
{
    if (!g_gl) {
        sp_error err = {0};
        sp_headless_create(&g_gl, &err);
        if (!g_gl) fprintf(stderr, "  cannot create a headless OpenGL context: %s\n", err.text);
        ENSURE(g_gl != NULL);
        sp_renderer_create(&(sp_renderer_desc){0}, &g_r, &err);
        if (!g_r) fprintf(stderr, "  %s\n", err.text);
        ENSURE(g_r != NULL);
    }
}

static void scene_make(scene* s, double bend)
{
    memset(s, 0, sizeof *s);
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 3, .rings_per_bone = 8, .ring_vertices = 16, .seed = 3}, &s->rig);
    s->p = calloc((size_t)s->rig.param_count, sizeof(double));
    sp_rig_defaults(&s->rig, s->p);
    // Bend the middle and last joints about their z axes.
    s->p[sp_rig_find_param(&s->rig, "j1.rz")] = bend;
    s->p[sp_rig_find_param(&s->rig, "j2.rz")] = 0.5 * bend;
    s->p[sp_rig_find_param(&s->rig, "j2.rx")] = 0.3;
    s->xyz = malloc(sizeof(double) * 3 * (size_t)s->rig.vertex_count);
    const sp_abstraction* a = &s->rig.abstractions[0];
    s->stick = malloc(sizeof(double) * 3 * (size_t)a->point_count);
    sp_rig_eval* ev;
    sp_rig_eval_create(&s->rig, &ev, NULL);
    sp_rig_eval_update(ev, s->p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(&s->rig), s->xyz);
    sp_rig_eval_abstraction(ev, a, s->xyz, s->stick);
    sp_rig_eval_destroy(ev);
    sp_bounds(s->xyz, s->rig.vertex_count, &s->lo, &s->hi);
}

static void scene_free(scene* s)
{
    sp_rig_free(&s->rig);
    free(s->p);
    free(s->xyz);
    free(s->stick);
}

static sp_render_mesh* scene_mesh(const scene* s)
{
    sp_error err = {0};
    sp_render_mesh* m;
    sp_render_mesh_create(g_r,
                          &(sp_mesh_desc){.vertex_count = s->rig.vertex_count,
                                          .positions = s->xyz,
                                          .base_color = {0.8f, 0.3f, 0.25f, 1.0f},
                                          .triangle_count = s->rig.triangle_count,
                                          .triangles = s->rig.triangles},
                          &m, &err);
    if (!m) fprintf(stderr, "  %s\n", err.text);
    ENSURE(m != NULL);
    return m;
}

static bool is_bg(const sp_image* img, int x, int y)
{
    const uint8_t* p = sp_image_at(img, x, y);
    int d = 0;
    for (int k = 0; k < 3; ++k)
        d += abs((int)p[k] - (int)(k_bg[k] * 255.0f + 0.5f));
    return d < 24;
}

// Bounding box of non-background pixels; false if there are none.
static bool coverage_box(const sp_image* img, int box[4])
{
    box[0] = img->width, box[1] = img->height, box[2] = -1, box[3] = -1;
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x)
            if (!is_bg(img, x, y)) {
                if (x < box[0]) box[0] = x;
                if (y < box[1]) box[1] = y;
                if (x > box[2]) box[2] = x;
                if (y > box[3]) box[3] = y;
            }
    return box[2] >= 0;
}

static void projected_box(const sp_camera* cam, const double* xyz, int n, double box[4])
{
    box[0] = box[1] = INFINITY, box[2] = box[3] = -INFINITY;
    for (int i = 0; i < n; ++i) {
        sp_vec2 u = sp_camera_project(cam, sp_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
        box[0] = fmin(box[0], u.x), box[1] = fmin(box[1], u.y);
        box[2] = fmax(box[2], u.x), box[3] = fmax(box[3], u.y);
    }
}

// Pixel x covers [x, x+1): the box of covered pixels is the floor of the projected box.
static void ensure_boxes_match(const sp_image* img, const double pbox[4], double px_per_cam)
{
    int box[4];
    ENSURE(coverage_box(img, box));
    printf("  covered [%d %d]-[%d %d], projected [%.2f %.2f]-[%.2f %.2f] (x%.1f)\n", box[0], box[1], box[2], box[3], pbox[0],
           pbox[1], pbox[2], pbox[3], px_per_cam);
    for (int k = 0; k < 4; ++k)
        ENSURE_NEAR(box[k], floor(pbox[k] * px_per_cam), 2.0);
}

// An offscreen target of w x h pixels (fails the running test without one).
static sp_render_target* new_target(int w, int h)
{
    sp_error err = {0};
    sp_render_target* t;
    sp_render_target_create(w, h, 0, &t, &err);
    ENSURE(t != NULL);
    return t;
}

static void render_scene(const scene* s, sp_render_mesh* m, const sp_camera* cam, sp_render_target* t, int vw, int vh,
                         bool with_stick, sp_image* img)
{
    sp_error err = {0};
    sp_render_target_bind(t);
    sp_renderer_begin(g_r, cam, vw, vh);
    sp_renderer_clear(g_r, k_bg, NULL);
    sp_renderer_draw_mesh(g_r, m, NULL);
    if (with_stick) sp_renderer_draw_abstraction(g_r, &s->rig.abstractions[0], s->stick, 3.0f, SP_COLOR_ABSTRACTION);
    sp_renderer_end(g_r);
    sp_result rc = sp_render_target_read(t, img, &err);
    if (rc != SP_OK) fprintf(stderr, "  %s\n", err.text);
    ENSURE(rc == SP_OK);
}

static void save_for_people(const sp_image* img, const char* name)
{
    sp_error err = {0};
    const char* path = sp_test_keep_path(name);
    if (sp_image_write_png(img, path, &err) == SP_OK) printf("  wrote %s\n", path);
}

static void check_mesh_alignment(sp_camera_kind kind, const char* png)
{
    need_gl();
    scene s;
    scene_make(&s, 0.9);
    sp_camera cam = sp_camera_frame(kind, s.lo, s.hi, sp_v3(0, 0, -1), sp_v3(0, 1, 0), W, H);
    sp_render_target* t = new_target(W, H);
    sp_render_mesh* m = scene_mesh(&s);
    sp_image img = {0};
    render_scene(&s, m, &cam, t, W, H, false, &img);
    save_for_people(&img, png);

    // Not blank, and smooth-shaded: the covered pixels vary in brightness.
    int covered = 0, lmin = 255, lmax = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (!is_bg(&img, x, y)) {
                const uint8_t* p = sp_image_at(&img, x, y);
                int l = (p[0] + p[1] + p[2]) / 3;
                ++covered, lmin = l < lmin ? l : lmin, lmax = l > lmax ? l : lmax;
            }
    printf("  %d covered pixels, luminance %d..%d\n", covered, lmin, lmax);
    ENSURE(covered > W * H / 30);
    ENSURE(lmax - lmin > 40);

    double pbox[4];
    projected_box(&cam, s.xyz, s.rig.vertex_count, pbox);
    ensure_boxes_match(&img, pbox, 1.0);

    // Every projected vertex lands on a covered pixel (or next to one).
    for (int i = 0; i < s.rig.vertex_count; i += 7) {
        sp_vec2 u = sp_camera_project(&cam, sp_v3(s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]));
        int x = (int)floor(u.x), y = (int)floor(u.y), hit = 0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                if (x + dx >= 0 && y + dy >= 0 && x + dx < W && y + dy < H) hit |= !is_bg(&img, x + dx, y + dy);
        ENSURE(hit);
    }

    // Reuse the uploaded mesh for a new pose: the coverage follows.
    scene s2;
    scene_make(&s2, -0.8);
    sp_render_mesh_update(m, s2.xyz, NULL);
    render_scene(&s2, m, &cam, t, W, H, false, &img);
    projected_box(&cam, s2.xyz, s2.rig.vertex_count, pbox);
    ensure_boxes_match(&img, pbox, 1.0);
    scene_free(&s2);

    sp_image_free(&img);
    sp_render_mesh_destroy(m);
    sp_render_target_destroy(t);
    scene_free(&s);
}

static void test_mesh_orthographic(void)
{
    check_mesh_alignment(SP_CAMERA_ORTHOGRAPHIC, "render_ortho.png");
}
static void test_mesh_perspective(void)
{
    check_mesh_alignment(SP_CAMERA_PERSPECTIVE, "render_persp.png");
}

// A viewport twice the camera canvas (a HiDPI window): everything scales by 2.
static void test_viewport_scale(void)
{
    need_gl();
    scene s;
    scene_make(&s, 0.6);
    sp_camera cam = sp_camera_frame(SP_CAMERA_PERSPECTIVE, s.lo, s.hi, sp_v3(0.3, -0.2, -1), sp_v3(0, 1, 0), W, H);
    sp_render_target* t = new_target(2 * W, 2 * H);
    sp_render_mesh* m = scene_mesh(&s);
    sp_image img = {0};
    render_scene(&s, m, &cam, t, 2 * W, 2 * H, false, &img);
    ENSURE(img.width == 2 * W && img.height == 2 * H);
    double pbox[4];
    projected_box(&cam, s.xyz, s.rig.vertex_count, pbox);
    ensure_boxes_match(&img, pbox, 2.0);
    sp_image_free(&img);
    sp_render_mesh_destroy(m);
    sp_render_target_destroy(t);
    scene_free(&s);
}

// Depth test and model matrices: a copy moved towards the camera hides the
// original whatever the draw order; a depth range fitted to the mesh keeps it whole.
static void test_depth_and_model(void)
{
    need_gl();
    scene s;
    scene_make(&s, 0.7);
    sp_camera cam = sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, s.lo, s.hi, sp_v3(0, 0, -1), sp_v3(0, 1, 0), W, H);
    sp_error err = {0};
    sp_render_target* t = new_target(W, H);
    sp_mesh_desc d = {.vertex_count = s.rig.vertex_count,
                      .positions = s.xyz,
                      .base_color = {0.9f, 0.05f, 0.05f, 1},
                      .triangle_count = s.rig.triangle_count,
                      .triangles = s.rig.triangles};
    sp_render_mesh* red;
    sp_render_mesh_create(g_r, &d, &red, &err);
    d.base_color[0] = 0.05f, d.base_color[2] = 0.9f;
    sp_render_mesh* blue;
    sp_render_mesh_create(g_r, &d, &blue, &err);
    ENSURE(red && blue);
    const double dz = 0.5 * (s.hi.z - s.lo.z) + 0.2;
    sp_mat4 closer = sp_mat4_trs(sp_v3(0, 0, dz), sp_quat_identity(), sp_v3(1, 1, 1));
    sp_vec3 lo = s.lo, hi = sp_v3_add(s.hi, sp_v3(0, 0, dz));
    sp_render_fit_depth(&cam, lo, hi);
    sp_image img = {0};
    for (int order = 0; order < 2; ++order) {
        sp_render_target_bind(t);
        sp_renderer_begin(g_r, &cam, W, H);
        sp_renderer_clear(g_r, k_bg, NULL);
        if (order == 0)
            sp_renderer_draw_mesh(g_r, blue, &closer), sp_renderer_draw_mesh(g_r, red, NULL);
        else
            sp_renderer_draw_mesh(g_r, red, NULL), sp_renderer_draw_mesh(g_r, blue, &closer);
        sp_renderer_end(g_r);
        ENSURE(sp_render_target_read(t, &img, &err) == SP_OK);
        int reddish = 0, bluish = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const uint8_t* p = sp_image_at(&img, x, y);
                if (is_bg(&img, x, y)) continue;
                if (p[0] > p[2] + 40) ++reddish;
                if (p[2] > p[0] + 40) ++bluish;
            }
        printf("  order %d: %d blue, %d red pixels\n", order, bluish, reddish);
        ENSURE(bluish > 1000 && reddish < bluish / 50);
    }
    // A depth range that misses the mesh, then the fitted one: coverage comes back.
    sp_camera cut = cam;
    double mid = -sp_mat4_point(&cam.view, sp_v3_scale(sp_v3_add(s.lo, s.hi), 0.5)).z;
    cut.zfar = mid - sp_v3_len(sp_v3_sub(s.hi, s.lo)), cut.znear = cut.zfar - 1.0; // all in front of the mesh
    sp_render_target_bind(t);
    sp_renderer_begin(g_r, &cut, W, H);
    sp_renderer_clear(g_r, k_bg, NULL);
    sp_renderer_draw_mesh(g_r, red, NULL);
    sp_renderer_end(g_r);
    ENSURE(sp_render_target_read(t, &img, &err) == SP_OK);
    int clipped = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            clipped += !is_bg(&img, x, y);
    sp_render_fit_depth(&cut, s.lo, s.hi);
    render_scene(&s, red, &cut, t, W, H, false, &img);
    int whole = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            whole += !is_bg(&img, x, y);
    printf("  clipped %d, fitted %d pixels\n", clipped, whole);
    ENSURE(clipped == 0 && whole > 2000);
    double pbox[4];
    projected_box(&cut, s.xyz, s.rig.vertex_count, pbox);
    ensure_boxes_match(&img, pbox, 1.0);
    sp_image_free(&img);
    sp_render_mesh_destroy(red);
    sp_render_mesh_destroy(blue);
    sp_render_target_destroy(t);
    scene_free(&s);
}

static bool near_color(const uint8_t* p, const float c[3], int tol)
{
    for (int k = 0; k < 3; ++k)
        if (abs((int)p[k] - (int)(c[k] * 255.0f + 0.5f)) > tol) return false;
    return true;
}

// The 3D stick projected over the mesh shows in yellow on its points.
static void test_abstraction_overlay(void)
{
    need_gl();
    scene s;
    scene_make(&s, 0.9);
    sp_camera cam = sp_camera_frame(SP_CAMERA_PERSPECTIVE, s.lo, s.hi, sp_v3(0, 0, -1), sp_v3(0, 1, 0), W, H);
    sp_render_target* t = new_target(W, H);
    sp_render_mesh* m = scene_mesh(&s);
    sp_image img = {0};
    render_scene(&s, m, &cam, t, W, H, true, &img);
    save_for_people(&img, "render_stick.png");
    const sp_abstraction* a = &s.rig.abstractions[0];
    for (int i = 0; i < a->point_count; ++i) {
        sp_vec2 u = sp_camera_project(&cam, sp_v3(s.stick[3 * i], s.stick[3 * i + 1], s.stick[3 * i + 2]));
        const uint8_t* p = sp_image_at(&img, (int)floor(u.x), (int)floor(u.y));
        if (!near_color(p, SP_COLOR_ABSTRACTION, 3))
            fprintf(stderr, "  point %d at (%.1f, %.1f): %d %d %d\n", i, u.x, u.y, p[0], p[1], p[2]);
        ENSURE(near_color(p, SP_COLOR_ABSTRACTION, 3));
    }
    sp_image_free(&img);
    sp_render_mesh_destroy(m);
    sp_render_target_destroy(t);
    scene_free(&s);
}

// A blue polyline: its colour on the line, round joins, the background off it.
static void test_polyline(void)
{
    need_gl();
    sp_camera cam = {.kind = SP_CAMERA_ORTHOGRAPHIC, .view = sp_mat4_identity(), .scale = 1, .width = W, .height = H};
    sp_error err = {0};
    sp_render_target* t = new_target(W, H);
    const sp_vec2 pts[4] = {{40.5, 40.5}, {200.5, 60.5}, {120.5, 200.5}, {280.5, 210.5}};
    sp_render_target_bind(t);
    sp_renderer_begin(g_r, &cam, W, H);
    sp_renderer_clear(g_r, k_bg, NULL);
    sp_renderer_draw_polyline(g_r, pts, 4, false, 6.0f, SP_COLOR_STROKE);
    sp_renderer_draw_dots(g_r, &(sp_vec2){300.5, 20.5}, 1, 5.0f, SP_COLOR_ABSTRACTION);
    // A translucent line of many short segments (overlapping round caps).
    sp_vec2 dense[41];
    for (int i = 0; i <= 40; ++i)
        dense[i] = (sp_vec2){20.5 + 5.0 * i, 228.5};
    const float half_red[4] = {0.9f, 0.1f, 0.1f, 0.5f};
    sp_renderer_draw_polyline(g_r, dense, 41, false, 8.0f, half_red);
    sp_renderer_end(g_r);
    sp_image img = {0};
    ENSURE(sp_render_target_read(t, &img, &err) == SP_OK);
    save_for_people(&img, "render_polyline.png");
    for (int s = 0; s < 3; ++s)
        for (int k = 0; k <= 10; ++k) {
            sp_vec2 q = sp_v2_add(pts[s], sp_v2_scale(sp_v2_sub(pts[s + 1], pts[s]), k / 10.0));
            const uint8_t* p = sp_image_at(&img, (int)floor(q.x), (int)floor(q.y));
            ENSURE(near_color(p, SP_COLOR_STROKE, 2));
        }
    // Round join at the corner: a point 2.5 px off the vertex on the outer side is covered.
    ENSURE(near_color(sp_image_at(&img, 200 + 2, 60 - 1), SP_COLOR_STROKE, 40));
    // 6 px off the first segment's middle: background.
    ENSURE(is_bg(&img, 120, 50 + 7));
    ENSURE(is_bg(&img, 120, 50 - 7));
    ENSURE(is_bg(&img, 10, 230));
    ENSURE(near_color(sp_image_at(&img, 300, 20), SP_COLOR_ABSTRACTION, 2));
    // Translucent: blended once everywhere, joins (x = 25, 30, ...) included.
    const uint8_t* ref = sp_image_at(&img, 27, 228);
    ENSURE(ref[1] > 100 && ref[1] < 160); // half-way between white and red
    for (int x = 24; x < 200; ++x) {
        const uint8_t* p = sp_image_at(&img, x, 228);
        if (abs((int)p[1] - (int)ref[1]) > 2) fprintf(stderr, "  x=%d: %d vs %d\n", x, p[1], ref[1]);
        ENSURE(abs((int)p[1] - (int)ref[1]) <= 2);
    }
    // Anti-aliased edge: some pixel across the line edge is between the two colours.
    int partial = 0;
    for (int y = 45; y < 60; ++y) {
        const uint8_t* p = sp_image_at(&img, 120, y);
        if (p[0] > 60 && p[0] < 230) ++partial;
    }
    ENSURE(partial >= 1);
    sp_image_free(&img);
    sp_render_target_destroy(t);
}

// Ink on a surface (sp_renderer_draw_curve3d_facing): drawn where its
// surface faces the camera, covered by a mesh in front of it, not drawn at
// all where its normal faces away.
static void test_ink_on_surface(void)
{
    need_gl();
    // A grey square at z = 0 facing +z and a green one at z = 0.5 over its right half.
    const double back[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const double front[12] = {0.2, -1, 0.5, 1, -1, 0.5, 1, 1, 0.5, 0.2, 1, 0.5};
    const uint32_t tris[6] = {0, 1, 2, 0, 2, 3};
    sp_error err = {0};
    sp_render_mesh *mb = NULL, *mf = NULL;
    sp_render_mesh_create(
        g_r,
        &(sp_mesh_desc){
            .vertex_count = 4, .positions = back, .base_color = {0.6f, 0.6f, 0.6f, 1}, .triangle_count = 2, .triangles = tris},
        &mb, &err);
    sp_render_mesh_create(
        g_r,
        &(sp_mesh_desc){
            .vertex_count = 4, .positions = front, .base_color = {0.1f, 0.7f, 0.1f, 1}, .triangle_count = 2, .triangles = tris},
        &mf, &err);
    ENSURE(mb && mf);
    sp_camera cam =
        sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, sp_v3(-1, -1, 0), sp_v3(1, 1, 0.5), sp_v3(0, 0, -1), sp_v3(0, 1, 0), W, H);
    sp_render_fit_depth(&cam, sp_v3(-1, -1, -0.1), sp_v3(1, 1, 0.6));
    // A line across the grey square at y = 0.3 (above) and y = -0.3 (its normal turned away).
    double line[2][3 * 41], up[3 * 41], down[3 * 41];
    for (int i = 0; i <= 40; ++i)
        for (int k = 0; k < 2; ++k) {
            double* q = line[k] + 3 * i;
            q[0] = -0.9 + 1.8 * i / 40, q[1] = k ? -0.3 : 0.3, q[2] = 0;
            up[3 * i] = down[3 * i] = 0, up[3 * i + 1] = down[3 * i + 1] = 0, up[3 * i + 2] = 1, down[3 * i + 2] = -1;
        }
    sp_render_target* t = new_target(W, H);
    sp_render_target_bind(t);
    sp_renderer_begin(g_r, &cam, W, H);
    sp_renderer_clear(g_r, k_bg, NULL);
    sp_renderer_draw_mesh(g_r, mb, NULL);
    sp_renderer_draw_mesh(g_r, mf, NULL);
    sp_renderer_draw_curve3d_facing(g_r, line[0], up, 41, 5.0f, SP_COLOR_INK);
    sp_renderer_draw_curve3d_facing(g_r, line[1], down, 41, 5.0f, SP_COLOR_INK);
    sp_renderer_end(g_r);
    sp_image img = {0};
    ENSURE(sp_render_target_read(t, &img, &err) == SP_OK);
    save_for_people(&img, "render_ink.png");
    int shown = 0, covered = 0, away = 0;
    for (int i = 1; i < 40; ++i)
        for (int k = 0; k < 2; ++k) {
            const double* q = line[k] + 3 * i;
            sp_vec2 u = sp_camera_project(&cam, sp_v3(q[0], q[1], q[2]));
            const uint8_t* p = sp_image_at(&img, (int)floor(u.x), (int)floor(u.y));
            bool ink = near_color(p, SP_COLOR_INK, 12);
            if (k == 1)
                away += ink;
            else if (q[0] < 0.15)
                shown += ink;
            else if (q[0] > 0.25)
                covered += ink;
        }
    printf("  ink shown %d of the uncovered points, %d covered, %d facing away\n", shown, covered, away);
    ENSURE(shown >= 20 && covered == 0 && away == 0);
    sp_image_free(&img);
    sp_render_mesh_destroy(mb);
    sp_render_mesh_destroy(mf);
    sp_render_target_destroy(t);
}

static void test_png_roundtrip(void)
{
    sp_image img = {0}, back = {0};
    ENSURE(sp_image_alloc(&img, 7, 5) == SP_OK);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x) {
            uint8_t* p = sp_image_at(&img, x, y);
            p[0] = (uint8_t)(x * 30), p[1] = (uint8_t)(y * 50), p[2] = 7, p[3] = 255;
        }
    sp_error err = {0};
    const char* path = sp_test_tmp_path("roundtrip.png");
    ENSURE(sp_image_write_png(&img, path, &err) == SP_OK);
    ENSURE(sp_image_read_png(path, &back, &err) == SP_OK);
    ENSURE(back.width == 7 && back.height == 5);
    ENSURE(!memcmp(img.rgba, back.rgba, 7 * 5 * 4));
    ENSURE(sp_image_read_png(sp_test_tmp_path("missing.png"), &back, &err) != SP_OK);
    ENSURE(strstr(err.text, "missing.png") != NULL);
    sp_image_free(&img);
    sp_image_free(&back);
}

// Reads a whole file into buf (at most cap bytes); its size, -1 when it cannot be read.
static long slurp(const char* path, char* buf, long cap)
{
    FILE* f = fopen(path, "rb");
    if (!f) return -1;
    long n = (long)fread(buf, 1, (size_t)cap, f);
    fclose(f);
    return n;
}

// Files left in the folder of `path` by process `pid`'s writer: its
// temporary files (sp_path_temp_beside, ".sp-<pid>-..."), or any whose
// names start with the file's own and differ from it.
static int leftovers(const char* path, int pid)
{
    char dir[1024], cmd[2300];
    snprintf(dir, sizeof dir, "%s", path);
    char* slash = strrchr(dir, '/');
    ENSURE(slash);
    *slash = 0;
    snprintf(cmd, sizeof cmd, "ls -A '%s' | grep -c -F -e '%s.' -e '.sp-%d-'", dir, slash + 1, pid);
    FILE* p = popen(cmd, "r");
    int n = -1;
    ENSURE(p && fscanf(p, "%d", &n) == 1);
    pclose(p);
    return n;
}

// A write that fails (here a file size limit, as on a full disk) leaves the
// old file as it was and no truncated or temporary one: the PNG, and the
// same writer under the JSON, glTF and stroke files (sp_file_write). A
// symbolic link stays one, and a FIFO is written into, not replaced.
static void test_png_write_whole(void)
{
    sp_image img = {0};
    ENSURE(sp_image_alloc(&img, 256, 256) == SP_OK);
    uint32_t z = 12345; // noise: a PNG of about 256 KB, far beyond the limit below
    for (int i = 0; i < 256 * 256 * 4; ++i)
        img.rgba[i] = (uint8_t)((z = z * 1664525u + 1013904223u) >> 24);
    sp_error err = {0};
    const char* path = sp_test_tmp_path("whole.png");
    ENSURE(sp_image_write_png(&img, path, &err) == SP_OK);
    static char before[1 << 20], after[1 << 20];
    long n0 = slurp(path, before, sizeof before);
    ENSURE(n0 > 65536);
    for (int i = 0; i < 256 * 256 * 4; ++i)
        img.rgba[i] ^= 0x5a;
    int pid = sp_fixture_fork_file_limit(16384);
    if (pid == 0) {
        sp_error e = {0};
        sp_result r = sp_image_write_png(&img, path, &e);
        fprintf(stderr, "  under a 16 KB file limit: %s\n", r == SP_OK ? "written" : e.text);
        _exit(r == SP_ERR_IO && strstr(e.text, "whole.png") && strstr(e.text, "too large") ? 0 : 1);
    }
    ENSURE(sp_fixture_child_passed(pid));
    ENSURE(slurp(path, after, sizeof after) == n0 && !memcmp(before, after, (size_t)n0));
    ENSURE(leftovers(path, pid) == 0);
    // Through a symbolic link: the target is written, the link stays.
    const char* link = sp_test_tmp_path("whole_link.png");
    unlink(link);
    ENSURE(symlink(path, link) == 0);
    ENSURE(sp_image_write_png(&img, link, &err) == SP_OK);
    struct stat st;
    ENSURE(lstat(link, &st) == 0 && S_ISLNK(st.st_mode));
    ENSURE(slurp(path, after, sizeof after) > 65536 && memcmp(before, after, 64 * 1024) != 0);
    // Into a FIFO: a reader gets every byte, and the FIFO is still one.
    const char* fifo = sp_test_tmp_path("whole.fifo");
    unlink(fifo);
    ENSURE(mkfifo(fifo, 0600) == 0);
    pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) {
        long n = slurp(fifo, after, sizeof after);
        _exit(n == slurp(path, before, sizeof before) && !memcmp(before, after, (size_t)n) ? 0 : 1);
    }
    ENSURE(sp_image_write_png(&img, fifo, &err) == SP_OK);
    ENSURE(sp_fixture_child_passed(pid));
    ENSURE(lstat(fifo, &st) == 0 && S_ISFIFO(st.st_mode));
    // A folder is not a file.
    const char* dir = sp_test_tmp_path("whole_dir");
    mkdir(dir, 0755);
    ENSURE(sp_image_write_png(&img, dir, &err) == SP_ERR_IO && strstr(err.text, "folder"));
    rmdir(dir);
    unlink(fifo);
    unlink(link);
    sp_image_free(&img);
}

static void test_projection_matches_camera(void)
{
    // Pure math: NDC of the GL projection equals sp_camera_project mapped to NDC.
    scene s;
    scene_make(&s, 0.4);
    for (int kind = 0; kind < 2; ++kind) {
        sp_camera cam = sp_camera_frame((sp_camera_kind)kind, s.lo, s.hi, sp_v3(0.2, -0.3, -1), sp_v3(0, 1, 0), 333, 211);
        cam.cx += 13.25, cam.cy -= 7.5; // an off-centre principal point
        sp_mat4 P = sp_render_projection(&cam);
        for (int i = 0; i < s.rig.vertex_count; i += 5) {
            sp_vec3 w = sp_v3(s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]);
            sp_vec3 c = sp_mat4_point(&cam.view, w);
            const double* m = P.m;
            double cx = m[0] * c.x + m[4] * c.y + m[8] * c.z + m[12];
            double cy = m[1] * c.x + m[5] * c.y + m[9] * c.z + m[13];
            double cz = m[2] * c.x + m[6] * c.y + m[10] * c.z + m[14];
            double cw = m[3] * c.x + m[7] * c.y + m[11] * c.z + m[15];
            sp_vec2 u = sp_camera_project(&cam, w);
            ENSURE_NEAR((cx / cw + 1.0) * 0.5 * cam.width, u.x, 1e-9 * cam.width);
            ENSURE_NEAR((1.0 - cy / cw) * 0.5 * cam.height, u.y, 1e-9 * cam.height);
            ENSURE(cz / cw > -1.0 && cz / cw < 1.0); // inside the depth range
        }
    }
    scene_free(&s);
}

// A contact sheet's label wider than its cell is drawn smaller, not cut:
// names that differ only at their end (the visitors' "hind-legs-walking",
// "hind-legs-walk-long") stay told apart, and no ink leaves the cell.
static void test_sheet_labels(void)
{
    const char* labels[2] = {"hind-legs-walking-2a", "hind-legs-walking-2b"};
    sp_image img[2] = {{0}};
    for (int i = 0; i < 2; ++i) {
        sp_sheet_item it = {.label = labels[i]};
        sp_error err = {0};
        ENSURE(sp_sheet_render(&it, 1, &(sp_sheet_desc){.cell = 170}, &img[i], &err) == SP_OK);
        for (int y = 170; y < img[i].height; ++y)
            for (int x = 165; x < 169; ++x)
                ENSURE(sp_image_at(&img[i], x, y)[0] > 200); // paper right of the text
    }
    long differ = 0;
    for (int y = 0; y < img[0].height; ++y)
        for (int x = 0; x < img[0].width; ++x)
            differ += sp_image_at(&img[0], x, y)[0] != sp_image_at(&img[1], x, y)[0];
    ENSURE(differ > 0);
    sp_image_free(&img[0]);
    sp_image_free(&img[1]);
}

int main(int argc, char** argv)
{
    int rc = sp_test_run(argc, argv,
                         (sp_test[]){{"projection_matches_camera", test_projection_matches_camera},
                                     {"png_roundtrip", test_png_roundtrip},
                                     {"png_write_whole", test_png_write_whole},
                                     {"mesh_orthographic", test_mesh_orthographic},
                                     {"mesh_perspective", test_mesh_perspective},
                                     {"viewport_scale", test_viewport_scale},
                                     {"depth_and_model", test_depth_and_model},
                                     {"abstraction_overlay", test_abstraction_overlay},
                                     {"polyline", test_polyline},
                                     {"ink_on_surface", test_ink_on_surface},
                                     {"sheet_labels", test_sheet_labels},
                                     {0}});
    sp_renderer_destroy(g_r);
    sp_headless_destroy(g_gl);
    return rc;
}
