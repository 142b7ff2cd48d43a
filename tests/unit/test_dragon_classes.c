// Dragon-part classes: the hand-drawing model (determinism, each effect
// measured on the drawn geometry with the others switched off, the presets'
// ranges), the part database's synthetic sketches going through it, the
// `sketchpose synth --parts` folder, and the dragon-part classifier criteria
// of issue 5 on a smaller set (train on normal sketches of seed family 1, test
// on harsh sketches of family 2, reject Quick, Draw! drawings of objects).
// Parts: assets/*.glb when all six are there, else stand-ins built in code
// (tests/support/dragon_parts.h); `test_dragon_classes --write-standins DIR`
// writes the stand-ins as .glb for trying the command line by hand.
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "db_internal.h"
#include "dragon_parts.h"
#include "sp/classifier.h"
#include "sp/concept.h"
#include "sp/curve.h"
#include "sp/handdraw.h"
#include "sp/synth.h"
#include "test.h"

#define PI 3.14159265358979323846

static dragon_part g_parts[DRAGON_PART_COUNT];
static bool g_loaded, g_assets;

static dragon_part* parts(void)
{
    if (!g_loaded) {
        g_assets = dragon_parts_load(sp_test_src_path("assets"), g_parts);
        g_loaded = true;
        printf("  parts: %s\n", g_assets ? "assets/*.glb" : "code-built stand-ins (assets/ incomplete)");
    }
    return g_parts;
}

// The clean sketch of part i at its rest pose.
static sp_sketch clean_sketch(int i)
{
    dragon_part* p = &parts()[i];
    double* q = malloc(sizeof(double) * (size_t)p->ch.rig.param_count);
    sp_rig_defaults(&p->ch.rig, q);
    sp_sketch sk = {0};
    ENSURE(sp_synth_sketch(&p->ch.rig, p->abstraction, &p->ch.camera, q, &sk) == SP_OK);
    free(q);
    return sk;
}

static double diag(const sp_sketch* s)
{
    sp_vec2 lo, hi;
    ENSURE(sp_sketch_bounds(s, &lo, &hi));
    return hypot(hi.x - lo.x, hi.y - lo.y);
}

static double poly_length(const sp_stroke* s)
{
    return sp_curve_length(s->points, s->count, false);
}

// Distance from p to the polyline pts[0..n).
static double dist_to_poly(sp_vec2 p, const sp_vec2* pts, int n)
{
    double best = INFINITY;
    for (int i = 0; i + 1 < n; ++i) {
        sp_vec2 a = pts[i], d = sp_v2_sub(pts[i + 1], a);
        double l2 = sp_v2_dot(d, d), t = l2 > 0 ? sp_v2_dot(sp_v2_sub(p, a), d) / l2 : 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        best = fmin(best, sp_v2_len(sp_v2_sub(p, sp_v2_add(a, sp_v2_scale(d, t)))));
    }
    return best;
}

// Signed area (shoelace) of a stroke taken as closed; y down, so > 0 is clockwise on screen.
static double signed_area(const sp_stroke* s)
{
    double a = 0;
    for (int i = 0; i < s->count; ++i) {
        sp_vec2 p = s->points[i], q = s->points[(i + 1) % s->count];
        a += p.x * q.y - q.x * p.y;
    }
    return 0.5 * a;
}

// Every effect off: a resampled copy of the clean sketch.
static sp_handdraw_params only(void)
{
    return sp_handdraw_preset(SP_HANDDRAW_CLEAN);
}

static bool same_sketch(const sp_sketch* a, const sp_sketch* b)
{
    if (a->stroke_count != b->stroke_count) return false;
    for (int s = 0; s < a->stroke_count; ++s) {
        if (a->strokes[s].count != b->strokes[s].count) return false;
        if (memcmp(a->strokes[s].points, b->strokes[s].points, sizeof(sp_vec2) * (size_t)a->strokes[s].count)) return false;
        if (memcmp(a->strokes[s].t, b->strokes[s].t, sizeof(double) * (size_t)a->strokes[s].count)) return false;
    }
    return true;
}

// ---- the hand-drawing model ----------------------------------------------------

static void test_handdraw_deterministic(void)
{
    dragon_part* p = &parts()[5];
    sp_error err = {0};
    for (int st = SP_HANDDRAW_NORMAL; st <= SP_HANDDRAW_HARSH; ++st) {
        sp_handdraw_desc d = {.style = (sp_handdraw_style)st};
        sp_sketch a, b, c;
        ENSURE(sp_handdraw_part(&p->ch.rig, p->abstraction, &p->ch.camera, &d, 42, &a, NULL, &err) == SP_OK);
        ENSURE(sp_handdraw_part(&p->ch.rig, p->abstraction, &p->ch.camera, &d, 42, &b, NULL, &err) == SP_OK);
        ENSURE(sp_handdraw_part(&p->ch.rig, p->abstraction, &p->ch.camera, &d, 43, &c, NULL, &err) == SP_OK);
        ENSURE(same_sketch(&a, &b));
        ENSURE(!same_sketch(&a, &c));
        ENSURE(sp_sketch_is_valid(&a) && a.canvas_w == p->ch.camera.width && a.canvas_h == p->ch.camera.height);
        sp_sketch_free(&a);
        sp_sketch_free(&b);
        sp_sketch_free(&c);
    }
    // A whole labelled set, twice; families and parts give distinct seeds.
    sp_dataset x, y;
    ENSURE(dragon_set(parts(), 4, 9, &(sp_handdraw_desc){0}, &x, &err) == SP_OK);
    ENSURE(dragon_set(parts(), 4, 9, &(sp_handdraw_desc){0}, &y, &err) == SP_OK);
    ENSURE(x.count == 4 * DRAGON_PART_COUNT && y.count == x.count);
    for (int i = 0; i < x.count; ++i)
        ENSURE(same_sketch(&x.samples[i].sketch, &y.samples[i].sketch) && x.samples[i].label == y.samples[i].label);
    sp_dataset_free(&x);
    sp_dataset_free(&y);
    ENSURE(sp_handdraw_seed(1, 0) != sp_handdraw_seed(2, 0) && sp_handdraw_seed(1, 0) != sp_handdraw_seed(1, 1));
    ENSURE(sp_handdraw_part_family(1, "wings") != sp_handdraw_part_family(1, "tail"));
    ENSURE(sp_handdraw_part_family(1, "wings") == sp_handdraw_part_family(1, "wings"));
}

