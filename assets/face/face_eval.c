// face_eval.c: evaluates the face rig and exports it as a black-box plugin
// (SP_BLACKBOX_ENTRY). Per point, in order:
//   1. eyeballs turn with the gaze; eyelid shells are placed procedurally
//      (their edges are circles of latitude that swing with lid_close and
//      lid_lower_up);
//   2. shape: eye size (about each eye's centre), nose size (about the nose
//      root), brow height, mouth and jaw width (x scalings);
//   3. blendshapes: x += sum_s p_s * delta_s;
//   4. local deformers: nose bends (rotations about the nose root whose
//      angle grows towards the tip), mouth twist (about the mouth centre,
//      fading with distance), jaw open and side (about the jaw hinge, with
//      smooth weights);
//   5. the neck: head width and squash and stretch of the head, then
//      twist, nod and tilt whose angles ramp up along the neck (bend and
//      twist deformers), all weighted by the point's neck level.
// evaluate() reads only the rig, which nothing writes after it is built, and
// its own stack, so it is safe to call from several threads at once.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "face.h"

// A 3x4 affine transform, row-major.
typedef struct aff {
    double m[12];
} aff;

static aff aff_identity(void)
{
    return (aff){{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}};
}

static aff aff_mul(const aff* a, const aff* b)
{
    aff r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
            double v = a->m[4 * i] * b->m[j] + a->m[4 * i + 1] * b->m[4 + j] + a->m[4 * i + 2] * b->m[8 + j];
            r.m[4 * i + j] = v + (j == 3 ? a->m[4 * i + 3] : 0.0);
        }
    }
    return r;
}

// Rotation with cosine c and sine s about the world axis (0 x, 1 y, 2 z)
// through `pivot`.
static aff aff_rotation(int axis, double c, double s, const double pivot[3])
{
    aff r = aff_identity();
    int i = (axis + 1) % 3, j = (axis + 2) % 3; // the rotated plane, right-handed
    r.m[4 * i + i] = c, r.m[4 * i + j] = -s;
    r.m[4 * j + i] = s, r.m[4 * j + j] = c;
    for (int k = 0; k < 3; ++k) {
        double t = pivot[k];
        for (int l = 0; l < 3; ++l)
            t -= r.m[4 * k + l] * pivot[l];
        r.m[4 * k + 3] = t;
    }
    return r;
}

static inline void aff_apply(const aff* a, double p[3])
{
    double x = p[0], y = p[1], z = p[2];
    p[0] = a->m[0] * x + a->m[1] * y + a->m[2] * z + a->m[3];
    p[1] = a->m[4] * x + a->m[5] * y + a->m[6] * z + a->m[7];
    p[2] = a->m[8] * x + a->m[9] * y + a->m[10] * z + a->m[11];
}

// Cosine and sine of angle * l / F_LEVELS for every level l, by the
// angle-addition recurrence: two library calls per deformer instead of one
// per level (exact at angle 0, ~1e-14 off at the last level otherwise).
typedef struct level_trig {
    double c[F_LEVELS + 1], s[F_LEVELS + 1];
} level_trig;

static void level_angles(double angle, level_trig* t)
{
    double c1 = cos(angle / F_LEVELS), s1 = sin(angle / F_LEVELS);
    t->c[0] = 1, t->s[0] = 0;
    for (int l = 0; l < F_LEVELS; ++l) {
        t->c[l + 1] = t->c[l] * c1 - t->s[l] * s1;
        t->s[l + 1] = t->s[l] * c1 + t->c[l] * s1;
    }
}

// What one evaluation computes once for all points.
typedef struct eval_ctx {
    aff neck[F_LEVELS + 1], jaw[F_LEVELS + 1], mouth[F_LEVELS + 1], nose[F_LEVELS + 1];
    aff look[2];                                                   // eyeball rotations about the eye centres
    double eye[2][3];                                              // eye centres
    double lid_c[2][2][FACE_LID_ROWS], lid_s[2][2][FACE_LID_ROWS]; // [side][upper][row]: cos and sin of the lid angle
    double nose_root[3];
} eval_ctx;

