# Classifier benchmark: built with the tests, run on demand (never by CTest).
add_executable(bench_classifier bench/classifier.c)
target_link_libraries(bench_classifier PRIVATE sp_test_fixtures sp::classifier)
