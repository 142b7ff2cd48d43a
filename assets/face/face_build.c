// face_build.c: generates the face rig: the head surface (a warped
// latitude-longitude grid around an ellipsoid, sculpted by smooth
// displacement fields), eyeballs, eyelid shells, lips, brows, their
// colours, the blendshape deltas, the deformers' weights, the parameters
// and the sketch abstraction. Everything follows from the constants here;
// the same code gives the same bytes on every run.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "face.h"

#define PI 3.14159265358979323846

// The head ellipsoid: centre height, semi-axes (front and back depth differ
// so the face is flatter than the back of the head).
#define CY 0.15
#define AX 0.74
#define AY 0.85
#define AZF 0.86
#define AZB 0.98
#define MOUTH_HALF 0.19 // half the mouth's width at rest

enum {
    COLS = 96,
    HEAD_ROWS = 48,
    NECK_ROWS = 9,
    EYE_RINGS = 10,
    EYE_SEGS = 14,
    LID_ACROSS = FACE_LID_ACROSS,
    LID_ROWS = FACE_LID_ROWS,
    LIP_ACROSS = 33,
    LIP_ROWS = 5,
    BROW_ALONG = 17,
    NOSE_POINTS = 9
};

static double clamp01(double t)
{
    return t < 0 ? 0 : (t > 1 ? 1 : t);
}
static double smoothstep(double e0, double e1, double x)
{
    double t = clamp01((x - e0) / (e1 - e0));
    return t * t * (3 - 2 * t);
}
static double gauss2(double dx, double dy, double sx, double sy)
{
    return exp(-(dx * dx) / (sx * sx) - (dy * dy) / (sy * sy));
}
static double lerp(double a, double b, double t)
{
    return a + (b - a) * t;
}

// ---------------------------------------------------------------- the sculpted surface

// The head's half width at height y: the ellipsoid's, narrowed towards the
// chin so that the jaw tapers.
static double half_width(double y)
{
    return AX * (1.0 - 0.2 * smoothstep(0.1, -0.7, y));
}

static double front_base_z(double x, double y)
{
    double ax = half_width(y);
    double u = 1.0 - (x / ax) * (x / ax) - ((y - CY) / AY) * ((y - CY) / AY);
    return AZF * sqrt(u > 0 ? u : 0);
}

static double nose_disp(double x, double y)
{
    // Along the ridge from the root (y 0.2) to the tip (y -0.10), then a
    // quick fall to the lip; narrow at the root, wider at the tip.
    double t = (0.20 - y) / 0.30, h;
    if (t < 0)
        h = 0.03 * exp(-(t / 0.25) * (t / 0.25));
    else if (t <= 1)
        h = 0.03 + 0.15 * pow(t, 1.6);
    else
        h = 0.18 * exp(-((t - 1) / 0.13) * ((t - 1) / 0.13));
    double sx = 0.032 + 0.03 * clamp01(t);
    double ridge = h * exp(-(x / sx) * (x / sx));
    double wings = 0.05 * (gauss2(x - 0.062, y + 0.118, 0.035, 0.03) + gauss2(x + 0.062, y + 0.118, 0.035, 0.03));
    return ridge + wings;
}

static double face_disp(double x, double y)
{
    double ax = fabs(x);
    return nose_disp(x, y) + 0.035 * gauss2(ax - 0.25, y - 0.37, 0.2, 0.06) // brow ridge
           + 0.045 * gauss2(ax - 0.33, y + 0.08, 0.12, 0.12)                // cheekbones
           + 0.05 * gauss2(x, y - FACE_MOUTH_Y, 0.25, 0.14)                 // muzzle
           + 0.06 * gauss2(x, y + 0.60, 0.14, 0.08)                         // chin
           - 0.08 * gauss2(ax - FACE_EYE_X, y - FACE_EYE_Y, 0.11, 0.085);   // eye sockets
}

static double surface_z(double x, double y)
{
    return front_base_z(x, y) + face_disp(x, y);
}

// The lips' outlines above and below the mouth line, s in [0, 1] from the
// right corner (-x) to the left one.
static double lip_x(double s)
{
    return -MOUTH_HALF * cos(PI * s);
}
static double upper_outline(double s)
{
    return 0.052 * pow(sin(PI * s), 0.7) - 0.010 * exp(-((s - 0.5) / 0.07) * ((s - 0.5) / 0.07));
}
static double lower_outline(double s)
{
    return 0.062 * pow(sin(PI * s), 0.8);
}

// How far inside the lips' outline a point of the head surface is (0
// outside, 1 well inside): that skin is the mouth's interior, recessed and
// dark, and shows when the jaw opens.
static double inside_lips(double x, double y)
{
    if (fabs(x) >= MOUTH_HALF) return 0;
    double s = acos(-x / MOUTH_HALF) / PI;
    double up = FACE_MOUTH_Y + upper_outline(s), lo = FACE_MOUTH_Y - lower_outline(s);
    double d = fmin(up - y, y - lo);
    return smoothstep(0.0, 0.012, d);
}

