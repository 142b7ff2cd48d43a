// blackbox.c: black-box rigs (sp/blackbox.h): validating a description,
// checked evaluation, the sketch view, synthetic targets, the finite-
// difference Jacobian engine with its thread pool, and the solver's model
// of such a rig (model.h).
#include "sp/blackbox.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "blackbox_internal.h"
#include "model.h"
#include "sp/clock.h"
#include "sp/synth.h"
#include "synth_internal.h"

// Limits that catch garbage counts (a misread struct, an uninitialised
// field) before they become huge allocations. Parameters: the solver's
// normal equations are dense, two P x P matrices (4096: 256 MB); more could
// be loaded but never solved.
enum { BB_MAX_PARAMS = 4096, BB_MAX_VERTICES = 50000000, BB_MAX_POINTS = 10000000 };

// The FD step as a fraction of a parameter's range (see sp_blackbox_fd_step).
#define SP_BB_FD_FRACTION 1e-5

// Well-formed UTF-8 (no overlong forms, surrogates or values past
// U+10FFFF): names go into JSON reports and pose files as they are.
static bool utf8_ok(const unsigned char* s)
{
    while (*s) {
        unsigned c = *s++;
        if (c < 0x80) continue;
        int more = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : c >= 0xC2 ? 1 : -1;
        if (more < 0 || c > 0xF4) return false;
        unsigned v = c & (0x3Fu >> more);
        for (int i = 0; i < more; ++i, ++s) {
            if ((*s & 0xC0) != 0x80) return false;
            v = (v << 6) | (*s & 0x3Fu);
        }
        if ((more == 2 && (v < 0x800 || (v >= 0xD800 && v <= 0xDFFF))) || (more == 3 && (v < 0x10000 || v > 0x10FFFF)))
            return false;
    }
    return true;
}

// What is wrong with a name, in `buf`, or NULL.
static const char* name_problem(const char* s, size_t max, char* buf, size_t size)
{
    if (!s || !s[0]) return "has no name";
    if (strlen(s) > max) {
        snprintf(buf, size, "has a name longer than %zu bytes", max);
        return buf;
    }
    return utf8_ok((const unsigned char*)s) ? NULL : "has a name that is not UTF-8";
}

static bool all_finite(const double* v, size_t n, size_t* bad)
{
    // x * 0 is 0 for a finite x and NaN otherwise: four independent sums
    // check a rig's whole output in a fraction of an evaluation; the slow
    // search for the index runs only when one is bad.
    double acc[4] = {0, 0, 0, 0};
    size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k)
            acc[k] += v[i + k] * 0.0;
    for (; i < n; ++i)
        acc[0] += v[i] * 0.0;
    if (acc[0] + acc[1] + acc[2] + acc[3] == 0.0) return true;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) break;
    if (bad) *bad = i < n ? i : 0;
    return false;
}

// ---------------------------------------------------------------- open

