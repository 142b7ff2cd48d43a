// foreign_gltf.c: the lizard of foreign_gltf.h, written as glTF by hand (cJSON
// and a byte buffer), the way exporters elsewhere lay a rigged file out.
#include "foreign_gltf.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/math.h"

const char* const sp_foreign_joint_names[SP_FOREIGN_JOINTS] = {
    "root",         "neck",        "head",         "tail_1",     "tail_2",      "tail_3",     "front_leg_l",
    "front_knee_l", "front_leg_r", "front_knee_r", "hind_leg_l", "hind_knee_l", "hind_leg_r", "hind_knee_r"};

static const double k_pi = 3.14159265358979323846;

// Joints (Y-up, facing +X): parent, pivot, and where its bone points.
static const struct {
    int parent;
    double p[3], to[3];
} k_joints[SP_FOREIGN_JOINTS] = {
    {-1, {0, 0, 0}, {0.55, 0.05, 0}},
    {0, {0.55, 0.05, 0}, {0.95, 0.45, 0}},
    {1, {0.95, 0.45, 0}, {1.45, 0.40, 0}},
    {0, {-0.55, 0, 0}, {-1.05, 0.08, 0}},
    {3, {-1.05, 0.08, 0}, {-1.5, 0.22, 0}},
    {4, {-1.5, 0.22, 0}, {-1.9, 0.40, 0}},
    {0, {0.35, -0.12, 0.18}, {0.42, -0.5, 0.2}},
    {6, {0.42, -0.5, 0.2}, {0.38, -0.85, 0.2}},
    {0, {0.35, -0.12, -0.18}, {0.42, -0.5, -0.2}},
    {8, {0.42, -0.5, -0.2}, {0.38, -0.85, -0.2}},
    {0, {-0.35, -0.12, 0.18}, {-0.45, -0.5, 0.2}},
    {10, {-0.45, -0.5, 0.2}, {-0.38, -0.85, 0.2}},
    {0, {-0.35, -0.12, -0.18}, {-0.45, -0.5, -0.2}},
    {12, {-0.45, -0.5, -0.2}, {-0.38, -0.85, -0.2}},
};

// A tube along a polyline; segment k belongs to joint owner[k]; the radius
// runs through (u, r) pairs along the normalised arc length.
typedef struct tube {
    int n;
    double p[5][3];
    int owner[4];
    int nr;
    double r[4][2];
} tube;

static const tube k_body = {2, {{-0.6, 0, 0}, {0.6, 0.05, 0}}, {0}, 4, {{0, 0.13}, {0.15, 0.21}, {0.85, 0.21}, {1, 0.13}}};
static const tube k_tail = {
    4, {{-0.45, 0, 0}, {-0.55, 0, 0}, {-1.05, 0.08, 0}, {-1.5, 0.22, 0}}, {0, 3, 4}, 3, {{0, 0.17}, {0.5, 0.09}, {1, 0.05}}};
static const tube k_tail_end = {2, {{-1.5, 0.22, 0}, {-1.9, 0.40, 0}}, {5}, 2, {{0, 0.05}, {1, 0.015}}};
static const tube k_head = {4,
                            {{0.45, 0.03, 0}, {0.55, 0.05, 0}, {0.95, 0.45, 0}, {1.45, 0.40, 0}},
                            {0, 1, 2},
                            4,
                            {{0, 0.13}, {0.45, 0.09}, {0.7, 0.16}, {1, 0.04}}};

static sp_vec3 v3(const double* a)
{
    return sp_v3(a[0], a[1], a[2]);
}

typedef struct bytes {
    unsigned char* d;
    size_t n, cap;
    bool oom;
} bytes;

static size_t put(bytes* b, const void* src, size_t n)
{
    while (b->n % 4)
        b->n++;
    if (b->n + n > b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1 << 16;
        while (cap < b->n + n)
            cap *= 2;
        unsigned char* g = realloc(b->d, cap);
        if (!g) {
            b->oom = true;
            return 0;
        }
        memset(g + b->cap, 0, cap - b->cap);
        b->d = g, b->cap = cap;
    }
    size_t at = b->n;
    memcpy(b->d + at, src, n);
    b->n += n;
    return at;
}

