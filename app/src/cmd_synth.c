// sketchpose synth: strokes of a random pose within bounds (tests, training).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "pose_io.h"
#include "posing.h"
#include "sp/gltf.h"
#include "sp/sketch_io.h"
#include "sp/synth.h"

int cmd_synth(int argc, char** argv)
{
    const char *rig_path = NULL, *abs_name = NULL, *out = NULL, *truth = NULL, *size = NULL, *pose = NULL;
    int seed = 0;
    double amplitude = 0.7853981633974483, noise = 0;
    const sp_opt opts[] = {
        {"--rig", SP_OPT_STRING, &rig_path, "R.gltf", "the rigged character (.gltf or .glb)", true},
        {"--abstraction", SP_OPT_STRING, &abs_name, "NAME", "which abstraction to draw (default: the first)", false},
        {"--seed", SP_OPT_INT, &seed, "N", "random seed (required unless --pose)", false},
        {"--pose", SP_OPT_STRING, &pose, "p.json", "draw this pose instead of a random one", false},
        {"--amplitude", SP_OPT_DOUBLE, &amplitude, "A", "largest change per rotation from rest, radians (default 0.785)", false},
        {"--out", SP_OPT_STRING, &out, "S.json", "stroke file to write", true},
        {"--truth", SP_OPT_STRING, &truth, "p.json", "also write the pose's parameters", false},
        {"--size", SP_OPT_STRING, &size, "WxH", "canvas size (default: the rig's sketch view)", false},
        {"--noise", SP_OPT_DOUBLE, &noise, "PX", "Gaussian jitter of the stroke points, pixels (default 0)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose synth", "Writes the strokes of a random pose of the rig's abstraction.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    bool seeded = false;
    for (int i = 1; i < argc; ++i) seeded |= !strcmp(argv[i], "--seed");
    if (!seeded && !pose) {
        fprintf(stderr, "sketchpose synth: missing --seed N or --pose p.json (see --help)\n");
        return SP_EXIT_USAGE;
    }
    int w = 0, h = 0;
    if (size && !sp_cli_parse_size(size, &w, &h)) {
        fprintf(stderr, "sketchpose synth: --size expects WxH with sides 16..8192, got '%s'\n", size);
        return SP_EXIT_USAGE;
    }
    if (amplitude < 0 || noise < 0) {
        fprintf(stderr, "sketchpose synth: --amplitude and --noise must not be negative\n");
        return SP_EXIT_USAGE;
    }
    sp_character ch = {0};
    sp_error err = {0};
    sp_sketch sk = {0};
    double* p = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_gltf_load(rig_path, &ch, &err) != SP_OK) goto fail;
    int a = sp_pick_abstraction(&ch, rig_path, abs_name, &err);
    if (a < 0) goto fail;
    sp_camera cam = w ? sp_camera_resize(&ch.camera, w, h) : ch.camera;
    p = malloc(sizeof(double) * (size_t)(ch.rig.param_count + 1));
    if (!p) goto fail;
    if (pose) {
        memcpy(p, ch.pose, sizeof(double) * (size_t)ch.rig.param_count);
        if (sp_pose_read(pose, &ch.rig, p, NULL, &err) != SP_OK) goto fail;
    } else {
        sp_synth_params(&ch.rig, (uint64_t)(unsigned)seed, amplitude, p);
    }
    if (sp_synth_sketch(&ch.rig, a, &cam, p, &sk) != SP_OK) {
        sp_fail(&err, SP_ERR_INTERNAL, "%s: cannot project abstraction '%s'", rig_path, ch.rig.abstractions[a].name);
        goto fail;
    }
    if (noise > 0) {
        sp_rng rng = {(uint64_t)(unsigned)seed ^ 0xA5A5A5A5ull};
        for (int i = 0; i < sk.stroke_count; ++i)
            for (int j = 0; j < sk.strokes[i].count; ++j) {
                sk.strokes[i].points[j].x += noise * sp_rng_normal(&rng);
                sk.strokes[i].points[j].y += noise * sp_rng_normal(&rng);
            }
    }
    if (sp_sketch_write_json(out, &sk, &err) != SP_OK) goto fail;
    if (truth && sp_pose_write(truth, &ch.rig, p, &err) != SP_OK) goto fail;
    exit_code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose synth: %s\n", err.text[0] ? err.text : "out of memory");
done:
    free(p);
    sp_sketch_free(&sk);
    sp_character_free(&ch);
    return exit_code;
}
