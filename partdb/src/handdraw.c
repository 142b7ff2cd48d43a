// handdraw.c: the hand-drawing model (sp/handdraw.h).
//
// Each curve is first resampled densely and smoothed (rounded corners), then
// traced by a simulated pen: a start, a direction and a traced length (gap,
// overshoot, partial), a smooth displacement (wobble, the miss at closure),
// and points taken at a fixed sample interval at a varying speed (uneven
// spacing). The whole drawing is transformed at the end (rotation, aspect,
// shear, size, position), so noise amplitudes are relative to the clean
// drawing and transform with it, as they would on paper.
#include "sp/handdraw.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sp/curve.h"
#include "sp/synth.h"

#define PI 3.14159265358979323846
// Fine sampling step of the dense curve and the pen path, fraction of D: well
// below every modelled length (the smallest point spacing is 0.004 D).
#define FINE 0.002
// Pen sample interval (a 60 Hz touch screen) and its jitter, ms.
#define SAMPLE_MS (1000.0 / 60.0)

static const char* const k_style_names[SP_HANDDRAW_STYLE_COUNT] = {"normal", "harsh", "clean"};

const char* sp_handdraw_style_name(sp_handdraw_style s)
{
    return s >= 0 && s < SP_HANDDRAW_STYLE_COUNT ? k_style_names[s] : "?";
}

sp_handdraw_style sp_handdraw_style_parse(const char* name)
{
    for (int i = 0; name && i < SP_HANDDRAW_STYLE_COUNT; ++i)
        if (!strcmp(name, k_style_names[i])) return (sp_handdraw_style)i;
    return SP_HANDDRAW_STYLE_COUNT;
}

sp_handdraw_params sp_handdraw_preset(sp_handdraw_style s)
{
    switch (s) {
    case SP_HANDDRAW_HARSH:
        return (sp_handdraw_params){.rotation_deg = 20,
                                    .aspect = 1.35,
                                    .shear = 0.15,
                                    .wobble = 0.025,
                                    .wobble_waves = 6,
                                    .tremor = 0.002,
                                    .corner = 0.025,
                                    .gap = 0.08,
                                    .overshoot = 0.12,
                                    .gap_probability = 0.5,
                                    .miss = 0.04,
                                    .partial_probability = 0.2,
                                    .partial = 0.3,
                                    .split_probability = 0.3,
                                    .reverse_probability = 0.5,
                                    .random_start = true,
                                    .spacing_min = 0.006,
                                    .spacing_max = 0.04,
                                    .scale_min = 0.6,
                                    .scale_max = 1.2,
                                    .shift = 0.1};
    case SP_HANDDRAW_CLEAN:
        return (sp_handdraw_params){
            .aspect = 1, .wobble_waves = 1, .spacing_min = 0.01, .spacing_max = 0.01, .scale_min = 1, .scale_max = 1};
    case SP_HANDDRAW_NORMAL:
    default:
        return (sp_handdraw_params){.rotation_deg = 15,
                                    .aspect = 1.2,
                                    .shear = 0.08,
                                    .wobble = 0.012,
                                    .wobble_waves = 4,
                                    .tremor = 0.001,
                                    .corner = 0.012,
                                    .gap = 0.03,
                                    .overshoot = 0.05,
                                    .gap_probability = 0.5,
                                    .miss = 0.015,
                                    .partial_probability = 0.05,
                                    .partial = 0.15,
                                    .split_probability = 0.1,
                                    .reverse_probability = 0.5,
                                    .random_start = true,
                                    .spacing_min = 0.004,
                                    .spacing_max = 0.02,
                                    .scale_min = 0.8,
                                    .scale_max = 1.1,
                                    .shift = 0.05};
    }
}