static sp_result validate(const sp_blackbox_rig* r, const char* what, sp_error* err)
{
    if (!r->evaluate) return sp_fail(err, SP_ERR_INVALID, "%s: the rig has no evaluate function", what);
    if (r->param_count < 1 || r->param_count > BB_MAX_PARAMS || !r->params)
        return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: %d parameters (1..%d)%s", what, (int)r->param_count,
                       BB_MAX_PARAMS, r->params ? "" : ", params is NULL");
    for (int i = 0; i < r->param_count; ++i) {
        const sp_blackbox_param* q = &r->params[i];
        char why[64];
        const char* bad = name_problem(q->name, 2 * SP_NAME_MAX - 1, why, sizeof why);
        if (bad) return sp_fail(err, SP_ERR_INVALID, "%s: parameter %d %s", what, i, bad);
        for (int j = 0; j < i; ++j)
            if (!strcmp(r->params[j].name, q->name))
                return sp_fail(err, SP_ERR_INVALID, "%s: two parameters are called '%s'", what, q->name);
        if (!isfinite(q->min) || !isfinite(q->max) || !isfinite(q->def) || !(q->min <= q->def && q->def <= q->max))
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: parameter '%s' needs finite bounds with min <= default <= max (has %g <= %g <= %g)", what,
                           q->name, q->min, q->def, q->max);
        // The finite-difference step is a fraction of the range, which must
        // itself be a number (-DBL_MAX..DBL_MAX is not).
        if (!isfinite(q->max - q->min))
            return sp_fail(err, SP_ERR_INVALID, "%s: parameter '%s' has a range max - min too large to be a number (%g..%g)",
                           what, q->name, q->min, q->max);
        if (q->group != SP_GROUP_POSE && q->group != SP_GROUP_SHAPE)
            return sp_fail(err, SP_ERR_INVALID, "%s: parameter '%s' has group %d (0 pose, 1 shape)", what, q->name,
                           (int)q->group);
        if (q->unit < SP_BB_UNIT_ANGLE || q->unit > SP_BB_UNIT_WEIGHT)
            return sp_fail(err, SP_ERR_INVALID, "%s: parameter '%s' has unit %d (0 angle, 1 length, 2 factor, 3 weight)", what,
                           q->name, (int)q->unit);
    }
    if (r->vertex_count < 1 || r->vertex_count > BB_MAX_VERTICES || !r->rest)
        return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: %d vertices (1..%d)%s", what, (int)r->vertex_count,
                       BB_MAX_VERTICES, r->rest ? "" : ", rest is NULL");
    size_t bad = 0;
    if (!all_finite(r->rest, 3 * (size_t)r->vertex_count, &bad))
        return sp_fail(err, SP_ERR_INVALID, "%s: rest vertex %zu is not finite", what, bad / 3);
    if (r->triangle_count < 0 || (r->triangle_count > 0 && !r->triangles))
        return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: %d triangles%s", what, (int)r->triangle_count,
                       r->triangles ? "" : " (triangles is NULL)");
    for (size_t i = 0; i < 3 * (size_t)r->triangle_count; ++i)
        if (r->triangles[i] >= (uint32_t)r->vertex_count)
            return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: triangle %zu uses vertex %u of %d", what, i / 3,
                           r->triangles[i], (int)r->vertex_count);
    // Colours are drawn and written to glTF, whose COLOR_0 is 0..1.
    for (size_t i = 0; r->colors && i < 4 * (size_t)r->vertex_count; ++i)
        if (!(r->colors[i] >= 0.0f && r->colors[i] <= 1.0f))
            return sp_fail(err, SP_ERR_INVALID, "%s: the colour of vertex %zu has a component %g, not in 0..1", what, i / 4,
                           (double)r->colors[i]);
    if (r->abstraction_count < 1 || !r->abstractions)
        return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: %d abstractions (at least one is needed)%s", what,
                       (int)r->abstraction_count, r->abstraction_count >= 1 ? ", abstractions is NULL" : "");
    long long total = 0;
    for (int a = 0; a < r->abstraction_count; ++a) {
        const sp_blackbox_abstraction* ab = &r->abstractions[a];
        char why[64];
        const char* bad = name_problem(ab->name, SP_NAME_MAX - 1, why, sizeof why);
        if (bad) return sp_fail(err, SP_ERR_INVALID, "%s: abstraction %d %s", what, a, bad);
        for (int b = 0; b < a; ++b)
            if (!strcmp(r->abstractions[b].name, ab->name))
                return sp_fail(err, SP_ERR_INVALID, "%s: two abstractions are called '%s'", what, ab->name);
        if (ab->correspondence != SP_CORR_ORDERED && ab->correspondence != SP_CORR_CLOSEST)
            return sp_fail(err, SP_ERR_INVALID, "%s: abstraction '%s' has correspondence %d (0 ordered, 1 closest)", what,
                           ab->name, (int)ab->correspondence);
        if (ab->curve_count < 1 || ab->curve_count > SP_REPORT_CURVES || !ab->curves)
            return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: abstraction '%s' has %d curves (1..%d)", what, ab->name,
                           (int)ab->curve_count, SP_REPORT_CURVES);
        for (int c = 0; c < ab->curve_count; ++c) {
            const sp_blackbox_curve* cv = &ab->curves[c];
            bad = name_problem(cv->name, SP_NAME_MAX - 1, why, sizeof why);
            if (bad) return sp_fail(err, SP_ERR_INVALID, "%s: curve %d of '%s' %s", what, c, ab->name, bad);
            for (int d = 0; d < c; ++d)
                if (!strcmp(ab->curves[d].name, cv->name))
                    return sp_fail(err, SP_ERR_INVALID, "%s: two curves of '%s' are called '%s'", what, ab->name, cv->name);
            if (cv->point_count < 2 || cv->point_count > BB_MAX_POINTS)
                return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: curve '%s' of '%s' has %d points (2..%d)", what,
                               cv->name, ab->name, (int)cv->point_count, BB_MAX_POINTS);
            total += cv->point_count;
        }
        if (total > BB_MAX_POINTS)
            return sp_fail(err, SP_ERR_INVALID, "%s: inconsistent sizes: %lld abstraction points (at most %d)", what, total,
                           BB_MAX_POINTS);
    }
    if (!all_finite(r->view_forward, 3, NULL) || !all_finite(r->view_up, 3, NULL))
        return sp_fail(err, SP_ERR_INVALID, "%s: the sketch view has a non-finite direction", what);
    sp_vec3 f = {r->view_forward[0], r->view_forward[1], r->view_forward[2]};
    sp_vec3 u = {r->view_up[0], r->view_up[1], r->view_up[2]};
    if (sp_v3_len(f) > 0 && sp_v3_len(u) > 0 && sp_v3_len(sp_v3_cross(sp_v3_norm(f), sp_v3_norm(u))) < 1e-6)
        return sp_fail(err, SP_ERR_INVALID, "%s: the sketch view's up direction is parallel to its forward direction", what);
    return SP_OK;
}

static void blackbox_destroy(sp_blackbox* bb, bool release)
{
    if (!bb) return;
    if (release && bb->rig.release) bb->rig.release(bb->rig.user);
    for (int a = 0; a < bb->abstraction_count; ++a)
        free(bb->abs[a].curves);
    free(bb->abs), free(bb->first), free(bb->params), free(bb->desc_params);
    free(bb);
}

