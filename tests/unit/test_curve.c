// Curve tests: arc-length resampling, cleaning, the ordered and closest-point
// correspondences, the Hungarian method against brute force, and the
// stroke-to-curve assignment under shuffling and reversal.
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fixtures.h"
#include "sp/curve.h"
#include "test.h"

static double d2(sp_vec2 a, sp_vec2 b)
{
    return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y);
}

static double seg_dist(sp_vec2 q, sp_vec2 a, sp_vec2 b)
{
    sp_vec2 ab = sp_v2_sub(b, a);
    double l2 = sp_v2_dot(ab, ab);
    double t = l2 > 0 ? sp_v2_dot(sp_v2_sub(q, a), ab) / l2 : 0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return sp_v2_len(sp_v2_sub(q, sp_v2_add(a, sp_v2_scale(ab, t))));
}

// Arc-length position of each sample on the polyline, walking forward (the
// samples are in arc order), so that self-touching polylines are fine. Every
// sample must lie on the polyline (within tol).
static void arc_params(const sp_vec2* p, int n, bool closed, const sp_vec2* q, int m, double* s, double tol)
{
    int nseg = closed ? n : n - 1, j = 0;
    double s0 = 0;
    for (int k = 0; k < m; ++k) {
        while (j < nseg) {
            sp_vec2 a = p[j], b = p[(j + 1) % n];
            if (seg_dist(q[k], a, b) <= tol) break;
            s0 += sp_v2_len(sp_v2_sub(b, a));
            ++j;
        }
        ENSURE(j < nseg);
        s[k] = s0 + sp_v2_len(sp_v2_sub(q[k], p[j]));
    }
}

// A zigzag with repeated points and zero-length segments.
static int zigzag(sp_vec2* p)
{
    sp_vec2 pts[] = {{0, 0}, {10, 0}, {10, 0}, {10, 5}, {3, 5}, {3, 5}, {3, 5}, {3, 12}, {20, 12}, {20, 30}, {20, 30}};
    int n = (int)(sizeof pts / sizeof pts[0]);
    memcpy(p, pts, sizeof pts);
    return n;
}

static void test_resample_open_uniform(void)
{
    sp_vec2 p[16], q[57];
    double s[57];
    int n = zigzag(p), m = 57;
    double L = sp_curve_length(p, n, false);
    ENSURE_NEAR(L, 10 + 5 + 7 + 7 + 17 + 18, 1e-12);
    ENSURE(sp_curve_resample(p, n, false, m, q) == SP_OK);
    ENSURE(q[0].x == p[0].x && q[0].y == p[0].y);
    ENSURE(q[m - 1].x == p[n - 1].x && q[m - 1].y == p[n - 1].y);
    arc_params(p, n, false, q, m, s, 1e-9);
    for (int k = 0; k < m; ++k)
        ENSURE_NEAR(s[k], L * k / (m - 1), 1e-9);
    // m = 2: just the end points.
    ENSURE(sp_curve_resample(p, n, false, 2, q) == SP_OK);
    ENSURE(q[0].x == 0 && q[0].y == 0 && q[1].x == 20 && q[1].y == 30);
}

static void test_resample_closed_uniform(void)
{
    sp_vec2 p[16], q[41];
    double s[41];
    int n = zigzag(p), m = 41;
    double L = sp_curve_length(p, n, true);
    ENSURE_NEAR(L, sp_curve_length(p, n, false) + sqrt(20 * 20 + 30 * 30), 1e-12);
    ENSURE(sp_curve_resample(p, n, true, m, q) == SP_OK);
    ENSURE(q[0].x == p[0].x && q[0].y == p[0].y);
    arc_params(p, n, true, q, m, s, 1e-9);
    for (int k = 0; k < m; ++k)
        ENSURE_NEAR(s[k], L * k / m, 1e-9);
    // Across the seam: the closing gap equals every other spacing.
    ENSURE_NEAR(L - s[m - 1], L / m, 1e-9);
    // A square with its start repeated at the end (closing segment of length 0).
    sp_vec2 sq[5] = {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 0}};
    sp_vec2 r[8];
    ENSURE(sp_curve_resample(sq, 5, true, 8, r) == SP_OK);
    sp_vec2 want[8] = {{0, 0}, {2, 0}, {4, 0}, {4, 2}, {4, 4}, {2, 4}, {0, 4}, {0, 2}};
    for (int k = 0; k < 8; ++k)
        ENSURE(d2(r[k], want[k]) < 1e-24);
}

static void test_resample_degenerate(void)
{
    sp_vec2 q[10];
    sp_vec2 one = {3, 4};
    ENSURE(sp_curve_resample(&one, 1, false, 10, q) == SP_OK);
    for (int k = 0; k < 10; ++k)
        ENSURE(q[k].x == 3 && q[k].y == 4);
    ENSURE(sp_curve_resample(&one, 1, true, 10, q) == SP_OK);
    for (int k = 0; k < 10; ++k)
        ENSURE(q[k].x == 3 && q[k].y == 4);
    sp_vec2 same[6] = {{1, 2}, {1, 2}, {1, 2}, {1, 2}, {1, 2}, {1, 2}};
    ENSURE(sp_curve_length(same, 6, true) == 0);
    ENSURE(sp_curve_resample(same, 6, false, 7, q) == SP_OK);
    for (int k = 0; k < 7; ++k)
        ENSURE(q[k].x == 1 && q[k].y == 2);
    // m = 1: the first point.
    sp_vec2 line[2] = {{0, 0}, {10, 0}};
    ENSURE(sp_curve_resample(line, 2, false, 1, q) == SP_OK);
    ENSURE(q[0].x == 0 && q[0].y == 0);
    // Errors.
    ENSURE(sp_curve_resample(line, 0, false, 5, q) == SP_ERR_INVALID);
    ENSURE(sp_curve_resample(line, 2, false, 0, q) == SP_ERR_INVALID);
    sp_vec2 bad[3] = {{0, 0}, {NAN, 1}, {2, 2}};
    ENSURE(!sp_curve_is_valid(bad, 3));
    ENSURE(sp_curve_resample(bad, 3, false, 5, q) == SP_ERR_INVALID);
    bad[1] = (sp_vec2){INFINITY, 0};
    ENSURE(sp_curve_resample(bad, 3, true, 5, q) == SP_ERR_INVALID);
    // Finite coordinates whose length overflows.
    sp_vec2 huge[2] = {{-1.7e308, 0}, {1.7e308, 0}};
    ENSURE(sp_curve_resample(huge, 2, false, 5, q) == SP_ERR_INVALID);
    ENSURE(sp_curve_clean(bad, 0, 0, q) == 0);
}

