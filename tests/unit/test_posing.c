// Posing uses beyond a single solve: key-pose animations (animate) and
// draw-over curves embedded in the mesh (drawover), in process and through
// the command line on CesiumMan when ../shared/data is there; the commands'
// rig handle on both kinds of rig.
#include <cjson/cJSON.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"
#include "fixtures.h"
#include "pose_io.h"
#include "posing.h"
#include "rig_handle.h"
#include "sp/blackbox.h"
#include "sp/embed.h"
#include "sp/gltf.h"
#include "sp/plugin.h"
#include "sp/sketch_io.h"
#include "sp/solver.h"
#include "sp/synth.h"
#include "test.h"

static sp_camera front_camera(const sp_rig* rig)
{
    return sp_camera_default_view(rig->rest, rig->vertex_count, 640, 480);
}

// The animation passes through every key: sampled at each key time, the
// joints' world transforms equal those of the key's parameters. (Compared as
// transforms, not parameters: Euler angles past +-90 degrees have twins.)
static void check_animation_keys(const sp_rig* rig, const sp_animation* an, const double* keys, const double* times, int n, double tol)
{
    int P = rig->param_count, J = rig->joint_count;
    sp_vec3* t = malloc(sizeof(sp_vec3) * J);
    sp_quat* r = malloc(sizeof(sp_quat) * J);
    sp_vec3* s = malloc(sizeof(sp_vec3) * J);
    sp_mat4* w = malloc(sizeof(sp_mat4) * J);
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    for (int k = 0; k < n; ++k) {
        // Prefilled with the rest pose: a joint with parameters but no channel fails.
        for (int j = 0; j < J; ++j) t[j] = rig->joints[j].rest_t, r[j] = rig->joints[j].rest_r, s[j] = rig->joints[j].rest_s;
        sp_animation_sample(an, times[k], t, r, s);
        sp_rig_eval_update(ev, keys + (size_t)k * P, false);
        const sp_mat4* ref = sp_rig_eval_world(ev);
        for (int j = 0; j < J; ++j) {
            sp_mat4 l = sp_mat4_trs(t[j], r[j], s[j]);
            w[j] = rig->joints[j].parent < 0 ? l : sp_mat4_mul(&w[rig->joints[j].parent], &l);
            for (int e = 0; e < 16; ++e) ENSURE_NEAR(w[j].m[e], ref[j].m[e], tol * fmax(1.0, fabs(ref[j].m[e])));
        }
    }
    sp_rig_eval_destroy(ev);
    free(t), free(r), free(s), free(w);
}

static void test_animation_from_keys(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 6, .all_channels = true, .seed = 21}, &rig);
    int P = rig.param_count, n = 4;
    double* keys = malloc(sizeof(double) * P * n);
    double times[4] = {0.0, 0.4, 1.0, 1.7};
    for (int k = 0; k < n; ++k) sp_synth_params(&rig, 50 + k, 0.6, keys + (size_t)k * P);
    sp_animation an;
    sp_error err = {0};
    ENSURE(sp_animation_from_keys(&rig, keys, times, n, "keys", &an, &err) == SP_OK);
    ENSURE(an.channel_count > rig.joint_count);
    ENSURE_NEAR(an.duration_s, 1.7, 1e-12);
    check_animation_keys(&rig, &an, keys, times, n, 1e-5); // float storage
    // Times that do not increase are refused.
    sp_animation bad;
    double t2[2] = {1.0, 1.0};
    ENSURE(sp_animation_from_keys(&rig, keys, t2, 2, "bad", &bad, &err) == SP_ERR_INVALID);
    // So are times a float channel cannot hold: overflow, underflow to equal, NaN.
    double t3[3][2] = {{0, 1e300}, {0, 1e-300}, {NAN, 1}};
    for (int i = 0; i < 3; ++i) {
        ENSURE(sp_animation_from_keys(&rig, keys, t3[i], 2, "bad", &bad, &err) == SP_ERR_INVALID);
        printf("  %s\n", err.text);
    }
    rig.animations = malloc(sizeof(sp_animation));
    rig.animations[0] = an;
    rig.animation_count = 1;
    free(keys);
    sp_rig_free(&rig);
}

// Draw-over on the project's own chain: a curve along the last bone,
// redrawn bent, bends it; the first bone stays put (W_dist, locality).
static void test_drawover_fixture(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 5, .seed = 3, .ring_vertices = 16, .rings_per_bone = 8}, &rig);
    sp_camera cam = front_camera(&rig);
    int P = rig.param_count;
    double* p0 = calloc(P, sizeof(double));
    double* bent = calloc(P, sizeof(double));
    double* p = calloc(P, sizeof(double));
    sp_rig_defaults(&rig, p0);
    memcpy(bent, p0, sizeof(double) * P);
    bent[sp_rig_find_param(&rig, "j3.rz")] = 0.7;
    // S1: the last bone's stick curve at rest; S2: the same at the bent pose.
    sp_sketch s_rest, s_bent;
    ENSURE(sp_synth_sketch(&rig, 0, &cam, p0, &s_rest) == SP_OK);
    ENSURE(sp_synth_sketch(&rig, 0, &cam, bent, &s_bent) == SP_OK);
    const sp_stroke* on = &s_rest.strokes[3];
    sp_sketch to = {0};
    sp_sketch_add_stroke(&to, s_bent.strokes[3].points, NULL, s_bent.strokes[3].count);
    double* xyz = malloc(sizeof(double) * 3 * rig.vertex_count);
    sp_rig_eval* ev;
    sp_rig_eval_create(&rig, &ev, NULL);
    sp_rig_eval_update(ev, p0, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(&rig), xyz);
    sp_abstraction emb;
    sp_error err = {0};
    ENSURE(sp_embed_curve(&rig, xyz, &cam, on->points, on->count, 32, "drawover", &emb, &err) == SP_OK);
    int a = sp_rig_add_abstraction(&rig, &emb);
    ENSURE(a == 1);
    sp_solver* s;
    sp_solver_create(&rig, a, &cam, &(sp_solve_desc){0}, &s, NULL);
    sp_solve_report rep;
    ENSURE(sp_solver_solve(s, &to, p0, p, &rep, &err) == SP_OK);
    ENSURE(rep.mean_error_px <= 0.02 * rep.bbox_diagonal_px);
    // Vertices of the first bone (rings 0..7 of bone 0) barely move.
    double* x1 = malloc(sizeof(double) * 3 * rig.vertex_count);
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(&rig), x1);
    sp_vec3 lo, hi;
    sp_bounds(xyz, rig.vertex_count, &lo, &hi);
    double D = sp_v3_len(sp_v3_sub(hi, lo)), far = 0;
    for (int v = 0; v < 8 * 16; ++v) far = fmax(far, sp_v3_len(sp_v3_sub(sp_v3(x1[3 * v], x1[3 * v + 1], x1[3 * v + 2]), sp_v3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]))));
    fprintf(stderr, "  drawover fixture: mean error %.2f px (%.2f%%), far vertices moved %.3f%% of the size\n", rep.mean_error_px,
            100 * rep.mean_error_px / rep.bbox_diagonal_px, 100 * far / D);
    ENSURE(far <= 0.01 * D);
    // A curve drawn beside the character is refused.
    sp_vec2 off[2] = {{2, 2}, {30, 4}};
    sp_abstraction none;
    ENSURE(sp_embed_curve(&rig, xyz, &cam, off, 2, 16, "x", &none, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "not on the character"));
    sp_solver_destroy(s);
    sp_rig_eval_destroy(ev);
    sp_abstraction_free(&emb);
    sp_sketch_free(&s_rest), sp_sketch_free(&s_bent), sp_sketch_free(&to);
    free(p0), free(bent), free(p), free(xyz), free(x1);
    sp_rig_free(&rig);
}

// Solves a draw-over as `sketchpose drawover` does (the placement held, the
// weights scaled to the drawn curves unless !scale) from `start`, and poses
// the mesh at the result into x1 (ev: the rig's evaluator).
static void drawover_solve(const sp_rig* rig, int a, const sp_camera* cam, const double* xyz, bool scale, const sp_sketch* to,
                           const double* start, sp_rig_eval* ev, double* x1, sp_solve_report* rep, double* factor)
{
    bool* active = sp_drawover_active(rig, &rig->abstractions[a]);
    double* p = malloc(sizeof(double) * rig->param_count);
    ENSURE(active && p);
    sp_solve_desc desc = {.active = active, .ordered_by_ends = true};
    *factor = scale ? sp_drawover_scale_weights(&desc, rig, xyz, cam, &rig->abstractions[a]) : 1;
    sp_solver* s;
    sp_error err = {0};
    sp_solver_create(rig, a, cam, &desc, &s, NULL);
    ENSURE(sp_solver_solve(s, to, start, p, rep, &err) == SP_OK);
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(rig), x1);
    sp_solver_destroy(s);
    free(active), free(p);
}

// Draw-over on CesiumMan: a curve drawn along the arm at rest, redrawn bent,
// bends the arm; the fitted curve matches and the legs barely move.
static void test_drawover_cesiumman(void)
{
    sp_character ch;
    sp_fixture_shared_gltf("CesiumMan/CesiumMan.glb", &ch);
    sp_error err = {0};
    sp_rig* rig = &ch.rig;
    int P = rig->param_count, arm = sp_rig_find_param(rig, "node17.rx");
    ENSURE(arm >= 0);
    double* bent = malloc(sizeof(double) * P);
    memcpy(bent, ch.pose, sizeof(double) * P);
    bent[arm] = 1.0;
    bent[sp_rig_find_param(rig, "node17.rz")] = 0.6;
    // The derived stick curve of that arm (node12 -> node16 -> node17 -> node18), from the shoulder on.
    int c = -1;
    for (int i = 0; i < rig->abstractions[0].curve_count; ++i)
        if (!strcmp(rig->abstractions[0].curves[i].name, "node12-node18")) c = i;
    ENSURE(c >= 0);
    sp_sketch s_rest, s_bent;
    ENSURE(sp_synth_sketch(rig, 0, &ch.camera, ch.pose, &s_rest) == SP_OK);
    ENSURE(sp_synth_sketch(rig, 0, &ch.camera, bent, &s_bent) == SP_OK);
    int n = s_rest.strokes[c].count, from = n / 3;
    double* xyz = malloc(sizeof(double) * 3 * rig->vertex_count);
    double* x1 = malloc(sizeof(double) * 3 * rig->vertex_count);
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    sp_rig_eval_update(ev, ch.pose, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    sp_abstraction emb;
    ENSURE(sp_embed_curve(rig, xyz, &ch.camera, s_rest.strokes[c].points + from, n - from, 48, "drawover", &emb, &err) == SP_OK);
    int a = sp_rig_add_abstraction(rig, &emb);
    // The redrawn stroke: the embedded curve itself at the bent pose, so the
    // target is reachable by bending the arm alone.
    sp_sketch to = {0};
    ENSURE(sp_synth_sketch(rig, a, &ch.camera, bent, &to) == SP_OK);
    // As `sketchpose drawover` solves: the character stays where it stands.
    sp_solve_report rep;
    double f;
    drawover_solve(rig, a, &ch.camera, xyz, true, &to, ch.pose, ev, x1, &rep, &f);
    // Far from the arm: the vertices below the hips (lowest 40% of the body).
    sp_vec3 lo, hi;
    sp_bounds(xyz, rig->vertex_count, &lo, &hi);
    double D = sp_v3_len(sp_v3_sub(hi, lo)), far = 0, arm_moved = 0;
    const int up = 1; // y is up in the default view
    for (int v = 0; v < rig->vertex_count; ++v) {
        double d = sp_v3_len(sp_v3_sub(sp_v3(x1[3 * v], x1[3 * v + 1], x1[3 * v + 2]), sp_v3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2])));
        double h = xyz[3 * v + up];
        if (h < lo.y + 0.4 * (hi.y - lo.y)) far = fmax(far, d);
        arm_moved = fmax(arm_moved, d);
    }
    fprintf(stderr,
            "  drawover CesiumMan: mean error %.2f%% of %.0f px, legs moved %.3f%%, the arm %.1f%% of the size (weights x%.1f)\n",
            100 * rep.mean_error_px / rep.bbox_diagonal_px, rep.bbox_diagonal_px, 100 * far / D, 100 * arm_moved / D, f);
    ENSURE(rep.mean_error_px <= 0.02 * rep.bbox_diagonal_px);
    ENSURE(arm_moved > 0.05 * D); // the arm did bend
    ENSURE(far <= 0.002 * D);     // the hips held (sp_drawover_active): 0.49% when they could turn
    sp_rig_eval_destroy(ev);
    sp_abstraction_free(&emb);
    sp_sketch_free(&s_rest), sp_sketch_free(&s_bent), sp_sketch_free(&to);
    free(bent), free(xyz), free(x1);
    sp_character_free(&ch);
}

// CesiumMan at its stored pose: the mesh there (xyz), room for another
// pose's (x1) and the evaluator.
typedef struct posed_man {
    sp_character ch;
    double *xyz, *x1;
    sp_rig_eval* ev;
} posed_man;

static void posed_man_load(posed_man* m)
{
    sp_fixture_shared_gltf("CesiumMan/CesiumMan.glb", &m->ch);
    int V = m->ch.rig.vertex_count;
    m->xyz = malloc(sizeof(double) * 3 * V);
    m->x1 = malloc(sizeof(double) * 3 * V);
    ENSURE(m->xyz && m->x1 && sp_rig_eval_create(&m->ch.rig, &m->ev, NULL) == SP_OK);
    sp_rig_eval_update(m->ev, m->ch.pose, false);
    sp_rig_eval_points(m->ev, sp_rig_mesh_points(&m->ch.rig), m->xyz);
}

static void posed_man_free(posed_man* m)
{
    sp_rig_eval_destroy(m->ev);
    free(m->xyz), free(m->x1);
    sp_character_free(&m->ch);
}

// Draw-over is local for a short curve too: a line drawn up CesiumMan's
// neck and redrawn tilted tilts the head, and the hands and feet stay put.
// The match term is measured over the curve's own size, so before the
// weights were scaled to the character's (sp_drawover_scale_weights) the
// redrawn neck swung an arm. Returns the largest move of a vertex drawn far
// from the curve, over the mesh's size; *err: the fit's mean error in px.
static double neck_far_move(bool scale, double* err_px, double* factor)
{
    posed_man m;
    posed_man_load(&m);
    sp_rig* rig = &m.ch.rig;
    int V = rig->vertex_count;
    const double *xyz = m.xyz, *x1 = m.x1;
    sp_vec2 on_pts[14], to_pts[14];
    for (int i = 0; i < 14; ++i) {
        on_pts[i] = (sp_vec2){321, 165 - 5 * i};
        to_pts[i] = (sp_vec2){321 + (i < 3 ? 0 : (i - 3) * 2.2), 165 - 5 * i + (i < 3 ? 0 : (i - 3) * 0.6)};
    }
    sp_sketch to = {.canvas_w = 640, .canvas_h = 480, .stroke_count = 1, .strokes = &(sp_stroke){.count = 14, .points = to_pts}};
    sp_error err = {0};
    sp_abstraction emb;
    ENSURE(sp_embed_curve(rig, xyz, &m.ch.camera, on_pts, 14, 48, "drawover", &emb, &err) == SP_OK);
    int a = sp_rig_add_abstraction(rig, &emb);
    sp_solve_report rep;
    drawover_solve(rig, a, &m.ch.camera, xyz, scale, &to, m.ch.pose, m.ev, m.x1, &rep, factor);
    *err_px = rep.mean_error_px;
    sp_vec3 lo, hi;
    sp_bounds(xyz, V, &lo, &hi);
    double D = sp_v3_len(sp_v3_sub(hi, lo)), far = 0;
    // Far: drawn more than 150 px (a third of the figure) from every point of the curve.
    for (int v = 0; v < V; ++v) {
        sp_vec2 q = sp_camera_project(&m.ch.camera, sp_v3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]));
        double near = INFINITY;
        for (int i = 0; i < 14; ++i)
            near = fmin(near, sp_v2_len(sp_v2_sub(q, on_pts[i])));
        if (near > 150)
            far = fmax(far, sp_v3_len(sp_v3_sub(sp_v3(x1[3 * v], x1[3 * v + 1], x1[3 * v + 2]),
                                                sp_v3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]))));
    }
    sp_abstraction_free(&emb);
    posed_man_free(&m);
    return far / D;
}

