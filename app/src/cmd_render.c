// cmd_render.c: `sketchpose render`: a rig, posed, with an abstraction overlaid, to PNG.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "rig_handle.h"
#include "sp/headless.h"
#include "sp/image.h"
#include "sp/render.h"
#include "sp/sketch_io.h"

// The sketch camera maps the character onto its own canvas; fit that canvas
// into the output keeping its aspect, centred (letterboxed), so that a
// stroke file drawn on the canvas overlays the render at the same scale.
static sp_camera fit_camera(const sp_camera* src, int w, int h)
{
    sp_camera c = *src;
    double cw = src->width > 0 ? src->width : w, chh = src->height > 0 ? src->height : h;
    double k = fmin(w / cw, h / chh);
    c.scale = src->scale * k;
    c.cx = src->cx * k + 0.5 * (w - cw * k);
    c.cy = src->cy * k + 0.5 * (h - chh * k);
    c.width = w;
    c.height = h;
    return c;
}

// Orbits the camera about the character's centre c: yaw about world +Y,
// then pitch about the camera's horizontal axis (positive: from above). The
// centre keeps its pixel, so the framing stays.
static void orbit_camera(sp_camera* cam, sp_vec3 c, double yaw, double pitch)
{
    sp_mat4 to = sp_mat4_trs(c, sp_quat_identity(), sp_v3(1, 1, 1));
    sp_mat4 from = sp_mat4_trs(sp_v3_scale(c, -1.0), sp_quat_identity(), sp_v3(1, 1, 1));
    sp_mat4 ry = sp_mat4_trs(sp_v3(0, 0, 0), sp_quat_axis_angle(sp_v3(0, 1, 0), yaw), sp_v3(1, 1, 1));
    sp_mat4 world = sp_mat4_mul(&to, &ry);
    world = sp_mat4_mul(&world, &from);
    sp_mat4 view = sp_mat4_mul(&cam->view, &world);
    sp_vec3 cc = sp_mat4_point(&view, c);
    sp_mat4 cto = sp_mat4_trs(cc, sp_quat_identity(), sp_v3(1, 1, 1));
    sp_mat4 cfrom = sp_mat4_trs(sp_v3_scale(cc, -1.0), sp_quat_identity(), sp_v3(1, 1, 1));
    sp_mat4 rx = sp_mat4_trs(sp_v3(0, 0, 0), sp_quat_axis_angle(sp_v3(1, 0, 0), pitch), sp_v3(1, 1, 1));
    sp_mat4 cam_m = sp_mat4_mul(&cto, &rx);
    cam_m = sp_mat4_mul(&cam_m, &cfrom);
    cam->view = sp_mat4_mul(&cam_m, &view);
}

// The abstraction in yellow, its open curves' ends as dots; a dark halo
// first so that yellow reads on light skin and background. ends: room for
// two a curve.
static void draw_overlay(sp_renderer* r, const sp_camera* cam, const sp_abstraction* ab, const double* zxyz, sp_vec2* ends,
                         float lw)
{
    int n_ends = 0;
    for (int c = 0; c < ab->curve_count; ++c) {
        const sp_curve* cv = &ab->curves[c];
        if (cv->point_count < 1 || cv->closed) continue;
        const double* a = zxyz + 3 * (size_t)cv->first_point;
        const double* b = zxyz + 3 * (size_t)(cv->first_point + cv->point_count - 1);
        ends[n_ends++] = sp_camera_project(cam, sp_v3(a[0], a[1], a[2]));
        ends[n_ends++] = sp_camera_project(cam, sp_v3(b[0], b[1], b[2]));
    }
    sp_renderer_draw_abstraction(r, ab, zxyz, lw + 2.0f * fmaxf(1.0f, 0.35f * lw), SP_COLOR_OUTLINE);
    sp_renderer_draw_dots(r, ends, n_ends, 0.5f * lw * 1.6f + fmaxf(1.0f, 0.35f * lw), SP_COLOR_OUTLINE);
    sp_renderer_draw_abstraction(r, ab, zxyz, lw, SP_COLOR_ABSTRACTION);
    sp_renderer_draw_dots(r, ends, n_ends, 0.5f * lw * 1.6f, SP_COLOR_ABSTRACTION);
}

