// visitors_make.c: builds the visitors' evaluation set from its sources, so
// that the set can be rebuilt and audited:
//
//   sp-visitors-make --designs tests/data/visitors/designs.json [--quickdraw ../shared/data/quickdraw] --out DIR
//                    [--train-out assets/sketches]
//
// The repository keeps the hand-placed drawings (tests/data/visitors, made
// without --quickdraw); the build makes the whole set, the people's strokes
// read from the Quick, Draw! data, in <build>/tests/data/visitors
// (tests/bench/visitors.cmake): the data's terms ask that it not be copied.
//
// designs.json lists every drawing, in two kinds:
//   {"name", "label", "closed": true|false, "points": [[x, y], ...]}   hand-placed control points
//       in a 100 x 100 box (y down; a point written twice is a corner), drawn by the pen model below;
//   {"name", "label", "qd": "<category>", "drawing": i, "stroke": j}   stroke j of drawing i (0-based,
//       the line in <category>.ndjson) of the Quick, Draw! data, as the person drew it (only scaled,
//       placed and, with "flip", mirrored).
// Both may give "size" (pixels, the longest side; default: 260-520 from the seed), "at" ([x, y] centre;
// default: from the seed), "rot" (degrees, counter-clockwise on screen) and "flip" (mirror left-right).
//
// The pen model is deliberately NOT the project's hand-drawing model
// (partdb/src/handdraw.c), so that nothing the classifier trains on shares it:
// the hand aims at each control point and misses it a little (Gaussian,
// 1.2% of the size), moves between them along a centripetal Catmull-Rom path
// with a speed profile between constant and minimum-jerk (slow at each aim
// point, fast between; longer moves faster: isochrony), drifts sideways by an
// Ornstein-Uhlenbeck process, is sampled at 60 Hz with a little clock jitter
// and integer touch coordinates, starts with a small hook in a random
// direction 40% of the time, flicks off at the end 30% of the time, and closes
// a closed shape with a gap (up to 6% of its length) or an overshoot (up to 8%).
//
// designs.json's "training" list names Quick, Draw! strokes for the part
// database's default training set instead: {"label", "qd", "drawing", "stroke"}.
// None may come from a drawing the evaluation uses (the tool refuses that:
// evaluation and training drawings have different makers). With
// --train-out DIR they are written to DIR/picks.json as references ({"category",
// "file", "line" from 1, "stroke", "key_id"}), which the default recipe reads
// from the data (sp_db_people_strokes).
//
// Output: <out>/<half>/<label>/<name>.json (sketchpose-strokes, one stroke,
// canvas 1280 x 800), half = tune or report: within each label, the
// hand-placed drawings alternate tune, report, tune, ... in file order, and so
// do the Quick, Draw! ones (README.md there says the same). A drawing with
// "fresh": true (made by other hands after the split, to tune on) goes to
// <out>/fresh instead and takes no turn in the alternation. The contact
// sheets <out>/tune.png, <out>/report.png and <out>/fresh.png show every
// drawing with its name.
#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sp/sketch_io.h"
#include "sp/sketch_sheet.h"
#include "sp/synth.h"

#define PI 3.14159265358979323846
#define CANVAS_W 1280.0
#define CANVAS_H 800.0
#define MAXP 4096

static uint64_t name_seed(const char* s)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (; *s; ++s)
        h = (h ^ (unsigned char)*s) * 0x100000001b3ull;
    return h ? h : 1;
}

typedef struct placement {
    double size, cx, cy, rot;
    bool flip;
} placement;

