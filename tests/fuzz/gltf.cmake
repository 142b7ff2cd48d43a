# fuzz_gltf: libFuzzer over the glTF loader (SP_FUZZ=ON, clang only).
if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang" OR NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(WARNING "SP_FUZZ needs clang (-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++); fuzz_gltf not built")
  return()
endif()
# Coverage feedback from the loader itself, not only the entry point.
target_compile_options(sp_gltf PRIVATE -fsanitize=fuzzer-no-link,address -fno-omit-frame-pointer)
add_executable(fuzz_gltf ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_gltf.c)
target_link_libraries(fuzz_gltf PRIVATE sp::gltf)
target_compile_options(fuzz_gltf PRIVATE -fsanitize=fuzzer,address -fno-omit-frame-pointer)
target_link_options(fuzz_gltf PRIVATE -fsanitize=fuzzer,address)
# A short smoke run over the seed corpus, so that CTest notices a crashing
# seed. New inputs go to the first directory (in the build tree), never into
# the checked-in seeds.
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_gltf)
add_test(NAME fuzz_gltf_seeds COMMAND fuzz_gltf -runs=2000 -seed=1 ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_gltf
         ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/gltf)
set_tests_properties(fuzz_gltf_seeds PROPERTIES TIMEOUT 300)
