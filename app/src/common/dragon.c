// dragon.c: the kiosk pipeline without a window (see dragon.h for the
// world, placement, attachment and animation conventions).
#include "dragon.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "posing.h"
#include "report.h"
#include "sp/curve.h"
#include "sp/synth.h"

// ---- small helpers ---------------------------------------------------------------

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

static void copy_name(char* dst, size_t cap, const char* src)
{
    snprintf(dst, cap, "%s", src ? src : "");
}

// Unit quaternion of an orthonormal 3x3 (column-major) rotation (Shepperd).
static sp_quat quat_from_columns(sp_vec3 c0, sp_vec3 c1, sp_vec3 c2)
{
    double m00 = c0.x, m10 = c0.y, m20 = c0.z, m01 = c1.x, m11 = c1.y, m21 = c1.z, m02 = c2.x, m12 = c2.y, m22 = c2.z;
    double tr = m00 + m11 + m22;
    sp_quat q;
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        q = (sp_quat){(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s};
    } else if (m00 > m11 && m00 > m22) {
        double s = sqrt(1.0 + m00 - m11 - m22) * 2;
        q = (sp_quat){0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s};
    } else if (m11 > m22) {
        double s = sqrt(1.0 + m11 - m00 - m22) * 2;
        q = (sp_quat){(m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s};
    } else {
        double s = sqrt(1.0 + m22 - m00 - m11) * 2;
        q = (sp_quat){(m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s};
    }
    return sp_quat_norm(q);
}

// The nearest similarity (translation, rotation, uniform scale) to an affine
// matrix. Why: glTF nodes must be TRS, and a joint frame with non-uniform
// bone scales under a rotation would shear whatever hangs on it.
typedef struct sim3 {
    sp_vec3 t;
    sp_quat r;
    double s;
} sim3;

static sim3 sim_of(const sp_mat4* m)
{
    sp_vec3 c0 = {m->m[0], m->m[1], m->m[2]}, c1 = {m->m[4], m->m[5], m->m[6]}, c2 = {m->m[8], m->m[9], m->m[10]};
    double det = sp_v3_dot(c0, sp_v3_cross(c1, c2));
    double s = cbrt(fabs(det));
    if (!(s > 1e-300) || !isfinite(s)) s = 1.0;
    // Gram-Schmidt keeps the first axis; good enough for the near-conformal frames we get.
    sp_vec3 x = sp_v3_norm(c0);
    sp_vec3 y = sp_v3_norm(sp_v3_sub(c1, sp_v3_scale(x, sp_v3_dot(x, c1))));
    sp_vec3 z = sp_v3_cross(x, y);
    if (sp_v3_len(x) < 0.5 || sp_v3_len(y) < 0.5) x = sp_v3(1, 0, 0), y = sp_v3(0, 1, 0), z = sp_v3(0, 0, 1);
    return (sim3){sp_mat4_translation(m), quat_from_columns(x, y, z), s};
}

static sp_mat4 sim_mat(sim3 a)
{
    return sp_mat4_trs(a.t, a.r, (sp_vec3){a.s, a.s, a.s});
}

static sp_mat4 mat_translate(sp_vec3 t)
{
    sp_mat4 m = sp_mat4_identity();
    m.m[12] = t.x, m.m[13] = t.y, m.m[14] = t.z;
    return m;
}

static void transform_points(const sp_mat4* m, double* xyz, int n)
{
    for (int i = 0; i < n; ++i) {
        sp_vec3 p = sp_mat4_point(m, (sp_vec3){xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
        xyz[3 * i] = p.x, xyz[3 * i + 1] = p.y, xyz[3 * i + 2] = p.z;
    }
}

// ---- parts as stored (templates) -------------------------------------------------

typedef struct dsocket {
    char name[SP_NAME_MAX];
    int joint;
    sp_vec3 local;     // in the joint's frame at the rest pose
    char accepts[256]; // ",head,neck," or empty: anything
} dsocket;

typedef struct tpl {
    int refs; // the cache and every placed part hold one
    char name[SP_NAME_MAX], category[SP_NAME_MAX], sha256[65];
    sp_character ch;
    int abstraction;
    sp_camera base;           // the part's sketch view on the dragon canvas, orthographic
    double depth0;            // camera z of the rest-pose centre in `base`
    sp_vec2 rest_lo, rest_hi; // the rest abstraction's bounding box in `base`, pixels
    bool is_torso;
    int socket_count;
    dsocket* sockets;
    int attach_joint;
    sp_vec3 attach_local;
    char prefer[SP_NAME_MAX]; // preferred socket name
    const sp_animation* clip;
    double clip_start, clip_len; // seconds
    double* clip0;               // the rest parameters: the clip's offsets are keyed relative to them
    double* scratch_p;           // param_count
    sp_vec3 *tr, *sc;            // joint_count scratch for sampling the clip
    sp_quat* rot;
    sp_solver* solver;
    sp_camera solver_cam; // the solver reads the camera through this pointer at every solve
    sp_rig_eval* ev;
} tpl;

static void tpl_release(tpl* t)
{
    if (!t || --t->refs > 0) return;
    sp_solver_destroy(t->solver);
    sp_rig_eval_destroy(t->ev);
    free(t->sockets);
    free(t->clip0);
    free(t->scratch_p);
    free(t->tr);
    free(t->sc);
    free(t->rot);
    sp_character_free(&t->ch);
    free(t);
}

static bool read_vec3(const cJSON* a, sp_vec3* out)
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 3) return false;
    double v[3];
    for (int i = 0; i < 3; ++i) {
        const cJSON* e = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) return false;
        v[i] = e->valuedouble;
    }
    *out = (sp_vec3){v[0], v[1], v[2]};
    return true;
}

// A point given in model space at the rest pose, as an offset in `joint`'s frame.
static sp_vec3 to_joint_local(tpl* t, int joint, sp_vec3 model)
{
    const sp_mat4* G = &sp_rig_eval_world(t->ev)[joint];
    sp_mat4 inv;
    if (!sp_mat4_inverse(G, &inv)) return (sp_vec3){0, 0, 0};
    return sp_mat4_point(&inv, model);
}

// Reads the sockets / attach hints of the part's sp_part extras (DESIGN.md;
// every key optional). t->ev must hold the rest pose.
static void read_part_extras(tpl* t)
{
    const sp_rig* rig = &t->ch.rig;
    t->attach_joint = 0;
    for (int j = 0; j < rig->joint_count; ++j)
        if (rig->joints[j].parent < 0) {
            t->attach_joint = j;
            break;
        }
    t->attach_local = (sp_vec3){0, 0, 0};
    t->is_torso = !strcmp(t->category, "torso");
    cJSON* part = t->ch.part_json ? cJSON_Parse(t->ch.part_json) : NULL;
    if (!part) return;
    const cJSON* sockets = cJSON_GetObjectItemCaseSensitive(part, "sockets");
    int n = cJSON_IsArray(sockets) ? cJSON_GetArraySize(sockets) : 0;
    if (n > 0) t->sockets = calloc((size_t)n, sizeof(dsocket));
    const cJSON* s;
    if (t->sockets) cJSON_ArrayForEach(s, sockets)
        {
            dsocket* d = &t->sockets[t->socket_count];
            const cJSON* name = cJSON_GetObjectItemCaseSensitive(s, "name");
            const cJSON* joint = cJSON_GetObjectItemCaseSensitive(s, "joint");
            const cJSON* pos = cJSON_GetObjectItemCaseSensitive(s, "position");
            const cJSON* acc = cJSON_GetObjectItemCaseSensitive(s, "accepts");
            d->joint = cJSON_IsString(joint) ? sp_rig_find_joint(rig, joint->valuestring) : t->attach_joint;
            if (d->joint < 0) continue; // a socket on a joint the part does not have: ignore it
            snprintf(d->name, sizeof d->name, "%s", cJSON_IsString(name) ? name->valuestring : "socket");
            sp_vec3 p;
            d->local = read_vec3(pos, &p) ? to_joint_local(t, d->joint, p) : (sp_vec3){0, 0, 0};
            if (cJSON_IsArray(acc)) {
                const cJSON* c;
                size_t len = 0;
                d->accepts[len++] = ',';
                cJSON_ArrayForEach(c, acc) if (cJSON_IsString(c) && len + strlen(c->valuestring) + 2 < sizeof d->accepts)
                {
                    len += (size_t)snprintf(d->accepts + len, sizeof d->accepts - len, "%s,", c->valuestring);
                }
                if (len == 1) d->accepts[0] = 0;
            } else if (cJSON_IsString(acc)) {
                snprintf(d->accepts, sizeof d->accepts, ",%s,", acc->valuestring);
            }
            ++t->socket_count;
        }
    if (t->socket_count > 0) t->is_torso = true;
    const cJSON* at = cJSON_GetObjectItemCaseSensitive(part, "attach");
    if (cJSON_IsString(at)) {
        int j = sp_rig_find_joint(rig, at->valuestring);
        if (j >= 0) t->attach_joint = j;
    } else if (cJSON_IsObject(at)) {
        const cJSON* joint = cJSON_GetObjectItemCaseSensitive(at, "joint");
        const cJSON* pos = cJSON_GetObjectItemCaseSensitive(at, "position");
        const cJSON* sock = cJSON_GetObjectItemCaseSensitive(at, "socket");
        int j = cJSON_IsString(joint) ? sp_rig_find_joint(rig, joint->valuestring) : -1;
        if (j >= 0) t->attach_joint = j;
        sp_vec3 p;
        if (read_vec3(pos, &p)) t->attach_local = to_joint_local(t, t->attach_joint, p);
        if (cJSON_IsString(sock)) copy_name(t->prefer, sizeof t->prefer, sock->valuestring);
    }
    cJSON_Delete(part);
}

// The clip's parameters at clip time tc (into out), from the joints' local TRS.
static void clip_params(tpl* t, double tc, double* out)
{
    const sp_rig* rig = &t->ch.rig;
    for (int j = 0; j < rig->joint_count; ++j)
        t->tr[j] = rig->joints[j].rest_t, t->rot[j] = rig->joints[j].rest_r, t->sc[j] = rig->joints[j].rest_s;
    sp_animation_sample(t->clip, tc, t->tr, t->rot, t->sc);
    sp_rig_defaults(rig, out);
    for (int j = 0; j < rig->joint_count; ++j)
        if (rig->joints[j].param_count > 0) sp_rig_params_from_trs(rig, j, t->tr[j], t->rot[j], t->sc[j], out);
}

static tpl* tpl_load(sp_db* db, const char* name, int canvas_w, int canvas_h, const sp_solve_desc* solve, sp_error* err)
{
    tpl* t = calloc(1, sizeof *t);
    if (!t) {
        sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        return NULL;
    }
    t->refs = 1;
    sp_db_part_info info;
    if (sp_db_part(db, name, &info, err) != SP_OK || sp_db_load_part(db, name, &t->ch, err) != SP_OK) {
        free(t);
        return NULL;
    }
    copy_name(t->name, sizeof t->name, name);
    copy_name(t->category, sizeof t->category, info.category);
    copy_name(t->sha256, sizeof t->sha256, info.sha256);
    const sp_rig* rig = &t->ch.rig;
    t->abstraction = info.abstraction[0] ? sp_rig_find_abstraction(rig, info.abstraction) : -1;
    if (t->abstraction < 0) t->abstraction = rig->abstraction_count > 0 ? 0 : -1;
    size_t P = (size_t)rig->param_count + 1, J = (size_t)rig->joint_count + 1;
    t->ev = sp_rig_eval_create(rig);
    t->scratch_p = malloc(sizeof(double) * P);
    t->tr = malloc(sizeof(sp_vec3) * J);
    t->sc = malloc(sizeof(sp_vec3) * J);
    t->rot = malloc(sizeof(sp_quat) * J);
    double* xyz = malloc(sizeof(double) * 3 * ((size_t)rig->vertex_count + 1));
    double* xy =
        t->abstraction >= 0 ? malloc(sizeof(double) * 2 * ((size_t)rig->abstractions[t->abstraction].point_count + 1)) : NULL;
    if (!t->ev || !t->scratch_p || !t->tr || !t->sc || !t->rot || !xyz || (t->abstraction >= 0 && !xy)) {
        sp_fail(err, SP_ERR_NO_MEMORY, "part %s: out of memory", name);
        goto fail;
    }
    if (t->abstraction < 0 || rig->abstractions[t->abstraction].point_count < 2) {
        sp_fail(err, SP_ERR_INVALID, "part %s: no sketch abstraction to fit", name);
        goto fail;
    }
    // The rest pose: where sockets and attach points are given, and the depth reference.
    sp_rig_defaults(rig, t->scratch_p);
    sp_rig_eval_update(t->ev, t->scratch_p, false);
    read_part_extras(t);
    sp_rig_eval_update(t->ev, t->ch.pose, false);
    sp_rig_eval_points(t->ev, sp_rig_mesh_points(rig), xyz);
    sp_vec3 lo, hi;
    sp_bounds(xyz, rig->vertex_count, &lo, &hi);
    sp_vec3 centre = sp_v3_scale(sp_v3_add(lo, hi), 0.5);
    t->base = sp_camera_resize(&t->ch.camera, canvas_w, canvas_h);
    sp_vec3 c = sp_mat4_point(&t->base.view, centre);
    if (t->base.kind == SP_CAMERA_PERSPECTIVE) {
        // Weak perspective at the part's centre: the world is orthographic (dragon.h).
        double d = -c.z > 1e-9 ? -c.z : 1.0;
        t->base.kind = SP_CAMERA_ORTHOGRAPHIC;
        t->base.scale /= d;
    }
    t->depth0 = c.z;
    sp_abstraction_project(rig, t->abstraction, &t->base, t->ch.pose, xy);
    int n = rig->abstractions[t->abstraction].point_count;
    t->rest_lo = t->rest_hi = (sp_vec2){xy[0], xy[1]};
    for (int i = 1; i < n; ++i) {
        t->rest_lo.x = fmin(t->rest_lo.x, xy[2 * i]), t->rest_lo.y = fmin(t->rest_lo.y, xy[2 * i + 1]);
        t->rest_hi.x = fmax(t->rest_hi.x, xy[2 * i]), t->rest_hi.y = fmax(t->rest_hi.y, xy[2 * i + 1]);
    }
    double diag = sp_v2_len(sp_v2_sub(t->rest_hi, t->rest_lo));
    if (!(diag > 1e-6) || !isfinite(diag)) {
        sp_fail(err, SP_ERR_INVALID, "part %s: its abstraction is invisible in its sketch view", name);
        goto fail;
    }
    // The clip: the first animation with channels.
    for (int a = 0; a < rig->animation_count && !t->clip; ++a) {
        const sp_animation* an = &rig->animations[a];
        double start = INFINITY, end = -INFINITY;
        for (int k = 0; k < an->channel_count; ++k)
            if (an->channels[k].key_count > 0) {
                start = fmin(start, an->channels[k].times[0]);
                end = fmax(end, an->channels[k].times[an->channels[k].key_count - 1]);
            }
        if (end - start > 1e-3 && isfinite(end - start)) {
            t->clip = an;
            t->clip_start = start;
            t->clip_len = end - start;
        }
    }
    if (t->clip) {
        t->clip0 = malloc(sizeof(double) * P);
        if (!t->clip0) {
            sp_fail(err, SP_ERR_NO_MEMORY, "part %s: out of memory", name);
            goto fail;
        }
        // Offsets relative to rest (docs/DESIGN.md, "Animation clips as
        // offsets"), not to the clip's first frame: the clips have phase lags
        // along their chains, and subtracting a first frame would make a flap
        // or a sway lopsided about the drawn pose.
        sp_rig_defaults(rig, t->clip0);
    }
    t->solver_cam = t->base;
    t->solver = sp_solver_create(rig, t->abstraction, &t->solver_cam, solve);
    if (!t->solver) {
        sp_fail(err, SP_ERR_NO_MEMORY, "part %s: cannot prepare the solver (out of memory)", name);
        goto fail;
    }
    free(xyz);
    free(xy);
    return t;
fail:
    free(xyz);
    free(xy);
    tpl_release(t);
    return NULL;
}

// ---- the dragon ------------------------------------------------------------------

typedef struct part {
    sp_dragon_part pub;
    tpl* t;
    double* p_fit;
    sp_vec2* stroke;
    int stroke_n;
    sp_mat4 world_fit; // model -> world at t = 0, after attachment
    sim3 socket0;      // the socket's frame at the torso's fitted pose (attached parts)
    double *p_t, *xyz, *outline;
    sp_mat4 world_t;
    sp_rig_eval* ev;
} part;

struct sp_dragon {
    sp_dragon_desc desc;
    sp_db* db;
    bool own_db;
    char db_path[1024], assets_dir[1024];
    dev_t dev;
    ino_t ino;
    uint64_t gen;
    sp_clf* clf;
    tpl** cache;
    int cache_n;
    part** parts;
    int part_n, part_cap;
    uint64_t next_id;
    sp_camera world;
    double period;
    bool posed;
};

const char* sp_dragon_reject_name(sp_dragon_reject r)
{
    switch (r) {
    case SP_DRAGON_ACCEPTED:
        return "accepted";
    case SP_DRAGON_TOO_SHORT:
        return "too_short";
    case SP_DRAGON_UNRECOGNISED:
        return "unrecognised";
    case SP_DRAGON_NO_PART:
        return "no_part";
    case SP_DRAGON_NO_MODEL:
        return "no_model";
    case SP_DRAGON_FIT_FAILED:
        return "fit_failed";
    case SP_DRAGON_NOTHING_TO_REFIT:
        return "nothing_to_refit";
    case SP_DRAGON_FULL:
        return "full";
    }
    return "unknown";
}

static void part_free(part* p)
{
    if (!p) return;
    tpl_release(p->t);
    free(p->p_fit);
    free(p->stroke);
    free(p->p_t);
    free(p->xyz);
    free(p->outline);
    sp_rig_eval_destroy(p->ev);
    free(p);
}

static void cache_clear(sp_dragon* d)
{
    for (int i = 0; i < d->cache_n; ++i)
        tpl_release(d->cache[i]);
    free(d->cache);
    d->cache = NULL;
    d->cache_n = 0;
}

// After a change of the database: keeps the loaded parts whose stored bytes
// are unchanged (same name, category and SHA-256), so a curator's edit does
// not make every next stroke pay for loading and preparing its part again.
static void cache_prune(sp_dragon* d)
{
    int kept = 0;
    for (int i = 0; i < d->cache_n; ++i) {
        tpl* t = d->cache[i];
        sp_db_part_info info;
        sp_error e = {0};
        bool same = d->db && sp_db_part(d->db, t->name, &info, &e) == SP_OK && !strcmp(info.sha256, t->sha256) &&
                    !strcmp(info.category, t->category);
        if (same)
            d->cache[kept++] = t;
        else
            tpl_release(t);
    }
    d->cache_n = kept;
}

static bool file_id(const char* path, dev_t* dev, ino_t* ino)
{
    struct stat st;
    if (stat(path, &st) != 0) return false;
    *dev = st.st_dev, *ino = st.st_ino;
    return true;
}

// After the database file was replaced by a rename, its -wal/-shm beside it
// still belong to the old file (SQLite does not remove them when the file it
// had open has moved), and a new connection would read the new file through
// the old file's WAL. They are removed when no process holds a lock on the
// -shm (nobody uses them) and the WAL was not written since the new file
// arrived (its ctime: rename sets it).
static void drop_stale_sidecars(const char* path)
{
    char wal[1100], shm[1100];
    snprintf(wal, sizeof wal, "%s-wal", path);
    snprintf(shm, sizeof shm, "%s-shm", path);
    struct stat db, w;
    if (stat(path, &db) != 0) return;
    if (stat(wal, &w) == 0 && w.st_mtime > db.st_ctime) return;
    int fd = open(shm, O_RDWR);
    if (fd >= 0) {
        // SQLite's unix VFS locks bytes 120..128 of the -shm (the lock slots and the dead man switch).
        struct flock fl = {.l_type = F_WRLCK, .l_whence = SEEK_SET, .l_start = 120, .l_len = 9};
        bool used = fcntl(fd, F_GETLK, &fl) != 0 || fl.l_type != F_UNLCK;
        close(fd);
        if (used) return;
    }
    unlink(wal);
    unlink(shm);
}

// Opens our own connection, read-only: the kiosk never writes.
static sp_result open_own(sp_dragon* d, sp_error* err)
{
    sp_db* db = NULL;
    sp_result r = sp_db_open(d->db_path, SP_DB_READONLY, &db, err);
    if (r != SP_OK) return r;
    d->db = db;
    file_id(d->db_path, &d->dev, &d->ino);
    return SP_OK;
}

sp_dragon* sp_dragon_create(const sp_dragon_desc* desc, sp_error* err)
{
    sp_dragon* d = calloc(1, sizeof *d);
    if (!d) {
        sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        return NULL;
    }
    d->desc = desc ? *desc : (sp_dragon_desc){0};
    sp_dragon_desc* o = &d->desc;
    if (o->canvas_w <= 0 || o->canvas_h <= 0) o->canvas_w = 1280, o->canvas_h = 800;
    // Kiosk defaults: a visitor waits for the fit (target 50 ms pen-up to part);
    // 100 representatives and 48 samples per curve halve the solve on the
    // shipped parts at the same accuracy for freehand strokes (notes/pipeline.md).
    if (!(o->solve.time_cap_ms > 0)) o->solve.time_cap_ms = 250;
    if (o->solve.representatives <= 0) o->solve.representatives = 100;
    if (o->solve.samples <= 0) o->solve.samples = 48;
    if (o->snap_fraction == 0) o->snap_fraction = 0.15;
    if (o->max_variants <= 0) o->max_variants = 4;
    if (!(o->fps > 0)) o->fps = 30;
    if (o->max_parts <= 0) o->max_parts = 48;
    o->solve.active = NULL; // a flag array would belong to one rig; parts differ
    d->next_id = 1;
    // The world camera (dragon.h): canvas height = 2 units, origin at the centre, eye on +Z.
    sp_camera w = {0};
    w.kind = SP_CAMERA_ORTHOGRAPHIC;
    w.view = mat_translate((sp_vec3){0, 0, -10});
    w.scale = 0.5 * o->canvas_h;
    w.cx = 0.5 * o->canvas_w, w.cy = 0.5 * o->canvas_h;
    w.width = o->canvas_w, w.height = o->canvas_h;
    w.znear = 0.1, w.zfar = 20;
    d->world = w;
    if (o->db) {
        d->db = o->db;
        copy_name(d->db_path, sizeof d->db_path, sp_db_path(o->db));
    } else {
        copy_name(d->db_path, sizeof d->db_path, o->db_path ? o->db_path : sp_db_default_path());
        const char* env = getenv("SP_ASSETS");
        copy_name(d->assets_dir, sizeof d->assets_dir, o->assets_dir ? o->assets_dir : env && *env ? env : "assets");
        if (sp_db_open_or_create_default(d->db_path, d->assets_dir, SP_DB_READONLY, &d->db, err) != SP_OK) {
            free(d);
            return NULL;
        }
        file_id(d->db_path, &d->dev, &d->ino);
        d->own_db = true;
    }
    o->db = NULL, o->db_path = NULL, o->assets_dir = NULL; // not kept: the caller's strings
    d->gen = sp_db_generation(d->db);
    sp_error merr = {0};
    if (sp_db_load_model(d->db, &d->clf, NULL, &merr) != SP_OK) d->clf = NULL; // strokes then need a forced category
    return d;
}

void sp_dragon_destroy(sp_dragon* d)
{
    if (!d) return;
    sp_dragon_clear(d);
    free(d->parts);
    cache_clear(d);
    sp_clf_free(d->clf);
    if (d->own_db) sp_db_close(d->db);
    free(d);
}

// Takes the newest model of the (re)opened database; keeps the old one when it cannot be read.
static void reload_model(sp_dragon* d)
{
    sp_clf* clf = NULL;
    sp_error merr = {0};
    sp_result r = sp_db_load_model(d->db, &clf, NULL, &merr);
    if (r == SP_OK || r == SP_ERR_INVALID) {
        // SP_ERR_INVALID: no model stored (strokes then need a forced category).
        sp_clf_free(d->clf);
        d->clf = r == SP_OK ? clf : NULL;
    }
}

sp_result sp_dragon_reload_if_changed(sp_dragon* d, bool* reloaded, sp_error* err)
{
    if (reloaded) *reloaded = false;
    if (d->own_db) {
        // A database replaced on disk (a new file renamed over it) is a new
        // inode: the open connection still reads the old one. A deleted file
        // keeps being read through the open connection until a new one appears.
        dev_t dev;
        ino_t ino;
        bool replaced = d->db && file_id(d->db_path, &dev, &ino) && (dev != d->dev || ino != d->ino);
        if (replaced || !d->db) {
            if (d->db) sp_db_close(d->db); // first: then nothing of ours holds the old file's sidecars
            if (replaced) drop_stale_sidecars(d->db_path);
            d->db = NULL;
            if (open_own(d, err) != SP_OK) return SP_ERR_IO; // parts already loaded and the model stay usable
            reload_model(d);
            d->gen = sp_db_generation(d->db);
            cache_prune(d);
            if (reloaded) *reloaded = true;
            return SP_OK;
        }
    }
    uint64_t g = sp_db_generation(d->db);
    if (g == 0) return sp_fail(err, SP_ERR_IO, "%s: the database cannot be read", d->db_path);
    if (g == d->gen) return SP_OK;
    reload_model(d);
    d->gen = g;
    cache_prune(d);
    if (reloaded) *reloaded = true;
    return SP_OK;
}

const sp_clf* sp_dragon_model(const sp_dragon* d)
{
    return d->clf;
}

int sp_dragon_part_count(const sp_dragon* d)
{
    return d->part_n;
}

const sp_dragon_part* sp_dragon_part_get(const sp_dragon* d, int i)
{
    return i >= 0 && i < d->part_n ? &d->parts[i]->pub : NULL;
}

sp_camera sp_dragon_camera(const sp_dragon* d)
{
    return d->world;
}

double sp_dragon_period(const sp_dragon* d)
{
    return d->period;
}

// The templates of a category (loaded and cached), up to max_variants.
static int category_templates(sp_dragon* d, const char* category, tpl** out, int cap, sp_error* err)
{
    char** names = NULL;
    int n = 0, got = 0;
    if (!d->db) {
        // The database is gone for now: the parts already loaded still serve.
        for (int k = 0; k < d->cache_n && got < cap; ++k)
            if (!strcmp(d->cache[k]->category, category)) out[got++] = d->cache[k];
        return got;
    }
    if (sp_db_category_parts(d->db, category, &names, &n, err) != SP_OK) return 0;
    for (int i = 0; i < n && got < cap; ++i) {
        tpl* t = NULL;
        for (int k = 0; k < d->cache_n && !t; ++k)
            if (!strcmp(d->cache[k]->name, names[i])) t = d->cache[k];
        if (!t) {
            t = tpl_load(d->db, names[i], d->desc.canvas_w, d->desc.canvas_h, &d->desc.solve, err);
            if (!t) continue; // a part that does not load is skipped; err keeps why
            tpl** c = realloc(d->cache, sizeof(tpl*) * (size_t)(d->cache_n + 1));
            if (!c) {
                tpl_release(t);
                continue;
            }
            d->cache = c;
            d->cache[d->cache_n++] = t;
        }
        out[got++] = t;
    }
    sp_db_free_strings(names, n);
    return got;
}

sp_result sp_dragon_preload(sp_dragon* d, sp_error* err)
{
    if (!d->db) return SP_OK;
    char** cats = NULL;
    int n = 0;
    sp_result r = sp_db_categories(d->db, &cats, &n, err);
    if (r != SP_OK) return r;
    for (int i = 0; i < n; ++i) {
        tpl* got[16];
        category_templates(d, cats[i], got, d->desc.max_variants < 16 ? d->desc.max_variants : 16, err);
    }
    sp_db_free_strings(cats, n);
    return SP_OK;
}

// World point of a joint-local offset of part p at its fitted pose.
static sp_vec3 fitted_point(const part* p, const sp_mat4* model_to_world, int joint, sp_vec3 local)
{
    tpl* t = p->t;
    sp_rig_eval_update(t->ev, p->p_fit, false);
    sp_vec3 m = sp_mat4_point(&sp_rig_eval_world(t->ev)[joint], local);
    return sp_mat4_point(model_to_world, m);
}

static bool socket_accepts(const dsocket* s, const char* category, const char* prefer)
{
    if (prefer[0] && !strcmp(s->name, prefer)) return true;
    if (!strcmp(s->name, category)) return true; // sockets named after what they take (assets/)
    if (!s->accepts[0]) return false;
    char key[SP_NAME_MAX + 2];
    snprintf(key, sizeof key, ",%s,", category);
    return strstr(s->accepts, key) != NULL;
}

// Recomputes every attachment and the loop period (after any change).
static void relayout(sp_dragon* d)
{
    double diag = hypot(d->desc.canvas_w, d->desc.canvas_h);
    d->period = 0;
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        p->world_fit = p->pub.placement;
        p->pub.attached_to = -1;
        p->pub.socket[0] = 0;
        p->pub.socket_joint = -1;
        if (p->t->clip) d->period = fmax(d->period, p->t->clip_len);
    }
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        if (p->t->is_torso) continue;
        sp_vec3 a = fitted_point(p, &p->pub.placement, p->t->attach_joint, p->t->attach_local);
        sp_vec2 a2 = sp_camera_project(&d->world, a);
        // Two rounds: sockets that want this part (by category or name), then any socket.
        for (int round = 0; round < 2 && p->pub.attached_to < 0; ++round) {
            double best = INFINITY;
            int bk = -1, bs = -1;
            sp_vec3 bpos = {0, 0, 0};
            for (int k = 0; k < d->part_n; ++k) {
                const part* q = d->parts[k];
                if (k == i || !q->t->is_torso) continue;
                for (int s = 0; s < q->t->socket_count; ++s) {
                    const dsocket* so = &q->t->sockets[s];
                    if (round == 0 && !socket_accepts(so, p->pub.category, p->t->prefer)) continue;
                    sp_vec3 w = fitted_point(q, &q->pub.placement, so->joint, so->local);
                    double dist = sp_v2_len(sp_v2_sub(sp_camera_project(&d->world, w), a2));
                    if (dist < best) best = dist, bk = k, bs = s, bpos = w;
                }
                if (q->t->socket_count == 0 && round == 1) {
                    // A torso without declared sockets: its root joint is the socket.
                    sp_vec3 w = fitted_point(q, &q->pub.placement, q->t->attach_joint, (sp_vec3){0, 0, 0});
                    double dist = sp_v2_len(sp_v2_sub(sp_camera_project(&d->world, w), a2));
                    if (dist < best) best = dist, bk = k, bs = -1, bpos = w;
                }
            }
            if (bk < 0) continue;
            const part* q = d->parts[bk];
            int joint = bs >= 0 ? q->t->sockets[bs].joint : q->t->attach_joint;
            sp_vec3 delta = sp_v3_sub(bpos, a);
            bool snap = d->desc.snap_fraction > 0 && best <= d->desc.snap_fraction * diag;
            if (!snap) delta.x = delta.y = 0;
            sp_mat4 tr = mat_translate(delta);
            p->world_fit = sp_mat4_mul(&tr, &p->pub.placement);
            sp_rig_eval_update(q->t->ev, q->p_fit, false);
            sp_mat4 f0 = sp_mat4_mul(&q->pub.placement, &sp_rig_eval_world(q->t->ev)[joint]);
            p->socket0 = sim_of(&f0);
            p->pub.attached_to = bk;
            p->pub.socket_joint = joint;
            copy_name(p->pub.socket, sizeof p->pub.socket, bs >= 0 ? q->t->sockets[bs].name : q->t->ch.rig.joints[joint].name);
        }
    }
    d->posed = false;
}

