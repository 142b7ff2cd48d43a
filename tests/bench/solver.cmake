add_executable(bench_solver bench/solver.c)
target_link_libraries(bench_solver PRIVATE sp_test_fixtures sp::partdb sp::plugin)
# The black-box row poses the face plugin (assets/face).
target_compile_definitions(bench_solver PRIVATE SP_FACE_PLUGIN="$<TARGET_FILE:sp_face>")
add_dependencies(bench_solver sp_face)
set_target_properties(bench_solver PROPERTIES OUTPUT_NAME solver RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