static placement read_placement(const cJSON* d, sp_rng* rng)
{
    placement p = {.size = sp_rng_range(rng, 260, 520)};
    const cJSON* v;
    if (cJSON_IsNumber(v = cJSON_GetObjectItem(d, "size"))) p.size = v->valuedouble;
    // Kept inside the canvas with a 30 px margin.
    double hw = 0.5 * p.size + 30;
    p.cx = sp_rng_range(rng, fmin(hw, CANVAS_W / 2), fmax(CANVAS_W - hw, CANVAS_W / 2));
    p.cy = sp_rng_range(rng, fmin(hw, CANVAS_H / 2), fmax(CANVAS_H - hw, CANVAS_H / 2));
    if (cJSON_IsArray(v = cJSON_GetObjectItem(d, "at")) && cJSON_GetArraySize(v) == 2) {
        p.cx = cJSON_GetArrayItem(v, 0)->valuedouble;
        p.cy = cJSON_GetArrayItem(v, 1)->valuedouble;
    }
    if (cJSON_IsNumber(v = cJSON_GetObjectItem(d, "rot"))) p.rot = v->valuedouble * PI / 180;
    p.flip = cJSON_IsTrue(cJSON_GetObjectItem(d, "flip"));
    return p;
}

// Maps points from their own box onto the canvas: longest side = size, centred at (cx, cy).
static void place(sp_vec2* q, int n, const placement* pl)
{
    double lx = 1e300, ly = 1e300, hx = -1e300, hy = -1e300;
    double c = cos(pl->rot), s = sin(pl->rot);
    for (int i = 0; i < n; ++i) {
        double x = pl->flip ? -q[i].x : q[i].x, y = q[i].y;
        q[i] = (sp_vec2){c * x + s * y, -s * x + c * y}; // counter-clockwise on screen (y down)
        lx = fmin(lx, q[i].x), hx = fmax(hx, q[i].x), ly = fmin(ly, q[i].y), hy = fmax(hy, q[i].y);
    }
    double k = pl->size / fmax(fmax(hx - lx, hy - ly), 1e-9);
    for (int i = 0; i < n; ++i)
        q[i] = (sp_vec2){pl->cx + k * (q[i].x - 0.5 * (lx + hx)), pl->cy + k * (q[i].y - 0.5 * (ly + hy))};
}

// Centripetal Catmull-Rom between b and c (a, d the neighbours) at u in [0, 1].
static sp_vec2 catmull(sp_vec2 a, sp_vec2 b, sp_vec2 c, sp_vec2 d, double u)
{
    double t0 = 0, t1 = t0 + pow(hypot(b.x - a.x, b.y - a.y) + 1e-6, 0.5), t2 = t1 + pow(hypot(c.x - b.x, c.y - b.y) + 1e-6, 0.5),
           t3 = t2 + pow(hypot(d.x - c.x, d.y - c.y) + 1e-6, 0.5);
    double t = t1 + u * (t2 - t1);
#define LERP(p, q, ta, tb)                                                                                                       \
    ((sp_vec2){((tb - t) * p.x + (t - ta) * q.x) / (tb - ta), ((tb - t) * p.y + (t - ta) * q.y) / (tb - ta)})
    sp_vec2 a1 = LERP(a, b, t0, t1), a2 = LERP(b, c, t1, t2), a3 = LERP(c, d, t2, t3);
    sp_vec2 b1 = LERP(a1, a2, t0, t2), b2 = LERP(a2, a3, t1, t3);
    return LERP(b1, b2, t1, t2);
#undef LERP
}

