// concept.c: the dragon parts as visitors imagine them (sp/concept.h).
//
// Every design is built facing +x with y down, in units of the part's main
// size (a skull's radius, a body's half length), as one path in the order a
// hand draws it, then mirrored, turned, scaled and centred on the canvas.
// The shapes follow the variety the issue names (open jaws and teeth, horns,
// frills, 2-5 scallops, spades and curls, claws, boots, humps); they are not
// copied from the evaluation drawings (tests/data/visitors), which no part of
// the recipe reads.
#include "sp/concept.h"

#include <math.h>
#include <string.h>

#include "db_internal.h"
#include "sp/handdraw.h"
#include "sp/synth.h"

#define PATH_CAP 1024

typedef struct path {
    sp_vec2 p[PATH_CAP];
    int n;
} path;

static const char* const k_names[SP_CONCEPT_COUNT] = {"head", "wings", "tail", "front_legs", "hind_legs", "torso"};

const char* sp_concept_name(sp_concept c) { return (unsigned)c < SP_CONCEPT_COUNT ? k_names[c] : "unknown"; }

sp_concept sp_concept_parse(const char* category)
{
    for (int i = 0; category && i < SP_CONCEPT_COUNT; ++i)
        if (!strcmp(category, k_names[i])) return (sp_concept)i;
    return SP_CONCEPT_COUNT;
}

static double U(sp_rng* r, double lo, double hi) { return sp_rng_range(r, lo, hi); }
static bool chance(sp_rng* r, double p) { return sp_rng_uniform(r) < p; }

static void put(path* P, double x, double y)
{
    if (P->n < PATH_CAP) P->p[P->n++] = (sp_vec2){x, y};
}
static void put_v(path* P, sp_vec2 v) { put(P, v.x, v.y); }

// Ellipse arc from angle a0 to a1 (y down: increasing angles go clockwise on screen), both ends included.
static void arc(path* P, double cx, double cy, double rx, double ry, double a0, double a1)
{
    int n = 2 + (int)(fabs(a1 - a0) / 0.12);
    for (int i = 0; i <= n; ++i) {
        double a = a0 + (a1 - a0) * i / n;
        put(P, cx + rx * cos(a), cy + ry * sin(a));
    }
}

// Quadratic curve from the path's last point through control c to b (b included).
static void quad_to(path* P, sp_vec2 c, sp_vec2 b)
{
    sp_vec2 a = P->n ? P->p[P->n - 1] : c;
    for (int i = 1; i <= 6; ++i) {
        double t = i / 6.0, u = 1 - t;
        put(P, u * u * a.x + 2 * u * t * c.x + t * t * b.x, u * u * a.y + 2 * u * t * c.y + t * t * b.y);
    }
}

// k teeth (or spikes) from the last point to b, tips h to the left of the way (y down: left is the screen's
// counter-clockwise side; a negative h points them to the right).
static void teeth_to(path* P, sp_vec2 b, int k, double h)
{
    sp_vec2 a = P->n ? P->p[P->n - 1] : b;
    sp_vec2 d = sp_v2_sub(b, a);
    double len = sqrt(d.x * d.x + d.y * d.y);
    if (len <= 0 || k < 1) {
        put_v(P, b);
        return;
    }
    sp_vec2 nrm = {d.y / len, -d.x / len};
    for (int i = 0; i < k; ++i) {
        double tm = (i + 0.5) / k, te = (i + 1.0) / k;
        put(P, a.x + d.x * tm + nrm.x * h, a.y + d.y * tm + nrm.y * h);
        put(P, a.x + d.x * te, a.y + d.y * te);
    }
}

// A point in a local frame at o with axis u (v = u turned a quarter clockwise on screen).
static sp_vec2 local(sp_vec2 o, sp_vec2 u, double s, double a, double b)
{
    return (sp_vec2){o.x + s * (a * u.x - b * u.y), o.y + s * (a * u.y + b * u.x)};
}

// ---- head: a skull with a snout, jaws open or shut, horns, a frill or ears, maybe a neck ---------------------

