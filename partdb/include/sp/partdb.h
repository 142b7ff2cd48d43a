/// sp/partdb.h: the part database: rigged parts, example sketches, trained
/// classifier models and the curators' log, in one SQLite file.
///
/// How to use (a curator's tool):
///
///     sp_db* db; sp_error err = {0};
///     if (sp_db_open("sketchpose.db", SP_DB_CREATE, &db, &err) != SP_OK) { fprintf(stderr, "%s\n", err.text); ... }
///     sp_db_part_info info;
///     sp_db_add_part_file(db, "wings2.glb", &(sp_db_part_desc){.category = "wings"}, &info, &err);
///     sp_db_train(db, &(sp_db_train_desc){0}, NULL, &err);
///     sp_db_close(db);
///
/// and a reader that must notice a curator's change (the kiosk):
///
///     uint64_t seen = sp_db_generation(db);
///     ... per stroke: if (sp_db_generation(db) != seen) { reload model and parts; seen = ...; }
///
/// Guarantees:
///   - every write (adding a part with its synthetic sketches, adding sketches,
///     removing, storing a trained model) is one SQLite transaction: a crash,
///     SIGKILL or full disk leaves either the old or the new state, never a mix;
///   - everything expensive (glTF validation, the solver self-test, training)
///     runs before the write lock is taken, so writers hold it for milliseconds;
///   - a writer that waits longer than the busy timeout for another writer fails
///     with SP_ERR_BUSY and "database is busy (held by another writer for more than N s)";
///   - WAL mode: readers never block the writer nor see a half-written change.
///
/// The schema is versioned with `PRAGMA user_version` (SP_DB_SCHEMA_VERSION):
/// opening for writing migrates an older database forward in one transaction;
/// a database from a newer schema is refused (read-only opens refuse an older one too,
/// naming the command that migrates it).
#ifndef SP_PARTDB_H
#define SP_PARTDB_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sp/classifier.h"
#include "sp/derive.h"
#include "sp/gltf.h"
#include "sp/result.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Schema version this build reads and writes (PRAGMA user_version).
#define SP_DB_SCHEMA_VERSION 3
/// Default busy timeout: how long a writer waits for another writer.
#define SP_DB_BUSY_MS_DEFAULT 5000
/// Synthetic sketches stored with a part by default (per part: random shape and
/// pose, the shapes of the default recipe, drawn by the hand-drawing model of
/// sp/handdraw.h; docs/DESIGN.md "Part database training data"). Why not 300:
/// several times the cost and no bar gained in full; 120 and 200 gained
/// nothing on the visitors' drawings either (docs/DESIGN.md; BENCHMARKS.md,
/// "Dragon-part classifier" and "Visitors' drawings", first pass).
#define SP_DB_SYNTH_DEFAULT 60
/// Concept sketches per part category of the default database (sp/concept.h:
/// the parts as visitors imagine them, designs of their own).
#define SP_DB_CONCEPTS_DEFAULT 60

typedef struct sp_db sp_db;

/// sp_db_open flags.
enum sp_db_flags {
    SP_DB_CREATE = 1,   ///< create the file (and schema) if it does not exist
    SP_DB_READONLY = 2, ///< never write; refuses a database that needs migrating
};

/// The path used when the user gives none: $SP_DB if set, else "sketchpose.db"
/// in the current directory.
const char* sp_db_default_path(void);

