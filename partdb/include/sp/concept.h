/// sp/concept.h: drawings of the dragon parts as visitors imagine them, not
/// as the shipped parts look (the default recipe's "concept" sketches, issue 16
/// item 2; docs/DESIGN.md "Part database training data").
///
/// The parts' own silhouettes, however posed and cropped, are one design each;
/// a child's head is a round skull with a snout, horns or a frill, a wing is an
/// arm with 2-5 scallops, a tail a wavy line ending in a spade or a curl. Each
/// concept is a small shape grammar with its designs drawn from the seed
/// (proportions, features, pose, facing), traced as one stroke the way a
/// person draws a part in the kiosk, then passed through the hand-drawing
/// model (sp/handdraw.h, normal style). Same seed, same bits on every machine.
///
///     sp_concept c = sp_concept_parse("head");
///     if (c != SP_CONCEPT_COUNT) sp_concept_sketch(c, seed, &sketch, &err);
#ifndef SP_CONCEPT_H
#define SP_CONCEPT_H

#include <stdint.h>

#include "sp/result.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The parts a concept exists for (the kiosk's six categories).
typedef enum sp_concept {
    SP_CONCEPT_HEAD = 0,
    SP_CONCEPT_WINGS,
    SP_CONCEPT_TAIL,
    SP_CONCEPT_FRONT_LEGS,
    SP_CONCEPT_HIND_LEGS,
    SP_CONCEPT_TORSO,
    SP_CONCEPT_COUNT
} sp_concept;

/// The category name of a concept ("head", "wings", "tail", "front_legs", "hind_legs", "torso").
const char* sp_concept_name(sp_concept c);
/// The concept of a part category; SP_CONCEPT_COUNT when there is none (a curator's own category).
sp_concept sp_concept_parse(const char* category);

/// Canvas of concept sketches, pixels (the kiosk's).
#define SP_CONCEPT_CANVAS_W 1280.0
#define SP_CONCEPT_CANVAS_H 800.0

/// The seed of the i-th concept sketch of `c` in seed family `family`:
/// sp_handdraw_seed(sp_handdraw_part_family(family, its name), i). Family 1
/// is the default database's own; `db init --concept-family F` and `synth
/// --concepts --seed F` draw the same sketches through it.
uint64_t sp_concept_seed(sp_concept c, uint64_t family, int i);
/// The clean drawing of the design of `seed`: one stroke, a closed one
/// repeating its first point at the end, its bounding box 340 px across the
/// diagonal, centred on the canvas. SP_ERR_INVALID for an unknown concept.
sp_result sp_concept_clean(sp_concept c, uint64_t seed, sp_sketch* out, sp_error* err);
/// The same design through the hand-drawing model (normal style), with timestamps.
sp_result sp_concept_sketch(sp_concept c, uint64_t seed, sp_sketch* out, sp_error* err);
/// A placed sketch (sp_concept_clean's, or a design's placed as one) through the
/// hand-drawing model (normal style), seeded by `seed`, as sp_concept_sketch
/// draws its own: the recipe's designs are drawn by the same hand.
sp_result sp_concept_draw(const sp_sketch* clean, uint64_t seed, sp_sketch* out, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
