# fuzz_kiosk_ui: libFuzzer over the kiosk's UI state machine and its session
# scripts (SP_FUZZ=ON, clang only). The fuzz build builds no apps, so the
# GL-free UI library (app/kiosk_ui) is built here from its sources,
# instrumented. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_kiosk_ui -max_total_time=600 /tmp/ui-corpus tests/fuzz/corpus/kiosk_ui
file(GLOB SP_FUZZ_UI_SRC CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/app/kiosk_ui/src/*.c)
add_library(sp_kiosk_ui_fuzz STATIC ${SP_FUZZ_UI_SRC})
target_include_directories(sp_kiosk_ui_fuzz PUBLIC ${PROJECT_SOURCE_DIR}/app/kiosk_ui/include)
target_link_libraries(sp_kiosk_ui_fuzz PUBLIC sp::solver sp_flags PRIVATE sp::sketchio PkgConfig::CJSON ${MATH_LIB})
# UBSan too: the state machine is arithmetic on times and pixels (NaN, overflow).
sp_fuzz_target(kiosk_ui LIBS sp_kiosk_ui_fuzz ${MATH_LIB} INSTRUMENT sp_kiosk_ui_fuzz SAN address undefined
               OPTIONS -fno-sanitize-recover=all RUNS 3000 MAX_LEN 65536)