static bool in(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

bool sp_handdraw_params_valid(const sp_handdraw_params* p)
{
    return in(p->rotation_deg, 0, 180) && in(p->aspect, 1, 10) && in(p->shear, 0, 2) && in(p->wobble, 0, 1) &&
           in(p->wobble_waves, 1, 100) && in(p->tremor, 0, 1) && in(p->corner, 0, 1) && in(p->gap, 0, 0.9) &&
           in(p->overshoot, 0, 1) && in(p->gap_probability, 0, 1) && in(p->miss, 0, 1) && in(p->partial_probability, 0, 1) &&
           in(p->partial, 0, 0.9) && in(p->split_probability, 0, 1) && in(p->reverse_probability, 0, 1) &&
           in(p->spacing_min, 1e-3, 1) && in(p->spacing_max, p->spacing_min, 1) && in(p->scale_min, 1e-3, 100) &&
           in(p->scale_max, p->scale_min, 100) && in(p->shift, 0, 1);
}

uint64_t sp_handdraw_seed(uint64_t family, int i)
{
    // splitmix64 finaliser over (family, i): nearby families and indices give unrelated seeds.
    uint64_t z = family * 0x9E3779B97F4A7C15ull ^ ((uint64_t)(uint32_t)i + 1) * 0xD1B54A32D192ED03ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

uint64_t sp_handdraw_part_family(uint64_t family, const char* part_name)
{
    uint64_t h = 0xcbf29ce484222325ull; // FNV-1a of the name
    for (const unsigned char* c = (const unsigned char*)(part_name ? part_name : ""); *c; ++c)
        h = (h ^ *c) * 0x100000001b3ull;
    return sp_handdraw_seed(family ^ h, -1);
}

// ---------------------------------------------------------------------------

// A growable point list with timestamps.
typedef struct pen_buf {
    sp_vec2* p;
    double* t;
    int n, cap;
} pen_buf;

static bool pen_push(pen_buf* b, sp_vec2 p, double t)
{
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 256;
        sp_vec2* np = realloc(b->p, sizeof *np * (size_t)cap);
        if (!np) return false;
        b->p = np;
        double* nt = realloc(b->t, sizeof *nt * (size_t)cap);
        if (!nt) return false;
        b->t = nt;
        b->cap = cap;
    }
    b->p[b->n] = p;
    b->t[b->n++] = t;
    return true;
}

static sp_vec2 lerp2(sp_vec2 a, sp_vec2 b, double f)
{
    return (sp_vec2){a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f};
}

// The dense curve at fractional index u (closed: cyclic in [0, m); open: clamped to [0, m-1]).
static sp_vec2 dense_at(const sp_vec2* d, int m, bool closed, double u)
{
    if (closed) {
        u = fmod(u, (double)m);
        if (u < 0) u += m;
        int i = (int)u;
        if (i >= m) i = m - 1;
        return lerp2(d[i], d[(i + 1) % m], u - i);
    }
    if (u <= 0) return d[0];
    if (u >= m - 1) return d[m - 1];
    int i = (int)u;
    return lerp2(d[i], d[i + 1], u - i);
}

// Gaussian smoothing along the curve (rounded corners): sigma in samples.
static void smooth(const sp_vec2* in, int m, bool closed, double sigma, sp_vec2* out)
{
    if (sigma < 0.3) {
        memcpy(out, in, sizeof *in * (size_t)m);
        return;
    }
    int r = (int)ceil(3 * sigma);
    if (closed && r > m / 2) r = m / 2;
    for (int i = 0; i < m; ++i) {
        double sx = 0, sy = 0, sw = 0;
        for (int k = -r; k <= r; ++k) {
            int j = i + k;
            if (closed)
                j = ((j % m) + m) % m;
            else if (j < 0 || j >= m)
                continue; // truncated and renormalised: the ends round off too
            double w = exp(-0.5 * k * k / (sigma * sigma));
            sx += w * in[j].x;
            sy += w * in[j].y;
            sw += w;
        }
        out[i] = (sp_vec2){sx / sw, sy / sw};
    }
}

// Sum of three sinusoids with random frequencies (1..waves cycles per curve
// length), phases and weights; |value| <= 1.
typedef struct wave3 {
    double f[3], ph[3], w[3];
} wave3;

static wave3 wave_make(sp_rng* rng, double waves)
{
    wave3 w;
    double sum = 0;
    for (int j = 0; j < 3; ++j) {
        w.f[j] = sp_rng_range(rng, 1.0, waves > 1 ? waves : 1.0);
        w.ph[j] = sp_rng_range(rng, 0, 2 * PI);
        w.w[j] = sp_rng_normal(rng);
        sum += fabs(w.w[j]);
    }
    for (int j = 0; j < 3; ++j)
        w.w[j] = sum > 0 ? w.w[j] / sum : 0;
    return w;
}

static double wave_at(const wave3* w, double x)
{
    double v = 0;
    for (int j = 0; j < 3; ++j)
        v += w->w[j] * sin(2 * PI * w->f[j] * x + w->ph[j]);
    return v;
}

typedef struct draw_ctx {
    const sp_handdraw_params* hp;
    sp_rng* rng;
    double D; // clean drawing's bbox diagonal
    double t; // pen clock, ms
    sp_sketch* out;
    sp_handdraw_info* info;
} draw_ctx;

// Traces one curve (pts, n >= 2, closed without the repeated point) into one or more strokes.
// Where the pen goes along a curve of length L: its direction (1 or -1),
// where it starts, how far it traces (a closed curve's gap, overshoot or
// part; an open one's part), counted in c->info.
static void pen_course(draw_ctx* c, double L, bool closed, int* dir, double* s0, double* total)
{
    const sp_handdraw_params* hp = c->hp;
    sp_rng* rng = c->rng;
    *dir = sp_rng_uniform(rng) < hp->reverse_probability ? -1 : 1;
    double covered = 1.0;
    bool partial = sp_rng_uniform(rng) < hp->partial_probability && hp->partial > 0;
    double q = partial ? sp_rng_range(rng, 0.35, 1.0) * hp->partial : 0.0;
    if (closed) {
        *s0 = hp->random_start ? sp_rng_range(rng, 0, L) : 0.0;
        double closure;
        if (partial)
            closure = -q;
        else if (sp_rng_uniform(rng) < hp->gap_probability)
            closure = -sp_rng_uniform(rng) * hp->gap;
        else
            closure = sp_rng_uniform(rng) * hp->overshoot;
        *total = L * (1 + closure);
        covered = fmin(1.0, 1 + closure);
        c->info->closed_curves++;
        if (closure < 0)
            c->info->gaps++;
        else if (closure > 0)
            c->info->overshoots++;
        c->info->closure_min = fmin(c->info->closure_min, closure);
        c->info->closure_max = fmax(c->info->closure_max, closure);
    } else {
        double a = q * sp_rng_uniform(rng); // left out at the abstraction's start; q - a at its end
        *total = L * (1 - q);
        *s0 = *dir > 0 ? a * L : L - (q - a) * L;
        covered = 1 - q;
    }
    c->info->partial += partial;
    c->info->reversed += *dir < 0;
    c->info->covered_min = fmin(c->info->covered_min, covered);
    c->info->curves++;
}

// The pen slows in corners: turning angle over about 1% of D either side.
static void corner_slowness(const sp_vec2* fine, int K, double* slow)
{
    int w = (int)ceil(0.01 / FINE);
    for (int k = 0; k < K; ++k) {
        int a = k - w < 0 ? 0 : k - w, b = k + w >= K ? K - 1 : k + w;
        sp_vec2 u = sp_v2_sub(fine[k], fine[a]), v = sp_v2_sub(fine[b], fine[k]);
        double lu = sp_v2_len(u), lv = sp_v2_len(v);
        double ang = lu > 0 && lv > 0 ? acos(fmax(-1.0, fmin(1.0, sp_v2_dot(u, v) / (lu * lv)))) : 0.0;
        slow[k] = 1.0 / (1.0 + 2.0 * ang);
    }
}

// The pen's points as one to three strokes: the hand lifts and restarts a
// little off, overlapping or leaving a gap; then it moves to the next curve.
static sp_result add_pieces(draw_ctx* c, pen_buf* pen)
{
    const sp_handdraw_params* hp = c->hp;
    const double D = c->D;
    sp_rng* rng = c->rng;
    int pieces = 1, cut[3] = {0, pen->n, pen->n};
    if (pen->n >= 12 && sp_rng_uniform(rng) < hp->split_probability) {
        pieces = sp_rng_uniform(rng) < 0.7 ? 2 : 3;
        if (pieces == 2)
            cut[1] = (int)(pen->n * sp_rng_range(rng, 0.3, 0.7));
        else {
            cut[1] = (int)(pen->n * sp_rng_range(rng, 0.2, 0.4));
            cut[2] = (int)(pen->n * sp_rng_range(rng, 0.6, 0.8));
        }
        c->info->split++;
    }
    double last_t = pen->t[0];
    for (int pc = 0; pc < pieces; ++pc) {
        int b = cut[pc], e = pc + 1 < pieces ? cut[pc + 1] : pen->n;
        sp_vec2 off = {0, 0};
        double shift_t = 0;
        if (pc > 0) {
            b += (int)lround(sp_rng_range(rng, -0.04, 0.02) * pen->n); // < 0: overlap, > 0: gap
            if (b < 0) b = 0;
            if (b > e - 2) b = e - 2;
            double ol = sp_rng_range(rng, 0, 0.008) * D, oa = sp_rng_range(rng, 0, 2 * PI);
            off = (sp_vec2){ol * cos(oa), ol * sin(oa)};
            shift_t = last_t + sp_rng_range(rng, 150, 400) - pen->t[b]; // a pause, then on from the restart
        }
        // In place: points before b that were already copied into the previous stroke are not read again.
        for (int i = b; i < e; ++i) {
            pen->p[i] = sp_v2_add(pen->p[i], off);
            pen->t[i] += shift_t;
        }
        sp_result r = sp_sketch_add_stroke(c->out, pen->p + b, pen->t + b, e - b);
        if (r != SP_OK) return r;
        last_t = pen->t[e - 1];
    }
    c->t = last_t + sp_rng_range(rng, 150, 600); // the hand moves to the next curve
    return SP_OK;
}

static sp_result draw_curve(draw_ctx* c, const sp_vec2* pts, int n, bool closed)
{
    const sp_handdraw_params* hp = c->hp;
    sp_rng* rng = c->rng;
    const double D = c->D;
    double L = sp_curve_length(pts, n, closed);
    sp_result r = SP_OK;
    sp_vec2 *dense = NULL, *sm = NULL, *fine = NULL;
    double *cum = NULL, *slow = NULL;
    pen_buf pen = {0};
    int m = (int)ceil(L / (FINE * D));
    if (m < 16) m = 16;
    if (m > 20000) m = 20000;
    dense = malloc(sizeof *dense * (size_t)m);
    sm = malloc(sizeof *sm * (size_t)m);
    if (!dense || !sm) {
        r = SP_ERR_NO_MEMORY;
        goto done;
    }
    if ((r = sp_curve_resample(pts, n, closed, m, dense)) != SP_OK) goto done;
    double step = closed ? L / m : L / (m - 1);
    // Rounded corners.
    smooth(dense, m, closed, hp->corner * D * sp_rng_range(rng, 0.5, 1.0) / step, sm);

    // Where the pen goes: start, direction, traced length.
    int dir;
    double s0, total;
    pen_course(c, L, closed, &dir, &s0, &total);

    // The pen path, finely sampled, displaced by wobble and (closed curves) the miss at closure.
    int K = (int)ceil(total / (FINE * D)) + 1;
    if (K < 2) K = 2;
    fine = malloc(sizeof *fine * (size_t)K);
    cum = malloc(sizeof *cum * (size_t)K);
    slow = malloc(sizeof *slow * (size_t)K);
    if (!fine || !cum || !slow) {
        r = SP_ERR_NO_MEMORY;
        goto done;
    }
    wave3 wx = wave_make(rng, hp->wobble_waves), wy = wave_make(rng, hp->wobble_waves);
    double amp = hp->wobble * D * sp_rng_range(rng, 0.4, 1.0);
    double miss = closed ? hp->miss * D * sp_rng_range(rng, 0.3, 1.0) : 0.0;
    double miss_ang = sp_rng_range(rng, 0, 2 * PI);
    for (int k = 0; k < K; ++k) {
        double f = (double)k / (K - 1), along = f * total;
        double s = s0 + dir * along;
        sp_vec2 p = dense_at(sm, m, closed, closed ? s / L * m : s / L * (m - 1));
        p.x += amp * wave_at(&wx, along / L);
        p.y += amp * wave_at(&wy, along / L);
        if (miss > 0 && f > 0.8) {
            double e = (f - 0.8) / 0.2;
            e = e * e * (3 - 2 * e); // smoothstep: the hand drifts off only near the end
            p.x += miss * e * cos(miss_ang);
            p.y += miss * e * sin(miss_ang);
        }
        fine[k] = p;
        cum[k] = k ? cum[k - 1] + sp_v2_len(sp_v2_sub(p, fine[k - 1])) : 0.0;
    }
    corner_slowness(fine, K, slow);

    // Sampling at a fixed interval while the speed varies: uneven spacing.
    double len = cum[K - 1];
    double g = sp_rng_range(rng, 0.5, 3.0), psi = sp_rng_range(rng, 0, 2 * PI);
    double lo = log(hp->spacing_min), hi = log(hp->spacing_max);
    bool uneven = hi > lo; // spacing_min == spacing_max: a constant speed (the clean style)
    double pos = 0;
    int k = 0;
    if (!pen_push(&pen, fine[0], c->t)) goto oom;
    while (len > 0) {
        double u = pos / len;
        double h = exp(lo + (hi - lo) * (0.5 + 0.5 * sin(2 * PI * g * u + psi))) * D;
        if (uneven) {
            double ease = 0.35 + 0.65 * fmin(1.0, fmin(u, 1.0 - u) / 0.08); // the pen speeds up and slows down
            h *= ease * slow[k] * sp_rng_range(rng, 0.75, 1.25);
        }
        if (h < 0.25 * hp->spacing_min * D) h = 0.25 * hp->spacing_min * D;
        pos += h;
        c->t += SAMPLE_MS;
        if (pos >= len) {
            if (!pen_push(&pen, fine[K - 1], c->t)) goto oom;
            break;
        }
        while (k + 1 < K - 1 && cum[k + 1] < pos)
            ++k;
        double seg = cum[k + 1] - cum[k];
        if (!pen_push(&pen, lerp2(fine[k], fine[k + 1], seg > 0 ? (pos - cum[k]) / seg : 0.0), c->t)) goto oom;
    }
    // Tremor.
    for (int i = 0; i < pen.n && hp->tremor > 0; ++i) {
        pen.p[i].x += hp->tremor * D * sp_rng_normal(rng);
        pen.p[i].y += hp->tremor * D * sp_rng_normal(rng);
    }

    if ((r = add_pieces(c, &pen)) != SP_OK) goto done;
    goto done;
oom:
    r = SP_ERR_NO_MEMORY;
done:
    free(dense);
    free(sm);
    free(fine);
    free(cum);
    free(slow);
    free(pen.p);
    free(pen.t);
    return r;
}

sp_result sp_handdraw_apply(const sp_sketch* clean, const sp_handdraw_params* hp, uint64_t seed, sp_sketch* out,
                            sp_handdraw_info* info, sp_error* err)
{
    memset(out, 0, sizeof *out);
    sp_handdraw_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    info->closure_min = INFINITY;
    info->closure_max = -INFINITY;
    info->covered_min = 1.0;
    if (!sp_handdraw_params_valid(hp)) return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: a parameter is out of range");
    if (!sp_sketch_is_valid(clean))
        return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: the sketch has non-finite coordinates");
    sp_vec2 lo, hi;
    if (!sp_sketch_bounds(clean, &lo, &hi)) return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: the sketch is empty");
    const double D = hypot(hi.x - lo.x, hi.y - lo.y);
    if (!(D > 1e-9)) return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: the sketch is a single point");
    sp_rng rng = {seed ^ 0x6A09E667F3BCC908ull};
    // Whole-drawing choices first, so that they do not depend on the curves.
    double rot = sp_rng_range(&rng, -1, 1) * hp->rotation_deg * PI / 180;
    double ar = exp(sp_rng_range(&rng, -1, 1) * log(hp->aspect));
    double shear = sp_rng_range(&rng, -1, 1) * hp->shear;
    double scale = sp_rng_range(&rng, hp->scale_min, hp->scale_max);
    double cw = clean->canvas_w > 0 ? clean->canvas_w : D, ch = clean->canvas_h > 0 ? clean->canvas_h : D;
    sp_vec2 shift = {sp_rng_range(&rng, -1, 1) * hp->shift * cw, sp_rng_range(&rng, -1, 1) * hp->shift * ch};
    info->rotation = rot;
    info->aspect = ar;
    info->scale = scale;

    sp_sketch drawn = {0};
    draw_ctx c = {hp, &rng, D, 0.0, &drawn, info};
    sp_result r = SP_OK;
    sp_vec2* buf = NULL;
    int cap = 0;
    for (int s = 0; s < clean->stroke_count && r == SP_OK; ++s) {
        const sp_stroke* st = &clean->strokes[s];
        if (st->count < 1) continue;
        if (st->count > cap) {
            free(buf);
            cap = st->count;
            if (!(buf = malloc(sizeof *buf * (size_t)cap))) {
                r = SP_ERR_NO_MEMORY;
                break;
            }
        }
        int n = sp_curve_clean(st->points, st->count, 0.0, buf);
        bool closed = n >= 4 && sp_v2_len(sp_v2_sub(buf[0], buf[n - 1])) <= 1e-6 * D;
        if (closed) --n;
        if (n < 2 || sp_curve_length(buf, n, closed) <= 1e-6 * D) { // a dot stays a dot
            double t = c.t;
            r = sp_sketch_add_stroke(&drawn, buf, &t, 1);
            c.t += 300;
            continue;
        }
        r = draw_curve(&c, buf, n, closed);
    }
    free(buf);
    if (r != SP_OK) {
        sp_sketch_free(&drawn);
        return sp_fail(err, r, "hand-drawing model: %s", sp_result_name(r));
    }
    if (info->closed_curves == 0) info->closure_min = info->closure_max = 0;

    // Whole drawing: about the clean drawing's centre, shear and aspect, then
    // rotation (counter-clockwise on screen, y down), size, position.
    sp_vec2 ctr = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y)};
    double sx = sqrt(ar), sy = 1 / sqrt(ar), cs = cos(rot), sn = sin(rot);
    for (int s = 0; s < drawn.stroke_count; ++s)
        for (int i = 0; i < drawn.strokes[s].count; ++i) {
            sp_vec2 p = sp_v2_sub(drawn.strokes[s].points[i], ctr);
            p.x += shear * p.y;
            p.x *= sx;
            p.y *= sy;
            sp_vec2 q = {cs * p.x + sn * p.y, -sn * p.x + cs * p.y};
            drawn.strokes[s].points[i] = (sp_vec2){ctr.x + shift.x + scale * q.x, ctr.y + shift.y + scale * q.y};
        }
    // Curves in a random order (people do not follow the abstraction's), timestamps renumbered to that order.
    for (int s = drawn.stroke_count - 1; s > 0; --s) {
        int j = (int)(sp_rng_uniform(&rng) * (s + 1));
        sp_stroke tmp = drawn.strokes[s];
        drawn.strokes[s] = drawn.strokes[j];
        drawn.strokes[j] = tmp;
    }
    double t = 0;
    for (int s = 0; s < drawn.stroke_count; ++s) {
        sp_stroke* st = &drawn.strokes[s];
        double t0 = st->t[0];
        for (int i = 0; i < st->count; ++i)
            st->t[i] = t + (st->t[i] - t0);
        t = st->t[st->count - 1] + 300;
    }
    drawn.canvas_w = clean->canvas_w;
    drawn.canvas_h = clean->canvas_h;
    *out = drawn;
    return SP_OK;
}

