# fuzz_png: libFuzzer over the PNG drawing decoder (classifier/src/png_decode.c:
# header, chunk CRCs, then Debian's stb_image) (SP_FUZZ=ON, clang only). Run
# longer by hand, e.g.
#   build-fuzz/tests/fuzz_png -max_total_time=300 /tmp/png-corpus tests/fuzz/corpus/png
# The decoder's file compiled in, instrumented; stb_image is Debian's library
# (not instrumented: the target also feeds it each input with its CRCs made right).
sp_fuzz_target(png SOURCES ${PROJECT_SOURCE_DIR}/classifier/src/png_decode.c LIBS PkgConfig::STB ZLIB::ZLIB sp_flags RUNS 2000
               MAX_LEN 65536)
target_include_directories(fuzz_png PRIVATE ${PROJECT_SOURCE_DIR}/classifier/src)
