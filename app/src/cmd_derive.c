// cmd_derive.c: `sketchpose derive --rig R.gltf|.glb --out R_sp.glb [--preview out.png]`:
// a rigged glTF made elsewhere turned into a kiosk part (sp/derive.h): the
// outline and stick abstractions, the visitor's parameters, the attachment
// point and the clip, written as a .glb a curator can inspect (or edit in
// Blender) and add with `db add-part`.
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "outputs.h"
#include "report.h"
#include "sp/derive.h"
#include "sp/part_preview.h"
#include "sp/sketch_io.h"

static const char* k_cmd = "sketchpose derive";

int cmd_derive(int argc, char** argv)
{
    const char *rig_path = NULL, *out_path = NULL, *preview = NULL, *view = NULL;
    sp_derive_desc d = {0};
    const sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "a rigged, skinned glTF (.gltf or .glb), e.g. from Blender or a download",
         true},
        {"--out", SP_OPT_OUT, &out_path, "R_sp.glb", "the part with the derived extras (.glb, or .gltf with embedded buffers)",
         true},
        {"--preview", SP_OPT_OUT, &preview, "out.png",
         "also render the derived outline over the part at rest and in three random poses", false},
        {"--category", SP_OPT_STRING, &d.category, "C",
         "the part's category (sp_part.category; `db add-part --category` can give it later)", false},
        {"--abstraction", SP_OPT_STRING, &d.abstraction, "A", "what its sketches show: outline (default) or stick", false},
        {"--attach-joint", SP_OPT_STRING, &d.attach_joint, "NAME", "the joint it attaches by (default: the root's end)", false},
        {"--view", SP_OPT_STRING, &view, "V",
         "the sketch camera looks along -z, +z, -x or +x of the file's Y-up world (default auto: the file's camera, else the "
         "wider of "
         "-z and -x); +z shows a part modelled facing left from its other side, facing right like the shipped parts",
         false},
    };
    int rc =
        sp_cli_parse(argc, argv, k_cmd,
                     "derive what the kiosk needs of a rigged glTF without sketchpose extras: an outline traced from its side "
                     "silhouette, a stick figure, in-plane rotations and bone scales, the root's placement, an attachment point "
                     "and its first animation as the part's clip; JSON on stdout",
                     opts, (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_out(k_cmd, "--out", out_path, SP_CLI_OUT_GLTF) ||
        !sp_cli_check_out(k_cmd, "--preview", preview, SP_CLI_OUT_PNG))
        return SP_EXIT_USAGE;
    if (!sp_cli_check_name(k_cmd, "--category", d.category)) return SP_EXIT_USAGE;
    if (view && !sp_derive_view_parse(view, &d.view)) {
        fprintf(stderr, "%s: --view wants auto, -z, +z, -x or +x, got '%s'\n", k_cmd,
                sp_text_printable(view, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    if (d.abstraction && strcmp(d.abstraction, "outline") != 0 && strcmp(d.abstraction, "stick") != 0) {
        fprintf(stderr, "%s: --abstraction wants outline or stick, got '%s'\n", k_cmd,
                sp_text_printable(d.abstraction, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    if (!sp_cli_check_out_folders(k_cmd, opts, (int)(sizeof opts / sizeof opts[0]))) return SP_EXIT_INPUT; // before the work
    sp_error err = {0};
    sp_character src = {0}, part = {0};
    sp_derive_info info;
    sp_image sheet = {0};
    int code = SP_EXIT_INPUT;
    if (sp_gltf_load(rig_path, &src, &err) != SP_OK) {
        fprintf(stderr, "%s: %s\n", k_cmd, err.text);
        return SP_EXIT_INPUT;
    }
    // Everything that can fail runs before anything is written.
    if (sp_part_derive(&src, &d, &part, &info, &err) != SP_OK) {
        fprintf(stderr, "%s: %s: %s\n", k_cmd, rig_path, err.text);
        goto done;
    }
    int ab = sp_rig_find_abstraction(&part.rig, d.abstraction ? d.abstraction : "outline");
    if (preview && sp_part_preview_render(&part, ab, &sheet, &err) != SP_OK) {
        fprintf(stderr, "%s: preview: %s\n", k_cmd, err.text);
        goto done;
    }
    sp_outputs staged = {0};
    const char *out_to, *preview_to;
    if (sp_outputs_stage(&staged, out_path, &out_to, &err) != SP_OK ||
        sp_outputs_stage(&staged, preview, &preview_to, &err) != SP_OK || sp_gltf_save(&part, NULL, out_to, &err) != SP_OK ||
        (preview_to && sp_image_write_png(&sheet, preview_to, &err) != SP_OK) || sp_outputs_commit(&staged, &err) != SP_OK) {
        sp_outputs_undo(&staged, &err); // a failed command leaves the outputs as they were
        fprintf(stderr, "%s: %s\n", k_cmd, err.text);
        goto done;
    }
    char shown[300]; // the path as typed, on one line (warnings are one line each)
    sp_text_printable(rig_path, shown, sizeof shown);
    for (int i = 0; i < part.warning_count; ++i)
        fprintf(stderr, "%s: warning: %s: %s\n", k_cmd, shown, part.warnings[i]);

    cJSON* root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "out", out_path);
    if (preview) cJSON_AddStringToObject(root, "preview", preview);
    if (part.part.category[0])
        cJSON_AddStringToObject(root, "category", part.part.category);
    else
        cJSON_AddNullToObject(root, "category");
    cJSON_AddStringToObject(root, "abstraction", part.rig.abstractions[ab].name);
    cJSON* derived = cJSON_AddArrayToObject(root, "derived");
    for (int b = 0; b < SP_DERIVED_COUNT; ++b)
        if (info.derived & (1u << b)) cJSON_AddItemToArray(derived, cJSON_CreateString(sp_derived_name(b)));
    cJSON_AddNumberToObject(root, "vertices", part.rig.vertex_count);
    cJSON_AddNumberToObject(root, "joints", part.rig.joint_count);
    cJSON_AddNumberToObject(root, "joints_folded", info.joints_folded);
    cJSON_AddStringToObject(root, "root", info.root);
    cJSON_AddNumberToObject(root, "parameters", part.rig.param_count);
    cJSON* att = cJSON_AddObjectToObject(root, "attach");
    cJSON_AddStringToObject(att, "joint", info.attach_joint);
    const sp_vec3 at = part.part.attach.position; // the derived part always has its attachment point
    cJSON_AddItemToObject(att, "position", cJSON_CreateDoubleArray((const double[3]){at.x, at.y, at.z}, 3));
    cJSON* abs = cJSON_AddArrayToObject(root, "abstractions");
    for (int a = 0; a < part.rig.abstraction_count; ++a) {
        const sp_abstraction* x = &part.rig.abstractions[a];
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", x->name);
        cJSON_AddNumberToObject(o, "curves", x->curve_count);
        cJSON_AddNumberToObject(o, "points", x->point_count);
        cJSON_AddItemToArray(abs, o);
    }
    cJSON_AddNumberToObject(root, "outline_pieces", info.outline_regions);
    if (info.clip[0]) {
        cJSON* clip = cJSON_AddObjectToObject(root, "clip");
        cJSON_AddStringToObject(clip, "name", info.clip);
        cJSON_AddNumberToObject(clip, "keys", info.clip_keys);
        cJSON_AddNumberToObject(clip, "channels", info.clip_channels);
        cJSON_AddNumberToObject(clip, "duration_s", part.rig.animations[0].duration_s);
    } else {
        cJSON_AddNullToObject(root, "clip");
    }
    cJSON* warnings = cJSON_AddArrayToObject(root, "warnings");
    for (int i = 0; i < part.warning_count; ++i)
        cJSON_AddItemToArray(warnings, cJSON_CreateString(part.warnings[i]));
    // The part or its preview on stdout has it to itself.
    char* text = sp_cli_stdout_taken((const char* const[]){out_path, preview}, 2) ? NULL : cJSON_PrintUnformatted(root);
    if (text) puts(text);
    free(text);
    cJSON_Delete(root);
    code = SP_EXIT_OK;
done:
    sp_image_free(&sheet);
    sp_character_free(&part);
    sp_character_free(&src);
    return code;
}
