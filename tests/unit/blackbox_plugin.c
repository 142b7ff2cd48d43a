// blackbox_plugin.c: small black-box rig plugins for the loader's tests, one
// source compiled into several modules (tests/unit/blackbox.cmake), each a
// different defect chosen by a macro:
//   SP_TEST_PLUGIN_good       a valid rig: a 6x6 sheet that moves, turns and bends
//   SP_TEST_PLUGIN_nosym      exports no entry symbol
//   SP_TEST_PLUGIN_null       its entry returns NULL
//   SP_TEST_PLUGIN_badversion ABI version 99
//   SP_TEST_PLUGIN_badsize    struct_size of another layout
//   SP_TEST_PLUGIN_badtri     a triangle uses a vertex that does not exist
//   SP_TEST_PLUGIN_badrest    evaluate() at the defaults is not the rest mesh
//   SP_TEST_PLUGIN_nan        evaluate() writes NaN
//   SP_TEST_PLUGIN_nanlater   evaluate() writes NaN once bend > 0.3 (only during a solve)
#include <math.h>
#include <stdlib.h>

#include "sp/blackbox.h"

enum { N = 6, V = N * N, T = 2 * (N - 1) * (N - 1), L = 8 };

typedef struct sheet {
    sp_blackbox_rig desc;
    double rest[3 * V];
    uint32_t tris[3 * T];
    int released;
} sheet;

static const sp_blackbox_param PARAMS[4] = {
    {"move_x", -1, 1, 0, SP_GROUP_POSE, SP_BB_UNIT_LENGTH},
    {"move_y", -1, 1, 0, SP_GROUP_POSE, SP_BB_UNIT_LENGTH},
    {"turn", -1, 1, 0, SP_GROUP_POSE, SP_BB_UNIT_ANGLE},
    {"bend", -1, 1, 0, SP_GROUP_POSE, SP_BB_UNIT_ANGLE},
};
static const sp_blackbox_curve CURVES[1] = {{"edge", L, 0}};
static const sp_blackbox_abstraction ABS[1] = {{"line", SP_CORR_ORDERED, 1, CURVES}};

// A point of the sheet at (u, v) in [0, 1]^2 under the parameters.
static void sheet_point(const double* p, double u, double v, double out[3])
{
    double x = 2 * u - 1, y = 2 * v - 1, k = p[3];
    // bend: the sheet's x axis becomes an arc of curvature k (straight at 0)
    double bx = x, bz = 0;
    if (fabs(k) > 1e-12) bx = sin(k * x) / k, bz = (1 - cos(k * x)) / k;
    double c = cos(p[2]), s = sin(p[2]);
    out[0] = c * bx - s * y + p[0];
    out[1] = s * bx + c * y + p[1];
    out[2] = bz;
}

static int evaluate(void* user, const double* p, double* x, double* z)
{
    (void)user;
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i)
            sheet_point(p, (double)i / (N - 1), (double)j / (N - 1), x + 3 * (j * N + i));
    if (z)
        for (int k = 0; k < L; ++k)
            sheet_point(p, (double)k / (L - 1), 1.0, z + 3 * k);
#if defined(SP_TEST_PLUGIN_nan)
    x[7] = NAN;
#elif defined(SP_TEST_PLUGIN_nanlater)
    if (p[3] > 0.3 && z) z[4] = NAN;
#elif defined(SP_TEST_PLUGIN_badrest)
    x[0] += 0.5;
#endif
    return 0;
}

static void release(void* user)
{
    free(user);
}

#if !defined(SP_TEST_PLUGIN_nosym)
__attribute__((visibility("default"))) const sp_blackbox_rig* sp_blackbox_plugin_v1(void);
const sp_blackbox_rig* sp_blackbox_plugin_v1(void)
#else
__attribute__((visibility("default"))) const sp_blackbox_rig* some_other_function(void);
const sp_blackbox_rig* some_other_function(void)
#endif
{
#if defined(SP_TEST_PLUGIN_null)
    return NULL;
#endif
#if defined(SP_TEST_PLUGIN_badversion) || defined(SP_TEST_PLUGIN_badsize)
    // A host cannot call release() of a layout it does not know, so these
    // rigs live in static storage (a real plugin of another version would
    // leak its heap copy, once).
    static sheet one;
    sheet* s = &one;
#else
    sheet* s = calloc(1, sizeof *s);
    if (!s) return NULL;
#endif
    double p0[4] = {0, 0, 0, 0};
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i)
            sheet_point(p0, (double)i / (N - 1), (double)j / (N - 1), s->rest + 3 * (j * N + i));
    int t = 0;
    for (int j = 0; j + 1 < N; ++j)
        for (int i = 0; i + 1 < N; ++i) {
            uint32_t a = (uint32_t)(j * N + i), b = a + 1, c = a + N, d = c + 1;
            uint32_t q[6] = {a, b, c, b, d, c};
            for (int k = 0; k < 6; ++k)
                s->tris[t++] = q[k];
        }
#if defined(SP_TEST_PLUGIN_badtri)
    s->tris[5] = V + 3;
#endif
    s->desc = (sp_blackbox_rig){
        .abi_version = SP_BLACKBOX_ABI_VERSION,
        .struct_size = sizeof(sp_blackbox_rig),
        .name = "sheet",
        .param_count = 4,
        .params = PARAMS,
        .vertex_count = V,
        .rest = s->rest,
        .triangle_count = T,
        .triangles = s->tris,
        .abstraction_count = 1,
        .abstractions = ABS,
        .user = s,
        .evaluate = evaluate,
        .release = release,
    };
#if defined(SP_TEST_PLUGIN_badversion)
    s->desc.abi_version = 99;
    s->desc.release = NULL;
#elif defined(SP_TEST_PLUGIN_badsize)
    s->desc.struct_size = sizeof(sp_blackbox_rig) + 16;
    s->desc.release = NULL;
#endif
    return &s->desc;
}
