// cmd_inspect.c: `sketchpose inspect --rig R`: a rig's joints, parameters,
// abstractions, animations and load warnings as JSON (DESIGN.md contract).
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "plugin_rig.h"
#include "sp/gltf.h"

static cJSON* inspect_json(const sp_character* ch)
{
    const sp_rig* rig = &ch->rig;
    cJSON* root = cJSON_CreateObject();
    cJSON_AddNumberToObject(root, "vertices", rig->vertex_count);
    cJSON_AddNumberToObject(root, "triangles", rig->triangle_count);
    cJSON* joints = cJSON_AddArrayToObject(root, "joints");
    for (int j = 0; j < rig->joint_count; ++j) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", rig->joints[j].name);
        int pa = rig->joints[j].parent;
        if (pa >= 0)
            cJSON_AddStringToObject(o, "parent", rig->joints[pa].name);
        else
            cJSON_AddNullToObject(o, "parent");
        cJSON_AddItemToArray(joints, o);
    }
    cJSON* params = cJSON_AddArrayToObject(root, "parameters");
    for (int k = 0; k < rig->param_count; ++k) {
        const sp_param* q = &rig->params[k];
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", q->name);
        cJSON_AddNumberToObject(o, "min", q->min);
        cJSON_AddNumberToObject(o, "max", q->max);
        cJSON_AddNumberToObject(o, "default", q->def);
        cJSON_AddStringToObject(o, "group", q->group == SP_GROUP_SHAPE ? "shape" : "pose");
        cJSON_AddItemToArray(params, o);
    }
    cJSON* abs = cJSON_AddArrayToObject(root, "abstractions");
    for (int a = 0; a < rig->abstraction_count; ++a) {
        const sp_abstraction* ab = &rig->abstractions[a];
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", ab->name);
        cJSON_AddNumberToObject(o, "curves", ab->curve_count);
        cJSON_AddNumberToObject(o, "points", ab->point_count);
        cJSON_AddStringToObject(o, "correspondence", ab->correspondence == SP_CORR_CLOSEST ? "closest" : "ordered");
        cJSON_AddBoolToObject(o, "derived", ch->derived_abstraction && !strcmp(ab->name, "stick"));
        cJSON_AddItemToArray(abs, o);
    }
    cJSON* anims = cJSON_AddArrayToObject(root, "animations");
    for (int a = 0; a < rig->animation_count; ++a) {
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", rig->animations[a].name);
        cJSON_AddNumberToObject(o, "duration_s", rig->animations[a].duration_s);
        cJSON_AddItemToArray(anims, o);
    }
    cJSON_AddBoolToObject(root, "camera_from_file", ch->has_camera);
    cJSON_AddBoolToObject(root, "derived_dofs", ch->derived_dofs);
    cJSON* part = ch->part_json ? cJSON_Parse(ch->part_json) : NULL;
    if (part)
        cJSON_AddItemToObject(root, "part", part);
    else
        cJSON_AddNullToObject(root, "part");
    cJSON* warnings = cJSON_AddArrayToObject(root, "warnings");
    for (int i = 0; i < ch->warning_count; ++i)
        cJSON_AddItemToArray(warnings, cJSON_CreateString(ch->warnings[i]));
    return root;
}

int cmd_inspect(int argc, char** argv)
{
    const char* rig_path = NULL;
    sp_opt opts[] = {{"--rig", SP_OPT_STRING, &rig_path, "R.gltf", "the rigged character (.gltf or .glb), or a black-box rig plugin (.so)", true}};
    int rc = sp_cli_parse(argc, argv, "sketchpose inspect",
                          "Print a rig's joints, parameters, abstractions, animations and load warnings as JSON.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (sp_is_plugin_path(rig_path)) return sp_plugin_inspect(rig_path);
    sp_character ch = {0};
    sp_error err = {0};
    if (sp_gltf_load(rig_path, &ch, &err) != SP_OK) {
        fprintf(stderr, "sketchpose inspect: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    cJSON* root = inspect_json(&ch);
    char* text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    sp_character_free(&ch);
    if (!text) {
        fprintf(stderr, "sketchpose inspect: out of memory\n");
        return SP_EXIT_INPUT;
    }
    puts(text);
    free(text);
    return SP_EXIT_OK;
}
