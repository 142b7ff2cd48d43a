// tests/bench/derive: deriving a kiosk part from a rigged glTF made elsewhere
// (sp/derive.h), the work of `sketchpose derive` without the preview: load the
// file, derive (outline traced and bound to the surface, stick, parameters,
// clip re-keyed), write the .glb. Median of runs.
//   build/tests/bench/derive [--json] [--runs N]
// Cases: the project's lizard (tests/support/foreign_gltf.h: several meshes
// and primitives under one skin, Z-up, a 2 s clip) at 3k, 30k and 100k
// vertices (issue 17: 100,000 vertices in at most 10 s on 2 cores), and
// CesiumMan when ../shared/data is present. Single-threaded code: one core.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "foreign_gltf.h"
#include "sp/clock.h"
#include "sp/derive.h"
#include "sp/gltf.h"
#include "test.h"

enum { MAX_ROWS = 16 };

typedef struct stage_ms {
    double load, derive, save, total;
} stage_ms;

static bool derive_once(const char* in, const char* out, stage_ms* t, int* vertices)
{
    sp_character src = {0}, part = {0};
    sp_error err = {0};
    double t0 = sp_now_ms();
    bool ok = sp_gltf_load(in, &src, &err) == SP_OK;
    double t1 = sp_now_ms();
    ok = ok && sp_part_derive(&src, NULL, &part, NULL, &err) == SP_OK;
    double t2 = sp_now_ms();
    ok = ok && sp_gltf_save(&part, NULL, out, &err) == SP_OK;
    double t3 = sp_now_ms();
    if (!ok) fprintf(stderr, "bench derive: %s\n", err.text);
    *t = (stage_ms){t1 - t0, t2 - t1, t3 - t2, t3 - t0};
    *vertices = src.rig.vertex_count;
    sp_character_free(&part);
    sp_character_free(&src);
    return ok;
}

static int bench_file(const char* label, const char* in, int runs, double target, sp_bench_row* rows)
{
    char out[1024];
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("bench_derive_sp.glb"));
    double* ms[4];
    for (int k = 0; k < 4; ++k)
        ms[k] = malloc(sizeof(double) * (size_t)runs);
    int vertices = 0;
    for (int r = 0; r < runs; ++r) {
        stage_ms t;
        if (!derive_once(in, out, &t, &vertices)) exit(1);
        ms[0][r] = t.total, ms[1][r] = t.load, ms[2][r] = t.derive, ms[3][r] = t.save;
    }
    const char* stage[4] = {"load+derive+save", "load", "derive", "save"};
    for (int k = 0; k < 4; ++k) {
        sp_bench_row* row = &rows[k];
        *row = (sp_bench_row){.runs = runs, .paper_ms = -1, .target_ms = k == 0 ? target : -1};
        snprintf(row->name, sizeof row->name, "%s: %s", label, stage[k]);
        sp_bench_stats(ms[k], runs, &row->ms_median, &row->ms_p90);
        snprintf(row->extra, sizeof row->extra, "\"vertices\": %d", vertices);
        free(ms[k]);
    }
    unlink(out);
    return 4;
}

int main(int argc, char** argv)
{
    int runs = 5;
    for (int i = 1; i < argc; ++i)
        if (!strcmp(argv[i], "--runs") && i + 1 < argc) runs = atoi(argv[++i]);
    if (runs < 1) runs = 1;
    sp_bench_row rows[MAX_ROWS];
    int n = 0;
    const int sizes[3] = {3000, 30000, 100000};
    for (int s = 0; s < 3; ++s) {
        char path[1024], label[64];
        snprintf(path, sizeof path, "%s", sp_test_tmp_path("bench_lizard.glb"));
        int nv = sp_foreign_write(&(sp_foreign_desc){.vertices = sizes[s], .z_up = true}, path);
        if (nv < 0) return 1;
        snprintf(label, sizeof label, "lizard %dk", (sizes[s] + 500) / 1000);
        n += bench_file(label, path, runs, sizes[s] == 100000 ? 10000.0 : -1, rows + n);
        unlink(path);
    }
    const char* data = sp_test_data_dir();
    if (data) {
        char path[1024];
        snprintf(path, sizeof path, "%s/gltf/CesiumMan/CesiumMan.glb", data);
        if (access(path, R_OK) == 0) n += bench_file("CesiumMan", path, runs, -1, rows + n);
    } else {
        fprintf(stderr, "note: ../shared/data absent, CesiumMan skipped\n");
    }
    sp_bench_print("Deriving a kiosk part from a rigged glTF (load, derive, save; ms)", rows, n, sp_bench_json_flag(argc, argv));
    return 0;
}
