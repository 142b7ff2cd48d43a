/// fixtures.h: reference rigs shared by tests and benchmarks.
///
/// sp_fixture_tree_rig builds a tube mesh around any skeleton: rings of
/// vertices along every bone, skinned smoothly between the bone's two joints,
/// plus a "stick" abstraction (points along each bone, rigid to its parent).
///
/// The fixture library (sp_test_fixtures, tests/CMakeLists.txt) holds every
/// fixture the tests and benchmarks share: these rigs, the dragon parts
/// (dragon_parts.h), the pipeline test's parts (test_parts.h), the foreign
/// lizard (foreign_gltf.h), sp_fixture_glb_json and the JSON and kiosk
/// session readers.
#ifndef SP_FIXTURES_H
#define SP_FIXTURES_H

#include <stdint.h>

#include "sp/rig.h"

struct sp_character;
struct sp_dataset;

/// Deterministic splitmix64 generator for tests.
typedef struct sp_test_rng { uint64_t s; } sp_test_rng;
double sp_test_uniform(sp_test_rng* r); ///< [0, 1)
double sp_test_range(sp_test_rng* r, double lo, double hi);

typedef struct sp_fixture_desc {
    int joint_count;       ///< 0: 4 (a chain)
    bool branching;        ///< random tree instead of a chain
    int rings_per_bone;    ///< 0: 6
    int ring_vertices;     ///< 0: 12
    bool all_channels;     ///< root gets tx/ty/tz + s, others sx/sy/sz or s besides rx/ry/rz
    bool root_scale;       ///< only a uniform scale on the root besides the rotations
    int stick_points;      ///< abstraction points per bone; 0: 8
    bool closest;          ///< the abstraction uses closest-point correspondences
    uint64_t seed;
} sp_fixture_desc;

/// Builds and finalizes a rig (asserts on failure).
void sp_fixture_tree_rig(const sp_fixture_desc* desc, sp_rig* out);
/// Random in-bounds parameters (rotations within +-amplitude of the default).
void sp_fixture_random_params(const sp_rig* rig, sp_test_rng* rng, double amplitude, double* p);

// ---- pieces the fixture rigs are built from (fixtures.c, test_parts.c, dragon_parts.c)

/// Room for a tube mesh of `bones` bones, each `rings` rings of
/// `ring_vertices` vertices: vertex_count, rest (unset), joints4 and
/// weights4 (zero), triangle_count and the triangles between the rings.
void sp_fixture_tube_alloc(sp_rig* rig, int bones, int rings, int ring_vertices);
/// The triangles between the rings of one bone whose first vertex is
/// `base` (ring after ring), written from triangle *t on; *t advances.
void sp_fixture_tube_triangles(sp_rig* rig, int base, int rings, int ring_vertices, int* t);
/// An abstraction "outline" of n points (closest-point correspondences), one
/// closed curve "outline"; rest, joints and weights zero, to fill.
sp_abstraction sp_fixture_outline(int n);

/// ../shared/data/gltf/<rel> (e.g. "CesiumMan/CesiumMan.glb") loaded into
/// ch; skips the running test when ../shared/data is absent, fails it when
/// the file does not load. Free with sp_character_free.
void sp_fixture_shared_gltf(const char* rel, struct sp_character* ch);
/// Whether one of ch's load or derive warnings contains `text`.
bool sp_fixture_has_warning(const struct sp_character* ch, const char* text);

/// ../shared/data/quickdraw as a data set, for a benchmark: false, having
/// said why on stderr after "prog: ", when the data is absent or does not load.
bool sp_fixture_bench_quickdraw(const char* prog, struct sp_dataset* ds);

/// A GLB file's JSON chunk, parsed (fails the running test when the file is
/// no GLB or its JSON does not parse). Free with cJSON_Delete.
struct cJSON* sp_fixture_glb_json(const char* path);

/// A whole file as text (malloc'd, NUL-terminated; *n its bytes, n may be
/// NULL); fails the running test when it does not read.
char* sp_fixture_file_text(const char* path, size_t* n);

/// Runs a shell command (popen): its stdout in out, cut to cap - 1 bytes
/// and NUL-terminated; returns its exit status (-1 when it did not exit).
/// Fails the running test when the command cannot be started.
int sp_fixture_run(const char* cmd, char* out, size_t cap);

/// The npm test tools' folder (tests/tools, or $SP_TEST_TOOLS_DIR) when node
/// and its package pkg ("gltf-validator", "@gltf-transform/core") are
/// installed; NULL when not. With SP_TEST_REQUIRE_TOOLS=1 (tools/sp test sets
/// it, having installed them) a missing tool fails the running test instead:
/// a check that skips quietly there would hide a broken install.
const char* sp_fixture_node_tools(const char* pkg);

/// The Khronos glTF validator (tests/tools/validate.js) on a file: 1 when
/// it passes, 0 when it fails (its report on stderr), -1 when node or the
/// validator is not installed (see sp_fixture_node_tools).
int sp_fixture_gltf_validate(const char* file);

/// fork() for a write checked against a full disk: the child (0 returned)
/// may grow files to at most `bytes` (SIGXFSZ ignored, so a write past it
/// fails with EFBIG; it exits 3 when the limit cannot be set); the parent
/// gets the child's pid, for sp_fixture_child_passed. Fails the running test
/// when fork fails.
int sp_fixture_fork_file_limit(long bytes);

/// fork() for a call that must not hang (a read of a pipe): the child (0
/// returned) is killed by SIGALRM after `seconds`; the parent gets its pid,
/// for sp_fixture_child_passed. Fails the running test when fork fails.
int sp_fixture_fork_alarm(unsigned seconds);

/// Waits for the child `pid`: true when it exited with status 0.
bool sp_fixture_child_passed(int pid);

/// Removes a SQLite database and the -wal and -shm files beside it (each may be absent).
void sp_fixture_remove_db(const char* path);

/// Arms partdb's test hook: the next database open renames `from` over `to`
/// just after SQLite opened the file (a curator's new file arriving during
/// the open). sp_fixture_rename_done says whether it ran, and disarms.
void sp_fixture_rename_when_opened(const char* from, const char* to);
bool sp_fixture_rename_done(void);

/// Stores the newest model of the database at `path` again, as a new row:
/// what `db train` commits, without its minute (the real model's bytes, so a
/// reader reads them as it would). False, said on stderr, when it cannot.
bool sp_fixture_store_model_again(const char* path);

/// Takes the sketchpose database at `path` back to schema version 2 (before
/// reviews: no status column) or 1 (nor a generation counter either), as
/// an older release left it; false, with a line on stderr, on failure.
bool sp_fixture_db_downgrade(const char* path, int version);

/// A JSON file, parsed (fails the running test when it does
/// not read or parse). Free with cJSON_Delete.
struct cJSON* sp_fixture_json_file(const char* path);

/// The strokes of a kiosk session file (sketchpose-kiosk-session, e.g. the
/// README's docs/img/kiosk_on_body.json), in order, at most cap: each
/// malloc'd, n[k] points. Fails the running test when the file does not
/// parse. Returns how many.
int sp_fixture_session_strokes(const char* path, sp_vec2** xy, int* n, int cap);

#endif