static void prepare(const face_rig* f, const double* p, eval_ctx* c)
{
    double hinge[3] = {0, FACE_HINGE_Y, FACE_HINGE_Z}, neck[3] = {0, FACE_NECK_Y, FACE_NECK_Z}, mouth[3];
    face_mouth_centre(mouth);
    face_nose_root(c->nose_root);
    level_trig tw, nd, tl, jo, js, mt, ns, nu;
    level_angles(p[F_HEAD_TWIST], &tw), level_angles(p[F_HEAD_NOD], &nd), level_angles(p[F_HEAD_TILT], &tl);
    level_angles(0.32 * p[F_JAW_OPEN], &jo), level_angles(0.12 * p[F_JAW_SIDE], &js);
    level_angles(p[F_MOUTH_TWIST], &mt);
    level_angles(p[F_NOSE_BEND_SIDE], &ns), level_angles(-p[F_NOSE_BEND_UP], &nu);
    for (int l = 0; l <= F_LEVELS; ++l) {
        double w = (double)l / F_LEVELS;
        if (f->used[0][l]) {
            // Head width, squash and stretch about the top of the neck
            // (volume kept), then twist, nod and tilt about the neck's pivot.
            double s = 1 + (p[F_FACE_SQUASH] - 1) * w, r = 1 / sqrt(s), hw = 1 + (p[F_HEAD_WIDTH] - 1) * w;
            aff sq = {{r * hw, 0, 0, 0, 0, s, 0, FACE_SQUASH_Y * (1 - s), 0, 0, r, 0}};
            aff a = aff_rotation(1, tw.c[l], tw.s[l], neck), b = aff_rotation(0, nd.c[l], nd.s[l], neck),
                d = aff_rotation(2, tl.c[l], tl.s[l], neck);
            a = aff_mul(&a, &sq);
            a = aff_mul(&b, &a);
            c->neck[l] = aff_mul(&d, &a);
        }
        if (f->used[1][l]) {
            aff op = aff_rotation(0, jo.c[l], jo.s[l], hinge), sd = aff_rotation(1, js.c[l], js.s[l], hinge);
            c->jaw[l] = aff_mul(&sd, &op);
        }
        if (f->used[2][l]) c->mouth[l] = aff_rotation(2, mt.c[l], mt.s[l], mouth);
        if (f->used[3][l]) {
            aff sd = aff_rotation(1, ns.c[l], ns.s[l], c->nose_root), up = aff_rotation(0, nu.c[l], nu.s[l], c->nose_root);
            c->nose[l] = aff_mul(&sd, &up);
        }
    }
    for (int s = 0; s < 2; ++s) {
        face_eye_centre(s, c->eye[s]);
        aff h = aff_rotation(1, cos(p[F_LOOK_H]), sin(p[F_LOOK_H]), c->eye[s]),
            v = aff_rotation(0, cos(-p[F_LOOK_V]), sin(-p[F_LOOK_V]), c->eye[s]);
        c->look[s] = aff_mul(&h, &v);
        double edge[2] = {face_lower_edge(p[s == 0 ? F_LID_LOWER_L : F_LID_LOWER_R]),
                          face_upper_edge(p[s == 0 ? F_LID_CLOSE_L : F_LID_CLOSE_R])};
        for (int u = 0; u < 2; ++u)
            for (int r = 0; r < FACE_LID_ROWS; ++r) {
                double psi = face_lid_psi(u, face_lid_fraction(r), edge[u]);
                c->lid_c[s][u][r] = cos(psi), c->lid_s[s][u][r] = sin(psi);
            }
    }
}

