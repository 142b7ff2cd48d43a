// rig.c: the rig as data: validation, parameters, the TRS parameterisation,
// animation sampling and animations through key poses. Evaluation (FK,
// skinning, Jacobians) is in eval.c.
#include "sp/rig.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* const k_channel_names[SP_CH_COUNT] = {"rx", "ry", "rz", "tx", "ty", "tz", "sx", "sy", "sz", "s"};

const char* sp_channel_name(sp_channel c) { return (unsigned)c < SP_CH_COUNT ? k_channel_names[c] : NULL; }

sp_channel sp_channel_parse(const char* s)
{
    for (int i = 0; i < SP_CH_COUNT; ++i)
        if (s && !strcmp(s, k_channel_names[i])) return (sp_channel)i;
    return SP_CH_COUNT;
}

static double channel_default(sp_channel c) { return sp_channel_is_scale(c) ? 1.0 : 0.0; }

int sp_rig_add_param(sp_rig* rig, int joint, sp_channel ch, double min, double max, sp_group group)
{
    if (joint < 0 || joint >= rig->joint_count || (unsigned)ch >= SP_CH_COUNT) return -1;
    sp_param* grown = realloc(rig->params, sizeof(sp_param) * (size_t)(rig->param_count + 1));
    if (!grown) return -1;
    rig->params = grown;
    sp_param* p = &rig->params[rig->param_count];
    memset(p, 0, sizeof *p);
    p->joint = joint;
    p->channel = ch;
    p->min = min;
    p->max = max;
    p->def = channel_default(ch);
    p->group = group;
    snprintf(p->name, sizeof p->name, "%s.%s", rig->joints[joint].name, k_channel_names[ch]);
    return rig->param_count++;
}

static int cmp_param(const void* a, const void* b)
{
    const sp_param* x = a;
    const sp_param* y = b;
    if (x->joint != y->joint) return x->joint < y->joint ? -1 : 1;
    return (int)x->channel - (int)y->channel;
}