// Cleans a stroke: clamps onto the canvas, drops repeated points, resamples
// very long strokes. *out malloc'd. Returns the point count (0 on no memory).
static int clean_stroke(const sp_dragon* d, const sp_vec2* xy, int n, sp_vec2** out)
{
    double W = d->desc.canvas_w, H = d->desc.canvas_h;
    sp_vec2* tmp = malloc(sizeof(sp_vec2) * (size_t)(n > 0 ? n : 1));
    if (!tmp) return 0;
    for (int i = 0; i < n; ++i)
        tmp[i] = (sp_vec2){fmin(fmax(xy[i].x, 0.0), W), fmin(fmax(xy[i].y, 0.0), H)};
    int m = sp_curve_clean(tmp, n, 0.0, tmp);
    if (m > SP_DRAGON_MAX_STROKE_POINTS) {
        sp_vec2* r = malloc(sizeof(sp_vec2) * SP_DRAGON_MAX_STROKE_POINTS);
        if (!r || sp_curve_resample(tmp, m, false, SP_DRAGON_MAX_STROKE_POINTS, r) != SP_OK) {
            free(r);
            free(tmp);
            return 0;
        }
        free(tmp);
        tmp = r;
        m = SP_DRAGON_MAX_STROKE_POINTS;
    }
    *out = tmp;
    return m;
}

