# tests/bench/dragon_bodies: the kiosk pipeline as the canvas fills with dragons (see the file's top comment).
if(TARGET sp_dragon)
  add_executable(bench_dragon_bodies bench/dragon_bodies.c)
  target_link_libraries(bench_dragon_bodies PRIVATE sp_test_fixtures sp_dragon sp::partdb)
  set_target_properties(bench_dragon_bodies PROPERTIES OUTPUT_NAME dragon_bodies RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
endif()