// 10^6 points on a noisy spiral: linear time, and still uniform.
static void test_resample_million(void)
{
    int n = 1000000, m = 1000;
    sp_vec2* p = malloc(sizeof(sp_vec2) * n);
    sp_vec2* q = malloc(sizeof(sp_vec2) * m);
    double* s = malloc(sizeof(double) * m);
    sp_test_rng rng = {7};
    for (int i = 0; i < n; ++i) {
        double t = 20.0 * i / n, r = 10 + 10 * t;
        p[i] = (sp_vec2){r * cos(t) + sp_test_range(&rng, -0.01, 0.01), r * sin(t)};
        if (i % 10 == 3) p[i] = p[i - 1]; // duplicates
    }
    clock_t t0 = clock();
    ENSURE(sp_curve_resample(p, n, false, m, q) == SP_OK);
    ENSURE(sp_curve_resample(p, n, true, m, q) == SP_OK);
    ENSURE(sp_curve_resample(p, n, false, m, q) == SP_OK);
    double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    ENSURE(secs < 2.0); // ~30 ms when linear, even under sanitizers well below
    double L = sp_curve_length(p, n, false);
    arc_params(p, n, false, q, m, s, 1e-7);
    for (int k = 0; k < m; ++k)
        ENSURE_NEAR(s[k], L * k / (m - 1), 1e-6 * L);
    ENSURE(q[m - 1].x == p[n - 1].x && q[m - 1].y == p[n - 1].y);
    int kept = sp_curve_clean(p, n, 0, p);
    ENSURE(kept == n - n / 10);
    free(p), free(q), free(s);
}

static void test_clean_smooth(void)
{
    sp_vec2 p[8] = {{0, 0}, {0, 0}, {1, 0}, {1, 0}, {1.2, 0}, {3, 0}, {3.1, 0}, {3.1, 0}};
    sp_vec2 q[8];
    ENSURE(sp_curve_clean(p, 8, 0, q) == 5);
    ENSURE(q[4].x == 3.1 && q[3].x == 3 && q[2].x == 1.2);
    // With a 0.5 px step: 1.2 goes (too close to 1), 3.1 replaces 3 (the end is kept).
    ENSURE(sp_curve_clean(p, 8, 0.5, q) == 3);
    ENSURE(q[0].x == 0 && q[1].x == 1 && q[2].x == 3.1);
    // In place, and a stroke shorter than the step keeps both ends.
    sp_vec2 tiny[3] = {{0, 0}, {0.1, 0}, {0.2, 0}};
    ENSURE(sp_curve_clean(tiny, 3, 1.0, tiny) == 2);
    ENSURE(tiny[0].x == 0 && tiny[1].x == 0.2);
    sp_vec2 dot[3] = {{5, 5}, {5, 5}, {5, 5}};
    ENSURE(sp_curve_clean(dot, 3, 1.0, dot) == 1);
    // Smoothing keeps evenly spaced straight lines and open end points, and pulls in a spike.
    sp_vec2 l[5] = {{0, 0}, {1, 0}, {2, 3}, {3, 0}, {4, 0}};
    sp_curve_smooth(l, 5, false, 3, l);
    ENSURE(l[0].x == 0 && l[0].y == 0 && l[4].x == 4 && l[4].y == 0);
    ENSURE(l[2].y < 3 && l[2].y > 0);
    sp_vec2 straight[4] = {{0, 0}, {1, 1}, {2, 2}, {3, 3}}, out[4];
    sp_curve_smooth(straight, 4, false, 5, out);
    for (int i = 0; i < 4; ++i) {
        ENSURE_NEAR(out[i].x, i, 1e-12);
        ENSURE_NEAR(out[i].y, i, 1e-12);
    }
    sp_vec2 sq[4] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
    sp_curve_smooth(sq, 4, true, 1, sq);
    ENSURE_NEAR(sq[0].x, 0.5, 1e-12);
    ENSURE_NEAR(sq[0].y, 0.5, 1e-12);
}

// n points along an ellipse about c (radii rx, ry) gone round `turns` times.
static void ring(sp_vec2* p, int n, sp_vec2 c, double rx, double ry, double turns)
{
    for (int i = 0; i < n; ++i) {
        double a = 2 * M_PI * turns * i / (n - 1);
        p[i] = (sp_vec2){c.x + rx * cos(a), c.y + ry * sin(a)};
    }
}