// The factor is the solver's own scale: the character's size over the
// curve as embedded (the report's bbox_diagonal_px), also for a stroke that
// runs off the mesh, which embedding pulls onto it (the stroke as drawn
// gave a factor 3.6 times too small for an arm line run past the hand).
static void test_drawover_scale_is_solvers(void)
{
    posed_man m;
    posed_man_load(&m);
    sp_rig* rig = &m.ch.rig;
    int V = rig->vertex_count;
    const double* xyz = m.xyz;
    // Along the right arm and 120 px past the hand (CesiumMan's hand ends near x 470).
    sp_vec2 on_pts[16], to_pts[16];
    for (int i = 0; i < 16; ++i) {
        on_pts[i] = (sp_vec2){360 + 15 * i, 160 + 3.9 * i};
        to_pts[i] = (sp_vec2){360 + 15 * i, 160 + 3.9 * i - 0.08 * i * i};
    }
    sp_error err = {0};
    sp_abstraction emb;
    ENSURE(sp_embed_curve(rig, xyz, &m.ch.camera, on_pts, 16, 48, "drawover", &emb, &err) == SP_OK);
    int a = sp_rig_add_abstraction(rig, &emb);
    sp_sketch to = {.canvas_w = 640, .canvas_h = 480, .stroke_count = 1, .strokes = &(sp_stroke){.count = 16, .points = to_pts}};
    sp_solve_report rep;
    double f;
    drawover_solve(rig, a, &m.ch.camera, xyz, true, &to, m.ch.pose, m.ev, m.x1, &rep, &f);
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int v = 0; v < V; ++v) {
        sp_vec2 q = sp_camera_project(&m.ch.camera, sp_v3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]));
        lx = fmin(lx, q.x), hx = fmax(hx, q.x), ly = fmin(ly, q.y), hy = fmax(hy, q.y);
    }
    double mesh = hypot(hx - lx, hy - ly), want = (mesh / rep.bbox_diagonal_px) * (mesh / rep.bbox_diagonal_px);
    fprintf(stderr,
            "  a stroke run off the hand: drawn %.0f px, embedded %.0f px; weights x%.2f, the solver's scale gives x%.2f\n",
            hypot(on_pts[15].x - on_pts[0].x, on_pts[15].y - on_pts[0].y), rep.bbox_diagonal_px, f, want);
    ENSURE(fabs(f - want) <= 0.02 * want);
    sp_abstraction_free(&emb);
    posed_man_free(&m);
}

static void test_drawover_neck_local(void)
{
    double e0, e1, f0, f1;
    double before = neck_far_move(false, &e0, &f0), after = neck_far_move(true, &e1, &f1);
    fprintf(stderr,
            "  a redrawn neck: far vertices moved %.2f%% of the size (error %.2f px) at the paper's weights, %.2f%% (%.2f px) "
            "at %.0f times them\n",
            100 * before, e0, 100 * after, e1, f1);
    // The chest, skinned onto the neck all along the line, is no carrier
    // (curve_carriers: a trunk counts only where the neck does not), so
    // nothing far moves at either weight; with the chest free, at the
    // paper's weights, an arm swung.
    ENSURE(f1 > 10 && e1 < 1.0);
    ENSURE(after < 0.001 && before < 0.001);
}

// Runs a shell command; returns its exit status.
static int run(const char* cmd)
{
    int rc = system(cmd);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// `sketchpose animate` with 4 keys on CesiumMan: the .glb's animation,
// sampled at each key time, reproduces each key's fitted pose.
static void test_animate_cli_cesiumman(void)
{
    const char* data = sp_test_data_dir();
    if (!data) SKIP("../shared/data absent");
    char rig[1024], cmd[8192];
    snprintf(rig, sizeof rig, "%s/gltf/CesiumMan/CesiumMan.glb", data);
    const char* keys[4] = {sp_test_tmp_path("k0.json"), sp_test_tmp_path("k1.json"), sp_test_tmp_path("k2.json"), sp_test_tmp_path("k3.json")};
    for (int k = 0; k < 4; ++k) {
        snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s' --seed %d --amplitude 0.4 --out '%s'", SP_SKETCHPOSE, rig, 10 + k,
                 keys[k]);
        ENSURE(run(cmd) == 0);
    }
    const char* out = sp_test_tmp_path("anim.glb");
    const char* rep = sp_test_tmp_path("anim_report.json");
    char errs[1024];
    snprintf(errs, sizeof errs, "%s", sp_test_tmp_path("anim_err.txt"));
    snprintf(
        cmd, sizeof cmd,
        "'%s' animate --rig '%s' --strokes '%s' '%s' '%s' '%s' --times 0,0.5,1.25,2 --out '%s' --report '%s' > /dev/null 2> '%s'",
        SP_SKETCHPOSE, rig, keys[0], keys[1], keys[2], keys[3], out, rep, errs);
    ENSURE(run(cmd) == 0);
    // CesiumMan's texture is not in the file written: one line says so.
    char* said = sp_fixture_file_text(errs, NULL);
    char want[2048];
    snprintf(want, sizeof want, "sketchpose animate: warning: %s has a texture, which %s does not keep", rig, out);
    ENSURE(said && strstr(said, want) && strchr(said, '\n') == said + strlen(said) - 1);
    free(said);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(out, &ch, &err) == SP_OK);
    ENSURE(!ch.textured); // what was written has no texture, so a second save says nothing
    // The new clip comes first (viewers play the first), CesiumMan's own after it.
    int an = 0;
    ENSURE(ch.rig.animation_count == 2 && !strcmp(ch.rig.animations[0].name, "sketchpose"));
    cJSON* reports = sp_fixture_json_file(rep);
    ENSURE(reports && cJSON_GetArraySize(reports) == 4);
    int P = ch.rig.param_count;
    double* keyp = malloc(sizeof(double) * P * 4);
    double times[4] = {0, 0.5, 1.25, 2};
    for (int k = 0; k < 4; ++k) {
        cJSON* params = cJSON_GetObjectItem(cJSON_GetArrayItem(reports, k), "parameters");
        for (int i = 0; i < P; ++i) {
            cJSON* v = cJSON_GetObjectItem(params, ch.rig.params[i].name);
            ENSURE(cJSON_IsNumber(v));
            keyp[(size_t)k * P + i] = v->valuedouble;
        }
        cJSON* e = cJSON_GetObjectItem(cJSON_GetArrayItem(reports, k), "mean_error_px");
        cJSON* d = cJSON_GetObjectItem(cJSON_GetArrayItem(reports, k), "bbox_diagonal_px");
        ENSURE(e->valuedouble <= 0.01 * d->valuedouble);
    }
    check_animation_keys(&ch.rig, &ch.rig.animations[an], keyp, times, 4, 1e-4);
    cJSON_Delete(reports);
    free(keyp);
    sp_character_free(&ch);
}

// An animation is one character: from the first key that is not a best
// effort on, the proportions (the shape parameters under another one's
// joint: bone lengths, the head's size) stay that key's, and so does the
// overall size (the root's scale) but for a key drawn at another size. A jump of the cartoon man drawn by an
// outside review (stand, crouch, in the air, land, stand, then the stand
// drawn 1.25 times larger): started from each other, the keys' proportions
// drifted (the head to 0.82) and the last stand fitted the figure 1.22 times
// its size at 1.3 px; with the overall size held as well, the larger stand
// was a best effort at 20.7 px (a second review).
static void test_animate_holds_proportions(void)
{
    const char* names[6] = {"k0_stand", "k1_crouch", "k2_air", "k3_land", "k0_stand", "k0_stand_big"};
    char cmd[8192], list[4096] = "";
    for (int k = 0; k < 6; ++k) {
        size_t at = strlen(list);
        snprintf(list + at, sizeof list - at, " '%s/tests/data/posing/cartoon_man_jump_%s.json'", SP_SOURCE_DIR, names[k]);
    }
    const char* rig = SP_SOURCE_DIR "/assets/cartoon_man.glb";
    const char* rep = sp_test_tmp_path("jump_report.json");
    snprintf(cmd, sizeof cmd, "'%s' animate --rig '%s' --strokes%s --out '%s' --report '%s' > /dev/null 2>&1", SP_SKETCHPOSE, rig,
             list, sp_test_tmp_path("jump.glb"), rep);
    ENSURE(run(cmd) == 0);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(rig, &ch, &err) == SP_OK);
    cJSON* reports = sp_fixture_json_file(rep);
    ENSURE(reports && cJSON_GetArraySize(reports) == 6);
    double drift = 0, worst = 0, e[6], size[6];
    int proportions = 0;
    const cJSON* first = cJSON_GetObjectItem(cJSON_GetArrayItem(reports, 0), "parameters");
    for (int k = 0; k < 6; ++k) {
        const cJSON* key = cJSON_GetArrayItem(reports, k);
        const cJSON* params = cJSON_GetObjectItem(key, "parameters");
        for (int i = 0; i < ch.rig.param_count; ++i) {
            if (ch.rig.params[i].group != SP_GROUP_SHAPE) continue;
            double v = cJSON_GetNumberValue(cJSON_GetObjectItem(params, ch.rig.params[i].name));
            if (ch.rig.joints[ch.rig.params[i].joint].parent < 0) {
                size[k] = v;
                continue;
            }
            proportions += k == 0;
            drift = fmax(drift, fabs(v - cJSON_GetNumberValue(cJSON_GetObjectItem(first, ch.rig.params[i].name))));
        }
        e[k] = cJSON_GetNumberValue(cJSON_GetObjectItem(key, "mean_error_px"));
        worst = fmax(worst, e[k] / cJSON_GetNumberValue(cJSON_GetObjectItem(key, "bbox_diagonal_px")));
    }
    fprintf(
        stderr,
        "  a jump in 6 keys: %d proportions, drifting at most %.3g; keys within %.2f%% of their size; the stand first %.2f px "
        "(size %.3f), last %.2f px (%.3f), 1.25x larger %.2f px (%.3f)\n",
        proportions, drift, 100 * worst, e[0], size[0], e[4], size[4], e[5], size[5]);
    ENSURE(proportions > 5 && drift == 0 && worst < 0.01);
    for (int k = 1; k < 5; ++k) // drawn at one size: the figure's size held (it crept to 1.22, leaning back)
        ENSURE(fabs(size[k] - size[0]) < 0.03);
    ENSURE(e[4] < e[0] + 0.3); // the same drawing, the same figure
    ENSURE(size[5] > 1.15 * size[0]);                            // a larger drawing, a larger figure
    cJSON_Delete(reports);
    sp_character_free(&ch);
}

// `animate --times` refuses times the .glb cannot store as floats (it used to
// write a file that would not load again); fine times still load back.
static void test_animate_cli_times(void)
{
    const char* rig = sp_test_src_path("tests/e2e/data/two_bone_extras.gltf");
    char a[1024], b[1024], out[1024], log[1024], cmd[8192];
    snprintf(a, sizeof a, "%s", sp_test_tmp_path("times_a.json"));
    snprintf(b, sizeof b, "%s", sp_test_tmp_path("times_b.json"));
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("times.glb"));
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("times_err.txt"));
    for (int k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s' --seed %d --out '%s' > /dev/null", SP_SKETCHPOSE, rig, 1 + k, k ? b : a);
        ENSURE(run(cmd) == 0);
    }
    // Decimal numbers only: strtod's hexadecimal was taken (0x1 as 1; an outside review).
    const char* bad[] = {"0,1e300", "0,1e-300", "1e39,1e40", "0,inf", "0x1,2", "0,nan"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        remove(out);
        snprintf(cmd, sizeof cmd, "'%s' animate --rig '%s' --strokes '%s' '%s' --times '%s' --out '%s' > /dev/null 2> '%s'",
                 SP_SKETCHPOSE, rig, a, b, bad[i], out, log);
        ENSURE(run(cmd) == 2);
        char text[1024] = {0};
        FILE* f = fopen(log, "rb");
        ENSURE(f && fread(text, 1, sizeof text - 1, f) > 0);
        fclose(f);
        printf("  %s", text);
        ENSURE(strstr(text, "--times") && strstr(text, bad[i]));
        ENSURE(fopen(out, "rb") == NULL);
    }
    snprintf(cmd, sizeof cmd, "'%s' animate --rig '%s' --strokes '%s' '%s' --times 0,3e38 --out '%s' > /dev/null", SP_SKETCHPOSE,
             rig, a, b, out);
    ENSURE(run(cmd) == 0);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(out, &ch, &err) == SP_OK);
    sp_character_free(&ch);
}

// `synth --noise`: every coordinate moved by seeded Gaussian noise of the
// given deviation; the same seed, the same drawing.
static void test_synth_jitter(void)
{
    enum { N = 4000 };
    sp_vec2* pts = calloc(N, sizeof(sp_vec2));
    ENSURE(pts);
    sp_sketch a = {0}, b = {0};
    ENSURE(sp_sketch_add_stroke(&a, pts, NULL, N) == SP_OK && sp_sketch_add_stroke(&b, pts, NULL, N) == SP_OK);
    sp_synth_jitter(&a, 2.0, 7);
    sp_synth_jitter(&b, 2.0, 7);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < N; ++i) {
        const sp_vec2 p = a.strokes[0].points[i];
        ENSURE(p.x == b.strokes[0].points[i].x && p.y == b.strokes[0].points[i].y);
        sum += p.x + p.y;
        sum2 += p.x * p.x + p.y * p.y;
    }
    double mean = sum / (2 * N), sd = sqrt(sum2 / (2 * N) - mean * mean);
    ENSURE(fabs(mean) < 0.1 && fabs(sd - 2.0) < 0.1);
    sp_synth_jitter(&b, 2.0, 8); // another seed moves the points differently
    ENSURE(b.strokes[0].points[0].x != 2 * a.strokes[0].points[0].x);
    sp_sketch_free(&a), sp_sketch_free(&b);
    free(pts);
}

static void write_text(const char* path, const char* text)
{
    FILE* f = fopen(path, "wb");
    ENSURE(f && fputs(text, f) >= 0 && fclose(f) == 0);
}