/// Opens (and with SP_DB_CREATE creates) a database: WAL mode, foreign keys,
/// the default busy timeout, schema migrated forward. A missing file without
/// SP_DB_CREATE, a file that is not an SQLite database, a newer schema, a file
/// that cannot be written (unless SP_DB_READONLY) are refused with one line.
sp_result sp_db_open(const char* path, unsigned flags, sp_db** out, sp_error* err);
/// sp_db_open with a busy timeout of busy_ms (< 0: the default) from the open
/// on: a database another process holds locked (a rollback-journal write)
/// makes the open itself wait.
sp_result sp_db_open_wait(const char* path, unsigned flags, int busy_ms, sp_db** out, sp_error* err);
/// Closes (NULL is fine). The WAL is checkpointed into the main file.
void sp_db_close(sp_db* db);
/// Sets how long a write waits for another writer (milliseconds, >= 0).
void sp_db_set_busy_timeout(sp_db* db, int ms);
/// Moves what is committed from the WAL into the main file and empties the
/// WAL, waiting at most the busy timeout for readers: afterwards a copy of
/// the file, or the file renamed away, holds every commit, and a file
/// renamed over it does not meet this one's WAL. SP_ERR_BUSY when a reader
/// or writer kept it from finishing (nothing is lost: the commits stay in
/// the WAL until the next checkpoint).
sp_result sp_db_checkpoint(sp_db* db, sp_error* err);
/// After the database file at `path` was replaced by a rename (another inode
/// there), the -wal and -shm beside it still belong to the old file: SQLite
/// does not remove them when the file it had open has moved, and a
/// connection opened by path would read the new file through the old file's
/// WAL, and a writer's checkpoint would write the old pages into it. Removes
/// them when no handle of this process has the new file open (one that
/// follows first makes its own), no other process uses them (a lock on the
/// -shm) and the WAL was not made or written since the new file arrived
/// (rename sets its ctime). Call it only once the file is known to be
/// replaced, with the caller's own handle on the old file closed.
void sp_db_drop_stale_sidecars(const char* path);
/// The file's path as opened.
const char* sp_db_path(const sp_db* db);
/// Whether the path still names the file the handle opened.
typedef enum sp_db_file_state {
    SP_DB_FILE_SAME,
    /// Another file is there (a curator's renamed over it), also when it
    /// arrived while the handle was being opened: open the path again.
    SP_DB_FILE_REPLACED,
    SP_DB_FILE_GONE, ///< nothing is there (deleted, or moved away)
} sp_db_file_state;
/// A stat of the path against the file there when the handle was opened
/// (taken before the open: a rename during it reads as replaced, at worst
/// once too often). A path that cannot be checked (permissions) reads as the same.
sp_db_file_state sp_db_file_check(const sp_db* db);
/// The device and inode of that file (false and zeros when unknown), for a
/// reader that opens the path again and must know it is the same file.
bool sp_db_file_id(const sp_db* db, uint64_t* dev, uint64_t* ino);
/// The schema version of the open database (== SP_DB_SCHEMA_VERSION once open).
int sp_db_schema_version(sp_db* db);
/// A counter that grows with every committed change of parts, sketches or
/// models, by this or any other connection. Cheap (PRAGMA data_version first;
/// the counter is read only when some connection committed since the last call).
/// Returns 0 if the database cannot be read.
uint64_t sp_db_generation(sp_db* db);

/// What a part is, as stored (summary computed at add time).
typedef struct sp_db_part_info {
    char name[SP_NAME_MAX];
    char category[SP_NAME_MAX];
    char abstraction[SP_NAME_MAX]; ///< the abstraction its sketches are drawn of
    int vertices, triangles, joints, parameters, abstractions, animations;
    size_t bytes;          ///< size of the stored glTF
    char sha256[65];       ///< hex SHA-256 of the stored glTF bytes
    double selftest_error; ///< solver self-test: mean error / 2D diagonal over the seeds (0.02 = 2%)
    unsigned derived;      ///< what add-part derived (sp_derived flags of sp/derive.h); 0: stored as given (list/show: 0)
    int sketches;          ///< example sketches of its category (list/show only)
    char added_by[64];
    char added_at[32];     ///< UTC, ISO 8601
} sp_db_part_info;