// Strokes that go over themselves (a loop gone round twice, a line out and
// back) and strokes that only come near themselves (a closing overlap, a
// spiral, stick legs drawn down, up and down again).
static void test_retrace_start(void)
{
    enum { N = 400 };
    static sp_vec2 p[N];
    // An oval gone round twice, its second turn 3 px outside the first: cut after one turn.
    for (int i = 0; i < N; ++i) {
        double a = 4 * M_PI * i / (N - 1), grow = 3.0 * i / (N - 1);
        p[i] = (sp_vec2){500 + (200 + grow) * cos(a), 400 + (85 + grow) * sin(a)};
    }
    int r = sp_curve_retrace_start(p, N, 10, 0.25);
    fprintf(stderr, "  oval twice: keep %d of %d\n", r, N);
    ENSURE(r >= N / 2 - 4 && r <= N / 2 + 8);
    // An eye 12 px across gone round three times, at the kiosk's tolerance
    // (7.5 px, more than its radius): cut after one whole turn, where it was
    // cut a tol short of closing, four fifths of a ring (an outside review).
    ring(p, 90, (sp_vec2){600, 400}, 6, 6, 3.0);
    r = sp_curve_retrace_start(p, 90, 7.5, 0.25);
    fprintf(stderr, "  eye three times: keep %d of 90 (a turn is 30)\n", r);
    ENSURE(r >= 29 && r <= 34);
    // A body gone round one and a half times: cut after one turn (the rest
    // of the first turn, not gone over again, was cut as a line back to the
    // start: half a ring; a second review).
    ring(p, 120, (sp_vec2){640, 420}, 220, 110, 1.5);
    r = sp_curve_retrace_start(p, 120, 7.5, 0.25);
    fprintf(stderr, "  body one and a half times: keep %d of 120 (a turn is 80)\n", r);
    ENSURE(r >= 76 && r <= 86);
    // A D whose straight side is one segment, gone round twice: one D (the
    // cut went on along the whole segment; a second review).
    int nd = 0;
    for (int lap = 0; lap < 2; ++lap) {
        for (int i = lap ? 1 : 0; i <= 40; ++i)
            p[nd++] = (sp_vec2){500 + 150 * cos(-M_PI / 2 + M_PI * i / 40), 400 + 150 * sin(-M_PI / 2 + M_PI * i / 40)};
        p[nd++] = (sp_vec2){500, 250};
    }
    r = sp_curve_retrace_start(p, nd, 7.5, 0.25);
    fprintf(stderr, "  a D twice: keep %d of %d (a D is 42)\n", r, nd);
    ENSURE(r >= 41 && r <= 45);
    // A coiled spring drawn, the pen back to its start in a wide arc, and the
    // spring again: cut before the arc (a test of straightness kept it and
    // closed the spring into wings; a third review). Its coils cross, as no
    // loop's one turn does.
    nd = 0;
    for (int i = 0; i < 60; ++i) {
        double u = i / 59.0;
        p[nd++] = (sp_vec2){480 + 300 * u - 25 * sin(8 * M_PI * u), 150 + 50 * cos(8 * M_PI * u)};
    }
    for (int i = 1; i < 12; ++i) { // a quadratic arc over the top, back to (455, 200)
        double u = i / 12.0;
        sp_vec2 a = p[59], b = {630, -120}, e = p[0];
        p[nd++] = (sp_vec2){(1 - u) * (1 - u) * a.x + 2 * u * (1 - u) * b.x + u * u * e.x,
                            (1 - u) * (1 - u) * a.y + 2 * u * (1 - u) * b.y + u * u * e.y};
    }
    for (int i = 0; i < 60; ++i)
        p[nd++] = p[i];
    r = sp_curve_retrace_start(p, nd, 9.5, 0.25);
    fprintf(stderr, "  a spring, a wide arc back, the spring: keep %d of %d (the spring is 60)\n", r, nd);
    ENSURE(r >= 56 && r <= 64);
    // 1.2 turns: the overlap of a closed outline stays.
    ring(p, N, (sp_vec2){500, 400}, 200, 85, 1.2);
    ENSURE(sp_curve_retrace_start(p, N, 10, 0.25) == N);
    // A wavy line out and back along itself (2 px beside it): cut at the turn.
    for (int i = 0; i < N; ++i) {
        double u = i < N / 2 ? i / (N / 2.0 - 1) : 1 - (i - N / 2) / (N / 2.0 - 1);
        p[i] = (sp_vec2){100 + 600 * u, 300 + 40 * sin(6 * u) + (i >= N / 2 ? 2 : 0)};
    }
    r = sp_curve_retrace_start(p, N, 10, 0.25);
    fprintf(stderr, "  out and back: keep %d of %d\n", r, N);
    ENSURE(r >= N / 2 - 4 && r <= N / 2 + 12);
    // Stick legs: down, up the same line, down another 60 px away: not a retrace.
    for (int i = 0; i < N; ++i) {
        int leg = i * 3 / N;
        double u = (i - leg * N / 3.0) / (N / 3.0);
        p[i] = leg == 0   ? (sp_vec2){300, 200 + 200 * u}
               : leg == 1 ? (sp_vec2){300, 400 - 200 * u}
                          : (sp_vec2){300 + 60 * u, 200 + 200 * u};
    }
    ENSURE(sp_curve_retrace_start(p, N, 10, 0.25) == N);
    // A spiral of three rings 20 px apart.
    for (int i = 0; i < N; ++i) {
        double a = 6 * M_PI * i / (N - 1);
        p[i] = (sp_vec2){500 + (20 + 20 * a / (2 * M_PI)) * cos(a), 400 + (20 + 20 * a / (2 * M_PI)) * sin(a)};
    }
    ENSURE(sp_curve_retrace_start(p, N, 10, 0.25) == N);
    // Shading drawn back and forth, each pass a little lower (as a child
    // colours in): each pass goes over the last one only.
    for (int i = 0; i < 200; ++i)
        p[i] = (sp_vec2){500 - 15 + 30 * fabs(fmod(i * 0.37, 2.0) - 1), 400 - 12 + 0.12 * i};
    ENSURE(sp_curve_retrace_start(p, 200, 3, 0.25) == 200);
    // Teeth 22 px tall, closed by a straight line back through their middle:
    // within tol of every tooth, in half their length.
    int m = 0;
    for (double x = 0; x <= 280; x += 4, ++m)
        p[m] = (sp_vec2){300 + x, 300 - (2 + 22 * (1 - fabs(2 * fmod(x, 28) / 28 - 1)))};
    for (double x = 280; x >= 0; x -= 4)
        p[m++] = (sp_vec2){300 + x, 300 - 12};
    ENSURE(sp_curve_retrace_start(p, m, 7.3, 0.25) == m);
    // A doodle drawn again from where it began, the pen jumping back (one
    // long segment): cut where the first pass ends, the jump left out (kept,
    // it closed the doodle into a shape a part).
    m = 0;
    for (int i = 0; i < 60; ++i)
        p[m++] = (sp_vec2){300 + 4 * i, 300 + (i < 30 ? 2 * i : 120 - 2 * i)};
    for (int i = 1; i < 60; ++i)
        p[m++] = p[i];
    ENSURE(sp_curve_retrace_start(p, m, 7.5, 0.25) == 60);
    // An outline with 40 teeth 12 px tall gone round twice exactly: the teeth
    // lie off the chords of a 64-sample resampling, not off the stroke.
    enum { LAP = 190 };
    for (int i = 0; i < 2 * LAP; ++i) {
        double a = 2 * M_PI * (i % LAP) / LAP, rad = 200 + ((i % LAP) % 5 == 2 ? 12 : 0);
        p[i] = (sp_vec2){500 + rad * cos(a), 400 + rad * sin(a)};
    }
    r = sp_curve_retrace_start(p, 2 * LAP, 7.5, 0.25);
    fprintf(stderr, "  toothed outline twice: keep %d of %d\n", r, 2 * LAP);
    ENSURE(r >= LAP - 4 && r <= LAP + 8);
    // A scribble: its points lie near the scribble before them, but here
    // and there, not along it.
    uint64_t z = 42;
    for (int i = 0; i < 400; ++i) {
        z = z * 6364136223846793005ull + 1442695040888963407ull;
        double u = (double)(z >> 11) / 9007199254740992.0;
        z = z * 6364136223846793005ull + 1442695040888963407ull;
        double v = (double)(z >> 11) / 9007199254740992.0;
        p[i] = (sp_vec2){500 + 300 * u, 300 + 200 * v};
    }
    ENSURE(sp_curve_retrace_start(p, 400, 9, 0.25) == 400);
    // Too few points, no tolerance, no length.
    ENSURE(sp_curve_retrace_start(p, 3, 10, 0.25) == 3 && sp_curve_retrace_start(p, N, 0, 0.25) == N);
    for (int i = 0; i < 8; ++i)
        p[i] = (sp_vec2){7, 7};
    ENSURE(sp_curve_retrace_start(p, 8, 10, 0.25) == 8);
}