// The rig handle (rig_handle.h) on a glTF character and on the face plugin:
// the plugin's parameter table is its own (names, bounds, groups, units),
// start poses and pose files, abstraction picking, the view on a canvas, the
// plugin baked static at p, and saved files keep only the file's own
// abstractions (not those a command adds, as drawover does).
static void test_rig_handle(void)
{
    ENSURE(sp_rig_path_is_plugin("dir/libface.so") && sp_rig_path_is_plugin("libface.so.1"));
    ENSURE(!sp_rig_path_is_plugin("face.glb") && !sp_rig_path_is_plugin("lib.so/face.gltf") && !sp_rig_path_is_plugin(NULL));
    // A glTF's extension wins over ".so." in the name (it was dlopen'ed).
    ENSURE(!sp_rig_path_is_plugin("cm.so.backup.glb") && !sp_rig_path_is_plugin("rig.so.2.GLTF"));
    sp_error err = {0};
    sp_rig_handle *g = NULL, *f = NULL;
    ENSURE(sp_rig_handle_load(sp_test_src_path("tests/e2e/data/two_bone_extras.gltf"), &g, &err) == SP_OK);
    ENSURE(sp_rig_handle_load(SP_FACE_PLUGIN, &f, &err) == SP_OK);
    sp_blackbox* bb = NULL;
    ENSURE(sp_blackbox_load_plugin(SP_FACE_PLUGIN, &bb, &err) == SP_OK);
    const sp_blackbox_rig* d = sp_blackbox_desc(bb);
    sp_character* ch = sp_rig_handle_character(g);
    ENSURE(ch && !sp_rig_handle_is_black_box(g) && !sp_rig_handle_character(f) && sp_rig_handle_is_black_box(f));

    // Parameters.
    ENSURE(sp_rig_handle_params(g) == ch->rig.params && sp_rig_handle_param_count(g) == ch->rig.param_count);
    ENSURE(sp_rig_handle_unit(g, 0) == NULL);
    ENSURE(sp_rig_handle_param_count(f) == d->param_count && d->param_count == 44);
    static const char* const units[] = {"angle", "length", "factor", "weight"};
    for (int k = 0; k < d->param_count; ++k) {
        const sp_param* q = &sp_rig_handle_params(f)[k];
        ENSURE(!strcmp(q->name, d->params[k].name) && q->min == d->params[k].min && q->max == d->params[k].max);
        ENSURE(q->def == d->params[k].def && (int)q->group == d->params[k].group);
        ENSURE(!strcmp(sp_rig_handle_unit(f, k), units[d->params[k].unit]));
    }
    ENSURE(sp_rig_handle_vertex_count(f) == d->vertex_count && sp_rig_handle_triangle_count(f) == d->triangle_count);
    ENSURE(sp_rig_handle_vertex_count(g) == ch->rig.vertex_count);

    // Start poses and pose files.
    double *pg = NULL, *pf = NULL;
    ENSURE(sp_rig_handle_read_pose(g, NULL, &pg, NULL, &err) == SP_OK);
    ENSURE(!memcmp(pg, ch->pose, sizeof(double) * (size_t)ch->rig.param_count));
    const char* pose = sp_test_tmp_path("handle_pose.json");
    write_text(pose, "{\"parameters\": {\"jaw_open\": 5, \"smile_l\": 0.25}}");
    int clamped = -1, jaw = -1, smile = -1;
    ENSURE(sp_rig_handle_read_pose(f, pose, &pf, &clamped, &err) == SP_OK && clamped == 1);
    for (int k = 0; k < d->param_count; ++k) {
        if (!strcmp(d->params[k].name, "jaw_open"))
            jaw = k;
        else if (!strcmp(d->params[k].name, "smile_l"))
            smile = k;
        else
            ENSURE(pf[k] == d->params[k].def);
    }
    ENSURE(jaw >= 0 && pf[jaw] == d->params[jaw].max && smile >= 0 && pf[smile] == 0.25);
    free(pf);
    write_text(pose, "{\"parameters\": {\"nope\": 1}}");
    ENSURE(sp_rig_handle_read_pose(f, pose, &pf, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "'nope'") &&
           strstr(err.text, pose));
    free(pf);

    // Abstractions and the view.
    ENSURE(sp_rig_handle_abstraction_count(f) == 1 && !strcmp(sp_rig_handle_abstractions(f)[0].name, "face"));
    ENSURE(sp_rig_handle_pick_abstraction(f, NULL, &err) == 0 && sp_rig_handle_pick_abstraction(f, "face", &err) == 0);
    ENSURE(sp_rig_handle_pick_abstraction(f, "nope", &err) == -1 && strstr(err.text, "'nope'") &&
           strstr(err.text, "it has: face"));
    sp_camera v0 = sp_rig_handle_camera(f, 0, 0), v1 = sp_rig_handle_camera(f, 319.6, 240.2),
              want = sp_blackbox_camera(bb, 640, 480);
    ENSURE(v0.width == 640 && v0.height == 480 && v0.scale == want.scale && v0.cx == want.cx);
    want = sp_camera_resize(&want, 320, 240);
    ENSURE(v1.width == 320 && v1.height == 240 && v1.scale == want.scale && v1.cx == want.cx && v1.cy == want.cy);
    ENSURE(sp_rig_handle_camera(g, 0.4, 0.4).width == ch->camera.width);

    // A plugin at p baked static: one joint, no parameters, its posed mesh and
    // abstraction, the given view; saved and loaded back as glTF.
    ENSURE(sp_rig_handle_read_pose(f, NULL, &pf, NULL, &err) == SP_OK);
    sp_rig_handle_synth_params(f, 3, 1.0, pf);
    double* x = malloc(sizeof(double) * 3 * (size_t)d->vertex_count);
    double* z = malloc(sizeof(double) * 3 * (size_t)sp_blackbox_total_points(bb));
    ENSURE(sp_blackbox_evaluate(bb, pf, x, z, &err) == SP_OK);
    sp_rig_posed v;
    ENSURE(sp_rig_handle_posed(f, 0, pf, &v1, &v, &err) == SP_OK);
    const sp_rig* br = &v.character->rig;
    ENSURE(v.character == &v.baked && !v.params && v.abstraction == 0 && v.saved_abstractions == 1);
    ENSURE(br->joint_count == 1 && br->param_count == 0 && br->vertex_count == d->vertex_count && br->abstraction_count == 1);
    ENSURE(!memcmp(br->rest, x, sizeof(double) * 3 * (size_t)d->vertex_count));
    ENSURE(!memcmp(br->abstractions[0].rest, z, sizeof(double) * 3 * (size_t)br->abstractions[0].point_count));
    ENSURE(v.character->camera.width == 320 && v.character->camera.scale == v1.scale);
    const char* glb = sp_test_tmp_path("handle_face.glb");
    ENSURE(sp_rig_posed_save(&v, glb, &err) == SP_OK);
    sp_rig_posed_free(&v);
    sp_character back = {0};
    ENSURE(sp_gltf_load(glb, &back, &err) == SP_OK);
    ENSURE(back.rig.vertex_count == d->vertex_count && back.rig.abstraction_count == 1 &&
           !strcmp(back.rig.abstractions[0].name, "face"));
    // No parameters, no stored pose: it read back as "sp_pose.parameters is not a JSON object".
    if (back.warning_count) fprintf(stderr, "  baked face read back: %s\n", back.warnings[0]);
    ENSURE(back.warning_count == 0);
    cJSON* gj = sp_fixture_glb_json(glb); // nor a scene "extras": null
    const cJSON* scene0 = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(gj, "scenes"), 0);
    ENSURE(scene0 && !cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(scene0, "extras")));
    cJSON_Delete(gj);
    sp_character_free(&back);

    // A glTF character as it is; a curve a command adds is shown, not saved.
    int own = ch->rig.abstraction_count;
    sp_abstraction extra = ch->rig.abstractions[0];
    snprintf(extra.name, sizeof extra.name, "added");
    int a = sp_rig_add_abstraction(&ch->rig, &extra);
    ENSURE(a == own && sp_rig_handle_abstraction_count(g) == own + 1);
    ENSURE(sp_rig_handle_posed(g, a, pg, &ch->camera, &v, &err) == SP_OK);
    ENSURE(v.character == ch && v.params == pg && v.abstraction == a && v.saved_abstractions == own);
    const char* gl = sp_test_tmp_path("handle_two_bone.glb");
    ENSURE(sp_rig_posed_save(&v, gl, &err) == SP_OK);
    sp_rig_posed_free(&v);
    ENSURE(sp_gltf_load(gl, &back, &err) == SP_OK && back.rig.abstraction_count == own);
    sp_character_free(&back);

    free(x), free(z), free(pf), free(pg);
    sp_blackbox_destroy(bb);
    sp_rig_handle_free(f);
    sp_rig_handle_free(g);
}

// The shared option parser: a value that starts with "--" is a missing value
// (it was taken as the value: `--out --no-shadow` wrote "--no-shadow"), "-1" is one.
static void test_cli_missing_value(void)
{
    const char *out = NULL, *rig = NULL;
    bool flag = false;
    int n = 0;
    sp_opt opts[] = {{"--out", SP_OPT_STRING, &out, "X.png", "", false},
                     {"--rig", SP_OPT_STRING, &rig, "R", "", false},
                     {"--flag", SP_OPT_FLAG, &flag, "", "", false},
                     {"--n", SP_OPT_INT, &n, "N", "", false}};
    char* a1[] = {"t", "--rig", "X", "--out", "--flag"};
    ENSURE(sp_cli_parse(5, a1, "t", "", opts, 4) == 2 && out == NULL && !flag);
    char* a2[] = {"t", "--out", "--rig", "o/x.glb"};
    ENSURE(sp_cli_parse(4, a2, "t", "", opts, 4) == 2 && out == NULL);
    char* a3[] = {"t", "--n", "-1", "--out", "-"};
    ENSURE(sp_cli_parse(5, a3, "t", "", opts, 4) == -1 && n == -1 && out && !strcmp(out, "-"));
    // A value given twice is bad usage (it silently took the last); a flag twice means the same.
    char* a4[] = {"t", "--out", "a.png", "--flag", "--out", "b.png"};
    ENSURE(sp_cli_parse(6, a4, "t", "", opts, 4) == 2);
    char* a5[] = {"t", "--n", "1", "--n", "1"};
    ENSURE(sp_cli_parse(5, a5, "t", "", opts, 4) == 2);
    flag = false;
    char* a6[] = {"t", "--flag", "--flag"};
    ENSURE(sp_cli_parse(3, a6, "t", "", opts, 4) == -1 && flag);
}

// The solve's limits on the command line: out of range is bad usage (it
// silently became the default).
static void test_pose_option_ranges(void)
{
    char cmd[2048];
    const char* bad[] = {"--max-iterations 0",   "--max-iterations -1", "--max-ms 0",    "--max-ms -1",
                         "--representatives -5", "--representatives 0", "--max-ms 0x10", "--lambda-pose 0x1p-2"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' pose --rig r.glb --strokes s.json %s 2>/dev/null", SP_SKETCHPOSE, bad[i]);
        ENSURE(run(cmd) == 2);
    }
    snprintf(cmd, sizeof cmd, "'%s' drawover --rig r.glb --on a.json --to b.json --max-ms -1 2>/dev/null", SP_SKETCHPOSE);
    ENSURE(run(cmd) == 2);
    // In range the command runs (and fails on the missing rig: exit 1).
    snprintf(cmd, sizeof cmd, "'%s' pose --rig /nonexistent.glb --strokes s.json --max-iterations 5 --max-ms 10 2>/dev/null",
             SP_SKETCHPOSE);
    ENSURE(run(cmd) == 1);
    // A number too small for a normal double is a number all the same.
    snprintf(cmd, sizeof cmd, "'%s' pose --rig /nonexistent.glb --strokes s.json --lambda-pose 1e-320 2>/dev/null",
             SP_SKETCHPOSE);
    ENSURE(run(cmd) == 1);
}

// A pose file is written whole (`synth --truth`): a write that fails part-way
// (here a file size limit, as on a full disk) leaves the old file as it was.
static void test_pose_file_whole(void)
{
    sp_param params[40];
    double p[40];
    memset(params, 0, sizeof params);
    for (int i = 0; i < 40; ++i) {
        snprintf(params[i].name, sizeof params[i].name, "joint_%02d.rx", i);
        params[i].min = -1, params[i].max = 1;
        p[i] = 0.01 * i;
    }
    const char* path = sp_test_tmp_path("whole_pose.json");
    sp_error err = {0};
    ENSURE(sp_pose_write(path, params, 2, p, &err) == SP_OK);
    double back[2] = {0};
    ENSURE(sp_pose_read(path, params, 2, back, NULL, &err) == SP_OK && back[1] == p[1]);
    FILE* f = fopen(path, "rb");
    char before[4096];
    size_t n = f ? fread(before, 1, sizeof before, f) : 0;
    if (f) fclose(f);
    ENSURE(n > 10 && n < 256);
    int pid = sp_fixture_fork_file_limit(256);
    if (pid == 0) {
        sp_error e = {0};
        sp_result r = sp_pose_write(path, params, 40, p, &e); // about 1 KB
        fprintf(stderr, "  under a 256-byte file limit: %s\n", r == SP_OK ? "written" : e.text);
        _exit(r == SP_ERR_IO && strstr(e.text, "whole_pose.json") ? 0 : 1);
    }
    ENSURE(sp_fixture_child_passed(pid));
    char after[4096];
    f = fopen(path, "rb");
    size_t m = f ? fread(after, 1, sizeof after, f) : 0;
    if (f) fclose(f);
    ENSURE(m == n && !memcmp(before, after, n));
    unlink(path);
}

// A pose file is one JSON document naming each key once, as a stroke file
// is (sp_json_document_check): text after it and a parameter given twice
// were taken (the last value silently won); a NUL ended it silently, and
// "parameters" given twice kept the first (an outside review).
static void test_pose_file_strict(void)
{
    sp_param params[2] = {{.name = "head.rx", .min = -1, .max = 1}, {.name = "head.ry", .min = -1, .max = 1}};
    const struct {
        const char* text;
        size_t len; // 0: strlen
        const char* said;
    } cases[] = {
        {"{\"parameters\": {\"head.rx\": 0.1}}\n", 0, NULL},
        {"{\"parameters\": {\"head.rx\": 0.1}} x\n", 0, "pose.json: text after the JSON document, line 1"},
        {"{\"parameters\": {\"head.rx\": 0.1, \"head.rx\": 0.2}}", 0, "pose.json: key \"head.rx\" given twice"},
        {"{\"parameters\": {\"head.rx\": 0.1}, \"parameters\": {}}", 0, "pose.json: key \"parameters\" given twice"},
        {"{\"parameters\": {\"head.rx\": 0.1}}\0{\"garbage", 42, "pose.json: text after the JSON document, line 1"},
        {"{\"parameters\": {\"head.rx\": 0.1", 0,
         "pose.json: malformed JSON near line 1, column 30, at '1' (the file ends before the document does: cut short?)"},
        // One line as Python's json writes it: where, what stands there, and why.
        {"{\"parameters\": {\"head.rx\": NaN, \"head.ry\": 0.2}}", 0,
         "pose.json: malformed JSON near line 1, column 28, at 'NaN, \"head.ry\": ' (NaN and infinity are not JSON numbers)"},
        // Not a NaN, only a word that begins like one; bytes past ASCII escaped (a UTF-16 file's BOM).
        {"{\"parameters\": nancy}", 0, "pose.json: malformed JSON near line 1, column 16, at 'nancy}'"},
        {"\xff\xfe{\"parameters\"", 0, "pose.json: malformed JSON near line 1, column 1, at '\\xFF\\xFE{\"parameters\"'"},
        {" \n ", 0, "pose.json: the file is empty (no JSON document)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        double p[2] = {0};
        sp_error err = {0};
        size_t len = cases[i].len ? cases[i].len : strlen(cases[i].text);
        sp_result r = sp_pose_parse(cases[i].text, len, "pose.json", params, 2, p, NULL, &err);
        fprintf(stderr, "  %s -> %s\n", cases[i].text, r == SP_OK ? "read" : err.text);
        ENSURE(cases[i].said ? r != SP_OK && !strcmp(err.text, cases[i].said) : r == SP_OK && p[0] == 0.1);
    }
}

// A device or a pipe given where a file is read (a rig, a pose, a model, a
// stroke file, a PNG to add) is refused in one line, not read without end:
// /dev/zero used to fill the memory of `inspect --rig`.
static void test_device_inputs(void)
{
    // %1$s the device or pipe, %2$s the source tree, %3$s a stroke file, %4$s an output.
    enum { DEVICE, FIFO, FIFO_SO }; // a named pipe with no writer: opening it to read used to wait forever
    const struct {
        const char* fmt;
        int kind;
    } cases[] = {{"inspect --rig '%1$s'", DEVICE},
                 {"export --rig '%2$s/assets/tail.glb' --pose '%1$s' --out '%4$s'", DEVICE},
                 {"classify --model '%1$s' --strokes /dev/null", DEVICE},
                 {"pose --rig '%2$s/assets/tail.glb' --strokes '%1$s' --out '%4$s'", DEVICE},
                 {"pose --rig '%1$s' --strokes /dev/null", DEVICE},
                 {"inspect --rig '%1$s'", FIFO},
                 {"export --rig '%2$s/assets/tail.glb' --pose '%1$s' --out '%4$s'", FIFO},
                 {"classify --model '%1$s' --strokes '%3$s'", FIFO},
                 {"pose --rig '%2$s/assets/tail.glb' --strokes '%1$s' --out '%4$s'", FIFO},
                 {"inspect --rig '%1$s'", FIFO_SO}}; // a black-box rig's plugin
    // Copies: sp_test_tmp_path's buffers are reused after eight calls.
    char out[1024], fifo[1024], fifo_so[1024], strokes[1024], log[1024], cmd[3000];
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("device_inputs.glb"));
    snprintf(fifo, sizeof fifo, "%s", sp_test_tmp_path("device_inputs.fifo"));
    snprintf(fifo_so, sizeof fifo_so, "%s", sp_test_tmp_path("device_inputs.so"));
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("device_inputs.json"));
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("device_inputs.txt"));
    unlink(fifo), unlink(fifo_so);
    ENSURE(mkfifo(fifo, 0600) == 0 && mkfifo(fifo_so, 0600) == 0);
    snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s/assets/tail.glb' --seed 1 --out '%s' > /dev/null", SP_SKETCHPOSE,
             SP_SOURCE_DIR, strokes);
    ENSURE(run(cmd) == 0);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char args[1200];
        const char* input = cases[i].kind == FIFO ? fifo : cases[i].kind == FIFO_SO ? fifo_so : "/dev/zero";
        snprintf(args, sizeof args, cases[i].fmt, input, SP_SOURCE_DIR, strokes, out);
        // timeout: a reader that does not refuse would run until the memory is gone, or wait for a writer.
        snprintf(cmd, sizeof cmd, "timeout 60 '%s' %s 2>'%s' >/dev/null", SP_SKETCHPOSE, args, log);
        int rc = run(cmd);
        size_t n = 0;
        char* text = sp_fixture_file_text(log, &n);
        fprintf(stderr, "  %s: exit %d, %s", args, rc, text);
        char said[1100];
        snprintf(said, sizeof said, "%s: not a regular file", cases[i].kind == DEVICE ? "" : strrchr(input, '/') + 1);
        ENSURE(rc == 1 && strstr(text, said) && strchr(text, '\n') == text + n - 1);
        ENSURE(access(out, F_OK) != 0);
        free(text);
    }
    unlink(fifo), unlink(fifo_so);
}

