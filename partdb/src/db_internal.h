// db_internal.h: what the database's source files share (and tests reach).
#ifndef SP_DB_INTERNAL_H
#define SP_DB_INTERNAL_H

#include <cjson/cJSON.h>
#include <sqlite3.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "sp/partdb.h"

struct sp_db {
    sqlite3* h;
    char* path;
    dev_t dev; // the file opened (db.c's list of this process's open files)
    ino_t ino;
    bool listed;
    dev_t at_dev; // the file at the path just before the open (sp_db_file_check)
    ino_t at_ino;
    bool at_known;
    int busy_ms;
    int kiosk_pending_max; // 0: SP_DB_KIOSK_PENDING_MAX
    bool readonly;
    bool gen_valid;   // gen is current as of data_version dv
    int dv;
    uint64_t gen;
};

/// Test hook: called at named points inside write transactions (NULL in
/// production). The crash test sleeps there so that SIGKILL lands mid-write.
extern void (*sp_db_test_hook)(const char* point);
#define DB_HOOK(name)                          \
    do {                                       \
        if (sp_db_test_hook) sp_db_test_hook(name); \
    } while (0)

/// Runs the migrations from the file's version up to `target` (tests build
/// old-schema files with it). Inside a write transaction taken here.
sp_result db_migrate(sp_db* db, int target, sp_error* err);

/// Maps an SQLite failure to a result and a one-line message naming the file.
sp_result db_fail(sp_db* db, int rc, const char* doing, sp_error* err);
/// BEGIN IMMEDIATE with the busy message; COMMIT (rolls back on failure); ROLLBACK.
sp_result db_begin(sp_db* db, sp_error* err);
sp_result db_commit(sp_db* db, sp_error* err);
void db_rollback(sp_db* db);
/// Executes SQL without results.
sp_result db_exec(sp_db* db, const char* sql, sp_error* err);
/// Binds a blob, SQLITE_STATIC; one larger than SQLite's value limit fails
/// saying so (`what` names it: "the model"), and finalizes `st`.
sp_result db_bind_blob(sp_db* db, sqlite3_stmt* st, int i, const void* data, size_t size, const char* what, sp_error* err);
/// Prepares or fails with a message.
sp_result db_prepare(sp_db* db, const char* sql, sqlite3_stmt** st, sp_error* err);
/// Appends a log row (inside the caller's transaction).
sp_result db_log_row(sp_db* db, const char* by, const char* action, const char* subject, const char* details, sp_error* err);
/// The curator's name: `by` if given, else $USER, else "unknown".
const char* db_who(const char* by);

/// SQL for the highest sketch id ever given: the table's, or the one kept in
/// meta ('sketch_id_high') when the newest rows were deleted. New sketches
/// take it plus one, so an id never names two drawings.
#define DB_SKETCH_ID_HIGH                                                                                                        \
    "max(coalesce((SELECT max(id) FROM sketches), 0), coalesce((SELECT value FROM meta WHERE key = 'sketch_id_high'), 0))"
/// Inserts one sketch (strokes or raster) inside the caller's transaction.
sp_result db_insert_sketch(sp_db* db, const char* category, sp_db_source source, int64_t part_id, const sp_sample* smp,
                           const sp_db_png* png, const char* by, sp_error* err);
/// Significant digits of a stored sketch's numbers. Not SP_SKETCH_JSON_EXACT:
/// the default database's model is trained from the stored text, and 17
/// digits change it (and the visitors' answers); a change of this is a
/// change of every database's training data.
#define DB_SKETCH_DIGITS 9
/// Checks a sample is storable (strokes with finite points, or a raster).
sp_result db_sample_ok(const sp_sample* smp, const char* what, sp_error* err);
/// A name that differs from one the database has only in case is a slip
/// (the kiosk showed "Front legs" twice, one tile a part each; an export's
/// files collide on a FAT stick): `sql` selects such a name for ?1 (the
/// value); found, SP_ERR_INVALID "DB: KIND 'value' differs from its 'other'
/// only in case (WHY)".
sp_result db_case_clash(sp_db* db, const char* sql, const char* kind, const char* value, const char* why, sp_error* err);
/// db_case_clash for a category against the parts' and the sketches' categories.
sp_result db_category_case_clash(sp_db* db, const char* category, sp_error* err);
/// Reads a whole file (malloc'd, NUL-terminated beyond size).
sp_result db_read_file(const char* path, void** data, size_t* size, sp_error* err);
/// Reads and parses a JSON file as one document, each key once
/// (sp_json_document_check): malformed JSON, text after it or a key given
/// twice is an error naming the file; the caller names what else it wanted.
sp_result db_read_json(const char* path, cJSON** root, sp_error* err);
/// Writes a whole file in place (for files in a folder put in place whole; else sp_file_write).
sp_result db_write_file(const char* path, const void* data, size_t size, sp_error* err);
/// What a training set holds and leaves out.
typedef struct db_training_counts {
    int unused;           ///< sketches of categories with no part
    int kiosk;            ///< approved kiosk sketches in the set
    int curated;          ///< curated sketches in the set
    int curated_left_out; ///< curated sketches of the set's categories past the cap
} db_training_counts;
/// The training set: sp_db_load_dataset with at most `kiosk_cap` approved
/// kiosk sketches per category (the newest) and `curated_max` curated ones
/// (-1: all; spread over those stored); `counts` may be NULL.
sp_result db_load_training_set(sp_db* db, int kiosk_cap, int curated_max, sp_dataset* out, db_training_counts* counts,
                               sp_error* err);
/// A dataset of one category and n zeroed samples (count 0: the caller fills them in and counts).
sp_result db_dataset_one(sp_dataset* out, const char* category, int n, sp_error* err);
/// A dataset with no samples whose categories are the distinct string values
/// of `key` over the objects of the JSON array `items`, sorted (as a labelled
/// folder gives them). An item without a non-empty string there: SP_ERR_PARSE,
/// *bad its index (from 0), err untouched, for the caller to name it.
sp_result db_dataset_labels(const cJSON* items, const char* key, sp_dataset* out, int* bad, sp_error* err);
/// Synthetic sketches of a part (amplitude 0: the default), label 0 in a one-category dataset.
sp_result db_synth_sketches(const sp_character* ch, int abstraction, int n, uint64_t seed, double amplitude, sp_dataset* out, sp_error* err);

/// A growable string.
typedef struct db_str {
    char* s;
    size_t len, cap;
    bool oom;
} db_str;
void db_str_printf(db_str* b, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void db_str_json(db_str* b, const char* s); // a JSON string literal

// A design's path (`p`, in drawing order, overwritten) placed as a concept
// sketch (concept.c): mirrored about the upright axis (`mirror` -1) or not
// (1), turned by `turn` radians, scaled to a bounding-box diagonal of 340 px
// and centred on the canvas, as the one stroke of *out. SP_ERR_INVALID for a
// path with no extent (fewer than 2 points, or all at one place).
sp_result sp_concept_place(sp_vec2* p, int n, double mirror, double turn, sp_sketch* out, sp_error* err);

#endif
