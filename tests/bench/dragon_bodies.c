// tests/bench/dragon_bodies: the kiosk pipeline (sp_dragon, no window) as
// the canvas fills with dragons: the six parts' strokes (kp_six_strokes, the
// body first) at half size, one dragon after another in a 3 x 2 grid. A new
// body lays out every part on the canvas again, so its stroke is the one
// whose time grows with the parts already there.
//   build/tests/bench/dragon_bodies [--db DB] [--dragons N (1..6, default 6)] [--runs R (default 5)] [--json]
// Without --db it builds the test database of tests/support/kiosk_parts.h.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "fixtures.h"
#include "kiosk_parts.h"
#include "sp/clock.h"
#include "sp/dragon.h"

enum { W = 1280, H = 800, MAX_DRAGONS = 6 };

int main(int argc, char** argv)
{
    bool json = sp_bench_json_flag(argc, argv);
    const char* db = NULL;
    int dragons = MAX_DRAGONS, runs = 5;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--db") && i + 1 < argc)
            db = argv[++i];
        else if (!strcmp(argv[i], "--dragons") && i + 1 < argc)
            dragons = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
    }
    if (dragons < 1 || dragons > MAX_DRAGONS) dragons = MAX_DRAGONS;
    if (runs < 1) runs = 1;
    sp_error err = {0};
    char db_path[1100], dir[1024];
    bool real = false;
    kp_stroke strokes[DRAGON_PART_COUNT];
    if (!kp_bench_setup("dragon_bodies", &db, "bench_dragon_bodies.db", dir, db_path, &real, strokes)) return 1;
    // ms[run][dragon][part]
    double* ms = calloc((size_t)runs * MAX_DRAGONS * DRAGON_PART_COUNT, sizeof(double));
    int parts_at_end = 0;
    for (int r = 0; r < runs; ++r) {
        sp_dragon* d = NULL;
        sp_dragon_create(&(sp_dragon_desc){.db_path = db, .canvas_w = W, .canvas_h = H}, &d, &err);
        if (!d || !sp_dragon_model(d)) {
            fprintf(stderr, "bench dragon_bodies: %s\n", d ? sp_dragon_model_error(d) : err.text);
            return 1;
        }
        for (int g = 0; g < dragons; ++g)
            for (int i = 0; i < DRAGON_PART_COUNT; ++i) {
                const kp_stroke* s = &strokes[i];
                sp_vec2* xy = malloc(sizeof(sp_vec2) * (size_t)s->n);
                for (int k = 0; k < s->n; ++k)
                    xy[k] = (sp_vec2){20 + 420 * (g % 3) + 0.5 * s->xy[k].x, 10 + 400 * (g / 3) + 0.5 * s->xy[k].y};
                sp_stroke st = {s->n, xy, NULL};
                sp_dragon_result res;
                double t0 = sp_now_ms();
                if (sp_dragon_add_stroke(d, &st, NULL, &res, &err) != SP_OK) {
                    fprintf(stderr, "bench dragon_bodies: %s\n", err.text);
                    return 1;
                }
                ms[((size_t)r * MAX_DRAGONS + (size_t)g) * DRAGON_PART_COUNT + (size_t)i] = sp_now_ms() - t0;
                free(xy);
            }
        parts_at_end = sp_dragon_part_count(d);
        sp_dragon_destroy(d);
    }
    sp_bench_row rows[MAX_DRAGONS + 1];
    int nr = 0;
    double* v = malloc(sizeof(double) * (size_t)runs * DRAGON_PART_COUNT);
    for (int g = 0; g < dragons; ++g) {
        for (int r = 0; r < runs; ++r)
            v[r] = ms[((size_t)r * MAX_DRAGONS + (size_t)g) * DRAGON_PART_COUNT];
        rows[nr] = (sp_bench_row){"", 0, 0, runs, -1, 50, ""};
        snprintf(rows[nr].name, sizeof rows[nr].name, "body stroke of dragon %d (%d strokes before it)", g + 1,
                 g * DRAGON_PART_COUNT);
        sp_bench_stats(v, runs, &rows[nr].ms_median, &rows[nr].ms_p90);
        ++nr;
    }
    int n = 0;
    for (int r = 0; r < runs; ++r)
        for (int i = 1; i < DRAGON_PART_COUNT; ++i)
            v[n++] = ms[((size_t)r * MAX_DRAGONS + (size_t)(dragons - 1)) * DRAGON_PART_COUNT + (size_t)i];
    rows[nr] = (sp_bench_row){"", 0, 0, n, -1, 50, ""};
    snprintf(rows[nr].name, sizeof rows[nr].name, "the last dragon's other strokes");
    snprintf(rows[nr].extra, sizeof rows[nr].extra, "\"parts_at_end\": %d", parts_at_end);
    sp_bench_stats(v, n, &rows[nr].ms_median, &rows[nr].ms_p90);
    ++nr;
    sp_bench_print("dragon pipeline as the canvas fills (headless, 1280x800)", rows, nr, json);
    const char* given = db == db_path ? (real ? "the assets' parts" : "stand-in parts") : db;
    if (!json) printf("%d parts on the canvas at the end (%s)\n", parts_at_end, given);
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        free(strokes[i].xy);
    free(v), free(ms);
    return 0;
}