// The command's stderr (one line expected) after running `args` with exit rc.
static char* run_said(const char* args, int* rc)
{
    char log[1024], cmd[4096];
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("outputs_said.txt"));
    snprintf(cmd, sizeof cmd, "timeout 120 '%s' %s 2>'%s' >/dev/null", SP_SKETCHPOSE, args, log);
    *rc = run(cmd);
    char* text = sp_fixture_file_text(log, NULL);
    fprintf(stderr, "  %s\n    -> exit %d, %s", args, *rc, text);
    return text;
}

// Outputs are all or nothing and never an input: a command that fails
// after its work (a file size limit) leaves files it would have
// replaced as they were (they used to be deleted), an output that is a folder or
// in no folder is refused before the work, and an output that names an
// input or another output is refused (`pose --report` onto `--strokes`
// replaced the strokes with the report).
static void test_outputs_kept(void)
{
    char dir[1024], strokes[1200], said[1200], out[1200], report[1200], args[6000];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("outputs"));
    mkdir(dir, 0755);
    snprintf(strokes, sizeof strokes, "%s/s.json", dir);
    snprintf(said, sizeof said, "%s/said.txt", dir);
    snprintf(out, sizeof out, "%s/posed.glb", dir);
    snprintf(report, sizeof report, "%s/report.json", dir);
    const char* rig = SP_SOURCE_DIR "/assets/tail.glb";
    snprintf(args, sizeof args, "synth --rig '%s' --seed 2 --out '%s'", rig, strokes);
    int rc;
    free(run_said(args, &rc));
    ENSURE(rc == 0);
    FILE* o = fopen(out, "wb");
    ENSURE(o && fputs("old glb", o) >= 0 && fclose(o) == 0);
    FILE* r = fopen(report, "wb");
    ENSURE(r && fputs("old report", r) >= 0 && fclose(r) == 0);
    ENSURE(chmod(report, 0600) == 0);
    // Files of at most 10 KB: the report (1.5 KB) is written, the .glb
    // (750 KB) is not, after the solve.
    int pid = sp_fixture_fork_file_limit(10000);
    if (pid == 0) {
        int devnull = open("/dev/null", O_WRONLY), log = open(said, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (devnull < 0 || log < 0 || dup2(devnull, 1) < 0 || dup2(log, 2) < 0) _exit(9);
        snprintf(args, sizeof args, "%s/r.png", dir);
        execl(SP_SKETCHPOSE, SP_SKETCHPOSE, "pose", "--rig", rig, "--strokes", strokes, "--out", out, "--report", report,
              "--render", args, (char*)NULL);
        _exit(10);
    }
    int status = 0;
    ENSURE(waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 1);
    char* text = sp_fixture_file_text(said, NULL);
    fprintf(stderr, "  pose under a 10 KB file limit: %s", text);
    ENSURE(strstr(text, out) && !strstr(text, ".sp-") && strchr(text, '\n') == text + strlen(text) - 1);
    free(text);
    ENSURE(unlink(said) == 0);
    text = sp_fixture_file_text(out, NULL);
    ENSURE(!strcmp(text, "old glb"));
    free(text);
    text = sp_fixture_file_text(report, NULL);
    ENSURE(!strcmp(text, "old report"));
    free(text);
    // Nothing staged is left behind.
    char ls[1400];
    snprintf(ls, sizeof ls, "ls -A '%s' | grep -q -e part -e '^[.]sp-'", dir);
    ENSURE(run(ls) == 1); // grep found none
    // The same command that succeeds replaces them, keeping the report's permissions.
    snprintf(args, sizeof args, "pose --rig '%s' --strokes '%s' --out '%s' --report '%s'", rig, strokes, out, report);
    free(run_said(args, &rc));
    ENSURE(rc == 0);
    struct stat st;
    ENSURE(stat(out, &st) == 0 && st.st_size > 1000 && stat(report, &st) == 0 && (st.st_mode & 0777) == 0600);
    cJSON_Delete(sp_fixture_glb_json(out));
    // synth's strokes and their pose likewise: files of at most 4608 bytes
    // take the elephant's strokes (4.4 KB), not its pose (4.9 KB), so the
    // pose fails after the strokes were written (they replaced the old file).
    char pose_out[1200];
    snprintf(pose_out, sizeof pose_out, "%s/p.json", dir);
    r = fopen(pose_out, "wb");
    ENSURE(r && fputs("old pose", r) >= 0 && fclose(r) == 0);
    char* had = sp_fixture_file_text(report, NULL);
    pid = sp_fixture_fork_file_limit(4608);
    if (pid == 0) {
        int devnull = open("/dev/null", O_WRONLY);
        if (devnull < 0 || dup2(devnull, 1) < 0 || dup2(devnull, 2) < 0) _exit(9);
        execl(SP_SKETCHPOSE, SP_SKETCHPOSE, "synth", "--rig", SP_SOURCE_DIR "/assets/elephant.glb", "--seed", "3", "--out",
              report, "--truth", pose_out, (char*)NULL);
        _exit(10);
    }
    status = 0;
    ENSURE(waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 1);
    text = sp_fixture_file_text(pose_out, NULL);
    ENSURE(!strcmp(text, "old pose"));
    free(text);
    text = sp_fixture_file_text(report, NULL);
    ENSURE(!strcmp(text, had));
    free(text), free(had);
    ENSURE(run(ls) == 1);

    // Refused before the work, naming the option and the path.
    struct {
        const char* fmt;
        int rc;
        const char* said;
    } cases[] = {
        {"pose --rig '%1$s' --strokes '%2$s' --render '%3$s/folder.png'", 1, "--render %3$s/folder.png: is a folder, not a file"},
        {"pose --rig '%1$s' --strokes '%2$s' --out '%3$s/none/p.glb'", 1, "cannot write into folder '%3$s/none'"},
        {"pose --rig '%1$s' --strokes '%2$s' --report '%2$s'", 2,
         "--report %2$s is the same file as --strokes: it would be overwritten"},
        {"synth --rig '%1$s' --seed 1 --out '%3$s/t.json' --truth '%3$s/./t.json'", 2,
         "--truth %3$s/./t.json is the same file as --out: one would overwrite the other"},
        {"export --rig '%3$s/posed.glb' --out '%3$s/posed.glb'", 2, "--out %3$s/posed.glb is the same file as --rig"},
        {"animate --rig '%1$s' --strokes '%2$s' '%3$s/posed.glb' --out '%3$s/posed.glb'", 2,
         "--out %3$s/posed.glb is the same file as --strokes"},
        // A contact sheet too (said after the work, not naming the option).
        {"synth --drawings --sheet '%3$s/none/s.png'", 1, "--sheet %3$s/none/s.png: cannot write into folder '%3$s/none'"},
        {"synth --concepts --sheet '%3$s/none/s.png'", 1, "--sheet %3$s/none/s.png: cannot write into folder '%3$s/none'"},
        {"db review --db '%3$s/no.db' --sheet '%3$s/none/s.png'", 1, "--sheet %3$s/none/s.png: cannot write into folder"},
        // A name with a newline and an escape code in it: one line, both written out (an outside review).
        {"pose --rig '%1$s' --strokes '%2$s' --out '%3$s/none/a\nb\x1b[2J.glb'", 1,
         "--out %3$s/none/a\\nb\\x1b[2J.glb: cannot write into folder"},
    };
    struct stat before;
    ENSURE(stat(strokes, &before) == 0);
    snprintf(args, sizeof args, "%s/folder.png", dir);
    ENSURE(mkdir(args, 0755) == 0);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char said[2000];
        snprintf(args, sizeof args, cases[i].fmt, rig, strokes, dir);
        snprintf(said, sizeof said, cases[i].said, rig, strokes, dir);
        text = run_said(args, &rc);
        ENSURE(rc == cases[i].rc && strstr(text, said) && strchr(text, '\n') == text + strlen(text) - 1);
        free(text);
    }
    ENSURE(stat(strokes, &st) == 0 && st.st_size == before.st_size && st.st_mtime == before.st_mtime);
    ENSURE(access(strcat(dir, "/t.json"), F_OK) != 0);
}

// A file that a glTF input reads is an input too: `pose --report` onto a
// .gltf's external buffer replaced the rig's vertices with the report, and
// `--render` onto its texture the picture. Refused before the work, for a
// .gltf and a .glb's JSON chunk alike, the files left as they were.
static void test_outputs_off_gltf_files(void)
{
    char dir[1024], gltf[1200], glb[1200], bin[1200], png[1200], args[6000];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("gltf_files"));
    mkdir(dir, 0755);
    snprintf(gltf, sizeof gltf, "%s/ext.gltf", dir);
    snprintf(glb, sizeof glb, "%s/ext.glb", dir);
    snprintf(bin, sizeof bin, "%s/ext data.bin", dir);
    snprintf(png, sizeof png, "%s/skin.png", dir);
    // Read as far as its file names only: the check runs before any loading.
    const char* json = "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"ext%20data.bin\", \"byteLength\": 4}, "
                       "{\"uri\": \"data:application/octet-stream;base64,AAAA\", \"byteLength\": 3}], "
                       "\"images\": [{\"uri\": \"skin.png\"}, {\"uri\": \"/tmp/abs.png\"}]}  ";
    FILE* f = fopen(gltf, "wb");
    ENSURE(f && fputs(json, f) >= 0 && fclose(f) == 0);
    uint32_t len = (uint32_t)strlen(json), head[5] = {0x46546C67u, 2, 20 + len, len, 0x4E4F534Au}; // "glTF", "JSON"
    f = fopen(glb, "wb");
    ENSURE(f && fwrite(head, sizeof head, 1, f) == 1 && fputs(json, f) >= 0 && fclose(f) == 0);
    f = fopen(bin, "wb");
    ENSURE(f && fputs("abcd", f) >= 0 && fclose(f) == 0);
    f = fopen(png, "wb");
    ENSURE(f && fputs("not a png", f) >= 0 && fclose(f) == 0);
    snprintf(args, sizeof args, "%s/rig", dir);
    unlink(args);
    ENSURE(symlink("ext.gltf", args) == 0);
    char strokes[1200]; // never read: the check comes first
    snprintf(strokes, sizeof strokes, "%s/s.json", dir);
    f = fopen(strokes, "wb");
    ENSURE(f && fputs("{}", f) >= 0 && fclose(f) == 0);
    const char* cases[][2] = {
        {"pose --rig '%1$s/ext.gltf' --strokes '%2$s' --report '%1$s/ext data.bin'",
         "--report %1$s/ext data.bin is a file that --rig %1$s/ext.gltf reads (%1$s/ext data.bin): it would be overwritten"},
        {"render --rig '%1$s/ext.glb' --out '%1$s/./skin.png'", "--out %1$s/./skin.png is a file that --rig %1$s/ext.glb reads"},
        {"pose --rig '%1$s/ext.gltf' --strokes '%2$s' --render '%1$s/skin.png'", "--render %1$s/skin.png is a file that --rig"},
        {"db add-part --db '%1$s/p.db' '%1$s/ext.gltf' --preview '%1$s/skin.png'",
         "--preview %1$s/skin.png is a file that the part %1$s/ext.gltf reads"},
        // The loader goes by the content: a link without the extension is a glTF too.
        {"pose --rig '%1$s/rig' --strokes '%2$s' --report '%1$s/ext data.bin'",
         "--report %1$s/ext data.bin is a file that --rig"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char said[2000];
        int rc;
        snprintf(args, sizeof args, cases[i][0], dir, strokes);
        snprintf(said, sizeof said, cases[i][1], dir, strokes);
        char* text = run_said(args, &rc);
        ENSURE(rc == 2 && strstr(text, said) && strchr(text, '\n') == text + strlen(text) - 1);
        free(text);
    }
    char* text = sp_fixture_file_text(bin, NULL);
    ENSURE(!strcmp(text, "abcd"));
    free(text);
    text = sp_fixture_file_text(png, NULL);
    ENSURE(!strcmp(text, "not a png"));
    free(text);
    snprintf(args, sizeof args, "%s/p.db", dir);
    ENSURE(access(args, F_OK) != 0); // refused before a database was made
}

// `sketchpose synth` of the rig's first abstraction at a seed, into path.
static void synth_strokes(const char* rig, int seed, const char* path)
{
    char args[4000];
    snprintf(args, sizeof args, "'%s' synth --rig '%s' --seed %d --out '%s' 2>/dev/null", SP_SKETCHPOSE, rig, seed, path);
    ENSURE(run(args) == 0);
}

// One stroke on a 640 x 480 canvas, into path.
static void write_one_stroke(const char* path, const sp_vec2* pts, int n)
{
    sp_sketch sk = {.canvas_w = 640, .canvas_h = 480};
    sp_error err = {0};
    ENSURE(sp_sketch_add_stroke(&sk, pts, NULL, n) == SP_OK && sp_sketch_write_json(path, &sk, &err) == SP_OK);
    sp_sketch_free(&sk);
}

// `sketchpose ARGS --report REPORT`, quiet, exit 0; the report read back.
static cJSON* report_of(const char* args, const char* report)
{
    char cmd[6000];
    snprintf(cmd, sizeof cmd, "'%s' %s --report '%s' >/dev/null 2>&1", SP_SKETCHPOSE, args, report);
    ENSURE(run(cmd) == 0);
    char* text = sp_fixture_file_text(report, NULL);
    cJSON* j = cJSON_Parse(text);
    free(text);
    ENSURE(j);
    return j;
}

// The cartoon man's draw-over from one stroke (n points) to another; its report.
static cJSON* drawover_man(const sp_vec2* on_pts, const sp_vec2* to_pts, int n, const char* tag)
{
    char on[1100], to[1100], rep[1100], args[4000];
    snprintf(on, sizeof on, "%s_on.json", sp_test_tmp_path(tag));
    snprintf(to, sizeof to, "%s_to.json", sp_test_tmp_path(tag));
    snprintf(rep, sizeof rep, "%s_report.json", sp_test_tmp_path(tag));
    write_one_stroke(on, on_pts, n);
    write_one_stroke(to, to_pts, n);
    snprintf(args, sizeof args, "drawover --rig '%s/assets/cartoon_man.glb' --on '%s' --to '%s'", SP_SOURCE_DIR, on, to);
    return report_of(args, rep);
}