/// How to add a part. Zero means the default.
typedef struct sp_db_part_desc {
    const char* name;        ///< NULL: the file name without extension (sp_db_add_part: required)
    const char* category;    ///< NULL: the part's `extras.sp_part.category`
    const char* abstraction; ///< NULL: `sp_part.abstraction`, else the first abstraction (a derived part: "outline")
    const char* attach_joint; ///< a derived part's attachment joint (NULL: its root)
    sp_derive_view view;      ///< a derived part's sketch view (0: auto)
    const char* added_by;    ///< NULL: $USER, else "unknown"
    int synth_sketches;      ///< synthetic sketches stored with it; 0: SP_DB_SYNTH_DEFAULT; -1: none
    uint64_t seed;           ///< seed family of the synthetic sketches (0: one of the part's own, from its name; sp/handdraw.h)
    double synth_amplitude;  ///< largest rotation from rest in the synthetic sketches, radians (0: the recipe's, 0.4 and the whole bounds by turns; see sp/synth.h)
    int selftest_seeds;      ///< solver self-test seeds; 0: 3; -1: skip the self-test
    double selftest_tolerance; ///< largest mean error over the seeds, fraction of the 2D diagonal; 0: 0.02
    /// Called with each warning of the part as loaded, or as derived when it
    /// is (sp_character.warnings: an ignored mesh, a missing texture,
    /// renormalised weights, replaced sp_dofs), one line each, before it is
    /// validated (a refused part may have warned); NULL: not reported.
    void (*warn)(void* user, const char* line);
    void* warn_user; ///< passed to warn
    /// Called with the part as it will be stored (validated; derived when it
    /// was; `abstraction` its sketches' index) before anything is written:
    /// a failure (err set) refuses the part, nothing written. What a command
    /// makes of the part (add-part's --preview) fails before the database
    /// changes, not after. NULL: none.
    sp_result (*before_store)(void* user, const sp_character* part, int abstraction, sp_error* err);
    void* before_store_user; ///< passed to before_store
    /// The sha256 (64 hex digits) of the file the part was first added from,
    /// kept for the same-file warning: an export's part file is that file
    /// derived (`db init --from` passes the manifest's); NULL: the file's own.
    const char* source_sha256;
} sp_db_part_desc;

/// Validates a part without writing anything: the glTF loads, it has a skin
/// (joints and skinned vertices), triangles, an abstraction with curves, a
/// category, every parameter has finite bounds, it projects to a visible
/// non-degenerate picture in its sketch view, and the solver fits its own
/// synthetic sketches (mean error <= tolerance of the diagonal). On failure err
/// holds every reason, separated by "; ". `info` (may be NULL) gets the summary.
sp_result sp_db_validate_part(const void* glb, size_t size, const char* what, const sp_db_part_desc* desc, sp_db_part_info* info,
                              sp_error* err);
/// Validates and stores a part (and its synthetic sketches) in one transaction.
/// A part without sketch abstractions of its own (a rigged glTF made
/// elsewhere) is first given what the kiosk needs by sp_part_derive
/// (sp/derive.h: outline, stick, parameters, attachment, clip) and stored
/// derived; info->derived says what was derived. attach_joint and view apply
/// only to such a part: given for a part with abstractions of its own they
/// are refused (SP_ERR_INVALID), not ignored.
/// A name that exists is refused (remove it first), and a category that differs
/// from one the database has only in case. Nothing is written on failure.
sp_result sp_db_add_part(sp_db* db, const void* glb, size_t size, const sp_db_part_desc* desc, sp_db_part_info* info, sp_error* err);
/// Same from a .gltf/.glb file: the part is re-encoded as one self-contained GLB
/// (derived, as above, when it has no sketch abstraction of its own).
sp_result sp_db_add_part_file(sp_db* db, const char* path, const sp_db_part_desc* desc, sp_db_part_info* info, sp_error* err);
/// Removes a part and the synthetic sketches stored with it (curated and kiosk
/// sketches of its category stay: they are the curators' work; training uses
/// only the categories of current parts). SP_ERR_INVALID when there is no such part.
sp_result sp_db_remove_part(sp_db* db, const char* name, const char* by, sp_error* err);
/// Every part, by name (*parts malloc'd, free()).
sp_result sp_db_list_parts(sp_db* db, sp_db_part_info** parts, int* count, sp_error* err);
/// One part's summary; SP_ERR_INVALID when there is no such part.
sp_result sp_db_part(sp_db* db, const char* name, sp_db_part_info* info, sp_error* err);
/// The stored glTF bytes (*glb malloc'd, free()).
sp_result sp_db_part_bytes(sp_db* db, const char* name, void** glb, size_t* size, sp_error* err);
/// Loads a part as a character (checksum verified first).
sp_result sp_db_load_part(sp_db* db, const char* name, sp_character* out, sp_error* err);
/// The names of the parts of a category, by name (*names malloc'd array of
/// malloc'd strings; free with sp_db_free_strings).
sp_result sp_db_category_parts(sp_db* db, const char* category, char*** names, int* count, sp_error* err);
/// Distinct categories of the current parts, sorted (free with sp_db_free_strings).
sp_result sp_db_categories(sp_db* db, char*** names, int* count, sp_error* err);
void sp_db_free_strings(char** names, int count);