// The part's sketch view zoomed and panned so its rest abstraction covers the stroke's box.
static sp_camera zoomed_view(const tpl* t, sp_vec2 lo, sp_vec2 hi)
{
    sp_camera c = t->base;
    double ds = sp_v2_len(sp_v2_sub(hi, lo)), dr = sp_v2_len(sp_v2_sub(t->rest_hi, t->rest_lo));
    double f = ds / dr;
    sp_vec2 cs = sp_v2_scale(sp_v2_add(lo, hi), 0.5), cr = sp_v2_scale(sp_v2_add(t->rest_lo, t->rest_hi), 0.5);
    c.scale = t->base.scale * f;
    c.cx = cs.x - f * (cr.x - t->base.cx);
    c.cy = cs.y - f * (cr.y - t->base.cy);
    return c;
}

// Part model space -> world, making the part's view and the world camera agree (dragon.h).
static sp_mat4 placement_of(const sp_dragon* d, const tpl* t, const sp_camera* view)
{
    const sp_camera* w = &d->world;
    double k = view->scale / w->scale;
    sp_mat4 a = sp_mat4_identity();
    a.m[0] = a.m[5] = a.m[10] = k;
    a.m[12] = (view->cx - w->cx) / w->scale;
    a.m[13] = (w->cy - view->cy) / w->scale;
    a.m[14] = -k * t->depth0;
    // World camera coordinates -> world (its view is a translation).
    sp_mat4 winv;
    sp_mat4_inverse(&w->view, &winv);
    sp_mat4 m = sp_mat4_mul(&a, &view->view);
    m = sp_mat4_mul(&winv, &m);
    return sim_mat(sim_of(&m));
}

