// db_parts.c: validating, storing, listing and loading rigged parts.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "db_internal.h"
#include "gltf_internal.h"
#include "sp/handdraw.h"
#include "sp/part.h"
#include "sp/sketch_io.h"
#include "sp/solver.h"
#include "sp/synth.h"

// Rotation amplitude of the self-test poses (radians): visibly posed, yet
// within reach of a rest-pose start.
#define SELFTEST_AMPLITUDE 0.5

static void add_reason(char* buf, size_t cap, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void add_reason(char* buf, size_t cap, const char* fmt, ...)
{
    size_t n = strlen(buf);
    if (n + 3 >= cap) return;
    if (n) {
        strcat(buf, "; ");
        n += 2;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + n, cap - n, fmt, ap);
    va_end(ap);
}

static void copy_name(char* dst, size_t cap, const char* src)
{
    snprintf(dst, cap, "%s", src ? src : "");
}

// A name of the part's sp_part, or NULL when the file gives none.
static const char* part_name(const char* name)
{
    return name[0] ? name : NULL;
}

static int pick_abstraction(const sp_character* ch, const sp_db_part_desc* d)
{
    const char* want = d && d->abstraction ? d->abstraction : part_name(ch->part.abstraction);
    if (want) return sp_rig_find_abstraction(&ch->rig, want);
    return ch->rig.abstraction_count > 0 ? 0 : -1;
}

// The solver fits the part's own synthetic sketches from the rest pose.
static double self_test(const sp_character* ch, int abstraction, int seeds, char* reasons, size_t cap)
{
    const sp_rig* rig = &ch->rig;
    double* p = malloc(sizeof(double) * (size_t)rig->param_count);
    double* q = malloc(sizeof(double) * (size_t)rig->param_count);
    sp_solver* s;
    sp_error serr = {0};
    sp_solver_create(rig, abstraction, &ch->camera, &(sp_solve_desc){.time_cap_ms = 2000}, &s, &serr);
    double sum = 0;
    int done = 0;
    if (!s) {
        add_reason(reasons, cap, "self-test: %s", serr.text);
        goto out;
    }
    if (!p || !q) {
        add_reason(reasons, cap, "self-test: out of memory");
        goto out;
    }
    for (int k = 0; k < seeds; ++k) {
        sp_sketch sk = {0};
        sp_synth_params(rig, 1000u + (uint64_t)k, SELFTEST_AMPLITUDE, p);
        if (sp_synth_sketch(rig, abstraction, &ch->camera, p, &sk) != SP_OK) {
            add_reason(reasons, cap, "self-test: cannot draw the abstraction's synthetic sketch (seed %d)", k);
            goto out;
        }
        sp_solve_report rep;
        sp_error e = {0};
        sp_result r = sp_solver_solve(s, &sk, NULL, q, &rep, &e);
        sp_sketch_free(&sk);
        if (r != SP_OK) {
            add_reason(reasons, cap, "self-test: the solver failed on its own sketch (seed %d): %s", k, e.text);
            goto out;
        }
        sum += rep.bbox_diagonal_px > 0 ? rep.mean_error_px / rep.bbox_diagonal_px : INFINITY;
        ++done;
    }
out:
    sp_solver_destroy(s);
    free(p);
    free(q);
    return done == seeds && seeds > 0 ? sum / seeds : INFINITY;
}

static sp_result validate(const void* glb, size_t size, const char* what, const sp_db_part_desc* d, sp_db_part_info* info,
                          sp_character* keep, int* abstraction_out, sp_error* err)
{
    sp_db_part_info tmp;
    if (!info) info = &tmp;
    memset(info, 0, sizeof *info);
    sp_character ch = {0};
    sp_result r = sp_gltf_load_memory(glb, size, what, &ch, err);
    if (r != SP_OK) return r;
    const sp_rig* rig = &ch.rig;
    char reasons[sizeof err->text] = "";
    if (rig->joint_count == 0 || !rig->weights4 || !rig->joints4) add_reason(reasons, sizeof reasons, "no skin");
    if (rig->vertex_count == 0 || rig->triangle_count == 0) add_reason(reasons, sizeof reasons, "no triangle mesh");
    const char* category = d && d->category ? d->category : part_name(ch.part.category);
    if (!category) add_reason(reasons, sizeof reasons, "no category (give --category or the scene's extras.sp_part.category)");
    else if (!sp_part_name_is_plain(category)) {
        char shown[128]; // escaped: a category from a file may hold newlines and escape codes
        add_reason(reasons, sizeof reasons, "category '%s' is not a plain name ([A-Za-z0-9_.-], < 64)",
                   sp_text_printable(category, shown, sizeof shown));
    }
    int a = pick_abstraction(&ch, d);
    // The loader's word on an abstraction it left out (a curve saved as LINES
    // by Blender) is the reason: "no sketch abstraction" alone sent a curator
    // to `inspect` to find it (an outside review).
    const char* why = NULL;
    for (int w = 0; a < 0 && w < ch.warning_count && !why; ++w)
        if (strstr(ch.warnings[w], "sp_abstraction")) why = ch.warnings[w];
    if (a < 0)
        add_reason(reasons, sizeof reasons, "no sketch abstraction%s%s%s%s%s", d && d->abstraction ? " named " : "",
                   d && d->abstraction ? d->abstraction : "", why ? " (" : "", why ? why : "", why ? ")" : "");
    else if (rig->abstractions[a].curve_count == 0 || rig->abstractions[a].point_count < 2)
        add_reason(reasons, sizeof reasons, "abstraction '%s' has no curve", rig->abstractions[a].name);
    if (rig->param_count == 0) add_reason(reasons, sizeof reasons, "no rig parameters");
    // Joints sp_part names that the skeleton lacks (a bone renamed in an
    // editor): the kiosk attached such a part by its root, without a word.
    if (ch.has_part && ch.part.has_attach && ch.part.attach.joint[0] && sp_rig_find_joint(rig, ch.part.attach.joint) < 0)
        add_reason(reasons, sizeof reasons,
                   "sp_part.attach names joint '%s', which the part does not have (renamed in an editor? fix it, or derive the "
                   "file without sp_part again, --attach-joint)",
                   ch.part.attach.joint);
    for (int i = 0; ch.has_part && i < ch.part.socket_count; ++i)
        if (ch.part.sockets[i].joint[0] && sp_rig_find_joint(rig, ch.part.sockets[i].joint) < 0)
            add_reason(reasons, sizeof reasons, "sp_part socket '%s' names joint '%s', which the part does not have",
                       ch.part.sockets[i].name, ch.part.sockets[i].joint);
    for (int i = 0; i < rig->param_count; ++i) {
        const sp_param* pm = &rig->params[i];
        if (!isfinite(pm->min) || !isfinite(pm->max) || pm->min > pm->max ||
            (sp_channel_is_rotation(pm->channel) && pm->max - pm->min > 4 * 3.14159265358979323846)) {
            add_reason(reasons, sizeof reasons, "parameter %s is not bounded ([%g, %g])", pm->name, pm->min, pm->max);
            break;
        }
    }
    // "Renders": the mesh and the abstraction project to a non-degenerate picture that overlaps the canvas.
    if (!reasons[0]) {
        double* xy = malloc(sizeof(double) * 2 * (size_t)rig->abstractions[a].point_count);
        double* p = malloc(sizeof(double) * (size_t)rig->param_count);
        if (!xy || !p) add_reason(reasons, sizeof reasons, "out of memory");
        else {
            sp_rig_defaults(rig, p);
            sp_abstraction_project(rig, a, &ch.camera, p, xy);
            double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (int i = 0; i < rig->abstractions[a].point_count; ++i)
                for (int c = 0; c < 2; ++c) {
                    lo[c] = fmin(lo[c], xy[2 * i + c]);
                    hi[c] = fmax(hi[c], xy[2 * i + c]);
                }
            double diag = hypot(hi[0] - lo[0], hi[1] - lo[1]);
            if (!isfinite(diag) || diag < 8) add_reason(reasons, sizeof reasons, "the abstraction is invisible in the sketch view (%.1f px)", diag);
            else if (hi[0] < 0 || hi[1] < 0 || lo[0] > ch.camera.width || lo[1] > ch.camera.height)
                add_reason(reasons, sizeof reasons, "the abstraction lies outside the sketch view");
        }
        free(xy);
        free(p);
    }
    int seeds = d && d->selftest_seeds ? d->selftest_seeds : 3;
    double tol = d && d->selftest_tolerance > 0 ? d->selftest_tolerance : 0.02;
    info->selftest_error = -1;
    if (!reasons[0] && seeds > 0) {
        info->selftest_error = self_test(&ch, a, seeds, reasons, sizeof reasons);
        if (!reasons[0] && !(info->selftest_error <= tol))
            add_reason(reasons, sizeof reasons, "self-test: the solver fits its own synthetic sketches with %.2f%% mean error (> %.2f%% of the diagonal)",
                       100 * info->selftest_error, 100 * tol);
    }
    if (reasons[0]) {
        sp_character_free(&ch);
        return sp_fail(err, SP_ERR_INVALID, "%s: refused: %s", what, reasons);
    }
    copy_name(info->category, sizeof info->category, category);
    copy_name(info->abstraction, sizeof info->abstraction, rig->abstractions[a].name);
    info->vertices = rig->vertex_count;
    info->triangles = rig->triangle_count;
    info->joints = rig->joint_count;
    info->parameters = rig->param_count;
    info->abstractions = rig->abstraction_count;
    info->animations = rig->animation_count;
    info->bytes = size;
    if (!sp_sha256_hex(glb, size, info->sha256)) {
        sp_character_free(&ch);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    if (abstraction_out) *abstraction_out = a;
    if (keep) *keep = ch;
    else sp_character_free(&ch);
    return SP_OK;
}

sp_result sp_db_validate_part(const void* glb, size_t size, const char* what, const sp_db_part_desc* desc, sp_db_part_info* info,
                              sp_error* err)
{
    return validate(glb, size, what, desc, info, NULL, NULL, err);
}

// The part's parameters and abstractions, and the sha256 of the file it
// was added from (before any derivation: warn_same_file).
static char* summary_json(const sp_rig* rig, const char* source_sha)
{
    db_str b = {0};
    db_str_printf(&b, "{\"source_sha256\": \"%s\", \"parameters\": [", source_sha);
    for (int i = 0; i < rig->param_count; ++i) {
        const sp_param* p = &rig->params[i];
        db_str_printf(&b, "%s{\"name\": ", i ? ", " : "");
        db_str_json(&b, p->name);
        db_str_printf(&b, ", \"min\": %.9g, \"max\": %.9g, \"default\": %.9g, \"group\": \"%s\"}", p->min, p->max, p->def,
                      p->group == SP_GROUP_SHAPE ? "shape" : "pose");
    }
    db_str_printf(&b, "], \"abstractions\": [");
    for (int i = 0; i < rig->abstraction_count; ++i) {
        const sp_abstraction* a = &rig->abstractions[i];
        db_str_printf(&b, "%s{\"name\": ", i ? ", " : "");
        db_str_json(&b, a->name);
        db_str_printf(&b, ", \"curves\": %d, \"points\": %d, \"correspondence\": \"%s\"}", a->curve_count, a->point_count,
                      a->correspondence == SP_CORR_CLOSEST ? "closest" : "ordered");
    }
    db_str_printf(&b, "]}");
    if (b.oom) {
        free(b.s);
        return NULL;
    }
    return b.s;
}

static void report_warnings(const sp_character* ch, const sp_db_part_desc* d)
{
    for (int i = 0; d->warn && i < ch->warning_count; ++i)
        d->warn(d->warn_user, ch->warnings[i]);
}

// A part without sketch abstractions of its own, derived (sp/derive.h) and
// encoded as GLB (*glb malloc'd); *glb stays NULL when ch has its own.
static sp_result derive_part(const sp_character* ch, const sp_db_part_desc* d, const char* what, void** glb, size_t* size,
                             unsigned* derived, sp_error* err)
{
    *glb = NULL;
    *derived = 0;
    if (!sp_part_needs_derivation(ch)) {
        // Its own extras are kept as they are: a derivation option would be silently ignored.
        if (d->attach_joint || d->view != SP_DERIVE_VIEW_AUTO)
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: %s applies to a part derived from a plain rigged glTF; this one already has sketchpose extras",
                           what, d->attach_joint ? "attach_joint" : "view");
        report_warnings(ch, d);
        // Derived before (`derive --abstraction stick`, then add-part): said
        // here too, as derive said it (it was stored without a word).
        char line[320];
        if (d->warn && sp_part_curves_warning(&ch->rig, pick_abstraction(ch, d), line, sizeof line)) d->warn(d->warn_user, line);
        return SP_OK;
    }
    sp_character part = {0};
    sp_derive_info info;
    sp_error e = {0};
    sp_derive_desc dd = {
        .category = d->category, .abstraction = d->abstraction, .attach_joint = d->attach_joint, .view = d->view};
    sp_result r = sp_part_derive(ch, &dd, &part, &info, &e);
    if (r != SP_OK) return sp_fail(err, r, "%s: refused: %s", what, e.text);
    report_warnings(&part, d); // the source's, and the derivation's own
    r = sp_gltf_save_memory(&part, NULL, glb, size, err);
    sp_character_free(&part);
    if (r == SP_OK) *derived = info.derived;
    return r;
}

static sp_result add_part(sp_db* db, const void* glb, size_t size, const sp_db_part_desc* desc, unsigned derived,
                          const char* source_sha, sp_db_part_info* info_out, sp_error* err);

sp_result sp_db_add_part(sp_db* db, const void* glb, size_t size, const sp_db_part_desc* desc, sp_db_part_info* info_out, sp_error* err)
{
    sp_db_part_desc d = desc ? *desc : (sp_db_part_desc){0};
    const char* what = d.name ? d.name : "part";
    sp_character ch = {0};
    sp_result r = sp_gltf_load_memory(glb, size, what, &ch, err);
    if (r != SP_OK) return r;
    void* derived_glb = NULL;
    size_t derived_size = 0;
    unsigned derived = 0;
    r = derive_part(&ch, &d, what, &derived_glb, &derived_size, &derived, err);
    sp_character_free(&ch);
    char source[65];
    if (r == SP_OK && !sp_sha256_hex(glb, size, source)) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (r == SP_OK)
        r = derived_glb ? add_part(db, derived_glb, derived_size, &d, derived, source, info_out, err)
                        : add_part(db, glb, size, &d, 0, source, info_out, err);
    free(derived_glb);
    return r;
}

sp_result db_case_clash(sp_db* db, const char* sql, const char* kind, const char* value, const char* why, sp_error* err)
{
    sqlite3_stmt* st = NULL;
    sp_result r = db_prepare(db, sql, &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_text(st, 1, value, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        r = sp_fail(err, SP_ERR_INVALID, "%s: %s '%s' differs from its '%s' only in case (%s)", db->path, kind, value,
                    (const char*)sqlite3_column_text(st, 0), why);
    else if (rc != SQLITE_DONE)
        r = db_fail(db, rc, "reading the names", err);
    sqlite3_finalize(st);
    return r;
}

sp_result db_category_case_clash(sp_db* db, const char* category, sp_error* err)
{
    sp_result r = db_case_clash(db, "SELECT category FROM parts WHERE category = ?1 COLLATE NOCASE AND category <> ?1 LIMIT 1",
                                "category", category, "use that one", err);
    if (r == SP_OK)
        r = db_case_clash(db, "SELECT category FROM sketches WHERE category = ?1 COLLATE NOCASE AND category <> ?1 LIMIT 1",
                          "category", category, "use that one", err);
    return r;
}

// A part stored already from the same bytes (under another name), or
// derived from the same file, is said: the classifier then learns two
// categories from the same shapes, and a curator added one file twice
// without a word (an outside review). The file's own hash: a plain glTF
// derived under two categories is stored as two files (the category is in
// them), so the case this is for went unsaid (a second review).
static void warn_same_file(sp_db* db, const sp_db_part_info* info, const char* source_sha, const sp_db_part_desc* d)
{
    sqlite3_stmt* st = NULL;
    sp_error e = {0};
    if (!d->warn ||
        db_prepare(db,
                   "SELECT name, category FROM parts WHERE sha256 = ?1 OR json_extract(summary, '$.source_sha256') = ?2"
                   " ORDER BY sha256 = ?1 DESC LIMIT 1",
                   &st, &e) != SP_OK)
        return;
    sqlite3_bind_text(st, 1, info->sha256, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, source_sha, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(st) == SQLITE_ROW) {
        char line[320];
        snprintf(line, sizeof line,
                 "the same file as part '%s' (category %s): visitors' drawings of the two look alike to the classifier",
                 (const char*)sqlite3_column_text(st, 0), (const char*)sqlite3_column_text(st, 1));
        d->warn(d->warn_user, line);
    }
    sqlite3_finalize(st);
}

static sp_result add_part(sp_db* db, const void* glb, size_t size, const sp_db_part_desc* desc, unsigned derived,
                          const char* source_sha, sp_db_part_info* info_out, sp_error* err)
{
    sp_db_part_desc d = desc ? *desc : (sp_db_part_desc){0};
    char shown[128];
    if (!d.name || !sp_part_name_is_plain(d.name))
        return sp_fail(err, SP_ERR_INVALID, "part name '%s' is not a plain name ([A-Za-z0-9_.-], < 64 chars)",
                       sp_text_printable(d.name, shown, sizeof shown));
    sp_db_part_info info;
    sp_character ch = {0};
    int a = -1;
    // Everything slow happens before the write lock.
    sp_result r = validate(glb, size, d.name, &d, &info, &ch, &a, err);
    if (r != SP_OK) return r;
    if (d.before_store && (r = d.before_store(d.before_store_user, &ch, a, err)) != SP_OK) {
        sp_character_free(&ch);
        return r;
    }
    copy_name(info.name, sizeof info.name, d.name);
    int nsynth = d.synth_sketches == 0 ? SP_DB_SYNTH_DEFAULT : d.synth_sketches < 0 ? 0 : d.synth_sketches;
    sp_dataset synth = {0};
    // Without a seed each part gets its own family (from its name), so that parts do not share rotations and wobbles.
    uint64_t family = d.seed ? d.seed : sp_handdraw_part_family(1, d.name);
    if (nsynth > 0 && (r = db_synth_sketches(&ch, a, nsynth, family, d.synth_amplitude, &synth, err)) != SP_OK) {
        sp_character_free(&ch);
        return r;
    }
    char* summary = summary_json(&ch.rig, source_sha);
    sp_character_free(&ch);
    if (!summary) {
        sp_dataset_free(&synth);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    const char* by = db_who(d.added_by);
    sqlite3_stmt* st = NULL;
    if ((r = db_begin(db, err)) != SP_OK) goto done;
    if ((r = db_category_case_clash(db, info.category, err)) != SP_OK ||
        (r = db_case_clash(db, "SELECT name FROM parts WHERE name = ?1 COLLATE NOCASE AND name <> ?1 LIMIT 1", "part name",
                           info.name, "an export's files of the two would be one on a case-blind file system", err)) != SP_OK)
        goto rollback;
    warn_same_file(db, &info, source_sha, &d);
    if ((r = db_prepare(db,
                        "INSERT INTO parts(name, category, abstraction, gltf, bytes, sha256, vertices, triangles, joints, parameters,"
                        " abstractions, animations, selftest_error, summary, added_by) VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
                        &st, err)) != SP_OK)
        goto rollback;
    sqlite3_bind_text(st, 1, info.name, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, info.category, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, info.abstraction, -1, SQLITE_TRANSIENT);
    if ((r = db_bind_blob(db, st, 4, glb, size, "the part's glTF", err)) != SP_OK) goto rollback;
    sqlite3_bind_int64(st, 5, (sqlite3_int64)size);
    sqlite3_bind_text(st, 6, info.sha256, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(st, 7, info.vertices);
    sqlite3_bind_int(st, 8, info.triangles);
    sqlite3_bind_int(st, 9, info.joints);
    sqlite3_bind_int(st, 10, info.parameters);
    sqlite3_bind_int(st, 11, info.abstractions);
    sqlite3_bind_int(st, 12, info.animations);
    if (info.selftest_error >= 0) sqlite3_bind_double(st, 13, info.selftest_error);
    sqlite3_bind_text(st, 14, summary, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 15, by, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        if (rc == SQLITE_CONSTRAINT_UNIQUE)
            r = sp_fail(err, SP_ERR_INVALID, "%s: a part named '%s' exists (remove it first)", db->path, info.name);
        else r = db_fail(db, rc, "storing the part", err);
        goto rollback;
    }
    int64_t part_id = sqlite3_last_insert_rowid(db->h);
    DB_HOOK("part");
    for (int i = 0; i < synth.count; ++i) {
        if ((r = db_insert_sketch(db, info.category, SP_DB_SOURCE_SYNTHETIC, part_id, &synth.samples[i], NULL, by, err)) != SP_OK)
            goto rollback;
        if (i == synth.count / 2) DB_HOOK("sketches");
    }
    char details[256];
    snprintf(details, sizeof details, "{\"category\": \"%s\", \"sha256\": \"%s\", \"bytes\": %zu, \"synthetic_sketches\": %d}", info.category,
             info.sha256, size, synth.count);
    if ((r = db_log_row(db, by, "add-part", info.name, details, err)) != SP_OK) goto rollback;
    r = db_commit(db, err);
    goto done;
rollback:
    db_rollback(db);
done:
    free(summary);
    sp_dataset_free(&synth);
    if (r == SP_OK && info_out) {
        *info_out = info;
        sp_error e2 = {0};
        if (sp_db_part(db, info.name, info_out, &e2) != SP_OK) copy_name(info_out->added_by, sizeof info_out->added_by, by);
        info_out->selftest_error = info.selftest_error;
        info_out->derived = derived;
    }
    return r;
}

sp_result sp_db_add_part_file(sp_db* db, const char* path, const sp_db_part_desc* desc, sp_db_part_info* info, sp_error* err)
{
    // Load from the path first: its messages are the loader's, and a .gltf
    // with external buffers only loads there.
    sp_character ch = {0};
    sp_result r = sp_gltf_load(path, &ch, err);
    if (r != SP_OK) return r;
    sp_db_part_desc d = desc ? *desc : (sp_db_part_desc){0};
    void* bytes = NULL;
    size_t size = 0;
    unsigned derived = 0;
    // Derived from what the path loads (a .gltf's external buffers, a missing
    // texture only a warning), before any re-encoding would add our extras.
    if ((r = derive_part(&ch, &d, path, &bytes, &size, &derived, err)) != SP_OK) {
        sp_character_free(&ch);
        return r;
    }
    sp_character probe = {0};
    sp_error e2 = {0};
    if (!bytes && (r = db_read_file(path, &bytes, &size, err)) != SP_OK) {
        sp_character_free(&ch);
        return r;
    }
    if (derived || sp_gltf_load_memory(bytes, size, path, &probe, &e2) == SP_OK) {
        sp_character_free(&probe);
    } else {
        // Not self-contained (external .bin): store it re-encoded as one GLB.
        free(bytes);
        bytes = NULL;
        if ((r = sp_gltf_save_memory(&ch, NULL, &bytes, &size, err)) != SP_OK) {
            sp_character_free(&ch);
            return r;
        }
    }
    sp_character_free(&ch);
    char name[SP_NAME_MAX];
    if (!d.name) {
        const char* base = strrchr(path, '/');
        base = base ? base + 1 : path;
        snprintf(name, sizeof name, "%s", base);
        char* dot = strrchr(name, '.');
        if (dot && dot != name) *dot = 0;
        d.name = name;
        // The name comes from the file: say so, and how to give another.
        char shown[128];
        if (!sp_part_name_is_plain(name)) {
            free(bytes);
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: the part would be named '%s' after the file, which is not a plain name ([A-Za-z0-9_.-], < 64 "
                           "chars): rename the file, or give the part a name (db add-part --name)",
                           path, sp_text_printable(name, shown, sizeof shown));
        }
    }
    // The file as given, for warn_same_file (bytes may be derived from it).
    char source[65];
    void* raw = NULL;
    size_t raw_size = 0;
    if (d.source_sha256 && strlen(d.source_sha256) == 64 && strspn(d.source_sha256, "0123456789abcdef") == 64) {
        memcpy(source, d.source_sha256, 65);
    } else if (!derived) {
        r = sp_sha256_hex(bytes, size, source) ? SP_OK : sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    } else if ((r = db_read_file(path, &raw, &raw_size, err)) == SP_OK && !sp_sha256_hex(raw, raw_size, source)) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    free(raw);
    if (r == SP_OK) r = add_part(db, bytes, size, &d, derived, source, info, err);
    free(bytes);
    return r;
}

sp_result sp_db_remove_part(sp_db* db, const char* name, const char* by, sp_error* err)
{
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    sqlite3_stmt* st;
    if ((r = db_prepare(db, "DELETE FROM parts WHERE name = ?", &st, err)) != SP_OK) goto rollback;
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        r = db_fail(db, rc, "removing the part", err);
        goto rollback;
    }
    if (sqlite3_changes(db->h) == 0) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: no part named '%s'", db->path, name);
        goto rollback;
    }
    DB_HOOK("remove");
    if ((r = db_log_row(db, by, "remove-part", name, NULL, err)) != SP_OK) goto rollback;
    return db_commit(db, err);
rollback:
    db_rollback(db);
    return r;
}

#define PART_COLS                                                                                                             \
    "p.name, p.category, p.abstraction, p.vertices, p.triangles, p.joints, p.parameters, p.abstractions, p.animations, p.bytes," \
    " p.sha256, p.selftest_error, p.added_by, p.added_at, (SELECT count(*) FROM sketches s WHERE s.category = p.category)"

static void read_info(sqlite3_stmt* st, sp_db_part_info* o)
{
    memset(o, 0, sizeof *o);
    copy_name(o->name, sizeof o->name, (const char*)sqlite3_column_text(st, 0));
    copy_name(o->category, sizeof o->category, (const char*)sqlite3_column_text(st, 1));
    copy_name(o->abstraction, sizeof o->abstraction, (const char*)sqlite3_column_text(st, 2));
    o->vertices = sqlite3_column_int(st, 3);
    o->triangles = sqlite3_column_int(st, 4);
    o->joints = sqlite3_column_int(st, 5);
    o->parameters = sqlite3_column_int(st, 6);
    o->abstractions = sqlite3_column_int(st, 7);
    o->animations = sqlite3_column_int(st, 8);
    o->bytes = (size_t)sqlite3_column_int64(st, 9);
    copy_name(o->sha256, sizeof o->sha256, (const char*)sqlite3_column_text(st, 10));
    o->selftest_error = sqlite3_column_type(st, 11) == SQLITE_NULL ? -1 : sqlite3_column_double(st, 11);
    copy_name(o->added_by, sizeof o->added_by, (const char*)sqlite3_column_text(st, 12));
    copy_name(o->added_at, sizeof o->added_at, (const char*)sqlite3_column_text(st, 13));
    o->sketches = sqlite3_column_int(st, 14);
}

sp_result sp_db_list_parts(sp_db* db, sp_db_part_info** parts, int* count, sp_error* err)
{
    *parts = NULL;
    *count = 0;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "SELECT " PART_COLS " FROM parts p ORDER BY p.name", &st, err);
    if (r != SP_OK) return r;
    int rc, n = 0, cap = 0;
    sp_db_part_info* out = NULL;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (n == cap) {
            cap = cap ? 2 * cap : 8;
            sp_db_part_info* g = realloc(out, sizeof *out * (size_t)cap);
            if (!g) {
                free(out);
                sqlite3_finalize(st);
                return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
            }
            out = g;
        }
        read_info(st, &out[n++]);
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        free(out);
        return db_fail(db, rc, "listing parts", err);
    }
    *parts = out;
    *count = n;
    return SP_OK;
}

// The row of part `name` that `sql` selects (its one parameter is the name),
// stepped and ready to read; the caller finalizes it. No such part, or a failed
// read, finalizes it here and says which.
static sp_result part_row(sp_db* db, const char* sql, const char* name, sqlite3_stmt** row, sp_error* err)
{
    *row = NULL;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, sql, &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        *row = st;
        return SP_OK;
    }
    r = rc == SQLITE_DONE ? sp_fail(err, SP_ERR_INVALID, "%s: no part named '%s'", db->path, name)
                          : db_fail(db, rc, "reading a part", err);
    sqlite3_finalize(st);
    return r;
}

