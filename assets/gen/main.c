// main.c: sp-assetgen --out DIR [--only NAME]: writes every generated asset
// (DIR/<name>.glb). Deterministic: the same sources give the same bytes.
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "characters.h"
#include "dragon.h"

typedef struct asset {
    const char* name;
    sp_result (*build)(const char* path, sp_error* err);
} asset;

static const asset k_assets[] = {
    {"torso", sp_dragon_torso},
    {"tail", sp_dragon_tail},
    {"head", sp_dragon_head},
    {"wings", sp_dragon_wings},
    {"front_legs", sp_dragon_front_legs},
    {"hind_legs", sp_dragon_hind_legs},
    {"cartoon_man", sp_character_cartoon_man},
    {"elephant", sp_character_elephant},
};
enum { ASSET_COUNT = sizeof k_assets / sizeof k_assets[0] };

static void usage(FILE* f)
{
    fprintf(f, "usage: sp-assetgen --out DIR [--only NAME]\n"
               "writes DIR/<name>.glb for every generated asset (or only NAME):");
    for (int i = 0; i < ASSET_COUNT; ++i)
        fprintf(f, " %s", k_assets[i].name);
    fprintf(f, "\n");
}

int main(int argc, char** argv)
{
    const char *out = NULL, *only = NULL;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(argv[i], "--out") && i + 1 < argc) {
            out = argv[++i];
        } else if (!strcmp(argv[i], "--only") && i + 1 < argc) {
            only = argv[++i];
        } else {
            fprintf(stderr, "sp-assetgen: unknown or incomplete option '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }
    if (!out) {
        fprintf(stderr, "sp-assetgen: --out DIR is required\n");
        usage(stderr);
        return 2;
    }
    struct stat st;
    if (stat(out, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "sp-assetgen: %s: not a directory\n", out);
        return 1;
    }
    int done = 0;
    for (int i = 0; i < ASSET_COUNT; ++i) {
        if (only && strcmp(only, k_assets[i].name) != 0) continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.glb", out, k_assets[i].name);
        sp_error err = {0};
        if (k_assets[i].build(path, &err) != SP_OK) {
            fprintf(stderr, "sp-assetgen: %s\n", err.text);
            return 1;
        }
        printf("%s\n", path);
        ++done;
    }
    if (!done) {
        fprintf(stderr, "sp-assetgen: no asset named '%s'\n", only);
        usage(stderr);
        return 2;
    }
    return 0;
}