static sp_result new_part(sp_dragon* d, tpl* t, const double* p, const sp_solve_report* rep, const sp_camera* view,
                          const sp_vec2* xy, int n, float confidence, part** out, sp_error* err)
{
    const sp_rig* rig = &t->ch.rig;
    part* q = calloc(1, sizeof *q);
    if (!q) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    size_t P = (size_t)rig->param_count + 1;
    q->p_fit = malloc(sizeof(double) * P);
    q->p_t = malloc(sizeof(double) * P);
    q->xyz = malloc(sizeof(double) * 3 * ((size_t)rig->vertex_count + 1));
    q->outline = malloc(sizeof(double) * 3 * ((size_t)rig->abstractions[t->abstraction].point_count + 1));
    q->stroke = malloc(sizeof(sp_vec2) * (size_t)(n > 0 ? n : 1));
    q->ev = sp_rig_eval_create(rig);
    if (!q->p_fit || !q->p_t || !q->xyz || !q->outline || !q->stroke || !q->ev) {
        q->t = NULL;
        part_free(q);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    memcpy(q->p_fit, p, sizeof(double) * (size_t)rig->param_count);
    memcpy(q->stroke, xy, sizeof(sp_vec2) * (size_t)n);
    q->stroke_n = n;
    q->t = t;
    ++t->refs;
    sp_dragon_part* pub = &q->pub;
    pub->id = d->next_id++;
    copy_name(pub->name, sizeof pub->name, t->name);
    copy_name(pub->category, sizeof pub->category, t->category);
    pub->confidence = confidence;
    pub->character = &t->ch;
    pub->abstraction = t->abstraction;
    pub->params = q->p_fit;
    pub->report = *rep;
    pub->view = *view;
    pub->placement = placement_of(d, t, view);
    pub->is_torso = t->is_torso;
    pub->attached_to = -1;
    pub->socket_joint = -1;
    pub->stroke_points = n;
    pub->stroke_xy = q->stroke;
    *out = q;
    return SP_OK;
}

static void fill_guesses(const sp_clf* clf, const sp_clf_answer* a, sp_dragon_result* out)
{
    out->guess_count = 0;
    for (int i = 0; i < a->count && out->guess_count < SP_DRAGON_GUESSES; ++i) {
        sp_dragon_guess* g = &out->guesses[out->guess_count++];
        copy_name(g->category, sizeof g->category, sp_clf_category(clf, a->ranked[i].category));
        g->confidence = a->ranked[i].score;
    }
}

// The kiosk's refusal policy (docs/DESIGN.md, "Refusal policy"): a stroke
// that looks anything like a part becomes the best guess; refused are only
// scribbles (checked before the fit, `fit` < 0) and strokes far from every
// part, where "far" weighs the classifier's nearest-drawing distance (in
// units of the model's calibrated reject distance) together with how badly
// the best guess's part takes the stroke (`fit`: the fit's mean error over
// the stroke's diagonal). Taps and tiny strokes never get here.
// Constants tuned on the tune half of tests/data/visitors (BENCHMARKS.md,
// "Visitors' drawings").
static bool kiosk_refuses(const sp_vec2* pts, int n, const sp_clf_answer* a, double fit)
{
    if (fit < 0) {
        // A scribble: far more ink than its size, or crossing itself over and over.
        enum { M = 64 };
        sp_vec2 r[M], lo = pts[0], hi = pts[0];
#define CROSS(a, b) ((a).x * (b).y - (a).y * (b).x)
        for (int i = 1; i < n; ++i)
            lo.x = fmin(lo.x, pts[i].x), lo.y = fmin(lo.y, pts[i].y), hi.x = fmax(hi.x, pts[i].x), hi.y = fmax(hi.y, pts[i].y);
        double diag = sp_v2_len(sp_v2_sub(hi, lo));
        if (sp_curve_length(pts, n, false) > 6.0 * diag) return true;
        if (sp_curve_resample(pts, n, false, M, r) != SP_OK) return false;
        int crossings = 0;
        for (int i = 0; i + 1 < M; ++i)
            for (int j = i + 2; j + 1 < M; ++j) {
                sp_vec2 p = r[i], q = r[i + 1], u = r[j], v = r[j + 1];
                double d1 = CROSS(sp_v2_sub(q, p), sp_v2_sub(u, p)), d2 = CROSS(sp_v2_sub(q, p), sp_v2_sub(v, p));
                double d3 = CROSS(sp_v2_sub(v, u), sp_v2_sub(p, u)), d4 = CROSS(sp_v2_sub(v, u), sp_v2_sub(q, u));
                crossings += d1 * d2 < 0 && d3 * d4 < 0;
            }
#undef CROSS
        return crossings > 12;
    }
    double near = isfinite(a->reject_distance) && a->reject_distance > 0 ? a->distance / a->reject_distance : 0.0;
    return near + 8.0 * fit > 1.37;
}

static sp_result reject(sp_dragon_result* out, sp_dragon_reject why, double t0)
{
    out->rejected = true;
    out->reason = why;
    out->part = -1;
    out->ms_total = now_ms() - t0;
    return SP_OK;
}

sp_result sp_dragon_add_points(sp_dragon* d, const sp_vec2* xy, int count, const sp_dragon_stroke_opts* opts,
                               sp_dragon_result* out, sp_error* err)
{
    double t0 = now_ms();
    memset(out, 0, sizeof *out);
    out->part = -1;
    sp_dragon_stroke_opts o = opts ? *opts : (sp_dragon_stroke_opts){0};
    if (count < 0 || (count > 0 && !xy)) return sp_fail(err, SP_ERR_INVALID, "stroke: %d points", count);
    if (count > 0 && !sp_curve_is_valid(xy, count))
        return sp_fail(err, SP_ERR_INVALID, "stroke: a coordinate is not a finite number");
    sp_error rerr = {0};
    sp_dragon_reload_if_changed(d, NULL, &rerr); // a failed poll keeps the current model: the kiosk goes on
    if (count < 2) return reject(out, SP_DRAGON_TOO_SHORT, t0);
    if (!(o.replace_last && d->part_n > 0) && d->part_n >= d->desc.max_parts) return reject(out, SP_DRAGON_FULL, t0);
    sp_vec2* pts = NULL;
    int n = clean_stroke(d, xy, count, &pts);
    if (n == 0) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sp_vec2 lo = pts[0], hi = pts[0];
    for (int i = 1; i < n; ++i)
        lo.x = fmin(lo.x, pts[i].x), lo.y = fmin(lo.y, pts[i].y), hi.x = fmax(hi.x, pts[i].x), hi.y = fmax(hi.y, pts[i].y);
    if (n < 2 || sp_v2_len(sp_v2_sub(hi, lo)) < 0.01 * hypot(d->desc.canvas_w, d->desc.canvas_h)) {
        free(pts);
        return reject(out, SP_DRAGON_TOO_SHORT, t0);
    }
    sp_sketch sk = {.canvas_w = d->desc.canvas_w,
                    .canvas_h = d->desc.canvas_h,
                    .stroke_count = 1,
                    .strokes = &(sp_stroke){.count = n, .points = pts}};
    // Classify (also when forced: the chips still show the classifier's guesses).
    char category[SP_NAME_MAX] = "";
    float confidence = 1.0f;
    sp_clf_answer a = {0};
    if (d->clf) {
        sp_error cerr = {0};
        double tc = now_ms();
        if (sp_clf_classify(d->clf, &sk, NULL, &a, &cerr) == SP_OK) {
            fill_guesses(d->clf, &a, out);
            if (!o.category) {
                if (a.count == 0 || a.ranked[0].score < d->desc.min_confidence || kiosk_refuses(pts, n, &a, -1.0)) {
                    free(pts);
                    out->ms_classify = now_ms() - tc;
                    return reject(out, SP_DRAGON_UNRECOGNISED, t0);
                }
                copy_name(category, sizeof category, sp_clf_category(d->clf, a.ranked[0].category));
                confidence = a.ranked[0].score;
            }
        } else if (!o.category) {
            free(pts);
            return reject(out, SP_DRAGON_UNRECOGNISED, t0);
        }
        out->ms_classify = now_ms() - tc;
    } else if (!o.category) {
        free(pts);
        return reject(out, SP_DRAGON_NO_MODEL, t0);
    }
    if (o.category) copy_name(category, sizeof category, o.category);
    // Fit every variant of the category; keep the one that matches best.
    double tf = now_ms();
    tpl* cands[16];
    int cap = d->desc.max_variants < 16 ? d->desc.max_variants : 16;
    sp_error lerr = {0};
    int nc = category_templates(d, category, cands, cap, &lerr);
    if (nc == 0) {
        free(pts);
        return reject(out, SP_DRAGON_NO_PART, t0);
    }
    int best = -1;
    double best_score = INFINITY;
    double* best_p = NULL;
    sp_solve_report best_rep;
    sp_camera best_view = {0};
    for (int c = 0; c < nc; ++c) {
        tpl* t = cands[c];
        const sp_rig* rig = &t->ch.rig;
        double* p = malloc(sizeof(double) * ((size_t)rig->param_count + 1));
        if (!p) continue;
        memcpy(p, t->ch.pose, sizeof(double) * (size_t)rig->param_count);
        t->solver_cam = zoomed_view(t, lo, hi);
        sp_solve_report rep;
        sp_error serr = {0};
        if (sp_solver_solve(t->solver, &sk, p, p, &rep, &serr) != SP_OK) {
            free(p);
            continue;
        }
        double score = rep.mean_error_px / fmax(rep.bbox_diagonal_px, 1.0);
        if (!isfinite(score)) score = 1e300;
        if (best < 0 || score < best_score) {
            free(best_p);
            best = c, best_score = score, best_p = p, best_rep = rep, best_view = t->solver_cam;
        } else {
            free(p);
        }
    }
    out->ms_fit = now_ms() - tf;
    if (best < 0) {
        free(pts);
        return reject(out, SP_DRAGON_FIT_FAILED, t0);
    }
    if (!o.category && d->clf && kiosk_refuses(pts, n, &a, best_score)) {
        free(pts);
        free(best_p);
        return reject(out, SP_DRAGON_UNRECOGNISED, t0);
    }
    part* q = NULL;
    sp_result r = new_part(d, cands[best], best_p, &best_rep, &best_view, pts, n, confidence, &q, err);
    free(best_p);
    free(pts);
    if (r != SP_OK) return r;
    if (o.replace_last && d->part_n > 0) {
        part_free(d->parts[d->part_n - 1]);
        d->parts[d->part_n - 1] = q;
    } else {
        if (d->part_n == d->part_cap) {
            int cap2 = d->part_cap ? 2 * d->part_cap : 8;
            part** np = realloc(d->parts, sizeof(part*) * (size_t)cap2);
            if (!np) {
                part_free(q);
                return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
            }
            d->parts = np, d->part_cap = cap2;
        }
        d->parts[d->part_n++] = q;
    }
    relayout(d);
    out->part = d->part_n - 1;
    out->rejected = false;
    out->reason = SP_DRAGON_ACCEPTED;
    out->ms_total = now_ms() - t0;
    return SP_OK;
}

sp_result sp_dragon_add_stroke(sp_dragon* d, const sp_stroke* stroke, const sp_dragon_stroke_opts* opts, sp_dragon_result* out,
                               sp_error* err)
{
    return sp_dragon_add_points(d, stroke ? stroke->points : NULL, stroke ? stroke->count : 0, opts, out, err);
}

sp_result sp_dragon_refit_last(sp_dragon* d, const char* category, sp_dragon_result* out, sp_error* err)
{
    if (d->part_n == 0 || !category) {
        memset(out, 0, sizeof *out);
        return reject(out, SP_DRAGON_NOTHING_TO_REFIT, now_ms());
    }
    part* last = d->parts[d->part_n - 1];
    // A copy: the part (and its stroke) is freed when replaced.
    int n = last->stroke_n;
    sp_vec2* xy = malloc(sizeof(sp_vec2) * (size_t)n);
    if (!xy) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    memcpy(xy, last->stroke, sizeof(sp_vec2) * (size_t)n);
    sp_result r = sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = category, .replace_last = true}, out, err);
    free(xy);
    return r;
}