// A horn (or an ear) on the skull's outline: the arc up to its base, its tip
// bent `back` towards the nape, the other side of its base; *a moves past it.
static void horn(path* P, double ry, double* a, double ah, double hw, double len, double back)
{
    arc(P, 0, 0, 1, ry, *a, ah - hw);
    double d = ah - back;
    put(P, cos(ah) + len * cos(d), ry * sin(ah) + len * sin(d));
    put(P, cos(ah + hw), ry * sin(ah + hw));
    *a = ah + hw;
}

static void head(path* P, sp_rng* r)
{
    double ry = U(r, 0.8, 1.1), L = U(r, 0.5, 1.6);
    double top0 = -ry * U(r, 0.25, 0.6), tip_top = top0 + U(r, 0.0, 0.35);
    double mouth = ry * U(r, 0.05, 0.35), chin = ry * U(r, 0.45, 0.85);
    bool open = chance(r, 0.4), teeth = chance(r, 0.45), frill = chance(r, 0.25), ear = !frill && chance(r, 0.3);
    int horns = chance(r, 0.3) ? 0 : chance(r, 0.55) ? 1 : 2;
    bool neck = chance(r, 0.45), neck_open = neck && chance(r, 0.4);
    double a_s = M_PI - U(r, 0.3, 0.9), a_e = 2 * M_PI + asin(top0 / ry), a_c = asin(fmin(0.99, chin / ry));
    double a = a_s;
    put(P, cos(a), ry * sin(a));
    if (frill) { // spikes or scallops round the back of the skull
        int k = 3 + (int)U(r, 0, 3);
        double f1 = M_PI + U(r, 0.5, 0.9), h = U(r, 0.25, 0.5);
        arc(P, 0, 0, 1, ry, a, M_PI - 0.2);
        for (int i = 0; i < k; ++i) {
            double m = M_PI - 0.2 + (f1 - M_PI + 0.2) * (i + 0.5) / k, e = M_PI - 0.2 + (f1 - M_PI + 0.2) * (i + 1.0) / k;
            put(P, (1 + h) * cos(m), ry * (1 + h) * sin(m));
            put(P, cos(e), ry * sin(e));
        }
        a = f1;
    }
    double hs = M_PI + U(r, 0.9, 1.2);
    for (int i = 0; i < horns; ++i) {
        double ah = hs + i * U(r, 0.3, 0.5), hw = U(r, 0.1, 0.22);
        if (ah - hw <= a) ah = a + hw + 0.05;
        horn(P, ry, &a, ah, hw, U(r, 0.4, 1.1), U(r, 0.2, 0.8));
    }
    if (ear) {
        double ah = M_PI + U(r, 1.0, 1.3);
        if (ah - 0.2 > a) horn(P, ry, &a, ah, 0.2, U(r, 0.25, 0.45), U(r, 0.3, 0.7));
    }
    arc(P, 0, 0, 1, ry, a, a_e);
    double tip = 1 + L;
    if (chance(r, 0.3)) put(P, 1 + L * 0.75, tip_top - U(r, 0.08, 0.18)); // a nostril bump
    put(P, tip, tip_top);
    put(P, tip + U(r, 0.03, 0.12), (tip_top + mouth) * 0.5);
    if (open) {
        double corner = 1 + L * U(r, 0.05, 0.35), drop = L * U(r, 0.3, 0.6), lower_tip = 1 + L * U(r, 0.7, 1.0);
        put(P, tip, mouth);
        if (teeth) teeth_to(P, (sp_vec2){corner, mouth}, 2 + (int)U(r, 0, 4), -0.12);
        else put(P, corner, mouth);
        sp_vec2 lt = {lower_tip, mouth + drop};
        if (teeth && chance(r, 0.6)) teeth_to(P, lt, 2 + (int)U(r, 0, 3), -0.1);
        else put_v(P, lt);
        put(P, lower_tip - 0.05, mouth + drop + U(r, 0.12, 0.3));
        put(P, cos(a_c), chin);
    } else {
        double cy = mouth + U(r, 0.1, 0.35);
        put(P, tip, mouth);
        if (teeth) teeth_to(P, (sp_vec2){tip - L * 0.45, cy}, 2 + (int)U(r, 0, 2), -0.1);
        else put(P, tip - 0.05, cy);
        put(P, cos(a_c), chin);
    }
    if (neck) {
        double nl = U(r, 0.5, 1.3), nw = U(r, 0.5, 0.9), lean = U(r, 0.2, 0.9);
        sp_vec2 j1 = {cos(M_PI / 2 + 0.1), ry * sin(M_PI / 2 + 0.1)};
        arc(P, 0, 0, 1, ry, a_c, M_PI / 2 + 0.1);
        sp_vec2 n1 = {j1.x - lean * nl, j1.y + nl}, n2 = {n1.x - nw, n1.y - U(r, 0.0, 0.3)};
        put_v(P, n1);
        if (neck_open) { // drawn from the neck's far end round to its other end, open
            int n = P->n < PATH_CAP ? P->n : PATH_CAP - 1;
            memmove(P->p + 1, P->p, sizeof *P->p * (size_t)n);
            P->p[0] = n2;
            P->n = n + 1;
            return;
        }
        put_v(P, n2);
        put(P, cos(a_s), ry * sin(a_s));
    } else {
        arc(P, 0, 0, 1, ry, a_c, a_s);
    }
    put_v(P, P->p[0]);
}

