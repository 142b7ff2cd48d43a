/// sp/math.h: tiny by-value math for rigs and cameras.
///
/// Everything is `static inline` on small structs. Matrices are 4x4,
/// column-major like glTF and OpenGL: m[col*4 + row]. Quaternions are
/// (x, y, z, w) like glTF. Double precision throughout, because the
/// Jacobian tests compare against central differences to 1e-6 relative.
#ifndef SP_MATH_H
#define SP_MATH_H

#include <math.h>
#include <stdbool.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sp_vec2 { double x, y; } sp_vec2;
typedef struct sp_vec3 { double x, y, z; } sp_vec3;
typedef struct sp_quat { double x, y, z, w; } sp_quat;
/// Column-major 4x4: m[c*4 + r].
typedef struct sp_mat4 { double m[16]; } sp_mat4;

static inline sp_vec3 sp_v3(double x, double y, double z) { return (sp_vec3){x, y, z}; }
static inline sp_vec3 sp_v3_add(sp_vec3 a, sp_vec3 b) { return (sp_vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline sp_vec3 sp_v3_sub(sp_vec3 a, sp_vec3 b) { return (sp_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline sp_vec3 sp_v3_scale(sp_vec3 a, double s) { return (sp_vec3){a.x * s, a.y * s, a.z * s}; }
static inline double sp_v3_dot(sp_vec3 a, sp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline sp_vec3 sp_v3_cross(sp_vec3 a, sp_vec3 b)
{
    return (sp_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline double sp_v3_len(sp_vec3 a) { return sqrt(sp_v3_dot(a, a)); }
static inline sp_vec3 sp_v3_norm(sp_vec3 a)
{
    double l = sp_v3_len(a);
    return l > 0.0 ? sp_v3_scale(a, 1.0 / l) : a;
}
static inline bool sp_v3_is_valid(sp_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

static inline sp_vec2 sp_v2_sub(sp_vec2 a, sp_vec2 b) { return (sp_vec2){a.x - b.x, a.y - b.y}; }
static inline sp_vec2 sp_v2_add(sp_vec2 a, sp_vec2 b) { return (sp_vec2){a.x + b.x, a.y + b.y}; }
static inline sp_vec2 sp_v2_scale(sp_vec2 a, double s) { return (sp_vec2){a.x * s, a.y * s}; }
static inline double sp_v2_dot(sp_vec2 a, sp_vec2 b) { return a.x * b.x + a.y * b.y; }
static inline double sp_v2_len(sp_vec2 a) { return sqrt(a.x * a.x + a.y * a.y); }
static inline bool sp_v2_is_valid(sp_vec2 a) { return isfinite(a.x) && isfinite(a.y); }
/// Distance from p to the segment a-b (a point when a == b).
static inline double sp_v2_segment_dist(sp_vec2 p, sp_vec2 a, sp_vec2 b)
{
    sp_vec2 ab = sp_v2_sub(b, a), ap = sp_v2_sub(p, a);
    double l2 = sp_v2_dot(ab, ab), t = l2 > 0 ? fmin(fmax(sp_v2_dot(ap, ab) / l2, 0), 1) : 0;
    return sp_v2_len(sp_v2_sub(ap, sp_v2_scale(ab, t)));
}

static inline sp_quat sp_quat_identity(void) { return (sp_quat){0, 0, 0, 1}; }
static inline sp_quat sp_quat_mul(sp_quat a, sp_quat b)
{
    return (sp_quat){a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                     a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                     a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
                     a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}
static inline sp_quat sp_quat_norm(sp_quat q)
{
    double l = sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (!(l > 0.0)) return sp_quat_identity();
    return (sp_quat){q.x / l, q.y / l, q.z / l, q.w / l};
}
static inline sp_quat sp_quat_conj(sp_quat q) { return (sp_quat){-q.x, -q.y, -q.z, q.w}; }
/// Rotation of `angle` radians about unit `axis`.
static inline sp_quat sp_quat_axis_angle(sp_vec3 axis, double angle)
{
    double s = sin(0.5 * angle);
    return (sp_quat){axis.x * s, axis.y * s, axis.z * s, cos(0.5 * angle)};
}
static inline sp_vec3 sp_quat_rotate(sp_quat q, sp_vec3 v)
{
    sp_vec3 u = {q.x, q.y, q.z};
    sp_vec3 t = sp_v3_scale(sp_v3_cross(u, v), 2.0);
    return sp_v3_add(sp_v3_add(v, sp_v3_scale(t, q.w)), sp_v3_cross(u, t));
}
/// Spherical interpolation on the short arc (glTF animation semantics).
static inline sp_quat sp_quat_slerp(sp_quat a, sp_quat b, double t)
{
    double d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
    if (d < 0.0) { b = (sp_quat){-b.x, -b.y, -b.z, -b.w}; d = -d; }
    double wa, wb;
    if (d > 0.9995) { wa = 1.0 - t; wb = t; }
    else {
        double th = acos(d), s = sin(th);
        wa = sin((1.0 - t) * th) / s;
        wb = sin(t * th) / s;
    }
    return sp_quat_norm((sp_quat){wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z, wa * a.w + wb * b.w});
}

static inline sp_mat4 sp_mat4_identity(void)
{
    sp_mat4 r = {{0}};
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0;
    return r;
}
static inline sp_mat4 sp_mat4_mul(const sp_mat4* a, const sp_mat4* b)
{
    sp_mat4 r;
    for (int c = 0; c < 4; ++c)
        for (int rr = 0; rr < 4; ++rr) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += a->m[k * 4 + rr] * b->m[c * 4 + k];
            r.m[c * 4 + rr] = s;
        }
    return r;
}
/// Affine point transform (w = 1).
static inline sp_vec3 sp_mat4_point(const sp_mat4* a, sp_vec3 p)
{
    const double* m = a->m;
    return (sp_vec3){m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                     m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]};
}
/// Direction transform (w = 0).
static inline sp_vec3 sp_mat4_dir(const sp_mat4* a, sp_vec3 p)
{
    const double* m = a->m;
    return (sp_vec3){m[0] * p.x + m[4] * p.y + m[8] * p.z, m[1] * p.x + m[5] * p.y + m[9] * p.z,
                     m[2] * p.x + m[6] * p.y + m[10] * p.z};
}
/// T * R * S, the glTF node transform.
static inline sp_mat4 sp_mat4_trs(sp_vec3 t, sp_quat q, sp_vec3 s)
{
    double x = q.x, y = q.y, z = q.z, w = q.w;
    sp_mat4 r = sp_mat4_identity();
    r.m[0] = (1 - 2 * (y * y + z * z)) * s.x;
    r.m[1] = (2 * (x * y + z * w)) * s.x;
    r.m[2] = (2 * (x * z - y * w)) * s.x;
    r.m[4] = (2 * (x * y - z * w)) * s.y;
    r.m[5] = (1 - 2 * (x * x + z * z)) * s.y;
    r.m[6] = (2 * (y * z + x * w)) * s.y;
    r.m[8] = (2 * (x * z + y * w)) * s.z;
    r.m[9] = (2 * (y * z - x * w)) * s.z;
    r.m[10] = (1 - 2 * (x * x + y * y)) * s.z;
    r.m[12] = t.x;
    r.m[13] = t.y;
    r.m[14] = t.z;
    return r;
}
/// General inverse; returns false (and identity) when singular.
static inline bool sp_mat4_inverse(const sp_mat4* a, sp_mat4* out)
{
    const double* m = a->m;
    double inv[16];
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
    double det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    if (!(fabs(det) > 1e-300) || !isfinite(det)) {
        *out = sp_mat4_identity();
        return false;
    }
    det = 1.0 / det;
    for (int i = 0; i < 16; ++i) out->m[i] = inv[i] * det;
    return true;
}
/// sp_mat4_inverse_rel's `rel` for skin and rest matrices: below it a matrix
/// flattens space for any practical purpose (a scale of 1e-7 along one axis),
/// and its inverse would move points a million-fold or past float range.
#define SP_MAT4_FLAT 1e-6
/// The inverse, when the linear (upper 3x3) part is well away from singular
/// whatever its scale: |det| over `rel` times its Frobenius norm cubed (a
/// rotation with any uniform scale gives 3^-1.5); false and the identity
/// otherwise. sp_mat4_inverse's test is absolute (1e-300), right only where
/// the scale is known.
static inline bool sp_mat4_inverse_rel(const sp_mat4* a, double rel, sp_mat4* out)
{
    const double* m = a->m;
    double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[4] * (m[1] * m[10] - m[2] * m[9]) + m[8] * (m[1] * m[6] - m[2] * m[5]);
    double n2 = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            n2 += m[4 * c + r] * m[4 * c + r];
    if (!(fabs(det) > rel * n2 * sqrt(n2))) {
        *out = sp_mat4_identity();
        return false;
    }
    return sp_mat4_inverse(a, out);
}
static inline sp_vec3 sp_mat4_translation(const sp_mat4* a) { return (sp_vec3){a->m[12], a->m[13], a->m[14]}; }
/// The translation by t.
static inline sp_mat4 sp_mat4_translate(sp_vec3 t)
{
    sp_mat4 m = sp_mat4_identity();
    m.m[12] = t.x, m.m[13] = t.y, m.m[14] = t.z;
    return m;
}
/// Transforms n points in place (xyz: n by 3).
static inline void sp_mat4_points(const sp_mat4* a, double* xyz, int n)
{
    for (int i = 0; i < n; ++i) {
        sp_vec3 p = sp_mat4_point(a, (sp_vec3){xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
        xyz[3 * i] = p.x, xyz[3 * i + 1] = p.y, xyz[3 * i + 2] = p.z;
    }
}

/// Unit quaternion of the rotation whose matrix has the orthonormal columns
/// c0, c1, c2 (Shepperd's method: the largest diagonal term divides).
static inline sp_quat sp_quat_from_columns(sp_vec3 c0, sp_vec3 c1, sp_vec3 c2)
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

/// A similarity: x -> t + s R(r) x (uniform scale s > 0). What a glTF node's
/// TRS can hold without shearing whatever hangs below it.
typedef struct sp_sim3 {
    sp_vec3 t;
    sp_quat r;
    double s;
} sp_sim3;
/// The similarity's matrix.
static inline sp_mat4 sp_sim3_mat4(sp_sim3 a) { return sp_mat4_trs(a.t, a.r, (sp_vec3){a.s, a.s, a.s}); }
/// The similarity nearest an affine matrix with a positive determinant: its
/// translation, the cube root of |det| as scale, and the rotation of the
/// first axis and the Gram-Schmidt of the second (good for the
/// near-conformal frames of skinned joints; a degenerate matrix gives the
/// identity rotation and scale 1).
static inline sp_sim3 sp_sim3_from_mat4(const sp_mat4* m)
{
    sp_vec3 c0 = {m->m[0], m->m[1], m->m[2]}, c1 = {m->m[4], m->m[5], m->m[6]}, c2 = {m->m[8], m->m[9], m->m[10]};
    double det = sp_v3_dot(c0, sp_v3_cross(c1, c2));
    double s = cbrt(fabs(det));
    if (!(s > 1e-300) || !isfinite(s)) s = 1.0;
    sp_vec3 x = sp_v3_norm(c0);
    sp_vec3 y = sp_v3_norm(sp_v3_sub(c1, sp_v3_scale(x, sp_v3_dot(x, c1))));
    sp_vec3 z = sp_v3_cross(x, y);
    if (sp_v3_len(x) < 0.5 || sp_v3_len(y) < 0.5) x = sp_v3(1, 0, 0), y = sp_v3(0, 1, 0), z = sp_v3(0, 0, 1);
    return (sp_sim3){sp_mat4_translation(m), sp_quat_from_columns(x, y, z), s};
}

/// qsort comparator of doubles, ascending (NaNs compare equal to anything).
static inline int sp_cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

/// Quantile q (0..1) of n values sorted ascending, the nearest rank rounded
/// up at a half: one rule for the median and the p90, so that the p90 is
/// never below the median (eval rounded the two ways: 15 ms median, 3 ms
/// p90). 0 for none.
static inline double sp_sorted_quantile(const double* sorted, int n, double q)
{
    if (n <= 0) return 0;
    int i = (int)floor(q * (n - 1) + 0.5);
    return sorted[i < 0 ? 0 : i >= n ? n - 1 : i];
}

/// The same for ints (no subtraction, so no overflow).
static inline int sp_cmp_int(const void* a, const void* b)
{
    int x = *(const int*)a, y = *(const int*)b;
    return (x > y) - (x < y);
}

/// The same for floats.
static inline int sp_cmp_float(const void* a, const void* b)
{
    float x = *(const float*)a, y = *(const float*)b;
    return (x > y) - (x < y);
}

/// qsort comparator of C strings (an array of char*), by strcmp.
static inline int sp_cmp_cstr(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }

#ifdef __cplusplus
}
#endif
#endif