bool sp_dragon_undo(sp_dragon* d)
{
    if (d->part_n == 0) return false;
    part_free(d->parts[--d->part_n]);
    relayout(d);
    return true;
}

void sp_dragon_clear(sp_dragon* d)
{
    while (d->part_n > 0)
        part_free(d->parts[--d->part_n]);
    relayout(d);
}

// ---- animation -------------------------------------------------------------------

// Part p's parameters at dragon time t (see dragon.h: clip offsets on the fit).
static void animated_params(const sp_dragon* d, part* p, double t, double* out)
{
    tpl* tp = p->t;
    const sp_rig* rig = &tp->ch.rig;
    memcpy(out, p->p_fit, sizeof(double) * (size_t)rig->param_count);
    if (!tp->clip || !(d->period > 0)) return;
    double n = fmax(1.0, round(d->period / tp->clip_len));
    double per = d->period / n;
    double ph = fmod(t, per);
    if (ph < 0) ph += per;
    if (!(ph == ph)) ph = 0;
    double tc = tp->clip_start + ph / per * tp->clip_len;
    clip_params(tp, tc, tp->scratch_p);
    for (int k = 0; k < rig->param_count; ++k) {
        if (sp_channel_is_scale(rig->params[k].channel))
            out[k] *= tp->clip0[k] > 0 ? tp->scratch_p[k] / tp->clip0[k] : 1.0;
        else
            out[k] += tp->scratch_p[k] - tp->clip0[k];
    }
    sp_rig_clamp(rig, out);
}