/// Where an example sketch came from.
typedef enum sp_db_source { SP_DB_SOURCE_SYNTHETIC, SP_DB_SOURCE_CURATED, SP_DB_SOURCE_KIOSK } sp_db_source;
/// "synthetic", "curated", "kiosk".
const char* sp_db_source_name(sp_db_source s);

/// Stores drawings of a dataset in one transaction; sample i goes under
/// `data->categories[label]` (every sample needs strokes or a raster; empty or
/// non-finite drawings, and ones beyond the stroke files' limits, refuse the
/// whole set; as `SP_DB_SOURCE_KIOSK`, each must be a kiosk sketch: one
/// stroke of 2..SP_DB_KIOSK_POINTS_MAX points). `png` (may be NULL) gives the original PNG bytes of raster
/// samples, kept for export.
typedef struct sp_db_png {
    const void* bytes;
    size_t size;
} sp_db_png;
sp_result sp_db_add_sketches(sp_db* db, const sp_dataset* data, const sp_db_png* png, sp_db_source source, const char* by, int* added,
                             sp_error* err);
/// Number of training sketches per category (kiosk sketches only when approved): parallel arrays (free with sp_db_free_strings /
/// free()).
sp_result sp_db_sketch_counts(sp_db* db, char*** categories, int** counts, int* count, sp_error* err);
/// Number of stored sketches from `source` added by `by`: a curator's name, or
/// one of the default recipe's makers below.
sp_result sp_db_sketch_count_by(sp_db* db, sp_db_source source, const char* by, int* count, sp_error* err);
/// Who adds the default recipe's sketches (sp_db_create_default): the parts'
/// own synthetic sketches and the people's strokes (curated) are by "assets",
/// the concept sketches and the designs' draws (both synthetic) by their own.
#define SP_DB_BY_ASSETS "assets"
#define SP_DB_BY_CONCEPTS "concepts"
#define SP_DB_BY_DRAWINGS "drawings"
/// The training set: the stored sketches of the current part categories as a
/// dataset (categories = sp_db_categories), kiosk sketches only when approved
/// (the newest SP_DB_KIOSK_TRAIN_MAX per category), curated ones at most
/// SP_DB_CURATED_TRAIN_MAX per category; `unused` (may be NULL) counts
/// sketches of other categories.
sp_result sp_db_load_dataset(sp_db* db, sp_dataset* out, int* unused, sp_error* err);

// ---- visitors' strokes (kiosk sketches) -------------------------------------------

