// stickfig.c: the stick-figure abstraction derived from a skeleton, for
// glTF files without our `sp_abstraction` curves (DESIGN.md).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_internal.h"

typedef struct stick_buf {
    int n, cap;
    double* rest;
    uint16_t* joints;
    float* weights;
} stick_buf;

static bool stick_push(stick_buf* b, const sp_mat4* inv_skin, int joint, sp_vec3 world)
{
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 64;
        double* r = realloc(b->rest, sizeof(double) * 3 * (size_t)cap);
        if (r) b->rest = r;
        uint16_t* j = realloc(b->joints, sizeof(uint16_t) * 4 * (size_t)cap);
        if (j) b->joints = j;
        float* w = realloc(b->weights, sizeof(float) * 4 * (size_t)cap);
        if (w) b->weights = w;
        if (!r || !j || !w) return false;
        b->cap = cap;
    }
    // Why bind space: skinning at the default parameters must give back the
    // world point, x = (G_a IBM_a) x0, like the mesh vertices.
    sp_vec3 x0 = sp_mat4_point(inv_skin, world);
    int i = b->n++;
    b->rest[3 * i] = x0.x, b->rest[3 * i + 1] = x0.y, b->rest[3 * i + 2] = x0.z;
    b->joints[4 * i] = (uint16_t)joint;
    b->joints[4 * i + 1] = b->joints[4 * i + 2] = b->joints[4 * i + 3] = 0;
    b->weights[4 * i] = 1.0f;
    b->weights[4 * i + 1] = b->weights[4 * i + 2] = b->weights[4 * i + 3] = 0.0f;
    return true;
}

sp_result sp_gltf_derive_stick(sp_rig* rig, const bool* is_skin, sp_error* err)
{
    int J = rig->joint_count;
    int* nchild = calloc((size_t)J, sizeof(int));
    int* chain = malloc(sizeof(int) * (size_t)(J + 1));
    double* p = malloc(sizeof(double) * (size_t)(rig->param_count + 1));
    sp_mat4* inv = malloc(sizeof(sp_mat4) * (size_t)J);
    sp_vec3* pos = malloc(sizeof(sp_vec3) * (size_t)J);
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    stick_buf b = {0};
    sp_result r = SP_OK;
    if (!nchild || !chain || !p || !inv || !pos || !ev) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
        goto done;
    }
    sp_rig_defaults(rig, p);
    sp_rig_eval_update(ev, p, false);
    const sp_mat4* world = sp_rig_eval_world(ev);
    const sp_mat4* skin = sp_rig_eval_skin(ev);
    sp_vec3 lo = {0, 0, 0}, hi = {0, 0, 0};
    for (int j = 0; j < J; ++j) {
        sp_mat4_inverse(&skin[j], &inv[j]);
        pos[j] = sp_mat4_translation(&world[j]);
        if (j == 0) lo = hi = pos[j];
        lo = sp_v3(fmin(lo.x, pos[j].x), fmin(lo.y, pos[j].y), fmin(lo.z, pos[j].z));
        hi = sp_v3(fmax(hi.x, pos[j].x), fmax(hi.y, pos[j].y), fmax(hi.z, pos[j].z));
        int pa = rig->joints[j].parent;
        if (pa >= 0 && is_skin[j] && is_skin[pa]) ++nchild[pa];
    }
    // Why relative: bones shorter than a millionth of the skeleton are
    // coincident joints (common at roots) and would give repeated points.
    double eps = 1e-6 * fmax(sp_v3_len(sp_v3_sub(hi, lo)), 1e-12);
    for (int a = 0; a < J; ++a) {
        if (!is_skin[a] || nchild[a] == 0) continue;
        int pa = rig->joints[a].parent;
        bool starts = pa < 0 || !is_skin[pa] || nchild[a] != 1;
        if (!starts) continue;
        for (int c = a + 1; c < J; ++c) {
            if (rig->joints[c].parent != a || !is_skin[c]) continue;
            // The chain a -> c -> ... through single-child joints.
            int len = 0;
            chain[len++] = a;
            int cur = c;
            chain[len++] = cur;
            while (nchild[cur] == 1) {
                int next = -1;
                for (int k = cur + 1; k < J && next < 0; ++k)
                    if (rig->joints[k].parent == cur && is_skin[k]) next = k;
                cur = next;
                chain[len++] = cur;
            }
            b.n = 0;
            int last_u = -1, last_v = -1;
            for (int i = 0; i + 1 < len; ++i) {
                int u = chain[i], v = chain[i + 1];
                sp_vec3 d = sp_v3_sub(pos[v], pos[u]);
                if (!(sp_v3_len(d) > eps)) continue;
                for (int k = 0; k < SP_STICK_POINTS_PER_BONE; ++k)
                    if (!stick_push(&b, &inv[u], u, sp_v3_add(pos[u], sp_v3_scale(d, (double)k / SP_STICK_POINTS_PER_BONE)))) {
                        r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
                        goto done;
                    }
                last_u = u, last_v = v;
            }
            if (last_u < 0) continue;
            if (!stick_push(&b, &inv[last_u], last_u, pos[last_v])) {
                r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
                goto done;
            }
            char name[SP_NAME_MAX];
            snprintf(name, sizeof name, "%.31s-%.31s", rig->joints[chain[0]].name, rig->joints[chain[len - 1]].name);
            if (sp_gltf_append_curve(rig, "stick", SP_CORR_ORDERED, name, false, b.n, b.rest, b.joints, b.weights) != SP_OK) {
                r = sp_fail(err, SP_ERR_NO_MEMORY, "stick figure: out of memory");
                goto done;
            }
        }
    }
done:
    sp_rig_eval_destroy(ev);
    free(nchild), free(chain), free(p), free(inv), free(pos);
    free(b.rest), free(b.joints), free(b.weights);
    return r;
}