static bool finite3(const double* v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

// Checks and renormalises one set of skinned points; `kind` names it in errors.
static sp_result check_skinned(int n, double* rest, uint16_t* joints, float* weights, int joint_count, const char* what,
                               const char* kind, int* renormalised, sp_error* err)
{
    for (int i = 0; i < n; ++i) {
        if (!finite3(rest + 3 * i)) return sp_fail(err, SP_ERR_INVALID, "%s: %s %d has a non-finite position", what, kind, i);
        double sum = 0.0;
        for (int k = 0; k < SP_INFLUENCES; ++k) {
            float w = weights[4 * i + k];
            if (!isfinite(w) || w < 0.0f)
                return sp_fail(err, SP_ERR_INVALID, "%s: %s %d has an invalid skin weight", what, kind, i);
            if (w > 0.0f && joints[4 * i + k] >= joint_count)
                return sp_fail(err, SP_ERR_INVALID, "%s: %s %d uses joint %d, but the skin has %d", what, kind, i,
                               joints[4 * i + k], joint_count);
            if (w == 0.0f && joints[4 * i + k] >= joint_count) joints[4 * i + k] = 0;
            sum += w;
        }
        if (!(sum > 1e-8)) return sp_fail(err, SP_ERR_INVALID, "%s: %s %d has no skin weight", what, kind, i);
        // Why 2e-3: exporters write weights quantised to 8 or 16 bits; only
        // clearly wrong sums count as renormalised (glTF validator tolerance).
        if (fabs(sum - 1.0) > 2e-3) ++*renormalised;
        for (int k = 0; k < SP_INFLUENCES; ++k) weights[4 * i + k] = (float)(weights[4 * i + k] / sum);
    }
    return SP_OK;
}

sp_result sp_rig_finalize(sp_rig* rig, const char* what, int* renormalised, sp_error* err)
{
    if (!what) what = "rig";
    int renorm = 0;
    if (rig->joint_count <= 0 || !rig->joints) return sp_fail(err, SP_ERR_INVALID, "%s: the rig has no joints", what);
    if (rig->joint_count > 65535) return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: %d joints (65535 at most)", what, rig->joint_count);
    for (int j = 0; j < rig->joint_count; ++j) {
        sp_joint* jt = &rig->joints[j];
        if (jt->parent >= j || jt->parent < -1)
            return sp_fail(err, SP_ERR_INVALID, "%s: joint '%s' comes before its parent", what, jt->name);
        double t[3] = {jt->rest_t.x, jt->rest_t.y, jt->rest_t.z}, s[3] = {jt->rest_s.x, jt->rest_s.y, jt->rest_s.z};
        double q2 = jt->rest_r.x * jt->rest_r.x + jt->rest_r.y * jt->rest_r.y + jt->rest_r.z * jt->rest_r.z + jt->rest_r.w * jt->rest_r.w;
        if (!finite3(t) || !finite3(s) || !isfinite(q2))
            return sp_fail(err, SP_ERR_INVALID, "%s: joint '%s' has a non-finite rest transform", what, jt->name);
        if (!(q2 > 1e-12)) return sp_fail(err, SP_ERR_INVALID, "%s: joint '%s' has a zero rotation quaternion", what, jt->name);
        jt->rest_r = sp_quat_norm(jt->rest_r);
        if (s[0] == 0.0 || s[1] == 0.0 || s[2] == 0.0)
            return sp_fail(err, SP_ERR_INVALID, "%s: joint '%s' has a zero rest scale", what, jt->name);
        for (int k = 0; k < 16; ++k)
            if (!isfinite(jt->inverse_bind.m[k]))
                return sp_fail(err, SP_ERR_INVALID, "%s: joint '%s' has a non-finite inverse bind matrix", what, jt->name);
        jt->first_param = 0;
        jt->param_count = 0;
    }
    // Parameters: sorted by joint then channel, unique, bounded, named.
    if (rig->param_count > 0) qsort(rig->params, (size_t)rig->param_count, sizeof(sp_param), cmp_param);
    for (int i = 0; i < rig->param_count; ++i) {
        sp_param* p = &rig->params[i];
        if (p->joint < 0 || p->joint >= rig->joint_count || (unsigned)p->channel >= SP_CH_COUNT)
            return sp_fail(err, SP_ERR_INVALID, "%s: parameter %d has an invalid joint or channel", what, i);
        const char* jn = rig->joints[p->joint].name;
        if (i > 0 && rig->params[i - 1].joint == p->joint && rig->params[i - 1].channel == p->channel)
            return sp_fail(err, SP_ERR_INVALID, "%s: joint '%s' declares channel %s twice", what, jn, k_channel_names[p->channel]);
        if (!isfinite(p->min) || !isfinite(p->max) || !(p->min <= p->max))
            return sp_fail(err, SP_ERR_INVALID, "%s: parameter %s.%s has invalid bounds [%g, %g]", what, jn,
                           k_channel_names[p->channel], p->min, p->max);
        if (sp_channel_is_scale(p->channel) && !(p->min > 0.0))
            return sp_fail(err, SP_ERR_INVALID, "%s: scale parameter %s.%s must have min > 0 (got %g)", what, jn,
                           k_channel_names[p->channel], p->min);
        if (!isfinite(p->def) || p->def < p->min || p->def > p->max)
            return sp_fail(err, SP_ERR_INVALID, "%s: parameter %s.%s: rest value %g is outside its bounds [%g, %g]", what, jn,
                           k_channel_names[p->channel], p->def, p->min, p->max);
        snprintf(p->name, sizeof p->name, "%s.%s", jn, k_channel_names[p->channel]);
        sp_joint* jt = &rig->joints[p->joint];
        if (jt->param_count == 0) jt->first_param = i;
        ++jt->param_count;
    }
    sp_result r = check_skinned(rig->vertex_count, rig->rest, rig->joints4, rig->weights4, rig->joint_count, what, "vertex",
                                &renorm, err);
    if (r != SP_OK) return r;
    for (int t = 0; t < 3 * rig->triangle_count; ++t)
        if (rig->triangles[t] >= (uint32_t)rig->vertex_count)
            return sp_fail(err, SP_ERR_INVALID, "%s: triangle %d uses vertex %u, but there are %d", what, t / 3,
                           rig->triangles[t], rig->vertex_count);
    for (int a = 0; a < rig->abstraction_count; ++a) {
        sp_abstraction* ab = &rig->abstractions[a];
        bool embedded = ab->tri_vertices != NULL;
        if (embedded == (ab->rest != NULL))
            return sp_fail(err, SP_ERR_INVALID, "%s: abstraction '%s' must be either skinned or embedded", what, ab->name);
        if (ab->curve_count <= 0) return sp_fail(err, SP_ERR_INVALID, "%s: abstraction '%s' has no curves", what, ab->name);
        for (int c = 0; c < ab->curve_count; ++c) {
            const sp_curve* cv = &ab->curves[c];
            if (cv->point_count < 2 || cv->first_point < 0 || cv->first_point + cv->point_count > ab->point_count)
                return sp_fail(err, SP_ERR_INVALID, "%s: curve '%s' of abstraction '%s' has fewer than 2 points or a bad range",
                               what, cv->name, ab->name);
        }
        if (!embedded) {
            r = check_skinned(ab->point_count, ab->rest, ab->joints, ab->weights, rig->joint_count, what, "abstraction point",
                              &renorm, err);
            if (r != SP_OK) return r;
        } else {
            for (int i = 0; i < 3 * ab->point_count; ++i)
                if (ab->tri_vertices[i] >= (uint32_t)rig->vertex_count || !isfinite(ab->bary[i]))
                    return sp_fail(err, SP_ERR_INVALID, "%s: abstraction '%s' point %d is embedded in an invalid triangle", what,
                                   ab->name, i / 3);
        }
    }
    for (int a = 0; a < rig->animation_count; ++a) {
        sp_animation* an = &rig->animations[a];
        double dur = 0.0;
        for (int c = 0; c < an->channel_count; ++c) {
            sp_anim_channel* ch = &an->channels[c];
            int comps = ch->path == SP_ANIM_ROTATION ? 4 : 3;
            int per = comps * (ch->interp == SP_INTERP_CUBICSPLINE ? 3 : 1);
            if (ch->joint < 0 || ch->joint >= rig->joint_count || ch->key_count < 1)
                return sp_fail(err, SP_ERR_INVALID, "%s: animation '%s' channel %d targets no joint or has no keys", what, an->name, c);
            for (int k = 0; k < ch->key_count; ++k) {
                if (!isfinite(ch->times[k]) || (k > 0 && !(ch->times[k] > ch->times[k - 1])))
                    return sp_fail(err, SP_ERR_INVALID, "%s: animation '%s' channel %d has key times that do not increase", what,
                                   an->name, c);
                for (int v = 0; v < per; ++v)
                    if (!isfinite(ch->values[k * per + v]))
                        return sp_fail(err, SP_ERR_INVALID, "%s: animation '%s' channel %d has a non-finite value", what, an->name, c);
            }
            if (ch->times[ch->key_count - 1] > dur) dur = ch->times[ch->key_count - 1];
        }
        an->duration_s = dur;
    }
    if (renormalised) *renormalised = renorm;
    return SP_OK;
}

void sp_abstraction_free(sp_abstraction* a)
{
    if (!a) return;
    free(a->curves);
    free(a->rest);
    free(a->joints);
    free(a->weights);
    free(a->tri_vertices);
    free(a->bary);
    memset(a, 0, sizeof *a);
}

void sp_rig_free(sp_rig* rig)
{
    if (!rig) return;
    free(rig->joints);
    free(rig->params);
    free(rig->rest);
    free(rig->joints4);
    free(rig->weights4);
    free(rig->triangles);
    for (int a = 0; a < rig->abstraction_count; ++a) sp_abstraction_free(&rig->abstractions[a]);
    free(rig->abstractions);
    for (int a = 0; a < rig->animation_count; ++a) {
        for (int c = 0; c < rig->animations[a].channel_count; ++c) {
            free(rig->animations[a].channels[c].times);
            free(rig->animations[a].channels[c].values);
        }
        free(rig->animations[a].channels);
    }
    free(rig->animations);
    memset(rig, 0, sizeof *rig);
}

// malloc+memcpy that treats n == 0 as "nothing to copy, NULL result".
static bool dup(void** dst, const void* src, size_t n)
{
    *dst = NULL;
    if (!src || n == 0) return true;
    *dst = malloc(n);
    if (!*dst) return false;
    memcpy(*dst, src, n);
    return true;
}

sp_result sp_rig_clone(const sp_rig* s, sp_rig* d)
{
    memset(d, 0, sizeof *d);
    d->joint_count = s->joint_count;
    d->param_count = s->param_count;
    d->vertex_count = s->vertex_count;
    d->triangle_count = s->triangle_count;
    size_t nv = (size_t)s->vertex_count;
    bool ok = dup((void**)&d->joints, s->joints, sizeof(sp_joint) * (size_t)s->joint_count) &&
              dup((void**)&d->params, s->params, sizeof(sp_param) * (size_t)s->param_count) &&
              dup((void**)&d->rest, s->rest, sizeof(double) * 3 * nv) &&
              dup((void**)&d->joints4, s->joints4, sizeof(uint16_t) * 4 * nv) &&
              dup((void**)&d->weights4, s->weights4, sizeof(float) * 4 * nv) &&
              dup((void**)&d->triangles, s->triangles, sizeof(uint32_t) * 3 * (size_t)s->triangle_count);
    if (ok && s->abstraction_count > 0) {
        d->abstractions = calloc((size_t)s->abstraction_count, sizeof(sp_abstraction));
        ok = d->abstractions != NULL;
        for (int a = 0; ok && a < s->abstraction_count; ++a) {
            const sp_abstraction* sa = &s->abstractions[a];
            sp_abstraction* da = &d->abstractions[a];
            ++d->abstraction_count;
            *da = *sa;
            size_t np = (size_t)sa->point_count;
            ok = dup((void**)&da->curves, sa->curves, sizeof(sp_curve) * (size_t)sa->curve_count) &&
                 dup((void**)&da->rest, sa->rest, sizeof(double) * 3 * np) &&
                 dup((void**)&da->joints, sa->joints, sizeof(uint16_t) * 4 * np) &&
                 dup((void**)&da->weights, sa->weights, sizeof(float) * 4 * np) &&
                 dup((void**)&da->tri_vertices, sa->tri_vertices, sizeof(uint32_t) * 3 * np) &&
                 dup((void**)&da->bary, sa->bary, sizeof(double) * 3 * np);
        }
    }
    if (ok && s->animation_count > 0) {
        d->animations = calloc((size_t)s->animation_count, sizeof(sp_animation));
        ok = d->animations != NULL;
        for (int a = 0; ok && a < s->animation_count; ++a) {
            const sp_animation* sa = &s->animations[a];
            sp_animation* da = &d->animations[a];
            ++d->animation_count;
            *da = *sa;
            da->channels = NULL;
            da->channel_count = 0;
            if (sa->channel_count > 0) {
                da->channels = calloc((size_t)sa->channel_count, sizeof(sp_anim_channel));
                ok = da->channels != NULL;
            }
            for (int c = 0; ok && c < sa->channel_count; ++c) {
                const sp_anim_channel* sc = &sa->channels[c];
                sp_anim_channel* dc = &da->channels[c];
                ++da->channel_count;
                *dc = *sc;
                int per = (sc->path == SP_ANIM_ROTATION ? 4 : 3) * (sc->interp == SP_INTERP_CUBICSPLINE ? 3 : 1);
                ok = dup((void**)&dc->times, sc->times, sizeof(float) * (size_t)sc->key_count) &&
                     dup((void**)&dc->values, sc->values, sizeof(float) * (size_t)(sc->key_count * per));
            }
        }
    }
    if (!ok) {
        sp_rig_free(d);
        return SP_ERR_NO_MEMORY;
    }
    return SP_OK;
}

int sp_rig_find_joint(const sp_rig* rig, const char* name)
{
    for (int j = 0; j < rig->joint_count; ++j)
        if (!strcmp(rig->joints[j].name, name)) return j;
    return -1;
}

int sp_rig_find_param(const sp_rig* rig, const char* name)
{
    for (int i = 0; i < rig->param_count; ++i)
        if (!strcmp(rig->params[i].name, name)) return i;
    return -1;
}

int sp_rig_find_abstraction(const sp_rig* rig, const char* name)
{
    for (int i = 0; i < rig->abstraction_count; ++i)
        if (!strcmp(rig->abstractions[i].name, name)) return i;
    return -1;
}

void sp_rig_defaults(const sp_rig* rig, double* p)
{
    for (int i = 0; i < rig->param_count; ++i) p[i] = rig->params[i].def;
}

int sp_params_clamp(const sp_param* params, int count, double* p)
{
    int changed = 0;
    for (int i = 0; i < count; ++i) {
        double v = sp_param_clamp(p[i], params[i].min, params[i].max, params[i].def);
        if (v != p[i]) ++changed;
        p[i] = v;
    }
    return changed;
}

int sp_rig_clamp(const sp_rig* rig, double* p)
{
    return sp_params_clamp(rig->params, rig->param_count, p);
}

// The quaternion of one rotation channel about the joint's own rest axis.
static sp_quat axis_quat(sp_channel c, double angle)
{
    sp_vec3 axis = {c == SP_CH_RX, c == SP_CH_RY, c == SP_CH_RZ};
    return sp_quat_axis_angle(axis, angle);
}

void sp_rig_local_trs(const sp_rig* rig, int joint, const double* p, sp_vec3* t, sp_quat* r, sp_vec3* s)
{
    const sp_joint* jt = &rig->joints[joint];
    double ch[SP_CH_COUNT] = {0, 0, 0, 0, 0, 0, 1, 1, 1, 1};
    for (int i = 0; i < jt->param_count; ++i) {
        const sp_param* q = &rig->params[jt->first_param + i];
        ch[q->channel] = p[jt->first_param + i];
    }
    *t = (sp_vec3){jt->rest_t.x + ch[SP_CH_TX], jt->rest_t.y + ch[SP_CH_TY], jt->rest_t.z + ch[SP_CH_TZ]};
    sp_quat q = jt->rest_r;
    // Why fixed X, Y, Z order: a stable convention that the inverse
    // (sp_rig_params_from_trs) and the Jacobian share.
    if (ch[SP_CH_RX] != 0.0) q = sp_quat_mul(q, axis_quat(SP_CH_RX, ch[SP_CH_RX]));
    if (ch[SP_CH_RY] != 0.0) q = sp_quat_mul(q, axis_quat(SP_CH_RY, ch[SP_CH_RY]));
    if (ch[SP_CH_RZ] != 0.0) q = sp_quat_mul(q, axis_quat(SP_CH_RZ, ch[SP_CH_RZ]));
    *r = q;
    *s = (sp_vec3){jt->rest_s.x * ch[SP_CH_SX] * ch[SP_CH_S], jt->rest_s.y * ch[SP_CH_SY] * ch[SP_CH_S],
                   jt->rest_s.z * ch[SP_CH_SZ] * ch[SP_CH_S]};
}

void sp_rig_params_from_trs(const sp_rig* rig, int joint, sp_vec3 t, sp_quat r, sp_vec3 s, double* p)
{
    const sp_joint* jt = &rig->joints[joint];
    // Rotation offset q = rest^-1 * r, as R = Rx(a) Ry(b) Rz(c).
    sp_quat q = sp_quat_norm(sp_quat_mul(sp_quat_conj(jt->rest_r), sp_quat_norm(r)));
    sp_mat4 m = sp_mat4_trs((sp_vec3){0, 0, 0}, q, (sp_vec3){1, 1, 1});
    double m00 = m.m[0], m01 = m.m[4], m02 = m.m[8], m12 = m.m[9], m22 = m.m[10];
    double b = asin(fmax(-1.0, fmin(1.0, m02)));
    double a = atan2(-m12, m22);
    double c = atan2(-m01, m00);
    double ch[SP_CH_COUNT] = {a, b, c, t.x - jt->rest_t.x, t.y - jt->rest_t.y, t.z - jt->rest_t.z,
                              s.x / jt->rest_s.x, s.y / jt->rest_s.y, s.z / jt->rest_s.z, 1.0};
    bool has_axis_scale = false;
    for (int i = 0; i < jt->param_count; ++i) {
        sp_channel c2 = rig->params[jt->first_param + i].channel;
        has_axis_scale |= c2 == SP_CH_SX || c2 == SP_CH_SY || c2 == SP_CH_SZ;
    }
    // A joint with only a uniform scale channel takes the mean factor.
    ch[SP_CH_S] = has_axis_scale ? 1.0 : (ch[SP_CH_SX] + ch[SP_CH_SY] + ch[SP_CH_SZ]) / 3.0;
    for (int i = 0; i < jt->param_count; ++i) {
        int k = jt->first_param + i;
        const sp_param* pp = &rig->params[k];
        p[k] = sp_param_clamp(ch[pp->channel], pp->min, pp->max, pp->def);
    }
}

// Index of the key interval for time t: keys[i] <= t < keys[i+1].
static int find_key(const float* times, int n, double t)
{
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (times[mid] <= t) lo = mid;
        else hi = mid;
    }
    return lo;
}