sp_result sp_blackbox_open(const sp_blackbox_rig* r, const char* what, sp_blackbox** out, sp_error* err)
{
    *out = NULL;
    if (!what) what = r && r->name ? r->name : "black-box rig";
    if (!r) return sp_fail(err, SP_ERR_INVALID, "%s: the rig description is NULL", what);
    if (r->abi_version != SP_BLACKBOX_ABI_VERSION)
        return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: black-box ABI version %u, this build reads version %u", what, r->abi_version,
                       SP_BLACKBOX_ABI_VERSION);
    if (r->struct_size != sizeof(sp_blackbox_rig))
        return sp_fail(
            err, SP_ERR_UNSUPPORTED,
            "%s: inconsistent sizes: sp_blackbox_rig is %u bytes in the rig, %zu here (built against another sp/blackbox.h)",
            what, r->struct_size, sizeof(sp_blackbox_rig));
    sp_result res = validate(r, what, err);
    if (res != SP_OK) {
        if (r->release) r->release(r->user);
        return res;
    }
    sp_blackbox* bb = calloc(1, sizeof *bb);
    if (!bb) {
        if (r->release) r->release(r->user);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    }
    bb->rig = *r;
    snprintf(bb->what, sizeof bb->what, "%s", what);
    bb->P = r->param_count;
    bb->n = r->vertex_count;
    bb->abstraction_count = r->abstraction_count;
    bb->abs = calloc((size_t)r->abstraction_count, sizeof(sp_abstraction));
    bb->first = calloc((size_t)r->abstraction_count + 1, sizeof(int));
    bb->params = calloc((size_t)bb->P, sizeof(sp_param));
    bb->desc_params = calloc((size_t)bb->P, sizeof(sp_blackbox_param));
    if (!bb->abs || !bb->first || !bb->params || !bb->desc_params) goto oom;
    for (int i = 0; i < bb->P; ++i) {
        const sp_blackbox_param* q = &r->params[i];
        sp_param* d = &bb->params[i];
        *d = (sp_param){
            .joint = -1, .channel = SP_CH_COUNT, .min = q->min, .max = q->max, .def = q->def, .group = (sp_group)q->group};
        snprintf(d->name, sizeof d->name, "%s", q->name); // validated: at most 127 bytes
        bb->desc_params[i] = *q;
        bb->desc_params[i].name = d->name;
    }
    bb->rig.params = bb->desc_params;
    for (int a = 0; a < r->abstraction_count; ++a) {
        const sp_blackbox_abstraction* src = &r->abstractions[a];
        sp_abstraction* dst = &bb->abs[a];
        snprintf(dst->name, sizeof dst->name, "%s", src->name);
        dst->correspondence = (sp_correspondence)src->correspondence;
        dst->curve_count = src->curve_count;
        dst->curves = calloc((size_t)src->curve_count, sizeof(sp_curve));
        if (!dst->curves) goto oom;
        for (int c = 0; c < src->curve_count; ++c) {
            sp_curve* cv = &dst->curves[c];
            snprintf(cv->name, sizeof cv->name, "%s", src->curves[c].name);
            cv->first_point = dst->point_count;
            cv->point_count = src->curves[c].point_count;
            cv->closed = src->curves[c].closed != 0;
            dst->point_count += cv->point_count;
        }
        bb->first[a + 1] = bb->first[a] + dst->point_count;
    }
    bb->total = bb->first[r->abstraction_count];
    sp_vec3 lo, hi;
    sp_bounds(r->rest, bb->n, &lo, &hi);
    bb->diag = sp_v3_len(sp_v3_sub(hi, lo));
    // evaluate() at the defaults must work and reproduce the rest mesh: this
    // catches a rig whose counts disagree with what it writes, and NaNs.
    {
        double* x = malloc(sizeof(double) * 3 * (size_t)bb->n);
        double* z = malloc(sizeof(double) * 3 * (size_t)(bb->total + 1));
        double* def = malloc(sizeof(double) * (size_t)bb->P);
        if (!x || !z || !def) {
            free(x), free(z), free(def);
            goto oom;
        }
        // NaN where evaluate() must write: what it leaves out is then caught.
        for (size_t i = 0; i < 3 * (size_t)bb->n; ++i)
            x[i] = NAN;
        sp_blackbox_defaults(bb, def);
        int rc = 0;
        size_t bad = 0;
        res = sp__blackbox_eval_raw(bb, def, x, z, &rc, &bad);
        if (res != SP_OK) res = sp__blackbox_eval_message(bb, res, rc, bad, "at the defaults", err);
        double tol = 1e-6 * (bb->diag > 0 ? bb->diag : 1.0), worst = 0;
        int wi = 0;
        for (int i = 0; res == SP_OK && i < bb->n; ++i) {
            double d = sp_v3_len(sp_v3_sub((sp_vec3){x[3 * i], x[3 * i + 1], x[3 * i + 2]},
                                           (sp_vec3){r->rest[3 * i], r->rest[3 * i + 1], r->rest[3 * i + 2]}));
            if (d > worst) worst = d, wi = i;
        }
        free(x), free(z), free(def);
        if (res == SP_OK && worst > tol)
            res = sp_fail(err, SP_ERR_INVALID,
                          "%s: evaluate() at the defaults does not reproduce the rest mesh (vertex %d is %.3g away)", what, wi,
                          worst);
        if (res != SP_OK) {
            blackbox_destroy(bb, true);
            return res;
        }
    }
    *out = bb;
    return SP_OK;
oom:
    blackbox_destroy(bb, true);
    return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
}

void sp_blackbox_on_destroy(sp_blackbox* bb, void (*fn)(void* user), void* user)
{
    bb->on_destroy = fn;
    bb->on_destroy_user = user;
}

void sp_blackbox_destroy(sp_blackbox* bb)
{
    if (!bb) return;
    void (*fn)(void*) = bb->on_destroy;
    void* user = bb->on_destroy_user;
    blackbox_destroy(bb, true);
    if (fn) fn(user);
}

// ---------------------------------------------------------------- queries

