// synth.c: random poses within bounds and their projected abstractions.
#include "sp/synth.h"

#include <stdlib.h>
#include <string.h>

#include "synth_internal.h"

double sp_rng_uniform(sp_rng* r)
{
    uint64_t z = (r->state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

double sp_rng_range(sp_rng* r, double lo, double hi) { return lo + (hi - lo) * sp_rng_uniform(r); }

double sp_rng_normal(sp_rng* r)
{
    double u = sp_rng_uniform(r), v = sp_rng_uniform(r);
    if (u < 1e-300) u = 1e-300;
    return sqrt(-2.0 * log(u)) * cos(2.0 * 3.14159265358979323846 * v);
}

void sp_synth_jitter(sp_sketch* sk, double noise_px, uint64_t seed)
{
    sp_rng rng = {seed ^ 0xA5A5A5A5ull};
    for (int i = 0; i < sk->stroke_count; ++i)
        for (int j = 0; j < sk->strokes[i].count; ++j) {
            sk->strokes[i].points[j].x += noise_px * sp_rng_normal(&rng);
            sk->strokes[i].points[j].y += noise_px * sp_rng_normal(&rng);
        }
}

sp_rng sp__synth_rng(uint64_t seed)
{
    return (sp_rng){seed * 0x2545F4914F6CDD1Dull + 1};
}

double sp__synth_param(sp_rng* rng, double def, double min, double max, bool angle, bool pose, double amplitude)
{
    double a = fabs(amplitude), lo = min, hi = max;
    if (angle) {
        lo = fmax(lo, def - a), hi = fmin(hi, def + a);
    } else if (pose) {
        double f = fmin(1.0, a / 3.14159265358979323846);
        lo = def - f * (def - min), hi = def + f * (max - def);
    }
    return sp_rng_range(rng, lo, hi);
}

void sp_synth_params(const sp_rig* rig, uint64_t seed, double amplitude, double* p)
{
    sp_rng rng = sp__synth_rng(seed);
    for (int i = 0; i < rig->param_count; ++i) {
        const sp_param* q = &rig->params[i];
        p[i] = sp__synth_param(&rng, q->def, q->min, q->max, sp_channel_is_rotation(q->channel), q->group == SP_GROUP_POSE,
                               amplitude);
    }
}

sp_result sp_abstraction_project(const sp_rig* rig, int abstraction, const sp_camera* cam, const double* p, double* xy)
{
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return SP_ERR_INVALID;
    const sp_abstraction* ab = &rig->abstractions[abstraction];
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    double* mesh = ab->rest ? NULL : malloc(sizeof(double) * 3 * (size_t)(rig->vertex_count + 1));
    double* z = malloc(sizeof(double) * 3 * (size_t)(ab->point_count + 1));
    sp_result r = SP_OK;
    if (!ev || !z || (!ab->rest && !mesh)) {
        r = SP_ERR_NO_MEMORY;
    } else {
        sp_rig_eval_update(ev, p, false);
        if (mesh) sp_rig_eval_points(ev, sp_rig_mesh_points(rig), mesh);
        sp_rig_eval_abstraction(ev, ab, mesh, z);
        for (int i = 0; i < ab->point_count; ++i) {
            sp_vec2 q = sp_camera_project(cam, (sp_vec3){z[3 * i], z[3 * i + 1], z[3 * i + 2]});
            xy[2 * i] = q.x, xy[2 * i + 1] = q.y;
        }
    }
    sp_rig_eval_destroy(ev);
    free(mesh), free(z);
    return r;
}

sp_result sp_synth_sketch(const sp_rig* rig, int abstraction, const sp_camera* cam, const double* p, sp_sketch* out)
{
    memset(out, 0, sizeof *out);
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return SP_ERR_INVALID;
    const sp_abstraction* ab = &rig->abstractions[abstraction];
    double* xy = malloc(sizeof(double) * 2 * (size_t)(ab->point_count + 1));
    sp_vec2* pts = malloc(sizeof(sp_vec2) * (size_t)(ab->point_count + 1));
    sp_result r = !xy || !pts ? SP_ERR_NO_MEMORY : sp_abstraction_project(rig, abstraction, cam, p, xy);
    out->canvas_w = cam->width, out->canvas_h = cam->height;
    for (int c = 0; r == SP_OK && c < ab->curve_count; ++c) {
        const sp_curve* cv = &ab->curves[c];
        for (int i = 0; i < cv->point_count; ++i) pts[i] = (sp_vec2){xy[2 * (cv->first_point + i)], xy[2 * (cv->first_point + i) + 1]};
        int n = cv->point_count;
        if (cv->closed) pts[n++] = pts[0];
        r = sp_sketch_add_stroke(out, pts, NULL, n);
    }
    free(xy), free(pts);
    if (r != SP_OK) sp_sketch_free(out);
    return r;
}