/// How long sp_db_collect_kiosk_sketch waits for another writer, ms: short
/// enough for a kiosk's UI thread (a frame is 16 ms), long enough to slip
/// between a curator's short writes.
#define SP_DB_COLLECT_BUSY_MS 15
/// Approved kiosk sketches per category in a training set (the newest):
/// `db train` within 2 minutes on 2 cores with a year of visitors stored
/// (BENCHMARKS.md, "Kiosk sketches").
#define SP_DB_KIOSK_TRAIN_MAX 200
/// Curated sketches per category in a training set (sp_db_train_desc.curated_max
/// by default), spread over those stored: without a cap a curator's tens of
/// thousands made `db train` slow and the kiosk huge (BENCHMARKS.md,
/// "Curated sketches in training").
#define SP_DB_CURATED_TRAIN_MAX 400
/// Models a database keeps after `db train` stores one (sp_db_train_desc.keep_models
/// by default): the newest, and the two before it to compare reports with. Each
/// is tens of MB and only the newest is used: a weekly retrain kept 1.6 GB a year.
#define SP_DB_KEEP_MODELS 3
/// Pending kiosk sketches a database takes (sp_db_collect_kiosk_sketch): a
/// year of a busy museum's, the most measured (BENCHMARKS.md, "Kiosk
/// sketches"). A kiosk nobody reviews stops there instead of filling its
/// disk, which its saves and the curators' `db train` also need.
#define SP_DB_KIOSK_PENDING_MAX 100000
/// A kiosk sketch is one stroke of 2 to this many points (the kiosk's own
/// stroke holds fewer), collected or added (`db add-sketch --source kiosk`).
#define SP_DB_KIOSK_POINTS_MAX 65536
/// Why `smp` cannot be stored as a kiosk sketch ("a picture", "several
/// strokes", "one stroke of too many points", "one stroke of fewer than 2
/// points"), or NULL when it can: one check for the library and the command
/// that names the file.
const char* sp_db_kiosk_sketch_problem(const sp_sample* smp);

/// Review status of a kiosk sketch.
typedef enum sp_db_status { SP_DB_PENDING, SP_DB_APPROVED, SP_DB_REJECTED, SP_DB_STATUS_COUNT } sp_db_status;
/// "pending", "approved", "rejected".
const char* sp_db_status_name(sp_db_status s);

/// Stores one stroke a visitor left on the kiosk as a `kiosk` sketch, pending
/// review, under `category` (the label the visitor left it with): the points
/// (pixels) and, when given, their times (ms); nothing else about the visit.
/// Made for a kiosk that must not wait (its collector thread): it waits at
/// most SP_DB_COLLECT_BUSY_MS for another writer and commits without waiting
/// for the disk (a power cut may lose the last strokes, never the database). A busy, read-only or full
/// database keeps nothing and returns SP_ERR_BUSY or SP_ERR_IO with one line
/// for the kiosk's log; so do a category that is not a plain name and a
/// stroke with fewer than 2 points, more than 65536, non-finite ones or ones
/// beyond SP_SKETCH_COORD_MAX (or a canvas beyond SP_SKETCH_CANVAS_MAX), which
/// no reader would take back (SP_ERR_INVALID). *id (may be NULL) gets the new
/// sketch's id. With SP_DB_KIOSK_PENDING_MAX (sp_db_set_kiosk_pending_max)
/// pending already, it keeps nothing and returns SP_ERR_UNSUPPORTED, its line
/// saying that they await review.
sp_result sp_db_collect_kiosk_sketch(sp_db* db, const char* category, const sp_stroke* stroke, double canvas_w, double canvas_h,
                                     int64_t* id, sp_error* err);

/// Sets how many pending kiosk sketches the handle's sp_db_collect_kiosk_sketch
/// takes (>= 1; 0: SP_DB_KIOSK_PENDING_MAX).
void sp_db_set_kiosk_pending_max(sp_db* db, int max);

/// One kiosk sketch as stored (sp_db_kiosk_list).
typedef struct sp_db_kiosk_sketch {
    int64_t id;
    char category[SP_NAME_MAX];
    sp_db_status status;
    char created_at[32]; ///< UTC, ISO 8601
    sp_sketch sketch;    ///< its stroke(s)
} sp_db_kiosk_sketch;

/// Which kiosk sketches to list. Zero means the default.
typedef struct sp_db_kiosk_query {
    unsigned statuses; ///< bit (1 << sp_db_status) per status wanted; 0: pending only
    int limit;         ///< at most this many, oldest first; 0: all
    int64_t after;     ///< only ids above this (paging; 0: from the first)
} sp_db_kiosk_query;