// A buffer view and accessor for `count` elements; returns the accessor index.
static int accessor(cJSON* root, bytes* b, const void* data, size_t count, int comp, const char* type, int ncomp, int target)
{
    int csize = comp == 5126 || comp == 5125 ? 4 : comp == 5123 ? 2 : 1;
    size_t at = put(b, data, count * (size_t)ncomp * (size_t)csize);
    cJSON* views = cJSON_GetObjectItem(root, "bufferViews");
    cJSON* view = cJSON_CreateObject();
    cJSON_AddNumberToObject(view, "buffer", 0);
    cJSON_AddNumberToObject(view, "byteOffset", (double)at);
    cJSON_AddNumberToObject(view, "byteLength", (double)(count * (size_t)ncomp * (size_t)csize));
    if (target) cJSON_AddNumberToObject(view, "target", target);
    cJSON_AddItemToArray(views, view);
    cJSON* accs = cJSON_GetObjectItem(root, "accessors");
    cJSON* a = cJSON_CreateObject();
    cJSON_AddNumberToObject(a, "bufferView", cJSON_GetArraySize(views) - 1);
    cJSON_AddNumberToObject(a, "componentType", comp);
    cJSON_AddNumberToObject(a, "count", (double)count);
    cJSON_AddStringToObject(a, "type", type);
    if (comp == 5126 && (!strcmp(type, "VEC3") || !strcmp(type, "SCALAR"))) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        const float* f = data;
        for (size_t i = 0; i < count; ++i)
            for (int c = 0; c < ncomp; ++c)
                lo[c] = fmin(lo[c], f[i * (size_t)ncomp + (size_t)c]), hi[c] = fmax(hi[c], f[i * (size_t)ncomp + (size_t)c]);
        cJSON_AddItemToObject(a, "min", cJSON_CreateDoubleArray(lo, ncomp));
        cJSON_AddItemToObject(a, "max", cJSON_CreateDoubleArray(hi, ncomp));
    }
    cJSON_AddItemToArray(accs, a);
    return cJSON_GetArraySize(accs) - 1;
}

typedef struct prim {
    int nv, ni, cap_v, cap_i;
    float *pos, *uv, *w;
    uint16_t* j;
    uint32_t* idx;
} prim;

static bool prim_grow(prim* p, int nv, int ni)
{
    if (p->nv + nv > p->cap_v) {
        int cap = 2 * (p->nv + nv);
        float* a = realloc(p->pos, sizeof(float) * 3 * (size_t)cap);
        if (a) p->pos = a;
        float* u = realloc(p->uv, sizeof(float) * 2 * (size_t)cap);
        if (u) p->uv = u;
        float* w = realloc(p->w, sizeof(float) * 4 * (size_t)cap);
        if (w) p->w = w;
        uint16_t* j = realloc(p->j, sizeof(uint16_t) * 4 * (size_t)cap);
        if (j) p->j = j;
        if (!a || !u || !w || !j) return false;
        p->cap_v = cap;
    }
    if (p->ni + ni > p->cap_i) {
        int cap = 2 * (p->ni + ni);
        uint32_t* i = realloc(p->idx, sizeof(uint32_t) * (size_t)cap);
        if (!i) return false;
        p->idx = i, p->cap_i = cap;
    }
    return true;
}

static void prim_free(prim* p)
{
    free(p->pos), free(p->uv), free(p->w), free(p->j), free(p->idx);
}

typedef struct shape {
    const sp_foreign_desc* d;
    sp_quat to_model; // world (Y-up) -> stored data (Z-up or not)
    int segments;
    double rings_per_unit;
} shape;

static sp_vec3 place(const shape* s, sp_vec3 p)
{
    if (s->d->facing_left) p.x = -p.x;
    return sp_quat_rotate(s->to_model, p);
}