// Concept sketches (sp/concept.h): the six parts as visitors imagine them.
static void test_concepts(void)
{
    for (int c = 0; c < SP_CONCEPT_COUNT; ++c)
        ENSURE(sp_concept_parse(sp_concept_name((sp_concept)c)) == (sp_concept)c);
    ENSURE(sp_concept_parse("horns") == SP_CONCEPT_COUNT && sp_concept_parse(NULL) == SP_CONCEPT_COUNT);
    sp_error err = {0};
    sp_sketch sk;
    ENSURE(sp_concept_clean(SP_CONCEPT_COUNT, 1, &sk, &err) == SP_ERR_INVALID && sk.stroke_count == 0);
    enum { N = 300 };
    for (int c = 0; c < SP_CONCEPT_COUNT; ++c) {
        double aspect_sum = 0, aspect_sq = 0;
        int closed = 0;
        for (int i = 0; i < N; ++i) {
            uint64_t seed = sp_handdraw_seed(9, i);
            // The clean design: one stroke, about 340 px across, centred on the kiosk's canvas.
            ENSURE(sp_concept_clean((sp_concept)c, seed, &sk, &err) == SP_OK);
            ENSURE(sk.stroke_count == 1 && sk.strokes[0].count >= 4 && sp_sketch_is_valid(&sk));
            ENSURE(sk.canvas_w == SP_CONCEPT_CANVAS_W && sk.canvas_h == SP_CONCEPT_CANVAS_H);
            sp_vec2 lo, hi;
            ENSURE(sp_sketch_bounds(&sk, &lo, &hi));
            ENSURE_NEAR(hypot(hi.x - lo.x, hi.y - lo.y), 340, 1e-6);
            ENSURE_NEAR((lo.x + hi.x) / 2, SP_CONCEPT_CANVAS_W / 2, 1e-6);
            const sp_stroke* st = &sk.strokes[0];
            closed += st->points[0].x == st->points[st->count - 1].x && st->points[0].y == st->points[st->count - 1].y;
            double a = log((hi.x - lo.x + 1) / (hi.y - lo.y + 1));
            aspect_sum += a, aspect_sq += a * a;
            sp_sketch_free(&sk);
            // Drawn by hand: valid, with times, the same for the same seed, another for the next.
            sp_sketch x, y, z;
            ENSURE(sp_concept_sketch((sp_concept)c, seed, &x, &err) == SP_OK);
            ENSURE(sp_sketch_is_valid(&x) && x.stroke_count >= 1 && x.strokes[0].t);
            if (i < 20) {
                ENSURE(sp_concept_sketch((sp_concept)c, seed, &y, &err) == SP_OK);
                ENSURE(sp_concept_sketch((sp_concept)c, seed + 1, &z, &err) == SP_OK);
                ENSURE(same_sketch(&x, &y) && !same_sketch(&x, &z));
                sp_sketch_free(&y);
                sp_sketch_free(&z);
            }
            sp_sketch_free(&x);
        }
        // Designs vary (proportions, pose, facing) and mix closed outlines with open lines where people draw both.
        double mean = aspect_sum / N, sd = sqrt(fmax(0, aspect_sq / N - mean * mean));
        fprintf(stderr, "  %-10s closed %3d of %d, log aspect %.2f +- %.2f\n", sp_concept_name((sp_concept)c), closed, N, mean, sd);
        ENSURE(sd > 0.1);
        if (c == SP_CONCEPT_TAIL || c == SP_CONCEPT_FRONT_LEGS || c == SP_CONCEPT_HIND_LEGS) ENSURE(closed > N / 10 && closed < N * 9 / 10);
        if (c == SP_CONCEPT_HEAD || c == SP_CONCEPT_TORSO) ENSURE(closed > N / 2);
        if (c == SP_CONCEPT_TAIL) ENSURE(mean > 0.5); // long and thin
        // A leg pair is mostly the one closed outline round both limbs, as a hand traces it, not limb by limb.
        if (c == SP_CONCEPT_FRONT_LEGS || c == SP_CONCEPT_HIND_LEGS) ENSURE(closed > N / 2);
    }
}

static void test_handdraw_bad_input(void)
{
    sp_error err = {0};
    sp_sketch out;
    sp_handdraw_params hp = sp_handdraw_preset(SP_HANDDRAW_NORMAL);
    sp_sketch empty = {0};
    ENSURE(sp_handdraw_apply(&empty, &hp, 1, &out, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "empty"));
    sp_vec2 nan_pts[2] = {{0, 0}, {NAN, 1}};
    sp_sketch bad = {0};
    ENSURE(sp_sketch_add_stroke(&bad, nan_pts, NULL, 2) == SP_OK);
    ENSURE(sp_handdraw_apply(&bad, &hp, 1, &out, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "finite"));
    sp_sketch_free(&bad);
    sp_vec2 dot[2] = {{5, 5}, {5, 5}};
    ENSURE(sp_sketch_add_stroke(&bad, dot, NULL, 2) == SP_OK);
    ENSURE(sp_handdraw_apply(&bad, &hp, 1, &out, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "single point"));
    sp_sketch_free(&bad);
    sp_sketch sk = clean_sketch(0);
    hp.gap = -0.1;
    ENSURE(sp_handdraw_apply(&sk, &hp, 1, &out, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "out of range"));
    hp = sp_handdraw_preset(SP_HANDDRAW_NORMAL);
    hp.spacing_max = hp.spacing_min / 2;
    ENSURE(!sp_handdraw_params_valid(&hp));
    sp_sketch_free(&sk);
    dragon_part* p = &parts()[0];
    ENSURE(sp_handdraw_part(&p->ch.rig, 7, &p->ch.camera, NULL, 1, &out, NULL, &err) == SP_ERR_INVALID);
    ENSURE(sp_handdraw_style_parse("harsh") == SP_HANDDRAW_HARSH && sp_handdraw_style_parse("x") == SP_HANDDRAW_STYLE_COUNT);
}