// The report printed on stdout once, also when --report names stdout
// (DESIGN's `--report /dev/stdout >> log` appended it twice: two JSON
// documents, which no reader takes).
static void test_report_on_stdout_once(void)
{
    char strokes[1100], log[1100], args[4000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("stdout_once.json"));
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("stdout_once.log"));
    const char* rig = SP_SOURCE_DIR "/assets/tail.glb";
    synth_strokes(rig, 2, strokes);
    const char* reports[] = {"/dev/stdout", "-", "/dev/fd/1", "'%s'"};
    for (size_t i = 0; i < sizeof reports / sizeof reports[0]; ++i) {
        char report[1200];
        snprintf(report, sizeof report, reports[i], log);
        FILE* f = fopen(log, "wb");
        ENSURE(f && fputs("[1]\n", f) >= 0 && fclose(f) == 0);
        snprintf(args, sizeof args, "'%s' pose --rig '%s' --strokes '%s' --report %s >> '%s' 2>/dev/null", SP_SKETCHPOSE, rig,
                 strokes, report, log);
        int rc = run(args);
        char* text = sp_fixture_file_text(log, NULL);
        // A file named as itself (the last) is replaced whole, the rest appended to.
        const char* doc = i + 1 < sizeof reports / sizeof reports[0] ? strstr(text, "]\n") + 2 : text;
        const char* end = NULL;
        cJSON* j = cJSON_ParseWithOpts(doc, &end, false);
        fprintf(stderr, "  --report %s: exit %d, %zu bytes\n", report, rc, strlen(text));
        ENSURE(rc == 0 && j && cJSON_GetObjectItem(j, "parameters") && strspn(end, " \n") == strlen(end));
        cJSON_Delete(j);
        free(text);
    }
}

// A file written to stdout has it to itself: `export --out /dev/stdout`
// followed its glTF with the command's summary and `pose --render
// /dev/stdout` its PNG with the report (an outside review of the README).
static void test_file_on_stdout_alone(void)
{
    char strokes[1100], pose[1100], out[1100], args[4000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("alone_strokes.json"));
    snprintf(pose, sizeof pose, "%s", sp_test_tmp_path("alone_pose.json"));
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("alone_out"));
    const char* rig = SP_SOURCE_DIR "/assets/tail.glb";
    synth_strokes(rig, 2, strokes);
    FILE* f = fopen(pose, "wb");
    ENSURE(f && fputs("{\"parameters\": {}}\n", f) >= 0 && fclose(f) == 0);
    snprintf(args, sizeof args, "'%s' export --rig '%s' --pose '%s' --out /dev/stdout > '%s' 2>/dev/null", SP_SKETCHPOSE, rig,
             pose, out);
    ENSURE(run(args) == 0);
    char* text = sp_fixture_file_text(out, NULL);
    const char* end = NULL;
    cJSON* j = cJSON_ParseWithOpts(text, &end, false);
    ENSURE(j && cJSON_GetObjectItem(j, "asset") && strspn(end, " \n") == strlen(end)); // a glTF, nothing after it
    cJSON_Delete(j);
    free(text);
    snprintf(args, sizeof args, "'%s' pose --rig '%s' --strokes '%s' --render /dev/stdout > '%s' 2>/dev/null", SP_SKETCHPOSE, rig,
             strokes, out);
    ENSURE(run(args) == 0);
    size_t n = 0;
    unsigned char* png = (unsigned char*)sp_fixture_file_text(out, &n);
    // A PNG ends with its IEND chunk and its CRC: nothing after it.
    ENSURE(png && n > 12 && !memcmp(png + 1, "PNG", 3) && !memcmp(png + n - 8, "IEND", 4));
    free(png);
}

// A solve out of iterations is reported so, also when the cap falls between
// two stages of its plan: the next stage ended at once, "converged", with
// no iteration left (the cartoon man's outline drawn as one loop: its
// ordered stage ends after 10 iterations here, the closest-point stage
// that follows had none).
static void test_max_iterations_between_stages(void)
{
    char strokes[1100], report[1100], args[4000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("cap_strokes.json"));
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("cap_report.json"));
    const char* rig = SP_SOURCE_DIR "/assets/cartoon_man.glb";
    snprintf(args, sizeof args, "'%s' synth --rig '%s' --abstraction outline --seed 1 --amplitude 0.1 --out '%s' 2>/dev/null",
             SP_SKETCHPOSE, rig, strokes);
    ENSURE(run(args) == 0);
    const int caps[] = {10, 1000};
    for (int i = 0; i < 2; ++i) {
        snprintf(args, sizeof args, "pose --rig '%s' --abstraction outline --strokes '%s' --max-iterations %d", rig, strokes,
                 caps[i]);
        cJSON* j = report_of(args, report);
        const char* stopped = cJSON_GetStringValue(cJSON_GetObjectItem(j, "stopped"));
        int its = (int)cJSON_GetNumberValue(cJSON_GetObjectItem(j, "iterations"));
        fprintf(stderr, "  --max-iterations %d: %s after %d iterations, %d rounds\n", caps[i], stopped, its,
                (int)cJSON_GetNumberValue(cJSON_GetObjectItem(j, "icp_rounds")));
        // Uncapped, it settles (stalled or converged) well within 1000.
        ENSURE(stopped && (!strcmp(stopped, "max_iterations") == (i == 0)) && (i == 1 || its == caps[i]) && its < 1000);
        cJSON_Delete(j);
    }
    // A fit cut short says the cap stopped it, not that the abstraction cannot
    // reach the strokes (an outside review: a --max-ms 5 fit was told so, and
    // the same strokes fit at 1.2 px).
    snprintf(args, sizeof args, "'%s' synth --rig '%s' --seed 2 --amplitude 0.9 --out '%s' 2>/dev/null", SP_SKETCHPOSE, rig,
             strokes);
    ENSURE(run(args) == 0);
    snprintf(args, sizeof args, "pose --rig '%s' --strokes '%s' --max-iterations 1", rig, strokes);
    cJSON* j = report_of(args, report);
    const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
    fprintf(stderr, "  --max-iterations 1: %s\n", note ? note : "(no note)");
    ENSURE(note && strstr(note, "best effort: the iteration cap stopped the solve first") && !strstr(note, "cannot reach"));
    cJSON_Delete(j);
}

// --render's picture is the strokes' canvas, at most 4096 px on its longer
// side and 16 on its shorter: an A4 drawing's viewBox (21000 x 29700)
// failed after the solve ("exceeds the GL limit"), one of 12000 x 9000 took
// 52 s and 4.3 GB, and a canvas of 8 x 6 gave an 8 x 6 picture.
static void test_render_size(void)
{
    char strokes[1100], scaled[1100], png[1100], args[4000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("size_strokes.json"));
    snprintf(scaled, sizeof scaled, "%s", sp_test_tmp_path("size_scaled.json"));
    snprintf(png, sizeof png, "%s", sp_test_tmp_path("size.png"));
    const char* rig = SP_SOURCE_DIR "/assets/tail.glb";
    synth_strokes(rig, 2, strokes);
    sp_sketch sk;
    sp_error err = {0};
    ENSURE(sp_sketch_read_json(strokes, &sk, &err) == SP_OK && sk.canvas_w == 640 && sk.canvas_h == 480);
    const struct {
        double k;
        unsigned w, h;
    } cases[] = {{1, 640, 480}, {20, 4096, 3072}, {0.02, 21, 16}};
    for (int c = 0; c < 3; ++c) {
        sp_sketch big = {.canvas_w = 640 * cases[c].k, .canvas_h = 480 * cases[c].k};
        for (int i = 0; i < sk.stroke_count; ++i) {
            sp_vec2* xy = malloc(sizeof(sp_vec2) * (size_t)sk.strokes[i].count);
            ENSURE(xy);
            for (int q = 0; q < sk.strokes[i].count; ++q)
                xy[q] = (sp_vec2){sk.strokes[i].points[q].x * cases[c].k, sk.strokes[i].points[q].y * cases[c].k};
            ENSURE(sp_sketch_add_stroke(&big, xy, NULL, sk.strokes[i].count) == SP_OK);
            free(xy);
        }
        ENSURE(sp_sketch_write_json(scaled, &big, &err) == SP_OK);
        sp_sketch_free(&big);
        snprintf(args, sizeof args, "'%s' pose --rig '%s' --strokes '%s' --render '%s' >/dev/null 2>&1", SP_SKETCHPOSE, rig,
                 scaled, png);
        ENSURE(run(args) == 0);
        unsigned char head[24];
        FILE* f = fopen(png, "rb");
        ENSURE(f && fread(head, 1, 24, f) == 24 && fclose(f) == 0);
        unsigned w = (unsigned)head[16] << 24 | head[17] << 16 | head[18] << 8 | head[19];
        unsigned h = (unsigned)head[20] << 24 | head[21] << 16 | head[22] << 8 | head[23];
        fprintf(stderr, "  canvas %g x %g: picture %u x %u\n", 640 * cases[c].k, 480 * cases[c].k, w, h);
        ENSURE(w == cases[c].w && h == cases[c].h);
    }
    sp_sketch_free(&sk);
}

// One stroke for a five-curve stick figure: the note names the curves left
// without a stroke and the curve the stroke took (a raised arm drawn alone
// went to the spine and folded the figure with an empty note); every curve
// drawn, no such note.
static void test_note_unmatched_curves(void)
{
    char strokes[1100], report[1100], args[4000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("one_stroke.json"));
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("one_stroke_report.json"));
    const char* rig = SP_SOURCE_DIR "/assets/cartoon_man.glb";
    const sp_vec2 arm[] = {{355, 205}, {380, 170}, {400, 130}, {410, 100}};
    write_one_stroke(strokes, arm, 4);
    for (int all = 0; all < 2; ++all) {
        if (all) synth_strokes(rig, 3, strokes);
        snprintf(args, sizeof args, "pose --rig '%s' --strokes '%s'", rig, strokes);
        cJSON* j = report_of(args, report);
        const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
        fprintf(stderr, "  %s: note \"%s\"\n", all ? "every curve drawn" : "one stroke", note ? note : "(none)");
        ENSURE(note && (strstr(note, "4 curves without a stroke") != NULL) == !all &&
               (strstr(note, "stroke 0 '") != NULL) == !all);
        cJSON_Delete(j);
    }
}

// More strokes than curves (outside reviews' drawings of the cartoon man,
// tests/data/posing): a line traced twice, every line traced twice, dot
// eyes, legs drawn together, a line of action. The retrace and the dots are left unused and named, and the posed
// limbs keep their strokes: the retraced leg took the raised arm's curve
// (30 px), every line twice folded the figure (31 px), and a dot refused
// the whole drawing.
static void test_pose_surplus_strokes(void)
{
    const struct {
        const char *file, *said;
        int unused;
        double mean_below; // 0: 2 px
    } cases[] = {{"leg_retraced", "1 stroke left unused: 4 (traced over stroke 5)", 1, 0},
                 {"overdrawn", "(traced over stroke 7)", 5, 0},
                 {"dot_eyes", "6 (a dot), 7 (a dot)", 3, 0},
                 // Lines that only look like a retrace stay when leaving them
                 // out fits worse (a second review: legs drawn together with a
                 // head circle lost a leg, 23.8 px; a line of action beside the
                 // spine kept, the spine left out, 14.7 px).
                 {"legs_together_head", "1 stroke left unused: 5", 1, 0},
                 {"line_of_action", "1 stroke left unused: 0", 1, 0},
                 // One stroke over the curves, the arms raised (a third
                 // review): assigned against the rest pose, the head circle,
                 // a ground line or an arm's second piece took the spine's or
                 // an arm's curve and the figure folded (8-30 px mean).
                 {"arms_up_head_circle", "1 stroke left unused: 1 (the rest fit better without it)", 1, 0},
                 {"arms_up_ground", "1 stroke left unused: 5 (the rest fit better without it)", 1, 0},
                 // A line drawn in pieces, end to end, is one curve's line
                 // (a review against the paper: one piece was left out as a
                 // stray and the limb fitted short, the arm ending at the
                 // head, a foot at knee height at 0.96 px, a head folded
                 // into the chest at 0.58; five lines in ten pieces 18 px).
                 {"arms_up_arm_in_two", "strokes 1+2 taken as one line (drawn in pieces)", 0, 0},
                 {"leg_in_two", "strokes 3+4 taken as one line (drawn in pieces)", 0, 0},
                 {"spine_in_two", "strokes 0+1 taken as one line (drawn in pieces)", 0, 0},
                 {"star_in_pieces", "strokes 0+1, 2+3, 4+5, 6+7, 8+9 taken as one line each", 0, 0},
                 // A second review: pieces put down back over the last (the
                 // usual way) were never joined; with one stroke over, the
                 // spine going on into a leg took the only join.
                 {"leg_overlap", "strokes 3+4 taken as one line (drawn in pieces)", 0, 0},
                 // (Drawn whole, this figure fits at 2.8 px.)
                 {"leg_in_two_spine_on", "strokes 4+5 taken as one line (drawn in pieces)", 0, 3},
                 {"hatched", "taken as one line each (drawn in pieces)", 2, 0},
                 // The spine lifted where the arms start: its pieces were
                 // never joined (a stroke passing there is a junction, one
                 // ending there is not); every line in three pieces, the
                 // arms' pieces joined across the chest (one join where
                 // three or more ends meet, ranked by the way the pieces go
                 // over more of their length).
                 {"spine_lifted_at_chest", "strokes 0+1 taken as one line (drawn in pieces)", 0, 0},
                 {"lines_in_three", "strokes 0+1+2, 3+4+5, 6+7+8, 9+10+11, 12+13+14 taken as one line each", 0, 0},
                 // A third review: a retrace counted as ink left out kept an
                 // arm's pieces apart.
                 {"arm_in_two_retraced", "1 stroke left unused: 1 (traced over stroke 0); strokes 3+4 taken as one line", 1, 0},
                 {"crouch_head_circle", "1 stroke left unused: 1 (the rest fit better without it)", 1, 0},
                 // A fourth review: the fit without the ground line, solved
                 // from another start buffer than `pose` gives, stayed at
                 // 21.8 px (14.1 kept); two strays took an arm's curve at a
                 // 2.2 px fit, under the loose-fit thresholds.
                 {"arms_straight_up_ground", "1 stroke left unused: 5 (the rest fit better without it)", 1, 0},
                 {"arms_up_two_strays", "2 strokes left unused: 5 (the rest fit better without it), 6 (the rest", 2, 0}};
    char report[1100], args[4000];
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("surplus_report.json"));
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        snprintf(args, sizeof args, "pose --rig '%s/assets/cartoon_man.glb' --strokes '%s/tests/data/posing/cartoon_man_%s.json'",
                 SP_SOURCE_DIR, SP_SOURCE_DIR, cases[i].file);
        cJSON* j = report_of(args, report);
        const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
        double mean = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
        double max = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "max_error_px"));
        int unused = (int)cJSON_GetNumberValue(cJSON_GetObjectItem(j, "unused_strokes"));
        fprintf(stderr, "  %s: mean %.2f px, max %.1f px, note \"%s\"\n", cases[i].file, mean, max, note ? note : "");
        ENSURE(note && strstr(note, cases[i].said) && unused == cases[i].unused);
        ENSURE(mean < (cases[i].mean_below > 0 ? cases[i].mean_below : 2) && max < 13);
        cJSON_Delete(j);
    }
}

// A line drawn in pieces in a draw-over is one curve's line too (a third
// review: the raised arm redrawn in two pieces kept half, 0.19 px, where
// whole it fits at 0.63); and a curve's `reversed` is its stroke's, not the
// joined line's (an arm whose first piece runs to the shoulder).
static void test_drawover_in_pieces(void)
{
    char report[1100], args[4000];
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("in_pieces_report.json"));
    snprintf(args, sizeof args,
             "drawover --rig '%s/assets/cartoon_man.glb' --on '%s/tests/data/posing/cartoon_man_arm_on.json' --to "
             "'%s/tests/data/posing/cartoon_man_arm_to_in_two.json'",
             SP_SOURCE_DIR, SP_SOURCE_DIR, SP_SOURCE_DIR);
    cJSON* j = report_of(args, report);
    const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
    double mean = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
    fprintf(stderr, "  draw-over in two pieces: %.2f px, note \"%s\"\n", mean, note ? note : "");
    ENSURE(note && strstr(note, "strokes 0+1 taken as one line") && mean < 1);
    ENSURE((int)cJSON_GetNumberValue(cJSON_GetObjectItem(j, "unused_strokes")) == 0);
    cJSON_Delete(j);
    snprintf(args, sizeof args,
             "pose --rig '%s/assets/cartoon_man.glb' --strokes '%s/tests/data/posing/cartoon_man_arm_in_two_backwards.json'",
             SP_SOURCE_DIR, SP_SOURCE_DIR);
    j = report_of(args, report);
    note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
    ENSURE(note && strstr(note, "strokes 1+5 taken as one line"));
    const cJSON* c;
    int arm = 0;
    cJSON_ArrayForEach(c, cJSON_GetObjectItem(j, "curves"))
    {
        if (strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(c, "curve")), "arm_l")) continue;
        ENSURE(cJSON_GetNumberValue(cJSON_GetObjectItem(c, "stroke")) == 1 && cJSON_IsTrue(cJSON_GetObjectItem(c, "reversed")));
        ++arm;
    }
    ENSURE(arm == 1);
    cJSON_Delete(j);
}