static void circle(sp_vec2* p, int m, double cx, double cy, double r, double phase)
{
    for (int i = 0; i < m; ++i) {
        double a = phase + 2 * M_PI * i / m;
        p[i] = (sp_vec2){cx + r * cos(a), cy + 0.7 * r * sin(a)};
    }
}

static bool is_permutation(const int* match, int m)
{
    char seen[1024] = {0};
    for (int i = 0; i < m; ++i) {
        if (match[i] < 0 || match[i] >= m || seen[match[i]]) return false;
        seen[match[i]] = 1;
    }
    return true;
}

static void test_ordered_direction(void)
{
    enum { M = 50 };
    sp_vec2 z[M], y[M];
    int match[M];
    sp_test_rng rng = {3};
    for (int i = 0; i < M; ++i)
        z[i] = (sp_vec2){100 + 4 * i, 200 + 30 * sin(i * 0.1)};
    for (int i = 0; i < M; ++i)
        y[i] = sp_v2_add(z[M - 1 - i], (sp_vec2){sp_test_range(&rng, -1, 1), sp_test_range(&rng, -1, 1)});
    sp_ordered_info info;
    ENSURE(sp_corr_ordered(y, z, M, false, match, &info) == SP_OK);
    ENSURE(info.reversed && info.shift == 0);
    for (int i = 0; i < M; ++i)
        ENSURE(match[i] == M - 1 - i);
    double c = 0;
    for (int i = 0; i < M; ++i)
        c += d2(y[i], z[match[i]]);
    ENSURE_NEAR(info.cost, c, 1e-9);
    ENSURE(info.cost < 2.0 * M);
    // Forward.
    ENSURE(sp_corr_ordered(z, z, M, false, match, &info) == SP_OK);
    ENSURE(!info.reversed && info.cost == 0);
    for (int i = 0; i < M; ++i)
        ENSURE(match[i] == i);
    // Exact tie (all points equal): forward wins.
    sp_vec2 same[M];
    for (int i = 0; i < M; ++i)
        same[i] = (sp_vec2){1, 1};
    ENSURE(sp_corr_ordered(same, same, M, true, match, &info) == SP_OK);
    ENSURE(!info.reversed && info.shift == 0 && info.cost == 0);
    // m = 1 and invalid input.
    ENSURE(sp_corr_ordered(z, y, 1, true, match, &info) == SP_OK && match[0] == 0);
    ENSURE(sp_corr_ordered(z, y, 0, true, match, &info) == SP_ERR_INVALID);
    y[3].x = NAN;
    ENSURE(sp_corr_ordered(y, z, M, false, match, &info) == SP_ERR_INVALID);
}

static void test_ordered_cyclic_shift(void)
{
    enum { M = 60 };
    sp_vec2 z[M], y[M];
    int match[M];
    sp_ordered_info info;
    circle(z, M, 300, 200, 80, 0.3);
    for (int k = 0; k < M; k += 7) {
        // Same direction, start at sample k (plus a little noise).
        for (int i = 0; i < M; ++i)
            y[i] = sp_v2_add(z[(i + k) % M], (sp_vec2){0.3 * sin(i), 0.2 * cos(3 * i)});
        ENSURE(sp_corr_ordered(y, z, M, true, match, &info) == SP_OK);
        ENSURE(!info.reversed && info.shift == k);
        ENSURE(is_permutation(match, M));
        for (int i = 0; i < M; ++i)
            ENSURE(match[i] == (i + k) % M);
        // Drawn the other way round from sample k.
        for (int i = 0; i < M; ++i)
            y[i] = z[((k - i) % M + M) % M];
        ENSURE(sp_corr_ordered(y, z, M, true, match, &info) == SP_OK);
        ENSURE(info.reversed && info.shift == k && info.cost < 1e-18);
        ENSURE(is_permutation(match, M));
        for (int i = 0; i < M; ++i)
            ENSURE(match[i] == ((k - i) % M + M) % M);
    }
    // From resampling: a closed stroke that starts a quarter of the way around.
    enum { N = 400 };
    sp_vec2 dense[N], ys[M], zs[M];
    circle(dense, N, 0, 0, 100, 0);
    sp_vec2 rot[N];
    for (int i = 0; i < N; ++i)
        rot[i] = dense[(i + N / 4) % N];
    ENSURE(sp_curve_resample(dense, N, true, M, zs) == SP_OK);
    ENSURE(sp_curve_resample(rot, N, true, M, ys) == SP_OK);
    ENSURE(sp_corr_ordered(ys, zs, M, true, NULL, &info) == SP_OK);
    ENSURE(!info.reversed && info.shift == M / 4);
}

static void test_closest_both_ways(void)
{
    enum { MY = 37, MZ = 53 };
    sp_vec2 y[MY], z[MZ];
    sp_corr_pair pairs[MY + MZ];
    sp_test_rng rng = {9};
    for (int i = 0; i < MY; ++i)
        y[i] = (sp_vec2){sp_test_range(&rng, 0, 640), sp_test_range(&rng, 0, 480)};
    for (int j = 0; j < MZ; ++j)
        z[j] = (sp_vec2){sp_test_range(&rng, 0, 640), sp_test_range(&rng, 0, 480)};
    z[10] = z[4]; // an exact tie: the lowest index wins
    double cost = -1;
    ENSURE(sp_corr_closest(y, MY, z, MZ, pairs, &cost) == SP_OK);
    bool ycov[MY] = {0}, zcov[MZ] = {0};
    double c = 0;
    for (int k = 0; k < MY + MZ; ++k) {
        ENSURE(pairs[k].y >= 0 && pairs[k].y < MY && pairs[k].z >= 0 && pairs[k].z < MZ);
        ycov[pairs[k].y] = zcov[pairs[k].z] = true;
        c += d2(y[pairs[k].y], z[pairs[k].z]);
    }
    for (int i = 0; i < MY; ++i)
        ENSURE(ycov[i]);
    for (int j = 0; j < MZ; ++j)
        ENSURE(zcov[j]);
    ENSURE_NEAR(cost, c, 1e-9 * c);
    for (int i = 0; i < MY; ++i) {
        ENSURE(pairs[i].y == i);
        ENSURE(pairs[i].z != 10);
        for (int j = 0; j < MZ; ++j)
            ENSURE(d2(y[i], z[pairs[i].z]) <= d2(y[i], z[j]));
    }
    for (int j = 0; j < MZ; ++j) {
        ENSURE(pairs[MY + j].z == j);
        for (int i = 0; i < MY; ++i)
            ENSURE(d2(z[j], y[pairs[MY + j].y]) <= d2(z[j], y[i]));
    }
    ENSURE(sp_corr_closest(y, 0, z, MZ, pairs, NULL) == SP_ERR_INVALID);
}