sp_result sp_db_part(sp_db* db, const char* name, sp_db_part_info* info, sp_error* err)
{
    sqlite3_stmt* st;
    sp_result r = part_row(db, "SELECT " PART_COLS " FROM parts p WHERE p.name = ?", name, &st, err);
    if (r != SP_OK) return r;
    read_info(st, info);
    sqlite3_finalize(st);
    return SP_OK;
}

sp_result sp_db_part_bytes(sp_db* db, const char* name, void** glb, size_t* size, sp_error* err)
{
    *glb = NULL;
    *size = 0;
    sqlite3_stmt* st;
    sp_result r = part_row(db, "SELECT gltf, sha256 FROM parts WHERE name = ?", name, &st, err);
    if (r != SP_OK) return r;
    size_t n = (size_t)sqlite3_column_bytes(st, 0);
    const void* src = sqlite3_column_blob(st, 0);
    char want[65], got[65];
    copy_name(want, sizeof want, (const char*)sqlite3_column_text(st, 1));
    void* buf = sp_sha256_hex(src, n, got) ? malloc(n ? n : 1) : NULL;
    if (!buf)
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    else if (strcmp(want, got) != 0) {
        free(buf);
        r = sp_fail(err, SP_ERR_PARSE, "%s: part '%s': stored glTF does not match its checksum", db->path, name);
    } else {
        memcpy(buf, src, n);
        *glb = buf;
        *size = n;
    }
    sqlite3_finalize(st);
    return r;
}