// ---- wings: an arm to the wrist, fingers to 2-5 scallops, back to the root ----------------------------------

static void wings(path* P, sp_rng* r)
{
    int pose = (int)U(r, 0, 3); // raised, spread, drooping
    double arm = pose == 0 ? U(r, -1.45, -0.9) : pose == 1 ? U(r, -0.8, -0.3) : U(r, -0.3, 0.2);
    double l1 = U(r, 0.8, 1.3), l2 = U(r, 0.6, 1.2);
    sp_vec2 root = {0, 0};
    sp_vec2 w = {l1 * cos(arm), l1 * sin(arm)};
    double fore = arm + U(r, 0.2, 0.9);
    sp_vec2 tip = {w.x + l2 * cos(fore), w.y + l2 * sin(fore)};
    sp_vec2 low = {U(r, 0.0, 0.35), U(r, 0.15, 0.5)};
    bool open = chance(r, 0.15);
    int style = chance(r, 0.7) ? 0 : chance(r, 0.6) ? 1 : 2; // scallops in, feathers out, notches
    int k = 2 + (int)U(r, 0, 4);
    put_v(P, root);
    if (chance(r, 0.4)) put(P, w.x * 0.5 - 0.1, w.y * 0.5 - U(r, 0.05, 0.2)); // an elbow bump
    put_v(P, w);
    if (chance(r, 0.35)) { // thumb claw
        put(P, w.x - 0.08, w.y - U(r, 0.15, 0.3));
        put(P, w.x + 0.05, w.y + 0.02);
    }
    put_v(P, tip);
    // The finger tips lie on a curve from the tip to the low root point that
    // bulges away from the wrist; the trailing edge runs between them.
    sp_vec2 mid = {(tip.x + low.x) * 0.5, (tip.y + low.y) * 0.5}, away = sp_v2_sub(mid, w);
    double al = hypot(away.x, away.y), span = hypot(tip.x - low.x, tip.y - low.y);
    sp_vec2 ctrl = sp_v2_add(mid, sp_v2_scale(away, al > 0 ? span * U(r, 0.1, 0.35) / al : 0));
    sp_vec2 prev = tip;
    for (int i = 1; i <= k; ++i) {
        double t = (double)i / k, u = 1 - t;
        sp_vec2 f = {u * u * tip.x + 2 * u * t * ctrl.x + t * t * low.x, u * u * tip.y + 2 * u * t * ctrl.y + t * t * low.y};
        sp_vec2 m = {(prev.x + f.x) * 0.5, (prev.y + f.y) * 0.5};
        double depth = U(r, 0.25, 0.5) * (style == 1 ? -0.5 : 1);
        sp_vec2 c = sp_v2_add(m, sp_v2_scale(sp_v2_sub(w, m), depth));
        if (style == 2) {
            put_v(P, c);
            put_v(P, f);
        } else {
            quad_to(P, c, f);
        }
        prev = f;
    }
    if (!open) {
        put_v(P, root);
    }
}