// Both directions against a plain scan: the same partner, lowest index on ties.
static void check_closest_exact(const sp_vec2* y, int my, const sp_vec2* z, int mz)
{
    sp_corr_pair* pairs = malloc(sizeof(sp_corr_pair) * (size_t)(my + mz));
    ENSURE(sp_corr_closest(y, my, z, mz, pairs, NULL) == SP_OK);
    for (int i = 0; i < my; ++i) {
        int bj = 0;
        for (int j = 1; j < mz; ++j)
            if (d2(y[i], z[j]) < d2(y[i], z[bj])) bj = j;
        ENSURE(pairs[i].y == i && pairs[i].z == bj);
    }
    for (int j = 0; j < mz; ++j) {
        int bi = 0;
        for (int i = 1; i < my; ++i)
            if (d2(z[j], y[i]) < d2(z[j], y[bi])) bi = i;
        ENSURE(pairs[my + j].z == j && pairs[my + j].y == bi);
    }
    free(pairs);
}

// The sweep (below SP_CORR_BRUTE_MAX) is exact: integer points with many
// exact ties (equal coordinates, equal distances) in a square, a tall and a
// wide box (the sweep runs along the longer side), and curves, where each
// search starts from the previous answer, one of them queried backwards.
static void test_closest_exact_ties(void)
{
    enum { MY = 90, MZ = 70 };
    sp_vec2 y[MY], z[MZ];
    sp_test_rng rng = {33};
    // Integer grids (many ties): square, tall (swept along y) and wide.
    const double ext[3][2] = {{8, 8}, {3, 30}, {30, 3}};
    for (int e = 0; e < 3; ++e) {
        for (int i = 0; i < MY; ++i)
            y[i] = (sp_vec2){(double)(int)sp_test_range(&rng, 0, ext[e][0]), (double)(int)sp_test_range(&rng, 0, ext[e][1])};
        for (int j = 0; j < MZ; ++j)
            z[j] = (sp_vec2){(double)(int)sp_test_range(&rng, 0, ext[e][0]), (double)(int)sp_test_range(&rng, 0, ext[e][1])};
        check_closest_exact(y, MY, z, MZ);
    }
    // Curves (each search starts from the last answer): random walks, tall
    // and wide, one of them queried backwards, crossing each other.
    for (int e = 0; e < 2; ++e) {
        sp_vec2 a = {0, 0}, b = {5, 0};
        for (int i = 0; i < MY; ++i) {
            a = (sp_vec2){a.x + sp_test_range(&rng, -1, 1) * (e ? 4 : 1), a.y + sp_test_range(&rng, -1, 1) * (e ? 1 : 4)};
            y[e ? i : MY - 1 - i] = a;
        }
        for (int j = 0; j < MZ; ++j) {
            b = (sp_vec2){b.x + sp_test_range(&rng, -1, 1) * (e ? 4 : 1), b.y + sp_test_range(&rng, -1, 1) * (e ? 1 : 4)};
            z[j] = b;
        }
        check_closest_exact(y, MY, z, MZ);
    }
}

// Polyline distances by the sweep against every segment: a closed curve,
// an open one with a long segment (the sweep's reach must cover it), a lone
// point and a zero-length segment; queries around and far off; bad next[].
static void test_polyline_distances(void)
{
    enum { N = 60, NQ = 400 };
    sp_vec2 p[N], q[NQ];
    int next[N];
    double out[NQ];
    sp_test_rng rng = {8};
    for (int v = 0; v < 30; ++v) { // closed: a wobbly circle
        double a = 2 * 3.14159265358979 * v / 30, r = sp_test_range(&rng, 80, 120);
        p[v] = (sp_vec2){200 + r * cos(a), 200 + r * sin(a)};
        next[v] = v + 1 < 30 ? v + 1 : 0;
    }
    for (int v = 30; v < 58; ++v) { // open, one segment 300 px long
        p[v] = (sp_vec2){400 + 7 * (v - 30) + (v == 45 ? 300 : 0), 50 + sp_test_range(&rng, -20, 20)};
        next[v] = v + 1 < 58 ? v + 1 : -1;
    }
    p[58] = (sp_vec2){650, 200}, next[58] = -1; // alone, above the long segment
    p[59] = p[57], next[57] = 59, next[59] = -1;  // zero length
    for (int i = 0; i < NQ; ++i) q[i] = (sp_vec2){sp_test_range(&rng, -300, 1100), sp_test_range(&rng, -300, 700)};
    q[0] = (sp_vec2){650, 60}; // over the long segment, far from its ends
    ENSURE(sp_polyline_distances(p, next, N, q, NQ, out) == SP_OK);
    for (int i = 0; i < NQ; ++i) {
        double best = INFINITY;
        for (int v = 0; v < N; ++v) {
            bool lone = next[v] < 0;
            for (int u = 0; u < N && lone; ++u) lone = next[u] != v;
            if (lone) best = fmin(best, sqrt(d2(q[i], p[v])));
            if (next[v] < 0) continue;
            sp_vec2 a = p[v], b = p[next[v]];
            double l2 = d2(a, b), t = l2 > 0 ? ((q[i].x - a.x) * (b.x - a.x) + (q[i].y - a.y) * (b.y - a.y)) / l2 : 0;
            t = fmin(1, fmax(0, t));
            best = fmin(best, sqrt(d2(q[i], (sp_vec2){a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)})));
        }
        ENSURE_NEAR(out[i], best, 1e-9);
    }
    ENSURE(out[0] < 20);
    next[3] = N;
    ENSURE(sp_polyline_distances(p, next, N, q, NQ, out) == SP_ERR_INVALID);
    ENSURE(sp_polyline_distances(p, next, 0, q, NQ, out) == SP_ERR_INVALID);
}

static double ordered_cost_ref(const sp_vec2* y, const sp_vec2* z, int m, bool rev, int shift)
{
    double c = 0;
    for (int i = 0; i < m; ++i) c += d2(y[i], z[(((rev ? shift - i : shift + i) % m) + m) % m]);
    return c;
}