// Appends a tube, open at both ends.
static bool add_tube(const shape* s, prim* pr, const tube* t)
{
    double len[5] = {0}, total = 0;
    sp_vec3 p[5];
    for (int k = 0; k < t->n; ++k)
        p[k] = v3(t->p[k]);
    for (int k = 0; k + 1 < t->n; ++k)
        total += len[k + 1] = sp_v3_len(sp_v3_sub(p[k + 1], p[k]));
    for (int k = 1; k < t->n; ++k)
        len[k] += len[k - 1];
    int rings = (int)ceil(total * s->rings_per_unit) + 2, S = s->segments;
    if (!prim_grow(pr, rings * S, 6 * (rings - 1) * S)) return false;
    int base = pr->nv;
    for (int i = 0; i < rings; ++i) {
        double at = total * i / (rings - 1);
        int k = 0;
        while (k + 2 < t->n && len[k + 1] < at)
            ++k;
        sp_vec3 T = sp_v3_norm(sp_v3_sub(p[k + 1], p[k]));
        sp_vec3 c = sp_v3_add(p[k], sp_v3_scale(T, at - len[k]));
        // Skin: the segment's joint, blended with the neighbour's within h of a joint.
        const double h = 0.08;
        double wk = 1.0, d0 = at - len[k], d1 = len[k + 1] - at;
        int other = -1;
        if (k > 0 && d0 < h)
            wk = 0.5 + 0.5 * d0 / h, other = t->owner[k - 1];
        else if (k + 2 < t->n && d1 < h)
            wk = 0.5 + 0.5 * d1 / h, other = t->owner[k + 1];
        double u = at / total, r = t->r[0][1];
        for (int q = 0; q + 1 < t->nr; ++q)
            if (u >= t->r[q][0] && u <= t->r[q + 1][0])
                r = t->r[q][1] + (t->r[q + 1][1] - t->r[q][1]) * (u - t->r[q][0]) / (t->r[q + 1][0] - t->r[q][0]);
        sp_vec3 N = fabs(T.z) < 0.9 ? sp_v3_norm(sp_v3_cross(T, sp_v3(0, 0, 1))) : sp_v3(1, 0, 0);
        sp_vec3 B = sp_v3_cross(T, N);
        for (int a = 0; a < S; ++a) {
            double ang = 2 * k_pi * a / S;
            sp_vec3 x = sp_v3_add(c, sp_v3_add(sp_v3_scale(N, r * cos(ang)), sp_v3_scale(B, r * sin(ang))));
            sp_vec3 m = place(s, x);
            int v = pr->nv++;
            pr->pos[3 * v] = (float)m.x, pr->pos[3 * v + 1] = (float)m.y, pr->pos[3 * v + 2] = (float)m.z;
            pr->uv[2 * v] = (float)a / S, pr->uv[2 * v + 1] = (float)u;
            pr->j[4 * v] = (uint16_t)t->owner[k], pr->j[4 * v + 1] = (uint16_t)(other >= 0 ? other : 0);
            pr->j[4 * v + 2] = pr->j[4 * v + 3] = 0;
            pr->w[4 * v] = (float)wk, pr->w[4 * v + 1] = (float)(other >= 0 ? 1.0 - wk : 0.0);
            pr->w[4 * v + 2] = pr->w[4 * v + 3] = 0;
        }
    }
    // Outward triangles (T, N, B right-handed); mirrored data flips them back.
    bool flip = s->d->facing_left;
    for (int i = 0; i + 1 < rings; ++i)
        for (int a = 0; a < S; ++a) {
            uint32_t v00 = (uint32_t)(base + i * S + a), v01 = (uint32_t)(base + i * S + (a + 1) % S);
            uint32_t v10 = v00 + (uint32_t)S, v11 = v01 + (uint32_t)S;
            uint32_t tri[6] = {v00, v01, v11, v00, v11, v10};
            if (flip) tri[1] = v11, tri[2] = v01, tri[4] = v10, tri[5] = v11;
            memcpy(pr->idx + pr->ni, tri, sizeof tri);
            pr->ni += 6;
        }
    return true;
}