void face_eye_centre(int side, double out[3])
{
    double x = side == 0 ? FACE_EYE_X : -FACE_EYE_X;
    out[0] = x, out[1] = FACE_EYE_Y, out[2] = surface_z(x, FACE_EYE_Y) - 0.012;
}

void face_nose_root(double out[3])
{
    out[0] = 0, out[1] = 0.16, out[2] = surface_z(0, 0.16);
}
void face_mouth_centre(double out[3])
{
    out[0] = 0, out[1] = FACE_MOUTH_Y, out[2] = surface_z(0, FACE_MOUTH_Y);
}

double face_upper_edge(double close)
{
    return 0.42 - 1.0 * close;
}
double face_lower_edge(double lower_up)
{
    return -0.55 + 0.22 * lower_up;
}

double face_lid_beta(int j)
{
    return 0.42 + (PI - 0.84) * j / (FACE_LID_ACROSS - 1);
}

double face_lid_fraction(int r)
{
    double f = (double)r / (FACE_LID_ROWS - 1);
    return f * f; // rows close together at the edge, where the lid curves most
}

double face_lid_psi(int upper, double f, double edge)
{
    return edge + f * ((upper ? 1.75 : -1.6) - edge);
}

// ---------------------------------------------------------------- building

typedef struct builder {
    face_rig* f;
    int cap;
    float (*color)[4];
    int ccap;
    int ntri, tcap;
    int dcap;
} builder;

static double srgb(double c)
{
    return pow(c, 2.2);
}

static int add_point(builder* b, face_kind kind, int side, double x, double y, double z, const double rgb[3])
{
    face_rig* f = b->f;
    if (f->point_count == b->cap) {
        b->cap = b->cap ? 2 * b->cap : 8192;
        f->points = realloc(f->points, sizeof(face_point) * (size_t)b->cap);
        b->color = realloc(b->color, sizeof *b->color * (size_t)b->cap);
        if (!f->points || !b->color) return -1;
    }
    face_point* p = &f->points[f->point_count];
    memset(p, 0, sizeof *p);
    p->rest[0] = x, p->rest[1] = y, p->rest[2] = z;
    p->kind = (uint8_t)kind;
    p->side = (uint8_t)side;
    for (int c = 0; c < 3; ++c)
        b->color[f->point_count][c] = (float)srgb(rgb[c]);
    b->color[f->point_count][3] = 1.0f;
    return f->point_count++;
}

static bool add_tri(builder* b, int i, int j, int k)
{
    face_rig* f = b->f;
    if (b->ntri == b->tcap) {
        b->tcap = b->tcap ? 2 * b->tcap : 16384;
        f->triangles = realloc(f->triangles, sizeof(uint32_t) * 3 * (size_t)b->tcap);
        if (!f->triangles) return false;
    }
    uint32_t* t = f->triangles + 3 * b->ntri++;
    t[0] = (uint32_t)i, t[1] = (uint32_t)j, t[2] = (uint32_t)k;
    return true;
}

// A grid patch: rows x cols points from `first`, row-major; quads split
// into two triangles wound so that (row+1) x (col+1) faces outward.
static bool grid_tris(builder* b, int first, int rows, int cols, bool wrap, bool flip)
{
    for (int r = 0; r + 1 < rows; ++r)
        for (int c = 0; c < (wrap ? cols : cols - 1); ++c) {
            int c1 = (c + 1) % cols;
            int a = first + r * cols + c, bb = first + (r + 1) * cols + c, cc = first + r * cols + c1,
                d = first + (r + 1) * cols + c1;
            bool ok = flip ? add_tri(b, a, cc, bb) && add_tri(b, bb, cc, d) : add_tri(b, a, bb, cc) && add_tri(b, bb, d, cc);
            if (!ok) return false;
        }
    return true;
}

// Inverts the cumulative of a density on [lo, hi]: n samples spaced
// inversely to the density (dense where it is high).
static void warped(double lo, double hi, int n, double (*density)(double), double* out)
{
    enum { FINE = 4096 };
    double cum[FINE + 1];
    cum[0] = 0;
    for (int i = 1; i <= FINE; ++i) {
        double t = lo + (hi - lo) * (i - 0.5) / FINE;
        cum[i] = cum[i - 1] + density(t);
    }
    int k = 0;
    for (int i = 0; i < n; ++i) {
        double target = cum[FINE] * i / (n - 1);
        while (k < FINE - 1 && cum[k + 1] < target)
            ++k;
        double span = cum[k + 1] - cum[k];
        double frac = span > 0 ? (target - cum[k]) / span : 0;
        out[i] = lo + (hi - lo) * (k + clamp01(frac)) / FINE;
    }
}