// Fewer strokes than curves: a figure drawn with a limb or the spine left
// out (the outside reviews' drawings, strokes removed). The strokes go to
// the curves the joints tell, as when every curve is drawn: assigned on
// shape alone against the rest pose, a raised arm took the spine and the
// spine an arm (8-20 px mean, the figure bent double).
static void test_pose_fewer_strokes(void)
{
    const struct {
        const char* file;
        int drop[2];
        const char* missing; // the curve said to have no stroke
    } cases[] = {{"arms_up_head_circle", {1, 3}, "('arm_r')"},
                 {"arms_up_head_circle", {1, 2}, "('arm_l')"},
                 {"arms_up_head_circle", {1, 4}, "('leg_r')"},
                 {"arms_up_head_circle", {1, 5}, "('leg_l')"},
                 {"stand_up85", {0, -1}, "('spine')"}};
    char strokes[1100], report[1100], args[4000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("fewer_strokes.json"));
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("fewer_report.json"));
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char src[1100];
        snprintf(src, sizeof src, "%s/tests/data/posing/cartoon_man_%s.json", SP_SOURCE_DIR, cases[i].file);
        sp_sketch all, some = {0};
        sp_error err = {0};
        ENSURE(sp_sketch_read_json(src, &all, &err) == SP_OK);
        some.canvas_w = all.canvas_w, some.canvas_h = all.canvas_h;
        for (int k = 0; k < all.stroke_count; ++k)
            if (k != cases[i].drop[0] && k != cases[i].drop[1])
                ENSURE(sp_sketch_add_stroke(&some, all.strokes[k].points, NULL, all.strokes[k].count) == SP_OK);
        ENSURE(sp_sketch_write_json(strokes, &some, &err) == SP_OK);
        sp_sketch_free(&all), sp_sketch_free(&some);
        snprintf(args, sizeof args, "pose --rig '%s/assets/cartoon_man.glb' --strokes '%s'", SP_SOURCE_DIR, strokes);
        cJSON* j = report_of(args, report);
        const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
        double mean = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
        double max = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "max_error_px"));
        fprintf(stderr, "  %s without %d, %d: mean %.2f px, max %.1f px, note \"%s\"\n", cases[i].file, cases[i].drop[0],
                cases[i].drop[1], mean, max, note ? note : "");
        ENSURE(note && strstr(note, "1 curve without a stroke") && strstr(note, cases[i].missing));
        ENSURE(mean < 2 && max < 10);
        cJSON_Delete(j);
    }
    // An animator's drawings: the junctions tell an arm and a leg with no
    // spine apart (by shape the raised arm took the spine: 10.2 px), but
    // legs begun 14 px below the spine meet nothing there, and by the
    // junctions alone a leg took an arm's curve (7.7 px): the better fit of
    // the two assignments is kept.
    const struct {
        const char* file;
        const char* curves[5]; // the curve of each stroke
        double mean;
    } drawn[] = {{"arm_leg", {"arm_r", "leg_l"}, 2.0},
                 {"spine_legs_gap", {"spine", "leg_l", "leg_r"}, 5.0},
                 // A stroke alone has no junctions: tried on each curve (by
                 // shape the raised arm took the spine, 16.6 px).
                 {"arm_alone", {"arm_l"}, 2.0}};
    for (size_t i = 0; i < sizeof drawn / sizeof drawn[0]; ++i) {
        snprintf(args, sizeof args, "pose --rig '%s/assets/cartoon_man.glb' --strokes '%s/tests/data/posing/cartoon_man_%s.json'",
                 SP_SOURCE_DIR, SP_SOURCE_DIR, drawn[i].file);
        cJSON* j = report_of(args, report);
        double mean = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
        const cJSON* c;
        int right = 0, strokes = 0;
        cJSON_ArrayForEach(c, cJSON_GetObjectItem(j, "curves"))
        {
            const cJSON* st = cJSON_GetObjectItem(c, "stroke");
            if (!cJSON_IsNumber(st)) continue;
            int k = (int)cJSON_GetNumberValue(st);
            ++strokes;
            right += k >= 0 && k < 5 && drawn[i].curves[k] &&
                     !strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(c, "curve")), drawn[i].curves[k]);
        }
        fprintf(stderr, "  %s: mean %.2f px, %d of %d strokes on their curves\n", drawn[i].file, mean, right, strokes);
        ENSURE(mean < drawn[i].mean && right == strokes && strokes > 0);
        cJSON_Delete(j);
    }
}

// A figure drawn 85 px above where it stands (a jump; an outside review's
// drawings): closest points give a figure of vertical lines no pull upwards,
// and it stayed where it stood, "best effort" at 86 px; placed by its ordered
// pairs it rises to the drawing.
static void test_pose_drawn_higher(void)
{
    const char* names[] = {"stand_up85", "jump_up85"};
    char report[1100], args[4000];
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("higher_report.json"));
    for (int i = 0; i < 2; ++i) {
        snprintf(args, sizeof args, "pose --rig '%s/assets/cartoon_man.glb' --strokes '%s/tests/data/posing/cartoon_man_%s.json'",
                 SP_SOURCE_DIR, SP_SOURCE_DIR, names[i]);
        cJSON* j = report_of(args, report);
        double mean = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
        double diag = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "bbox_diagonal_px"));
        double ty = cJSON_GetNumberValue(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "parameters"), "root.ty"));
        fprintf(stderr, "  %s: mean %.2f px of %.0f, root.ty %.3f\n", names[i], mean, diag, ty);
        ENSURE(mean <= 0.01 * diag && ty > 0.35);
        cJSON_Delete(j);
    }
}

// The notes say why a fit is loose where the mean error does not (an
// outside review's drawings of the cartoon man): an outline drawn in two
// halves fitted with its raised arms down, 5.3 px on average but 57 px at
// the arms, with an empty note; a figure drawn 150 px left of where it
// stands was "a stroke missing?", where the root's translation had reached
// its bound.
static void test_pose_notes_say_why(void)
{
    const struct {
        const char *file, *abstraction, *said;
    } cases[] = {
        {"outline_halves", "outline", "loose fit: curve 'outline' lies up to "},
        {"left150", "stick", "root.tx stopped at its bound -0.6: the drawing lies beyond where the character may be moved"}};
    char report[1100], args[4000];
    snprintf(report, sizeof report, "%s", sp_test_tmp_path("why_report.json"));
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        snprintf(args, sizeof args,
                 "pose --rig '%s/assets/cartoon_man.glb' --abstraction %s --strokes '%s/tests/data/posing/cartoon_man_%s.json'",
                 SP_SOURCE_DIR, cases[i].abstraction, SP_SOURCE_DIR, cases[i].file);
        cJSON* j = report_of(args, report);
        const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
        fprintf(stderr, "  %s: note \"%s\"\n", cases[i].file, note ? note : "");
        ENSURE(note && strstr(note, cases[i].said));
        cJSON_Delete(j);
    }
}

// A draw-over of one arm moves that arm alone: RiggedFigure's upper arm is
// skinned to its spine at the shoulder, which made the spine a carrier, and
// the chest, the head and the other arm turned for a 0.46 px fit with no
// note (an outside review's strokes: the upper arm redrawn bent down).
static void test_drawover_arm_alone(void)
{
    const char* data = sp_test_data_dir();
    if (!data) SKIP("../shared/data absent");
    enum { N = 46 };
    sp_vec2 on[N], to[N];
    for (int i = 0; i < N; ++i) {
        double t = (double)i / (N - 1), u = 2 * t;
        on[i] = (sp_vec2){280 - 83 * t, 153 + 43 * t};
        to[i] = u < 1 ? (sp_vec2){280 - 5 * u, 153 + 47 * u} : (sp_vec2){275 + 15 * (u - 1), 200 + 50 * (u - 1)};
    }
    char on_f[1100], to_f[1100], rep[1100], args[4000];
    snprintf(on_f, sizeof on_f, "%s", sp_test_tmp_path("rf_arm_on.json"));
    snprintf(to_f, sizeof to_f, "%s", sp_test_tmp_path("rf_arm_to.json"));
    snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("rf_arm_report.json"));
    write_one_stroke(on_f, on, N);
    cJSON* same = NULL;
    for (int k = 0; k < 2; ++k) {
        write_one_stroke(to_f, k ? to : on, N);
        snprintf(args, sizeof args, "drawover --rig '%s/gltf/RiggedFigure/RiggedFigure.glb' --on '%s' --to '%s'", data, on_f,
                 to_f);
        cJSON* j = report_of(args, rep);
        if (!k) {
            same = j;
            continue;
        }
        // Against the same draw-over with nothing changed: which joints moved.
        double arm = 0, rest = 0;
        const cJSON *it, *p0 = cJSON_GetObjectItem(same, "parameters");
        cJSON_ArrayForEach(it, cJSON_GetObjectItem(j, "parameters"))
        {
            double d = fabs(it->valuedouble - cJSON_GetNumberValue(cJSON_GetObjectItem(p0, it->string)));
            bool on_arm =
                !strncmp(it->string, "node13.", 7) || !strncmp(it->string, "node14.", 7) || !strncmp(it->string, "node15.", 7);
            if (on_arm)
                arm = fmax(arm, d);
            else
                rest = fmax(rest, d);
        }
        double err_px = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
        fprintf(stderr, "  RiggedFigure's arm redrawn bent: %.2f px; the arm's joints moved up to %.2f, the rest %.4f\n", err_px,
                arm, rest);
        ENSURE(arm > 0.3 && rest < 1e-6 && err_px < 4);
        cJSON_Delete(j);
    }
    cJSON_Delete(same);
}

// Several curves drawn over at once each free their own joints: the
// cartoon man's leg, spine and head redrawn leaning (an outside review's
// strokes) fit as well as any two of them do, the spine leaning with them.
// Carriers were counted against the points of all the curves, so the
// spine's short curve freed nothing: 7.9 px, the chest bent into an S.
static void test_drawover_several_curves(void)
{
    char args[4000], rep[1100];
    snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("lean_report.json"));
    snprintf(args, sizeof args,
             "drawover --rig '%s/assets/cartoon_man.glb' --on '%s/tests/data/posing/cartoon_man_lean_on.json' --to "
             "'%s/tests/data/posing/cartoon_man_lean_to.json'",
             SP_SOURCE_DIR, SP_SOURCE_DIR, SP_SOURCE_DIR);
    cJSON* j = report_of(args, rep);
    double err_px = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px")), spine = 0;
    const cJSON* it;
    cJSON_ArrayForEach(it, cJSON_GetObjectItem(j, "parameters"))
    {
        if (!strncmp(it->string, "spine_", 6)) spine = fmax(spine, fabs(it->valuedouble));
    }
    fprintf(stderr, "  leg, spine and head redrawn: %.2f px, the spine turned up to %.2f rad\n", err_px, spine);
    ENSURE(err_px < 2.5 && spine > 0.1);
    cJSON_Delete(j);
}

// A single chain (the Khronos samples SimpleSkin and RiggedSimple, two
// bones above their placement) bends at its first joint too: the body's
// root is held only where limbs branch from it. SimpleSkin had nothing it
// could move, RiggedSimple only its top bone (an outside review's strokes).
static void test_drawover_single_chain(void)
{
    const char* data = sp_test_data_dir();
    if (!data) SKIP("../shared/data absent");
    const char* cases[][4] = {{"SimpleSkin/SimpleSkin.gltf", "simpleskin_line", "simpleskin_bent", "node2."},
                              {"RiggedSimple/RiggedSimple.glb", "riggedsimple_line", "riggedsimple_arc", "node2."}};
    for (int c = 0; c < 2; ++c) {
        char args[4000], rep[1100];
        snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("chain_report.json"));
        snprintf(args, sizeof args,
                 "drawover --rig '%s/gltf/%s' --on '%s/tests/data/posing/%s.json' --to '%s/tests/data/posing/%s.json'", data,
                 cases[c][0], SP_SOURCE_DIR, cases[c][1], SP_SOURCE_DIR, cases[c][2]);
        cJSON* j = report_of(args, rep);
        double err_px = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px")), first = 0;
        const cJSON* it;
        cJSON_ArrayForEach(it, cJSON_GetObjectItem(j, "parameters"))
        {
            if (!strncmp(it->string, cases[c][3], strlen(cases[c][3]))) first = fmax(first, fabs(it->valuedouble));
        }
        fprintf(stderr, "  %s redrawn bent: %.1f px, its first joint turned %.2f rad\n", cases[c][0], err_px, first);
        ENSURE(first > 0.2 && err_px < 20);
        cJSON_Delete(j);
    }
}

// Only the joints under a draw-over curve, the limb above them and the
// joints below them move: the cartoon man's left arm redrawn raised past
// what the arm allows twisted his spine, chest, neck and head to their
// bounds for a 1.0 px fit (an outside review's case); the arm alone now
// takes it, to about 2 px, the rest of him at rest. His hand alone redrawn
// raised moves the arm above it (a rule of carriers alone left the arm
// hanging, 35.7 px), still not the body.
static void test_drawover_only_carriers(void)
{
    const sp_vec2 strokes[2][2][5] = {
        {{{355, 205}, {372, 226}, {388, 245}, {404, 278}, {420, 310}},
         {{355, 205}, {378, 192}, {400, 180}, {420, 150}, {440, 120}}},
        {{{412, 282}, {418, 295}, {424, 308}, {428, 316}, {428, 316}},
         {{440, 215}, {448, 228}, {456, 240}, {461, 248}, {461, 248}}},
    };
    const char* what[2] = {"the left arm", "the left hand"};
    const double max_px[2] = {3.0, 1.0};
    for (int c = 0; c < 2; ++c) {
        cJSON* j = drawover_man(strokes[c][0], strokes[c][1], 4 + (c == 0), "carriers");
        double err_px = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px")), body = 0, arm = 0, upper = 0;
        const cJSON* it;
        cJSON_ArrayForEach(it, cJSON_GetObjectItem(j, "parameters"))
        {
            const char* n = it->string;
            double v = fabs(it->valuedouble - (n[strlen(n) - 1] == 's' && n[strlen(n) - 2] == '.' ? 1.0 : 0.0));
            bool arm_l = strstr(n, "_l.") && (strstr(n, "arm") || strstr(n, "clavicle") || strstr(n, "hand") ||
                                              strstr(n, "finger") || strstr(n, "thumb"));
            if (arm_l)
                arm = fmax(arm, v);
            else
                body = fmax(body, v);
            if (strstr(n, "upper_arm_l.")) upper = fmax(upper, v);
        }
        fprintf(stderr,
                "  %s redrawn raised: %.2f px; the left arm's joints moved up to %.2f (its upper arm %.2f), the rest %.4f\n",
                what[c], err_px, arm, upper, body);
        ENSURE(err_px < max_px[c] && upper > 0.1 && body < 1e-6);
        cJSON_Delete(j);
    }
}