// The world transform of part i at its current p_t (torsos must be evaluated first).
static sp_mat4 part_world_at(const sp_dragon* d, const part* p)
{
    if (p->pub.attached_to < 0) return p->world_fit;
    const part* q = d->parts[p->pub.attached_to];
    sp_mat4 f = sp_mat4_mul(&q->pub.placement, &sp_rig_eval_world(q->ev)[p->pub.socket_joint]);
    sp_mat4 ft = sim_mat(sim_of(&f)), f0 = sim_mat(p->socket0), f0inv;
    sp_mat4_inverse(&f0, &f0inv);
    sp_mat4 rel = sp_mat4_mul(&ft, &f0inv);
    return sp_mat4_mul(&rel, &p->world_fit);
}

sp_result sp_dragon_pose_at(sp_dragon* d, double t, sp_error* err)
{
    (void)err;
    if (!isfinite(t)) t = 0;
    // Pass 0: parts that carry others (torsos) and free parts; pass 1: attached parts.
    for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < d->part_n; ++i) {
            part* p = d->parts[i];
            if ((p->pub.attached_to >= 0) != (pass == 1)) continue;
            const sp_rig* rig = &p->t->ch.rig;
            animated_params(d, p, t, p->p_t);
            sp_rig_eval_update(p->ev, p->p_t, false);
            sp_rig_eval_points(p->ev, sp_rig_mesh_points(rig), p->xyz);
            sp_rig_eval_abstraction(p->ev, &rig->abstractions[p->t->abstraction], p->xyz, p->outline);
            p->world_t = part_world_at(d, p);
        }
    for (int i = 0; i < d->part_n; ++i) {
        part* p = d->parts[i];
        transform_points(&p->world_t, p->xyz, p->t->ch.rig.vertex_count);
        transform_points(&p->world_t, p->outline, p->t->ch.rig.abstractions[p->t->abstraction].point_count);
    }
    d->posed = true;
    return SP_OK;
}

