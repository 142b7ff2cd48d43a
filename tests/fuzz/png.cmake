# fuzz_png: libFuzzer over the PNG drawing decoder (classifier/src/png_decode.c:
# header, chunk CRCs, then Debian's stb_image) (SP_FUZZ=ON, clang only). Run
# longer by hand, e.g.
#   build-fuzz/tests/fuzz_png -max_total_time=300 /tmp/png-corpus tests/fuzz/corpus/png
if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
  message(WARNING "SP_FUZZ needs clang; fuzz_png not built")
  return()
endif()
# The decoder's file compiled in, instrumented; stb_image is Debian's library
# (not instrumented: the target also feeds it each input with its CRCs made right).
add_executable(fuzz_png ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_png.c ${PROJECT_SOURCE_DIR}/classifier/src/png_decode.c)
target_include_directories(fuzz_png PRIVATE ${PROJECT_SOURCE_DIR}/classifier/src)
target_link_libraries(fuzz_png PRIVATE PkgConfig::STB ZLIB::ZLIB sp_flags)
target_compile_options(fuzz_png PRIVATE -fsanitize=fuzzer,address -fno-omit-frame-pointer)
target_link_options(fuzz_png PRIVATE -fsanitize=fuzzer,address)
# Short smoke run over the seeds; new inputs go to the build tree, never into the checked-in seeds.
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_png)
add_test(NAME fuzz_png_seeds COMMAND fuzz_png -runs=2000 -seed=1 -max_len=65536 ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_png
         ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/png)
set_tests_properties(fuzz_png_seeds PROPERTIES TIMEOUT 300)