// The hand: via points (already on the canvas) -> one stroke with times.
static int pen(const sp_vec2* via_in, int nv, bool closed, double size, sp_rng* rng, sp_vec2* out, double* t_out)
{
    sp_vec2 via[512];
    if (nv > 500) nv = 500;
    // The hand misses each aim point a little; a repeated point (a corner) is missed once.
    for (int i = 0; i < nv; ++i) {
        if (i > 0 && via_in[i].x == via_in[i - 1].x && via_in[i].y == via_in[i - 1].y)
            via[i] = via[i - 1];
        else
            via[i] = (sp_vec2){via_in[i].x + 0.012 * size * sp_rng_normal(rng), via_in[i].y + 0.012 * size * sp_rng_normal(rng)};
    }
    int segs = closed ? nv : nv - 1;
    // Closure: a gap (< 0) or an overshoot (> 0), as a share of the path.
    double closure =
        closed ? (sp_rng_uniform(rng) < 0.5 ? -sp_rng_range(rng, 0.005, 0.06) : sp_rng_range(rng, 0.005, 0.08)) : 0.0;
    // Dense path with a time per sample: each segment's duration by isochrony, its
    // progress between constant speed and minimum jerk.
    enum { SUB = 40 };
    static sp_vec2 dense[512 * SUB + SUB];
    static double dt[512 * SUB + SUB];
    int nd = 0;
    double clock = 0;
    int extra = closed && closure > 0 ? (int)ceil(closure * segs) + 1 : 0;
    for (int s = 0; s < segs + extra; ++s) {
        int i = s % nv;
        sp_vec2 a = via[closed ? (i - 1 + nv) % nv : (i > 0 ? i - 1 : 0)], b = via[i], c = via[closed ? (i + 1) % nv : i + 1],
                d = via[closed ? (i + 2) % nv : (i + 2 < nv ? i + 2 : nv - 1)];
        double len = hypot(c.x - b.x, c.y - b.y);
        double dur = 60.0 + 9.0 * cbrt(len * len); // ms: longer moves are faster
        double alpha = sp_rng_range(rng, 0.3, 0.8);
        for (int k = (s == 0 ? 0 : 1); k <= SUB; ++k) {
            double u = (double)k / SUB;
            double mj = u * u * u * (10 - 15 * u + 6 * u * u);
            dense[nd] = len > 1e-9 ? catmull(a, b, c, d, u) : b;
            dt[nd++] = clock + dur * (u + alpha * (mj - u));
        }
        clock += dur;
    }
    // Trim to the traced share of a closed path (gap or overshoot).
    if (closed) {
        int keep = (int)lround(segs * SUB * (1 + closure)) + 1;
        if (keep < 4) keep = 4;
        if (keep < nd) nd = keep;
    }
    // Sideways drift: an Ornstein-Uhlenbeck offset along the path normal.
    double ou = 0, theta = 4.0, sigma = 0.008 * size * sqrt(2 * theta);
    double t_end = dt[nd - 1];
    // 60 Hz sampling with clock jitter.
    int n = 0;
    double t = 0;
    int j = 0;
    // The pen-down hook: a few points coming in from a random direction.
    if (sp_rng_uniform(rng) < 0.4 && nd > 2) {
        double ang = sp_rng_range(rng, 0, 2 * PI), l = sp_rng_range(rng, 0.006, 0.015) * size;
        int h = 2 + (int)(sp_rng_uniform(rng) * 2);
        for (int k = h; k >= 1; --k) {
            out[n] = (sp_vec2){dense[0].x + l * k / h * cos(ang), dense[0].y + l * k / h * sin(ang)};
            t_out[n] = (h - k) * 16.7;
            ++n;
        }
        t = h * 16.7;
    }
    double t0 = t;
    double prev_t = 0;
    while (n < MAXP - 8) {
        double tt = t - t0;
        if (tt > t_end) tt = t_end;
        while (j + 1 < nd && dt[j + 1] < tt)
            ++j;
        double f = j + 1 < nd && dt[j + 1] > dt[j] ? (tt - dt[j]) / (dt[j + 1] - dt[j]) : 0;
        if (f < 0) f = 0;
        if (f > 1) f = 1;
        sp_vec2 p =
            j + 1 < nd ? (sp_vec2){dense[j].x + f * (dense[j + 1].x - dense[j].x), dense[j].y + f * (dense[j + 1].y - dense[j].y)}
                       : dense[nd - 1];
        int a = j > 0 ? j - 1 : 0, b = j + 1 < nd ? j + 1 : nd - 1;
        double tx = dense[b].x - dense[a].x, ty = dense[b].y - dense[a].y, tl = hypot(tx, ty);
        double h = (tt - prev_t) / 1000.0;
        prev_t = tt;
        ou += -theta * ou * h + sigma * sqrt(fmax(h, 0)) * sp_rng_normal(rng);
        if (tl > 1e-9) p = (sp_vec2){p.x - ty / tl * ou, p.y + tx / tl * ou};
        out[n] = (sp_vec2){round(p.x), round(p.y)}; // touch screens report whole pixels
        t_out[n] = round(t);
        ++n;
        if (tt >= t_end) break;
        t += 1000.0 / 60.0 + sp_rng_range(rng, -2, 2);
    }
    // The flick at pen-up.
    if (sp_rng_uniform(rng) < 0.3 && n > 3) {
        double ang = sp_rng_range(rng, 0, 2 * PI), l = sp_rng_range(rng, 0.008, 0.02) * size;
        sp_vec2 e = out[n - 1];
        out[n] = (sp_vec2){round(e.x + l * cos(ang)), round(e.y + l * sin(ang))};
        t_out[n] = t_out[n - 1] + 16.7;
        ++n;
    }
    return n;
}