// The primitive's attributes (indexed or expanded to plain triangles).
static cJSON* write_prim(cJSON* root, bytes* b, const prim* p, bool indexed, bool skinned, int material)
{
    cJSON* pj = cJSON_CreateObject();
    cJSON* at = cJSON_AddObjectToObject(pj, "attributes");
    prim e = *p;
    prim flat = {0};
    if (!indexed) { // every index its own vertex: no index buffer
        if (!prim_grow(&flat, p->ni, 0)) return NULL;
        for (int i = 0; i < p->ni; ++i) {
            uint32_t v = p->idx[i];
            memcpy(flat.pos + 3 * i, p->pos + 3 * v, 3 * sizeof(float));
            memcpy(flat.uv + 2 * i, p->uv + 2 * v, 2 * sizeof(float));
            memcpy(flat.w + 4 * i, p->w + 4 * v, 4 * sizeof(float));
            memcpy(flat.j + 4 * i, p->j + 4 * v, 4 * sizeof(uint16_t));
        }
        flat.nv = p->ni;
        e = flat;
    }
    cJSON_AddNumberToObject(at, "POSITION", accessor(root, b, e.pos, (size_t)e.nv, 5126, "VEC3", 3, 34962));
    cJSON_AddNumberToObject(at, "TEXCOORD_0", accessor(root, b, e.uv, (size_t)e.nv, 5126, "VEC2", 2, 34962));
    if (skinned) {
        cJSON_AddNumberToObject(at, "JOINTS_0", accessor(root, b, e.j, (size_t)e.nv, 5123, "VEC4", 4, 34962));
        cJSON_AddNumberToObject(at, "WEIGHTS_0", accessor(root, b, e.w, (size_t)e.nv, 5126, "VEC4", 4, 34962));
    }
    if (indexed) cJSON_AddNumberToObject(pj, "indices", accessor(root, b, p->idx, (size_t)p->ni, 5125, "SCALAR", 1, 34963));
    cJSON_AddNumberToObject(pj, "material", material);
    prim_free(&flat);
    return pj;
}

static cJSON* floats(const double* v, int n)
{
    return cJSON_CreateDoubleArray(v, n);
}