const sp_blackbox_rig* sp_blackbox_desc(const sp_blackbox* bb)
{
    return &bb->rig;
}

int sp_blackbox_abstraction_points(const sp_blackbox* bb, int a)
{
    return bb->abs[a].point_count;
}
int sp_blackbox_total_points(const sp_blackbox* bb)
{
    return bb->total;
}
int sp_blackbox_first_point(const sp_blackbox* bb, int a)
{
    return bb->first[a];
}
const sp_abstraction* sp_blackbox_abstraction_at(const sp_blackbox* bb, int a)
{
    return &bb->abs[a];
}

const sp_param* sp_blackbox_params(const sp_blackbox* bb)
{
    return bb->params;
}

void sp_blackbox_defaults(const sp_blackbox* bb, double* p)
{
    for (int i = 0; i < bb->P; ++i)
        p[i] = bb->params[i].def;
}

sp_camera sp_blackbox_camera(const sp_blackbox* bb, int width, int height)
{
    const sp_blackbox_rig* r = &bb->rig;
    sp_vec3 f = {r->view_forward[0], r->view_forward[1], r->view_forward[2]};
    if (!(sp_v3_len(f) > 0)) return sp_camera_default_view(r->rest, bb->n, width, height);
    sp_vec3 u = {r->view_up[0], r->view_up[1], r->view_up[2]};
    if (!(sp_v3_len(u) > 0)) u = (sp_vec3){0, 1, 0};
    sp_vec3 lo, hi;
    sp_bounds(r->rest, bb->n, &lo, &hi);
    return sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, lo, hi, sp_v3_norm(f), sp_v3_norm(u), width, height);
}

sp_result sp__blackbox_eval_raw(const sp_blackbox* bb, const double* p, double* x, double* z, int* rc_out, size_t* bad)
{
    // The abstraction points are few: NaN in them catches a rig that writes
    // fewer than it declares on every call (its vertices, on open).
    for (size_t i = 0; z && i < 3 * (size_t)bb->total; ++i)
        z[i] = NAN;
    int rc = bb->rig.evaluate(bb->rig.user, p, x, z);
    if (rc_out) *rc_out = rc;
    if (rc != 0) return SP_ERR_INTERNAL;
    if (!all_finite(x, 3 * (size_t)bb->n, bad)) return SP_ERR_INVALID;
    if (z && !all_finite(z, 3 * (size_t)bb->total, bad)) {
        if (bad) *bad += 3 * (size_t)bb->n;
        return SP_ERR_INVALID;
    }
    return SP_OK;
}

sp_result sp__blackbox_eval_message(const sp_blackbox* bb, sp_result r, int rc, size_t bad, const char* where, sp_error* err)
{
    if (r == SP_ERR_INTERNAL) return sp_fail(err, SP_ERR_INVALID, "%s: evaluate() failed (returned %d) %s", bb->what, rc, where);
    size_t nx = 3 * (size_t)bb->n;
    if (bad < nx)
        return sp_fail(err, SP_ERR_INVALID, "%s: evaluate() gave a NaN or infinite coordinate, or none (vertex %zu) %s", bb->what,
                       bad / 3, where);
    return sp_fail(err, SP_ERR_INVALID, "%s: evaluate() gave a NaN or infinite coordinate, or none (abstraction point %zu) %s",
                   bb->what, (bad - nx) / 3, where);
}

sp_result sp_blackbox_evaluate(const sp_blackbox* bb, const double* p, double* vertices_xyz, double* abstraction_xyz,
                               sp_error* err)
{
    double* q = malloc(sizeof(double) * (size_t)bb->P);
    double* x = vertices_xyz ? vertices_xyz : malloc(sizeof(double) * 3 * (size_t)bb->n);
    if (!q || !x) {
        free(q);
        if (!vertices_xyz) free(x);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", bb->what);
    }
    memcpy(q, p, sizeof(double) * (size_t)bb->P);
    sp_params_clamp(bb->params, bb->P, q);
    int rc = 0;
    size_t bad = 0;
    sp_result r = sp__blackbox_eval_raw(bb, q, x, abstraction_xyz, &rc, &bad);
    if (r != SP_OK) sp__blackbox_eval_message(bb, r, rc, bad, "at the given parameters", err);
    free(q);
    if (!vertices_xyz) free(x);
    return r == SP_OK ? SP_OK : SP_ERR_INVALID;
}

double sp_blackbox_fd_step(const sp_blackbox* bb, int k)
{
    const sp_blackbox_param* q = &bb->rig.params[k];
    return SP_BB_FD_FRACTION * (q->max - q->min);
}

// ---------------------------------------------------------------- synthetic targets

void sp_blackbox_synth_params(const sp_blackbox* bb, uint64_t seed, double amplitude, double* p)
{
    sp_rng rng = sp__synth_rng(seed);
    for (int i = 0; i < bb->P; ++i) {
        const sp_blackbox_param* q = &bb->rig.params[i];
        p[i] = sp__synth_param(&rng, q->def, q->min, q->max, q->unit == SP_BB_UNIT_ANGLE, q->group == SP_GROUP_POSE, amplitude);
    }
}

