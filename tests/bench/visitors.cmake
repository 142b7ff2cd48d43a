# The visitors' evaluation set (tests/data/visitors): its builder, and the
# benchmark that feeds it through the kiosk pipeline. Built with the tests, run on demand.
add_executable(sp-visitors-make tools/visitors_make.c)
target_link_libraries(sp-visitors-make PRIVATE sp_render sp::classifier sp::solver PkgConfig::CJSON ${MATH_LIB})
add_executable(bench_visitors bench/visitors.c)
target_link_libraries(bench_visitors PRIVATE sp_test_fixtures sp_dragon sp_render)
set_target_properties(bench_visitors PROPERTIES OUTPUT_NAME visitors RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
