sp_unit_test(solver LIBS sp::solver)
# test_solver's `coarsening_remembered` counts FLANN's k-means runs through
# the linker (the solver calls it from its static library).
target_link_options(test_solver PRIVATE -Wl,--wrap=flann_compute_cluster_centers_double)
target_link_libraries(test_solver PRIVATE sp::flann)
