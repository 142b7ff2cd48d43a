# fuzz_kiosk_ui: libFuzzer over the kiosk's UI state machine and its session
# scripts (SP_FUZZ=ON, clang only). The fuzz build builds no apps, so the
# GL-free UI library (app/kiosk_ui) is built here from its sources,
# instrumented. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_kiosk_ui -max_total_time=600 /tmp/ui-corpus tests/fuzz/corpus/kiosk_ui
if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
  message(WARNING "SP_FUZZ needs clang; fuzz_kiosk_ui not built")
  return()
endif()
file(GLOB SP_FUZZ_UI_SRC CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/app/kiosk_ui/src/*.c)
add_library(sp_kiosk_ui_fuzz STATIC ${SP_FUZZ_UI_SRC})
target_include_directories(sp_kiosk_ui_fuzz PUBLIC ${PROJECT_SOURCE_DIR}/app/kiosk_ui/include)
target_link_libraries(sp_kiosk_ui_fuzz PUBLIC sp::solver sp_flags PRIVATE sp::sketchio PkgConfig::CJSON ${MATH_LIB})
# UBSan too: the state machine is arithmetic on times and pixels (NaN, overflow).
set(SP_FUZZ_UI_SAN -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
target_compile_options(sp_kiosk_ui_fuzz PRIVATE -fsanitize=fuzzer-no-link ${SP_FUZZ_UI_SAN})
add_executable(fuzz_kiosk_ui ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_kiosk_ui.c)
target_link_libraries(fuzz_kiosk_ui PRIVATE sp_kiosk_ui_fuzz ${MATH_LIB})
target_compile_options(fuzz_kiosk_ui PRIVATE -fsanitize=fuzzer ${SP_FUZZ_UI_SAN})
target_link_options(fuzz_kiosk_ui PRIVATE -fsanitize=fuzzer,address,undefined)
# Short smoke run over the seeds; new inputs go to the build tree, never into the checked-in seeds.
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_kiosk_ui)
add_test(NAME fuzz_kiosk_ui_seeds COMMAND fuzz_kiosk_ui -runs=3000 -seed=1 -max_len=65536
         ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus_kiosk_ui ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus/kiosk_ui)
set_tests_properties(fuzz_kiosk_ui_seeds PROPERTIES TIMEOUT 300)
