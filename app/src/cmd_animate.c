// sketchpose animate: the paper's redraw-posing animations (its Figure 1
// run cycle, Figure 3 fall). Each key's strokes are solved starting from the
// previous key's pose; the keys become one glTF animation.
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "posing.h"
#include "solve_cmd.h"

// "0,0.5,1.2" -> times; false if malformed, negative or not times an
// animation can store (sp_animation_check_times: the .glb stores floats, so
// 1e300 would overflow, 1e-300 fall to 0, and the file would not load again).
static bool parse_times(const char* s, double* t, int n)
{
    const char* at = s;
    for (int i = 0; i < n; ++i) {
        char* end = NULL;
        t[i] = strtod(at, &end);
        if (end == at || !(t[i] >= 0)) return false;
        at = end;
        if (i + 1 < n) {
            if (*at != ',') return false;
            ++at;
        }
    }
    sp_error ignored = {0}; // the caller's message says what times are wanted
    return *at == 0 && sp_animation_check_times(t, n, &ignored) == SP_OK;
}

// Solves the key again from `start`, keeping the better fit in p, *rep and
// *j. False when out of memory.
static bool solve_also_from(sp_solve_cmd* run, const sp_camera* cam, const sp_sketch* sk, const char* strokes,
                            const double* start, double* p, int P, sp_solve_report* rep, cJSON** j)
{
    double* alt = malloc(sizeof(double) * (size_t)(P + 1));
    if (!alt) return false;
    sp_solve_report r2;
    cJSON* j2 = NULL;
    if (sp_solve_cmd_solve(run, cam, sk, strokes, start, alt, &r2, &j2) && r2.mean_error_px < rep->mean_error_px) {
        memcpy(p, alt, sizeof(double) * (size_t)P);
        *rep = r2;
        cJSON_Delete(*j);
        *j = j2;
    } else {
        cJSON_Delete(j2);
    }
    free(alt);
    return true;
}

// The other starts of key k > 0, after the one from the last key's fit
// (p, *rep, *j): once the proportions are held (`moves`), the held key's
// own pose, of the same character (the chained start crept: a jump's last
// key, its first drawing again, fitted the figure 1.2 times its size at 1.6
// px, against 0.3 px from the held key's pose); and where the fit is a best
// effort (over 5% of the size: the character moved where the last pose
// cannot reach), the rest pose, the held values kept. `scratch`: P values.
static bool other_starts(sp_solve_cmd* run, const sp_camera* cam, const sp_sketch* sk, const char* strokes, const double* rest,
                         const bool* moves, const double* held_pose, double* scratch, double* p, int P, sp_solve_report* rep,
                         cJSON** j)
{
    if (moves && !solve_also_from(run, cam, sk, strokes, held_pose, p, P, rep, j)) return false;
    if (!(rep->mean_error_px > 0.05 * rep->bbox_diagonal_px)) return true;
    for (int q = 0; q < P; ++q)
        scratch[q] = moves && !moves[q] ? held_pose[q] : rest[q];
    return solve_also_from(run, cam, sk, strokes, scratch, p, P, rep, j);
}

// Whether shape parameter q sets a proportion (a joint under another joint
// with a shape parameter: a bone's length, the head's size) rather than the
// figure's overall size (the topmost scale: the root's), which a key drawn
// larger or smaller changes.
static bool is_proportion(const sp_param* params, int P, const sp_rig* rig, int q)
{
    if (params[q].group != SP_GROUP_SHAPE) return false;
    for (int a = rig->joints[params[q].joint].parent; a >= 0; a = rig->joints[a].parent)
        for (int k = 0; k < P; ++k)
            if (params[k].joint == a && params[k].group == SP_GROUP_SHAPE) return true;
    return false;
}

// One character through the clip: from the first key that fits well (its
// mean error within 1% of its size) on, its proportions are held at that
// key's, and the later keys move only the pose and the overall size (the
// solver made again with them held). Each key started from the last one's
// fit and nothing drew the proportions back: a jump's head shrank to 0.82,
// the same drawing at the clip's end fitted otherwise than at its start; a
// key drawn 1.25 times larger must still grow the figure, and a poor first
// key must not set the clip's proportions (outside reviews). False when out
// of memory.
static bool hold_shape(sp_solve_cmd* run, const sp_rig* rig, bool** held, int P)
{
    const sp_param* params = sp_rig_handle_params(run->rig);
    *held = malloc(sizeof(bool) * (size_t)(P + 1));
    if (!*held) return false;
    for (int q = 0; q < P; ++q)
        (*held)[q] = !is_proportion(params, P, rig, q) && (!run->desc.active || run->desc.active[q]);
    run->desc.active = *held;
    sp_solver_destroy(run->solver);
    run->solver = NULL;
    return true;
}

