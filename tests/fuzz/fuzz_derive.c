// fuzz_derive.c: libFuzzer entry for deriving a kiosk part from a rigged
// glTF made elsewhere (sp_part_derive, what `sketchpose derive` and
// `db add-part` run on a curator's file): whatever loads is derived, and a
// derived part must be written and read back, as the database stores it.
// The outline tracer (sp_outline_trace) runs on every fuzzed mesh.
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "sp/derive.h"
#include "sp/gltf.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    sp_character src;
    sp_error err = {0};
    if (sp_gltf_load_memory(data, size, "fuzz", &src, &err) != SP_OK) return 0;
    sp_character part;
    sp_derive_info info;
    err = (sp_error){0};
    if (sp_part_derive(&src, &(sp_derive_desc){.category = "tail"}, &part, &info, &err) == SP_OK) {
        void* glb = NULL;
        size_t n = 0;
        if (sp_gltf_save_memory(&part, NULL, &glb, &n, &err) != SP_OK) {
            fprintf(stderr, "a derived part does not save: %s\n", err.text);
            abort();
        }
        sp_character back;
        if (sp_gltf_load_memory(glb, n, "fuzz-derived", &back, &err) != SP_OK) {
            fprintf(stderr, "a derived part does not load again: %s\n", err.text);
            abort();
        }
        if (sp_part_needs_derivation(&back)) abort(); // its outline was lost
        sp_character_free(&back);
        free(glb);
        sp_character_free(&part);
    } else {
        sp_fuzz_one_line(&err);
    }
    sp_character_free(&src);
    return 0;
}