static double row_density(double phi)
{
    return 1.0 + 1.4 * exp(-((phi - 2.05) / 0.5) * ((phi - 2.05) / 0.5));
}

static const double SKIN[3] = {0.93, 0.74, 0.62}, HAIR[3] = {0.32, 0.21, 0.15}, LIPS[3] = {0.80, 0.40, 0.42},
                    MOUTH[3] = {0.32, 0.08, 0.10}, BROW[3] = {0.30, 0.19, 0.13}, WHITE[3] = {0.96, 0.96, 0.94},
                    IRIS[3] = {0.28, 0.50, 0.70}, PUPIL[3] = {0.03, 0.03, 0.04}, LASH[3] = {0.28, 0.18, 0.14};

static void mix3(const double a[3], const double b[3], double t, double out[3])
{
    for (int c = 0; c < 3; ++c)
        out[c] = lerp(a[c], b[c], t);
}

static bool build_head(builder* b)
{
    double phi[HEAD_ROWS], theta[COLS];
    warped(0.10, 2.75, HEAD_ROWS, row_density, phi);
    for (int j = 0; j < COLS; ++j) {
        double s = 2 * PI * j / COLS;
        theta[j] = s - 0.45 * sin(s); // columns twice as dense across the face as at the back
    }
    // Crown.
    if (add_point(b, FK_SKIN, 0, 0, CY + AY, 0, HAIR) < 0) return false;
    int first = b->f->point_count;
    double yb = CY + AY * cos(phi[HEAD_ROWS - 1]);
    for (int r = 0; r < HEAD_ROWS + NECK_ROWS; ++r) {
        for (int j = 0; j < COLS; ++j) {
            double th = theta[j], c = cos(th), s = sin(th);
            double az = c >= 0 ? AZF : AZF + (AZB - AZF) * c * c;
            double x, y, z;
            if (r < HEAD_ROWS) {
                y = CY + AY * cos(phi[r]), x = half_width(y) * sin(phi[r]) * s, z = az * sin(phi[r]) * c;
            } else {
                double t = (double)(r - HEAD_ROWS + 1) / NECK_ROWS, u = smoothstep(0, 0.6, t);
                double sp = sin(phi[HEAD_ROWS - 1]);
                y = yb - t * (yb + 1.25);
                x = lerp(half_width(yb) * sp, 0.34, u) * s;
                z = lerp(0, -0.10, u) + lerp(az * sp, 0.31, u) * c;
            }
            double m = smoothstep(0.2, 0.6, c);
            double in = m * inside_lips(x, y);
            z += m * face_disp(x, y) - 0.03 * in;
            // Ears: flaps at the sides.
            double ear = exp(-((y - 0.12) / 0.13) * ((y - 0.12) / 0.13) - ((z + 0.06) / 0.08) * ((z + 0.06) / 0.08)) *
                         smoothstep(0.5, 0.7, fabs(x));
            x += (x > 0 ? 1 : -1) * 0.09 * ear;
            double hairline = 0.62 - 0.32 * (1 - c) - 0.085 * (1 - c) * (1 - c);
            double hair = smoothstep(hairline - 0.07, hairline + 0.07, y) * (1 - smoothstep(0.2, 0.5, ear));
            double col[3];
            mix3(SKIN, HAIR, hair, col);
            if (in > 0) mix3(col, MOUTH, in, col);
            if (add_point(b, FK_SKIN, x > 0 ? 0 : 1, x, y, z, col) < 0) return false;
        }
    }
    int bottom = add_point(b, FK_SKIN, 0, 0, -1.25, -0.10, SKIN);
    if (bottom < 0) return false;
    for (int j = 0; j < COLS; ++j)
        if (!add_tri(b, 0, first + j, first + (j + 1) % COLS)) return false;
    if (!grid_tris(b, first, HEAD_ROWS + NECK_ROWS, COLS, true, false)) return false;
    int last = first + (HEAD_ROWS + NECK_ROWS - 1) * COLS;
    for (int j = 0; j < COLS; ++j)
        if (!add_tri(b, bottom, last + (j + 1) % COLS, last + j)) return false;
    return true;
}

static bool build_eye(builder* b, int side)
{
    double e[3];
    face_eye_centre(side, e);
    int pole = add_point(b, FK_EYEBALL, side, e[0], e[1], e[2] + FACE_EYE_R, PUPIL);
    if (pole < 0) return false;
    int first = b->f->point_count;
    for (int k = 1; k <= EYE_RINGS; ++k) {
        double a = 2.62 * pow((double)k / EYE_RINGS, 1.25); // rings close together at the iris
        const double* col = a < 0.2 ? PUPIL : (a < 0.42 ? IRIS : WHITE);
        for (int j = 0; j < EYE_SEGS; ++j) {
            double bt = 2 * PI * j / EYE_SEGS;
            double d[3] = {sin(a) * cos(bt), sin(a) * sin(bt), cos(a)};
            if (add_point(b, FK_EYEBALL, side, e[0] + FACE_EYE_R * d[0], e[1] + FACE_EYE_R * d[1], e[2] + FACE_EYE_R * d[2],
                          col) < 0)
                return false;
        }
    }
    for (int j = 0; j < EYE_SEGS; ++j)
        if (!add_tri(b, pole, first + j, first + (j + 1) % EYE_SEGS)) return false;
    return grid_tris(b, first, EYE_RINGS, EYE_SEGS, true, false);
}

