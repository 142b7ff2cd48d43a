add_executable(bench_solver bench/solver.c)
target_link_libraries(bench_solver PRIVATE sp_test_support sp::partdb)
set_target_properties(bench_solver PROPERTIES OUTPUT_NAME solver RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