static int mkdirs(const char* path)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char* p = buf + 1; *p; ++p)
        if (*p == '/') {
            *p = 0;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
            *p = '/';
        }
    return mkdir(buf, 0777) != 0 && errno != EEXIST ? -1 : 0;
}

static char* read_text(const char* path)
{
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char* b = malloc((size_t)n + 1);
    if (b && fread(b, 1, (size_t)n, f) != (size_t)n) {
        free(b);
        b = NULL;
    }
    if (b) b[n] = 0;
    fclose(f);
    return b;
}

// Line `index` (0-based) of a Quick, Draw! file, parsed; NULL when absent.
static cJSON* qd_line(const char* dir, const char* cat, int index)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.ndjson", dir, cat);
    char* text = read_text(path);
    if (!text) return NULL;
    cJSON* j = NULL;
    char* line = text;
    for (int i = 0; line && *line; ++i) {
        char* end = strchr(line, '\n');
        if (end) *end = 0;
        if (i == index) {
            j = cJSON_Parse(line);
            break;
        }
        line = end ? end + 1 : NULL;
    }
    free(text);
    return j;
}

// The training picks: checked against the evaluation's drawings and written as
// out_dir/picks.json, which names each stroke (file, line from 1, stroke from 0,
// key_id) for the default recipe to read from the data (sp_db_people_strokes):
// the data's terms ask that it not be copied into the repository.
static int write_training(const cJSON* root, const char* qd_dir, const char* out_dir)
{
    const cJSON* train = cJSON_GetObjectItem(root, "training");
    const cJSON* eval = cJSON_GetObjectItem(root, "drawings");
    const cJSON *t, *e;
    cJSON* out = cJSON_CreateObject();
    cJSON_AddStringToObject(out, "quickdraw", "../../../shared/data/quickdraw");
    cJSON* picks = cJSON_AddArrayToObject(out, "picks");
    cJSON_ArrayForEach(t, train)
    {
        const char* qd = cJSON_GetStringValue(cJSON_GetObjectItem(t, "qd"));
        const char* label = cJSON_GetStringValue(cJSON_GetObjectItem(t, "label"));
        int di = (int)cJSON_GetNumberValue(cJSON_GetObjectItem(t, "drawing")),
            si = (int)cJSON_GetNumberValue(cJSON_GetObjectItem(t, "stroke"));
        if (!qd || !label) {
            fprintf(stderr, "training pick without qd or label\n");
            cJSON_Delete(out);
            return 1;
        }
        cJSON_ArrayForEach(e, eval)
        {
            const char* eq = cJSON_GetStringValue(cJSON_GetObjectItem(e, "qd"));
            if (eq && !strcmp(eq, qd) && (int)cJSON_GetNumberValue(cJSON_GetObjectItem(e, "drawing")) == di) {
                fprintf(stderr, "training pick %s drawing %d is also an evaluation drawing (%s)\n", qd, di,
                        cJSON_GetStringValue(cJSON_GetObjectItem(e, "name")));
                cJSON_Delete(out);
                return 1;
            }
        }
        cJSON* j = qd_line(qd_dir, qd, di);
        const char* key = cJSON_GetStringValue(cJSON_GetObjectItem(j, "key_id"));
        if (!key || !cJSON_GetArrayItem(cJSON_GetObjectItem(j, "drawing"), si)) {
            fprintf(stderr, "%s/%s.ndjson: no drawing %d stroke %d with a key_id\n", qd_dir, qd, di, si);
            cJSON_Delete(j);
            cJSON_Delete(out);
            return 1;
        }
        char file[128];
        snprintf(file, sizeof file, "%s.ndjson", qd);
        cJSON* o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "category", label);
        cJSON_AddStringToObject(o, "file", file);
        cJSON_AddNumberToObject(o, "line", di + 1);
        cJSON_AddNumberToObject(o, "stroke", si);
        cJSON_AddStringToObject(o, "key_id", key);
        cJSON_AddItemToArray(picks, o);
        cJSON_Delete(j);
    }
    int rc = 0;
    if (out_dir) {
        char path[1024];
        snprintf(path, sizeof path, "%s/picks.json", out_dir);
        FILE* f = fopen(path, "w");
        // One pick a line: the file is read and reviewed by people.
        if (f) {
            fprintf(f, "{\"quickdraw\": \"%s\", \"picks\": [\n", cJSON_GetStringValue(cJSON_GetObjectItem(out, "quickdraw")));
            const cJSON* o;
            cJSON_ArrayForEach(o, picks)
            {
                char* line = cJSON_PrintUnformatted(o);
                fprintf(f, "  %s%s\n", line, o->next ? "," : "");
                free(line);
            }
            fprintf(f, "]}\n");
        }
        if (!f || fclose(f) != 0) {
            fprintf(stderr, "%s: cannot write\n", path);
            rc = 1;
        }
    }
    cJSON_Delete(out);
    return rc;
}

