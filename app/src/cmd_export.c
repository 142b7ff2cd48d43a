// cmd_export.c: `sketchpose export --rig R [--pose p.json] --out X.glb`:
// writes the rig posed by a pose file (default: the pose stored in R) as
// .glb, or .gltf with embedded buffers when --out ends otherwise.
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "pose_io.h"
#include "sp/gltf.h"

int cmd_export(int argc, char** argv)
{
    const char* rig_path = NULL;
    const char* pose_path = NULL;
    const char* out_path = NULL;
    sp_opt opts[] = {
        {"--rig", SP_OPT_STRING, &rig_path, "R.gltf", "the rigged character (.gltf or .glb)", true},
        {"--pose", SP_OPT_STRING, &pose_path, "p.json", "pose file {\"parameters\": {...}}; default: the pose stored in R",
         false},
        {"--out", SP_OPT_STRING, &out_path, "X.glb", "output: .glb, or .gltf with embedded buffers", true},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose export",
                          "Write a rig posed by a pose file as glTF (parameters baked into the joints).", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    sp_character ch = {0};
    sp_error err = {0};
    if (sp_gltf_load(rig_path, &ch, &err) != SP_OK) {
        fprintf(stderr, "sketchpose export: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    int clamped = 0;
    if (pose_path && sp_pose_read(pose_path, &ch.rig, ch.pose, &clamped, &err) != SP_OK) {
        fprintf(stderr, "sketchpose export: %s\n", err.text);
        sp_character_free(&ch);
        return SP_EXIT_INPUT;
    }
    if (sp_gltf_save(&ch, ch.pose, out_path, &err) != SP_OK) {
        fprintf(stderr, "sketchpose export: %s\n", err.text);
        sp_character_free(&ch);
        return SP_EXIT_INPUT;
    }
    cJSON* root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "out", out_path);
    cJSON_AddNumberToObject(root, "parameters", ch.rig.param_count);
    cJSON_AddNumberToObject(root, "clamped", clamped);
    char* text = cJSON_PrintUnformatted(root);
    if (text) puts(text);
    free(text);
    cJSON_Delete(root);
    sp_character_free(&ch);
    return SP_EXIT_OK;
}