sp_result sp_handdraw_part(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_handdraw_desc* desc, uint64_t seed,
                           sp_sketch* out, sp_handdraw_info* info, sp_error* err)
{
    memset(out, 0, sizeof *out);
    sp_handdraw_desc d = desc ? *desc : (sp_handdraw_desc){0};
    if (abstraction < 0 || abstraction >= rig->abstraction_count)
        return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: no abstraction %d", abstraction);
    if (d.style < 0 || d.style >= SP_HANDDRAW_STYLE_COUNT)
        return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: unknown style");
    sp_handdraw_params hp = d.params ? *d.params : sp_handdraw_preset(d.style);
    double* p = malloc(sizeof(double) * (size_t)(rig->param_count > 0 ? rig->param_count : 1));
    if (!p) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sp_synth_params(rig, seed, d.amplitude > 0 ? d.amplitude : SP_HANDDRAW_AMPLITUDE, p);
    sp_sketch clean = {0};
    bool plain = d.shape == SP_HANDDRAW_SHAPE_OUTLINE && !d.details && !(d.spikes > 0);
    sp_result r = plain ? sp_synth_sketch(rig, abstraction, cam, p, &clean)
                        : sp_handdraw_clean_shape(rig, abstraction, cam, p, d.shape, d.details, d.spikes, seed, &clean);
    free(p);
    if (r != SP_OK)
        return sp_fail(err, r, "hand-drawing model: cannot draw abstraction '%s' (%s)", rig->abstractions[abstraction].name,
                       sp_result_name(r));
    // The perturbation's stream is independent of the pose's.
    r = sp_handdraw_apply(&clean, &hp, seed * 0xC2B2AE3D27D4EB4Full + 0x165667B19E3779F9ull, out, info, err);
    sp_sketch_free(&clean);
    return r;
}