sp_result sp_blackbox_synth_sketch(const sp_blackbox* bb, int a, const sp_camera* cam, const double* p, sp_sketch* out,
                                   sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (a < 0 || a >= bb->abstraction_count) return sp_fail(err, SP_ERR_INVALID, "%s: no abstraction %d", bb->what, a);
    const sp_abstraction* ab = &bb->abs[a];
    double* z = malloc(sizeof(double) * 3 * (size_t)(bb->total + 1));
    sp_vec2* pts = malloc(sizeof(sp_vec2) * (size_t)(ab->point_count + 1));
    sp_result r =
        !z || !pts ? sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", bb->what) : sp_blackbox_evaluate(bb, p, NULL, z, err);
    out->canvas_w = cam->width, out->canvas_h = cam->height;
    const double* za = z ? z + 3 * (size_t)bb->first[a] : NULL;
    for (int c = 0; r == SP_OK && c < ab->curve_count; ++c) {
        const sp_curve* cv = &ab->curves[c];
        for (int i = 0; i < cv->point_count; ++i) {
            const double* w = za + 3 * (cv->first_point + i);
            pts[i] = sp_camera_project(cam, (sp_vec3){w[0], w[1], w[2]});
        }
        int n = cv->point_count;
        if (cv->closed) pts[n++] = pts[0];
        r = sp_sketch_add_stroke(out, pts, NULL, n);
        if (r != SP_OK) sp_fail(err, r, "%s: out of memory", bb->what);
    }
    free(z), free(pts);
    if (r != SP_OK) sp_sketch_free(out);
    return r;
}

// ---------------------------------------------------------------- finite differences

// One thread's buffers: the parameters and both ends of a stencil.
typedef struct fd_lane {
    double* q;       // P
    double *xa, *xb; // n * 3
    double *za, *zb; // total * 3
} fd_lane;

struct sp_blackbox_fd {
    const sp_blackbox* bb;
    int a, first, npts; // the abstraction, its first point in evaluate()'s output, its points
    int* rows;
    int nrows;
    int M; // values per column: 3 * (nrows + npts)
    int threads;
    fd_lane* lanes; // threads
    double* Jt;     // P columns of M values (column-major: no two threads share a cache line)
    int* status;    // P: 0 ok, else a failed evaluation (see column())
    int* rc;        // P: evaluate()'s return code when it failed
    size_t* bad;    // P: index of a non-finite value
    // The pool: workers wait for a new generation, take columns until none
    // is left, and report when done.
    pthread_t* tids;
    int started;
    pthread_mutex_t mu;
    pthread_cond_t wake, done;
    unsigned generation;
    int next_col, busy;
    bool quit, timed_out;
    double deadline_ms;
    const double* p;
};

// Column k of the Jacobian, computed by one thread from its own two
// evaluations: the value depends only on p and k, never on scheduling.
static void column(sp_blackbox_fd* fd, fd_lane* ln, int k)
{
    const sp_blackbox* bb = fd->bb;
    const sp_blackbox_param* q = &bb->rig.params[k];
    double* out = fd->Jt + (size_t)k * (size_t)fd->M;
    double h = sp_blackbox_fd_step(bb, k);
    fd->status[k] = 0;
    if (!(h > 0)) {
        memset(out, 0, sizeof(double) * (size_t)fd->M);
        return;
    }
    double lo = fd->p[k] - h, hi = fd->p[k] + h;
    if (hi > q->max) hi = q->max, lo = q->max - 2 * h;
    if (lo < q->min) lo = q->min, hi = q->min + 2 * h;
    memcpy(ln->q, fd->p, sizeof(double) * (size_t)bb->P);
    ln->q[k] = hi;
    int rc = bb->rig.evaluate(bb->rig.user, ln->q, ln->xb, ln->zb);
    if (rc == 0) {
        ln->q[k] = lo;
        rc = bb->rig.evaluate(bb->rig.user, ln->q, ln->xa, ln->za);
    }
    if (rc != 0) {
        fd->status[k] = SP_ERR_INTERNAL;
        fd->rc[k] = rc;
        memset(out, 0, sizeof(double) * (size_t)fd->M);
        return;
    }
    double step = hi - lo;
    for (int i = 0; i < fd->nrows; ++i) {
        const double* b = ln->xb + 3 * (size_t)fd->rows[i];
        const double* a = ln->xa + 3 * (size_t)fd->rows[i];
        for (int c = 0; c < 3; ++c)
            out[3 * i + c] = (b[c] - a[c]) / step;
    }
    double* oz = out + 3 * (size_t)fd->nrows;
    const double* zb = ln->zb + 3 * (size_t)fd->first;
    const double* za = ln->za + 3 * (size_t)fd->first;
    for (int i = 0; i < 3 * fd->npts; ++i)
        oz[i] = (zb[i] - za[i]) / step;
    // Only the values used are checked (a NaN elsewhere cannot reach the
    // solve); a NaN or infinity in them makes the column non-finite. `bad`
    // is reported as an index into evaluate()'s output, as for a state.
    size_t bad = 0;
    if (!all_finite(out, (size_t)fd->M, &bad)) {
        fd->status[k] = SP_ERR_INVALID;
        size_t nr = 3 * (size_t)fd->nrows;
        fd->bad[k] = bad < nr ? 3 * (size_t)fd->rows[bad / 3] : 3 * ((size_t)bb->n + (size_t)fd->first) + (bad - nr);
        memset(out, 0, sizeof(double) * (size_t)fd->M);
    }
}