// Returns the first point of the lid grid (LID_ROWS x LID_ACROSS, row 0 the edge).
static int build_lid(builder* b, int side, int upper)
{
    double e[3];
    face_eye_centre(side, e);
    int first = b->f->point_count;
    double edge = upper ? face_upper_edge(0) : face_lower_edge(0);
    for (int r = 0; r < LID_ROWS; ++r) {
        double f = face_lid_fraction(r), psi = face_lid_psi(upper, f, edge);
        for (int j = 0; j < LID_ACROSS; ++j) {
            double q[3];
            face_lid_point(upper, b->f->lid_cb[j], b->f->lid_sb[j], cos(psi), sin(psi), q);
            const double* col = r == 0 && upper ? LASH : SKIN;
            int i = add_point(b, upper ? FK_LID_UPPER : FK_LID_LOWER, side, e[0] + q[0], e[1] + q[1], e[2] + q[2], col);
            if (i < 0) return -1;
            face_point* pt = &b->f->points[i];
            pt->col = (uint8_t)j, pt->row = (uint8_t)r;
        }
    }
    // Upper lids grow upward (rows go up), lower lids downward: opposite windings.
    return grid_tris(b, first, LID_ROWS, LID_ACROSS, false, !upper) ? first : -1;
}

// Returns the first point of the lip (LIP_ROWS x LIP_ACROSS, row 0 the outline).
static int build_lip(builder* b, int upper)
{
    int first = b->f->point_count;
    for (int r = 0; r < LIP_ROWS; ++r) {
        double t = (double)r / (LIP_ROWS - 1);
        for (int j = 0; j < LIP_ACROSS; ++j) {
            double s = (double)j / (LIP_ACROSS - 1), x = lip_x(s), sn = sin(PI * s);
            double outline = upper ? FACE_MOUTH_Y + upper_outline(s) : FACE_MOUTH_Y - lower_outline(s);
            double line = FACE_MOUTH_Y + (upper ? 0.003 : -0.003) * sn;
            double y = lerp(outline, line, t);
            double bulge = (upper ? 0.028 : 0.034) * pow(sin(PI * 0.85 * t), 0.8) * pow(sn, 0.6);
            int i = add_point(b, FK_SKIN, x > 0 ? 0 : 1, x, y, surface_z(x, y) + 0.004 + bulge, LIPS);
            if (i < 0) return -1;
            face_point* pt = &b->f->points[i];
            pt->lip = (int8_t)(upper ? 1 : -1); // which lip (the mouth's fields tell them apart)
            pt->col = (uint8_t)j, pt->row = (uint8_t)r;
        }
    }
    return grid_tris(b, first, LIP_ROWS, LIP_ACROSS, false, !upper) ? first : -1;
}

// Returns the first point of the brow (3 x BROW_ALONG, row 1 the centre line).
static int build_brow(builder* b, int side)
{
    int first = b->f->point_count;
    double sg = side == 0 ? 1 : -1;
    for (int r = 0; r < 3; ++r)
        for (int j = 0; j < BROW_ALONG; ++j) {
            double s = (double)j / (BROW_ALONG - 1);
            double x = sg * (0.095 + 0.31 * s);
            double y = 0.385 + 0.05 * sin(PI * (0.12 + 0.8 * s)) - 0.025 * s;
            double h = 0.026 * (1 - 0.5 * s) * (r - 1);
            double lift = r == 1 ? 0.014 : 0.006;
            if (add_point(b, FK_SKIN, side, x, y - h, surface_z(x, y - h) + lift, BROW) < 0) return -1;
        }
    return grid_tris(b, first, 3, BROW_ALONG, false, side == 1) ? first : -1;
}

// ---------------------------------------------------------------- rig fields