// ---- tail: a wavy line or a tapering outline, maybe spiked, ending in a spade, arrow, curl, flame or club ------

static void tail_end(path* P, sp_rng* r, int kind, sp_vec2 o, sp_vec2 u, double s)
{
    switch (kind) {
    case 1: // spade
        put_v(P, local(o, u, s, -0.05, 0.22));
        put_v(P, local(o, u, s, 0.12, 0.18));
        put_v(P, local(o, u, s, 0.38, 0));
        put_v(P, local(o, u, s, 0.12, -0.18));
        put_v(P, local(o, u, s, -0.05, -0.22));
        put_v(P, o);
        break;
    case 2: // arrowhead
        put_v(P, local(o, u, s, -0.1, 0.2));
        put_v(P, local(o, u, s, 0.32, 0));
        put_v(P, local(o, u, s, -0.1, -0.2));
        put_v(P, o);
        break;
    case 3: { // curl
        double turn = U(r, 1.0, 1.7) * 2 * M_PI, rad = 0.3 * s, side = chance(r, 0.5) ? 1 : -1;
        sp_vec2 c = local(o, u, 1, 0, side * rad);
        double a = atan2(o.y - c.y, o.x - c.x);
        for (int i = 1; i <= 24; ++i) {
            double t = i / 24.0, rr = rad * (1 - 0.75 * t);
            put(P, c.x + rr * cos(a + side * turn * t), c.y + rr * sin(a + side * turn * t));
        }
        break;
    }
    case 4: { // flame or tuft
        int k = 3 + (int)U(r, 0, 2);
        for (int i = 0; i < k; ++i) {
            double b = -0.2 + 0.4 * (i + 0.5) / k;
            put_v(P, local(o, u, s, U(r, 0.25, 0.4), b));
            put_v(P, local(o, u, s, 0.08, -0.2 + 0.4 * (i + 1.0) / k));
        }
        put_v(P, o);
        break;
    }
    case 5: { // club
        sp_vec2 c = local(o, u, s, 0.13, 0);
        double a = atan2(o.y - c.y, o.x - c.x);
        for (int i = 1; i <= 16; ++i) put(P, c.x + 0.13 * s * cos(a + 2 * M_PI * i / 16), c.y + 0.13 * s * sin(a + 2 * M_PI * i / 16));
        break;
    }
    default: break;
    }
}

