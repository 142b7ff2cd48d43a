#include "fixtures.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cjson/cJSON.h>
#include <sqlite3.h>

#include "sp/classifier.h"
#include "sp/gltf.h"
#include "test.h"

double sp_test_uniform(sp_test_rng* r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

double sp_test_range(sp_test_rng* r, double lo, double hi) { return lo + (hi - lo) * sp_test_uniform(r); }

void sp_fixture_tree_rig(const sp_fixture_desc* d, sp_rig* rig)
{
    int nj = d->joint_count > 0 ? d->joint_count : 4;
    int rings = d->rings_per_bone > 0 ? d->rings_per_bone : 6;
    int rv = d->ring_vertices > 0 ? d->ring_vertices : 12;
    sp_test_rng rng = {d->seed * 7919u + 17u};
    memset(rig, 0, sizeof *rig);
    rig->joint_count = nj;
    rig->joints = calloc((size_t)nj, sizeof(sp_joint));
    sp_mat4* world = malloc(sizeof(sp_mat4) * (size_t)nj);
    for (int j = 0; j < nj; ++j) {
        sp_joint* jt = &rig->joints[j];
        snprintf(jt->name, sizeof jt->name, "j%d", j);
        jt->parent = j == 0 ? -1 : (d->branching ? (int)(sp_test_uniform(&rng) * j * 0.999) : j - 1);
        if (d->branching && j > 1 && sp_test_uniform(&rng) < 0.6) jt->parent = j - 1;
        // Bones point mostly along +Y with a random bend; rest rotations and
        // scales are not identity so that the tests exercise them.
        jt->rest_t = j == 0 ? sp_v3(0.1, 0.2, -0.1) : sp_v3(sp_test_range(&rng, -0.2, 0.2), sp_test_range(&rng, 0.6, 1.0), sp_test_range(&rng, -0.2, 0.2));
        sp_vec3 axis = sp_v3_norm(sp_v3(sp_test_range(&rng, -1, 1), sp_test_range(&rng, -1, 1), sp_test_range(&rng, -1, 1)));
        jt->rest_r = sp_quat_axis_angle(axis, sp_test_range(&rng, -0.4, 0.4));
        jt->rest_s = j == 0 ? sp_v3(1.1, 1.1, 1.1) : sp_v3(sp_test_range(&rng, 0.9, 1.1), sp_test_range(&rng, 0.9, 1.1), sp_test_range(&rng, 0.9, 1.1));
        sp_mat4 local = sp_mat4_trs(jt->rest_t, jt->rest_r, jt->rest_s);
        world[j] = jt->parent < 0 ? local : sp_mat4_mul(&world[jt->parent], &local);
        sp_mat4_inverse(&world[j], &jt->inverse_bind);
    }
    for (int j = 0; j < nj; ++j) {
        for (int c = SP_CH_RX; c <= SP_CH_RZ; ++c) sp_rig_add_param(rig, j, (sp_channel)c, -2.0, 2.0, SP_GROUP_POSE);
        if (j == 0 && d->root_scale) sp_rig_add_param(rig, j, SP_CH_S, 0.5, 2.0, SP_GROUP_SHAPE);
        if (!d->all_channels) continue;
        if (j == 0) {
            for (int c = SP_CH_TX; c <= SP_CH_TZ; ++c) sp_rig_add_param(rig, j, (sp_channel)c, -5.0, 5.0, SP_GROUP_POSE);
            sp_rig_add_param(rig, j, SP_CH_S, 0.25, 4.0, SP_GROUP_SHAPE);
        } else if (j % 2) {
            for (int c = SP_CH_SX; c <= SP_CH_SZ; ++c) sp_rig_add_param(rig, j, (sp_channel)c, 0.5, 2.0, SP_GROUP_SHAPE);
        } else {
            sp_rig_add_param(rig, j, SP_CH_S, 0.5, 2.0, SP_GROUP_SHAPE);
            sp_rig_add_param(rig, j, SP_CH_TY, -0.3, 0.3, SP_GROUP_SHAPE);
        }
    }
    // Mesh: rings along each bone (parent -> child), blended weights.
    int bones = nj - 1 > 0 ? nj - 1 : 1;
    sp_fixture_tube_alloc(rig, bones, rings, rv);
    // Stick abstraction: 8 points per bone, one curve per bone.
    const int per = d->stick_points > 1 ? d->stick_points : 8;
    sp_abstraction ab = {0};
    snprintf(ab.name, sizeof ab.name, "stick");
    ab.correspondence = d->closest ? SP_CORR_CLOSEST : SP_CORR_ORDERED;
    ab.curve_count = bones;
    ab.curves = calloc((size_t)bones, sizeof(sp_curve));
    ab.point_count = bones * per;
    ab.rest = malloc(sizeof(double) * 3 * (size_t)ab.point_count);
    ab.joints = calloc((size_t)ab.point_count * 4, sizeof(uint16_t));
    ab.weights = calloc((size_t)ab.point_count * 4, sizeof(float));
    int v = 0, t = 0;
    for (int b = 0; b < bones; ++b) {
        int child = nj > 1 ? b + 1 : 0, par = nj > 1 ? rig->joints[child].parent : 0;
        sp_vec3 a = sp_mat4_translation(&world[par]), c = sp_mat4_translation(&world[child]);
        if (nj == 1) c = sp_v3_add(a, sp_v3(0, 1, 0));
        sp_vec3 dir = sp_v3_sub(c, a);
        sp_vec3 n1 = sp_v3_norm(sp_v3_cross(dir, fabs(dir.x) < 0.9 * sp_v3_len(dir) ? sp_v3(1, 0, 0) : sp_v3(0, 0, 1)));
        sp_vec3 n2 = sp_v3_norm(sp_v3_cross(dir, n1));
        double radius = 0.12 * sp_v3_len(dir) + 0.03;
        int base = v;
        for (int r = 0; r < rings; ++r) {
            double u = (double)r / (rings - 1);
            sp_vec3 center = sp_v3_add(a, sp_v3_scale(dir, u));
            for (int k = 0; k < rv; ++k) {
                double ang = 2.0 * 3.14159265358979323846 * k / rv;
                sp_vec3 p = sp_v3_add(center, sp_v3_add(sp_v3_scale(n1, radius * cos(ang)), sp_v3_scale(n2, radius * sin(ang))));
                rig->rest[3 * v] = p.x, rig->rest[3 * v + 1] = p.y, rig->rest[3 * v + 2] = p.z;
                rig->joints4[4 * v] = (uint16_t)par, rig->joints4[4 * v + 1] = (uint16_t)child;
                rig->weights4[4 * v] = (float)(1.0 - 0.5 * u), rig->weights4[4 * v + 1] = (float)(0.5 * u);
                ++v;
            }
        }
        sp_fixture_tube_triangles(rig, base, rings, rv, &t);
        snprintf(ab.curves[b].name, sizeof ab.curves[b].name, "bone%d", b);
        ab.curves[b].first_point = b * per;
        ab.curves[b].point_count = per;
        for (int k = 0; k < per; ++k) {
            int i = b * per + k;
            sp_vec3 p = sp_v3_add(a, sp_v3_scale(dir, (double)k / (per - 1)));
            ab.rest[3 * i] = p.x, ab.rest[3 * i + 1] = p.y, ab.rest[3 * i + 2] = p.z;
            ab.joints[4 * i] = (uint16_t)par;
            ab.weights[4 * i] = 1.0f;
        }
    }
    rig->abstraction_count = 1;
    rig->abstractions = malloc(sizeof(sp_abstraction));
    rig->abstractions[0] = ab;
    free(world);
    sp_error err = {0};
    sp_result r = sp_rig_finalize(rig, "fixture", NULL, &err);
    if (r != SP_OK) { // not assert: release builds (NDEBUG) would carry on with a broken rig
        fprintf(stderr, "fixture: %s\n", err.text);
        abort();
    }
}

void sp_fixture_tube_alloc(sp_rig* rig, int bones, int rings, int rv)
{
    int nv = bones * rings * rv;
    rig->vertex_count = nv;
    rig->rest = malloc(sizeof(double) * 3 * (size_t)nv);
    rig->joints4 = calloc((size_t)nv * 4, sizeof(uint16_t));
    rig->weights4 = calloc((size_t)nv * 4, sizeof(float));
    rig->triangle_count = bones * (rings - 1) * rv * 2;
    rig->triangles = malloc(sizeof(uint32_t) * 3 * (size_t)rig->triangle_count);
}

void sp_fixture_tube_triangles(sp_rig* rig, int base, int rings, int rv, int* t)
{
    for (int r = 0; r + 1 < rings; ++r)
        for (int k = 0; k < rv; ++k) {
            uint32_t i0 = (uint32_t)(base + r * rv + k), i1 = (uint32_t)(base + r * rv + (k + 1) % rv);
            uint32_t i2 = i0 + (uint32_t)rv, i3 = i1 + (uint32_t)rv;
            uint32_t* tr = rig->triangles + 3 * *t;
            tr[0] = i0, tr[1] = i1, tr[2] = i3, tr[3] = i0, tr[4] = i3, tr[5] = i2;
            *t += 2;
        }
}

sp_abstraction sp_fixture_outline(int n)
{
    sp_abstraction ab = {0};
    snprintf(ab.name, sizeof ab.name, "outline");
    ab.correspondence = SP_CORR_CLOSEST;
    ab.curve_count = 1;
    ab.curves = calloc(1, sizeof(sp_curve));
    snprintf(ab.curves[0].name, sizeof ab.curves[0].name, "outline");
    ab.curves[0].point_count = n;
    ab.curves[0].closed = true;
    ab.point_count = n;
    ab.rest = calloc((size_t)n * 3, sizeof(double));
    ab.joints = calloc((size_t)n * 4, sizeof(uint16_t));
    ab.weights = calloc((size_t)n * 4, sizeof(float));
    return ab;
}

void sp_fixture_random_params(const sp_rig* rig, sp_test_rng* rng, double amplitude, double* p)
{
    for (int i = 0; i < rig->param_count; ++i) {
        const sp_param* q = &rig->params[i];
        double lo = q->min, hi = q->max;
        if (sp_channel_is_rotation(q->channel)) lo = fmax(lo, q->def - amplitude), hi = fmin(hi, q->def + amplitude);
        p[i] = sp_test_range(rng, lo, hi);
    }
}

void sp_fixture_shared_gltf(const char* rel, sp_character* ch)
{
    const char* data = sp_test_data_dir();
    if (!data) SKIP("../shared/data absent");
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf/%s", data, rel);
    *ch = (sp_character){0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(path, ch, &err) == SP_OK);
}

bool sp_fixture_has_warning(const sp_character* ch, const char* text)
{
    for (int i = 0; i < ch->warning_count; ++i)
        if (strstr(ch->warnings[i], text)) return true;
    return false;
}

bool sp_fixture_bench_quickdraw(const char* prog, sp_dataset* ds)
{
    const char* data = sp_test_data_dir();
    if (!data) {
        fprintf(stderr, "%s: ../shared/data absent (needs quickdraw)\n", prog);
        return false;
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/quickdraw", data);
    sp_error err = {0};
    if (sp_dataset_load(path, ds, &err) != SP_OK) {
        fprintf(stderr, "%s: %s\n", prog, err.text);
        return false;
    }
    return true;
}

cJSON* sp_fixture_glb_json(const char* path)
{
    FILE* f = fopen(path, "rb");
    ENSURE(f);
    unsigned char h[20];
    ENSURE(fread(h, 1, 20, f) == 20);
    ENSURE(!memcmp(h, "glTF", 4));
    uint32_t len = (uint32_t)h[12] | (uint32_t)h[13] << 8 | (uint32_t)h[14] << 16 | (uint32_t)h[15] << 24;
    char* text = malloc(len + 1);
    ENSURE(fread(text, 1, len, f) == len);
    text[len] = 0;
    fclose(f);
    cJSON* j = cJSON_Parse(text);
    free(text);
    ENSURE(j);
    return j;
}

char* sp_fixture_file_text(const char* path, size_t* n)
{
    FILE* f = fopen(path, "rb");
    ENSURE(f);
    ENSURE(fseek(f, 0, SEEK_END) == 0);
    long len = ftell(f);
    ENSURE(len >= 0 && fseek(f, 0, SEEK_SET) == 0);
    char* t = malloc((size_t)len + 1);
    ENSURE(t && fread(t, 1, (size_t)len, f) == (size_t)len);
    fclose(f);
    t[len] = '\0';
    if (n) *n = (size_t)len;
    return t;
}

int sp_fixture_run(const char* cmd, char* out, size_t cap)
{
    FILE* p = popen(cmd, "r");
    ENSURE(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = 0;
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

const char* sp_fixture_node_tools(const char* pkg)
{
    static char dir[1024];
    const char* env = getenv("SP_TEST_TOOLS_DIR");
    snprintf(dir, sizeof dir, "%s", env && *env ? env : SP_SOURCE_DIR "/tests/tools");
    char probe[1200];
    snprintf(probe, sizeof probe, "%s/node_modules/%s", dir, pkg);
    struct stat st;
    bool node = system("command -v node >/dev/null 2>&1") == 0;
    if (node && stat(probe, &st) == 0) return dir;
    const char* req = getenv("SP_TEST_REQUIRE_TOOLS");
    if (req && !strcmp(req, "1")) {
        fprintf(stderr, "  %s is not installed (%s), and SP_TEST_REQUIRE_TOOLS=1: failing, not skipping\n", node ? pkg : "node",
                node ? probe : "not on PATH");
        ENSURE(!"a required test tool is missing");
    }
    return NULL;
}

int sp_fixture_gltf_validate(const char* file)
{
    const char* tools = sp_fixture_node_tools("gltf-validator");
    if (!tools) return -1;
    char cmd[3000];
    const char* rep = sp_test_tmp_path("gltf_validator.json");
    snprintf(cmd, sizeof cmd, "node '%s/validate.js' '%s' > '%s'", tools, file, rep);
    int rc = system(cmd);
    if (rc != 0) {
        snprintf(cmd, sizeof cmd, "cat '%s' >&2", rep);
        if (system(cmd) != 0) fprintf(stderr, "  (no report)\n");
    }
    return rc == 0;
}

int sp_fixture_fork_file_limit(long bytes)
{
    fflush(NULL); // nothing buffered is written twice
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) {
        signal(SIGXFSZ, SIG_IGN);
        struct rlimit rl = {.rlim_cur = (rlim_t)bytes, .rlim_max = RLIM_INFINITY};
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0) _exit(3);
    }
    return (int)pid;
}

int sp_fixture_fork_alarm(unsigned seconds)
{
    fflush(NULL);
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) alarm(seconds);
    return (int)pid;
}

bool sp_fixture_child_passed(int pid)
{
    int status = 0;
    return waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

void sp_fixture_remove_db(const char* path)
{
    char side[1200];
    unlink(path);
    snprintf(side, sizeof side, "%.1100s-wal", path);
    unlink(side);
    snprintf(side, sizeof side, "%.1100s-shm", path);
    unlink(side);
}

// partdb's test hook (db_internal.h): called at named points; "opened":
// SQLite has just opened the database file.
extern void (*sp_db_test_hook)(const char* point);
static char g_rename_from[1024], g_rename_to[1024];

static void rename_at_open(const char* point)
{
    if (strcmp(point, "opened") != 0 || !g_rename_from[0]) return;
    ENSURE(rename(g_rename_from, g_rename_to) == 0);
    g_rename_from[0] = 0;
}

void sp_fixture_rename_when_opened(const char* from, const char* to)
{
    snprintf(g_rename_from, sizeof g_rename_from, "%s", from);
    snprintf(g_rename_to, sizeof g_rename_to, "%s", to);
    sp_db_test_hook = rename_at_open;
}

bool sp_fixture_rename_done(void)
{
    sp_db_test_hook = NULL;
    bool done = !g_rename_from[0];
    g_rename_from[0] = 0;
    return done;
}

cJSON* sp_fixture_json_file(const char* path)
{
    size_t got = 0;
    char* text = sp_fixture_file_text(path, &got);
    ENSURE(got > 0);
    cJSON* j = cJSON_Parse(text);
    free(text);
    ENSURE(j);
    return j;
}

int sp_fixture_session_strokes(const char* path, sp_vec2** xy, int* n, int cap)
{
    cJSON* session = sp_fixture_json_file(path);
    const cJSON* e;
    int strokes = 0;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(session, "events"))
    {
        const cJSON* type = cJSON_GetObjectItemCaseSensitive(e, "type");
        if (!cJSON_IsString(type) || strcmp(type->valuestring, "stroke") != 0 || strokes == cap) continue;
        const cJSON* pts = cJSON_GetObjectItemCaseSensitive(e, "points");
        int m = cJSON_GetArraySize(pts);
        sp_vec2* p = malloc(sizeof(sp_vec2) * (size_t)(m > 0 ? m : 1));
        ENSURE(p && m > 1);
        for (int i = 0; i < m; ++i) {
            const cJSON* pt = cJSON_GetArrayItem(pts, i);
            p[i] = (sp_vec2){cJSON_GetArrayItem(pt, 0)->valuedouble, cJSON_GetArrayItem(pt, 1)->valuedouble};
        }
        xy[strokes] = p, n[strokes++] = m;
    }
    cJSON_Delete(session);
    return strokes;
}

bool sp_fixture_store_model_again(const char* path)
{
    sqlite3* h = NULL;
    int rc = sqlite3_open(path, &h);
    if (rc == SQLITE_OK) {
        sqlite3_busy_timeout(h, 5000);
        rc = sqlite3_exec(h,
                          "INSERT INTO models (created_at, created_by, model, sha256, categories, options, report)"
                          " SELECT created_at, created_by, model, sha256, categories, options, report FROM models"
                          " ORDER BY id DESC LIMIT 1",
                          NULL, NULL, NULL);
    }
    if (rc != SQLITE_OK) fprintf(stderr, "  %s: %s\n", path, sqlite3_errmsg(h));
    sqlite3_close(h);
    return rc == SQLITE_OK;
}

bool sp_fixture_db_downgrade(const char* path, int version)
{
    sqlite3* h = NULL;
    int rc = version == 1 || version == 2 ? sqlite3_open(path, &h) : SQLITE_MISUSE;
    // The version-3 trigger reads the status column: it goes first.
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(h,
                          "DROP TRIGGER gen_sketches_ins; DROP INDEX sketches_review; ALTER TABLE sketches DROP COLUMN status;"
                          "CREATE TRIGGER gen_sketches_ins AFTER INSERT ON sketches BEGIN UPDATE meta SET value = value + 1 "
                          "WHERE key = 'generation'; END; PRAGMA user_version = 2",
                          NULL, NULL, NULL);
    if (rc == SQLITE_OK && version == 1)
        rc = sqlite3_exec(
            h,
            "DROP TRIGGER gen_parts_ins; DROP TRIGGER gen_parts_del; DROP TRIGGER gen_sketches_ins;"
            "DROP TRIGGER gen_sketches_del; DROP TRIGGER gen_models_ins; DROP TRIGGER gen_models_del; DROP TABLE meta;"
            "PRAGMA user_version = 1",
            NULL, NULL, NULL);
    if (rc != SQLITE_OK) fprintf(stderr, "  %s: %s\n", path, h ? sqlite3_errmsg(h) : "no such version");
    sqlite3_close(h);
    return rc == SQLITE_OK;
}
