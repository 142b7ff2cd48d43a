# fuzz_model: libFuzzer over classifier models (sp_clf_from_bytes, then one
# classification with a model that loads) (SP_FUZZ=ON, clang only). Seeds:
# three tiny models trained on made-up rings, zigzags and lines, three of
# each (`sketchpose train --threads 1` with --words 8 --knn 2;
# --words 6 --knn 3 --pyramid 2 --no-tfidf --shape-weight 0.5; --words 5
# --knn 1 --no-pyramid --no-hellinger --no-mirror --picture-weight -1);
# test_classifier model_files checks that they still load. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_model -max_total_time=300 /tmp/model-corpus tests/fuzz/corpus/model
if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang" OR NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(WARNING "SP_FUZZ needs clang; fuzz_model not built")
  return()
endif()
# Coverage feedback from the classifier itself, not only the entry point.
target_compile_options(sp_classifier PRIVATE -fsanitize=fuzzer-no-link,address -fno-omit-frame-pointer)
add_executable(fuzz_model ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_model.c)
target_link_libraries(fuzz_model PRIVATE sp::classifier)
target_compile_options(fuzz_model PRIVATE -fsanitize=fuzzer,address -fno-omit-frame-pointer)
target_link_options(fuzz_model PRIVATE -fsanitize=fuzzer,address)
# Short smoke run over the seeds; new inputs go to the build tree, never into the checked-in seeds.
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_model)
add_test(NAME fuzz_model_seeds COMMAND fuzz_model -runs=500 -seed=1 -max_len=70000 ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_model
         ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/model)
set_tests_properties(fuzz_model_seeds PROPERTIES TIMEOUT 300)
