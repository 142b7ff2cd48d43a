#include "posing.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/sketch_io.h"

int sp_pick_abstraction(const sp_abstraction* abs, int count, const char* rig_path, const char* name, sp_error* err)
{
    if (count == 0) {
        sp_fail(err, SP_ERR_INVALID, "%s: the rig has no sketch abstraction", rig_path);
        return -1;
    }
    if (!name) return 0;
    for (int a = 0; a < count; ++a)
        if (!strcmp(abs[a].name, name)) return a;
    char list[256] = "";
    for (int i = 0; i < count; ++i) {
        size_t n = strlen(list);
        snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", abs[i].name);
    }
    sp_fail(err, SP_ERR_INVALID, "%s: no abstraction '%s' (it has: %s)", rig_path, name, list);
    return -1;
}

sp_result sp_read_strokes(const char* path, sp_sketch* sk, sp_error* err)
{
    sp_result r = sp_sketch_read_json(path, sk, err);
    if (r != SP_OK) return r;
    if (sk->stroke_count == 0) {
        sp_sketch_free(sk);
        return sp_fail(err, SP_ERR_INVALID, "%s: the file has no strokes", path);
    }
    for (int i = 0; i < sk->stroke_count; ++i)
        if (sk->strokes[i].count < 2) {
            int n = sk->strokes[i].count;
            sp_sketch_free(sk);
            return sp_fail(err, SP_ERR_INVALID, "%s: stroke %d has %d point%s (at least 2 are needed)", path, i, n, n == 1 ? "" : "s");
        }
    return SP_OK;
}

sp_result sp_animation_from_keys(const sp_rig* rig, const double* keys, const double* times, int nkeys, const char* name,
                                 sp_animation* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", name);
    if (nkeys < 1) return sp_fail(err, SP_ERR_INVALID, "an animation needs at least one key");
    for (int k = 1; k < nkeys; ++k)
        if (!(times[k] > times[k - 1])) return sp_fail(err, SP_ERR_INVALID, "key times must increase (key %d: %g after %g)", k, times[k], times[k - 1]);
    // Up to three channels per joint with parameters.
    out->channels = calloc((size_t)rig->joint_count * 3, sizeof(sp_anim_channel));
    if (!out->channels) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    const int P = rig->param_count;
    for (int j = 0; j < rig->joint_count; ++j) {
        const sp_joint* jt = &rig->joints[j];
        bool path[3] = {false, false, false};
        for (int i = 0; i < jt->param_count; ++i) {
            sp_channel c = rig->params[jt->first_param + i].channel;
            path[sp_channel_is_rotation(c) ? SP_ANIM_ROTATION : (sp_channel_is_scale(c) ? SP_ANIM_SCALE : SP_ANIM_TRANSLATION)] = true;
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
