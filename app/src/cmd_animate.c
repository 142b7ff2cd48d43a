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
        t[i] = sp_cli_strtod(at, &end);
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

// One character through the clip. From the first key that is not a best
// effort (its mean error within 5% of its size: a sketchy key of 1-2% is a
// good key), its proportions are held for the later keys, and so is its
// overall size (the topmost scale) unless a key is drawn at another size
// (size_ratio). Each key started from the last one's fit and nothing drew
// the shape back: a jump's head shrank to 0.82, the figure grew to 1.22 and
// leaned back, and the same drawing at the clip's end fitted otherwise than
// at its start (outside reviews). held[0..P): what a key drawn at the held
// key's size moves; held[P..2P): what a key drawn at another size moves
// (its overall size too). False when out of memory.
static bool hold_shape(sp_solve_cmd* run, const sp_rig* rig, bool** held, int P)
{
    const sp_param* params = sp_rig_handle_params(run->rig);
    *held = malloc(sizeof(bool) * (size_t)(2 * P + 1));
    if (!*held) return false;
    for (int q = 0; q < P; ++q) {
        bool moves = !run->desc.active || run->desc.active[q];
        (*held)[q] = moves && params[q].group != SP_GROUP_SHAPE;
        (*held)[P + q] = moves && !is_proportion(params, P, rig, q);
    }
    return true;
}

// The drawn length of all the strokes: as a stick figure's bones are drawn
// whatever the pose, it says the figure's size on the canvas.
static double drawn_length(const sp_sketch* sk)
{
    double len = 0;
    for (int i = 0; i < sk->stroke_count; ++i)
        for (int k = 1; k < sk->strokes[i].count; ++k)
            len += sp_v2_len(sp_v2_sub(sk->strokes[i].points[k], sk->strokes[i].points[k - 1]));
    return len;
}

// How much larger key sk is drawn than the held key (1: the same size):
// its drawn length over the held key's when both have as many strokes
// (a key of fewer strokes, a spine alone, says nothing of the size); within
// 15% it is the same size (a hand's wobble, a pose that hides a limb).
static double size_ratio(const sp_sketch* sk, int held_strokes, double held_length)
{
    if (sk->stroke_count != held_strokes || !(held_length > 0)) return 1.0;
    double r = drawn_length(sk) / held_length;
    return r > 0.85 && r < 1.0 / 0.85 ? 1.0 : r;
}

// Sets the solver to move what `moves` says (made again when it changes).
static void set_moves(sp_solve_cmd* run, const bool* moves)
{
    if (run->desc.active == moves) return;
    run->desc.active = moves;
    sp_solver_destroy(run->solver);
    run->solver = NULL;
}

// `from` with the overall size (shape parameters that are not proportions)
// set to the held key's times `ratio`, within bounds, into out.
static void sized_start(const sp_param* params, const bool* held, int P, const double* from, const double* held_pose,
                        double ratio, double* out)
{
    memcpy(out, from, sizeof(double) * (size_t)P);
    for (int q = 0; q < P; ++q)
        if (params[q].group == SP_GROUP_SHAPE && held[P + q])
            out[q] = fmin(fmax(held_pose[q] * ratio, params[q].min), params[q].max);
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
    if (!sp_cli_check_out_folders("sketchpose animate", opts, (int)(sizeof opts / sizeof opts[0]))) {
        free(times);
        return SP_EXIT_INPUT; // before the work
    }
    sp_rig_handle* rig = NULL;
    sp_error err = {0};
    sp_solve_cmd run = {.cmd = "sketchpose animate"};
    double *kp = NULL, *p0 = NULL;
    bool* held = NULL; // the parameters the keys after held_key move (hold_shape)
    int held_key = 0;
    double *start_p = NULL, *held_p = NULL, *scratch = NULL; // a later key's starts; other_starts' scratch
    int held_strokes = 0;
    double held_length = 0;
    const sp_param* params = NULL;
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
    start_p = malloc(sizeof(double) * (size_t)(3 * P + 1));
    if (!kp || !notes || !start_p) goto oom;
    held_p = start_p + P, scratch = start_p + 2 * P;
    params = sp_rig_handle_params(rig);
    for (int k = 0; k < n; ++k) {
        sp_sketch sk = {0};
        if (sp_read_strokes(keys.items[k], &sk, &err) != SP_OK) goto fail;
        sp_camera cam = sp_rig_handle_camera(rig, sk.canvas_w, sk.canvas_h);
        const double* start = k == 0 ? p0 : kp + (size_t)(k - 1) * P;
        const bool* moves = NULL;
        if (held) {
            double ratio = size_ratio(&sk, held_strokes, held_length);
            moves = ratio == 1.0 ? held : held + P;
            set_moves(&run, moves);
            sized_start(params, held, P, start, kp + (size_t)held_key * P, ratio, start_p);
            sized_start(params, held, P, kp + (size_t)held_key * P, kp + (size_t)held_key * P, ratio, held_p);
            start = start_p;
        }
        sp_solve_report rep;
        cJSON* j = NULL;
        bool solved = sp_solve_cmd_solve(&run, &cam, &sk, keys.items[k], start, kp + (size_t)k * P, &rep, &j);
        if (solved && k > 0 &&
            !other_starts(&run, &cam, &sk, keys.items[k], p0, moves, held_p, scratch, kp + (size_t)k * P, P, &rep, &j)) {
            sp_sketch_free(&sk);
            goto oom;
        }
        if (solved && !held && rep.mean_error_px <= 0.05 * rep.bbox_diagonal_px) {
            if (!hold_shape(&run, &ch->rig, &held, P)) {
                sp_sketch_free(&sk);
                goto oom;
            }
            held_key = k, held_strokes = sk.stroke_count, held_length = drawn_length(&sk);
        }
        sp_sketch_free(&sk);
        if (!solved) goto done;
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