// Rotation alone: every drawn point, turned back by info.rotation about the
// clean drawing's centre, lies on the clean curve; the angle stays within
// +-20 degrees in the harsh preset (+-15 normal) and uses the range.
static void test_handdraw_rotation(void)
{
    sp_sketch sk = clean_sketch(4);
    const sp_stroke* cs = &sk.strokes[0];
    sp_vec2 lo, hi;
    sp_sketch_bounds(&sk, &lo, &hi);
    sp_vec2 c = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y)};
    double D = diag(&sk);
    sp_handdraw_params hp = only();
    hp.rotation_deg = 20;
    sp_error err = {0};
    for (uint64_t seed = 1; seed <= 10; ++seed) {
        sp_sketch out;
        sp_handdraw_info info;
        ENSURE(sp_handdraw_apply(&sk, &hp, seed, &out, &info, &err) == SP_OK);
        ENSURE(out.stroke_count == 1 && fabs(info.rotation) <= 20 * PI / 180 + 1e-12);
        double worst = 0, worst_unrotated = 0, cs_ = cos(info.rotation), sn = sin(info.rotation);
        for (int i = 0; i < out.strokes[0].count; ++i) {
            sp_vec2 p = sp_v2_sub(out.strokes[0].points[i], c);
            sp_vec2 back = {c.x + cs_ * p.x - sn * p.y, c.y + sn * p.x + cs_ * p.y};
            worst = fmax(worst, dist_to_poly(back, cs->points, cs->count));
            worst_unrotated = fmax(worst_unrotated, dist_to_poly(out.strokes[0].points[i], cs->points, cs->count));
        }
        ENSURE(worst < 0.002 * D); // the pen's points lie on chords of the dense resampling
        if (fabs(info.rotation) > 2 * PI / 180) ENSURE(worst_unrotated > 0.005 * D); // the rotation is real
        sp_sketch_free(&out);
    }
    for (int st = SP_HANDDRAW_NORMAL; st <= SP_HANDDRAW_HARSH; ++st) {
        sp_handdraw_params pp = sp_handdraw_preset((sp_handdraw_style)st);
        double limit = st == SP_HANDDRAW_HARSH ? 20 : 15, most = 0;
        for (uint64_t seed = 1; seed <= 300; ++seed) {
            sp_sketch out;
            sp_handdraw_info info;
            ENSURE(sp_handdraw_apply(&sk, &pp, seed, &out, &info, &err) == SP_OK);
            ENSURE(fabs(info.rotation) * 180 / PI <= limit + 1e-9);
            most = fmax(most, fabs(info.rotation) * 180 / PI);
            ENSURE(info.aspect >= 1 / pp.aspect - 1e-12 && info.aspect <= pp.aspect + 1e-12);
            sp_sketch_free(&out);
        }
        ENSURE(most > 0.9 * limit);
    }
    sp_sketch_free(&sk);
}

// Closure alone: the traced length is (1 + closure) of the curve's (gaps < 0,
// overshoots > 0), the ends stay apart by about the gap; the harsh preset has
// both gaps and overshoots, larger than the normal one's.
static void test_handdraw_closure(void)
{
    sp_sketch sk = clean_sketch(4);
    double L = poly_length(&sk.strokes[0]), D = diag(&sk);
    sp_error err = {0};
    for (int kind = 0; kind < 2; ++kind) {
        sp_handdraw_params hp = only();
        hp.random_start = true;
        hp.gap = 0.1;
        hp.overshoot = 0.1;
        hp.gap_probability = kind == 0 ? 1.0 : 0.0;
        int seen = 0;
        for (uint64_t seed = 1; seed <= 40; ++seed) {
            sp_sketch out;
            sp_handdraw_info info;
            ENSURE(sp_handdraw_apply(&sk, &hp, seed, &out, &info, &err) == SP_OK);
            ENSURE(out.stroke_count == 1 && info.closed_curves == 1);
            double c = info.closure_min, drawn = poly_length(&out.strokes[0]);
            ENSURE(kind == 0 ? (c <= 0 && c >= -0.1) : (c >= 0 && c <= 0.1));
            ENSURE_NEAR(drawn / L, 1 + c, 0.01);
            double ends = sp_v2_len(sp_v2_sub(out.strokes[0].points[0], out.strokes[0].points[out.strokes[0].count - 1]));
            if (kind == 0 && c < -0.03) {
                ENSURE(ends > 0.3 * (-c) * L); // a chord of the missing arc
                ++seen;
            }
            if (kind == 1 && c > 0.03) {
                // The pen passed its start: the start lies on the stroke's last stretch.
                const sp_stroke* s = &out.strokes[0];
                int from = s->count - 1;
                for (double back = 0; from > 0 && back < 1.2 * c * L; --from)
                    back += sp_v2_len(sp_v2_sub(s->points[from], s->points[from - 1]));
                ENSURE(dist_to_poly(s->points[0], s->points + from, s->count - from) < 0.01 * D);
                ++seen;
            }
            sp_sketch_free(&out);
        }
        ENSURE(seen >= 10);
    }
    // The presets: over many sketches, harsh has both kinds and larger ones.
    double extreme[2][2] = {{0}};
    for (int st = 0; st < 2; ++st) {
        sp_handdraw_params pp = sp_handdraw_preset(st ? SP_HANDDRAW_HARSH : SP_HANDDRAW_NORMAL);
        int gaps = 0, overs = 0;
        for (uint64_t seed = 1; seed <= 200; ++seed) {
            sp_sketch out;
            sp_handdraw_info info;
            ENSURE(sp_handdraw_apply(&sk, &pp, seed, &out, &info, &err) == SP_OK);
            gaps += info.gaps;
            overs += info.overshoots;
            extreme[st][0] = fmin(extreme[st][0], info.closure_min);
            extreme[st][1] = fmax(extreme[st][1], info.closure_max);
            sp_sketch_free(&out);
        }
        printf("  %s: %d gaps, %d overshoots in 200; closure %.3f .. %.3f\n", st ? "harsh" : "normal", gaps, overs,
               extreme[st][0], extreme[st][1]);
        ENSURE(gaps >= 50 && overs >= 50);
    }
    ENSURE(extreme[1][0] < -0.07 && extreme[1][1] > 0.1);
    ENSURE(extreme[1][0] < extreme[0][0] && extreme[1][1] > extreme[0][1]);
    sp_sketch_free(&sk);
}

// Partial strokes, splits and direction.
static void test_handdraw_partial_split_direction(void)
{
    sp_sketch sk = clean_sketch(3);
    double L = poly_length(&sk.strokes[0]);
    sp_error err = {0};
    sp_handdraw_params hp = only();
    hp.partial_probability = 1;
    hp.partial = 0.3;
    for (uint64_t seed = 1; seed <= 30; ++seed) {
        sp_sketch out;
        sp_handdraw_info info;
        ENSURE(sp_handdraw_apply(&sk, &hp, seed, &out, &info, &err) == SP_OK);
        double f = poly_length(&out.strokes[0]) / L;
        ENSURE(info.partial == 1 && f >= 0.7 - 0.01 && f <= 1 - 0.105 + 0.01);
        ENSURE_NEAR(f, info.covered_min, 0.01);
        sp_sketch_free(&out);
    }
    // Harsh: some curves drawn in part, some in several strokes, both directions.
    sp_handdraw_params pp = sp_handdraw_preset(SP_HANDDRAW_HARSH);
    int partial = 0, split = 0, multi = 0, cw = 0, ccw = 0, reversed = 0;
    for (uint64_t seed = 1; seed <= 200; ++seed) {
        sp_sketch out;
        sp_handdraw_info info;
        ENSURE(sp_handdraw_apply(&sk, &pp, seed, &out, &info, &err) == SP_OK);
        partial += info.partial;
        split += info.split;
        reversed += info.reversed;
        multi += out.stroke_count > 1;
        ENSURE((out.stroke_count > 1) == (info.split > 0));
        if (out.stroke_count == 1 && info.covered_min > 0.9) {
            if (signed_area(&out.strokes[0]) > 0)
                ++cw;
            else
                ++ccw;
        }
        sp_sketch_free(&out);
    }
    printf("  harsh: %d partial, %d split, %d reversed; closed single strokes %d clockwise, %d counter-clockwise\n", partial,
           split, reversed, cw, ccw);
    ENSURE(partial >= 20 && partial <= 60); // 20% of 200
    ENSURE(split >= 35 && split <= 85 && multi == split);
    ENSURE(reversed >= 70 && reversed <= 130 && cw >= 30 && ccw >= 30);
    sp_sketch_free(&sk);
}

