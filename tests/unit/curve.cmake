sp_unit_test(curve LIBS sp::solver)
