// sketchpose synth: strokes of a random pose within bounds (tests, training);
// with --style, passed through the hand-drawing model; with --parts DIR, a
// labelled folder of hand-drawn sketches of every part in DIR; with
// --concepts, the default recipe's concept sketches (sp/concept.h); with
// --drawings, its draws of the hand-placed designs (sp_db_drawn_sketches).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "clf_cli.h"
#include "cli.h"
#include "outputs.h"
#include "pose_io.h"
#include "posing.h"
#include "report.h"
#include "rig_handle.h"
#include "sp/concept.h"
#include "sp/gltf.h"
#include "sp/handdraw.h"
#include "sp/math.h"
#include "sp/partdb.h"
#include "sp/sketch_io.h"
#include "sp/sketch_sheet.h"
#include "sp/synth.h"

static bool has_opt(int argc, char** argv, const char* name)
{
    for (int i = 1; i < argc; ++i)
        if (!strcmp(argv[i], name)) return true;
    return false;
}

// Whether every option in argv is one of `taken` (NULL-terminated); else one
// line naming the first that is not and false (exit 2). An option a mode
// does not use was ignored: --per-part 5 with --rig still drew one drawing.
static bool takes_only(int argc, char** argv, const char* mode, const char* const* taken)
{
    for (int i = 1; i < argc; ++i) {
        if (strncmp(argv[i], "--", 2) != 0) continue; // a value (sp_cli_parse keeps "--" out of values)
        bool ok = false;
        for (const char* const* t = taken; *t && !ok; ++t)
            ok = !strcmp(argv[i], *t);
        if (!ok) {
            fprintf(stderr, "sketchpose synth: %s does not apply to %s (see --help)\n", argv[i], mode);
            return false;
        }
    }
    return true;
}

// Loads the parts `names` of `dir` into chs[] with the abstraction each
// draws in abs_of[] (-1: not a part, no category); false on the first that
// does not load or lacks its abstraction. The abstraction: --abstraction,
// else the part's own choice, else its outline, else the first.
static bool load_parts(const char* dir, char** names, int n, const char* abs_name, sp_character* chs, int* abs_of, sp_error* err)
{
    for (int k = 0; k < n; ++k) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        sp_character* ch = &chs[k];
        if (sp_gltf_load(path, ch, err) != SP_OK) return false;
        abs_of[k] = -1;
        if (!ch->part.category[0]) continue;
        const char* an = abs_name ? abs_name : ch->part.abstraction[0] ? ch->part.abstraction : NULL;
        if (!an && sp_rig_find_abstraction(&ch->rig, "outline") >= 0) an = "outline";
        if ((abs_of[k] = sp_pick_abstraction(ch->rig.abstractions, ch->rig.abstraction_count, path, an, err)) < 0) return false;
    }
    return true;
}

