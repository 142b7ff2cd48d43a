// sketchpose demo: the headless demo of the README's run command (no
// display): poses a shipped character from synthetic strokes, writes a
// render and a .glb, and says where.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "posing.h"
#include "report.h"
#include "snapshot.h"
#include "sp/gltf.h"
#include "sp/sketch_io.h"
#include "sp/solver.h"
#include "sp/synth.h"

#ifndef SP_SOURCE_DIR
#define SP_SOURCE_DIR "."
#endif

// The first candidate that exists: a shipped asset, else the shared samples.
static const char* find_character(char* buf, size_t n)
{
    const char* candidates[] = {SP_SOURCE_DIR "/assets/cartoon_man.glb", SP_SOURCE_DIR "/../shared/data/gltf/CesiumMan/CesiumMan.glb"};
    for (size_t i = 0; i < sizeof candidates / sizeof candidates[0]; ++i) {
        struct stat st;
        if (stat(candidates[i], &st) == 0) {
            snprintf(buf, n, "%s", candidates[i]);
            return buf;
        }
    }
    return NULL;
}

int cmd_demo(int argc, char** argv)
{
    const char *out_dir = "demo-out", *rig_path = NULL;
    int seed = 7;
    const sp_opt opts[] = {
        {"--out", SP_OPT_STRING, &out_dir, "DIR", "where to write the render, strokes and .glb (default demo-out)", false},
        {"--rig", SP_OPT_STRING, &rig_path, "R.gltf", "character to pose (default: a shipped one)", false},
        {"--seed", SP_OPT_INT, &seed, "N", "which random target pose (default 7)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose demo", "Headless demo: strokes of a pose in, a posed character out.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    char found[1024];
    if (!rig_path && !(rig_path = find_character(found, sizeof found))) {
        fprintf(stderr, "sketchpose demo: no character found (assets/ has none yet and ../shared/data is absent); pass --rig\n");
        return SP_EXIT_INPUT;
    }
    if (mkdir(out_dir, 0755) != 0) {
        struct stat st;
        if (stat(out_dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
            fprintf(stderr, "sketchpose demo: %s: cannot create the folder\n", out_dir);
            return SP_EXIT_INPUT;
        }
    }
    sp_character ch = {0};
    sp_error err = {0};
    sp_sketch sk = {0};
    double *truth = NULL, *p = NULL;
    sp_solver* solver = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_gltf_load(rig_path, &ch, &err) != SP_OK) goto fail;
    if (sp_pick_abstraction(&ch, rig_path, NULL, &err) < 0) goto fail;
    truth = malloc(sizeof(double) * (size_t)(ch.rig.param_count + 1));
    p = malloc(sizeof(double) * (size_t)(ch.rig.param_count + 1));
    if (!truth || !p) goto fail;
    sp_synth_params(&ch.rig, (uint64_t)(unsigned)seed, 0.6, truth);
    sp_camera cam = sp_camera_resize(&ch.camera, 960, 720);
    if (sp_synth_sketch(&ch.rig, 0, &cam, truth, &sk) != SP_OK) goto fail;
    solver = sp_solver_create(&ch.rig, 0, &cam, &(sp_solve_desc){0});
    if (!solver) goto fail;
    sp_solve_report rep;
    if (sp_solver_solve(solver, &sk, ch.pose, p, &rep, &err) != SP_OK) goto fail;
    char png[1200], glb[1200], strokes[1200], rest_png[1200];
    snprintf(png, sizeof png, "%s/posed.png", out_dir);
    snprintf(rest_png, sizeof rest_png, "%s/rest.png", out_dir);
    snprintf(glb, sizeof glb, "%s/posed.glb", out_dir);
    snprintf(strokes, sizeof strokes, "%s/strokes.json", out_dir);
    sp_snapshot_desc rest = {.character = &ch, .params = ch.pose, .camera = &cam, .abstraction = 0};
    sp_snapshot_desc d = {.character = &ch, .params = p, .camera = &cam, .abstraction = 0, .strokes = &sk};
    if (sp_snapshot_png(&rest, rest_png, &err) != SP_OK || sp_snapshot_png(&d, png, &err) != SP_OK) goto fail;
    if (sp_gltf_save(&ch, p, glb, &err) != SP_OK) goto fail;
    if (sp_sketch_write_json(strokes, &sk, &err) != SP_OK) goto fail;
    printf("posed %s from %d strokes in %.1f ms (mean error %.2f px, %s)\n", rig_path, sk.stroke_count, rep.ms, rep.mean_error_px,
           sp_stop_reason_name(rep.stopped));
    printf("wrote %s (rest pose), %s (strokes blue, fitted abstraction yellow), %s, %s\n", rest_png, png, glb, strokes);
    exit_code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose demo: %s\n", err.text[0] ? err.text : "out of memory");
done:
    sp_solver_destroy(solver);
    free(truth), free(p);
    sp_sketch_free(&sk);
    sp_character_free(&ch);
    return exit_code;
}
