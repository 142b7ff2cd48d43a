// db_recipe.c: the synthetic sketches stored with a part (the database's
// default training recipe, docs/DESIGN.md "Part database training data").
//
// Visitors draw their own idea of a part: its whole silhouette with the
// horns, spikes, teeth and claws, or without them, only its back or its
// belly, a tail or a pair of legs as one line, details the part does not
// have, in any pose the part can take. The recipe draws all of these from
// the part itself (sp/handdraw.h shapes) through the hand-drawing model, in
// a fixed cycle so that every count gets the same mix.
#include <stdlib.h>
#include <string.h>

#include "db_internal.h"
#include "sp/handdraw.h"
#include "sp/math.h"

// Pose amplitudes (radians): a visibly posed part, and the whole of its bounds.
#define AMPLITUDE_NEAR 0.4
#define AMPLITUDE_FULL 3.2

typedef struct recipe_slot {
    sp_handdraw_shape shape;
    bool details;  // the silhouette with decorations instead of the abstraction
    double spikes; // chance of added spikes
    bool clean;    // no perturbation: anchors small sets on the exact shape
} recipe_slot;

// One cycle of the recipe; sketch i takes slot i mod 20, its pose amplitude
// alternating between near and full every other cycle slot (pieces: near).
static const recipe_slot k_cycle[20] = {
    {SP_HANDDRAW_SHAPE_OUTLINE, false, 0, true},    {SP_HANDDRAW_SHAPE_PIECE, false, 0, false},
    {SP_HANDDRAW_SHAPE_OUTLINE, true, 0, false},    {SP_HANDDRAW_SHAPE_OUTLINE, true, 1, false},
    {SP_HANDDRAW_SHAPE_OUTLINE, false, 1, false},   {SP_HANDDRAW_SHAPE_PIECE, true, 0, false},
    {SP_HANDDRAW_SHAPE_OUTLINE, true, 0, false},    {SP_HANDDRAW_SHAPE_TOP, true, 0, false},
    {SP_HANDDRAW_SHAPE_UNDERSIDE, false, 0, false}, {SP_HANDDRAW_SHAPE_LINE, false, 0, false},
    {SP_HANDDRAW_SHAPE_OUTLINE, true, 0, true},     {SP_HANDDRAW_SHAPE_PIECE, false, 0, false},
    {SP_HANDDRAW_SHAPE_PIECE, true, 0, false},      {SP_HANDDRAW_SHAPE_OUTLINE, true, 1, false},
    {SP_HANDDRAW_SHAPE_OUTLINE, false, 1, false},   {SP_HANDDRAW_SHAPE_OUTLINE, true, 0, false},
    {SP_HANDDRAW_SHAPE_PIECE, true, 1, false},      {SP_HANDDRAW_SHAPE_TOP, false, 0, false},
    {SP_HANDDRAW_SHAPE_UNDERSIDE, true, 0, false},  {SP_HANDDRAW_SHAPE_LINE, false, 0, false},
};

sp_result db_dataset_one(sp_dataset* out, const char* category, int n, sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (sp_dataset_add_category(out, category) < 0 || (n > 0 && !(out->samples = calloc((size_t)n, sizeof *out->samples)))) {
        sp_dataset_free(out);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    out->capacity = n;
    return SP_OK;
}

sp_result db_dataset_labels(const cJSON* items, const char* key, sp_dataset* out, int* bad, sp_error* err)
{
    memset(out, 0, sizeof *out);
    int n = cJSON_GetArraySize(items), ncat = 0;
    const char** cats = calloc((size_t)(n ? n : 1), sizeof *cats);
    if (!cats) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sp_result r = SP_OK;
    for (int i = 0; i < n; ++i) {
        const char* c = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(items, i), key));
        if (!c || !*c) {
            *bad = i;
            r = SP_ERR_PARSE;
            break;
        }
        int k = 0;
        while (k < ncat && strcmp(cats[k], c) != 0)
            ++k;
        if (k == ncat) cats[ncat++] = c;
    }
    if (r == SP_OK) qsort(cats, (size_t)ncat, sizeof *cats, sp_cmp_cstr);
    for (int k = 0; r == SP_OK && k < ncat; ++k)
        if (sp_dataset_add_category(out, cats[k]) < 0) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    free(cats);
    if (r != SP_OK) sp_dataset_free(out);
    return r;
}

sp_result db_synth_sketches(const sp_character* ch, int abstraction, int n, uint64_t seed, double amplitude, sp_dataset* out,
                            sp_error* err)
{
    sp_result r = db_dataset_one(out, "part", n, err);
    if (r != SP_OK) return r;
    sp_sample* s = out->samples;
    bool line = sp_handdraw_shape_available(&ch->rig, SP_HANDDRAW_SHAPE_LINE),
         piece = sp_handdraw_shape_available(&ch->rig, SP_HANDDRAW_SHAPE_PIECE);
    for (int i = 0; r == SP_OK && i < n; ++i) {
        recipe_slot slot = k_cycle[i % 20];
        // No single line through a head or a torso: their silhouette instead.
        if ((slot.shape == SP_HANDDRAW_SHAPE_LINE && !line) || (slot.shape == SP_HANDDRAW_SHAPE_PIECE && !piece))
            slot = (recipe_slot){SP_HANDDRAW_SHAPE_OUTLINE, true, slot.spikes, false};
        double amp = amplitude > 0 ? amplitude : (i / 20) % 2 == (i % 2) ? AMPLITUDE_NEAR : AMPLITUDE_FULL;
        // A piece in a near pose: a head alone with its jaws gaping is a V, not a head.
        if (slot.shape == SP_HANDDRAW_SHAPE_PIECE && amplitude <= 0) amp = AMPLITUDE_NEAR;
        sp_handdraw_desc hd = {.style = slot.clean ? SP_HANDDRAW_CLEAN : SP_HANDDRAW_NORMAL,
                               .amplitude = slot.clean ? AMPLITUDE_NEAR : amp,
                               .shape = slot.shape,
                               .details = slot.details,
                               .spikes = slot.spikes};
        r = sp_handdraw_part(&ch->rig, abstraction, &ch->camera, &hd, sp_handdraw_seed(seed, i), &s[i].sketch, NULL, err);
        // A part whose view or mesh the other shapes cannot use (a perspective
        // camera, no skinned triangles) is drawn as its abstraction.
        if (r != SP_OK && (hd.shape != SP_HANDDRAW_SHAPE_OUTLINE || hd.details || hd.spikes > 0)) {
            hd.shape = SP_HANDDRAW_SHAPE_OUTLINE, hd.details = false, hd.spikes = 0;
            r = sp_handdraw_part(&ch->rig, abstraction, &ch->camera, &hd, sp_handdraw_seed(seed, i), &s[i].sketch, NULL, err);
        }
        s[i].label = 0;
        s[i].index = i;
        out->count = i + (r == SP_OK);
    }
    if (r != SP_OK) sp_dataset_free(out);
    return r;
}