static int evaluate(void* user, const double* params, double* vertices, double* abstraction)
{
    const face_rig* f = user;
    const double* p = params;
    for (int k = 0; k < F_PARAMS; ++k)
        if (!isfinite(p[k])) return 1;
    eval_ctx c;
    prepare(f, p, &c);
    memcpy(vertices, f->rest, sizeof(double) * 3 * (size_t)f->vertex_count);
#define PT(i) (vertices + 3 * (size_t)(i))
    // 1. Eyeballs turn; lids are placed by their angles.
    const face_list* L = f->lists;
    for (const face_item* it = L[FL_EYEBALL].items; it < L[FL_EYEBALL].items + L[FL_EYEBALL].count; ++it)
        aff_apply(&c.look[it->side], PT(it->i));
    for (const face_item* it = L[FL_LID].items; it < L[FL_LID].items + L[FL_LID].count; ++it) {
        double* x = PT(it->i);
        face_lid_point(it->upper, f->lid_cb[it->col], f->lid_sb[it->col], c.lid_c[it->side][it->upper][it->row],
                       c.lid_s[it->side][it->upper][it->row], x);
        for (int k = 0; k < 3; ++k)
            x[k] += c.eye[it->side][k];
    }
    // 2. Shape.
    for (const face_item* it = L[FL_EYE_SIZE].items; it < L[FL_EYE_SIZE].items + L[FL_EYE_SIZE].count; ++it) {
        double* x = PT(it->i);
        const double* e = c.eye[it->side];
        double g = 1 + (p[F_EYE_SIZE] - 1) * it->w;
        for (int k = 0; k < 3; ++k)
            x[k] = e[k] + (x[k] - e[k]) * g;
    }
    for (const face_item* it = L[FL_NOSE_SIZE].items; it < L[FL_NOSE_SIZE].items + L[FL_NOSE_SIZE].count; ++it) {
        double* x = PT(it->i);
        double g = 1 + (p[F_NOSE_SIZE] - 1) * it->w;
        for (int k = 0; k < 3; ++k)
            x[k] = c.nose_root[k] + (x[k] - c.nose_root[k]) * g;
    }
    for (const face_item* it = L[FL_BROW].items; it < L[FL_BROW].items + L[FL_BROW].count; ++it)
        PT(it->i)[1] += p[F_BROW_HEIGHT] * it->w;
    for (const face_item* it = L[FL_XSCALE].items; it < L[FL_XSCALE].items + L[FL_XSCALE].count; ++it)
        PT(it->i)[0] *= (1 + (p[F_MOUTH_WIDTH] - 1) * it->w) * (1 + (p[F_JAW_WIDTH] - 1) * it->w2);
    // 3. Blendshapes.
    for (int s = 0; s < F_PARAMS; ++s) {
        double w = p[s];
        if (w == 0) continue;
        for (const face_entry* e = f->entries + f->shape_first[s]; e < f->entries + f->shape_first[s + 1]; ++e) {
            double* x = PT(e->i);
            x[0] += w * e->d[0], x[1] += w * e->d[1], x[2] += w * e->d[2];
        }
    }
    // 4. Local deformers, 5. the neck.
    for (const face_item* it = L[FL_NOSE_ROT].items; it < L[FL_NOSE_ROT].items + L[FL_NOSE_ROT].count; ++it)
        aff_apply(&c.nose[it->lv], PT(it->i));
    for (const face_item* it = L[FL_MOUTH_ROT].items; it < L[FL_MOUTH_ROT].items + L[FL_MOUTH_ROT].count; ++it)
        aff_apply(&c.mouth[it->lv], PT(it->i));
    for (const face_item* it = L[FL_JAW_ROT].items; it < L[FL_JAW_ROT].items + L[FL_JAW_ROT].count; ++it)
        aff_apply(&c.jaw[it->lv], PT(it->i));
    // The neck level by level: a run's transform stays in registers.
    for (const face_run* run = f->neck_runs; run < f->neck_runs + f->neck_run_count; ++run) {
        const aff a = c.neck[run->lv];
        for (double* x = PT(run->first); x < PT(run->first + run->count); x += 3) {
            double px = x[0], py = x[1], pz = x[2];
            x[0] = a.m[0] * px + a.m[1] * py + a.m[2] * pz + a.m[3];
            x[1] = a.m[4] * px + a.m[5] * py + a.m[6] * pz + a.m[7];
            x[2] = a.m[8] * px + a.m[9] * py + a.m[10] * pz + a.m[11];
        }
    }
    if (abstraction)
        for (int a = 0; a < f->abs_count; ++a)
            memcpy(abstraction + 3 * a, PT(f->abs_index[a]), sizeof(double) * 3);
#undef PT
    return 0;
}

static void release(void* user)
{
    face_free(user);
}

// The plugin's one export. Each call builds an independent rig.
#if defined(__GNUC__)
__attribute__((visibility("default")))
#endif
const sp_blackbox_rig*
sp_blackbox_plugin_v1(void);

const sp_blackbox_rig* sp_blackbox_plugin_v1(void)
{
    face_rig* f = face_build();
    if (!f) return NULL;
    f->desc = (sp_blackbox_rig){
        .abi_version = SP_BLACKBOX_ABI_VERSION,
        .struct_size = sizeof(sp_blackbox_rig),
        .name = "face",
        .param_count = F_PARAMS,
        .params = f->params,
        .vertex_count = f->vertex_count,
        .rest = f->rest,
        .triangle_count = f->triangle_count,
        .triangles = f->triangles,
        .colors = f->colors,
        .abstraction_count = 1,
        .abstractions = &f->abstraction,
        .view_forward = {0, 0, -1},
        .view_up = {0, 1, 0},
        .user = f,
        .evaluate = evaluate,
        .release = release,
    };
    return &f->desc;
}