// Redraw posing pairs a stroke with its curve the way the joints say: the
// stroke's end that meets another stroke goes with its curve's end that
// meets that stroke's curve. Paired by the least squared distance at the
// start, CesiumMan posed with arms raised and redrawn with arms hanging
// had both arms paired hand to shoulder and folded onto the chest (11.4 px,
// max 73.8, "converged"; now about 3 px, the head's line the worst), and
// one arm drawn across the chest, from rest, was a tangle (max 39.4 px).
// Hands drawn together over the head meet as the shoulders do: the whole
// figure's junctions tell them apart (9.0 px, max 95, one arm folded). Arms
// drawn raised, posed from a squat on the heels, ended upside down at 42 px
// with the directions held: a fit from a start of its own that ends poorly
// is solved again from rest. Strokes by outside reviews (tests/data/posing).
static void test_pose_directions_by_joints(void)
{
    const char* data = sp_test_data_dir();
    if (!data) SKIP("../shared/data absent");
    char args[6000], rig[1024], start[1100];
    snprintf(rig, sizeof rig, "%s/gltf/CesiumMan/CesiumMan.glb", data);
    snprintf(start, sizeof start, "%s", sp_test_tmp_path("arms_up_pose.json"));
    const char* rep = sp_test_tmp_path("directions_report.json");
    snprintf(args, sizeof args, "pose --rig '%s' --strokes '%s/tests/data/posing/cesiumman_arms_up.json'", rig, SP_SOURCE_DIR);
    cJSON* up = report_of(args, rep);
    cJSON* pose = cJSON_CreateObject();
    cJSON_AddItemToObject(pose, "parameters", cJSON_DetachItemFromObject(up, "parameters"));
    char* text = cJSON_Print(pose);
    write_text(start, text);
    free(text);
    cJSON_Delete(pose), cJSON_Delete(up);
    char squat[1100];
    snprintf(squat, sizeof squat, "%s/tests/data/posing/cesiumman_squat_pose.json", SP_SOURCE_DIR);
    const char* cases[4][2] = {{"cesiumman_arms_down", start},
                               {"cesiumman_arm_across", NULL},
                               {"cesiumman_hands_overhead", NULL},
                               {"cesiumman_arms_up", squat}};
    for (int k = 0; k < 4; ++k) {
        int n = snprintf(args, sizeof args, "pose --rig '%s' --strokes '%s/tests/data/posing/%s.json'", rig, SP_SOURCE_DIR,
                         cases[k][0]);
        if (cases[k][1]) snprintf(args + n, sizeof args - (size_t)n, " --start '%s'", cases[k][1]);
        cJSON* j = report_of(args, rep);
        double mean = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px")),
               max = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "max_error_px"));
        int reversed = 0;
        const cJSON* c;
        cJSON_ArrayForEach(c, cJSON_GetObjectItem(j, "curves")) reversed += cJSON_IsTrue(cJSON_GetObjectItem(c, "reversed"));
        fprintf(stderr, "  %s%s: %.2f px, max %.1f, %d curve(s) paired reversed\n", cases[k][0],
                !cases[k][1] ? " from rest"
                : k == 0     ? " from the arms raised"
                             : " from a squat",
                mean, max, reversed);
        ENSURE(reversed == 0 && mean < 4 && max < 25);
        cJSON_Delete(j);
    }
}

// A solve that holds some parameters (sp_solve_desc.active, as `animate`
// holds a clip's proportions) keeps them at the start's values also when
// its fit from that start is poor and the solve from rest wins: CesiumMan's
// arms drawn raised (tests/data/posing), posed from a squat with every
// joint turned far over, the hips' turn held at 0.3. The rest attempt set
// the held values back to rest, and `animate`'s proportions jumped to 1
// mid-clip (an outside review).
static void test_held_through_rest_attempt(void)
{
    const char* data = sp_test_data_dir();
    if (!data) SKIP("../shared/data absent");
    char rig_path[1024], squat[1100], strokes[1100];
    snprintf(rig_path, sizeof rig_path, "%s/gltf/CesiumMan/CesiumMan.glb", data);
    snprintf(squat, sizeof squat, "%s/tests/data/posing/cesiumman_squat_pose.json", SP_SOURCE_DIR);
    snprintf(strokes, sizeof strokes, "%s/tests/data/posing/cesiumman_arms_up.json", SP_SOURCE_DIR);
    sp_rig_handle* h = NULL;
    sp_error err = {0};
    ENSURE(sp_rig_handle_load(rig_path, &h, &err) == SP_OK);
    int P = sp_rig_handle_param_count(h), a = sp_rig_handle_pick_abstraction(h, NULL, &err);
    double* start = NULL;
    ENSURE(a >= 0 && sp_rig_handle_read_pose(h, squat, &start, NULL, &err) == SP_OK);
    const sp_param* params = sp_rig_handle_params(h);
    int held = -1;
    for (int q = 0; q < P && held < 0; ++q)
        if (params[q].channel == SP_CH_RY && sp_rig_handle_character(h)->rig.joints[params[q].joint].parent >= 0 &&
            params[q].max >= 0.3)
            held = q;
    ENSURE(held >= 0);
    // Every other joint turned far over (a start nothing drawn is near).
    for (int q = 0; q < P; ++q)
        if (sp_channel_is_rotation(params[q].channel) && sp_rig_handle_character(h)->rig.joints[params[q].joint].parent >= 0)
            start[q] = 0.8 * params[q].max;
    start[held] = 0.3;
    bool* active = malloc(sizeof(bool) * (size_t)P);
    double* p = malloc(sizeof(double) * (size_t)P);
    ENSURE(active && p);
    for (int q = 0; q < P; ++q)
        active[q] = q != held;
    sp_sketch sk = {0};
    ENSURE(sp_read_strokes(strokes, &sk, &err) == SP_OK);
    sp_camera cam = sp_rig_handle_camera(h, sk.canvas_w, sk.canvas_h);
    sp_solver* solver = NULL;
    ENSURE(sp_rig_handle_solver(h, a, &cam, &(sp_solve_desc){.active = active}, &solver, &err) == SP_OK);
    sp_solve_report rep;
    ENSURE(sp_solver_solve(solver, &sk, start, p, &rep, &err) == SP_OK);
    fprintf(stderr, "  arms up from a contorted squat, %s held at 0.3: %.2f px, the held value %.3f\n", params[held].name,
            rep.mean_error_px, p[held]);
    ENSURE(rep.mean_error_px < 4 && p[held] == 0.3);
    sp_solver_destroy(solver);
    sp_sketch_free(&sk);
    free(active), free(p), free(start);
    sp_rig_handle_free(h);
}

// A solve from the default pose is the solve from no start; started in the
// result's own buffer it ran the attempt from rest a second time (the
// aliased start held the first fit by then, so it did not look like rest):
// the same fit, the work paid again (arm_alone: 180 iterations, 128 now).
static void test_start_held_anywhere(void)
{
    sp_rig_handle* h = NULL;
    sp_error err = {0};
    ENSURE(sp_rig_handle_load(SP_SOURCE_DIR "/assets/cartoon_man.glb", &h, &err) == SP_OK);
    int P = sp_rig_handle_param_count(h), a = sp_rig_handle_pick_abstraction(h, NULL, &err);
    ENSURE(a >= 0);
    const char* drawings[2] = {"arm_alone", "spine_legs_gap"};
    for (int d = 0; d < 2; ++d) {
        char strokes[1100];
        snprintf(strokes, sizeof strokes, "%s/tests/data/posing/cartoon_man_%s.json", SP_SOURCE_DIR, drawings[d]);
        sp_sketch sk = {0};
        ENSURE(sp_read_strokes(strokes, &sk, &err) == SP_OK);
        sp_camera cam = sp_rig_handle_camera(h, sk.canvas_w, sk.canvas_h);
        sp_solver* solver = NULL;
        ENSURE(sp_rig_handle_solver(h, a, &cam, &(sp_solve_desc){0}, &solver, &err) == SP_OK);
        double* p = malloc(sizeof(double) * (size_t)(3 * P));
        ENSURE(p);
        for (int q = 0; q < P; ++q)
            p[P + q] = p[2 * P + q] = sp_rig_handle_params(h)[q].def;
        sp_solve_report rep[3];
        ENSURE(sp_solver_solve(solver, &sk, NULL, p, &rep[0], &err) == SP_OK);
        ENSURE(sp_solver_solve(solver, &sk, p + 2 * P, p + P, &rep[1], &err) == SP_OK);
        ENSURE(sp_solver_solve(solver, &sk, p + 2 * P, p + 2 * P, &rep[2], &err) == SP_OK);
        fprintf(stderr, "  %s: %.3f px in %d iterations; from defaults %.3f in %d; aliased %.3f in %d\n", drawings[d],
                rep[0].mean_error_px, rep[0].iterations, rep[1].mean_error_px, rep[1].iterations, rep[2].mean_error_px,
                rep[2].iterations);
        ENSURE(rep[1].mean_error_px == rep[0].mean_error_px && rep[1].iterations == rep[0].iterations);
        ENSURE(!memcmp(p + P, p, sizeof(double) * (size_t)P));
        // Aliased, the later attempts start from the best fit so far (as
        // documented), so a few iterations may differ; the attempt from rest
        // run twice cost 40% more.
        ENSURE(fabs(rep[2].mean_error_px - rep[0].mean_error_px) < 0.01 && rep[2].iterations <= rep[0].iterations * 1.1);
        free(p);
        sp_solver_destroy(solver);
        sp_sketch_free(&sk);
    }
    sp_rig_handle_free(h);
}

// An arm redrawn raised, turned about the shoulder by 100 to 160 degrees
// (an outside review: at 40 degrees above the horizontal and more, the
// line was paired reversed, the hand sent to the shoulder, the arm folded
// at 9-17 px): paired by its ends, the arm goes up. A tap drawn over the
// character is refused as --to's is (it swung the arm it touched, exit 0).
static void test_drawover_arm_raised(void)
{
    for (int deg = 0; deg <= 80; deg += 40) {
        enum { N = 16 };
        sp_vec2 on[N], to[N];
        double a = deg * M_PI / 180;
        for (int i = 0; i < N; ++i) {
            double t = (double)i / (N - 1);
            on[i] = (sp_vec2){368 + t * 47, 220 + t * 98}; // along the hanging arm, shoulder to hand
            to[i] = (sp_vec2){368 + t * 115 * cos(a), 220 - t * 115 * sin(a)};
        }
        cJSON* j = drawover_man(on, to, N, "raised");
        double err_px = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
        bool rev = cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(j, "curves"), 0), "reversed"));
        fprintf(stderr, "  the arm redrawn %d degrees above the horizontal: %.2f px%s\n", deg, err_px, rev ? ", reversed" : "");
        ENSURE(!rev && err_px < 5);
        cJSON_Delete(j);
    }
    char on[1100], to[1100], said[1024], cmd[4000];
    snprintf(on, sizeof on, "%s", sp_test_tmp_path("tap_on.json"));
    snprintf(to, sizeof to, "%s", sp_test_tmp_path("tap_to.json"));
    write_one_stroke(on, (const sp_vec2[]){{390, 260}, {390, 260}}, 2);
    write_one_stroke(to, (const sp_vec2[]){{368, 220}, {420, 150}}, 2);
    snprintf(cmd, sizeof cmd, "'%s' drawover --rig '%s/assets/cartoon_man.glb' --on '%s' --to '%s' 2>&1 >/dev/null",
             SP_SKETCHPOSE, SP_SOURCE_DIR, on, to);
    ENSURE(sp_fixture_run(cmd, said, sizeof said) == 1 && strstr(said, "stroke 0 is 0.0 px long") &&
           strchr(said, '\n') == said + strlen(said) - 1);
}

// A draw-over that cannot reach its redraw says which joints it could
// move: "cannot reach" alone left a user guessing why the arm stayed down.
static void test_drawover_note_held(void)
{
    // Redrawn beyond the arm's reach (a forearm raised at the elbow, which
    // was out of reach while its line was paired reversed, is now reached).
    const sp_vec2 forearm[2][3] = {{{390, 245}, {400, 265}, {410, 285}}, {{530, 245}, {545, 230}, {560, 215}}};
    cJSON* j = drawover_man(forearm[0], forearm[1], 3, "held");
    const char* note = cJSON_GetStringValue(cJSON_GetObjectItem(j, "note"));
    fprintf(stderr, "  the forearm redrawn out of reach: \"%s\"\n", note ? note : "(none)");
    ENSURE(note && strstr(note, "best effort") &&
           strstr(note, "draw-over moves only the joints under the drawn curves, from 'clavicle_l' down"));
    cJSON_Delete(j);
}

// drawover's two drawings are on one screen: --to on another canvas is
// refused, naming it (its points were read in --on's canvas: a wrong fit,
// exit 0); on the same canvas it fits.
static void test_drawover_canvas(void)
{
    char on[1100], to[1100], rep[1100], args[4000];
    snprintf(on, sizeof on, "%s", sp_test_tmp_path("drawover_on.json"));
    snprintf(to, sizeof to, "%s", sp_test_tmp_path("drawover_to.json"));
    snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("drawover_report.json"));
    const char* rig = SP_SOURCE_DIR "/assets/cartoon_man.glb";
    sp_error err = {0};
    // Down the body, then bent to the right.
    const sp_vec2 down[] = {{300, 150}, {320, 200}, {330, 260}}, bent[] = {{300, 150}, {340, 200}, {370, 240}};
    double mean_px[3] = {0};
    // Both at 640x480; --to at twice the size (refused); --on at twice the
    // size without a canvas, which takes --to's (it took the rig's view's,
    // and fitted to a mean error of 278 px with exit 0).
    for (int round = 0; round < 3; ++round) {
        int k_on = round == 2 ? 2 : 1, k_to = round == 0 ? 1 : 2;
        sp_vec2 xy[3];
        for (int i = 0; i < 3; ++i)
            xy[i] = (sp_vec2){down[i].x * k_on, down[i].y * k_on};
        sp_sketch a = {.canvas_w = round == 2 ? 0 : 640, .canvas_h = round == 2 ? 0 : 480};
        ENSURE(sp_sketch_add_stroke(&a, xy, NULL, 3) == SP_OK && sp_sketch_write_json(on, &a, &err) == SP_OK);
        sp_sketch_free(&a);
        for (int i = 0; i < 3; ++i)
            xy[i] = (sp_vec2){bent[i].x * k_to, bent[i].y * k_to};
        sp_sketch b = {.canvas_w = 640 * k_to, .canvas_h = 480 * k_to};
        ENSURE(sp_sketch_add_stroke(&b, xy, NULL, 3) == SP_OK && sp_sketch_write_json(to, &b, &err) == SP_OK);
        sp_sketch_free(&b);
        unlink(rep);
        snprintf(args, sizeof args, "drawover --rig '%s' --on '%s' --to '%s' --report '%s'", rig, on, to, rep);
        int rc;
        char* text = run_said(args, &rc);
        if (round == 1) {
            ENSURE(rc == 1 && strstr(text, "drawover_to.json: its canvas 1280x960 is not --on's 640x480") &&
                   strchr(text, '\n') == text + strlen(text) - 1);
        } else {
            ENSURE(rc == 0);
            char* r = sp_fixture_file_text(rep, NULL);
            cJSON* j = cJSON_Parse(r);
            free(r);
            mean_px[round] = cJSON_GetNumberValue(cJSON_GetObjectItem(j, "mean_error_px"));
            // The weights used: the paper's, scaled to the curve (sp_drawover_scale_weights).
            const cJSON* w = cJSON_GetObjectItem(j, "weights");
            double by = cJSON_GetNumberValue(cJSON_GetObjectItem(w, "scaled_by"));
            ENSURE(w && by >= 1 && by <= 10000);
            ENSURE_NEAR(cJSON_GetNumberValue(cJSON_GetObjectItem(w, "dist")), SP_LAMBDA_DIST * by, 1e-12 * by);
            ENSURE_NEAR(cJSON_GetNumberValue(cJSON_GetObjectItem(w, "pose")), SP_LAMBDA_POSE * by, 1e-12 * by);
            // The character stands where it was: the placement joint neither turns nor grows it
            // (a line down the body redrawn bent grew the cartoon man by a quarter).
            const cJSON* params = cJSON_GetObjectItem(j, "parameters");
            ENSURE(cJSON_GetNumberValue(cJSON_GetObjectItem(params, "root.rz")) == 0 &&
                   cJSON_GetNumberValue(cJSON_GetObjectItem(params, "root.s")) == 1 &&
                   cJSON_GetNumberValue(cJSON_GetObjectItem(params, "pelvis.rx")) == 0 &&
                   cJSON_GetNumberValue(cJSON_GetObjectItem(params, "pelvis.ry")) == 0);
            cJSON_Delete(j);
            fprintf(stderr, "  mean error %.2f px\n", mean_px[round]);
        }
        free(text);
    }
    // The same fit at twice the size: twice the error, give or take.
    ENSURE(mean_px[2] <= 2 * mean_px[0] + 2);
}

