// cmd_export.c: `sketchpose export --rig R [--pose p.json] --out X.glb`:
// writes the rig posed by a pose file (default: the pose stored in R) as
// .glb, or .gltf with embedded buffers (any other name is bad usage). A
// black-box plugin is written as its posed mesh, static (as `pose --out`).
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "rig_handle.h"

int cmd_export(int argc, char** argv)
{
    const char* rig_path = NULL;
    const char* pose_path = NULL;
    const char* out_path = NULL;
    sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "the rigged character (.gltf or .glb), or a black-box rig plugin (.so)", true},
        {"--pose", SP_OPT_IN, &pose_path, "p.json", "pose file {\"parameters\": {...}}; default: the pose stored in R", false},
        {"--out", SP_OPT_OUT, &out_path, "X.glb", "output: .glb, or .gltf with embedded buffers", true},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose export",
                          "Write a rig posed by a pose file as glTF (parameters baked into the joints).", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_out("sketchpose export", "--out", out_path, SP_CLI_OUT_GLTF)) return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders("sketchpose export", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work
    sp_rig_handle* rig = NULL;
    sp_error err = {0};
    sp_rig_posed posed = {0};
    double* p = NULL;
    int clamped = 0, exit_code = SP_EXIT_INPUT;
    if (sp_rig_handle_load(rig_path, &rig, &err) != SP_OK) goto fail;
    if (sp_rig_handle_read_pose(rig, pose_path, &p, &clamped, &err) != SP_OK) goto fail;
    sp_camera view = sp_rig_handle_camera(rig, 0, 0);
    if (sp_rig_handle_posed(rig, -1, p, &view, &posed, &err) != SP_OK || sp_rig_posed_save(&posed, out_path, &err) != SP_OK)
        goto fail;
    cJSON* root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "out", out_path);
    cJSON_AddNumberToObject(root, "parameters", sp_rig_handle_param_count(rig));
    cJSON_AddNumberToObject(root, "clamped", clamped);
    char* text = sp_cli_out_is_stdout(out_path) ? NULL : cJSON_PrintUnformatted(root); // the glTF has stdout
    if (text) puts(text);
    free(text);
    cJSON_Delete(root);
    sp_rig_handle_warn_textures("sketchpose export", rig, out_path);
    exit_code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose export: %s\n", err.text);
done:
    sp_rig_posed_free(&posed);
    free(p);
    sp_rig_handle_free(rig);
    return exit_code;
}