// Uneven sampling with timestamps; rounded corners; wobble.
static void test_handdraw_sampling_corners_wobble(void)
{
    sp_sketch sk = clean_sketch(5);
    double D = diag(&sk);
    sp_error err = {0};
    double cv[2] = {0};
    for (int st = 0; st < 2; ++st) {
        sp_handdraw_params hp = st ? sp_handdraw_preset(SP_HANDDRAW_NORMAL) : only();
        sp_sketch out;
        ENSURE(sp_handdraw_apply(&sk, &hp, 5, &out, NULL, &err) == SP_OK);
        double s1 = 0, s2 = 0;
        int n = 0;
        double t_prev = -1;
        for (int s = 0; s < out.stroke_count; ++s) {
            const sp_stroke* k = &out.strokes[s];
            ENSURE(k->t != NULL && k->t[0] > t_prev);
            for (int i = 1; i < k->count; ++i) {
                ENSURE(k->t[i] > k->t[i - 1]);
                double d = sp_v2_len(sp_v2_sub(k->points[i], k->points[i - 1]));
                s1 += d, s2 += d * d, ++n;
            }
            t_prev = k->t[k->count - 1];
        }
        double mean = s1 / n;
        cv[st] = sqrt(fmax(0, s2 / n - mean * mean)) / mean;
        sp_sketch_free(&out);
    }
    printf("  point spacing, coefficient of variation: clean %.3f, normal %.3f\n", cv[0], cv[1]);
    ENSURE(cv[0] < 0.1 && cv[1] > 0.4);
    // Corners: with rounding the drawn curve cuts the wing's sharp tips.
    sp_handdraw_params hp = only();
    hp.corner = 0.025;
    sp_sketch out;
    ENSURE(sp_handdraw_apply(&sk, &hp, 3, &out, NULL, &err) == SP_OK);
    double cut = 0;
    const sp_stroke* cs = &sk.strokes[0];
    for (int i = 0; i < cs->count; ++i)
        cut = fmax(cut, dist_to_poly(cs->points[i], out.strokes[0].points, out.strokes[0].count));
    printf("  rounded corners: a tip is cut by %.3f D\n", cut / D);
    ENSURE(cut > 0.005 * D && cut < 0.05 * D);
    sp_sketch_free(&out);
    // Wobble: the drawn curve strays from the clean one by about its amplitude, smoothly.
    hp = only();
    hp.wobble = 0.02;
    ENSURE(sp_handdraw_apply(&sk, &hp, 3, &out, NULL, &err) == SP_OK);
    double stray = 0;
    for (int i = 0; i < out.strokes[0].count; ++i)
        stray = fmax(stray, dist_to_poly(out.strokes[0].points[i], cs->points, cs->count));
    printf("  wobble: strays up to %.4f D\n", stray / D);
    ENSURE(stray > 0.003 * D && stray <= 0.02 * D + 1e-9);
    sp_sketch_free(&out);
    sp_sketch_free(&sk);
}

// The part database stores hand-drawn sketches (normal style) with each part.
static void test_db_synthetic_sketches(void)
{
    dragon_part* p = &parts()[1];
    sp_dataset a, b;
    sp_error err = {0};
    ENSURE(db_synth_sketches(&p->ch, p->abstraction, 5, 3, 0, &a, &err) == SP_OK);
    ENSURE(db_synth_sketches(&p->ch, p->abstraction, 5, 3, 0, &b, &err) == SP_OK);
    ENSURE(a.count == 5);
    for (int i = 0; i < a.count; ++i) {
        ENSURE(same_sketch(&a.samples[i].sketch, &b.samples[i].sketch));
        ENSURE(a.samples[i].sketch.strokes[0].t != NULL); // drawn by the model: timed pen samples
    }
    // Not the clean projection: closed curves do not end exactly where they start.
    int open_ends = 0;
    for (int i = 0; i < a.count; ++i) {
        const sp_stroke* s = &a.samples[i].sketch.strokes[0];
        open_ends += sp_v2_len(sp_v2_sub(s->points[0], s->points[s->count - 1])) > 1e-3;
    }
    ENSURE(open_ends >= 4);
    sp_dataset_free(&a);
    sp_dataset_free(&b);
}

