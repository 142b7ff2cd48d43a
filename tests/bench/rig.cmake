add_executable(bench_rig bench/rig.c)
target_link_libraries(bench_rig PRIVATE sp_test_fixtures sp::partdb)
set_target_properties(bench_rig PROPERTIES OUTPUT_NAME rig RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
