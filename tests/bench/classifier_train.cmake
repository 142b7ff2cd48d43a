# Classifier training time on 10k drawings (Quick, Draw! + hand-drawn variants):
# built with the tests, run on demand.
add_executable(bench_classifier_train bench/classifier_train.c)
target_link_libraries(bench_classifier_train PRIVATE sp_test_fixtures sp::partdb sp::classifier)
# Its table's rows leave their measured fields zero ({0}), which -Wextra flags.
target_compile_options(bench_classifier_train PRIVATE -Wno-missing-field-initializers)