int cmd_render(int argc, char** argv)
{
    const char *rig_path = NULL, *pose_path = NULL, *abs_name = NULL, *out_path = NULL, *size = NULL;
    double line_width = NAN, yaw = 0, pitch = 0; // NAN: not given
    bool no_shadow = false;
    const sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "the rigged character (.gltf or .glb), or a black-box rig plugin (.so)", true},
        {"--pose", SP_OPT_IN, &pose_path, "p.json", "pose file {\"parameters\": {...}} (default: the rig's stored pose)", false},
        {"--abstraction", SP_OPT_STRING, &abs_name, "NAME",
         "abstraction to overlay (default: the part's own, else the first; 'none': no overlay)", false},
        {"--out", SP_OPT_OUT, &out_path, "X.png", "the PNG to write", true},
        {"--size", SP_OPT_STRING, &size, "WxH", "image size in pixels, sides 16..8192 (default 640x480)", false},
        {"--line-width", SP_OPT_DOUBLE, &line_width, "PX",
         "overlay line width, pixels in (0, 256] (default: scales with the image)", false},
        {"--yaw", SP_OPT_DOUBLE, &yaw, "DEG", "orbit the sketch camera about the vertical axis (default 0)", false},
        {"--pitch", SP_OPT_DOUBLE, &pitch, "DEG", "then tilt it, positive looks from above (default 0)", false},
        {"--no-shadow", SP_OPT_FLAG, &no_shadow, NULL, "no ground shadow", false},
    };
    int rc =
        sp_cli_parse(argc, argv, "sketchpose render",
                     "render a rig posed by a pose file (else its stored pose), with an abstraction overlaid in yellow, to PNG",
                     opts, (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_out("sketchpose render", "--out", out_path, SP_CLI_OUT_PNG)) return SP_EXIT_USAGE;
    int w = 640, h = 480;
    if (size && !sp_cli_parse_size(size, &w, &h)) {
        fprintf(stderr, "sketchpose render: --size wants WxH with sides 16..8192, e.g. 640x480, got '%s'\n",
                sp_text_printable(size, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    // A typed 0 was the default width; the parser already refuses what is not finite.
    if ((!isnan(line_width) && !sp_cli_check_double("sketchpose render", "--line-width", line_width, 0, true, 256)) ||
        !sp_cli_check_double("sketchpose render", "--pitch", pitch, -89, false, 89))
        return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders("sketchpose render", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work

    sp_error err = {0};
    sp_rig_handle* handle = NULL;
    if (sp_rig_handle_load(rig_path, &handle, &err) != SP_OK) {
        fprintf(stderr, "sketchpose render: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    int nabs = sp_rig_handle_abstraction_count(handle), ai = -1;
    if (abs_name && strcmp(abs_name, "none") != 0) {
        if ((ai = sp_rig_handle_pick_abstraction(handle, abs_name, &err)) < 0) {
            fprintf(stderr, "sketchpose render: %s\n", err.text);
            sp_rig_handle_free(handle);
            return SP_EXIT_INPUT;
        }
    } else if (!abs_name && nabs > 0) {
        ai = 0;
    }

    int exit_code = SP_EXIT_INPUT;
    double* p = NULL;
    sp_rig_posed posed = {0};
    const sp_rig* rig = NULL;
    const sp_abstraction* ab = NULL;
    double *xyz = NULL, *zxyz = NULL;
    sp_vec2* ends = NULL;
    sp_rig_eval* ev = NULL;
    sp_headless* gl = NULL;
    sp_renderer* r = NULL;
    sp_render_target* target = NULL;
    sp_render_mesh* mesh = NULL;
    sp_image img = {0};
    // Parameters the pose file does not list keep the start pose. The view is
    // the rig's own (a plugin is baked in it, with every abstraction).
    sp_camera view = sp_rig_handle_camera(handle, 0, 0);
    if (sp_rig_handle_read_pose(handle, pose_path, &p, NULL, &err) != SP_OK ||
        sp_rig_handle_posed(handle, -1, p, &view, &posed, &err) != SP_OK) {
        fprintf(stderr, "sketchpose render: %s\n", err.text);
        goto done;
    }
    const sp_character* ch = posed.character;
    const double* params = posed.params ? posed.params : ch->pose;
    rig = &ch->rig;
    ab = ai >= 0 ? &rig->abstractions[ai] : NULL;
    xyz = malloc(sizeof(double) * 3 * (size_t)(rig->vertex_count ? rig->vertex_count : 1));
    zxyz = ab ? malloc(sizeof(double) * 3 * (size_t)(ab->point_count ? ab->point_count : 1)) : NULL;
    ends = ab ? malloc(sizeof(sp_vec2) * 2 * (size_t)(ab->curve_count ? ab->curve_count : 1)) : NULL;
    sp_rig_eval_create(rig, &ev, NULL);
    if (!xyz || (ab && (!zxyz || !ends)) || !ev) {
        fprintf(stderr, "sketchpose render: out of memory\n");
        goto done;
    }
    sp_rig_eval_update(ev, params, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    if (ab) sp_rig_eval_abstraction(ev, ab, xyz, zxyz);

    sp_vec3 lo, hi;
    sp_bounds(xyz, rig->vertex_count, &lo, &hi);
    sp_camera cam = fit_camera(&ch->camera, w, h);
    if (yaw != 0 || pitch != 0)
        orbit_camera(&cam, sp_v3_scale(sp_v3_add(lo, hi), 0.5), yaw * (3.14159265358979323846 / 180.0),
                     pitch * (3.14159265358979323846 / 180.0));
    sp_render_fit_depth(&cam, lo, hi);

    sp_headless_create(&gl, &err);
    if (!gl) {
        fprintf(stderr, "sketchpose render: %s\n", err.text);
        goto done;
    }
    sp_renderer_create(&(sp_renderer_desc){0}, &r, &err);
    if (r) sp_render_target_create(w, h, 0, &target, &err);
    const sp_mesh_desc md = sp_mesh_desc_of_rig(rig, xyz, ch->colors);
    if (target) sp_render_mesh_create(r, &md, &mesh, &err);
    if (!mesh) {
        fprintf(stderr, "sketchpose render: %s\n", err.text);
        goto done;
    }

    float lw = !isnan(line_width) ? (float)line_width : (float)fmax(2.0, fmin(w, h) / 150.0);
    sp_render_target_bind(target);
    sp_renderer_begin(r, &cam, w, h);
    sp_renderer_clear(r, SP_COLOR_BACKGROUND_TOP, SP_COLOR_BACKGROUND_BOTTOM);
    if (!no_shadow) sp_renderer_draw_ground_shadow(r, lo, hi, 0.0f);
    sp_renderer_draw_mesh(r, mesh, NULL);
    if (ab) draw_overlay(r, &cam, ab, zxyz, ends, lw);
    sp_renderer_end(r);
    if (sp_render_target_read(target, &img, &err) != SP_OK || sp_image_write_png(&img, out_path, &err) != SP_OK) {
        fprintf(stderr, "sketchpose render: %s\n", err.text);
        goto done;
    }
    exit_code = SP_EXIT_OK;
done:
    sp_image_free(&img);
    sp_render_mesh_destroy(mesh);
    sp_render_target_destroy(target);
    sp_renderer_destroy(r);
    sp_headless_destroy(gl);
    sp_rig_eval_destroy(ev);
    free(ends);
    free(zxyz);
    free(xyz);
    free(p);
    sp_rig_posed_free(&posed);
    sp_rig_handle_free(handle);
    return exit_code;
}
