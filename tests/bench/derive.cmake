add_executable(bench_derive bench/derive.c)
target_link_libraries(bench_derive PRIVATE sp_test_fixtures sp::partdb)
set_target_properties(bench_derive PROPERTIES OUTPUT_NAME derive RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
