// fuzz_svg.c: libFuzzer entry for the SVG reader.
#include <stddef.h>
#include <stdint.h>

#include "sp/sketch_io.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    sp_sketch s;
    sp_error err = {0};
    sp_sketch_parse_svg((const char*)data, size, "fuzz.svg", &s, &err);
    sp_sketch_free(&s);
    return 0;
}