const sp_animation* sp_rig_first_clip(const sp_rig* rig, double* start, double* end)
{
    for (int a = 0; a < rig->animation_count; ++a) {
        const sp_animation* an = &rig->animations[a];
        double t0 = INFINITY, t1 = -INFINITY;
        for (int k = 0; k < an->channel_count; ++k)
            if (an->channels[k].key_count > 0) {
                t0 = fmin(t0, an->channels[k].times[0]);
                t1 = fmax(t1, an->channels[k].times[an->channels[k].key_count - 1]);
            }
        if (t1 - t0 > 1e-3 && isfinite(t1 - t0)) {
            *start = t0, *end = t1;
            return an;
        }
    }
    return NULL;
}

void sp_animation_sample(const sp_animation* anim, double t, sp_vec3* trans, sp_quat* rot, sp_vec3* scale)
{
    for (int c = 0; c < anim->channel_count; ++c) {
        const sp_anim_channel* ch = &anim->channels[c];
        int comps = ch->path == SP_ANIM_ROTATION ? 4 : 3;
        bool cubic = ch->interp == SP_INTERP_CUBICSPLINE;
        int stride = comps * (cubic ? 3 : 1), off = cubic ? comps : 0;
        double v[4] = {0, 0, 0, 1};
        const float* times = ch->times;
        int n = ch->key_count;
        if (n == 1 || t <= times[0]) {
            for (int i = 0; i < comps; ++i) v[i] = ch->values[off + i];
        } else if (t >= times[n - 1]) {
            for (int i = 0; i < comps; ++i) v[i] = ch->values[(n - 1) * stride + off + i];
        } else {
            int k = find_key(times, n, t);
            double t0 = times[k], dt = times[k + 1] - t0, u = (t - t0) / dt;
            const float* a = ch->values + k * stride;
            const float* b = ch->values + (k + 1) * stride;
            if (ch->interp == SP_INTERP_STEP) {
                for (int i = 0; i < comps; ++i) v[i] = a[i];
            } else if (cubic) {
                double u2 = u * u, u3 = u2 * u;
                double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
                for (int i = 0; i < comps; ++i)
                    v[i] = h00 * a[comps + i] + h10 * dt * a[2 * comps + i] + h01 * b[comps + i] + h11 * dt * b[i];
            } else if (comps == 4) {
                sp_quat q = sp_quat_slerp((sp_quat){a[0], a[1], a[2], a[3]}, (sp_quat){b[0], b[1], b[2], b[3]}, u);
                v[0] = q.x, v[1] = q.y, v[2] = q.z, v[3] = q.w;
            } else {
                for (int i = 0; i < comps; ++i) v[i] = a[i] + (b[i] - a[i]) * u;
            }
        }
        int j = ch->joint;
        if (ch->path == SP_ANIM_TRANSLATION) trans[j] = (sp_vec3){v[0], v[1], v[2]};
        else if (ch->path == SP_ANIM_SCALE) scale[j] = (sp_vec3){v[0], v[1], v[2]};
        else rot[j] = sp_quat_norm((sp_quat){v[0], v[1], v[2], v[3]});
    }
}

