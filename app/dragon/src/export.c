// export.c: the dragon as one glTF: every part with its own skin, one looped
// animation of the joints' offsets and the attached parts' placements.
#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"
#include "posing.h"

static void animation_free(sp_animation* a)
{
    for (int c = 0; c < a->channel_count; ++c)
        free(a->channels[c].times), free(a->channels[c].values);
    free(a->channels);
    memset(a, 0, sizeof *a);
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
    qsort(k, n, sizeof *k, sp_cmp_double);
    // Keys closer than a millisecond are one key (float times must increase).
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        if (m == 0 || k[i] - k[m - 1] > 1e-3) k[m++] = k[i];
    k[m - 1] = T;
    *out = k;
    return (int)m;
}

// An orthographic camera looking along -Z (as the canvas does) on the
// canvas's aspect, framing the box [lo, hi] (already centred) with a margin.
static sp_camera framing_camera(const sp_dragon* d, sp_vec3 lo, sp_vec3 hi)
{
    double aspect = (double)d->desc.canvas_w / d->desc.canvas_h;
    double hx = fmax(fabs(lo.x), fabs(hi.x)), hy = fmax(fabs(lo.y), fabs(hi.y)), hz = fmax(fabs(lo.z), fabs(hi.z));
    double xmag = 1.1 * fmax(fmax(hx, hy * aspect), 1e-3);
    sp_camera c = {0};
    c.kind = SP_CAMERA_ORTHOGRAPHIC;
    c.width = d->desc.canvas_w, c.height = d->desc.canvas_h;
    c.scale = 0.5 * c.width / xmag;
    c.cx = 0.5 * c.width, c.cy = 0.5 * c.height;
    double eye = hz + 0.5 * xmag + 1e-3; // in front of everything
    c.view = sp_mat4_translate((sp_vec3){0, 0, -eye});
    c.znear = 0.01 * eye, c.zfar = eye + hz + 0.5 * xmag;
    return c;
}

// The details as ink lines on their parts' skins, grouped by part (each
// part's lines one run of `lines`), in drawing order within it; the points
// in one block (rest, joints, weights), sized for all the details.
static void group_ink(const sp_dragon* d, sp_gltf_scene_part* parts, sp_gltf_scene_line* lines, double* ink_rest,
                      uint16_t* ink_joints, float* ink_weights)
{
    int n = d->part_n, nd = d->detail_n;
    sp_dragon_detail e;
    for (int i = 0, used = 0, at = 0; i < n; ++i) {
        parts[i].lines = lines + used;
        for (int k = 0; k < nd; ++k) {
            double* r = ink_rest + 3 * (size_t)at;
            uint16_t* j = ink_joints + 4 * (size_t)at;
            float* w = ink_weights + 4 * (size_t)at;
            if (!sp_dragon_detail_get(d, k, &e) || e.part != i || dragon_detail_skinned(d, k, r, j, w) != i) continue;
            lines[used++] = (sp_gltf_scene_line){
                .point_count = e.point_count, .rest = r, .joints = j, .weights = w, .color = {0.01f, 0.006f, 0.006f, 1}};
            at += e.point_count;
            ++parts[i].line_count;
        }
    }
}

sp_result sp_dragon_export(sp_dragon* d, const char* path, sp_error* err)
{
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
    // The details shown, as ink on their parts' skins: one block of points for all of them.
    int nd = d->detail_n, total = 0;
    sp_dragon_detail e;
    for (int i = 0; i < nd; ++i)
        total += sp_dragon_detail_get(d, i, &e) ? e.point_count : 0;
    sp_gltf_scene_line* lines = calloc((size_t)nd + 1, sizeof *lines);
    double* ink_rest = malloc(sizeof(double) * 3 * ((size_t)total + 1));
    uint16_t* ink_joints = malloc(sizeof(uint16_t) * 4 * ((size_t)total + 1));
    float* ink_weights = malloc(sizeof(float) * 4 * ((size_t)total + 1));
    if (!parts || !anims || !keys || !names || !lines || !ink_rest || !ink_joints || !ink_weights ||
        (animated && (!place_trs || !ftimes || !times))) {
        res = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
        goto done;
    }
    // Centred: the dragon's box at t = 0 goes to the origin (a viewer's
    // default camera looks there); the camera in the file frames the box of
    // the whole loop.
    sp_vec3 lo, hi, alo, ahi;
    dragon_pose(d, 0);
    if (!sp_dragon_bounds(d, &lo, &hi)) lo = hi = (sp_vec3){0, 0, 0};
    alo = lo, ahi = hi;
    sp_vec3 offset = sp_v3_scale(sp_v3_add(lo, hi), -0.5);
    sp_mat4 shift = sp_mat4_translate(offset);
    for (int i = 0; i < n; ++i) {
        const part* p = d->parts[i];
        snprintf(names[i], sizeof names[i], "%02d_%s", i, p->pub.category);
        parts[i] = (sp_gltf_scene_part){
            .character = &p->t->ch, .params = p->p_fit, .name = names[i], .placement = sp_mat4_mul(&shift, &p->world_fit)};
        if (animated) {
            keys[i] = malloc(sizeof(double) * ((size_t)p->t->ch.rig.param_count + 1) * (size_t)(K + 1));
            if (!keys[i]) {
                res = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
                goto done;
            }
        }
    }
    group_ink(d, parts, lines, ink_rest, ink_joints, ink_weights);
    if (animated) {
        for (int k = 0; k <= K; ++k) {
            ftimes[k] = (float)times[k];
            dragon_pose(d, times[k]);
            sp_vec3 klo, khi;
            if (sp_dragon_bounds(d, &klo, &khi)) {
                alo = (sp_vec3){fmin(alo.x, klo.x), fmin(alo.y, klo.y), fmin(alo.z, klo.z)};
                ahi = (sp_vec3){fmax(ahi.x, khi.x), fmax(ahi.y, khi.y), fmax(ahi.z, khi.z)};
            }
            for (int i = 0; i < n; ++i) {
                const part* p = d->parts[i];
                size_t P = (size_t)p->t->ch.rig.param_count;
                memcpy(keys[i] + P * (size_t)k, p->p_t, sizeof(double) * P);
                sp_mat4 w = sp_mat4_mul(&shift, &p->world_t);
                sp_sim3 s = sp_sim3_from_mat4(&w);
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
        // Where the kiosk's world went: file = world + offset.
        cJSON_AddItemToObject(dj, "world_offset", cJSON_CreateDoubleArray((const double[3]){offset.x, offset.y, offset.z}, 3));
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
        sp_camera view = framing_camera(d, sp_v3_add(alo, offset), sp_v3_add(ahi, offset));
        sp_gltf_scene_desc sd = {
            .part_count = n, .parts = parts, .animation_name = "dragon", .extras_json = text, .camera = &view};
        res = sp_gltf_save_scene(&sd, path, err);
        free(text);
    }
done:
    for (int i = 0; i < n; ++i) {
        if (anims) animation_free(&anims[i]);
        if (keys) free(keys[i]);
    }
    free(parts), free(anims), free(keys), free(place_trs), free(ftimes), free(times), free(names);
    free(lines), free(ink_rest), free(ink_joints), free(ink_weights);
    d->posed = false;
    return res;
}