// What a sketch shows (sp_handdraw_shape): the silhouette holds the
// abstraction, the top lies above the underside and both span the part, a
// line through the joints exactly for chain-shaped skeletons, a piece is
// smaller than the whole (the head's: the same head alone for every seed),
// added spikes add ink. Clean (unperturbed) drawings
// at the rest pose, so the geometry can be checked directly.
static void test_part_shapes(void)
{
    for (int i = 0; i < DRAGON_PART_COUNT; ++i) {
        dragon_part* p = &parts()[i];
        const sp_rig* rig = &p->ch.rig;
        double* q = malloc(sizeof(double) * (size_t)rig->param_count);
        sp_rig_defaults(rig, q);
        sp_sketch ab = clean_sketch(i), sil, top, under, spiky;
        ENSURE(sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_OUTLINE, true, 0, 1, &sil) ==
               SP_OK);
        ENSURE(sil.stroke_count == 1 &&
               sp_v2_len(sp_v2_sub(sil.strokes[0].points[0], sil.strokes[0].points[sil.strokes[0].count - 1])) < 1e-9);
        sp_vec2 alo, ahi, slo, shi;
        ENSURE(sp_sketch_bounds(&ab, &alo, &ahi) && sp_sketch_bounds(&sil, &slo, &shi));
        double tol = 0.02 * diag(&sil);
        ENSURE(alo.x >= slo.x - tol && alo.y >= slo.y - tol && ahi.x <= shi.x + tol && ahi.y <= shi.y + tol);
        ENSURE(sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_TOP, true, 0, 1, &top) == SP_OK);
        ENSURE(sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_UNDERSIDE, true, 0, 1, &under) ==
               SP_OK);
        double ty = 0, uy = 0;
        for (int k = 0; k < top.strokes[0].count; ++k)
            ty += top.strokes[0].points[k].y / top.strokes[0].count;
        for (int k = 0; k < under.strokes[0].count; ++k)
            uy += under.strokes[0].points[k].y / under.strokes[0].count;
        sp_vec2 tlo, thi;
        ENSURE(sp_sketch_bounds(&top, &tlo, &thi));
        ENSURE(ty < uy && fabs(tlo.x - slo.x) < 1e-9 && fabs(thi.x - shi.x) < 1e-9);
        // A single line: exactly when the skeleton's leaves are one or two (a tail, a pair of legs).
        int leaves = 0;
        for (int j = 0; j < rig->joint_count; ++j) {
            bool leaf = true;
            for (int c = 0; c < rig->joint_count; ++c)
                leaf &= rig->joints[c].parent != j;
            leaves += leaf;
        }
        bool line = sp_handdraw_shape_available(rig, SP_HANDDRAW_SHAPE_LINE);
        ENSURE(line == (leaves == 1 || leaves == 2));
        sp_sketch ln = {0};
        ENSURE((sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_LINE, false, 0, 1, &ln) ==
                SP_OK) == line);
        if (line) ENSURE(ln.stroke_count == 1 && ln.strokes[0].count >= 3 && diag(&ln) > 0.3 * diag(&sil));
        if (sp_handdraw_shape_available(rig, SP_HANDDRAW_SHAPE_PIECE)) {
            sp_sketch pc;
            ENSURE(sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_PIECE, true, 0, 7, &pc) ==
                   SP_OK);
            sp_vec2 plo, phi;
            ENSURE(sp_sketch_bounds(&pc, &plo, &phi));
            ENSURE((phi.x - plo.x) * (phi.y - plo.y) < 0.95 * (shi.x - slo.x) * (shi.y - slo.y));
            // The head's piece is the head without its neck whatever the seed (its
            // subtree, 66% of the vertices, is the smallest holding half), not a
            // draw between it and the head with the last neck bone.
            for (uint64_t seed = 1; !strcmp(p->name, "head") && seed <= 6; ++seed) {
                sp_sketch other;
                ENSURE(sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_PIECE, true, 0, seed,
                                               &other) == SP_OK);
                ENSURE(other.strokes[0].count == pc.strokes[0].count);
                for (int k = 0; k < pc.strokes[0].count; ++k)
                    ENSURE(sp_v2_len(sp_v2_sub(other.strokes[0].points[k], pc.strokes[0].points[k])) < 1e-9);
                sp_sketch_free(&other);
            }
            sp_sketch_free(&pc);
        }
        ENSURE(sp_handdraw_clean_shape(rig, p->abstraction, &p->ch.camera, q, SP_HANDDRAW_SHAPE_OUTLINE, true, 1.0, 3, &spiky) ==
               SP_OK);
        ENSURE(poly_length(&spiky.strokes[0]) > 1.03 * poly_length(&sil.strokes[0]));
        printf("  %-10s silhouette %d points, line %s, spikes +%.0f%% ink\n", p->name, sil.strokes[0].count, line ? "yes" : "no",
               100 * (poly_length(&spiky.strokes[0]) / poly_length(&sil.strokes[0]) - 1));
        sp_sketch_free(&ab), sp_sketch_free(&sil), sp_sketch_free(&top), sp_sketch_free(&under), sp_sketch_free(&spiky),
            sp_sketch_free(&ln);
        free(q);
    }
}

// ---- the command line ------------------------------------------------------------

static const char* sketchpose_bin(void)
{
    static char b[1024];
    snprintf(b, sizeof b, "%s/app/sketchpose", SP_BINARY_DIR);
    return access(b, X_OK) == 0 ? b : NULL;
}

static bool write_standins(const char* dir)
{
    mkdir(dir, 0777);
    for (int i = 0; i < DRAGON_PART_COUNT; ++i) {
        dragon_part p;
        dragon_standin(i, &p);
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.glb", dir, p.name);
        sp_error err = {0};
        sp_result r = sp_gltf_save(&p.ch, NULL, path, &err);
        sp_character_free(&p.ch);
        if (r != SP_OK) {
            fprintf(stderr, "%s\n", err.text);
            return false;
        }
    }
    return true;
}

// A written labelled folder's drawing `index` of `category` holds `want`'s
// points (to 1e-3 px: the files and a .glb's float32 round them).
static void ensure_written(const sp_dataset* ds, const char* category, int index, const sp_sketch* want)
{
    const sp_sample* got = NULL;
    for (int i = 0; i < ds->count; ++i)
        if (!strcmp(ds->categories[ds->samples[i].label], category) && ds->samples[i].index == index) got = &ds->samples[i];
    ENSURE(got && got->sketch.stroke_count == want->stroke_count);
    for (int s = 0; s < want->stroke_count; ++s) {
        ENSURE(got->sketch.strokes[s].count == want->strokes[s].count);
        for (int i = 0; i < want->strokes[s].count; ++i) {
            ENSURE_NEAR(got->sketch.strokes[s].points[i].x, want->strokes[s].points[i].x, 1e-3);
            ENSURE_NEAR(got->sketch.strokes[s].points[i].y, want->strokes[s].points[i].y, 1e-3);
        }
    }
}

static void test_cli_synth_concepts(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char out[1024], cmd[8192];
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("concepts_out"));
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && '%s' synth --concepts --per-part 3 --seed 4 --out-dir '%s' --sheet '%s/sheet.png' > /dev/null",
             out, bin, out, out);
    ENSURE(system(cmd) == 0);
    sp_dataset ds;
    sp_error err = {0};
    ENSURE(sp_dataset_load(out, &ds, &err) == SP_OK);
    ENSURE(ds.count == 3 * SP_CONCEPT_COUNT && ds.category_count == SP_CONCEPT_COUNT);
    // The files are the library's sketches of that seed family, seeded as the default recipe seeds them.
    sp_sketch want;
    ENSURE(sp_concept_sketch(SP_CONCEPT_WINGS, sp_handdraw_seed(sp_handdraw_part_family(4, "wings"), 2), &want, &err) == SP_OK);
    ensure_written(&ds, "wings", 2, &want);
    sp_sketch_free(&want);
    sp_dataset_free(&ds);
    char png[1100];
    snprintf(png, sizeof png, "%s/sheet.png", out);
    struct stat st;
    ENSURE(stat(png, &st) == 0 && st.st_size > 1000);
    // Bad usage: exit 2.
    snprintf(cmd, sizeof cmd, "'%s' synth --concepts --per-part 3 2>/dev/null", bin);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' synth --concepts --per-part 3 --style harsh --sheet '%s/x.png' 2>/dev/null", bin, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' synth --concepts --per-part 0 --sheet '%s/x.png' 2>/dev/null", bin, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    // The default database's count of them: a bad one is bad usage, before anything is built.
    snprintf(cmd, sizeof cmd, "'%s' db init --db '%s/never.db' --concepts 20000 2>/dev/null", bin, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' db init --db '%s/never.db' --drawings 101 2>/dev/null", bin, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    // The hand-placed designs' draws as a sheet: one line of JSON naming how many; a sheet is required.
    snprintf(cmd, sizeof cmd, "'%s' synth --drawings --per-part 2 --seed 3 --sheet '%s/drawn.png'", bin, out);
    FILE* pipe = popen(cmd, "r");
    char line[256] = "";
    ENSURE(pipe && fgets(line, sizeof line, pipe) && pclose(pipe) == 0);
    int designs = 0, sketches = 0;
    ENSURE(sscanf(line, "{\"designs\": %d, \"sketches\": %d", &designs, &sketches) == 2 && designs >= 120 &&
           sketches == 2 * designs);
    snprintf(png, sizeof png, "%s/drawn.png", out);
    ENSURE(stat(png, &st) == 0 && st.st_size > 1000);
    snprintf(cmd, sizeof cmd, "'%s' synth --drawings 2>/dev/null", bin);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' synth --drawings --per-part 0 --sheet '%s/x.png' 2>/dev/null", bin, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "%s/never.db", out);
    ENSURE(access(cmd, F_OK) != 0);
}