// Blendshape s's delta at a point (world units at full weight).
static void shape_delta(int s, const face_point* pt, double d[3])
{
    double x = pt->rest[0], y = pt->rest[1], z = pt->rest[2];
    d[0] = d[1] = d[2] = 0;
    if (pt->kind == FK_EYEBALL) return; // eyeballs only turn and scale
    double fm = smoothstep(0.05, 0.4, z);
    if (fm == 0) return;
    int lip = pt->lip;
    double above = lip ? (lip > 0) : smoothstep(FACE_MOUTH_Y - 0.01, FACE_MOUTH_Y + 0.02, y);
    double below = lip ? (lip < 0) : smoothstep(FACE_MOUTH_Y + 0.01, FACE_MOUTH_Y - 0.02, y);
    // Side fields are written for the left (+x); the right mirrors x.
    bool right = s == F_SMILE_R || s == F_FROWN_R || s == F_STRETCH_R || s == F_PUFF_R || s == F_CHEEK_RAISE_R ||
                 s == F_SNEER_R || s == F_BROW_RAISE_R || s == F_BROW_INNER_R || s == F_FURROW_R;
    double sg = right ? -1 : 1, X = sg * x, g, g2;
    double my = FACE_MOUTH_Y;
    switch (s) {
    case F_SMILE_L:
    case F_SMILE_R:
        g = gauss2(X - 0.19, y - my, 0.11, 0.09), g2 = gauss2(X - 0.24, y + 0.14, 0.12, 0.10);
        d[0] = sg * (0.045 * g + 0.01 * g2), d[1] = 0.065 * g + 0.03 * g2, d[2] = 0.012 * g + 0.02 * g2;
        break;
    case F_FROWN_L:
    case F_FROWN_R:
        g = gauss2(X - 0.19, y - my + 0.02, 0.11, 0.10), g2 = gauss2(X - 0.12, y + 0.55, 0.1, 0.1);
        d[0] = sg * 0.005 * g, d[1] = -0.06 * g - 0.015 * g2, d[2] = -0.005 * g;
        break;
    case F_STRETCH_L:
    case F_STRETCH_R:
        g = gauss2(X - 0.2, y - my, 0.12, 0.09);
        d[0] = sg * 0.06 * g, d[1] = -0.012 * g, d[2] = -0.015 * g;
        break;
    case F_PUCKER:
        g = gauss2(x, y - my, 0.2, 0.1);
        d[0] = -0.4 * x * g, d[2] = 0.05 * g;
        break;
    case F_UPPER_LIP_RAISE:
        g = gauss2(x, y - (my + 0.03), 0.17, 0.06) * above;
        d[1] = 0.045 * g, d[2] = 0.01 * g;
        break;
    case F_LOWER_LIP_DEPRESS:
        g = gauss2(x, y - (my - 0.04), 0.17, 0.07) * below;
        d[1] = -0.05 * g, d[2] = 0.012 * g;
        break;
    case F_MOUTH_SHIFT:
        g = gauss2(x, y - my, 0.28, 0.15);
        d[0] = 0.08 * g;
        break;
    case F_CHIN_RAISE:
        g = gauss2(x, y + 0.58, 0.18, 0.14), g2 = gauss2(x, y - my + 0.04, 0.17, 0.05) * below;
        d[1] = 0.04 * g + 0.015 * g2, d[2] = 0.01 * g + 0.02 * g2;
        break;
    case F_PUFF_L:
    case F_PUFF_R:
        g = gauss2(X - 0.30, y + 0.28, 0.13, 0.14);
        d[0] = sg * 0.07 * g, d[2] = 0.04 * g;
        break;
    case F_CHEEK_RAISE_L:
    case F_CHEEK_RAISE_R:
        g = gauss2(X - 0.27, y + 0.05, 0.12, 0.1);
        d[1] = 0.04 * g, d[2] = 0.02 * g;
        if (pt->kind == FK_LID_LOWER && pt->side == (right ? 1 : 0))
            d[1] += 0.018 * (1 - face_lid_fraction(pt->row)); // squints the lower lid
        break;
    case F_SNEER_L:
    case F_SNEER_R:
        g = gauss2(X - 0.07, y + 0.10, 0.05, 0.06), g2 = gauss2(X - 0.08, y - my - 0.05, 0.07, 0.05) * above;
        d[0] = sg * 0.008 * g, d[1] = 0.035 * g + 0.02 * g2, d[2] = 0.005 * g;
        break;
    case F_BROW_RAISE_L:
    case F_BROW_RAISE_R:
        g = gauss2(X - 0.26, y - 0.40, 0.2, 0.12);
        d[1] = 0.07 * g, d[2] = 0.005 * g;
        break;
    case F_BROW_INNER_L:
    case F_BROW_INNER_R:
        g = gauss2(X - 0.12, y - 0.40, 0.09, 0.1);
        d[1] = 0.07 * g;
        break;
    case F_FURROW_L:
    case F_FURROW_R:
        g = gauss2(X - 0.14, y - 0.38, 0.12, 0.1);
        d[0] = -sg * 0.035 * g, d[1] = -0.045 * g, d[2] = 0.008 * g;
        break;
    default:
        return;
    }
    for (int c = 0; c < 3; ++c)
        d[c] *= fm;
}

static uint8_t level(double w)
{
    return (uint8_t)lround(clamp01(w) * F_LEVELS);
}
// Shape weights below 1% are zero, so that a point skips that deformer (a
// 1% weight of a 20% scaling moves a point by a twentieth of a pixel).
static float weight(double w)
{
    return w < 1e-2 ? 0.0f : (float)w;
}

