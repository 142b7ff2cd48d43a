#include "bench.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/math.h"

void sp_bench_stats(double* ms, int n, double* median, double* p90)
{
    qsort(ms, (size_t)n, sizeof(double), sp_cmp_double);
    *median = n % 2 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
    int k = (int)(0.9 * (n - 1) + 0.5);
    *p90 = ms[k];
}

bool sp_bench_json_flag(int argc, char** argv)
{
    for (int i = 1; i < argc; ++i)
        if (!strcmp(argv[i], "--json")) return true;
    return false;
}

void sp_bench_print(const char* title, const sp_bench_row* rows, int n, bool json)
{
    if (json) {
        printf("[\n");
        for (int i = 0; i < n; ++i) {
            const sp_bench_row* r = &rows[i];
            printf("  {\"case\": \"%s\", \"ms_median\": %.4f, \"ms_p90\": %.4f, \"runs\": %d", r->name, r->ms_median, r->ms_p90, r->runs);
            if (r->paper_ms >= 0) printf(", \"paper_ms\": %g", r->paper_ms);
            if (r->target_ms >= 0) printf(", \"target_ms\": %g", r->target_ms);
            if (r->extra[0]) printf(", %s", r->extra);
            printf("}%s\n", i + 1 < n ? "," : "");
        }
        printf("]\n");
        return;
    }
    printf("%s\n%-56s %12s %12s %6s %10s %10s\n", title, "case", "median ms", "p90 ms", "runs", "paper ms", "target ms");
    for (int i = 0; i < n; ++i) {
        const sp_bench_row* r = &rows[i];
        char paper[32] = "-", target[32] = "-";
        if (r->paper_ms >= 0) snprintf(paper, sizeof paper, "%g", r->paper_ms);
        if (r->target_ms >= 0) snprintf(target, sizeof target, "%g", r->target_ms);
        printf("%-56s %12.4f %12.4f %6d %10s %10s\n", r->name, r->ms_median, r->ms_p90, r->runs, paper, target);
    }
}