sp_result sp_db_load_part(sp_db* db, const char* name, sp_character* out, sp_error* err)
{
    void* glb;
    size_t size;
    sp_result r = sp_db_part_bytes(db, name, &glb, &size, err);
    if (r != SP_OK) return r;
    char what[256];
    snprintf(what, sizeof what, "%s:%s", db->path, name);
    r = sp_gltf_load_memory(glb, size, what, out, err);
    free(glb);
    return r;
}

static sp_result strings_query(sp_db* db, const char* sql, const char* arg, char*** names, int* count, sp_error* err)
{
    *names = NULL;
    *count = 0;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, sql, &st, err);
    if (r != SP_OK) return r;
    if (arg) sqlite3_bind_text(st, 1, arg, -1, SQLITE_TRANSIENT);
    int rc, n = 0, cap = 0;
    char** out = NULL;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (n == cap) {
            cap = cap ? 2 * cap : 8;
            char** g = realloc(out, sizeof *out * (size_t)cap);
            if (!g) break;
            out = g;
        }
        if (!(out[n] = strdup((const char*)sqlite3_column_text(st, 0)))) break;
        ++n;
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        sp_db_free_strings(out, n);
        return rc == SQLITE_ROW ? sp_fail(err, SP_ERR_NO_MEMORY, "out of memory") : db_fail(db, rc, "reading", err);
    }
    *names = out;
    *count = n;
    return SP_OK;
}

sp_result sp_db_category_parts(sp_db* db, const char* category, char*** names, int* count, sp_error* err)
{
    return strings_query(db, "SELECT name FROM parts WHERE category = ? ORDER BY name", category, names, count, err);
}

sp_result sp_db_categories(sp_db* db, char*** names, int* count, sp_error* err)
{
    return strings_query(db, "SELECT DISTINCT category FROM parts ORDER BY category", NULL, names, count, err);
}

sp_result sp_db_part_summary_json(sp_db* db, const char* name, char** json, sp_error* err)
{
    *json = NULL;
    sqlite3_stmt* st;
    sp_result r = part_row(db, "SELECT summary FROM parts WHERE name = ?", name, &st, err);
    if (r != SP_OK) return r;
    if (!(*json = strdup((const char*)sqlite3_column_text(st, 0)))) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sqlite3_finalize(st);
    return r;
}