static void set_weights(face_rig* f, face_point* pt)
{
    double x = pt->rest[0], y = pt->rest[1], z = pt->rest[2];
    double fm = smoothstep(0.05, 0.4, z);
    double head = smoothstep(-1.05, -0.55, y);
    pt->lv_neck = level(head);
    pt->w_low = weight(smoothstep(-0.05, -0.5, y) * (1 - smoothstep(-0.7, -0.95, y)));
    if (pt->kind == FK_EYEBALL || pt->kind == FK_LID_UPPER || pt->kind == FK_LID_LOWER) {
        pt->w_eye = 1;
    } else {
        pt->side = x > 0 ? 0 : 1;
        pt->w_eye = weight(gauss2(fabs(x) - FACE_EYE_X, y - FACE_EYE_Y, 0.13, 0.11) * fm);
        pt->w_mouth = weight(gauss2(x, y - FACE_MOUTH_Y, 0.3, 0.13) * fm);
        pt->w_brow = weight(gauss2(fabs(x) - 0.25, y - 0.42, 0.26, 0.1) * fm);
        double nose = fmin(1.0, nose_disp(x, y) / 0.18) * fm;
        pt->w_nose = weight(nose);
        pt->lv_nose = level(nose);
        pt->lv_mouth = level(gauss2(x, y - FACE_MOUTH_Y, 0.24, 0.16) * fm);
        double jaw;
        int lip = pt->lip;
        if (lip) {
            double s = (double)pt->col / (LIP_ACROSS - 1), corner = exp(-(fmin(s, 1 - s) / 0.08) * (fmin(s, 1 - s) / 0.08));
            jaw = lip > 0 ? 0.5 * corner : 1 - 0.5 * corner;
        } else {
            jaw = smoothstep(FACE_MOUTH_Y + 0.02, FACE_MOUTH_Y - 0.02, y) * smoothstep(-0.15, 0.3, z) *
                  (1 - smoothstep(-0.72, -0.95, y));
        }
        pt->lv_jaw = level(jaw);
    }
    f->used[0][pt->lv_neck] = f->used[1][pt->lv_jaw] = f->used[2][pt->lv_mouth] = f->used[3][pt->lv_nose] = 1;
}

static bool build_deltas(face_rig* f)
{
    int cap = 0;
    for (int i = 0; i < f->point_count; ++i) {
        face_point* pt = &f->points[i];
        pt->delta_first = f->delta_count;
        for (int s = F_SMILE_L; s < F_BLENDSHAPES; ++s) {
            double d[3];
            shape_delta(s, pt, d);
            // Gaussian tails below 3e-4 (1/7000 of the head, a twentieth of
            // a pixel in the sketch view) are dropped: invisible, and they
            // would cost most of the evaluation.
            if (fabs(d[0]) + fabs(d[1]) + fabs(d[2]) < 3e-4) continue;
            if (f->delta_count == cap) {
                cap = cap ? 2 * cap : 65536;
                f->deltas = realloc(f->deltas, sizeof(face_delta) * (size_t)cap);
                if (!f->deltas) return false;
            }
            f->deltas[f->delta_count++] = (face_delta){s, {(float)d[0], (float)d[1], (float)d[2]}};
        }
        pt->delta_count = (uint8_t)(f->delta_count - pt->delta_first);
    }
    return true;
}

// ---------------------------------------------------------------- parameters and abstraction

typedef struct param_def {
    const char* name;
    double min, max;
    int unit, group;
} param_def;

static const param_def PARAMS[F_PARAMS] = {
    {"jaw_open", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"jaw_side", -1, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"smile_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"smile_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"frown_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"frown_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"mouth_stretch_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"mouth_stretch_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"lip_pucker", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"upper_lip_raise", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"lower_lip_depress", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"mouth_shift", -1, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"chin_raise", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"cheek_puff_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"cheek_puff_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"cheek_raise_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"cheek_raise_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"nose_sneer_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"nose_sneer_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"brow_raise_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"brow_raise_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"brow_inner_up_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"brow_inner_up_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"brow_furrow_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"brow_furrow_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"lid_close_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"lid_close_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"lid_lower_up_l", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"lid_lower_up_r", 0, 1, SP_BB_UNIT_WEIGHT, SP_GROUP_POSE},
    {"eye_look_h", -0.45, 0.45, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"eye_look_v", -0.35, 0.35, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"mouth_twist", -0.3, 0.3, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"nose_bend_side", -0.35, 0.35, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"nose_bend_up", -0.3, 0.3, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"head_twist", -0.6, 0.6, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"head_nod", -0.4, 0.4, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"head_tilt", -0.35, 0.35, SP_BB_UNIT_ANGLE, SP_GROUP_POSE},
    {"face_squash", 0.85, 1.15, SP_BB_UNIT_FACTOR, SP_GROUP_POSE},
    {"head_width", 0.9, 1.1, SP_BB_UNIT_FACTOR, SP_GROUP_SHAPE},
    {"jaw_width", 0.85, 1.15, SP_BB_UNIT_FACTOR, SP_GROUP_SHAPE},
    {"nose_size", 0.8, 1.25, SP_BB_UNIT_FACTOR, SP_GROUP_SHAPE},
    {"eye_size", 0.85, 1.2, SP_BB_UNIT_FACTOR, SP_GROUP_SHAPE},
    {"mouth_width", 0.85, 1.15, SP_BB_UNIT_FACTOR, SP_GROUP_SHAPE},
    {"brow_height", -0.05, 0.05, SP_BB_UNIT_LENGTH, SP_GROUP_SHAPE},
};