sp_result sp_animation_check_times(const double* times, int n, sp_error* err)
{
    // Channels store times as floats: they must fit one and still increase.
    for (int k = 0; k < n; ++k)
        if (!isfinite(times[k]) || fabs(times[k]) > FLT_MAX)
            return sp_fail(err, SP_ERR_INVALID, "key time %d (%g) is not a finite single-precision number", k, times[k]);
    for (int k = 1; k < n; ++k)
        if (!((float)times[k] > (float)times[k - 1]))
            return sp_fail(err, SP_ERR_INVALID, "key times must increase in single precision (key %d: %.9g after %.9g)", k,
                           times[k], times[k - 1]);
    return SP_OK;
}

sp_result sp_animation_from_keys(const sp_rig* rig, const double* keys, const double* times, int nkeys, const char* name,
                                 sp_animation* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", name);
    if (nkeys < 1) return sp_fail(err, SP_ERR_INVALID, "an animation needs at least one key");
    sp_result r = sp_animation_check_times(times, nkeys, err);
    if (r != SP_OK) return r;
    // Up to three channels per joint with parameters.
    out->channels = calloc((size_t)rig->joint_count * 3, sizeof(sp_anim_channel));
    if (!out->channels) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    const int P = rig->param_count;
    for (int j = 0; j < rig->joint_count; ++j) {
        const sp_joint* jt = &rig->joints[j];
        bool path[3] = {false, false, false};
        for (int i = 0; i < jt->param_count; ++i) {
            sp_channel c = rig->params[jt->first_param + i].channel;
            path[sp_channel_is_rotation(c) ? SP_ANIM_ROTATION : (sp_channel_is_scale(c) ? SP_ANIM_SCALE : SP_ANIM_TRANSLATION)] =
                true;
        }
        for (int ph = 0; ph < 3; ++ph) {
            if (!path[ph]) continue;
            int comps = ph == SP_ANIM_ROTATION ? 4 : 3;
            sp_anim_channel* ch = &out->channels[out->channel_count];
            ch->joint = j;
            ch->path = (sp_anim_path)ph;
            ch->interp = SP_INTERP_LINEAR;
            ch->key_count = nkeys;
            ch->times = malloc(sizeof(float) * (size_t)nkeys);
            ch->values = malloc(sizeof(float) * (size_t)(nkeys * comps));
            ++out->channel_count;
            if (!ch->times || !ch->values) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
            for (int k = 0; k < nkeys; ++k) {
                sp_vec3 t, s;
                sp_quat r;
                sp_rig_local_trs(rig, j, keys + (size_t)k * P, &t, &r, &s);
                ch->times[k] = (float)times[k];
                float* v = ch->values + k * comps;
                if (ph == SP_ANIM_ROTATION) {
                    // Keep neighbouring keys on the same hemisphere so slerp takes the short way.
                    if (k > 0 && v[-4] * r.x + v[-3] * r.y + v[-2] * r.z + v[-1] * r.w < 0) r = (sp_quat){-r.x, -r.y, -r.z, -r.w};
                    v[0] = (float)r.x, v[1] = (float)r.y, v[2] = (float)r.z, v[3] = (float)r.w;
                } else {
                    sp_vec3 x = ph == SP_ANIM_SCALE ? s : t;
                    v[0] = (float)x.x, v[1] = (float)x.y, v[2] = (float)x.z;
                }
            }
        }
    }
    out->duration_s = times[nkeys - 1];
    return SP_OK;
}