// --parts DIR: every .glb/.gltf part of DIR (category from extras.sp_part),
// `per_part` hand-drawn sketches each, into OUT/<category>/<part>-<style>-<family>-<i>.json.
static int synth_parts(const char* dir, const char* abs_name, int per_part, uint64_t family, const sp_handdraw_desc* base,
                       const char* out_dir)
{
    sp_handdraw_style style = base->style;
    sp_error err = {0};
    char** names = NULL;
    int n = 0;
    if (sp_dir_list(dir, &names, &n, &err) != SP_OK) {
        fprintf(stderr, "sketchpose synth: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    // Only the .glb and .gltf files, in the listing's sorted order.
    int kept = 0;
    for (int k = 0; k < n; ++k) {
        if (sp_path_ext_is(names[k], "glb") || sp_path_ext_is(names[k], "gltf"))
            names[kept++] = names[k];
        else
            free(names[k]);
    }
    n = kept;
    int code = SP_EXIT_INPUT;
    if (n == 0) {
        fprintf(stderr, "sketchpose synth: %s: no .glb or .gltf parts in the folder\n", dir);
        free(names);
        return SP_EXIT_INPUT;
    }
    // Every part is read and checked before anything is written: a bad part
    // in the folder left the sketches of the ones before it in an existing D.
    sp_character* chs = calloc((size_t)n, sizeof *chs);
    int* abs_of = calloc((size_t)n, sizeof *abs_of);
    if (!chs || !abs_of || !load_parts(dir, names, n, abs_name, chs, abs_of, &err)) {
        fprintf(stderr, "sketchpose synth: %s\n", err.text[0] ? err.text : "out of memory");
        for (int j = 0; j < n; ++j) {
            free(names[j]);
            if (chs) sp_character_free(&chs[j]);
        }
        free(names), free(chs), free(abs_of);
        return SP_EXIT_INPUT;
    }
    // The result is said once the sketches are all written; a failure
    // takes back the folder it made (it printed a result and left the folder).
    // Made is mkdir's own answer: a folder another process made meanwhile is
    // not this command's to remove.
    bool made = mkdir(out_dir, 0777) == 0;
    char* text = NULL;
    size_t len = 0;
    FILE* js = open_memstream(&text, &len);
    if (!js || sp_dir_make(out_dir, &err) != SP_OK) goto fail;
    sp_handdraw_desc desc = *base;
    int total = 0, written = 0;
    fprintf(js, "{\"out_dir\": ");
    clf_cli_json_str(js, out_dir);
    fprintf(js, ", \"style\": \"%s\", \"seed\": %llu, \"parts\": [", sp_handdraw_style_name(style), (unsigned long long)family);
    for (int k = 0; k < n; ++k) {
        char path[4096], stem[256], category[SP_NAME_MAX];
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        snprintf(stem, sizeof stem, "%s", names[k]);
        *strrchr(stem, '.') = 0;
        const sp_character* ch = &chs[k];
        int a = abs_of[k];
        if (a < 0) {
            // A character beside the parts (assets/ holds both): not a part, left out.
            fprintf(stderr, "sketchpose synth: %s: skipped (no extras.sp_part.category: not a part)\n", path);
            continue;
        }
        snprintf(category, sizeof category, "%s", ch->part.category);
        char cdir[4096];
        snprintf(cdir, sizeof cdir, "%s/%s", out_dir, category);
        if (sp_dir_make(cdir, &err) != SP_OK) goto fail;
        uint64_t pf = sp_handdraw_part_family(family, stem);
        int count = sp_handdraw_shape_available(&ch->rig, desc.shape) ? per_part : 0; // no single line through a head
        for (int i = 0; i < count; ++i) {
            sp_sketch sk = {0};
            if (sp_handdraw_part(&ch->rig, a, &ch->camera, &desc, sp_handdraw_seed(pf, i), &sk, NULL, &err) != SP_OK) goto fail;
            char file[4400];
            snprintf(file, sizeof file, "%s/%s-%s-s%llu-%04d.json", cdir, stem, sp_handdraw_style_name(style),
                     (unsigned long long)family, i);
            sp_result r = sp_sketch_write_json(file, &sk, &err);
            sp_sketch_free(&sk);
            if (r != SP_OK) goto fail;
        }
        total += count;
        fprintf(js, "%s{\"name\": ", written++ ? ", " : "");
        clf_cli_json_str(js, stem);
        fprintf(js, ", \"category\": ");
        clf_cli_json_str(js, category);
        fprintf(js, ", \"abstraction\": ");
        clf_cli_json_str(js, ch->rig.abstractions[a].name);
        fprintf(js, ", \"sketches\": %d}", count);
    }
    fprintf(js, "], \"sketches\": %d}\n", total);
    if (written == 0) {
        sp_fail(&err, SP_ERR_INVALID, "%s: no part (a .glb/.gltf with extras.sp_part.category) in the folder", dir);
        goto fail;
    }
    if (fclose(js) != 0) {
        js = NULL;
        sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
        goto fail;
    }
    js = NULL;
    fputs(text, stdout);
    code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose synth: %s\n", err.text[0] ? err.text : "out of memory");
    if (made) sp_dir_remove_tree(out_dir);
done:
    if (js) fclose(js);
    free(text);
    for (int k = 0; k < n; ++k)
        free(names[k]), sp_character_free(&chs[k]);
    free(names), free(chs), free(abs_of);
    return code;
}

// --concepts: `per_part` concept sketches of each of the six parts (seeds
// sp_concept_seed: family 1 gives the default database's own), into
// OUT/<category>/concept-s<family>-<i>.json and/or one contact sheet.
static int synth_concepts(int per_part, uint64_t family, bool clean, const char* out_dir, const char* sheet)
{
    sp_error err = {0};
    int n = per_part * SP_CONCEPT_COUNT, code = SP_EXIT_INPUT, made = 0;
    sp_sketch* sk = calloc((size_t)n, sizeof *sk);
    sp_sheet_item* items = calloc((size_t)n, sizeof *items);
    char(*labels)[48] = calloc((size_t)n, sizeof *labels);
    if (!sk || !items || !labels) {
        sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
        goto fail;
    }
    if (out_dir && sp_dir_make(out_dir, &err) != SP_OK) goto fail;
    for (int c = 0; c < SP_CONCEPT_COUNT; ++c) {
        char cdir[4096];
        snprintf(cdir, sizeof cdir, "%s/%s", out_dir ? out_dir : ".", sp_concept_name((sp_concept)c));
        if (out_dir && sp_dir_make(cdir, &err) != SP_OK) goto fail;
        for (int i = 0; i < per_part; ++i, ++made) {
            uint64_t sd = sp_concept_seed((sp_concept)c, family, i);
            sp_result r = clean ? sp_concept_clean((sp_concept)c, sd, &sk[made], &err)
                                : sp_concept_sketch((sp_concept)c, sd, &sk[made], &err);
            if (r != SP_OK) goto fail;
            snprintf(labels[made], sizeof labels[made], "%s %d", sp_concept_name((sp_concept)c), i);
            items[made] = (sp_sheet_item){.sketch = &sk[made], .label = labels[made]};
            char file[4400];
            snprintf(file, sizeof file, "%s/concept-s%llu-%04d.json", cdir, (unsigned long long)family, i);
            if (out_dir && sp_sketch_write_json(file, &sk[made], &err) != SP_OK) goto fail;
        }
    }
    char title[96];
    snprintf(title, sizeof title, "concept sketches, seed family %llu", (unsigned long long)family);
    if (sheet && sp_sheet_write_png(items, n, &(sp_sheet_desc){.cols = per_part < 12 ? per_part : 12, .title = title}, sheet,
                                    &err) != SP_OK)
        goto fail;
    printf("{\"concepts\": %d, \"per_part\": %d, \"seed\": %llu}\n", made, per_part, (unsigned long long)family);
    code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose synth: %s\n", err.text[0] ? err.text : "out of memory");
done:
    for (int i = 0; sk && i < n; ++i)
        sp_sketch_free(&sk[i]);
    free(sk);
    free(items);
    free(labels);
    return code;
}

// --drawings: `per_design` draws of each design of assets/sketches/drawings.json
// (family: the default database's own is 1) as one contact sheet.
static int synth_drawings(int per_design, uint64_t family, const char* sheet)
{
    char assets[1024];
    snprintf(assets, sizeof assets, "%s/assets", SP_SOURCE_DIR);
    sp_error err = {0};
    sp_dataset ds;
    int designs = 0;
    if (sp_db_drawn_sketches(assets, per_design, family, &ds, &designs, &err) != SP_OK) {
        fprintf(stderr, "sketchpose synth: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    int code = SP_EXIT_OK;
    sp_sheet_item* items = calloc((size_t)(ds.count ? ds.count : 1), sizeof *items);
    char(*labels)[48] = calloc((size_t)(ds.count ? ds.count : 1), sizeof *labels);
    if (!items || !labels) {
        sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
        code = SP_EXIT_INPUT;
    }
    for (int i = 0; code == SP_EXIT_OK && i < ds.count; ++i) {
        snprintf(labels[i], sizeof labels[i], "%s %d", ds.categories[ds.samples[i].label], ds.samples[i].index);
        items[i] = (sp_sheet_item){.sketch = &ds.samples[i].sketch, .label = labels[i]};
    }
    char title[96];
    snprintf(title, sizeof title, "hand-placed designs, draws of each: %d, seed family %llu", per_design,
             (unsigned long long)family);
    if (code == SP_EXIT_OK &&
        sp_sheet_write_png(items, ds.count, &(sp_sheet_desc){.cols = 12, .title = title}, sheet, &err) != SP_OK)
        code = SP_EXIT_INPUT;
    if (code == SP_EXIT_OK)
        printf("{\"designs\": %d, \"sketches\": %d, \"seed\": %llu}\n", designs, ds.count, (unsigned long long)family);
    else
        fprintf(stderr, "sketchpose synth: %s\n", err.text);
    free(items);
    free(labels);
    sp_dataset_free(&ds);
    return code;
}

// The view frames the rest pose, so a random pose can carry the strokes
// off the canvas; posing from them then works on points no one could have
// drawn there. Said, not refused: a test may want exactly that.
static void warn_off_canvas(const sp_sketch* sk, const char* out)
{
    int outside = 0, total = 0;
    for (int i = 0; i < sk->stroke_count; ++i)
        outside += sp_stroke_points_off_canvas(&sk->strokes[i], sk->canvas_w, sk->canvas_h), total += sk->strokes[i].count;
    if (outside)
        fprintf(stderr, "sketchpose synth: warning: %s: %d of %d points lie outside the %gx%g canvas\n", out, outside, total,
                sk->canvas_w, sk->canvas_h);
}

// --shape's value (NULL: outline), SP_HANDDRAW_SHAPE_COUNT when unknown.
static int shape_index(const char* name)
{
    static const char* const shapes[SP_HANDDRAW_SHAPE_COUNT] = {"outline", "top", "underside", "line", "piece"};
    int k = 0;
    while (name && k < SP_HANDDRAW_SHAPE_COUNT && strcmp(shapes[k], name) != 0)
        ++k;
    return k;
}

// The rig mode's options, checked.
typedef struct rig_job {
    const char *rig_path, *abs_name, *pose;
    int seed;
    double amplitude;
    int w, h;                // 0: the rig's sketch view
    sp_handdraw_style style; // SP_HANDDRAW_STYLE_COUNT: not hand-drawn
    double noise;
    const char *out, *truth;
} rig_job;

// The rig mode's numbers and --size (into j->w, j->h): one line and false
// when one is out of range.
static bool rig_job_ok(rig_job* j, const char* size)
{
    if (size && !sp_cli_parse_size(size, &j->w, &j->h)) {
        fprintf(stderr, "sketchpose synth: --size expects WxH with sides 16..8192, got '%s'\n",
                sp_text_printable(size, (char[160]){0}, 160));
        return false;
    }
    if (j->amplitude < 0) {
        fprintf(stderr, "sketchpose synth: --amplitude must not be negative\n");
        return false;
    }
    // At most the largest canvas side (--size): jitter beyond the canvas is
    // no drawing, and 1e300 px wrote strokes that readers refuse.
    if (!sp_cli_check_double("sketchpose synth", "--noise", j->noise, 0, false, 8192)) return false;
    if (j->style != SP_HANDDRAW_STYLE_COUNT && sp_rig_path_is_plugin(j->rig_path)) {
        fprintf(stderr, "sketchpose synth: --style is not available for black-box rig plugins (.so)\n");
        return false;
    }
    return true;
}

// Writes the strokes of a pose (random, or j->pose) of the rig's abstraction.
static int synth_rig(const rig_job* j)
{
    sp_rig_handle* rig = NULL;
    sp_error err = {0};
    sp_sketch sk = {0};
    sp_outputs staged = {0};
    double* p = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_rig_handle_load(j->rig_path, &rig, &err) != SP_OK) goto fail;
    int a = sp_rig_handle_pick_abstraction(rig, j->abs_name, &err);
    if (a < 0) goto fail;
    sp_camera cam = sp_rig_handle_camera(rig, j->w, j->h);
    if (sp_rig_handle_read_pose(rig, j->pose, &p, NULL, &err) != SP_OK) goto fail;
    if (!j->pose) sp_rig_handle_synth_params(rig, (uint64_t)(unsigned)j->seed, j->amplitude, p);
    if (sp_rig_handle_synth_sketch(rig, a, &cam, p, &sk, &err) != SP_OK) goto fail;
    if (j->style != SP_HANDDRAW_STYLE_COUNT) {
        sp_handdraw_params hp = sp_handdraw_preset(j->style);
        sp_sketch drawn;
        if (sp_handdraw_apply(&sk, &hp, sp_handdraw_seed((uint64_t)(unsigned)j->seed, 0), &drawn, NULL, &err) != SP_OK) goto fail;
        sp_sketch_free(&sk);
        sk = drawn;
    }
    if (j->noise > 0) sp_synth_jitter(&sk, j->noise, (uint64_t)(unsigned)j->seed);
    // The strokes and their pose together or neither (sp_outputs).
    const char *out_to, *truth_to;
    if (sp_outputs_stage(&staged, j->out, &out_to, &err) != SP_OK ||
        sp_outputs_stage(&staged, j->truth, &truth_to, &err) != SP_OK || sp_sketch_write_json(out_to, &sk, &err) != SP_OK ||
        (truth_to && sp_pose_write(truth_to, sp_rig_handle_params(rig), sp_rig_handle_param_count(rig), p, &err) != SP_OK) ||
        sp_outputs_commit(&staged, &err) != SP_OK)
        goto fail;
    warn_off_canvas(&sk, j->out);
    exit_code = SP_EXIT_OK;
    goto done;
fail:
    sp_outputs_undo(&staged, &err);
    fprintf(stderr, "sketchpose synth: %s\n", err.text[0] ? err.text : "out of memory");
done:
    free(p);
    sp_sketch_free(&sk);
    sp_rig_handle_free(rig);
    return exit_code;
}

int cmd_synth(int argc, char** argv)
{
    const char *rig_path = NULL, *abs_name = NULL, *out = NULL, *truth = NULL, *size = NULL, *pose = NULL;
    const char *parts = NULL, *out_dir = NULL, *style_name = NULL;
    const char *shape_name = NULL, *sheet = NULL;
    int seed = 0, per_part = 60;
    double amplitude = 0.7853981633974483, noise = 0, spikes = 0;
    bool details = false, concepts = false, drawings = false;
    const sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf",
         "the rigged character (.gltf or .glb), or a black-box rig plugin (.so) (required unless --parts)", false},
        {"--abstraction", SP_OPT_STRING, &abs_name, "NAME", "which abstraction to draw (default: the part's own, else the first)",
         false},
        {"--seed", SP_OPT_INT, &seed, "N", "random seed, not negative (required unless --pose)", false},
        {"--pose", SP_OPT_IN, &pose, "p.json", "draw this pose instead of a random one", false},
        {"--amplitude", SP_OPT_DOUBLE, &amplitude, "A",
         "largest change per rotation from rest, radians (default 0.785; with --parts 0.4)", false},
        {"--out", SP_OPT_OUT, &out, "S.json", "stroke file to write (required unless --parts)", false},
        {"--truth", SP_OPT_OUT, &truth, "p.json", "also write the pose's parameters", false},
        {"--size", SP_OPT_STRING, &size, "WxH", "canvas size (default: the rig's sketch view)", false},
        {"--noise", SP_OPT_DOUBLE, &noise, "PX", "Gaussian jitter of the stroke points, pixels in [0, 8192] (default 0)", false},
        {"--style", SP_OPT_STRING, &style_name, "S",
         "hand-drawing model: normal, harsh or clean (default: none; with --parts: normal)", false},
        {"--parts", SP_OPT_STRING, &parts, "DIR",
         "every .glb/.gltf part in DIR (category from extras.sp_part): a labelled folder", false},
        {"--per-part", SP_OPT_INT, &per_part, "N", "with --parts: hand-drawn sketches per part (default 60)", false},
        {"--out-dir", SP_OPT_STRING, &out_dir, "D", "with --parts: folder to write D/<category>/<part>-<style>-s<seed>-<i>.json",
         false},
        {"--shape", SP_OPT_STRING, &shape_name, "S",
         "with --parts: outline (default), top, underside, line (one line through the joints; parts whose skeleton is one or two "
         "chains), or piece (the silhouette of the part's far end: a head without its neck, one leg)",
         false},
        {"--details", SP_OPT_FLAG, &details, "",
         "with --parts: the mesh's silhouette with its decorations instead of the abstraction", false},
        {"--spikes", SP_OPT_DOUBLE, &spikes, "P",
         "with --parts: chance 0..1 of a row of spikes added along the curve (default 0)", false},
        {"--concepts", SP_OPT_FLAG, &concepts, "",
         "the default recipe's concept sketches of the six dragon parts (designs of its own, not the parts' shapes), "
         "--per-part each (--style normal, the default, or clean), into --out-dir D/<category>/ and/or --sheet",
         false},
        {"--drawings", SP_OPT_FLAG, &drawings, "",
         "the default recipe's draws of the hand-placed designs of assets/sketches/drawings.json, --per-part draws of each "
         "(default 1), as --sheet",
         false},
        {"--sheet", SP_OPT_OUT, &sheet, "S.png", "with --concepts or --drawings: a labelled contact sheet of them", false},
    };
    int rc =
        sp_cli_parse(argc, argv, "sketchpose synth",
                     "Writes the strokes of a random pose of the rig's abstraction (--style: as drawn by hand); "
                     "with --parts DIR --out-dir D, a labelled folder of hand-drawn sketches of every part (seed family --seed).",
                     opts, (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_out("sketchpose synth", "--sheet", sheet, SP_CLI_OUT_PNG) ||
        !sp_cli_check_out("sketchpose synth", "--out", out, SP_CLI_OUT_STROKES))
        return SP_EXIT_USAGE;
    bool seeded = has_opt(argc, argv, "--seed");
    sp_handdraw_style style = SP_HANDDRAW_STYLE_COUNT;
    if (style_name && (style = sp_handdraw_style_parse(style_name)) == SP_HANDDRAW_STYLE_COUNT) {
        fprintf(stderr, "sketchpose synth: --style must be normal, harsh or clean, got '%s'\n",
                sp_text_printable(style_name, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    if (drawings) {
        int per = has_opt(argc, argv, "--per-part") ? per_part : SP_DB_DRAWN_DEFAULT;
        if (concepts || parts || rig_path || out || pose || truth || size || out_dir || !sheet || per < 1 || per > 100 ||
            seed < 0) {
            fprintf(stderr, "sketchpose synth: --drawings needs --sheet S.png, takes --per-part 1..100 and --seed F, and none of "
                            "--concepts, --parts, --rig, --out, --out-dir, --pose, --truth, --size\n");
            return SP_EXIT_USAGE;
        }
        static const char* const taken[] = {"--drawings", "--per-part", "--seed", "--sheet", NULL};
        if (!takes_only(argc, argv, "--drawings", taken)) return SP_EXIT_USAGE;
        if (!sp_cli_check_out_folders("sketchpose synth", opts, (int)(sizeof opts / sizeof opts[0]))) return SP_EXIT_INPUT;
        return synth_drawings(per, (uint64_t)(seeded ? seed : 1), sheet);
    }
    if (concepts) {
        if (parts || rig_path || out || pose || truth || size || (!out_dir && !sheet)) {
            fprintf(stderr,
                    "sketchpose synth: --concepts needs --out-dir D or --sheet S.png and takes none of --parts, --rig, --out, "
                    "--pose, --truth, --size\n");
            return SP_EXIT_USAGE;
        }
        if (per_part < 1 || per_part > 10000 || seed < 0 ||
            (style != SP_HANDDRAW_STYLE_COUNT && style != SP_HANDDRAW_NORMAL && style != SP_HANDDRAW_CLEAN)) {
            fprintf(
                stderr,
                "sketchpose synth: --per-part must be 1..10000 with --concepts, --seed not negative, --style normal or clean\n");
            return SP_EXIT_USAGE;
        }
        static const char* const taken[] = {"--concepts", "--per-part", "--seed", "--style", "--out-dir", "--sheet", NULL};
        if (!takes_only(argc, argv, "--concepts", taken)) return SP_EXIT_USAGE;
        // With --out-dir the sheet may go into the folder this command makes.
        if (!out_dir && !sp_cli_check_out_folders("sketchpose synth", opts, (int)(sizeof opts / sizeof opts[0])))
            return SP_EXIT_INPUT;
        return synth_concepts(per_part, (uint64_t)(seeded ? seed : 1), style == SP_HANDDRAW_CLEAN, out_dir, sheet);
    }
    if (parts) {
        if (!out_dir || rig_path || out || pose || truth || size) {
            fprintf(stderr,
                    "sketchpose synth: --parts DIR needs --out-dir D and takes none of --rig, --out, --pose, --truth, --size\n");
            return SP_EXIT_USAGE;
        }
        if (per_part < 1 || per_part > 100000 || seed < 0 || amplitude < 0 || noise != 0) {
            fprintf(stderr, "sketchpose synth: --per-part must be 1..100000, --seed and --amplitude not negative; --noise does "
                            "not apply to --parts\n");
            return SP_EXIT_USAGE;
        }
        sp_handdraw_desc hd = {.style = style == SP_HANDDRAW_STYLE_COUNT ? SP_HANDDRAW_NORMAL : style,
                               .amplitude = has_opt(argc, argv, "--amplitude") ? amplitude : 0.0,
                               .details = details,
                               .spikes = spikes};
        int k = shape_index(shape_name);
        if (k == SP_HANDDRAW_SHAPE_COUNT || !(spikes >= 0 && spikes <= 1)) {
            fprintf(stderr, "sketchpose synth: --shape must be outline, top, underside, line or piece, and --spikes 0..1\n");
            return SP_EXIT_USAGE;
        }
        hd.shape = (sp_handdraw_shape)k;
        static const char* const taken[] = {"--parts",     "--out-dir", "--per-part", "--seed",   "--style", "--abstraction",
                                            "--amplitude", "--shape",   "--details",  "--spikes", NULL};
        if (!takes_only(argc, argv, "--parts", taken)) return SP_EXIT_USAGE;
        return synth_parts(parts, abs_name, per_part, (uint64_t)(seeded ? seed : 1), &hd, out_dir);
    }
    if (!rig_path || !out) { // what else is given, e.g. --out-dir, takes_only names
        fprintf(stderr, "sketchpose synth: missing --rig R.gltf and --out S.json (or use --parts DIR --out-dir D; see --help)\n");
        return SP_EXIT_USAGE;
    }
    static const char* const taken[] = {"--rig",   "--abstraction", "--seed",  "--pose",  "--amplitude", "--out",
                                        "--truth", "--size",        "--noise", "--style", NULL};
    if (!takes_only(argc, argv, "--rig", taken)) return SP_EXIT_USAGE;
    if (!seeded && !pose) {
        fprintf(stderr, "sketchpose synth: missing --seed N or --pose p.json (see --help)\n");
        return SP_EXIT_USAGE;
    }
    if (seed < 0) { // as with --parts and --concepts: -1 was silently seed 4294967295
        fprintf(stderr, "sketchpose synth: --seed must not be negative, got %d\n", seed);
        return SP_EXIT_USAGE;
    }
    rig_job job = {rig_path, abs_name, pose, seed, amplitude, 0, 0, style, noise, out, truth};
    if (!rig_job_ok(&job, size)) return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders("sketchpose synth", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work
    return synth_rig(&job);
}