const double* sp_dragon_part_xyz(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? d->parts[i]->xyz : NULL;
}

const double* sp_dragon_part_outline(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? d->parts[i]->outline : NULL;
}

int sp_dragon_part_fitted_outline(const sp_dragon* d, int i, sp_vec2* xy)
{
    if (i < 0 || i >= d->part_n) return 0;
    const part* p = d->parts[i];
    const sp_rig* rig = &p->t->ch.rig;
    const sp_abstraction* ab = &rig->abstractions[p->t->abstraction];
    if (!xy) return ab->point_count;
    // In the part's own zoomed view, at the fit: exactly what the solver matched.
    double* tmp = malloc(sizeof(double) * 2 * ((size_t)ab->point_count + 1));
    if (!tmp || sp_abstraction_project(rig, p->t->abstraction, &p->pub.view, p->p_fit, tmp) != SP_OK) {
        free(tmp);
        return 0;
    }
    for (int k = 0; k < ab->point_count; ++k)
        xy[k] = (sp_vec2){tmp[2 * k], tmp[2 * k + 1]};
    free(tmp);
    return ab->point_count;
}

const double* sp_dragon_part_params(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? d->parts[i]->p_t : NULL;
}

const sp_mat4* sp_dragon_part_transform(const sp_dragon* d, int i)
{
    return d->posed && i >= 0 && i < d->part_n ? &d->parts[i]->world_t : NULL;
}

bool sp_dragon_bounds(const sp_dragon* d, sp_vec3* lo, sp_vec3* hi)
{
    bool any = false;
    for (int i = 0; d->posed && i < d->part_n; ++i) {
        const part* p = d->parts[i];
        int n = p->t->ch.rig.vertex_count;
        if (n <= 0) continue;
        sp_vec3 a, b;
        sp_bounds(p->xyz, n, &a, &b);
        if (!any) *lo = a, *hi = b;
        lo->x = fmin(lo->x, a.x), lo->y = fmin(lo->y, a.y), lo->z = fmin(lo->z, a.z);
        hi->x = fmax(hi->x, b.x), hi->y = fmax(hi->y, b.y), hi->z = fmax(hi->z, b.z);
        any = true;
    }
    return any;
}

// ---- report ----------------------------------------------------------------------

struct cJSON* sp_dragon_report_json(const sp_dragon* d)
{
    cJSON* o = cJSON_CreateObject();
    double ms = 0, eb = 0, ea = 0, mean = 0, mx = 0;
    int it = 0, rounds = 0, unused = 0;
    const char* stopped = "converged";
    sp_vec2 lo = {0, 0}, hi = {0, 0};
    char note[1024] = "";
    cJSON* curves = cJSON_CreateArray();
    cJSON* params = cJSON_CreateObject();
    cJSON* parts = cJSON_CreateArray();
    for (int i = 0; i < d->part_n; ++i) {
        const part* p = d->parts[i];
        const sp_solve_report* r = &p->pub.report;
        const sp_rig* rig = &p->t->ch.rig;
        const sp_abstraction* ab = &rig->abstractions[p->t->abstraction];
        ms += r->ms, it += r->iterations, rounds += r->icp_rounds, eb += r->before.total, ea += r->after.total;
        mean += r->mean_error_px / d->part_n, mx = fmax(mx, r->max_error_px), unused += r->unused_strokes;
        if (r->stopped != SP_STOP_CONVERGED && !strcmp(stopped, "converged")) stopped = sp_stop_reason_name(r->stopped);
        if (r->note[0]) {
            size_t l = strlen(note);
            snprintf(note + l, sizeof note - l, "%spart %d (%s): %s", l ? "; " : "", i, p->pub.category, r->note);
        }
        for (int k = 0; k < p->stroke_n; ++k) {
            sp_vec2 s = p->stroke[k];
            if (i == 0 && k == 0) lo = hi = s;
            lo.x = fmin(lo.x, s.x), lo.y = fmin(lo.y, s.y), hi.x = fmax(hi.x, s.x), hi.y = fmax(hi.y, s.y);
        }
        for (int c = 0; c < r->curve_count; ++c) {
            cJSON* cv = cJSON_CreateObject();
            cJSON_AddNumberToObject(cv, "part", i);
            cJSON_AddStringToObject(cv, "curve", c < ab->curve_count ? ab->curves[c].name : "");
            // One stroke per part, in order: the part's stroke is stroke i of the file.
            if (r->curves[c].stroke >= 0)
                cJSON_AddNumberToObject(cv, "stroke", i);
            else
                cJSON_AddNullToObject(cv, "stroke");
            cJSON_AddBoolToObject(cv, "reversed", r->curves[c].reversed);
            cJSON_AddNumberToObject(cv, "mean_error_px", r->curves[c].mean_px);
            cJSON_AddNumberToObject(cv, "max_error_px", r->curves[c].max_px);
            cJSON_AddItemToArray(curves, cv);
        }
        for (int k = 0; k < rig->param_count; ++k) {
            char key[3 * SP_NAME_MAX];
            snprintf(key, sizeof key, "%d/%s", i, rig->params[k].name);
            cJSON_AddNumberToObject(params, key, p->p_fit[k]);
        }
        cJSON* pj = cJSON_CreateObject();
        cJSON_AddStringToObject(pj, "category", p->pub.category);
        cJSON_AddNumberToObject(pj, "confidence", p->pub.confidence);
        cJSON_AddStringToObject(pj, "name", p->pub.name);
        if (p->pub.attached_to >= 0) {
            cJSON_AddNumberToObject(pj, "attached_to", p->pub.attached_to);
            cJSON_AddStringToObject(pj, "socket", p->pub.socket);
        } else {
            cJSON_AddNullToObject(pj, "attached_to");
            cJSON_AddNullToObject(pj, "socket");
        }
        cJSON_AddItemToObject(pj, "report", sp_report_to_json(r, rig, ab, p->p_fit));
        cJSON_AddItemToArray(parts, pj);
    }
    cJSON_AddNumberToObject(o, "ms", ms);
    cJSON_AddNumberToObject(o, "iterations", it);
    cJSON_AddNumberToObject(o, "icp_rounds", rounds);
    cJSON_AddStringToObject(o, "stopped", stopped);
    cJSON_AddNumberToObject(o, "energy_before", eb);
    cJSON_AddNumberToObject(o, "energy_after", ea);
    cJSON_AddNumberToObject(o, "mean_error_px", mean);
    cJSON_AddNumberToObject(o, "max_error_px", mx);
    cJSON_AddNumberToObject(o, "bbox_diagonal_px", sp_v2_len(sp_v2_sub(hi, lo)));
    cJSON_AddItemToObject(o, "curves", curves);
    cJSON_AddNumberToObject(o, "unused_strokes", unused);
    cJSON_AddStringToObject(o, "note", note);
    cJSON_AddItemToObject(o, "parameters", params);
    cJSON_AddNumberToObject(o, "period_s", d->period);
    cJSON_AddItemToObject(o, "parts", parts);
    return o;
}