static bool add_abs(builder* b, int cap, int point)
{
    face_rig* f = b->f;
    if (f->abs_count >= cap) return false;
    f->abs_index[f->abs_count++] = point;
    return true;
}

void face_free(face_rig* f)
{
    if (!f) return;
    free(f->points), free(f->deltas), free(f->rest), free(f->triangles), free(f->colors), free(f->abs_index);
    for (int l = 0; l < FL_COUNT; ++l)
        free(f->lists[l].items);
    free(f->entries), free(f->neck_runs);
    free(f);
}

static bool push(face_list* l, face_item it)
{
    if ((l->count & (l->count - 1)) == 0) { // grow at powers of two
        face_item* g = realloc(l->items, sizeof(face_item) * (size_t)(l->count ? 2 * l->count : 1));
        if (!g) return false;
        l->items = g;
    }
    l->items[l->count++] = it;
    return true;
}

// The evaluator's plan from the points (face_item in face.h).
static bool compile_plan(face_rig* f)
{
    f->entries = malloc(sizeof(face_entry) * (size_t)(f->delta_count + 1));
    f->neck_runs = malloc(sizeof(face_run) * (size_t)(f->point_count + 1));
    if (!f->entries || !f->neck_runs) return false;
    bool ok = true;
    for (int i = 0; i < f->point_count; ++i) {
        uint8_t lv = f->points[i].lv_neck;
        face_run* last = f->neck_run_count ? &f->neck_runs[f->neck_run_count - 1] : NULL;
        if (lv == 0) continue;
        if (last && last->lv == lv && last->first + last->count == i)
            ++last->count;
        else
            f->neck_runs[f->neck_run_count++] = (face_run){i, 1, lv};
    }
    for (int i = 0; ok && i < f->point_count; ++i) {
        const face_point* pt = &f->points[i];
        face_item it = {.i = i, .side = pt->side, .upper = pt->kind == FK_LID_UPPER, .col = pt->col, .row = pt->row};
        if (pt->kind == FK_EYEBALL) ok = ok && push(&f->lists[FL_EYEBALL], it);
        if (pt->kind == FK_LID_UPPER || pt->kind == FK_LID_LOWER) ok = ok && push(&f->lists[FL_LID], it);
        if (pt->w_eye != 0) ok = ok && push(&f->lists[FL_EYE_SIZE], (face_item){.i = i, .side = pt->side, .w = pt->w_eye});
        if (pt->w_nose != 0) ok = ok && push(&f->lists[FL_NOSE_SIZE], (face_item){.i = i, .w = pt->w_nose});
        if (pt->w_brow != 0) ok = ok && push(&f->lists[FL_BROW], (face_item){.i = i, .w = pt->w_brow});
        if (pt->w_mouth != 0 || pt->w_low != 0)
            ok = ok && push(&f->lists[FL_XSCALE], (face_item){.i = i, .w = pt->w_mouth, .w2 = pt->w_low});
        if (pt->lv_nose) ok = ok && push(&f->lists[FL_NOSE_ROT], (face_item){.i = i, .lv = pt->lv_nose});
        if (pt->lv_mouth) ok = ok && push(&f->lists[FL_MOUTH_ROT], (face_item){.i = i, .lv = pt->lv_mouth});
        if (pt->lv_jaw) ok = ok && push(&f->lists[FL_JAW_ROT], (face_item){.i = i, .lv = pt->lv_jaw});
    }
    // Deltas by shape; within a shape in point order.
    int k = 0;
    for (int sh = 0; sh < F_PARAMS; ++sh) {
        f->shape_first[sh] = k;
        for (int i = 0; i < f->point_count; ++i) {
            const face_point* pt = &f->points[i];
            for (const face_delta* d = f->deltas + pt->delta_first; d < f->deltas + pt->delta_first + pt->delta_count; ++d)
                if (d->shape == sh) f->entries[k++] = (face_entry){i, {d->d[0], d->d[1], d->d[2]}};
        }
    }
    f->shape_first[F_PARAMS] = k;
    return ok;
}