int sp_foreign_write(const sp_foreign_desc* d, const char* path)
{
    shape s = {.d = d};
    s.to_model = d->z_up ? sp_quat_axis_angle(sp_v3(1, 0, 0), k_pi / 2) : sp_quat_identity();
    int want = d->vertices > 0 ? d->vertices : 3000;
    s.segments = (int)fmax(6.0, round(sqrt(want / 10.0)));
    // Measured: about 13 S^2 vertices at this spacing; scaled to the request.
    s.rings_per_unit = s.segments / 0.75 * (want / (13.0 * s.segments * s.segments));

    // Joint frames in the stored data: +Y along the bone, rolled about it.
    sp_vec3 pm[SP_FOREIGN_JOINTS];
    sp_quat qm[SP_FOREIGN_JOINTS];
    for (int j = 0; j < SP_FOREIGN_JOINTS; ++j) {
        sp_vec3 p = place(&s, v3(k_joints[j].p)), to = place(&s, v3(k_joints[j].to));
        sp_vec3 y = sp_v3_norm(sp_v3_sub(to, p)), axis = sp_v3_cross(sp_v3(0, 1, 0), y);
        double sa = sp_v3_len(axis), ca = y.y;
        sp_quat arc = sa > 1e-9 ? sp_quat_axis_angle(sp_v3_scale(axis, 1.0 / sa), atan2(sa, ca)) : sp_quat_identity();
        pm[j] = p;
        qm[j] = sp_quat_norm(sp_quat_mul(arc, sp_quat_axis_angle(sp_v3(0, 1, 0), 0.35 * j - 1.0)));
    }

    prim body = {0}, tail = {0}, tip = {0}, legs = {0}, head = {0};
    bool ok = add_tube(&s, &body, &k_body) && add_tube(&s, &tail, &k_tail) && add_tube(&s, &tip, &k_tail_end) &&
              add_tube(&s, &head, &k_head);
    for (int leg = 6; ok && leg < SP_FOREIGN_JOINTS; leg += 2) {
        tube t = {4, {{k_joints[leg].p[0], 0.0, k_joints[leg].p[2]}}, {0, leg, leg + 1}, 2, {{0, 0.075}, {1, 0.045}}};
        memcpy(t.p[1], k_joints[leg].p, sizeof t.p[1]);
        memcpy(t.p[2], k_joints[leg + 1].p, sizeof t.p[2]);
        memcpy(t.p[3], k_joints[leg + 1].to, sizeof t.p[3]);
        ok = add_tube(&s, &legs, &t);
    }
    int nv = body.nv + tail.nv + tip.ni + legs.nv + head.nv; // the tip is not indexed: a vertex per corner
    cJSON* root = cJSON_CreateObject();
    bytes b = {0};
    if (!ok || !root) {
        fprintf(stderr, "sp_foreign_write: out of memory\n");
        nv = -1;
        goto done;
    }
    cJSON* asset = cJSON_AddObjectToObject(root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "sketchpose tests: foreign_gltf (a file made elsewhere)");
    cJSON_AddArrayToObject(root, "bufferViews");
    cJSON_AddArrayToObject(root, "accessors");
    cJSON* nodes = cJSON_AddArrayToObject(root, "nodes");
    // Node 0: the Armature (Z-up -> Y-up when the data is Z-up); 1..14 joints; 15..17 meshes.
    cJSON* arm = cJSON_CreateObject();
    cJSON_AddStringToObject(arm, "name", "Armature");
    if (d->z_up) {
        sp_quat r = sp_quat_conj(s.to_model);
        double q[4] = {r.x, r.y, r.z, r.w};
        cJSON_AddItemToObject(arm, "rotation", floats(q, 4));
    }
    cJSON_AddItemToObject(arm, "children", cJSON_CreateIntArray((const int[]){1}, 1));
    cJSON_AddItemToArray(nodes, arm);
    float ibm[16 * SP_FOREIGN_JOINTS];
    for (int j = 0; j < SP_FOREIGN_JOINTS; ++j) {
        cJSON* n = cJSON_CreateObject();
        cJSON_AddStringToObject(n, "name", sp_foreign_joint_names[j]);
        int pa = k_joints[j].parent;
        sp_vec3 t = pa < 0 ? pm[j] : sp_quat_rotate(sp_quat_conj(qm[pa]), sp_v3_sub(pm[j], pm[pa]));
        sp_quat r = pa < 0 ? qm[j] : sp_quat_norm(sp_quat_mul(sp_quat_conj(qm[pa]), qm[j]));
        double tv[3] = {t.x, t.y, t.z}, rv[4] = {r.x, r.y, r.z, r.w};
        cJSON_AddItemToObject(n, "translation", floats(tv, 3));
        cJSON_AddItemToObject(n, "rotation", floats(rv, 4));
        int kids[SP_FOREIGN_JOINTS], nk = 0;
        for (int c = 0; c < SP_FOREIGN_JOINTS; ++c)
            if (k_joints[c].parent == j) kids[nk++] = 1 + c;
        if (nk) cJSON_AddItemToObject(n, "children", cJSON_CreateIntArray(kids, nk));
        cJSON_AddItemToArray(nodes, n);
        sp_mat4 g = sp_mat4_trs(pm[j], qm[j], sp_v3(1, 1, 1)), inv;
        sp_mat4_inverse(&g, &inv);
        for (int k = 0; k < 16; ++k)
            ibm[16 * j + k] = (float)inv.m[k];
        ibm[16 * j + 3] = ibm[16 * j + 7] = ibm[16 * j + 11] = 0.0f, ibm[16 * j + 15] = 1.0f;
    }
    bool skinned = !d->no_skin;
    cJSON* skins = cJSON_AddArrayToObject(root, "skins");
    int joints_of_skin[SP_FOREIGN_JOINTS];
    for (int j = 0; j < SP_FOREIGN_JOINTS; ++j)
        joints_of_skin[j] = 1 + j;
    for (int k = 0; skinned && k < (d->two_skins ? 2 : 1); ++k) {
        cJSON* sk = cJSON_CreateObject();
        cJSON_AddNumberToObject(sk, "inverseBindMatrices", accessor(root, &b, ibm, SP_FOREIGN_JOINTS, 5126, "MAT4", 16, 0));
        cJSON_AddItemToObject(sk, "joints", cJSON_CreateIntArray(joints_of_skin, SP_FOREIGN_JOINTS));
        cJSON_AddNumberToObject(sk, "skeleton", 1);
        cJSON_AddItemToArray(skins, sk);
    }
    // Materials: a green skin (textured when asked, with the image missing), dark legs.
    cJSON* mats = cJSON_AddArrayToObject(root, "materials");
    for (int m = 0; m < 2; ++m) {
        cJSON* mat = cJSON_CreateObject();
        cJSON* pbr = cJSON_AddObjectToObject(mat, "pbrMetallicRoughness");
        double col[2][4] = {{0.35, 0.62, 0.25, 1}, {0.2, 0.3, 0.15, 1}};
        cJSON_AddItemToObject(pbr, "baseColorFactor", floats(col[m], 4));
        cJSON_AddNumberToObject(pbr, "metallicFactor", 0);
        if (m == 0 && d->missing_texture) {
            cJSON* tex = cJSON_AddObjectToObject(pbr, "baseColorTexture");
            cJSON_AddNumberToObject(tex, "index", 0);
        }
        cJSON_AddItemToArray(mats, mat);
    }
    if (d->missing_texture) {
        cJSON* img = cJSON_CreateObject();
        cJSON_AddStringToObject(img, "uri", "lizard_skin.png");
        cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "images"), img);
        cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "samplers"), cJSON_CreateObject());
        cJSON* tex = cJSON_CreateObject();
        cJSON_AddNumberToObject(tex, "sampler", 0);
        cJSON_AddNumberToObject(tex, "source", 0);
        cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "textures"), tex);
    }
    // Meshes: body (body, tail, and the tail's tip not indexed: three primitives), legs, head.
    cJSON* meshes = cJSON_AddArrayToObject(root, "meshes");
    const char* names[3] = {"body", "legs", "head"};
    for (int m = 0; m < 3; ++m) {
        cJSON* mesh = cJSON_CreateObject();
        cJSON_AddStringToObject(mesh, "name", names[m]);
        cJSON* ps = cJSON_AddArrayToObject(mesh, "primitives");
        if (m == 0) {
            cJSON_AddItemToArray(ps, write_prim(root, &b, &body, true, skinned, 0));
            cJSON_AddItemToArray(ps, write_prim(root, &b, &tail, true, skinned, 0));
            cJSON_AddItemToArray(ps, write_prim(root, &b, &tip, false, skinned, 0));
        } else {
            cJSON_AddItemToArray(ps, write_prim(root, &b, m == 1 ? &legs : &head, true, skinned, m == 1 ? 1 : 0));
        }
        cJSON_AddItemToArray(meshes, mesh);
        cJSON* n = cJSON_CreateObject();
        cJSON_AddStringToObject(n, "name", names[m]);
        cJSON_AddNumberToObject(n, "mesh", m);
        if (skinned) cJSON_AddNumberToObject(n, "skin", m == 1 && d->two_skins ? 1 : 0);
        cJSON_AddItemToArray(nodes, n);
    }
    cJSON* scene = cJSON_CreateObject();
    cJSON_AddItemToObject(scene, "nodes", cJSON_CreateIntArray((const int[]){0, 15, 16, 17}, 4));
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "scenes"), scene);
    cJSON_AddNumberToObject(root, "scene", 0);
    // The clip: tail, neck and legs sway in the side view, keyed as absolute
    // local rotations about the axis that is world Z in each joint's frame.
    if (!d->no_clip) {
        enum { KEYS = 21 };
        float times[KEYS];
        for (int k = 0; k < KEYS; ++k)
            times[k] = (float)((double)k / 10.0 * (d->clip_scale > 0 ? d->clip_scale : 1));
        cJSON* an = cJSON_CreateObject();
        cJSON_AddStringToObject(an, "name", "sway");
        cJSON* ch = cJSON_AddArrayToObject(an, "channels");
        cJSON* smp = cJSON_AddArrayToObject(an, "samplers");
        int input = accessor(root, &b, times, KEYS, 5126, "SCALAR", 1, 0);
        sp_vec3 up_axis = sp_quat_rotate(s.to_model, sp_v3(0, 0, 1));
        for (int j = 1; j < SP_FOREIGN_JOINTS; ++j) {
            double amp = j >= 3 && j <= 5 ? 0.25 : j >= 6 ? 0.3 : 0.12;
            sp_vec3 local = sp_quat_rotate(sp_quat_conj(qm[j]), up_axis);
            int pa = k_joints[j].parent;
            sp_quat rest = pa < 0 ? qm[j] : sp_quat_norm(sp_quat_mul(sp_quat_conj(qm[pa]), qm[j]));
            float q[4 * KEYS];
            for (int k = 0; k < KEYS; ++k) {
                // Mirrored data moves mirrored: the turn's sense flips.
                double a = (d->facing_left ? -amp : amp) * sin(2 * k_pi * k / (KEYS - 1) - 0.6 * j);
                sp_quat r = sp_quat_norm(sp_quat_mul(rest, sp_quat_axis_angle(local, a)));
                q[4 * k] = (float)r.x, q[4 * k + 1] = (float)r.y, q[4 * k + 2] = (float)r.z, q[4 * k + 3] = (float)r.w;
            }
            cJSON* sm = cJSON_CreateObject();
            cJSON_AddNumberToObject(sm, "input", input);
            cJSON_AddNumberToObject(sm, "output", accessor(root, &b, q, KEYS, 5126, "VEC4", 4, 0));
            cJSON_AddStringToObject(sm, "interpolation", "LINEAR");
            cJSON_AddItemToArray(smp, sm);
            cJSON* c = cJSON_CreateObject();
            cJSON_AddNumberToObject(c, "sampler", cJSON_GetArraySize(smp) - 1);
            cJSON* target = cJSON_AddObjectToObject(c, "target");
            cJSON_AddNumberToObject(target, "node", 1 + j);
            cJSON_AddStringToObject(target, "path", "rotation");
            cJSON_AddItemToArray(ch, c);
        }
        cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "animations"), an);
    }
    while (b.n % 4)
        b.n++;
    if (b.oom || b.n > b.cap) {
        fprintf(stderr, "sp_foreign_write: out of memory\n");
        nv = -1;
        goto done;
    }
    size_t plen = strlen(path);
    bool gltf = plen > 5 && !strcmp(path + plen - 5, ".gltf");
    cJSON* buffer = cJSON_CreateObject();
    cJSON_AddNumberToObject(buffer, "byteLength", (double)b.n);
    char bin_path[4096], bin_uri[4096];
    if (gltf) {
        snprintf(bin_path, sizeof bin_path, "%.*s.bin", (int)(plen - 5), path);
        const char* base = strrchr(bin_path, '/');
        snprintf(bin_uri, sizeof bin_uri, "%s", base ? base + 1 : bin_path);
        cJSON_AddStringToObject(buffer, "uri", bin_uri);
    }
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "buffers"), buffer);
    char* json = cJSON_PrintUnformatted(root);
    FILE* f = fopen(path, "wb");
    bool wrote = json && f;
    if (wrote && gltf) {
        wrote = fwrite(json, 1, strlen(json), f) == strlen(json);
        FILE* bf = fopen(bin_path, "wb");
        wrote = wrote && bf && fwrite(b.d, 1, b.n, bf) == b.n;
        if (bf) wrote = fclose(bf) == 0 && wrote;
    } else if (wrote) {
        size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3;
        uint32_t head[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + jp + 8 + b.n), (uint32_t)jp, 0x4E4F534Au};
        uint32_t bin_head[2] = {(uint32_t)b.n, 0x004E4942u};
        wrote = fwrite(head, 4, 5, f) == 5 && fwrite(json, 1, jl, f) == jl && fwrite("   ", 1, jp - jl, f) == jp - jl &&
                fwrite(bin_head, 4, 2, f) == 2 && fwrite(b.d, 1, b.n, f) == b.n;
    }
    if (f) wrote = fclose(f) == 0 && wrote;
    free(json);
    if (!wrote) {
        fprintf(stderr, "sp_foreign_write: %s: cannot write\n", path);
        nv = -1;
    }
done:
    cJSON_Delete(root);
    free(b.d);
    prim_free(&body), prim_free(&tail), prim_free(&tip), prim_free(&legs), prim_free(&head);
    return nv;
}
