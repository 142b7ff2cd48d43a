/// dragon_parts.h: the six dragon parts for classifier tests and benchmarks
/// (in the fixture library sp_test_fixtures).
///
/// dragon_parts_load() reads assets/<part>.glb (torso, wings, head, tail,
/// front_legs, hind_legs; category from extras.sp_part.category, the
/// `outline` abstraction) when all six are in the source tree, else builds
/// stand-ins in code: a flat closed outline per part (an oval body, a bat
/// wing, a horned head, a spade-tipped tail, a front and a hind leg with
/// claws), skinned rigidly to a chain of 3-5 joints with in-plane rotations
/// and a shape scale, seen from the front. The stand-ins exist so that the
/// hand-drawing model and the dragon-part classifier can be tested without
/// the assets; the real parts replace them as soon as they are there.
#ifndef SP_TEST_DRAGON_PARTS_H
#define SP_TEST_DRAGON_PARTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "sp/classifier.h"
#include "sp/gltf.h"
#include "sp/handdraw.h"
#include "sp/rig.h"
#include "sp/sketch_io.h"

#define DRAGON_PART_COUNT 6

// Benchmarks use this header too, where ENSURE has nowhere to jump: fail loudly instead.
#define DRAGON_CHECK(c)                                                                                                          \
    do {                                                                                                                         \
        if (!(c)) {                                                                                                              \
            fprintf(stderr, "%s:%d: %s failed: %s\n", __FILE__, __LINE__, #c, err.text);                                         \
            abort();                                                                                                             \
        }                                                                                                                        \
    } while (0)

typedef struct dragon_part {
    char name[64];     ///< file stem (torso, wings, ...)
    char category[64]; ///< classifier category
    sp_character ch;
    int abstraction; ///< index of `outline` (else the first)
} dragon_part;

/// The parts' file stems, in the order of parts[] everywhere.
extern const char* const k_dragon_part_names[DRAGON_PART_COUNT];

/// Stand-in part i (0..5) as a character with an `outline` abstraction (asserts on failure).
void dragon_standin(int i, dragon_part* out);

/// Fills parts[6] from assets/ when all six load, else with the stand-ins.
/// Returns true when the assets were used. Free with dragon_parts_free.
bool dragon_parts_load(const char* assets_dir, dragon_part parts[DRAGON_PART_COUNT]);

/// Frees what dragon_parts_load filled.
void dragon_parts_free(dragon_part parts[DRAGON_PART_COUNT]);

// ---- the dragon-part evaluation (issue 5): train on one seed family of
// normal hand-drawn sketches, test on other families drawn harshly, and on
// Quick, Draw! drawings of things that are no dragon part (to be rejected).

/// Quick, Draw! categories used as non-dragon scribbles: objects, none of them
/// an animal or a body part (chosen before any measurement; 8 x 25 = 200).
#define DRAGON_SCRIBBLE_CATEGORIES 8
extern const char* const k_scribble_categories[DRAGON_SCRIBBLE_CATEGORIES];

typedef struct dragon_scores {
    int n, right, top3, rejected, failed; ///< held-out dragon sketches
    int scribbles, scribbles_rejected;    ///< non-dragon drawings
    int confusion[DRAGON_PART_COUNT][DRAGON_PART_COUNT];
    float dragon_dist_max;   ///< largest nearest distance of a dragon sketch
    float scribble_dist_min; ///< smallest nearest distance of a scribble
} dragon_scores;

/// A labelled set of `per_part` hand-drawn sketches of every part; categories are
/// the parts' (sorted, shared when parts share one). Part k uses its own family
/// derived from `family` and its name (sp_handdraw_part_family).
sp_result dragon_set(const dragon_part parts[DRAGON_PART_COUNT], int per_part, uint64_t family, const sp_handdraw_desc* hd,
                     sp_dataset* ds, sp_error* err);
/// The first `per_category` drawings of each scribble category (labels -1).
/// Returns SP_ERR_IO when ../shared/data/quickdraw is absent.
sp_result dragon_scribbles(const char* data_dir, int per_category, sp_dataset* ds, sp_error* err);
/// Classifies `test` (labels = clf categories by name) and `scribbles` (may be NULL).
void dragon_score(const sp_clf* clf, const sp_dataset* test, const sp_dataset* scribbles, dragon_scores* s);

#endif