static void tail(path* P, sp_rng* r)
{
    enum { N = 40 };
    double len = U(r, 1.4, 2.8), amp = U(r, 0.0, 0.35), freq = U(r, 0.4, 1.6), ph = U(r, 0, 2 * M_PI), droop = U(r, -1.1, 1.3);
    sp_vec2 c[N + 1], nrm[N + 1];
    for (int i = 0; i <= N; ++i) {
        double s = (double)i / N;
        c[i] = (sp_vec2){s * len, amp * sin(2 * M_PI * freq * s + ph) * (0.3 + 0.7 * s) + droop * s * s};
    }
    for (int i = 0; i <= N; ++i) {
        sp_vec2 d = sp_v2_sub(c[i < N ? i + 1 : N], c[i > 0 ? i - 1 : 0]);
        double l = sqrt(d.x * d.x + d.y * d.y);
        nrm[i] = (sp_vec2){-d.y / l, d.x / l};
    }
    sp_vec2 u = sp_v2_sub(c[N], c[N - 1]);
    u = sp_v2_scale(u, 1 / sqrt(u.x * u.x + u.y * u.y));
    double pick = U(r, 0, 1);
    int end = pick < 0.25 ? 0 : pick < 0.45 ? 1 : pick < 0.6 ? 2 : pick < 0.75 ? 3 : pick < 0.88 ? 4 : 5;
    double es = U(r, 0.7, 1.3);
    if (chance(r, 0.45)) { // one line
        for (int i = 0; i <= N; ++i) put_v(P, c[i]);
        tail_end(P, r, end, c[N], u, es);
        return;
    }
    double w0 = U(r, 0.12, 0.42), pw = U(r, 0.6, 1.4), wmin = end ? 0.04 : 0.0;
    bool spiky = chance(r, 0.3), closed = chance(r, 0.5);
    int spike_from = N / 8, spike_step = 3 + (int)U(r, 0, 3);
    double spike_h = U(r, 0.1, 0.2);
    for (int i = 0; i <= N; ++i) {
        double s = (double)i / N, wd = w0 * pow(1 - s, pw) + wmin;
        if (spiky && i >= spike_from && i < N - 2 && (i - spike_from) % spike_step == spike_step / 2) wd += spike_h * (1.2 - s);
        put_v(P, sp_v2_sub(c[i], sp_v2_scale(nrm[i], wd)));
    }
    if (end) tail_end(P, r, end == 3 ? 2 : end, c[N], u, es);
    for (int i = N; i >= 0; --i) {
        double s = (double)i / N, wd = w0 * pow(1 - s, pw) + wmin;
        put_v(P, sp_v2_add(c[i], sp_v2_scale(nrm[i], wd)));
    }
    if (closed) put_v(P, P->p[0]);
}

// ---- leg pairs: two limbs, each with a foot (claws, round, boot), as one outline or limb by limb; or one line ---

typedef struct limb {
    sp_vec2 c[5]; // hip to ankle
    double w[5];
    int n;
} limb;

static sp_vec2 side_point(const limb* L, int i, double sgn)
{
    sp_vec2 d = sp_v2_sub(L->c[i < L->n - 1 ? i + 1 : i], L->c[i > 0 ? i - 1 : i]);
    double l = sqrt(d.x * d.x + d.y * d.y);
    sp_vec2 n = {-d.y / l, d.x / l}; // for a limb going down: the -x (back) side
    return sp_v2_add(L->c[i], sp_v2_scale(n, sgn * L->w[i] * 0.5));
}

static void foot(path* P, sp_rng* r, const limb* L, int kind, double fl)
{
    sp_vec2 a = L->c[L->n - 1];
    double w = L->w[L->n - 1], fh = w * U(r, 0.3, 0.6);
    double heel = a.x - w * 0.5 - U(r, 0.0, 0.1), toe = a.x + w * 0.5 + fl, sole = a.y + fh;
    put(P, heel, sole);
    switch (kind) {
    case 0: { // claws
        int k = 2 + (int)U(r, 0, 3);
        put(P, toe - 0.05, sole);
        double top = a.y + fh * 0.1;
        for (int i = 0; i < k; ++i) {
            double y0 = sole - (sole - top) * i / k, y1 = sole - (sole - top) * (i + 1) / k;
            put(P, toe + U(r, 0.12, 0.22), y0 - (y0 - y1) * 0.3);
            put(P, toe - 0.02, y1);
        }
        break;
    }
    case 1: // round foot
        arc(P, toe - fh * 0.5, sole - fh * 0.5, fh * 0.6, fh * 0.5, M_PI / 2, -M_PI / 2);
        break;
    default: // boot or hoof: square toe
        put(P, toe, sole);
        put(P, toe, a.y + fh * 0.1);
        break;
    }
    put_v(P, side_point(L, L->n - 1, -1));
}

// Where the limb's side (sgn as in side_point) crosses the height y; its nearest end when it does not.
static double side_x_at(const limb* L, double sgn, double y)
{
    sp_vec2 prev = side_point(L, 0, sgn);
    if (y <= prev.y) return prev.x;
    for (int i = 1; i < L->n; ++i) {
        sp_vec2 q = side_point(L, i, sgn);
        if (y <= q.y && q.y > prev.y) return prev.x + (q.x - prev.x) * (y - prev.y) / (q.y - prev.y);
        prev = q;
    }
    return prev.x;
}