typedef struct counter {
    char label[64];
    int hand, qd, fresh;
} counter;

int main(int argc, char** argv)
{
    const char *designs = NULL, *qd_dir = NULL, *out_dir = NULL, *train_out = NULL;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--designs"))
            designs = argv[i + 1];
        else if (!strcmp(argv[i], "--train-out"))
            train_out = argv[i + 1];
        else if (!strcmp(argv[i], "--quickdraw"))
            qd_dir = argv[i + 1];
        else if (!strcmp(argv[i], "--out"))
            out_dir = argv[i + 1];
    }
    if (!designs || !out_dir || (train_out && !qd_dir)) {
        fprintf(stderr, "usage: sp-visitors-make --designs designs.json [--quickdraw DIR] --out DIR [--train-out DIR (needs --quickdraw)]\n");
        return 2;
    }
    char* text = read_text(designs);
    cJSON* root = text ? cJSON_Parse(text) : NULL;
    free(text);
    const cJSON* list = cJSON_GetObjectItem(root, "drawings");
    if (!cJSON_IsArray(list)) {
        fprintf(stderr, "%s: not a designs file (no \"drawings\" array)\n", designs);
        return 1;
    }
    if (qd_dir && write_training(root, qd_dir, train_out) != 0) return 1;
    counter cnt[32] = {0};
    int ncnt = 0, written = 0, skipped = 0;
    static sp_vec2 pts[MAXP];
    static double ts[MAXP];
    const cJSON* d;
    cJSON_ArrayForEach(d, list)
    {
        const char* name = cJSON_GetStringValue(cJSON_GetObjectItem(d, "name"));
        const char* label = cJSON_GetStringValue(cJSON_GetObjectItem(d, "label"));
        if (!name || !label) {
            fprintf(stderr, "%s: a drawing without name or label\n", designs);
            return 1;
        }
        sp_rng rng = {name_seed(name)};
        placement pl = read_placement(d, &rng);
        const char* qd = cJSON_GetStringValue(cJSON_GetObjectItem(d, "qd"));
        int n = 0;
        // Without the data, its drawings are left out; the split stays the same
        // (hand-placed and Quick, Draw! drawings alternate halves separately).
        if (qd && !qd_dir) {
            ++skipped;
            continue;
        }
        bool times = true;
        if (qd) {
            char path[1024];
            snprintf(path, sizeof path, "%s/%s.ndjson", qd_dir, qd);
            sp_dataset ds = {0};
            sp_error err = {0};
            if (sp_dataset_read_ndjson(&ds, path, -1, &err) != SP_OK) {
                fprintf(stderr, "%s\n", err.text);
                return 1;
            }
            int di = (int)cJSON_GetNumberValue(cJSON_GetObjectItem(d, "drawing")),
                si = (int)cJSON_GetNumberValue(cJSON_GetObjectItem(d, "stroke"));
            if (di < 0 || di >= ds.count || si < 0 || si >= ds.samples[di].sketch.stroke_count) {
                fprintf(stderr, "%s: %s: no drawing %d stroke %d\n", designs, name, di, si);
                return 1;
            }
            const sp_stroke* st = &ds.samples[di].sketch.strokes[si];
            // Densified linearly (the simplified data keeps only corners) so that the
            // spacing looks like touch input; the shape is the person's.
            for (int k = 0; k < st->count && n < MAXP - 1; ++k) {
                if (k > 0) {
                    sp_vec2 a = st->points[k - 1], b = st->points[k];
                    int m = (int)ceil(hypot(b.x - a.x, b.y - a.y) / 3.0);
                    for (int q = 1; q < m && n < MAXP - 1; ++q)
                        pts[n++] = (sp_vec2){a.x + (b.x - a.x) * q / m, a.y + (b.y - a.y) * q / m};
                }
                pts[n++] = st->points[k];
            }
            place(pts, n, &pl);
            times = false;
            sp_dataset_free(&ds);
        } else {
            const cJSON* ps = cJSON_GetObjectItem(d, "points");
            int nv = cJSON_GetArraySize(ps);
            if (!cJSON_IsArray(ps) || nv < 2 || nv > 500) {
                fprintf(stderr, "%s: %s: needs 2..500 points\n", designs, name);
                return 1;
            }
            sp_vec2 via[500];
            for (int k = 0; k < nv; ++k) {
                const cJSON* p = cJSON_GetArrayItem(ps, k);
                via[k] = (sp_vec2){cJSON_GetArrayItem(p, 0)->valuedouble, cJSON_GetArrayItem(p, 1)->valuedouble};
            }
            place(via, nv, &pl);
            bool closed = cJSON_IsTrue(cJSON_GetObjectItem(d, "closed"));
            if (nv == 2 && via[0].x == via[1].x && via[0].y == via[1].y) { // a tap
                pts[0] = via[0];
                ts[0] = 0;
                pts[1] = (sp_vec2){via[0].x + 1, via[0].y};
                ts[1] = 50;
                n = 2;
            } else {
                n = pen(via, nv, closed, pl.size, &rng, pts, ts);
            }
        }
        for (int k = 0; k < n; ++k) { // the canvas clamps touches to its edge
            pts[k].x = fmin(fmax(pts[k].x, 0), CANVAS_W);
            pts[k].y = fmin(fmax(pts[k].y, 0), CANVAS_H);
        }
        int c = 0;
        while (c < ncnt && strcmp(cnt[c].label, label) != 0)
            ++c;
        if (c == ncnt) {
            if (ncnt == 32) return 1;
            snprintf(cnt[ncnt++].label, sizeof cnt[0].label, "%s", label);
        }
        // A fresh drawing keeps out of the alternation, so the two halves stay as they were split.
        const char* half = "fresh";
        if (cJSON_IsTrue(cJSON_GetObjectItem(d, "fresh"))) {
            cnt[c].fresh++;
        } else {
            int idx = qd ? cnt[c].qd++ : cnt[c].hand++;
            half = idx % 2 == 0 ? "tune" : "report";
        }
        char dir[1024], file[1200];
        snprintf(dir, sizeof dir, "%s/%s/%s", out_dir, half, label);
        if (mkdirs(dir) != 0) {
            fprintf(stderr, "%s: cannot create\n", dir);
            return 1;
        }
        snprintf(file, sizeof file, "%s/%s.json", dir, name);
        sp_sketch sk = {.canvas_w = CANVAS_W, .canvas_h = CANVAS_H};
        sp_error err = {0};
        if (sp_sketch_add_stroke(&sk, pts, times ? ts : NULL, n) != SP_OK || sp_sketch_write_json(file, &sk, &err) != SP_OK) {
            fprintf(stderr, "%s: %s\n", file, err.text);
            return 1;
        }
        sp_sketch_free(&sk);
        ++written;
    }
    cJSON_Delete(root);
    // Contact sheets, labelled with the file names, label by label.
    static const char *const halves[] = {"tune", "report", "fresh"}, *const names[] = {"tune half", "report half", "fresh set"};
    for (int h = 0; h < 3; ++h) {
        const char* half = halves[h];
        sp_sheet_item items[512];
        static char labels[512][96];
        static sp_sketch sketches[512];
        int n = 0;
        for (int c = 0; c < ncnt; ++c) {
            char dir[2600];
            snprintf(dir, sizeof dir, "%s/%s/%s", out_dir, half, cnt[c].label);
            struct dirent** list = NULL;
            int m = scandir(dir, &list, NULL, alphasort);
            for (int k = 0; k < m; ++k) {
                size_t l = strlen(list[k]->d_name);
                char file[2900];
                snprintf(file, sizeof file, "%s/%s", dir, list[k]->d_name);
                sp_error err = {0};
                if (n < 512 && l > 5 && !strcmp(list[k]->d_name + l - 5, ".json") && sp_sketch_read_json(file, &sketches[n], &err) == SP_OK) {
                    snprintf(labels[n], sizeof labels[n], "%.*s", (int)l - 5, list[k]->d_name);
                    items[n] = (sp_sheet_item){.sketch = &sketches[n], .label = cnt[c].label, .note = labels[n]};
                    ++n;
                }
                free(list[k]);
            }
            free(list);
        }
        char file[1100], title[192];
        snprintf(file, sizeof file, "%s/%s.png", out_dir, half);
        snprintf(title, sizeof title, "visitors' drawings, %s: %d drawings%s", names[h], n, skipped ? ", hand-placed only" : "");
        sp_error err = {0};
        if (n > 0 && sp_sheet_write_png(items, n, &(sp_sheet_desc){.cell = 130, .cols = 12, .title = title}, file, &err) != SP_OK) {
            fprintf(stderr, "%s\n", err.text);
            return 1;
        }
        for (int k = 0; k < n; ++k)
            sp_sketch_free(&sketches[k]);
    }
    printf("{\"written\": %d, \"quickdraw_left_out\": %d, \"labels\": {", written, skipped);
    for (int c = 0; c < ncnt; ++c)
        printf("%s\"%s\": {\"hand\": %d, \"quickdraw\": %d, \"fresh\": %d}", c ? ", " : "", cnt[c].label, cnt[c].hand, cnt[c].qd,
               cnt[c].fresh);
    printf("}}\n");
    return 0;
}
