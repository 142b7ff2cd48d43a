# fuzz_ndjson, fuzz_svg: libFuzzer over sketchio's stroke readers (SP_FUZZ=ON, clang only).
# fuzz_ndjson also feeds the stroke JSON reader. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_svg -max_total_time=60 /tmp/svg-corpus tests/fuzz/corpus/svg
sp_fuzz_target(ndjson LIBS sp::sketchio INSTRUMENT sp_sketchio RUNS 5000 MAX_LEN 65536)
sp_fuzz_target(svg LIBS sp::sketchio RUNS 5000 MAX_LEN 65536)
