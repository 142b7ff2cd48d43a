// cmd_inspect.c: `sketchpose inspect --rig R`: a rig's joints, parameters,
// abstractions, animations and load warnings as JSON (DESIGN.md contract),
// for a glTF character or a black-box plugin.
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "rig_handle.h"

// The keys of DESIGN.md for either kind of rig. A plugin adds "black_box":
// true (first) and a `unit` per parameter; it has no joints, animations,
// extras or load warnings, and declares its own sketch view.
static cJSON* inspect_json(sp_rig_handle* h)
{
    const sp_character* ch = sp_rig_handle_character(h); // NULL: a plugin
    cJSON* root = cJSON_CreateObject();
    if (!ch) cJSON_AddBoolToObject(root, "black_box", true);
    cJSON_AddNumberToObject(root, "vertices", sp_rig_handle_vertex_count(h));
    cJSON_AddNumberToObject(root, "triangles", sp_rig_handle_triangle_count(h));
    cJSON* joints = cJSON_AddArrayToObject(root, "joints");
    for (int j = 0; ch && j < ch->rig.joint_count; ++j) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", ch->rig.joints[j].name);
        int pa = ch->rig.joints[j].parent;
        if (pa >= 0)
            cJSON_AddStringToObject(o, "parent", ch->rig.joints[pa].name);
        else
            cJSON_AddNullToObject(o, "parent");
        cJSON_AddItemToArray(joints, o);
    }
    cJSON* params = cJSON_AddArrayToObject(root, "parameters");
    const sp_param* q = sp_rig_handle_params(h);
    for (int k = 0; k < sp_rig_handle_param_count(h); ++k) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", q[k].name);
        cJSON_AddNumberToObject(o, "min", q[k].min);
        cJSON_AddNumberToObject(o, "max", q[k].max);
        cJSON_AddNumberToObject(o, "default", q[k].def);
        cJSON_AddStringToObject(o, "group", q[k].group == SP_GROUP_SHAPE ? "shape" : "pose");
        const char* unit = sp_rig_handle_unit(h, k);
        if (unit) cJSON_AddStringToObject(o, "unit", unit);
        cJSON_AddItemToArray(params, o);
    }
    cJSON* abs = cJSON_AddArrayToObject(root, "abstractions");
    const sp_abstraction* ab = sp_rig_handle_abstractions(h);
    for (int a = 0; a < sp_rig_handle_abstraction_count(h); ++a) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", ab[a].name);
        cJSON_AddNumberToObject(o, "curves", ab[a].curve_count);
        cJSON_AddNumberToObject(o, "points", ab[a].point_count);
        cJSON_AddStringToObject(o, "correspondence", ab[a].correspondence == SP_CORR_CLOSEST ? "closest" : "ordered");
        cJSON_AddBoolToObject(o, "derived", ch && ch->derived_abstraction && !strcmp(ab[a].name, "stick"));
        cJSON_AddItemToArray(abs, o);
    }
    cJSON* anims = cJSON_AddArrayToObject(root, "animations");
    for (int a = 0; ch && a < ch->rig.animation_count; ++a) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", ch->rig.animations[a].name);
        cJSON_AddNumberToObject(o, "duration_s", ch->rig.animations[a].duration_s);
        cJSON_AddItemToArray(anims, o);
    }
    // A plugin declares its sketch view (or asks for the default one).
    cJSON_AddBoolToObject(root, "camera_from_file", ch ? ch->has_camera : true);
    if (ch) cJSON_AddBoolToObject(root, "derived_dofs", ch->derived_dofs);
    // sp_part as it is written (sp_part_write_json), parsed only to nest it in the output.
    char* part_text = NULL;
    sp_error part_err = {0};
    if (ch && ch->has_part && sp_part_write_json(&ch->part, &part_text, &part_err) != SP_OK) {
        cJSON_Delete(root); // only out of memory: the loader's part always writes
        return NULL;
    }
    cJSON* part = part_text ? cJSON_Parse(part_text) : NULL;
    free(part_text);
    if (part)
        cJSON_AddItemToObject(root, "part", part);
    else
        cJSON_AddNullToObject(root, "part");
    cJSON* warnings = cJSON_AddArrayToObject(root, "warnings");
    for (int i = 0; ch && i < ch->warning_count; ++i)
        cJSON_AddItemToArray(warnings, cJSON_CreateString(ch->warnings[i]));
    return root;
}

int cmd_inspect(int argc, char** argv)
{
    const char* rig_path = NULL;
    sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "the rigged character (.gltf or .glb), or a black-box rig plugin (.so)", true}};
    int rc = sp_cli_parse(argc, argv, "sketchpose inspect",
                          "Print a rig's joints, parameters, abstractions, animations and load warnings as JSON.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    sp_rig_handle* rig = NULL;
    sp_error err = {0};
    if (sp_rig_handle_load(rig_path, &rig, &err) != SP_OK) {
        fprintf(stderr, "sketchpose inspect: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    cJSON* root = inspect_json(rig);
    char* text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    sp_rig_handle_free(rig);
    if (!text) {
        fprintf(stderr, "sketchpose inspect: out of memory\n");
        return SP_EXIT_INPUT;
    }
    puts(text);
    free(text);
    return SP_EXIT_OK;
}