sp_result sp_handdraw_dataset(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_handdraw_desc* desc,
                              uint64_t family, int n, int label, int first_index, sp_dataset* ds, sp_error* err)
{
    if (n <= 0) return SP_OK;
    if (label < -1 || label >= ds->category_count)
        return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: label %d out of range", label);
    double share = desc ? desc->clean_share : 0.0;
    if (!(share >= 0.0 && share <= 1.0))
        return sp_fail(err, SP_ERR_INVALID, "hand-drawing model: clean share %g is not in [0, 1]", share);
    sp_handdraw_desc clean = desc ? *desc : (sp_handdraw_desc){0};
    clean.params = NULL;
    clean.style = SP_HANDDRAW_CLEAN;
    if (sp_dataset_reserve(ds, n) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    for (int i = 0; i < n; ++i) {
        sp_sample* s = &ds->samples[ds->count + i];
        memset(s, 0, sizeof *s);
        bool is_clean = floor((i + 1) * share) > floor(i * share);
        sp_result r =
            sp_handdraw_part(rig, abstraction, cam, is_clean ? &clean : desc, sp_handdraw_seed(family, i), &s->sketch, NULL, err);
        if (r != SP_OK) {
            for (int j = 0; j < i; ++j)
                sp_sketch_free(&ds->samples[ds->count + j].sketch);
            return r;
        }
        s->label = label;
        s->index = first_index + i;
    }
    ds->count += n;
    return SP_OK;
}