/// Counts of kiosk sketches by status (counts[SP_DB_STATUS_COUNT]).
sp_result sp_db_kiosk_counts(sp_db* db, int counts[SP_DB_STATUS_COUNT], sp_error* err);
/// The kiosk sketches the query selects, oldest first (*out malloc'd; free
/// with sp_db_kiosk_free). Uses the index on (source, status, id): a page
/// costs the same with a hundred or a million stored.
sp_result sp_db_kiosk_list(sp_db* db, const sp_db_kiosk_query* q, sp_db_kiosk_sketch** out, int* count, sp_error* err);
void sp_db_kiosk_free(sp_db_kiosk_sketch* s, int count);
/// Sets the review status of kiosk sketches, all in one transaction: an id
/// that is not a kiosk sketch changes nothing and fails with SP_ERR_INVALID
/// naming it. Logged for the curator log.
sp_result sp_db_kiosk_set_status(sp_db* db, const int64_t* ids, int n, sp_db_status status, const char* by, sp_error* err);
/// Ids first..last, both included.
typedef struct sp_db_kiosk_range {
    int64_t first, last;
} sp_db_kiosk_range;
/// sp_db_kiosk_set_status of the ids (any status) and of every kiosk sketch
/// still pending in each range (a curator approves a page but the few they
/// rejected), all in one transaction: an id that is not a kiosk sketch, or a
/// range with none pending, fails with SP_ERR_INVALID naming it and changes
/// nothing. *changed (may be NULL; malloc'd, free()) gets the ids set,
/// ascending, each once, and *n_changed (may be NULL) their count.
sp_result sp_db_kiosk_review(sp_db* db, const int64_t* ids, int n, const sp_db_kiosk_range* ranges, int nr, sp_db_status status,
                             const char* by, int64_t** changed, int* n_changed, sp_error* err);
/// Gives a kiosk sketch another category (one of the current part
/// categories; anything else fails with SP_ERR_INVALID and changes nothing).
sp_result sp_db_kiosk_relabel(sp_db* db, int64_t id, const char* category, const char* by, sp_error* err);
/// Deletes every rejected kiosk sketch in one transaction, logged as `by`;
/// *deleted (may be NULL) gets how many. Their space is reused by later
/// writes (the file does not shrink), so a kiosk's database stops growing
/// with the strokes its curators turned down.
sp_result sp_db_kiosk_delete_rejected(sp_db* db, const char* by, int* deleted, sp_error* err);

/// The classifier's shape evidence weight (sp_clf_desc.shape_weight) a part
/// database trains with unless told otherwise; tuned on the visitors' tune half
/// (tests/data/visitors).
#define SP_DB_SHAPE_WEIGHT 0.75

/// Training. Zero means the default.
typedef struct sp_db_train_desc {
    /// Classifier options (progress reported through it). Here clf.shape_weight
    /// 0 means SP_DB_SHAPE_WEIGHT: a part is drawn in one stroke, whose global
    /// shape tells the parts apart where the bag of features does not (< 0: none).
    sp_clf_desc clf;
    int folds;          ///< cross-validation folds for the report; 0: 3; -1: none
    const char* by;     ///< curator (NULL: $USER)
    /// Reject threshold calibration: this many hand-drawn sketches per part, in
    /// the harsh style and a seed family of their own (never stored, never
    /// trained on), set the threshold (sp_clf_calibrate_reject). 0: 50; -1: keep
    /// the training set's leave-one-out threshold.
    int calibrate;
    double calibrate_quantile; ///< share of the calibration sketches accepted; 0: 0.96
    int curated_max;           ///< curated sketches per category trained on; 0: SP_DB_CURATED_TRAIN_MAX; -1: all
    int keep_models;           ///< models kept once this one is stored, the newest (it among them); 0: SP_DB_KEEP_MODELS; -1: all
} sp_db_train_desc;
/// Rebuilds the classifier from the stored sketches of the current part
/// categories (synthetic, curated: `curated_max` per category, and approved kiosk sketches: the newest
/// SP_DB_KIOSK_TRAIN_MAX per category), cross-validates it for the report, calibrates its reject
/// threshold on fresh hand-drawn sketches of the parts, and stores the model with
/// its options and report in one transaction, removing the models older than
/// the newest `keep_models` in it (their space is reused by later writes; the
/// file does not shrink). `report_json` (may be NULL) gets
/// the report: {"categories", "drawings", "kiosk_sketches" (approved kiosk sketches among the drawings), "curated_sketches"
/// (likewise), "curated_left_out" (stored past the cap), "unused_drawings" (other categories'), "folds", "top1",
/// "per_class": {"<cat>": {"recall", "n"}}, "seconds_train", "seconds_cv", "reject_distance", "calibration": {"sketches",
/// "quantile"} (absent without calibration), "models_removed"} (malloc'd, free()). Fails when a part category has no sketches.
sp_result sp_db_train(sp_db* db, const sp_db_train_desc* desc, char** report_json, sp_error* err);
/// The newest model; *id (may be NULL) its row id. SP_ERR_INVALID when none is stored.
sp_result sp_db_load_model(sp_db* db, sp_clf** out, int64_t* id, sp_error* err);
/// The newest model's row id and SHA-256 without parsing the model (a
/// reader that has it loaded need not parse tens of MB again); *id 0 and
/// sha "" when none is stored. sha256 may be NULL: then only the id is read,
/// which is cheaper still (the checksum is stored past the model's bytes,
/// and reaching it walks them; BENCHMARKS.md, "A new model while the kiosk runs").
sp_result sp_db_model_head(sp_db* db, int64_t* id, char sha256[65], sp_error* err);

