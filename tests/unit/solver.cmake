sp_unit_test(solver LIBS sp::solver)