face_rig* face_build(void)
{
    face_rig* f = calloc(1, sizeof *f);
    if (!f) return NULL;
    builder b = {.f = f};
    for (int j = 0; j < LID_ACROSS; ++j) {
        f->lid_cb[j] = cos(face_lid_beta(j));
        f->lid_sb[j] = sin(face_lid_beta(j));
    }
    bool ok = build_head(&b) && build_eye(&b, 0) && build_eye(&b, 1);
    int lid[2][2] = {{-1, -1}, {-1, -1}}, lip[2] = {-1, -1}, brow[2] = {-1, -1};
    for (int s = 0; ok && s < 2; ++s)
        for (int u = 0; ok && u < 2; ++u)
            ok = (lid[s][u] = build_lid(&b, s, u)) >= 0;
    for (int u = 0; ok && u < 2; ++u)
        ok = (lip[u] = build_lip(&b, u == 0)) >= 0;
    for (int s = 0; ok && s < 2; ++s)
        ok = (brow[s] = build_brow(&b, s)) >= 0;
    // The base of the nose, on the sculpted surface: abstraction points
    // that no triangle uses (vertices all the same, so that every point
    // the rig moves is written straight to the caller's buffer).
    int nose_first = f->point_count;
    for (int i = 0; ok && i < NOSE_POINTS; ++i) {
        double u = -1 + 2.0 * i / (NOSE_POINTS - 1), x = 0.08 * u, y = -0.12 - 0.025 * (1 - u * u);
        ok = add_point(&b, FK_SKIN, x > 0 ? 0 : 1, x, y, surface_z(x, y), SKIN) >= 0;
    }
    f->vertex_count = f->point_count;
    f->triangle_count = b.ntri;
    for (int i = 0; ok && i < f->point_count; ++i)
        set_weights(f, &f->points[i]);
    ok = ok && build_deltas(f);
    ok = ok && compile_plan(f);
    // The abstraction: brows and lids (every other point of their rows),
    // the base of the nose and the outer loop of the lips.
    enum { ABS_CAP = 128 };
    f->abs_index = malloc(sizeof(int32_t) * ABS_CAP);
    f->rest = malloc(sizeof(double) * 3 * (size_t)f->vertex_count);
    f->colors = malloc(sizeof(float) * 4 * (size_t)f->vertex_count);
    ok = ok && f->abs_index && f->rest && f->colors;
    if (!ok) {
        free(b.color);
        face_free(f);
        return NULL;
    }
    static const char* const NAMES[8] = {"brow_l",      "brow_r",      "lid_upper_l", "lid_upper_r",
                                         "lid_lower_l", "lid_lower_r", "nose",        "mouth"};
    int nc = 0;
    for (int s = 0; s < 2; ++s) {
        int start = f->abs_count;
        for (int j = 0; j < BROW_ALONG; j += 2)
            add_abs(&b, ABS_CAP, brow[s] + BROW_ALONG + j);
        f->curves[nc++] = (sp_blackbox_curve){NAMES[s], f->abs_count - start, 0};
    }
    for (int u = 1; u >= 0; --u)
        for (int s = 0; s < 2; ++s) {
            int start = f->abs_count;
            for (int j = 0; j < LID_ACROSS; j += 2)
                add_abs(&b, ABS_CAP, lid[s][u] + j);
            f->curves[nc] = (sp_blackbox_curve){NAMES[nc], f->abs_count - start, 0};
            ++nc;
        }
    {
        int start = f->abs_count;
        for (int i = 0; i < NOSE_POINTS; ++i)
            add_abs(&b, ABS_CAP, nose_first + i);
        f->curves[nc++] = (sp_blackbox_curve){NAMES[6], f->abs_count - start, 0};
    }
    {
        // Upper outline corner to corner, then the lower one back, without its corners.
        int start = f->abs_count;
        for (int j = 0; j < LIP_ACROSS; j += 2)
            add_abs(&b, ABS_CAP, lip[0] + j);
        for (int j = LIP_ACROSS - 3; j >= 2; j -= 2)
            add_abs(&b, ABS_CAP, lip[1] + j);
        f->curves[nc++] = (sp_blackbox_curve){NAMES[7], f->abs_count - start, 1};
    }
    for (int i = 0; i < f->vertex_count; ++i) {
        memcpy(f->rest + 3 * i, f->points[i].rest, sizeof(double) * 3);
        memcpy(f->colors + 4 * i, b.color[i], sizeof(float) * 4);
    }
    free(b.color);
    for (int k = 0; k < F_PARAMS; ++k) {
        const param_def* d = &PARAMS[k];
        double def = d->unit == SP_BB_UNIT_FACTOR ? 1.0 : (d->min > 0 ? d->min : 0.0);
        f->params[k] = (sp_blackbox_param){d->name, d->min, d->max, def, d->group, d->unit};
    }
    f->abstraction = (sp_blackbox_abstraction){"face", SP_CORR_ORDERED, nc, f->curves};
    return f;
}