// The candidates of the ordered matching on a closed curve: a stroke that is
// the curve started 17 samples on puts shift 17 first at zero cost, drawn
// backwards the reversed direction; the list holds local minima of the cost
// only, best first, none within m / 20 of a better one of its direction, at
// most k.
static void test_ordered_candidates(void)
{
    enum { M = 80 };
    sp_vec2 z[M], y[M], yr[M];
    for (int i = 0; i < M; ++i) {
        double a = 2 * 3.14159265358979 * i / M;
        z[i] = (sp_vec2){300 + (100 + 40 * cos(3 * a)) * cos(a), 200 + (100 + 40 * cos(3 * a)) * sin(a)}; // three lobes
    }
    for (int i = 0; i < M; ++i) y[i] = z[(i + 17) % M], yr[i] = z[((17 - i) % M + M) % M];
    sp_ordered_info c[6];
    int n = sp_corr_ordered_candidates(y, z, M, c, 6);
    ENSURE(n >= 3); // a three-lobed outline has more than one local minimum
    ENSURE(!c[0].reversed && c[0].shift == 17 && c[0].cost < 1e-9);
    for (int t = 1; t < n; ++t) {
        ENSURE(c[t].cost >= c[t - 1].cost);
        for (int u = 0; u < t; ++u) {
            int d = abs(c[t].shift - c[u].shift);
            ENSURE(c[t].reversed != c[u].reversed || (d >= M / 20 && M - d >= M / 20));
        }
    }
    for (int t = 0; t < n; ++t) { // each is its cost, no higher than its neighbours'
        double here = ordered_cost_ref(y, z, M, c[t].reversed, c[t].shift);
        ENSURE_NEAR(c[t].cost, here, 1e-9 * (1 + here));
        ENSURE(here <= ordered_cost_ref(y, z, M, c[t].reversed, (c[t].shift + 1) % M));
        ENSURE(here <= ordered_cost_ref(y, z, M, c[t].reversed, (c[t].shift + M - 1) % M));
    }
    sp_ordered_info info;
    ENSURE(sp_corr_ordered(y, z, M, true, NULL, &info) == SP_OK && info.shift == c[0].shift && !info.reversed);
    ENSURE(sp_corr_ordered_candidates(yr, z, M, c, 2) == 2 && c[0].reversed && c[0].shift == 17 && c[0].cost < 1e-9);
    ENSURE(sp_corr_ordered_candidates(y, z, M, c, 1) == 1);
    ENSURE(sp_corr_ordered_candidates(y, z, 2, c, 4) == 0);
    y[5].x = NAN;
    ENSURE(sp_corr_ordered_candidates(y, z, M, c, 4) == 0);
}

// Above SP_CORR_BRUTE_MAX the k-d tree answers; it must be exact.
static void test_closest_kdtree(void)
{
    int my = 1500, mz = 1200;
    ENSURE((double)my * mz > SP_CORR_BRUTE_MAX);
    sp_vec2* y = malloc(sizeof(sp_vec2) * my);
    sp_vec2* z = malloc(sizeof(sp_vec2) * mz);
    sp_corr_pair* pairs = malloc(sizeof(sp_corr_pair) * (my + mz));
    sp_test_rng rng = {21};
    for (int i = 0; i < my; ++i)
        y[i] = (sp_vec2){sp_test_range(&rng, 0, 1920), sp_test_range(&rng, 0, 1080)};
    for (int j = 0; j < mz; ++j)
        z[j] = (sp_vec2){sp_test_range(&rng, 0, 1920), sp_test_range(&rng, 0, 1080)};
    double cost;
    ENSURE(sp_corr_closest(y, my, z, mz, pairs, &cost) == SP_OK);
    for (int i = 0; i < my; ++i) {
        double best = INFINITY;
        for (int j = 0; j < mz; ++j)
            best = fmin(best, d2(y[i], z[j]));
        ENSURE(pairs[i].y == i);
        ENSURE(d2(y[i], z[pairs[i].z]) == best);
    }
    for (int j = 0; j < mz; ++j) {
        double best = INFINITY;
        for (int i = 0; i < my; ++i)
            best = fmin(best, d2(z[j], y[i]));
        ENSURE(pairs[my + j].z == j);
        ENSURE(d2(z[j], y[pairs[my + j].y]) == best);
    }
    // A million stroke samples against a small curve: no crash, every sample paired.
    int big = 1000000;
    sp_vec2* yy = malloc(sizeof(sp_vec2) * big);
    sp_corr_pair* pp = malloc(sizeof(sp_corr_pair) * (big + 100));
    for (int i = 0; i < big; ++i)
        yy[i] = (sp_vec2){sp_test_range(&rng, 0, 640), sp_test_range(&rng, 0, 480)};
    ENSURE(sp_corr_closest(yy, big, z, 100, pp, NULL) == SP_OK);
    for (int i = 0; i < big; i += 9973) {
        double best = INFINITY;
        for (int j = 0; j < 100; ++j)
            best = fmin(best, d2(yy[i], z[j]));
        ENSURE(d2(yy[i], z[pp[i].z]) == best);
    }
    free(yy), free(pp), free(y), free(z), free(pairs);
}

// Minimum over all injective maps of the smaller side into the larger.
static double brute_assign(const double* c, int rows, int cols, int depth, bool* used, double acc)
{
    bool tr = rows > cols;
    int n = tr ? cols : rows, m = tr ? rows : cols;
    if (depth == n) return acc;
    double best = INFINITY;
    for (int j = 0; j < m; ++j) {
        if (used[j]) continue;
        used[j] = true;
        double v = tr ? c[j * cols + depth] : c[depth * cols + j];
        best = fmin(best, brute_assign(c, rows, cols, depth + 1, used, acc + v));
        used[j] = false;
    }
    return best;
}

static void check_hungarian(int rows, int cols, sp_test_rng* rng)
{
    double c[64];
    int r2c[8], c2r[8];
    for (int k = 0; k < rows * cols; ++k)
        c[k] = sp_test_range(rng, -5, 20);
    double total;
    ENSURE(sp_assign_hungarian(c, rows, cols, r2c, c2r, &total) == SP_OK);
    bool used[8] = {0};
    double sum = 0;
    int assigned = 0;
    for (int i = 0; i < rows; ++i) {
        if (r2c[i] < 0) continue;
        ENSURE(r2c[i] < cols && !used[r2c[i]] && c2r[r2c[i]] == i);
        used[r2c[i]] = true;
        sum += c[i * cols + r2c[i]];
        ++assigned;
    }
    for (int j = 0; j < cols; ++j)
        ENSURE(c2r[j] == -1 || r2c[c2r[j]] == j);
    ENSURE(assigned == (rows < cols ? rows : cols));
    ENSURE_NEAR(total, sum, 1e-12);
    bool u[8] = {0};
    ENSURE_NEAR(total, brute_assign(c, rows, cols, 0, u, 0), 1e-9);
}

