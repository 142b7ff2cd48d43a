/// bench.h: timing and reporting shared by the programs in tests/bench/.
///
/// Each benchmark collects rows (case name, per-run milliseconds, optional
/// paper and target figures) and prints a human table, or with --json one
/// JSON array of rows {"case", "ms_median", "ms_p90", "runs", "paper_ms",
/// "target_ms", ...} as DESIGN.md says.
#ifndef SP_BENCH_H
#define SP_BENCH_H

#include <stdbool.h>

typedef struct sp_bench_row {
    char name[96];
    double ms_median, ms_p90;
    int runs;
    double paper_ms;  ///< < 0: none
    double target_ms; ///< < 0: none
    char extra[256];  ///< extra JSON members, e.g. "\"vertices\": 50000" (may be empty)
} sp_bench_row;

/// Median and 90th percentile of n samples (sorts them).
void sp_bench_stats(double* ms, int n, double* median, double* p90);
/// Prints the rows as a table, or as JSON when json is set.
void sp_bench_print(const char* title, const sp_bench_row* rows, int n, bool json);
/// True if argv has --json.
bool sp_bench_json_flag(int argc, char** argv);

#endif
