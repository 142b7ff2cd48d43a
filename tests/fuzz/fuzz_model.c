// fuzz_model.c: libFuzzer entry for classifier models (sp_clf_from_bytes, what
// `--model` files and the part database's models go through), then one
// classification with each model that loads, so that the options a model
// carries are used as well as read.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model_checksum.h"
#include "sp/classifier.h"

// A zigzag over a square canvas: ink in every pyramid cell.
static void classify(const sp_clf* clf)
{
    sp_vec2 pts[12];
    for (int i = 0; i < 12; ++i)
        pts[i] = (sp_vec2){20.0 + 20.0 * i, i % 2 ? 60.0 : 200.0};
    sp_sketch s = {.canvas_w = 256, .canvas_h = 256};
    sp_error err = {0};
    if (sp_sketch_add_stroke(&s, pts, NULL, 12) == SP_OK) {
        sp_clf_answer a;
        sp_clf_classify(clf, &s, NULL, &a, &err);
    }
    sp_sketch_free(&s);
}

static void load(const uint8_t* data, size_t size)
{
    sp_clf* clf = NULL;
    sp_error err = {0};
    if (sp_clf_from_bytes(data, size, "fuzz.spclf", &clf, &err) != SP_OK) return;
    classify(clf);
    sp_clf_destroy(clf);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    load(data, size);
    // Again with the header's length and the checksum made right: a mutation
    // almost never keeps them, and the reader behind them must see such input.
    if (size < 32) return 0;
    uint8_t* fixed = malloc(size);
    if (!fixed) return 0;
    memcpy(fixed, data, size);
    uint64_t len = size - 32, sum = sp_clf_checksum(fixed + 24, (size_t)len);
    memcpy(fixed + 16, &len, 8);
    memcpy(fixed + 24 + len, &sum, 8);
    load(fixed, size);
    free(fixed);
    return 0;
}