static void test_hungarian_vs_brute(void)
{
    sp_test_rng rng = {1234};
    for (int trial = 0; trial < 200; ++trial) {
        check_hungarian(5, 5, &rng);
        check_hungarian(4, 6, &rng);
        check_hungarian(6, 4, &rng);
        check_hungarian(1, 3, &rng);
        check_hungarian(3, 1, &rng);
    }
    // Integer costs with many ties.
    for (int trial = 0; trial < 100; ++trial) {
        double c[25];
        int r2c[5];
        for (int k = 0; k < 25; ++k)
            c[k] = floor(sp_test_range(&rng, 0, 3));
        double total;
        ENSURE(sp_assign_hungarian(c, 5, 5, r2c, NULL, &total) == SP_OK);
        bool u[8] = {0};
        ENSURE(total == brute_assign(c, 5, 5, 0, u, 0));
    }
    // Degenerate sizes and bad input.
    int r2c[3] = {7, 7, 7};
    double total = 1;
    ENSURE(sp_assign_hungarian(NULL, 3, 0, r2c, NULL, &total) == SP_OK);
    ENSURE(r2c[0] == -1 && r2c[2] == -1 && total == 0);
    double bad[4] = {1, NAN, 2, 3};
    ENSURE(sp_assign_hungarian(bad, 2, 2, r2c, NULL, NULL) == SP_ERR_INVALID);
    // All equal: a valid, reproducible assignment.
    double flat[12] = {0};
    int a1[3], a2[3];
    ENSURE(sp_assign_hungarian(flat, 3, 4, a1, NULL, NULL) == SP_OK);
    ENSURE(sp_assign_hungarian(flat, 3, 4, a2, NULL, NULL) == SP_OK);
    ENSURE(memcmp(a1, a2, sizeof a1) == 0);
    ENSURE(a1[0] != a1[1] && a1[1] != a1[2] && a1[0] != a1[2]);
}

// A stick figure: head (closed), torso, two arms, one leg; in pixels.
enum { NC = 5 };
static sp_vec2 g_curve_pts[NC][40];
static sp_polyline g_curves[NC];

static void make_curves(void)
{
    circle(g_curve_pts[0], 24, 320, 80, 30, 0);
    g_curves[0] = (sp_polyline){g_curve_pts[0], 24, true};
    for (int i = 0; i < 10; ++i)
        g_curve_pts[1][i] = (sp_vec2){320, 115 + 18.0 * i};
    g_curves[1] = (sp_polyline){g_curve_pts[1], 10, false};
    for (int i = 0; i < 8; ++i)
        g_curve_pts[2][i] = (sp_vec2){310 - 14.0 * i, 140 + 6.0 * i};
    g_curves[2] = (sp_polyline){g_curve_pts[2], 8, false};
    for (int i = 0; i < 8; ++i)
        g_curve_pts[3][i] = (sp_vec2){330 + 14.0 * i, 140 + 2.0 * i * i};
    g_curves[3] = (sp_polyline){g_curve_pts[3], 8, false};
    for (int i = 0; i < 12; ++i)
        g_curve_pts[4][i] = (sp_vec2){315 - 6.0 * i, 290 + 15.0 * i};
    g_curves[4] = (sp_polyline){g_curve_pts[4], 12, false};
}

// Stroke s traces curve `perm[s]`, densely, with noise, reversed when asked,
// closed strokes starting at `start`.
static void make_strokes(sp_sketch* sk, const int* perm, const bool* rev, int count, int start, uint64_t seed)
{
    *sk = (sp_sketch){0};
    sp_test_rng rng = {seed};
    for (int s = 0; s < count; ++s) {
        const sp_polyline* c = &g_curves[perm[s]];
        int n = 30 + 7 * perm[s];
        sp_vec2 pts[200];
        sp_curve_resample(c->points, c->count, c->closed, n, pts);
        sp_vec2 tmp[200];
        for (int i = 0; i < n; ++i) {
            int k = c->closed ? (i + start) % n : i;
            tmp[i] = sp_v2_add(pts[k], (sp_vec2){sp_test_range(&rng, -2, 2), sp_test_range(&rng, -2, 2)});
        }
        if (rev[s])
            for (int i = 0; i < n / 2; ++i) {
                sp_vec2 t = tmp[i];
                tmp[i] = tmp[n - 1 - i], tmp[n - 1 - i] = t;
            }
        ENSURE(sp_sketch_add_stroke(sk, tmp, NULL, n) == SP_OK);
    }
}

static void test_assign_order_independent(void)
{
    make_curves();
    int ident[NC] = {0, 1, 2, 3, 4};
    bool fwd[NC] = {0};
    sp_sketch a;
    make_strokes(&a, ident, fwd, NC, 0, 5);
    for (int kind = 0; kind < 2; ++kind) {
        sp_assign_desc desc = {.match = kind ? SP_CORR_CLOSEST : SP_CORR_ORDERED};
        sp_stroke_match ma[NC], mb[NC];
        int c2s[NC];
        sp_error err = {{0}};
        ENSURE(sp_assign_strokes(a.strokes, NC, g_curves, NC, &desc, ma, c2s, &err) == SP_OK);
        for (int s = 0; s < NC; ++s) {
            ENSURE(ma[s].curve == s && c2s[s] == s);
            // The noisy head's start lands within one sample of the curve's.
            ENSURE(!ma[s].reversed && (ma[s].shift <= 1 || ma[s].shift == 63));
            ENSURE(ma[s].cost < 8.0); // noise of +-2 px
        }
        // Shuffled, every other stroke reversed, the head started elsewhere.
        int perm[NC] = {3, 0, 4, 2, 1};
        bool rev[NC] = {true, false, true, false, true};
        sp_sketch b;
        make_strokes(&b, perm, rev, NC, 0, 5);
        ENSURE(sp_assign_strokes(b.strokes, NC, g_curves, NC, &desc, mb, c2s, &err) == SP_OK);
        for (int s = 0; s < NC; ++s) {
            ENSURE(mb[s].curve == perm[s] && c2s[perm[s]] == s);
            ENSURE(mb[s].reversed == (kind == 0 && rev[s]));
        }
        sp_sketch_free(&b);
        // The same strokes (bit for bit) reversed and shuffled: identical mapping and costs.
        sp_sketch cpy = {0};
        for (int k = 0; k < NC; ++k) {
            int s = perm[k];
            const sp_stroke* st = &a.strokes[s];
            sp_vec2 tmp[200];
            for (int i = 0; i < st->count; ++i)
                tmp[i] = st->points[rev[k] ? st->count - 1 - i : i];
            ENSURE(sp_sketch_add_stroke(&cpy, tmp, NULL, st->count) == SP_OK);
        }
        ENSURE(sp_assign_strokes(cpy.strokes, NC, g_curves, NC, &desc, mb, NULL, &err) == SP_OK);
        for (int k = 0; k < NC; ++k) {
            ENSURE(mb[k].curve == ma[perm[k]].curve);
            ENSURE(mb[k].reversed == (kind == 0 && rev[k]));
            ENSURE_NEAR(mb[k].cost, ma[perm[k]].cost, 1e-9 * (1 + ma[perm[k]].cost));
        }
        sp_sketch_free(&cpy);
        // A closed stroke begun a third of the way round, drawn backwards.
        int head[1] = {0};
        bool back[1] = {true};
        sp_sketch h;
        make_strokes(&h, head, back, 1, 10, 8);
        sp_stroke_match mh;
        ENSURE(sp_assign_strokes(h.strokes, 1, g_curves, NC, &desc, &mh, c2s, &err) == SP_OK);
        ENSURE(mh.curve == 0 && c2s[0] == 0 && c2s[1] == -1);
        // Backwards from stroke point 10 of 30: its first point is curve point 9 of 30,
        // 0.3 of the way round, so near sample 19 of 64.
        if (kind == 0) ENSURE(mh.reversed && abs(mh.shift - 19) <= 1);
        sp_sketch_free(&h);
    }
    sp_sketch_free(&a);
}

