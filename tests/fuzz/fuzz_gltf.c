// fuzz_gltf.c: libFuzzer entry point over sp_gltf_load_memory (.gltf JSON
// and .glb bytes; external files are never opened from memory). Seeds:
// tests/fuzz/corpus/gltf (hand-made, see tests/unit/mini_gltf.h).
//
//     cmake -B build-fuzz -DSP_FUZZ=ON -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++
//     cmake --build build-fuzz --target fuzz_gltf
//     ./build-fuzz/tests/fuzz_gltf -max_total_time=60 tests/fuzz/corpus/gltf
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "sp/gltf.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    sp_character ch;
    sp_error err = {0};
    if (sp_gltf_load_memory(data, size, "fuzz", &ch, &err) == SP_OK) {
        // Whatever loads must also export and load again.
        void* glb = NULL;
        size_t n = 0;
        if (sp_gltf_save_memory(&ch, NULL, &glb, &n, &err) == SP_OK) {
            sp_character back;
            if (sp_gltf_load_memory(glb, n, "fuzz-export", &back, &err) == SP_OK)
                sp_character_free(&back);
            else {
                fprintf(stderr, "export does not load again: %s\n", err.text);
                abort(); // an export we cannot read back is a bug
            }
            free(glb);
        }
        sp_character_free(&ch);
    } else {
        sp_fuzz_one_line(&err);
    }
    return 0;
}