// Takes columns until none is left (the caller holds no lock).
static void drain(sp_blackbox_fd* fd, fd_lane* ln)
{
    for (;;) {
        // A rig that takes a second an evaluation would otherwise overrun
        // the solve's time cap by 2 P seconds.
        const bool late = sp_now_ms() > fd->deadline_ms;
        pthread_mutex_lock(&fd->mu);
        if (late) fd->timed_out = true, fd->next_col = fd->bb->P;
        int k = fd->next_col < fd->bb->P ? fd->next_col++ : -1;
        pthread_mutex_unlock(&fd->mu);
        if (k < 0) return;
        column(fd, ln, k);
    }
}

typedef struct worker_arg {
    sp_blackbox_fd* fd;
    int lane;
} worker_arg;

static void* worker(void* arg)
{
    worker_arg* wa = arg;
    sp_blackbox_fd* fd = wa->fd;
    fd_lane* ln = &fd->lanes[wa->lane];
    free(wa);
    unsigned seen = 0;
    pthread_mutex_lock(&fd->mu);
    for (;;) {
        while (!fd->quit && fd->generation == seen)
            pthread_cond_wait(&fd->wake, &fd->mu);
        if (fd->quit) break;
        seen = fd->generation;
        pthread_mutex_unlock(&fd->mu);
        drain(fd, ln);
        pthread_mutex_lock(&fd->mu);
        if (--fd->busy == 0) pthread_cond_signal(&fd->done);
    }
    pthread_mutex_unlock(&fd->mu);
    return NULL;
}

static int online_cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > 8 ? 8 : (int)n);
}

sp_result sp_blackbox_fd_create(const sp_blackbox* bb, int abstraction, const int* rows, int nrows, int threads,
                                sp_blackbox_fd** out, sp_error* err)
{
    *out = NULL;
    if (abstraction < 0 || abstraction >= bb->abstraction_count)
        return sp_fail(err, SP_ERR_INVALID, "%s: abstraction %d does not exist (the rig has %d)", bb->what, abstraction,
                       bb->abstraction_count);
    if (nrows < 0) return sp_fail(err, SP_ERR_INVALID, "%s: %d rows", bb->what, nrows);
    for (int i = 0; i < nrows; ++i)
        if (rows[i] < 0 || rows[i] >= bb->n)
            return sp_fail(err, SP_ERR_INVALID, "%s: row %d is vertex %d, out of range (%d vertices)", bb->what, i, rows[i],
                           bb->n);
    sp_blackbox_fd* fd = calloc(1, sizeof *fd);
    if (!fd) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory making a finite-difference engine", bb->what);
    fd->bb = bb;
    fd->a = abstraction;
    fd->first = bb->first[abstraction];
    fd->npts = bb->abs[abstraction].point_count;
    fd->nrows = nrows;
    fd->M = 3 * (nrows + fd->npts);
    fd->deadline_ms = INFINITY;
    fd->threads = threads > 0 ? threads : online_cores();
    if (fd->threads > bb->P) fd->threads = bb->P;
    fd->rows = malloc(sizeof(int) * (size_t)(nrows + 1));
    fd->lanes = calloc((size_t)fd->threads, sizeof(fd_lane));
    fd->Jt = malloc(sizeof(double) * (size_t)bb->P * (size_t)fd->M + 1);
    fd->status = calloc((size_t)bb->P, sizeof(int));
    fd->rc = calloc((size_t)bb->P, sizeof(int));
    fd->bad = calloc((size_t)bb->P, sizeof(size_t));
    fd->tids = calloc((size_t)fd->threads, sizeof(pthread_t));
    pthread_mutex_init(&fd->mu, NULL);
    pthread_cond_init(&fd->wake, NULL);
    pthread_cond_init(&fd->done, NULL);
    sp_result r = SP_ERR_NO_MEMORY;
    if (!fd->rows || !fd->lanes || !fd->Jt || !fd->status || !fd->rc || !fd->bad || !fd->tids) goto fail;
    if (nrows) memcpy(fd->rows, rows, sizeof(int) * (size_t)nrows);
    for (int t = 0; t < fd->threads; ++t) {
        fd_lane* ln = &fd->lanes[t];
        ln->q = malloc(sizeof(double) * (size_t)bb->P);
        ln->xa = malloc(sizeof(double) * 3 * (size_t)bb->n);
        ln->xb = malloc(sizeof(double) * 3 * (size_t)bb->n);
        ln->za = malloc(sizeof(double) * 3 * (size_t)(bb->total + 1));
        ln->zb = malloc(sizeof(double) * 3 * (size_t)(bb->total + 1));
        if (!ln->q || !ln->xa || !ln->xb || !ln->za || !ln->zb) goto fail;
    }
    // Lane 0 is the caller's; the others get a worker each.
    for (int t = 1; t < fd->threads; ++t) {
        worker_arg* wa = malloc(sizeof *wa);
        if (!wa) goto fail;
        *wa = (worker_arg){fd, t};
        int rc = pthread_create(&fd->tids[t], NULL, worker, wa);
        if (rc != 0) {
            free(wa);
            r = sp_fail(err, SP_ERR_INTERNAL, "%s: cannot start finite-difference thread %d (%s)", bb->what, t, strerror(rc));
            goto fail;
        }
        fd->started = t;
    }
    *out = fd;
    return SP_OK;
fail:
    sp_blackbox_fd_destroy(fd);
    return r == SP_ERR_NO_MEMORY ? sp_fail(err, r, "%s: out of memory making a finite-difference engine", bb->what) : r;
}

