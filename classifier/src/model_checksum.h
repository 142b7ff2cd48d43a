/// model_checksum.h: the classifier model file's checksum, 64-bit FNV-1a over
/// the body (classifier.c writes and checks it; the tests and fuzz_model that
/// forge files compute the same one).
#ifndef SP_MODEL_CHECKSUM_H
#define SP_MODEL_CHECKSUM_H

#include <stddef.h>
#include <stdint.h>

static inline uint64_t sp_clf_checksum(const unsigned char* p, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

#endif
