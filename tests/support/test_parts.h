/// test_parts.h: the kiosk pipeline test's parts (test_dragon), built in code
/// so that the test does not depend on assets/: chains in the XY plane with a
/// tube mesh, a closed outline abstraction, a looping clip, sp_part sockets /
/// attach hints. In the fixture library sp_test_fixtures.
#ifndef SP_TEST_PARTS_H
#define SP_TEST_PARTS_H

#include <stdbool.h>

#include "sp/rig.h"

typedef struct test_part_spec {
    const char* name;
    const char* category;
    int joints;          // chain joints (the last is the tip)
    double bone_len;     // world units
    double angle0, bend; // chain direction in the XY plane and rest bend per joint, radians
    double r0, r1;       // tube radius at the root and at the tip
    double clip_s;       // clip duration, seconds (0: no clip)
    double sway;         // clip amplitude, radians
    float color[3];
    const char* extras; // sp_part JSON
} test_part_spec;

enum { TEST_PART_COUNT = 5 };
/// Distinct silhouettes, so a small classifier trained on their synthetic sketches tells them apart.
extern const test_part_spec k_test_parts[TEST_PART_COUNT];
/// Added later by the live-update test (a category the first model does not know).
extern const test_part_spec k_test_part_horns;

/// The chain's rig: rotation about z per joint, root placement (tx, ty, uniform s),
/// per-joint uniform scales as shape parameters; a tube mesh; a closed outline.
/// flat: the mesh collapsed onto the chain (every triangle of zero area); the outline keeps its width.
/// Fails the running test on error.
void test_part_rig(const test_part_spec* s, bool flat, sp_rig* rig);
/// Writes the part as glTF (its colour, sp_part extras, a front orthographic camera) to `path`.
void test_part_write(const test_part_spec* s, bool flat, const char* path);

#endif