// `synth --parts` with a broken part after a good one prints no result and
// writes nothing: every part is read before a sketch is written (it printed
// a result and left a partial folder; then it took back a folder it made,
// but left the good part's sketches in one it did not); the folder the
// caller made stays, empty.
static void test_synth_parts_fails_whole(void)
{
    char parts[1100], out[1100], cmd[8000], args[4000];
    snprintf(parts, sizeof parts, "%s", sp_test_tmp_path("synth_parts"));
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("synth_parts_out"));
    snprintf(cmd, sizeof cmd,
             "rm -rf '%s' '%s' && mkdir '%s' && cp '%s/assets/tail.glb' '%s/a_tail.glb' && head -c 1000 '%s/assets/head.glb' > "
             "'%s/b_broken.glb'",
             parts, out, parts, SP_SOURCE_DIR, parts, SP_SOURCE_DIR, parts);
    ENSURE(run(cmd) == 0);
    char said[1200];
    snprintf(said, sizeof said, "%s", sp_test_tmp_path("synth_parts_stdout.txt"));
    for (int existed = 0; existed < 2; ++existed) {
        if (existed) ENSURE(mkdir(out, 0755) == 0);
        snprintf(args, sizeof args, "'%s' synth --parts '%s' --per-part 2 --out-dir '%s' > '%s' 2>/dev/null", SP_SKETCHPOSE,
                 parts, out, said);
        ENSURE(run(args) == 1);
        size_t n = 0;
        free(sp_fixture_file_text(said, &n));
        ENSURE(n == 0);
        struct stat st;
        if (existed) {
            snprintf(cmd, sizeof cmd, "test -d '%s' && test -z \"$(ls -A '%s')\"", out, out);
            ENSURE(run(cmd) == 0);
        } else
            ENSURE(stat(out, &st) != 0);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s'", parts, out);
    ENSURE(run(cmd) == 0);
}

// Writes a one-stroke file of n points from (x0, y0) by (dx, dy) each.
static void write_line(const char* path, double x0, double y0, double dx, double dy, int n)
{
    sp_sketch sk = {.canvas_w = 640, .canvas_h = 480};
    sp_vec2 pts[64];
    for (int i = 0; i < n && i < 64; ++i)
        pts[i] = (sp_vec2){x0 + dx * i, y0 + dy * (i % 2 ? i : -i)};
    sp_error err = {0};
    ENSURE(sp_sketch_add_stroke(&sk, pts, NULL, n) == SP_OK && sp_sketch_write_json(path, &sk, &err) == SP_OK);
    sp_sketch_free(&sk);
}

// A drawing with no extent (all its points at one place: a dot) is refused by
// classify and db add-sketch (both took it, exit 0) and left out of a
// labelled folder's training and evaluation with one warning line (it was
// trained on as a blank picture).
static void test_no_extent_cli(void)
{
    char dir[1024], cmd[6000], dot[1100], model[1100];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("extent_set"));
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s/a' '%s/b'", dir, dir, dir);
    ENSURE(run(cmd) == 0);
    for (int i = 0; i < 3; ++i) {
        char f[1200];
        snprintf(f, sizeof f, "%s/a/%d.json", dir, i);
        write_line(f, 100 + 5 * i, 200, 10, 0, 30);
        snprintf(f, sizeof f, "%s/b/%d.json", dir, i);
        write_line(f, 300, 50 + 5 * i, 1, 8, 30);
    }
    snprintf(dot, sizeof dot, "%s/b/dot.json", dir);
    write_line(dot, 320, 240, 0, 0, 5);
    snprintf(model, sizeof model, "%s", sp_test_tmp_path("extent.spclf"));
    char args[4000];
    int rc;
    snprintf(args, sizeof args, "train --data '%s' --model '%s' --words 20", dir, model);
    char* text = run_said(args, &rc);
    ENSURE(rc == 0 && strstr(text, "sketchpose train: warning: ") && strstr(text, "1 drawing left out: no extent"));
    free(text);
    snprintf(args, sizeof args, "eval --data '%s' --model '%s'", dir, model);
    text = run_said(args, &rc);
    ENSURE(rc == 0 && strstr(text, "1 drawing left out: no extent"));
    free(text);
    const char* want = "dot.json: the drawing has no extent: all its points are at one place\n";
    snprintf(args, sizeof args, "classify --model '%s' --strokes '%s'", model, dot);
    text = run_said(args, &rc);
    ENSURE(rc == 1 && strstr(text, "sketchpose classify: ") && strstr(text, want) &&
           strchr(text, '\n') == text + strlen(text) - 1);
    free(text);
    snprintf(args, sizeof args, "db add-sketch --db '%s/x.db' --category a '%s'", dir, dot);
    text = run_said(args, &rc);
    ENSURE(rc == 1 && strstr(text, "sketchpose db add-sketch: ") && strstr(text, want));
    free(text);
    // A blank picture is no drawing either (an outside review: `db
    // add-sketch` stored an all-white PNG, and `db train` trained on it,
    // which classify refused): an 8 x 8 white PNG.
    static const unsigned char white[71] = {
        0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
        0x00, 0x08, 0x00, 0x00, 0x00, 0x08, 0x08, 0x00, 0x00, 0x00, 0x00, 0xe1, 0x64, 0xe1, 0x57, 0x00, 0x00, 0x00,
        0x0e, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8, 0x0f, 0x05, 0x0c, 0x94, 0x31, 0x00, 0xf7, 0xc0, 0x3f,
        0xc1, 0xb2, 0x34, 0x41, 0xbb, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
    char blank[1200];
    snprintf(blank, sizeof blank, "%s/b/white.png", dir);
    FILE* f = fopen(blank, "wb");
    ENSURE(f && fwrite(white, sizeof white, 1, f) == 1 && fclose(f) == 0);
    snprintf(args, sizeof args, "db add-sketch --db '%s/x.db' --category a '%s'", dir, blank);
    text = run_said(args, &rc);
    ENSURE(rc == 1 && strstr(text, "white.png: the picture has no dark lines"));
    free(text);
    snprintf(args, sizeof args, "train --data '%s' --model '%s' --words 20", dir, model);
    text = run_said(args, &rc);
    ENSURE(rc == 0 && strstr(text, "2 drawings left out: no extent"));
    free(text);
    // classify says it in the same words (it said "raster has no dark lines").
    char said_by[3000];
    snprintf(said_by, sizeof said_by, "classify --model '%s' --strokes '%s'", model, blank);
    text = run_said(said_by, &rc);
    ENSURE(rc == 1 && strstr(text, "white.png: the picture has no dark lines (a blank page?)"));
    free(text);
    // A model written among the drawings replaced one (and the next train
    // failed on it): bad usage, the drawing kept (an outside review).
    const char* among[2] = {"b/0.json", "more.ndjson"};
    for (int i = 0; i < 2; ++i) {
        char over[1200], before[1200];
        snprintf(over, sizeof over, "%s/%s", dir, among[i]);
        snprintf(before, sizeof before, "%s", sp_test_tmp_path("extent_before"));
        snprintf(cmd, sizeof cmd, "touch '%s' && cp '%s' '%s'", over, over, before);
        ENSURE(run(cmd) == 0);
        snprintf(said_by, sizeof said_by, "train --data '%s' --model '%s' --words 20", dir, over);
        text = run_said(said_by, &rc);
        ENSURE(rc == 2 && strstr(text, "lies among the drawings of --data") && strchr(text, '\n') == text + strlen(text) - 1);
        free(text);
        snprintf(cmd, sizeof cmd, "cmp -s '%s' '%s' && rm '%s'%s%s%s", over, before, before, i ? " '" : "", i ? over : "",
                 i ? "'" : "");
        ENSURE(run(cmd) == 0);
    }
    // A category whose only drawing is blank: nothing to learn it from (it
    // was in the model, every drawing of it taken for another).
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/c' && cp '%s' '%s/c/'", dir, blank, dir);
    ENSURE(run(cmd) == 0);
    text = run_said(args, &rc);
    ENSURE(rc == 1 && strstr(text, "category 'c' has no drawing left (nothing to learn it from)"));
    free(text);
    snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s'", dir, model);
    ENSURE(run(cmd) == 0);
}

// Usage mistakes are exit 2 and one line that names the option and what it
// takes (an audit of the commands against DESIGN.md found these said
// otherwise: exit 1, or the wrong option, or a usage placeholder as the
// command's name).
static void test_usage_messages(void)
{
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s", sp_test_tmp_path("usage"));
    struct {
        const char* fmt;
        const char* said;
    } cases[] = {
        {"derive --rig '%1$s/assets/tail.glb' --out '%2$s.glb' --abstraction foo",
         "sketchpose derive: --abstraction wants outline or stick, got 'foo'"},
        {"eval --data /nonexistent --folds 101", "sketchpose eval: --folds must be 2..100 (-1 or 0: none), got 101"},
        {"eval --data /nonexistent --folds -1", "sketchpose eval: give --model M, or --folds K"},
        {"synth --rig '%1$s/assets/tail.glb' --seed 1 --out '%2$s.json' --out-dir '%2$s'",
         "sketchpose synth: --out-dir does not apply to --rig"},
        {"db review --db '%2$s.db' --limit -1", "sketchpose db review: --limit must not be negative, got -1"},
        {"db add-sketch '%2$s.json' --category head --category tail --db '%2$s.db'",
         "sketchpose db add-sketch: --category given twice"},
        // An unset variable's empty name: "cannot open", exit 1, before.
        {"pose --rig '' --strokes '%2$s.json'", "sketchpose pose: --rig needs a file name, got an empty value"},
        {"db log --db '%2$s.db' --by \"$(printf 'a\\033[2Jb')\"", "sketchpose db log: --by wants a name of 1 to 128 bytes"},
        {"render --rig '%1$s/assets/tail.glb' --out ''", "sketchpose render: --out needs a file name, got an empty value"},
        {"animate --rig '%1$s/assets/tail.glb' --strokes '' --out '%2$s.glb'", "sketchpose animate: --strokes needs file names"},
        {"db add-part '' --db '%2$s.db'", "sketchpose db add-part: PART.glb: got an empty file name"},
        // A name with a newline or an escape code: bad usage, the value shown escaped (it was echoed raw, exit 1).
        {"db add-sketch '%2$s.json' --category \"$(printf 'he\\nad')\" --db '%2$s.db'",
         "sketchpose db add-sketch: --category wants a plain name ([A-Za-z0-9_.-], 1 to 63 characters, not starting with "
         "'.'), got 'he\\nad'"},
        {"db add-part '%1$s/assets/tail.glb' --name \"$(printf 'h\\033[2Jx')\" --db '%2$s.db'",
         "sketchpose db add-part: --name wants a plain name ([A-Za-z0-9_.-], 1 to 63 characters, not starting with '.'), "
         "got 'h\\x1b[2Jx'"},
        {"db review --db '%2$s.db' --relabel 1 \"$(printf 'to\\nrso')\"",
         "sketchpose db review: --relabel's CATEGORY wants a plain name"},
        {"derive --rig '%1$s/assets/tail.glb' --out '%2$s.glb' --category \"$(printf 'a\\nb')\"",
         "sketchpose derive: --category wants a plain name ([A-Za-z0-9_.-], 1 to 63 characters, not starting with '.'), "
         "got 'a\\nb'"},
        // Every value a usage message repeats is shown escaped: a newline or an escape code typed in an option or
        // its value reached the terminal raw (two lines; a cleared screen).
        {"pose --rig x \"$(printf -- '--str\\033[2Jokes')\"", "sketchpose pose: unknown option '--str\\x1b[2Jokes' (see --help)"},
        {"db review --db '%2$s.db' --status \"$(printf 'al\\nl')\"",
         "sketchpose db review: --status must be pending, approved, rejected or all, got 'al\\nl'"},
        {"render --rig '%1$s/assets/tail.glb' --out '%2$s.png' --size \"$(printf '6\\n4x48')\"",
         "sketchpose render: --size wants WxH with sides 16..8192, e.g. 640x480, got '6\\n4x48'"},
        {"synth --rig '%1$s/assets/tail.glb' --seed \"$(printf '1\\n2')\" --out '%2$s.json'",
         "sketchpose synth: --seed expects an integer, got '1\\n2'"},
        // A malformed id or range is a malformed value, as a number out of its range (exit 1 before).
        {"db review --db '%2$s.db' --approve 1179-1172",
         "sketchpose db review: '1179-1172' is not a kiosk sketch id (a positive number) or a range of them"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char args[3000];
        snprintf(args, sizeof args, cases[i].fmt, SP_SOURCE_DIR, tmp);
        int rc;
        char* text = run_said(args, &rc);
        ENSURE(rc == 2 && !strncmp(text, cases[i].said, strlen(cases[i].said)) && strchr(text, '\n') == text + strlen(text) - 1);
        free(text);
    }
    ENSURE(access(tmp, F_OK) != 0);
    // A list option takes at most 256 values: the 257th is bad usage (one more
    // would be written past the list's end).
    char many[3000];
    int n = snprintf(many, sizeof many, "db review --db '%s.db' --approve", tmp);
    for (int v = 1; v <= 257; ++v)
        n += snprintf(many + n, sizeof many - (size_t)n, " %d", v);
    int rc;
    char* text = run_said(many, &rc);
    ENSURE(rc == 2 && strstr(text, "sketchpose db review: too many values for --approve (256 at most)"));
    free(text);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"animation_from_keys", test_animation_from_keys},
                                   {"drawover_fixture", test_drawover_fixture},
                                   {"animate_cli_cesiumman", test_animate_cli_cesiumman},
                                   {"animate_cli_times", test_animate_cli_times},
                                   {"drawover_cesiumman", test_drawover_cesiumman},
                                   {"drawover_neck_local", test_drawover_neck_local},
                                   {"drawover_arm_alone", test_drawover_arm_alone},
                                   {"drawover_several_curves", test_drawover_several_curves},
                                   {"animate_holds_proportions", test_animate_holds_proportions},
                                   {"held_through_rest_attempt", test_held_through_rest_attempt},
                                   {"start_held_anywhere", test_start_held_anywhere},
                                   {"drawover_in_pieces", test_drawover_in_pieces},
                                   {"drawover_single_chain", test_drawover_single_chain},
                                   {"drawover_scale_is_solvers", test_drawover_scale_is_solvers},
                                   {"synth_jitter", test_synth_jitter},
                                   {"rig_handle", test_rig_handle},
                                   {"cli_missing_value", test_cli_missing_value},
                                   {"no_extent_cli", test_no_extent_cli},
                                   {"pose_option_ranges", test_pose_option_ranges},
                                   {"pose_file_whole", test_pose_file_whole},
                                   {"device_inputs", test_device_inputs},
                                   {"outputs_kept", test_outputs_kept},
                                   {"outputs_off_gltf_files", test_outputs_off_gltf_files},
                                   {"report_on_stdout_once", test_report_on_stdout_once},
                                   {"file_on_stdout_alone", test_file_on_stdout_alone},
                                   {"render_size", test_render_size},
                                   {"pose_file_strict", test_pose_file_strict},
                                   {"note_unmatched_curves", test_note_unmatched_curves},
                                   {"pose_surplus_strokes", test_pose_surplus_strokes},
                                   {"pose_fewer_strokes", test_pose_fewer_strokes},
                                   {"pose_drawn_higher", test_pose_drawn_higher},
                                   {"pose_notes_say_why", test_pose_notes_say_why},
                                   {"drawover_only_carriers", test_drawover_only_carriers},
                                   {"drawover_note_held", test_drawover_note_held},
                                   {"drawover_arm_raised", test_drawover_arm_raised},
                                   {"pose_directions_by_joints", test_pose_directions_by_joints},
                                   {"max_iterations_between_stages", test_max_iterations_between_stages},
                                   {"drawover_canvas", test_drawover_canvas},
                                   {"synth_parts_fails_whole", test_synth_parts_fails_whole},
                                   {"usage_messages", test_usage_messages},
                                   {0}});
}
