// fuzz_ndjson.c: libFuzzer entry for the Quick, Draw! ndjson reader (and the stroke JSON reader).
#include <stddef.h>
#include <stdint.h>

#include "sp/sketch_io.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    sp_dataset ds = {0};
    sp_error err = {0};
    int label = sp_dataset_add_category(&ds, "fuzz");
    sp_dataset_parse_ndjson(&ds, (const char*)data, size, "fuzz.ndjson", label, &err);
    sp_dataset_free(&ds);
    sp_sketch s;
    sp_sketch_parse_json((const char*)data, size, "fuzz.json", &s, &err);
    sp_sketch_free(&s);
    return 0;
}
