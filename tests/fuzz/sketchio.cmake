# fuzz_ndjson, fuzz_svg: libFuzzer over sketchio's stroke readers (SP_FUZZ=ON, clang only).
# fuzz_ndjson also feeds the stroke JSON reader. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_svg -max_total_time=60 /tmp/svg-corpus tests/fuzz/corpus/svg
if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang" OR NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(WARNING "SP_FUZZ needs clang; fuzz_ndjson and fuzz_svg not built")
  return()
endif()
# Coverage feedback from the readers themselves, not only the entry points.
target_compile_options(sp_sketchio PRIVATE -fsanitize=fuzzer-no-link,address -fno-omit-frame-pointer)
foreach(t ndjson svg)
  add_executable(fuzz_${t} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_${t}.c)
  target_link_libraries(fuzz_${t} PRIVATE sp::sketchio)
  target_compile_options(fuzz_${t} PRIVATE -fsanitize=fuzzer,address -fno-omit-frame-pointer)
  target_link_options(fuzz_${t} PRIVATE -fsanitize=fuzzer,address)
  # Short smoke run over the seeds; new inputs go to the build tree, never into the checked-in seeds.
  file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_${t})
  add_test(NAME fuzz_${t}_seeds COMMAND fuzz_${t} -runs=5000 -seed=1 -max_len=65536
           ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_${t} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/${t})
  set_tests_properties(fuzz_${t}_seeds PROPERTIES TIMEOUT 300)
endforeach()