int cmd_animate(int argc, char** argv)
{
    const char *rig_path = NULL, *abs_name = NULL, *times_s = NULL, *out = NULL, *report = NULL;
    sp_str_list keys = {0};
    const sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "the rigged character (.gltf or .glb)", true},
        {"--abstraction", SP_OPT_STRING, &abs_name, "NAME",
         "which abstraction the strokes draw (default: the part's own, else the first)", false},
        {"--strokes", SP_OPT_IN_LIST, &keys, "K1.json K2.json ...", "one stroke file (or .svg) per key pose, in time order",
         true},
        {"--times", SP_OPT_STRING, &times_s, "t1,t2,...", "key times in seconds (default 0,1,2,...)", false},
        {"--out", SP_OPT_OUT, &out, "anim.glb", "the animated character", true},
        {"--report", SP_OPT_OUT, &report, "report.json", "write the per-key solve reports (also printed on stdout)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose animate", "Key poses from strokes, solved in sequence, as one glTF animation.",
                          opts, (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_out("sketchpose animate", "--out", out, SP_CLI_OUT_GLTF)) return SP_EXIT_USAGE;
    int n = keys.count;
    double* times = malloc(sizeof(double) * (size_t)n);
    if (!times) return SP_EXIT_INPUT;
    for (int k = 0; k < n; ++k) times[k] = k;
    if (times_s && !parse_times(times_s, times, n)) {
        fprintf(stderr,
                "sketchpose animate: --times needs %d non-negative numbers separated by commas, at most %g and increasing "
                "in single precision (the .glb stores floats), got '%s'\n",
                n, FLT_MAX, times_s);
        free(times);
        return SP_EXIT_USAGE;
    }
    if (!sp_cli_check_out_folders("sketchpose animate", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work
    sp_rig_handle* rig = NULL;
    sp_error err = {0};
    sp_solve_cmd run = {.cmd = "sketchpose animate"};
    double *kp = NULL, *p0 = NULL;
    bool* held = NULL; // the parameters the keys after held_key move (hold_shape)
    int held_key = 0;
    double* start_p = NULL;                                 // scratch for other_starts
    char(*notes)[sizeof((sp_solve_report){0}.note)] = NULL; // each key's report note
    cJSON* all = cJSON_CreateArray();
    int exit_code = SP_EXIT_INPUT;
    // A glTF animation keys joints; a black box's deformers have none.
    if (sp_rig_handle_load_character(rig_path, "animate", &rig, &err) != SP_OK) goto fail;
    sp_character* ch = sp_rig_handle_character(rig);
    run.rig = rig;
    run.abstraction = sp_rig_handle_pick_abstraction(rig, abs_name, &err);
    if (run.abstraction < 0) goto fail;
    const int P = sp_rig_handle_param_count(rig);
    if (sp_rig_handle_read_pose(rig, NULL, &p0, NULL, &err) != SP_OK) goto fail;
    kp = malloc(sizeof(double) * (size_t)(P + 1) * (size_t)n);
    notes = calloc((size_t)n, sizeof *notes);
    start_p = malloc(sizeof(double) * (size_t)(P + 1));
    if (!kp || !notes || !start_p) goto oom;
    for (int k = 0; k < n; ++k) {
        sp_sketch sk = {0};
        if (sp_read_strokes(keys.items[k], &sk, &err) != SP_OK) goto fail;
        sp_camera cam = sp_rig_handle_camera(rig, sk.canvas_w, sk.canvas_h);
        const double* start = k == 0 ? p0 : kp + (size_t)(k - 1) * P;
        sp_solve_report rep;
        cJSON* j = NULL;
        bool solved = sp_solve_cmd_solve(&run, &cam, &sk, keys.items[k], start, kp + (size_t)k * P, &rep, &j);
        if (solved && k > 0 &&
            !other_starts(&run, &cam, &sk, keys.items[k], p0, held, kp + (size_t)held_key * P, start_p, kp + (size_t)k * P, P,
                          &rep, &j)) {
            sp_sketch_free(&sk);
            goto oom;
        }
        sp_sketch_free(&sk);
        if (!solved) goto done;
        if (!held && rep.mean_error_px <= 0.01 * rep.bbox_diagonal_px) {
            if (!hold_shape(&run, &ch->rig, &held, P)) goto oom;
            held_key = k;
        }
        snprintf(notes[k], sizeof notes[k], "%s", rep.note);
        cJSON_AddStringToObject(j, "strokes", keys.items[k]);
        cJSON_AddNumberToObject(j, "time_s", times[k]);
        cJSON_AddItemToArray(all, j);
    }
    sp_animation anim;
    sp_result ar = sp_animation_from_keys(&ch->rig, kp, times, n, "sketchpose", &anim, &err);
    sp_animation* grown =
        ar == SP_OK ? realloc(ch->rig.animations, sizeof(sp_animation) * (size_t)(ch->rig.animation_count + 1)) : NULL;
    if (!grown) {
        for (int c = 0; c < anim.channel_count; ++c) free(anim.channels[c].times), free(anim.channels[c].values);
        free(anim.channels);
        if (ar == SP_OK) goto oom;
        goto fail;
    }
    // First in the file: viewers play a file's first animation, and the user
    // asked for this one (the file's own clips follow, kept).
    ch->rig.animations = grown;
    memmove(ch->rig.animations + 1, ch->rig.animations, sizeof(sp_animation) * (size_t)ch->rig.animation_count);
    ch->rig.animations[0] = anim;
    ++ch->rig.animation_count;
    // The keys' reports, then the character with the animation, at the first key's pose.
    if (sp_solve_cmd_write(&run, all, kp, &(sp_solve_outputs){.report = report, .out = out})) {
        exit_code = SP_EXIT_OK;
        // Each key's note, as pose says its one.
        for (int k = 0; k < n; ++k)
            if (notes[k][0]) fprintf(stderr, "sketchpose animate: %s: %s\n", keys.items[k], notes[k]);
    }
    goto done;
oom:
    sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
fail:
    fprintf(stderr, "sketchpose animate: %s\n", err.text);
done:
    cJSON_Delete(all);
    sp_solve_cmd_end(&run);
    free(kp), free(p0), free(times), free(notes), free(held), free(start_p);
    sp_rig_handle_free(rig);
    return exit_code;
}