// The pair as the one outline a hand traces round it: down the rear leg's back, its foot, up its front to the
// crotch, down the front leg's back, its foot, up its front, and over the top (a haunch over hind legs, a
// shoulder over front legs) back to the start. The limbs' sides above the crotch are inside the outline.
// Limbs that converge or cross (a stride) still cross the line, as they overlap in a side view.
static void legs_outline(path* P, sp_rng* r, const limb L[2], int kind, double fl, bool hind, double h)
{
    const limb* a = &L[0];
    const limb* b = &L[1];
    double cy = h * (hind ? U(r, 0.35, 0.55) : U(r, 0.15, 0.4));
    for (int i = 0; i < a->n; ++i)
        put_v(P, side_point(a, i, 1));
    foot(P, r, a, kind, fl);
    for (int i = a->n - 2; i >= 1; --i) {
        sp_vec2 q = side_point(a, i, -1);
        if (q.y > cy) put_v(P, q);
    }
    put(P, 0.5 * (side_x_at(a, -1, cy) + side_x_at(b, 1, cy)), cy);
    for (int i = 1; i < b->n; ++i) {
        sp_vec2 q = side_point(b, i, 1);
        if (q.y > cy) put_v(P, q);
    }
    foot(P, r, b, kind, fl);
    for (int i = b->n - 2; i >= 0; --i)
        put_v(P, side_point(b, i, -1));
    sp_vec2 s = P->p[0], e = P->p[P->n - 1];
    double bulge = h * (hind ? U(r, 0.2, 0.5) : U(r, 0.0, 0.12));
    quad_to(P, (sp_vec2){0.5 * (s.x + e.x), fmin(s.y, e.y) - 2 * bulge}, s);
}

static void legs(path* P, sp_rng* r, bool hind)
{
    double h = U(r, 0.9, 1.3), gap = U(r, 0.45, 0.9), w = U(r, 0.2, 0.34);
    int kind = chance(r, 0.5) ? 0 : chance(r, 0.5) ? 1 : 2;
    double fl = hind ? U(r, 0.3, 0.6) : U(r, 0.15, 0.4);
    bool one = chance(r, 0.15), stride = chance(r, 0.2), kick = !stride && chance(r, 0.12);
    limb L[2];
    for (int k = 0; k < 2; ++k) {
        // y down: a positive turn swings the limb back (-x).
        double x0 = k * gap, swing = U(r, -0.2, 0.2);
        if (stride) swing = (k ? 1 : -1) * U(r, 0.2, 0.45);
        if (kick && k == 1) swing = U(r, 0.5, 0.9);
        limb* l = &L[k];
        if (hind) { // a big thigh, the knee forward, the hock back, a long foot
            l->n = 4;
            sp_vec2 c[4] = {{x0, 0}, {x0 + U(r, 0.2, 0.35), h * 0.4}, {x0 - U(r, 0.05, 0.2), h * 0.75}, {x0 + U(r, 0.0, 0.1), h}};
            double ws[4] = {U(r, 0.45, 0.65), U(r, 0.25, 0.35), w * 0.6, w * 0.55};
            memcpy(l->c, c, sizeof c), memcpy(l->w, ws, sizeof ws);
        } else {
            l->n = 3;
            sp_vec2 c[3] = {{x0, 0}, {x0 + U(r, -0.08, 0.08), h * 0.5}, {x0 + U(r, -0.08, 0.15), h}};
            double ws[3] = {w * U(r, 1.1, 1.5), w, w * 0.9};
            memcpy(l->c, c, sizeof c), memcpy(l->w, ws, sizeof ws);
        }
        // No wider than the limb's segments are long, so that its sides never cross.
        for (int i = 0; i < l->n; ++i) {
            double sl = INFINITY;
            if (i > 0) sl = fmin(sl, hypot(l->c[i].x - l->c[i - 1].x, l->c[i].y - l->c[i - 1].y));
            if (i + 1 < l->n) sl = fmin(sl, hypot(l->c[i + 1].x - l->c[i].x, l->c[i + 1].y - l->c[i].y));
            l->w[i] = fmin(l->w[i], 0.9 * sl);
        }
        for (int i = 1; i < l->n; ++i) { // turn the limb about its hip
            sp_vec2 d = sp_v2_sub(l->c[i], l->c[0]);
            l->c[i] = (sp_vec2){l->c[0].x + d.x * cos(swing) - d.y * sin(swing), l->c[0].y + d.x * sin(swing) + d.y * cos(swing)};
        }
    }
    if (chance(r, 0.3)) { // one line: toe, up the first leg, over the hip, down the second, toe
        const limb* a = &L[0];
        const limb* b = &L[1];
        put(P, a->c[a->n - 1].x + fl + w * 0.5, a->c[a->n - 1].y + 0.05);
        for (int i = a->n - 1; i >= 0; --i) put_v(P, a->c[i]);
        if (one) return;
        for (int i = 0; i < b->n; ++i) put_v(P, b->c[i]);
        put(P, b->c[b->n - 1].x + fl + w * 0.5, b->c[b->n - 1].y + 0.05);
        return;
    }
    // Mostly the pair's outline; a quarter drawn limb by limb, each round on its own, as some hands do.
    if (!one && chance(r, 0.75)) {
        legs_outline(P, r, L, kind, fl, hind, h);
        return;
    }
    int count = one ? 1 : 2;
    for (int k = 0; k < count; ++k) {
        const limb* l = &L[k];
        for (int i = 0; i < l->n; ++i) put_v(P, side_point(l, i, 1));
        foot(P, r, l, kind, fl);
        for (int i = l->n - 2; i >= 0; --i) put_v(P, side_point(l, i, -1));
    }
    if (chance(r, 0.6)) put_v(P, P->p[0]); // the hip line closed
}