void sp_blackbox_fd_destroy(sp_blackbox_fd* fd)
{
    if (!fd) return;
    pthread_mutex_lock(&fd->mu);
    fd->quit = true;
    pthread_cond_broadcast(&fd->wake);
    pthread_mutex_unlock(&fd->mu);
    for (int t = 1; t <= fd->started; ++t)
        pthread_join(fd->tids[t], NULL);
    pthread_mutex_destroy(&fd->mu);
    pthread_cond_destroy(&fd->wake);
    pthread_cond_destroy(&fd->done);
    for (int t = 0; fd->lanes && t < fd->threads; ++t) {
        fd_lane* ln = &fd->lanes[t];
        free(ln->q), free(ln->xa), free(ln->xb), free(ln->za), free(ln->zb);
    }
    free(fd->lanes), free(fd->rows), free(fd->Jt), free(fd->status), free(fd->rc), free(fd->bad), free(fd->tids);
    free(fd);
}

int sp_blackbox_fd_threads(const sp_blackbox_fd* fd)
{
    return fd->threads;
}

void sp_blackbox_fd_set_deadline(sp_blackbox_fd* fd, double deadline_ms)
{
    pthread_mutex_lock(&fd->mu);
    fd->deadline_ms = deadline_ms;
    pthread_mutex_unlock(&fd->mu);
}

sp_result sp_blackbox_fd_jacobian(sp_blackbox_fd* fd, const double* p, double* J_rows, double* J_abs, sp_error* err)
{
    const sp_blackbox* bb = fd->bb;
    const int P = bb->P;
    pthread_mutex_lock(&fd->mu);
    fd->p = p;
    fd->next_col = 0;
    fd->timed_out = false;
    fd->busy = fd->threads - 1;
    ++fd->generation;
    pthread_cond_broadcast(&fd->wake);
    pthread_mutex_unlock(&fd->mu);
    drain(fd, &fd->lanes[0]);
    pthread_mutex_lock(&fd->mu);
    while (fd->busy > 0)
        pthread_cond_wait(&fd->done, &fd->mu);
    const bool timed_out = fd->timed_out;
    pthread_mutex_unlock(&fd->mu);
    if (timed_out) return sp_fail(err, SP_ERR_TIMEOUT, "%s: the time cap ran out during a finite-difference Jacobian", bb->what);
    // The first failing column (in parameter order, whatever thread ran it) names the problem.
    for (int k = 0; k < P; ++k)
        if (fd->status[k] != 0) {
            char where[200];
            snprintf(where, sizeof where, "at a finite-difference step of parameter '%s'", bb->rig.params[k].name);
            return sp__blackbox_eval_message(bb, (sp_result)fd->status[k], fd->rc[k], fd->bad[k], where, err);
        }
    // Column-major to the row-major (3 * rows) x P layout of the callers.
    const size_t M = (size_t)fd->M, nr = 3 * (size_t)fd->nrows;
    if (J_rows)
        for (size_t r = 0; r < nr; ++r)
            for (int k = 0; k < P; ++k)
                J_rows[r * P + k] = fd->Jt[(size_t)k * M + r];
    if (J_abs)
        for (size_t r = 0; r < 3 * (size_t)fd->npts; ++r)
            for (int k = 0; k < P; ++k)
                J_abs[r * P + k] = fd->Jt[(size_t)k * M + nr + r];
    return SP_OK;
}

// ---------------------------------------------------------------- the solver's model

typedef struct bb_model {
    sp_model base;
    const sp_blackbox* bb;
    int a, threads;
    sp_model_param* params;
    double* x;  // n * 3: vertices at the state
    double* z;  // total * 3: abstraction points at the state
    double* p;  // P: the state
    bool valid; // x, z hold a successful evaluation at p
    sp_blackbox_fd* fd;
    // The last Jacobian and where it was taken: after a round whose steps
    // were all rejected the solve asks again at the same parameters.
    double *pJ, *Jr, *Jz;
    bool J_valid;
} bb_model;

static int bbm_columns(const sp_model* m, bool abstraction, int v, int* out)
{
    // Nothing is known about which parameters move which point: dense rows.
    (void)abstraction, (void)v;
    for (int i = 0; i < m->P; ++i)
        out[i] = i;
    return m->P;
}

static sp_result bbm_prepare(sp_model* m, const int* reps, int k, sp_error* err)
{
    bb_model* B = (bb_model*)m;
    sp_blackbox_fd_destroy(B->fd);
    size_t P = (size_t)m->P;
    free(B->pJ), free(B->Jr), free(B->Jz);
    B->pJ = B->Jr = B->Jz = NULL;
    B->J_valid = false;
    sp_result r = sp_blackbox_fd_create(B->bb, B->a, reps, k, B->threads, &B->fd, err);
    if (r != SP_OK) return r;
    B->pJ = malloc(sizeof(double) * P);
    B->Jr = malloc(sizeof(double) * (3 * (size_t)k * P + 1));
    B->Jz = malloc(sizeof(double) * (3 * (size_t)m->ab->point_count * P + 1));
    if (!B->pJ || !B->Jr || !B->Jz) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory making a solver", B->bb->what);
    return SP_OK;
}

static void bbm_fail(bb_model* B, const sp_error* e)
{
    if (!B->base.failed) B->base.error = *e;
    B->base.failed = true;
}