static void test_assign_counts(void)
{
    make_curves();
    // Six strokes, five curves: the extra (a copy of the leg, shifted away) is unassigned.
    int perm6[6] = {4, 1, 0, 2, 3, 4};
    bool fwd[6] = {0};
    sp_sketch sk;
    make_strokes(&sk, perm6, fwd, 6, 0, 3);
    for (int i = 0; i < sk.strokes[5].count; ++i)
        sk.strokes[5].points[i].x += 200;
    sp_stroke_match mt[6];
    int c2s[NC];
    sp_error err = {{0}};
    ENSURE(sp_assign_strokes(sk.strokes, 6, g_curves, NC, NULL, mt, c2s, &err) == SP_OK);
    for (int s = 0; s < 5; ++s)
        ENSURE(mt[s].curve == perm6[s]);
    ENSURE(mt[5].curve == -1 && mt[5].cost == 0);
    for (int c = 0; c < NC; ++c)
        ENSURE(c2s[c] >= 0 && c2s[c] < 5);
    sp_sketch_free(&sk);
    // Two strokes, five curves: three curves unmatched.
    int perm2[2] = {3, 1};
    make_strokes(&sk, perm2, fwd, 2, 0, 4);
    ENSURE(sp_assign_strokes(sk.strokes, 2, g_curves, NC, &(sp_assign_desc){.samples = 16}, mt, c2s, &err) == SP_OK);
    ENSURE(mt[0].curve == 3 && mt[1].curve == 1);
    int unmatched = 0;
    for (int c = 0; c < NC; ++c)
        unmatched += c2s[c] == -1;
    ENSURE(unmatched == 3);
    // Determinism: bit-identical on a second run.
    sp_stroke_match again[2];
    ENSURE(sp_assign_strokes(sk.strokes, 2, g_curves, NC, &(sp_assign_desc){.samples = 16}, again, NULL, &err) == SP_OK);
    for (int s = 0; s < 2; ++s)
        ENSURE(again[s].curve == mt[s].curve && again[s].reversed == mt[s].reversed && again[s].shift == mt[s].shift &&
               memcmp(&again[s].cost, &mt[s].cost, sizeof(double)) == 0);
    sp_sketch_free(&sk);
    // No curves / no strokes.
    make_strokes(&sk, perm2, fwd, 2, 0, 4);
    ENSURE(sp_assign_strokes(sk.strokes, 2, g_curves, 0, NULL, mt, NULL, &err) == SP_OK);
    ENSURE(mt[0].curve == -1 && mt[1].curve == -1);
    ENSURE(sp_assign_strokes(NULL, 0, g_curves, NC, NULL, NULL, c2s, &err) == SP_OK);
    ENSURE(c2s[0] == -1 && c2s[4] == -1);
    sp_sketch_free(&sk);
}

static void test_assign_degenerate(void)
{
    make_curves();
    sp_sketch sk = {0};
    sp_vec2 one = {320, 80}, line[2] = {{320, 120}, {320, 280}};
    sp_vec2 same[4] = {{100, 100}, {100, 100}, {100, 100}, {100, 100}};
    ENSURE(sp_sketch_add_stroke(&sk, line, NULL, 2) == SP_OK);
    ENSURE(sp_sketch_add_stroke(&sk, &one, NULL, 1) == SP_OK);
    ENSURE(sp_sketch_add_stroke(&sk, same, NULL, 4) == SP_OK);
    sp_stroke_match mt[4];
    sp_error err = {{0}};
    ENSURE(sp_assign_strokes(sk.strokes, 3, g_curves, NC, NULL, mt, NULL, &err) == SP_OK);
    ENSURE(mt[0].curve == 1); // the torso line
    ENSURE(mt[1].curve >= 0 && mt[2].curve >= 0 && mt[1].curve != mt[2].curve);
    for (int s = 0; s < 3; ++s)
        ENSURE(isfinite(mt[s].cost));
    // An empty stroke and a NaN are reported by index.
    ENSURE(sp_sketch_add_stroke(&sk, NULL, NULL, 0) == SP_OK);
    ENSURE(sp_assign_strokes(sk.strokes, 4, g_curves, NC, NULL, mt, NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "stroke 3") != NULL);
    sk.strokes[0].points[1].y = NAN;
    ENSURE(sp_assign_strokes(sk.strokes, 3, g_curves, NC, NULL, mt, NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "stroke 0") != NULL);
    sp_sketch_free(&sk);
    // One stroke of 10^6 points (a dense torso line) against the figure.
    int n = 1000000;
    sp_vec2* p = malloc(sizeof(sp_vec2) * n);
    for (int i = 0; i < n; ++i)
        p[i] = (sp_vec2){320 + 0.5 * sin(i * 0.001), 115 + 162.0 * i / (n - 1)};
    sp_stroke big = {n, p, NULL};
    ENSURE(sp_assign_strokes(&big, 1, g_curves, NC, NULL, mt, NULL, &err) == SP_OK);
    ENSURE(mt[0].curve == 1 && !mt[0].reversed);
    free(p);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"resample_open_uniform", test_resample_open_uniform},
                                   {"resample_closed_uniform", test_resample_closed_uniform},
                                   {"resample_degenerate", test_resample_degenerate},
                                   {"resample_million", test_resample_million},
                                   {"clean_smooth", test_clean_smooth},
                                   {"retrace_start", test_retrace_start},
                                   {"ordered_direction", test_ordered_direction},
                                   {"ordered_cyclic_shift", test_ordered_cyclic_shift},
                                   {"closest_both_ways", test_closest_both_ways},
                                   {"closest_kdtree", test_closest_kdtree},
                                   {"hungarian_vs_brute", test_hungarian_vs_brute},
                                   {"closest_exact_ties", test_closest_exact_ties},
                                   {"polyline_distances", test_polyline_distances},
                                   {"ordered_candidates", test_ordered_candidates},
                                   {"assign_order_independent", test_assign_order_independent},
                                   {"assign_counts", test_assign_counts},
                                   {"assign_degenerate", test_assign_degenerate},
                                   {0}});
}