/// Stored models, newest first, as a JSON array [{"id", "created_at", "created_by",
/// "bytes", "categories", "options", "report"}] (malloc'd, free()).
sp_result sp_db_models_json(sp_db* db, char** json, sp_error* err);
/// A part's parameter and abstraction summary as stored:
/// {"parameters": [{"name", "min", "max", "default", "group"}], "abstractions": [{"name", "curves", "points", "correspondence"}]}.
sp_result sp_db_part_summary_json(sp_db* db, const char* name, char** json, sp_error* err);

/// Integrity check: SQLite's integrity and foreign key checks plus ours (every
/// part loads from its bytes and matches its checksum and size, every sketch
/// parses, the newest model loads and its categories equal the current part
/// categories). *ok tells; *json (may be NULL, malloc'd) gets
/// {"ok", "integrity", "parts", "sketches", "models", "problems": [...]}.
sp_result sp_db_check(sp_db* db, bool* ok, char** json, sp_error* err);

/// Writes DIR/parts/<name>.glb, DIR/sketches/<category>/<source>-<id>.{json,png}
/// and DIR/manifest.json (names, categories, curators), whole or not at all:
/// into DIR.partial-<pid>-<k> beside it, renamed to DIR once complete and
/// removed on failure. DIR must be absent or an empty folder (replaced, its
/// permissions kept); any other DIR is SP_ERR_INVALID, left untouched.
sp_result sp_db_export(sp_db* db, const char* dir, sp_error* err);
/// Adds every part and sketch of an export folder (parts validated as by
/// sp_db_add_part, no synthetic sketches added: the folder has them).
sp_result sp_db_import(sp_db* db, const char* dir, const char* by, sp_error* err);

