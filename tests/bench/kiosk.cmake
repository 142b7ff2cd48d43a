# tests/bench/kiosk: the kiosk's speed on a headless GL context (see the file's top comment).
if(TARGET sp_kiosk)
  add_executable(bench_kiosk bench/kiosk.c)
  target_link_libraries(bench_kiosk PRIVATE sp_test_fixtures sp_kiosk SQLite::SQLite3)
  set_target_properties(bench_kiosk PROPERTIES OUTPUT_NAME kiosk RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
endif()
