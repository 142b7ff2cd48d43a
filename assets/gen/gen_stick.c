// gen_stick.c: stick-figure abstractions along a generated skeleton.
#include "gen_stick.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sp_gen_stick_begin(sp_abstraction* ab)
{
    memset(ab, 0, sizeof *ab);
    snprintf(ab->name, sizeof ab->name, "stick");
    ab->correspondence = SP_CORR_ORDERED;
}

void sp_gen_stick_curve(sp_abstraction* ab, const sp_gen_rig* g, const char* name, const int* chain, int n, sp_vec3 tip,
                        int points)
{
    enum { MAX_BONES = 32 };
    if (n < 1 || n > MAX_BONES || points < n + 1) {
        fprintf(stderr, "sp-assetgen: stick curve '%s': %d joints, %d points\n", name, n, points);
        exit(1);
    }
    sp_vec3 at[MAX_BONES + 1];
    double len[MAX_BONES], total = 0;
    for (int k = 0; k < n; ++k)
        at[k] = g->pivot[chain[k]];
    at[n] = tip;
    for (int k = 0; k < n; ++k)
        total += len[k] = sp_v3_len(sp_v3_sub(at[k + 1], at[k]));
    // Points per bone: one each, the rest by length (largest remainder
    // first, ties to the earlier bone, so the result is deterministic);
    // the tip is the curve's last point.
    int share[MAX_BONES], given = 0, spare = points - 1 - n;
    double rem[MAX_BONES];
    for (int k = 0; k < n; ++k) {
        double want = spare * len[k] / total;
        share[k] = 1 + (int)floor(want);
        rem[k] = want - floor(want);
        given += share[k];
    }
    while (given < points - 1) {
        int best = 0;
        for (int k = 1; k < n; ++k)
            if (rem[k] > rem[best]) best = k;
        ++share[best], rem[best] = -1, ++given;
    }
    int first = ab->point_count, total_points = first + points;
    ab->rest = sp_gen_check_alloc(realloc(ab->rest, sizeof(double) * 3 * (size_t)total_points));
    ab->joints = sp_gen_check_alloc(realloc(ab->joints, sizeof(uint16_t) * 4 * (size_t)total_points));
    ab->weights = sp_gen_check_alloc(realloc(ab->weights, sizeof(float) * 4 * (size_t)total_points));
    ab->curves = sp_gen_check_alloc(realloc(ab->curves, sizeof(sp_curve) * (size_t)(ab->curve_count + 1)));
    int i = first;
    for (int k = 0; k <= n; ++k) {
        int m = k < n ? share[k] : 1;
        int joint = chain[k < n ? k : n - 1];
        for (int q = 0; q < m; ++q, ++i) {
            // Bind space is the generator's rest space (inverse binds are the
            // rest frames' inverses), like the mesh vertices.
            sp_vec3 p = k < n ? sp_v3_add(at[k], sp_v3_scale(sp_v3_sub(at[k + 1], at[k]), (double)q / m)) : tip;
            ab->rest[3 * i] = p.x, ab->rest[3 * i + 1] = p.y, ab->rest[3 * i + 2] = p.z;
            ab->joints[4 * i] = (uint16_t)joint;
            ab->joints[4 * i + 1] = ab->joints[4 * i + 2] = ab->joints[4 * i + 3] = 0;
            ab->weights[4 * i] = 1.0f;
            ab->weights[4 * i + 1] = ab->weights[4 * i + 2] = ab->weights[4 * i + 3] = 0.0f;
        }
    }
    sp_curve* c = &ab->curves[ab->curve_count++];
    memset(c, 0, sizeof *c);
    snprintf(c->name, sizeof c->name, "%s", name);
    c->first_point = first;
    c->point_count = points;
    c->closed = false;
    ab->point_count = total_points;
}