static void test_cli_synth_parts(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char dir[1024], out[1024], cmd[8192];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("standins"));
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("synth_out"));
    ENSURE(write_standins(dir));
    snprintf(cmd, sizeof cmd,
             "rm -rf '%s' && '%s' synth --parts '%s' --per-part 3 --seed 5 --style harsh --out-dir '%s' > '%s.json'", out, bin,
             dir, out, out);
    ENSURE(system(cmd) == 0);
    sp_dataset ds;
    sp_error err = {0};
    ENSURE(sp_dataset_load(out, &ds, &err) == SP_OK);
    ENSURE(ds.count == 3 * DRAGON_PART_COUNT && ds.category_count == DRAGON_PART_COUNT);
    ENSURE(!strcmp(ds.categories[0], "front_legs") && !strcmp(ds.categories[5], "wings"));
    // The same as the library's sketches of that family and style.
    dragon_part p;
    dragon_standin(3, &p);
    sp_sketch want;
    ENSURE(sp_handdraw_part(&p.ch.rig, 0, &p.ch.camera, &(sp_handdraw_desc){.style = SP_HANDDRAW_HARSH},
                            sp_handdraw_seed(sp_handdraw_part_family(5, "tail"), 1), &want, NULL, &err) == SP_OK);
    ensure_written(&ds, "tail", 1, &want);
    sp_sketch_free(&want);
    sp_character_free(&p.ch);
    sp_dataset_free(&ds);
    // Bad usage and bad input: exit 2 and 1 with one line.
    snprintf(cmd, sizeof cmd, "'%s' synth --parts '%s' --per-part 3 --style wild --out-dir '%s' 2>/dev/null", bin, dir, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' synth --parts '%s' --per-part 3 2>/dev/null", bin, dir);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' synth --parts '%s/none' --out-dir '%s' 2>/dev/null", bin, dir, out);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    // Single drawing with a style.
    snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s/wings.glb' --seed 2 --style normal --out '%s/w.json'", bin, dir, out);
    ENSURE(system(cmd) == 0);
    sp_sketch one;
    snprintf(cmd, sizeof cmd, "%s/w.json", out);
    ENSURE(sp_sketch_read_json(cmd, &one, &err) == SP_OK && one.stroke_count >= 1 && one.strokes[0].t);
    sp_sketch_free(&one);
}

// Reject calibration on held-out drawings: the threshold is the asked quantile
// of their distances, it survives save and load, bad arguments are refused.
static void test_calibrate_reject(void)
{
    sp_error err = {0};
    dragon_part sp[DRAGON_PART_COUNT];
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        dragon_standin(i, &sp[i]);
    sp_dataset train, held;
    ENSURE(dragon_set(sp, 12, 1, &(sp_handdraw_desc){0}, &train, &err) == SP_OK);
    ENSURE(dragon_set(sp, 10, 3, &(sp_handdraw_desc){.style = SP_HANDDRAW_HARSH}, &held, &err) == SP_OK);
    sp_clf* clf = NULL;
    ENSURE(sp_clf_train(&train, NULL, &(sp_clf_desc){.words = 32, .vocab_samples = 4000}, &clf, &err) == SP_OK);
    float d[64];
    int n = 0;
    ENSURE(sp_clf_calibrate_reject(clf, &held, NULL, 1.0, 1.0, d, &n, &err) == SP_OK);
    ENSURE(n == held.count && sp_clf_reject_distance(clf) == d[n - 1]);
    for (int i = 1; i < n; ++i)
        ENSURE(d[i] >= d[i - 1]);
    int rejected = 0;
    for (int i = 0; i < held.count; ++i) {
        sp_clf_answer a;
        ENSURE(sp_clf_classify(clf, &held.samples[i].sketch, NULL, &a, &err) == SP_OK);
        rejected += a.rejected;
    }
    ENSURE(rejected == 0); // the largest distance is accepted
    ENSURE(sp_clf_calibrate_reject(clf, &held, NULL, 0.5, 1.0, NULL, NULL, &err) == SP_OK);
    ENSURE(sp_clf_reject_distance(clf) == d[(int)ceil(0.5 * n) - 1]);
    rejected = 0;
    for (int i = 0; i < held.count; ++i) {
        sp_clf_answer a;
        ENSURE(sp_clf_classify(clf, &held.samples[i].sketch, NULL, &a, &err) == SP_OK);
        rejected += a.rejected;
    }
    ENSURE(rejected >= n / 2 - 1 && rejected <= n / 2 + 1);
    ENSURE(sp_clf_calibrate_reject(clf, &held, NULL, 0.5, 1.5, NULL, NULL, &err) == SP_OK);
    ENSURE_NEAR(sp_clf_reject_distance(clf), 1.5 * d[(int)ceil(0.5 * n) - 1], 1e-5);
    // Kept by the model file.
    const char* path = sp_test_tmp_path("calibrated.spclf");
    ENSURE(sp_clf_save(clf, path, &err) == SP_OK);
    sp_clf* back = NULL;
    ENSURE(sp_clf_load(path, &back, &err) == SP_OK);
    ENSURE(sp_clf_reject_distance(back) == sp_clf_reject_distance(clf));
    sp_clf_destroy(back);
    unlink(path);
    // Bad arguments.
    ENSURE(sp_clf_calibrate_reject(clf, &held, NULL, 0.0, 1.0, NULL, NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "quantile"));
    ENSURE(sp_clf_calibrate_reject(clf, &held, NULL, 1.5, 1.0, NULL, NULL, &err) == SP_ERR_INVALID);
    ENSURE(sp_clf_calibrate_reject(clf, &held, NULL, 0.9, 0.5, NULL, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "margin"));
    unsigned char none[64] = {0};
    ENSURE(sp_clf_calibrate_reject(clf, &held, none, 0.9, 1.0, NULL, NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "no usable"));
    sp_clf_destroy(clf);
    sp_dataset_free(&train);
    sp_dataset_free(&held);
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        sp_character_free(&sp[i].ch);
}