// ---- torso: a blob, boxy or round, pear or bean, humped, ridged, maybe with neck and tail stubs --------------

static void torso(path* P, sp_rng* r)
{
    enum { N = 96 };
    double ry = U(r, 0.35, 0.75), e = chance(r, 0.6) ? 2 : U(r, 2.5, 4), pear = U(r, -0.35, 0.35);
    int humps = chance(r, 0.5) ? 0 : chance(r, 0.6) ? 1 : 2;
    double hx[2] = {U(r, -0.6, 0.6), U(r, -0.6, 0.6)}, hh[2] = {U(r, 0.15, 0.4), U(r, 0.15, 0.4)}, hw = U(r, 0.2, 0.4);
    double bean = chance(r, 0.3) ? U(r, 0.1, 0.25) : 0;
    bool ridge = chance(r, 0.3), back_only = chance(r, 0.12);
    bool neck = chance(r, 0.25), tailstub = chance(r, 0.2);
    double rh = U(r, 0.1, 0.22);
    // A closed body ends on its first point exactly (the hand-drawing model closes only such curves).
    int i0 = back_only ? N / 2 : 0, i1 = back_only ? N : N - 1;
    for (int i = i0; i <= i1; ++i) {
        double t = 2 * M_PI * i / N, ct = cos(t), st = sin(t);
        double x = copysign(pow(fabs(ct), 2 / e), ct), y = copysign(pow(fabs(st), 2 / e), st) * ry * (1 + pear * x);
        if (y < 0)
            for (int k = 0; k < humps; ++k) y -= hh[k] * exp(-((x - hx[k]) / hw) * ((x - hx[k]) / hw));
        if (y > 0) y -= bean * exp(-(x / 0.5) * (x / 0.5));
        if (ridge && y < 0 && fabs(x) < 0.65 && i % 2 == 0) y -= rh;
        if (neck && i == (int)(N * 0.86)) { // up and forward from the shoulder, and back down the chest
            put(P, x + 0.3, y - 0.75);
            put(P, x + 0.65, y - 0.75);
            put(P, x + 0.45, y - 0.05);
        }
        if (tailstub && i == N / 2 - 2) put(P, x - 0.6, y + 0.05);
        put(P, x, y);
    }
    if (!back_only) put_v(P, P->p[0]);
}

