# A year of visitors' strokes in the part database: collecting, reviewing,
# training (see the file's top comment). Built with the tests, run on demand.
add_executable(bench_kiosk_sketches bench/kiosk_sketches.c)
target_include_directories(bench_kiosk_sketches PRIVATE ${PROJECT_SOURCE_DIR}/partdb/src)
target_link_libraries(bench_kiosk_sketches PRIVATE sp_test_fixtures sp::partdb SQLite::SQLite3)
set_target_properties(bench_kiosk_sketches PROPERTIES OUTPUT_NAME kiosk_sketches RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)