// `sketchpose train --calibrate DIR`: the threshold comes from the held-out folder.
static void test_cli_train_calibrate(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char dir[1024], tr[1024], cal[1024], model[1024], cmd[16384];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("standins_cal"));
    snprintf(tr, sizeof tr, "%s", sp_test_tmp_path("cal_train"));
    snprintf(cal, sizeof cal, "%s", sp_test_tmp_path("cal_held"));
    snprintf(model, sizeof model, "%s", sp_test_tmp_path("cal.spclf"));
    ENSURE(write_standins(dir));
    snprintf(cmd, sizeof cmd,
             "rm -rf '%s' '%s' && '%s' synth --parts '%s' --per-part 8 --seed 1 --out-dir '%s' > /dev/null && "
             "'%s' synth --parts '%s' --per-part 8 --seed 3 --style harsh --out-dir '%s' > /dev/null",
             tr, cal, bin, dir, tr, bin, dir, cal);
    ENSURE(system(cmd) == 0);
    char out[1100];
    snprintf(out, sizeof out, "%s.json", model);
    snprintf(cmd, sizeof cmd, "'%s' train --data '%s' --model '%s' --words 32 --calibrate '%s' --calibrate-quantile 1 > '%s'",
             bin, tr, model, cal, out);
    ENSURE(system(cmd) == 0);
    FILE* f = fopen(out, "r");
    ENSURE(f);
    char text[512] = "";
    size_t got = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[got] = 0;
    const char* rd = strstr(text, "\"reject_distance\": ");
    ENSURE(rd);
    double threshold = atof(rd + strlen("\"reject_distance\": "));
    // Quantile 1: no held-out drawing is rejected; each one's distance is at most the threshold.
    sp_clf* clf = NULL;
    sp_error err = {0};
    ENSURE(sp_clf_load(model, &clf, &err) == SP_OK);
    ENSURE_NEAR(sp_clf_reject_distance(clf), threshold, 1e-4);
    sp_dataset held;
    ENSURE(sp_dataset_load(cal, &held, &err) == SP_OK && held.count == 8 * DRAGON_PART_COUNT);
    for (int i = 0; i < held.count; ++i) {
        sp_clf_answer a;
        ENSURE(sp_clf_classify(clf, &held.samples[i].sketch, NULL, &a, &err) == SP_OK && !a.rejected);
    }
    sp_dataset_free(&held);
    sp_clf_destroy(clf);
    snprintf(cmd, sizeof cmd,
             "'%s' train --data '%s' --model '%s' --words 32 --calibrate '%s' --calibrate-quantile 2 2>/dev/null", bin, tr, model,
             cal);
    ENSURE(WEXITSTATUS(system(cmd)) == 2);
    snprintf(cmd, sizeof cmd, "'%s' train --data '%s' --model '%s' --words 32 --calibrate '%s/none' 2>/dev/null", bin, tr, model,
             cal);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    // eval's p90 is never below its median: with two drawings they were the
    // slower and the faster (15 ms median, 3 ms p90; an outside review).
    char two[1024], evals[1100];
    snprintf(two, sizeof two, "%s", sp_test_tmp_path("cal_two"));
    snprintf(evals, sizeof evals, "%s.json", two);
    snprintf(cmd, sizeof cmd,
             "rm -rf '%s' && mkdir -p '%s/head' '%s/tail' && cp '%s/head/head-harsh-s3-0000.json' '%s/head/' && "
             "cp '%s/tail/tail-harsh-s3-0000.json' '%s/tail/' && '%s' train --data '%s' --model '%s' --words 32 > /dev/null && "
             "'%s' eval --model '%s' --data '%s' > '%s'",
             two, two, two, cal, two, cal, two, bin, tr, model, bin, model, two, evals);
    ENSURE(system(cmd) == 0);
    f = fopen(evals, "r");
    ENSURE(f);
    got = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[got] = 0;
    const char *med = strstr(text, "\"ms_median\": "), *p90 = strstr(text, "\"ms_p90\": ");
    ENSURE(med && p90 && strstr(text, "\"n\": 2,"));
    ENSURE(atof(p90 + strlen("\"ms_p90\": ")) >= atof(med + strlen("\"ms_median\": ")));
    unlink(model);
}

// Out-of-range training and sketch options are bad usage, one line naming the
// option, before any data is read (they silently became defaults, or ran for hours).
static void test_cli_option_ranges(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char db[1024], cmd[4096];
    snprintf(db, sizeof db, "%s", sp_test_tmp_path("ranges.db"));
    unlink(db);
    const char* clf[] = {"--knn -3", "--knn 65", "--soft -1", "--pyramid 10", "--pyramid -1", "--reject-quantile 2",
                         "--reject-quantile -1", "--threads -1", "--threads 10000", "--seed -1", "--words 100000000",
                         "--words -5",
                         // a typed 0 is out of range too, not the default
                         "--words 0", "--knn 0", "--soft 0", "--pyramid 0", "--reject-quantile 0", "--threads 0"};
    const char* how[] = {"train --data /nonexistent --model /nonexistent/m", "eval --data /nonexistent --folds 3",
                         "db init --db '%s'", "db train --db '%s'"};
    for (size_t i = 0; i < sizeof clf / sizeof clf[0]; ++i) { // each command in turn: they share the check
        char sub[1200], line[512] = "", name[64];
        snprintf(sub, sizeof sub, how[i % 4], db);
        snprintf(cmd, sizeof cmd, "'%s' %s %s 2>&1 >/dev/null", bin, sub, clf[i]);
        FILE* p = popen(cmd, "r");
        ENSURE(p && fgets(line, sizeof line, p));
        int rc = pclose(p);
        snprintf(name, sizeof name, "%.*s must be", (int)strcspn(clf[i], " "), clf[i]);
        if (WEXITSTATUS(rc) != 2 || !strstr(line, name)) fprintf(stderr, "  %s: %d %s", cmd, WEXITSTATUS(rc), line);
        ENSURE(WEXITSTATUS(rc) == 2 && strstr(line, name));
    }
    const char* other[] = {
        "db add-part /nonexistent/p.glb --db '%s' --synth -5", "db add-part /nonexistent/p.glb --db '%s' --synth 100000000",
        "db init --db '%s' --synth -5", "synth --rig /nonexistent/r.glb --seed 1 --out '%s.json' --noise 1e300",
        "synth --rig /nonexistent/r.glb --seed 1 --out '%s.json' --noise -1",
        "synth --rig /nonexistent/r.glb --seed -1 --out '%s.json'",
        // ignored without --calibrate (the training set's threshold, silently)
        "train --data /nonexistent --model '%s.clf' --calibrate-quantile 0.5", "db init --db '%s' --augment 17",
        // a model keeps its training options: they were ignored
        "eval --model '%s.clf' --data /nonexistent --words 64", "eval --model '%s.clf' --data /nonexistent --folds 3 --knn 4",
        "eval --model '%s.clf' --data /nonexistent --handdraw"};
    for (size_t i = 0; i < sizeof other / sizeof other[0]; ++i) {
        char sub[1200];
        snprintf(sub, sizeof sub, other[i], db);
        snprintf(cmd, sizeof cmd, "'%s' %s 2>/dev/null", bin, sub);
        int rc = system(cmd);
        if (WEXITSTATUS(rc) != 2) fprintf(stderr, "  %s: %d\n", cmd, WEXITSTATUS(rc));
        ENSURE(WEXITSTATUS(rc) == 2);
    }
    ENSURE(access(db, F_OK) != 0); // refused before anything was written
}

