# Dragon-part classifier benchmark (hand-drawn training sketches, held-out harsh
# sketches, non-dragon Quick, Draw! scribbles): built with the tests, run on demand.
add_executable(bench_dragon_classes bench/dragon_classes.c)
target_link_libraries(bench_dragon_classes PRIVATE sp_test_fixtures sp::partdb sp::classifier)