/// The default database: every `*.glb`/`*.gltf` part of assets_dir (category
/// from its sp_part extras; files without one, such as the paper's characters,
/// are skipped), `synth_per_part` synthetic sketches each (0:
/// SP_DB_SYNTH_DEFAULT), `concepts_per_category` concept sketches for each
/// category that has a concept (0: SP_DB_CONCEPTS_DEFAULT; -1: none), drawn
/// from seed family `concept_family` (0: 1, the default database's own; as
/// `sketchpose synth --concepts --seed F`: another family is another draw of
/// the same designs, to measure a recipe over several draws), the people's
/// strokes that assets_dir/sketches/picks.json names (sp_db_people_strokes;
/// built without them when the Quick, Draw! folder is not there and
/// `quickdraw_dir` is NULL), `drawn_per_design` sketches of each design of
/// assets_dir/sketches/drawings.json (sp_db_drawn_sketches; 0:
/// SP_DB_DRAWN_DEFAULT; -1: none; family `concept_family`), and a trained
/// model. Creates `path`; refuses an existing file.
typedef struct sp_db_default_desc {
    int synth_per_part;
    int concepts_per_category;
    int concept_family;
    int drawn_per_design;
    const char* quickdraw_dir; ///< NULL: the folder picks.json names
    sp_db_train_desc train;
} sp_db_default_desc;
sp_result sp_db_create_default(const char* path, const char* assets_dir, const sp_db_default_desc* desc, sp_error* err);
/// The people's own strokes of the parts that the default recipe trains on.
/// assets_dir/sketches/picks.json names each in the Quick, Draw! data ("file",
/// "line" from 1, "stroke" from 0, "key_id") and says where that data is
/// ("quickdraw", relative to itself); `quickdraw_dir` (NULL: that folder)
/// overrides it. The repository keeps the names only: the strokes are read
/// from the data, whose terms ask that it not be copied. *out gets the labels
/// as categories, sorted, and the strokes in the file's order. No picks.json:
/// an empty set. The data's folder not there: an empty set and *missing true
/// (may be NULL), or SP_ERR_IO naming it when `quickdraw_dir` was given. A pick
/// the data does not have (no such line or stroke, another key_id) is an
/// error naming the file and line.
sp_result sp_db_people_strokes(const char* assets_dir, const char* quickdraw_dir, sp_dataset* out, bool* missing, sp_error* err);
/// Draws of each hand-placed design in the default database.
#define SP_DB_DRAWN_DEFAULT 1
/// The parts as other people designed them: assets_dir/sketches/drawings.json,
/// `{"drawings": [{"name", "label", "closed": bool, "points": [[x, y]...]}...]}`
/// (control points in the order drawn, in a 100 x 100 box, y down; a point
/// written twice is a corner). Each design is drawn `per_design` times as one
/// stroke: its control points moved a little, stretched, mirrored or not,
/// tilted, joined by a centripetal Catmull-Rom spline, scaled and centred as a
/// concept sketch, and passed through the hand-drawing model (normal style),
/// seeded by `family` and the design's name. *out gets the labels as
/// categories, sorted, and the sketches in the file's order; *designs (may be
/// NULL) the designs read. No drawings.json, or per_design <= 0: an empty set.
/// A malformed file or design is an error naming the file (and the design).
sp_result sp_db_drawn_sketches(const char* assets_dir, int per_design, uint64_t family, sp_dataset* out, int* designs,
                               sp_error* err);
/// What sp_db_people_strokes would read, from picks.json alone (the data is not
/// read): *picks, the strokes it names, and *missing, whether the data's
/// folder is not there (SP_ERR_IO when `quickdraw_dir` names one that is not).
/// A database the default recipe builds holds all *picks of them, or none.
sp_result sp_db_people_source(const char* assets_dir, const char* quickdraw_dir, int* picks, bool* missing, sp_error* err);
/// The line a first start (the kiosk's, the demo's) says before it builds the
/// default database when the people's strokes picks.json names are not
/// there (from the default Quick, Draw! folder): true and `note` filled, else
/// false.
bool sp_db_people_note(const char* assets_dir, char* note, size_t cap);
/// Creates `path` from an export folder (sp_db_import), then trains when
/// `train` is not NULL. Built beside `path` and moved into place when complete.
sp_result sp_db_create_from_export(const char* path, const char* dir, const sp_db_train_desc* train, const char* by, sp_error* err);
/// Opens `path`, creating it with sp_db_create_default first if it does not exist
/// (what the kiosk does at start).
sp_result sp_db_open_or_create_default(const char* path, const char* assets_dir, unsigned flags, sp_db** out, sp_error* err);

/// Appends to the curator log (also done by every write above). `details` is JSON or NULL.
sp_result sp_db_log(sp_db* db, const char* by, const char* action, const char* subject, const char* details, sp_error* err);
/// The log, oldest first, as a JSON array [{"id","at","by","action","subject","details"}]
/// (subject NULL: all entries) (malloc'd, free()).
sp_result sp_db_log_json(sp_db* db, const char* subject, char** json, sp_error* err);

/// Hex SHA-256 of bytes (hex: 65 chars with the NUL). False, hex empty, only
/// when libcrypto has no memory for its context: callers refuse the bytes.
bool sp_sha256_hex(const void* data, size_t size, char hex[65]);

#ifdef __cplusplus
}
#endif
#endif