// ---- the dragon-part classifier --------------------------------------------------

// Issue 5's criteria on a smaller set (the full 600/200 figures with 300
// training sketches per part: bench_dragon_classes): train on 6 x 100 sketches
// (normal style, one in four clean, seed family 1; 1000 words), calibrate the
// reject threshold on 6 x 50 harsh sketches of family 3 (quantile 0.96), test
// on 6 x 40 harsh sketches of family 2 and on 80 Quick, Draw! drawings of
// objects (8 categories x 10): top-1 >= 97%, <= 3% of the dragon sketches
// rejected, >= 80% of the scribbles.
static void test_dragon_accuracy_and_rejection(void)
{
#if defined(__SANITIZE_ADDRESS__)
    // Several minutes under ASan; the plain build measures it, and calibrate_reject
    // runs the same training, classification and calibration code here.
    SKIP("accuracy figures are measured in the plain build (slow under sanitizers)");
#endif
    sp_error err = {0};
    sp_dataset train, test, cal, scrib;
    ENSURE(dragon_set(parts(), 100, 1, &(sp_handdraw_desc){.style = SP_HANDDRAW_NORMAL, .clean_share = 0.25}, &train, &err) ==
           SP_OK);
    ENSURE(dragon_set(parts(), 40, 2, &(sp_handdraw_desc){.style = SP_HANDDRAW_HARSH}, &test, &err) == SP_OK);
    ENSURE(dragon_set(parts(), 50, 3, &(sp_handdraw_desc){.style = SP_HANDDRAW_HARSH}, &cal, &err) == SP_OK);
    bool have_scribbles = dragon_scribbles(sp_test_data_dir(), 10, &scrib, &err) == SP_OK;
    sp_clf* clf = NULL;
    sp_result r = sp_clf_train(&train, NULL, &(sp_clf_desc){.words = 1000}, &clf, &err);
    if (r != SP_OK) fprintf(stderr, "  %s\n", err.text);
    ENSURE(r == SP_OK);
    dragon_scores before;
    dragon_score(clf, &test, have_scribbles ? &scrib : NULL, &before);
    float loo = sp_clf_reject_distance(clf);
    ENSURE(sp_clf_calibrate_reject(clf, &cal, NULL, 0.96, 1.0, NULL, NULL, &err) == SP_OK);
    dragon_scores s;
    dragon_score(clf, &test, have_scribbles ? &scrib : NULL, &s);
    printf("  held-out harsh: top-1 %d/%d, top-3 %d/%d\n", s.right, s.n, s.top3, s.n);
    printf("  training-set threshold %.4f: %d/%d dragon sketches rejected, %d/%d scribbles\n", loo, before.rejected, before.n,
           before.scribbles_rejected, before.scribbles);
    printf("  calibrated threshold %.4f: %d/%d dragon sketches rejected, %d/%d scribbles\n", sp_clf_reject_distance(clf),
           s.rejected, s.n, s.scribbles_rejected, s.scribbles);
    for (int i = 0; i < train.category_count; ++i) {
        printf("    %-12s", train.categories[i]);
        for (int j = 0; j < train.category_count; ++j)
            printf(" %3d", s.confusion[i][j]);
        printf("\n");
    }
    ENSURE(s.n == 240 && s.failed == 0 && s.right == before.right);
    ENSURE(s.right >= 0.97 * s.n);
    ENSURE(s.rejected <= 0.03 * s.n);
    // Calibration is what makes the dragon sketches pass: the training set's own threshold rejects more of them.
    ENSURE(before.rejected > s.rejected);
    if (have_scribbles) ENSURE(s.scribbles == 80 && s.scribbles_rejected >= 0.8 * s.scribbles);
    sp_clf_destroy(clf);
    sp_dataset_free(&train);
    sp_dataset_free(&test);
    sp_dataset_free(&cal);
    if (have_scribbles) sp_dataset_free(&scrib);
    if (!have_scribbles) SKIP("../shared/data absent: rejection of non-dragon drawings not measured (accuracy was)");
}

static void test_cleanup(void)
{
    if (g_loaded) dragon_parts_free(g_parts);
    g_loaded = false;
}

int main(int argc, char** argv)
{
    if (argc == 3 && !strcmp(argv[1], "--write-standins")) {
        return write_standins(argv[2]) ? 0 : 1;
    }
    return sp_test_run(argc, argv,
                       (sp_test[]){{"handdraw_deterministic", test_handdraw_deterministic},
                                   {"handdraw_bad_input", test_handdraw_bad_input},
                                   {"handdraw_rotation", test_handdraw_rotation},
                                   {"handdraw_closure", test_handdraw_closure},
                                   {"handdraw_partial_split_direction", test_handdraw_partial_split_direction},
                                   {"handdraw_sampling_corners_wobble", test_handdraw_sampling_corners_wobble},
                                   {"db_synthetic_sketches", test_db_synthetic_sketches},
                                   {"part_shapes", test_part_shapes},
                                   {"concepts", test_concepts},
                                   {"cli_synth_parts", test_cli_synth_parts},
                                   {"cli_synth_concepts", test_cli_synth_concepts},
                                   {"calibrate_reject", test_calibrate_reject},
                                   {"cli_train_calibrate", test_cli_train_calibrate},
                                   {"cli_option_ranges", test_cli_option_ranges},
                                   {"dragon_accuracy_and_rejection", test_dragon_accuracy_and_rejection},
                                   {"zz_cleanup", test_cleanup},
                                   {0}});
}