// ---- export ----------------------------------------------------------------------

static void animation_free(sp_animation* a)
{
    for (int c = 0; c < a->channel_count; ++c)
        free(a->channels[c].times), free(a->channels[c].values);
    free(a->channels);
    memset(a, 0, sizeof *a);
}

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

// The export's key times over one period [0, T] (*out malloc'd; returns the
// count, 0 when out of memory): a grid at desc.fps, plus every key of every
// part's clip as retimed into the loop, so that LINEAR keys do not cut the
// corners of the clips' own keys. The last key is T (pose_at wraps it to 0).
static int key_times(const sp_dragon* d, double** out)
{
    double T = d->period;
    int grid = (int)ceil(T * d->desc.fps);
    if (grid < 2) grid = 2;
    size_t cap = (size_t)grid + 1;
    for (int i = 0; i < d->part_n; ++i) {
        const tpl* t = d->parts[i]->t;
        if (!t->clip) continue;
        size_t reps = (size_t)fmax(1.0, round(T / t->clip_len));
        for (int c = 0; c < t->clip->channel_count; ++c)
            cap += reps * (size_t)t->clip->channels[c].key_count;
    }
    double* k = malloc(sizeof(double) * cap);
    if (!k) return 0;
    size_t n = 0;
    for (int g = 0; g <= grid; ++g)
        k[n++] = T * g / grid;
    for (int i = 0; i < d->part_n; ++i) {
        const tpl* t = d->parts[i]->t;
        if (!t->clip) continue;
        double reps = fmax(1.0, round(T / t->clip_len)), per = T / reps;
        for (int r = 0; r < (int)reps; ++r)
            for (int c = 0; c < t->clip->channel_count; ++c)
                for (int q = 0; q < t->clip->channels[c].key_count; ++q) {
                    double u = (t->clip->channels[c].times[q] - t->clip_start) / t->clip_len;
                    if (u > 0 && u < 1) k[n++] = (r + u) * per;
                }
    }
    qsort(k, n, sizeof *k, cmp_double);
    // Keys closer than a millisecond are one key (float times must increase).
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        if (m == 0 || k[i] - k[m - 1] > 1e-3) k[m++] = k[i];
    k[m - 1] = T;
    *out = k;
    return (int)m;
}

sp_result sp_dragon_export(const sp_dragon* dc, const char* path, sp_error* err)
{
    // Why the cast: posing at the key times reuses the parts' evaluation
    // buffers; the visible state is restored at the end (posed = false).
    sp_dragon* d = (sp_dragon*)dc;
    if (d->part_n == 0) return sp_fail(err, SP_ERR_INVALID, "%s: the dragon has no parts to export", path);
    int n = d->part_n;
    bool animated = d->period > 0;
    // Keys: K intervals over one period; the last key repeats the first, so the loop closes.
    double* times = NULL;
    int K = animated ? key_times(d, &times) - 1 : 0;
    if (animated && K < 1) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    sp_result res = SP_OK;
    sp_gltf_scene_part* parts = calloc((size_t)n, sizeof *parts);
    sp_animation* anims = calloc((size_t)n, sizeof *anims);
    double** keys = calloc((size_t)n, sizeof *keys);
    float* place_trs = animated ? malloc(sizeof(float) * 8 * (size_t)n * (size_t)(K + 1)) : NULL;
    float* ftimes = animated ? malloc(sizeof(float) * (size_t)(K + 1)) : NULL;
    char(*names)[SP_NAME_MAX + 16] = calloc((size_t)n, sizeof *names);
    if (!parts || !anims || !keys || !names || (animated && (!place_trs || !ftimes || !times))) {
        res = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
        goto done;
    }
    for (int i = 0; i < n; ++i) {
        const part* p = d->parts[i];
        snprintf(names[i], sizeof names[i], "%02d_%s", i, p->pub.category);
        parts[i] = (sp_gltf_scene_part){.character = &p->t->ch, .params = p->p_fit, .name = names[i], .placement = p->world_fit};
        if (animated) {
            keys[i] = malloc(sizeof(double) * ((size_t)p->t->ch.rig.param_count + 1) * (size_t)(K + 1));
            if (!keys[i]) {
                res = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
                goto done;
            }
        }
    }
    if (animated) {
        for (int k = 0; k <= K; ++k) {
            ftimes[k] = (float)times[k];
            sp_dragon_pose_at(d, times[k], err);
            for (int i = 0; i < n; ++i) {
                const part* p = d->parts[i];
                size_t P = (size_t)p->t->ch.rig.param_count;
                memcpy(keys[i] + P * (size_t)k, p->p_t, sizeof(double) * P);
                sim3 s = sim_of(&p->world_t);
                float* v = place_trs + 8 * ((size_t)i * (size_t)(K + 1) + (size_t)k);
                v[0] = (float)s.t.x, v[1] = (float)s.t.y, v[2] = (float)s.t.z;
                v[3] = (float)s.r.x, v[4] = (float)s.r.y, v[5] = (float)s.r.z, v[6] = (float)s.r.w;
                v[7] = (float)s.s;
                // Keep neighbouring keys on the same hemisphere so slerp takes the short way.
                if (k > 0 && v[3] * v[-5] + v[4] * v[-4] + v[5] * v[-3] + v[6] * v[-2] < 0)
                    v[3] = -v[3], v[4] = -v[4], v[5] = -v[5], v[6] = -v[6];
            }
        }
        for (int i = 0; i < n; ++i) {
            const part* p = d->parts[i];
            if (p->t->clip && p->t->ch.rig.param_count > 0) {
                res = sp_animation_from_keys(&p->t->ch.rig, keys[i], times, K + 1, "dragon", &anims[i], err);
                if (res != SP_OK) goto done;
                parts[i].animation = &anims[i];
            }
            if (p->pub.attached_to >= 0 && d->parts[p->pub.attached_to]->t->clip) {
                parts[i].placement_key_count = K + 1;
                parts[i].placement_times = ftimes;
                parts[i].placement_trs = place_trs + 8 * (size_t)i * (size_t)(K + 1);
            }
        }
    }
    {
        // The scene's extras say what the parts are (for people and tests reading the file).
        cJSON* ex = cJSON_CreateObject();
        cJSON* dj = cJSON_AddObjectToObject(ex, "sp_dragon");
        cJSON* canvas = cJSON_AddArrayToObject(dj, "canvas");
        cJSON_AddItemToArray(canvas, cJSON_CreateNumber(d->desc.canvas_w));
        cJSON_AddItemToArray(canvas, cJSON_CreateNumber(d->desc.canvas_h));
        cJSON_AddNumberToObject(dj, "period_s", d->period);
        cJSON* pj = cJSON_AddArrayToObject(dj, "parts");
        for (int i = 0; i < n; ++i) {
            const part* p = d->parts[i];
            cJSON* o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "node", names[i]);
            cJSON_AddStringToObject(o, "name", p->pub.name);
            cJSON_AddStringToObject(o, "category", p->pub.category);
            if (p->pub.attached_to >= 0) {
                cJSON_AddNumberToObject(o, "attached_to", p->pub.attached_to);
                cJSON_AddStringToObject(o, "socket", p->pub.socket);
            }
            cJSON_AddItemToArray(pj, o);
        }
        char* text = cJSON_PrintUnformatted(ex);
        cJSON_Delete(ex);
        if (!text) {
            res = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
            goto done;
        }
        sp_gltf_scene_desc sd = {.part_count = n, .parts = parts, .animation_name = "dragon", .extras_json = text};
        res = sp_gltf_save_scene(&sd, path, err);
        free(text);
    }
done:
    for (int i = 0; i < n; ++i) {
        if (anims) animation_free(&anims[i]);
        if (keys) free(keys[i]);
    }
    free(parts), free(anims), free(keys), free(place_trs), free(ftimes), free(times), free(names);
    d->posed = false;
    return res;
}