sp_result sp_concept_clean(sp_concept c, uint64_t seed, sp_sketch* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    if ((unsigned)c >= SP_CONCEPT_COUNT) return sp_fail(err, SP_ERR_INVALID, "concept %d: no such part", (int)c);
    sp_rng r = {seed * 0x9E3779B97F4A7C15ull + 0xD1B54A32D192ED03ull * ((uint64_t)c + 1)};
    path P = {.n = 0};
    switch (c) {
    case SP_CONCEPT_HEAD: head(&P, &r); break;
    case SP_CONCEPT_WINGS: wings(&P, &r); break;
    case SP_CONCEPT_TAIL: tail(&P, &r); break;
    case SP_CONCEPT_FRONT_LEGS: legs(&P, &r, false); break;
    case SP_CONCEPT_HIND_LEGS: legs(&P, &r, true); break;
    case SP_CONCEPT_TORSO: torso(&P, &r); break;
    default: break;
    }
    // Facing, a tilt up to 17 degrees, a bounding-box diagonal of 340 px, centred on the canvas.
    double mirror = chance(&r, 0.5) ? -1 : 1, turn = U(&r, -0.3, 0.3);
    sp_result res = sp_concept_place(P.p, P.n, mirror, turn, out, err);
    if (res == SP_ERR_INVALID)
        return sp_fail(err, SP_ERR_INTERNAL, "concept %s: empty design (seed %llu)", k_names[c], (unsigned long long)seed);
    return res;
}

sp_result sp_concept_place(sp_vec2* p, int n, double mirror, double turn, sp_sketch* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    double cs = cos(turn), sn = sin(turn);
    sp_vec2 lo = {INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY};
    for (int i = 0; i < n; ++i) {
        sp_vec2 q = {mirror * p[i].x, p[i].y};
        p[i] = (sp_vec2){q.x * cs - q.y * sn, q.x * sn + q.y * cs};
        lo.x = fmin(lo.x, p[i].x), lo.y = fmin(lo.y, p[i].y), hi.x = fmax(hi.x, p[i].x), hi.y = fmax(hi.y, p[i].y);
    }
    double diag = hypot(hi.x - lo.x, hi.y - lo.y);
    if (n < 2 || !(diag > 0)) return sp_fail(err, SP_ERR_INVALID, "a design with no extent");
    double s = 340 / diag;
    for (int i = 0; i < n; ++i)
        p[i] = (sp_vec2){SP_CONCEPT_CANVAS_W / 2 + (p[i].x - (lo.x + hi.x) / 2) * s,
                         SP_CONCEPT_CANVAS_H / 2 + (p[i].y - (lo.y + hi.y) / 2) * s};
    out->canvas_w = SP_CONCEPT_CANVAS_W, out->canvas_h = SP_CONCEPT_CANVAS_H;
    if (sp_sketch_add_stroke(out, p, NULL, n) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    return SP_OK;
}

uint64_t sp_concept_seed(sp_concept c, uint64_t family, int i)
{
    return sp_handdraw_seed(sp_handdraw_part_family(family, sp_concept_name(c)), (uint64_t)i);
}

sp_result sp_concept_sketch(sp_concept c, uint64_t seed, sp_sketch* out, sp_error* err)
{
    sp_sketch clean;
    sp_result res = sp_concept_clean(c, seed, &clean, err);
    if (res != SP_OK) return res;
    res = sp_concept_draw(&clean, seed, out, err);
    sp_sketch_free(&clean);
    return res;
}

sp_result sp_concept_draw(const sp_sketch* clean, uint64_t seed, sp_sketch* out, sp_error* err)
{
    sp_handdraw_params hp = sp_handdraw_preset(SP_HANDDRAW_NORMAL);
    return sp_handdraw_apply(clean, &hp, seed * 0xC2B2AE3D27D4EB4Full + 0x27D4EB2F165667C5ull, out, NULL, err);
}