static void bbm_update(sp_model* m, const double* p, bool derivatives)
{
    bb_model* B = (bb_model*)m;
    (void)derivatives; // the Jacobian is computed when asked for, at this p
    const size_t P = (size_t)m->P;
    // The solve often evaluates a state it has just evaluated (energy, then
    // the next iteration at the accepted parameters): reuse it.
    if (B->valid && !memcmp(B->p, p, sizeof(double) * P)) return;
    memcpy(B->p, p, sizeof(double) * P);
    int rc = 0;
    size_t bad = 0;
    sp_result r = sp__blackbox_eval_raw(B->bb, p, B->x, B->z, &rc, &bad);
    B->valid = r == SP_OK;
    if (r != SP_OK) {
        sp_error e = {0};
        sp__blackbox_eval_message(B->bb, r, rc, bad, "during the solve", &e);
        bbm_fail(B, &e);
    }
}

static void bbm_abstraction(sp_model* m, double* z3)
{
    bb_model* B = (bb_model*)m;
    memcpy(z3, B->z + 3 * (size_t)B->bb->first[B->a], sizeof(double) * 3 * (size_t)m->ab->point_count);
}

static void bbm_rows(sp_model* m, const int* rows, int n, double* xyz)
{
    bb_model* B = (bb_model*)m;
    for (int i = 0; i < n; ++i)
        memcpy(xyz + 3 * i, B->x + 3 * (size_t)rows[i], sizeof(double) * 3);
}

static void bbm_jacobians(sp_model* m, const int* reps, int k, const sparse_block* ab_sb, const int* ab_cols, const bool* ab_used,
                          double* Jz, const sparse_block* rep_sb, const int* rep_cols, double* Jr)
{
    bb_model* B = (bb_model*)m;
    // Finite differences give every point at once: ab_used saves nothing here.
    (void)reps, (void)k, (void)ab_cols, (void)rep_cols, (void)ab_sb, (void)rep_sb, (void)ab_used;
    // Dense blocks one after the other are exactly the engine's row-major
    // (3 * points) x P layout (bbm_columns lists every parameter).
    size_t P = (size_t)m->P, nr = 3 * (size_t)k * P, nz = 3 * (size_t)m->ab->point_count * P;
    if (B->J_valid && !memcmp(B->pJ, B->p, sizeof(double) * P)) {
        // The Jacobian is a function of p alone: the same p, the same bits.
        memcpy(Jr, B->Jr, sizeof(double) * nr);
        memcpy(Jz, B->Jz, sizeof(double) * nz);
        return;
    }
    sp_error e = {0};
    B->J_valid = false;
    sp_blackbox_fd_set_deadline(B->fd, m->deadline_ms);
    sp_result r = sp_blackbox_fd_jacobian(B->fd, B->p, Jr, Jz, &e);
    if (r != SP_OK) {
        if (r == SP_ERR_TIMEOUT)
            m->timed_out = true; // not the rig's fault: the solve stops with what it has
        else
            bbm_fail(B, &e);
        memset(Jr, 0, sizeof(double) * nr);
        memset(Jz, 0, sizeof(double) * nz);
        return;
    }
    if (B->Jr && B->Jz && B->pJ) {
        memcpy(B->pJ, B->p, sizeof(double) * P);
        memcpy(B->Jr, Jr, sizeof(double) * nr);
        memcpy(B->Jz, Jz, sizeof(double) * nz);
        B->J_valid = true;
    }
}

static void bbm_destroy(sp_model* m)
{
    bb_model* B = (bb_model*)m;
    if (!B) return;
    sp_blackbox_fd_destroy(B->fd);
    free(B->params), free(B->x), free(B->z), free(B->p), free(B->pJ), free(B->Jr), free(B->Jz);
    free(B);
}

// No closed-form regularisers: the solver sums the representatives' rows.
static const sp_model_ops bb_ops = {bbm_columns, bbm_prepare, bbm_update, bbm_abstraction, bbm_rows, bbm_jacobians, bbm_destroy, NULL, NULL, NULL};

sp_result sp_solver_create_blackbox(const sp_blackbox* bb, int abstraction, const sp_camera* cam, const sp_solve_desc* desc,
                                    sp_solver** out, sp_error* err)
{
    *out = NULL;
    if (abstraction < 0 || abstraction >= bb->abstraction_count)
        return sp_fail(err, SP_ERR_INVALID, "%s: abstraction %d does not exist (the rig has %d)", bb->what, abstraction,
                       bb->abstraction_count);
    bb_model* B = calloc(1, sizeof *B);
    if (!B) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory making a solver", bb->what);
    B->bb = bb;
    B->a = abstraction;
    B->threads = desc ? desc->threads : 0;
    B->params = malloc(sizeof(sp_model_param) * (size_t)bb->P);
    B->x = malloc(sizeof(double) * 3 * (size_t)bb->n);
    B->z = malloc(sizeof(double) * 3 * (size_t)(bb->total + 1));
    B->p = malloc(sizeof(double) * (size_t)bb->P);
    if (!B->params || !B->x || !B->z || !B->p) {
        bbm_destroy(&B->base);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory making a solver", bb->what);
    }
    for (int i = 0; i < bb->P; ++i) {
        const sp_blackbox_param* q = &bb->rig.params[i];
        B->params[i] = (sp_model_param){q->min, q->max, q->def, q->unit == SP_BB_UNIT_LENGTH};
    }
    B->base = (sp_model){.ops = &bb_ops,
                         .P = bb->P,
                         .params = B->params,
                         .vertex_count = bb->n,
                         .rest = bb->rig.rest,
                         .ab = &bb->abs[abstraction],
                         .embedded = false,
                         .placement_count = 0};
    return sp__solver_create_model(&B->base, cam, desc, out, err);
}
